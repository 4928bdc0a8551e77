"""Close to V^c (k0 = 0.01, V = 0.9 V^c): does the cohort method's fixed point hold when
its cell is refined, and what moves it?

Each run is one ``micro.cohort.cycle_cohorts`` call at dt = 0.02 and the cell
``kappa zbar / h_div``, either with micro's default stopping (tol = 2e-5, ``--cycles 0``)
or forced to iterate ``--cycles`` plain cycles (tol = 1e-10: a run that cannot stop
early), with the cell floor ``CELL_FLOOR`` of ``micro.cohort.options`` (cells with less surviving mass
are dropped) set to ``--floor``.  Prints sigma_max, the period, the cycles run, whether
the result is certified and its message; appends a row to
benchmarks/results/micro_cohort_near_vc_check.csv.

Run, for example (CPU times at a load of 2-5):

    python -m studies micro_cohort_near_vc_check --h-div 20            # 10 s
    python -m studies micro_cohort_near_vc_check --h-div 20 --cycles 150  # 30 s
    python -m studies micro_cohort_near_vc_check --h-div 40            # 13 s
    python -m studies micro_cohort_near_vc_check --h-div 40 --cycles 450  # 160 s
    python -m studies micro_cohort_near_vc_check --h-div 40 --floor 1e-20  # 20-40 s

Recorded in docs/validation/micro_cohort.md, "Close to V^c: a failed acceleration".
Private names: ``cycle_cohorts`` (for ``max_iter`` and the history) and ``CELL_FLOOR``
(the floor is not an option of the public method).
"""
from __future__ import annotations

import argparse
import dataclasses

import pandas as pd

import micro
import micro.cohort as C  # cycle_cohorts' history (see above)
from micro.cohort import options as cohort_options  # CELL_FLOOR
from benchmarks._harness import RESULTS, Stopwatch, merged, write_csv


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--h-div", type=float, default=20.0)
    ap.add_argument("--dt", type=float, default=0.02)
    ap.add_argument("--cycles", type=int, default=0, help="plain cycles to force (0: default stopping)")
    ap.add_argument("--floor", type=float, default=cohort_options.DEFAULT.CELL_FLOOR)
    ap.add_argument("--k0", type=float, default=0.01)
    ap.add_argument("--fraction", type=float, default=0.9)
    a = ap.parse_args()
    cohort_options.DEFAULT = dataclasses.replace(cohort_options.DEFAULT, CELL_FLOOR=a.floor)
    model = micro.Model(k0=a.k0)
    V = a.fraction * micro.critical_velocity(model).Vc
    h = model.kappa * model.zbar / a.h_div
    with Stopwatch(cpu=True) as sw:
        r = C.cycle_cohorts(model, V, dt=a.dt, h=h, tol=2e-5 if a.cycles == 0 else 1e-10,
                            max_iter=max(a.cycles, 200))
    row = dict(k0=a.k0, V_over_Vc=a.fraction, dt=a.dt, h_div=a.h_div, floor=f"{a.floor:g}", cycles_forced=a.cycles,
               sigma_max=r.sigma_max, period=r.period, cycles=r.iterations,
               certified=bool(r.converged and r.error == r.error), error=r.error,
               dropped_mass=r.mass_error, cpu_s=sw.seconds, message=r.message)
    print(row)
    path = RESULTS / "micro_cohort_near_vc_check.csv"
    write_csv(merged(path, pd.DataFrame([row]), ["k0", "V_over_Vc", "dt", "h_div", "floor", "cycles_forced"]), path)


if __name__ == "__main__":
    main()
