"""The stick-slip amplitude against V^c - V by the cohort method (``micro.cohort``).

Fig. 4 parameters, k0 = 0.1 and 0.01, V / V^c from 0.5 to 0.999 with the exact V^c of
the renewal chain; each V starts from the previous V's cycle (its whole state),
converged to tol = 1e-6 at (dt, h) = (0.01, kappa zbar / 20), and again at (0.005,
kappa zbar / 40) to measure the discretisation error of each amplitude (``--dt`` sets the
levels, each with h = 5 kappa zbar dt).  The law is reported as the local
exponents d log(amplitude) / d log(1 - V/V^c) between neighbouring V, at each level.

Writes benchmarks/results/micro_cohort_amplitude.csv, a row at a time (rows merge by k0,
V / V^c, dt and h: ``--k0 0.01`` alone adds its rows).

    python -m studies micro_cohort_amplitude        # hours on 1 core (0.98-0.999 at dt = 0.005)
    python -m studies micro_cohort_amplitude --fractions 0.9,0.95,0.97,0.98,0.99,0.995 --dt 0.02
                                                       # k0 = 0.1: 16 minutes; 0.01: 1.5 minutes
    python -m studies micro_cohort_amplitude --k0 0.1 --fractions 0.95,0.97,0.98,0.99,0.995 \
        --dt 0.02,0.01 --tol 2e-5 --cold              # the k0 = 0.1 points near V^c again (2026-11-27)

``--tol`` (default 1e-6) and ``--cold`` (each point from rest) are in the rows.
"""
from __future__ import annotations

import argparse
from pathlib import Path

import numpy as np
import pandas as pd

import micro
from micro.cohort import cycle_cohorts

from benchmarks._harness import RESULTS, Stopwatch, warm_up, write_csv

FRACTIONS = (0.5, 0.7, 0.8, 0.9, 0.95, 0.97, 0.98, 0.99, 0.995, 0.998, 0.999)


def local_exponents(frac: np.ndarray, amp: np.ndarray) -> np.ndarray:
    """d log(amplitude) / d log(1 - V/V^c) between neighbouring points (sorted by V)."""
    d = 1.0 - frac
    return np.log(amp[:-1] / amp[1:]) / np.log(d[:-1] / d[1:])


KEY = ["k0", "V_over_Vc", "dt", "h"]


def save(rows: list[dict], out: Path) -> pd.DataFrame:
    """Merge ``rows`` into the CSV at ``out`` (a row replaces the one with its k0, V / V^c,
    dt and h), so that an interrupted run keeps its rows and runs at other k0 add theirs."""
    frame = pd.DataFrame(rows)
    frame["h"] = frame["h"].round(12)  # (h = 5 kappa zbar dt is a key: no round-off in it)
    if out.exists():
        old = pd.read_csv(out)
        old["h"] = old["h"].round(12)
        old = old[~old.set_index(KEY).index.isin(frame.set_index(KEY).index)]
        frame = pd.concat([old, frame], ignore_index=True)
    frame = frame.sort_values(["k0", "V_over_Vc", "dt"], ascending=[False, True, False]).reset_index(drop=True)
    return write_csv(frame, out)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--k0", default="0.1,0.01")
    ap.add_argument("--fractions", default=",".join(str(f) for f in FRACTIONS))
    ap.add_argument("--max-iter", type=int, default=400, help="cycles (and accelerated cycles) per point")
    ap.add_argument("--dt", default="0.01,0.005",
                    help="time steps, each with cells h = kappa zbar * dt * 5 (the default pairs)")
    ap.add_argument("--tol", type=float, default=1e-6, help="the fixed points' tolerance in stress")
    ap.add_argument("--cold", action="store_true",
                    help="start each point from rest instead of from the previous V's cycle")
    ap.add_argument("--out", default=str(RESULTS / "micro_cohort_amplitude.csv"))
    args = ap.parse_args()
    out = Path(args.out)
    rows = []
    warm_up(cycle_cohorts, micro.Model(k0=0.1), 0.3, tol=1e-3, max_iter=6)
    for k0 in (float(v) for v in args.k0.split(",")):
        model = micro.Model(k0=k0)
        Vc = micro.critical_velocity(model).Vc
        lam = model.kappa * model.zbar
        starts = {}
        for frac in (float(f) for f in args.fractions.split(",")):
            V = frac * Vc
            for dt in (float(v) for v in args.dt.split(",")):
                h = 5.0 * lam * dt
                sw = Stopwatch()
                res = cycle_cohorts(model, V, dt=dt, h=h, tol=args.tol, start=None if args.cold else starts.get(h),
                                    max_iter=args.max_iter)
                if res.applicable:
                    starts[h] = res  # (the next V continues from this cycle's whole state)
                rows.append(dict(k0=k0, Vc=Vc, V_over_Vc=frac, V=V, dt=dt, h=h, tol=args.tol, cold=args.cold,
                                 sigma_max=res.sigma_max,
                                 sigma_min=res.sigma_min, amplitude=res.sigma_max - res.sigma_min,
                                 period=res.period, unjumped=res.unjumped, error=res.error, cycles=res.iterations,
                                 converged=res.converged, applicable=res.applicable,
                                 wall_s=sw.seconds, message=res.message))
                print({k: v for k, v in rows[-1].items() if k != "message"}, flush=True)
                frame = save(rows, out)
    # the law: local exponents at each resolution (their change with the resolution is
    # their discretisation error)
    for (k0, dt), grp in frame[frame.converged].groupby(["k0", "dt"], sort=False):
        grp = grp.sort_values("V_over_Vc")
        if len(grp) >= 2:
            nu = local_exponents(grp.V_over_Vc.to_numpy(), grp.amplitude.to_numpy())
            pairs = ", ".join(f"{a:g}-{b:g}: {v:.3f}" for a, b, v in zip(grp.V_over_Vc, grp.V_over_Vc[1:], nu))
            print(f"k0 = {k0:g}, dt = {dt:g}: local exponents of the amplitude between V/Vc {pairs}")


if __name__ == "__main__":
    main()
