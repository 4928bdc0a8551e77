"""Does the cohort method's stick-slip cycle survive across V^c?  A continuation in V.

The cycle at the first ``--fractions`` V / V^c is solved from rest; each next V starts from
the last one's whole state (``micro.cohort.cycle_cohorts(..., start=previous)``), at
(dt, h = 5 kappa zbar dt).  Above V^c steady sliding is linearly stable (the renewal
chain's spectrum), so a cycle that converges there coexists with it (a subcritical
onset); one that decays ends without a fixed point, its amplitude falling cycle by cycle,
or with no shock at all.  Each row: the result, its error and message, and the amplitude
of the first and last cycles of the run's history (the cycles since its iteration last
restarted: a new step or an acceleration clears it) and their ratio per cycle.

Writes benchmarks/results/micro_cohort_above_vc.csv (rows merge by k0, V / V^c, dt).

    python -m studies micro_cohort_above_vc --k0 0.1 --fractions 0.99,0.995,0.998,1.0,1.002,1.005,1.01

Recorded in docs/validation/micro_transition.md section 5.
"""
from __future__ import annotations

import argparse
import math

import micro
from micro.cohort import cycle_cohorts

from benchmarks._harness import RESULTS, Stopwatch, write_csv


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--k0", type=float, default=0.1)
    ap.add_argument("--fractions", default="0.99,0.995,0.998,1.0,1.002,1.005,1.01")
    ap.add_argument("--dt", type=float, default=0.02)
    ap.add_argument("--tol", type=float, default=2e-5)
    ap.add_argument("--max-iter", type=int, default=300)
    a = ap.parse_args()
    model = micro.Model(k0=a.k0)
    Vc = micro.critical_velocity(model).Vc
    h = 5.0 * model.kappa * model.zbar * a.dt
    rows, start = [], None
    for frac in (float(f) for f in a.fractions.split(",")):
        with Stopwatch() as sw:
            r = cycle_cohorts(model, frac * Vc, dt=a.dt, h=h, tol=a.tol, start=start, max_iter=a.max_iter)
        hist = r.history if r.history is not None else []
        amps = [row[0] - row[1] for row in hist] if len(hist) else []
        first, last = (amps[0], amps[-1]) if amps else (math.nan, math.nan)
        per_cycle = (last / first) ** (1.0 / (len(amps) - 1)) if len(amps) > 1 and first > 0 and last > 0 else math.nan
        rows.append(dict(k0=a.k0, V_over_Vc=frac, V=frac * Vc, dt=a.dt, h=h, tol=a.tol, applicable=r.applicable,
                         converged=r.converged, sigma_max=r.sigma_max, sigma_min=r.sigma_min,
                         amplitude=r.sigma_max - r.sigma_min, period=r.period, unjumped=r.unjumped, error=r.error,
                         cycles=r.iterations, first_amplitude=first, last_amplitude=last,
                         amplitude_ratio_per_cycle=per_cycle, wall_s=sw.seconds, message=r.message))
        print({k: v for k, v in rows[-1].items() if k != "message"}, "|", r.message, flush=True)
        write_csv(rows, RESULTS / "micro_cohort_above_vc.csv", keys=["k0", "V_over_Vc", "dt"])
        if r.applicable and r.state is not None:
            start = r
        else:
            break


if __name__ == "__main__":
    main()
