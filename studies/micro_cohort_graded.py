"""Graded steps against uniform steps in long loading phases (the cohort method's graded step rule).

Fig. 4 parameters, the five k0 of Fig. 10 at V = 0.1 V^c (``--fraction``, or ``--V`` for
an absolute drive), where a loading phase lasts 7-11 relaxation times.  Each point is a
cold start of ``micro.cohort.cycle_cohorts`` at the time step ``--dt`` to ``--tol``, once
per cap ``--graded-max`` on the graded step (``GRADED_MAX``, in units of dt; ``1`` is
uniform steps, ``inf`` the uncapped grading, a step dt gamma d at the distance d from the
nearer end of the loading phase).  The first cap listed is the reference: the other rows
give their difference to it (what the cap costs in accuracy) and the ratio of the wall
times (what it saves).  Compilation is done first and not counted.

Writes benchmarks/results/micro_cohort_graded.csv (rows merge by k0, V, tol, dt and cap).

    python -m studies micro_cohort_graded        # about 5 minutes on 2 cores
    python -m studies micro_cohort_graded --k0 0.01 --V 0.01,0.1 --dt 0.02 --graded-max 4,16,inf
"""
from __future__ import annotations

import argparse
from pathlib import Path

import pandas as pd

import micro
# GRADED_MAX is a field of micro.cohort.options.CohortOptions: the uniform steps are had only
# by setting it to 1 for the run (options.override); no option of micro.Cohort sets it
from micro import cohort
from micro.cohort import options

from benchmarks._harness import K0, RESULTS, timed, warm_up, write_csv

QUANTITIES = ("sigma_max", "sigma_min", "sigma_before", "sigma_after")


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--k0", default=",".join(str(k) for k in K0))
    ap.add_argument("--fraction", type=float, default=0.1, help="V / V^c")
    ap.add_argument("--V", default=None, help="drive velocities (comma-separated), instead of --fraction")
    ap.add_argument("--dt", type=float, default=0.01)
    ap.add_argument("--tol", type=float, default=2e-6)
    ap.add_argument("--graded-max", default=f"{options.DEFAULT.GRADED_MAX:g},1",
                    help="caps of the graded step, in units of dt (1: uniform; inf: none); the first is the reference")
    ap.add_argument("--out", default=str(RESULTS / "micro_cohort_graded.csv"))
    args = ap.parse_args()
    out = Path(args.out)
    caps = [float(v) for v in args.graded_max.split(",")]  # ("inf" included)
    warm_up(cohort.cycle_cohorts, micro.Model(k0=0.1), 0.3, tol=1e-3, max_iter=6)
    for k0 in (float(v) for v in args.k0.split(",")):
        model = micro.Model(k0=k0)
        Vc = micro.critical_velocity(model).Vc
        velocities = ([float(v) for v in args.V.split(",")] if args.V else [args.fraction * Vc])
        for V in velocities:
            rows = []
            for cap in caps:
                with options.override(GRADED_MAX=cap):
                    res, wall = timed(cohort.cycle_cohorts, model, V, dt=args.dt, tol=args.tol)
                rows.append(dict(k0=k0, V_over_Vc=V / Vc, V=V, tol=args.tol, dt=args.dt,
                                 grading="uniform" if cap == 1.0 else "graded", graded_max=cap,
                                 **{name: getattr(res, name) for name in QUANTITIES}, period=res.period,
                                 error=res.error, cycles=res.iterations, converged=res.converged, wall_s=wall))
            ref = rows[0]
            for row in rows[1:]:
                for name in QUANTITIES:
                    row[f"{name}_minus_reference"] = row[name] - ref[name]
                row["speedup"] = ref["wall_s"] / row["wall_s"]
            for row in rows:
                diff = (f"minus cap {ref['graded_max']:g}: sigma_max {row['sigma_max_minus_reference']:+.1e}, "
                        f"sigma_min {row['sigma_min_minus_reference']:+.1e}, " if row is not ref else "")
                print(f"k0 = {k0:g}, V = {V:.4g} ({V / Vc:.3g} V^c), dt = {args.dt:g}, cap {row['graded_max']:g}: "
                      f"{diff}sigma_max {row['sigma_max']:.7f} (error {row['error']:.1e}), period {row['period']:.4g}, "
                      f"{row['cycles']} cycles, {row['wall_s']:.1f} s", flush=True)
            write_csv(pd.DataFrame(rows), out, keys=["k0", "V", "tol", "dt", "graded_max"])


if __name__ == "__main__":
    main()
