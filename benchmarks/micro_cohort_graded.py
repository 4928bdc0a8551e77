"""Graded steps against uniform steps in long loading phases (micro.cohort._step_length).

Fig. 4 parameters, the five k0 of Fig. 10 at V = 0.1 V^c (``--fraction``), where a
loading phase lasts 7-11 relaxation times.  Each point is a cold start of
``micro.cohort.cycle_cohorts`` at the default resolution to ``--tol``, once with the
graded steps (the default) and once with uniform steps (``GRADED_MAX = 1``); the
difference of the two fixed points is what the grading costs in accuracy, the ratio of
the wall times what it saves.  Compilation is done first and not counted.

Writes benchmarks/results/micro_cohort_graded.csv (rows merge by k0, V / V^c, tol and
grading).

    python benchmarks/micro_cohort_graded.py        # about 5 minutes on 2 cores
"""
from __future__ import annotations

import argparse
from pathlib import Path

import pandas as pd

import micro
# GRADED_MAX is a module constant of micro.cohort, not in its __all__: the uniform steps are
# had only by setting it to 1 for the run (and restoring it); no option of Cohort sets it
from micro import cohort

from _harness import K0, RESULTS, timed, warm_up, write_csv

QUANTITIES = ("sigma_max", "sigma_min", "sigma_before", "sigma_after")


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--k0", default=",".join(str(k) for k in K0))
    ap.add_argument("--fraction", type=float, default=0.1, help="V / V^c")
    ap.add_argument("--tol", type=float, default=2e-6)
    ap.add_argument("--out", default=str(RESULTS / "micro_cohort_graded.csv"))
    args = ap.parse_args()
    out = Path(args.out)
    warm_up(cohort.cycle_cohorts, micro.Model(k0=0.1), 0.3, tol=1e-3, max_iter=6)
    graded_max = cohort.GRADED_MAX
    for k0 in (float(v) for v in args.k0.split(",")):
        model = micro.Model(k0=k0)
        V = args.fraction * micro.critical_velocity(model).Vc
        rows = {}
        for grading, factor in (("graded", graded_max), ("uniform", 1.0)):
            cohort.GRADED_MAX = factor
            try:
                res, wall = timed(cohort.cycle_cohorts, model, V, tol=args.tol)
            finally:
                cohort.GRADED_MAX = graded_max
            rows[grading] = dict(k0=k0, V_over_Vc=args.fraction, V=V, tol=args.tol, grading=grading,
                                 **{name: getattr(res, name) for name in QUANTITIES}, period=res.period,
                                 error=res.error, cycles=res.iterations, converged=res.converged, wall_s=wall)
        g, u = rows["graded"], rows["uniform"]
        for name in QUANTITIES:
            g[f"{name}_minus_uniform"] = g[name] - u[name]
        g["speedup"] = u["wall_s"] / g["wall_s"]
        print(f"k0 = {k0:g}, {args.fraction:g} V^c: graded - uniform: sigma_max {g['sigma_max_minus_uniform']:+.1e}, "
              f"sigma_min {g['sigma_min_minus_uniform']:+.1e} (errors {g['error']:.1e}, {u['error']:.1e}); "
              f"{g['wall_s']:.1f} s against {u['wall_s']:.1f} s", flush=True)
        write_csv(pd.DataFrame([g, u]), out, keys=["k0", "V_over_Vc", "tol", "grading"])


if __name__ == "__main__":
    main()
