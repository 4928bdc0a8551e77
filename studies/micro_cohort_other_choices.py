"""The cohort method's discretisation choices other than its time step and cell, varied one
at a time at a fixed (dt, h): does any of them move the cycle?

The refinement studies move ``dt`` and the cell ``h`` (together or apart).  The method has
other choices, fields of ``micro.cohort.options.CohortOptions``, whose effect should vanish or be
nil: the grading of long loading phases (``GRADED_MAX``, ``GRADED_SLACK``), the step count
of short ones (``SHORT_PHASE``), the tolerance of the shock's start (``FOLD_TOL``), the mass
below which a cell is dropped (``CELL_FLOOR``), the replay of the loading phase's end for
the peak (``PEAK_CREEP``), the newborns' age within their step (``AGE``, the midpoint rule
that makes the method second order in dt; varied by +-0.05) and the Gauss-Legendre order
of the kernels' integrals over a cell (2 -> 4).  Each run solves the fixed point to
``--tol`` (far below the changes looked for), at ``micro.stationary(model, (1 - d) V^c,
method=micro.Cohort(dt, h = kappa zbar / h_div))``.

Written for the gap between the cohort's Richardson limit and the N-block at k0 = 0.01,
d = 0.1 (docs/validation/micro_transition.md §1): 4.5e-5 in the amplitude.

    NUMBA_NUM_THREADS=1 python -m studies micro_cohort_other_choices --k0 0.01 --d 0.1 --dt 0.01 --h-div 40

Writes ``benchmarks/results/micro_cohort_other_choices.csv`` (rows merge by k0, d, dt,
h_div, variant).  About 4 minutes on one core at k0 = 0.01, d = 0.1.
"""
from __future__ import annotations

import argparse

import numpy as np

import micro
from benchmarks._harness import RESULTS, Stopwatch, warm_up, write_csv
from micro import study_hooks
from micro.cohort import options as cohort_options

VARIANTS = (("GRADED_MAX", 1.0), ("SHORT_PHASE", 1.0), ("FOLD_TOL", 1e-10), ("CELL_FLOOR", 1e-16),
            ("PEAK_CREEP", 0.0), ("AGE", 0.45), ("AGE", 0.55), ("GRADED_SLACK", 0.05))


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--k0", type=float, default=0.01)
    ap.add_argument("--d", type=float, default=0.1)
    ap.add_argument("--dt", type=float, default=0.01)
    ap.add_argument("--h-div", type=float, default=40.0, help="the cell is kappa zbar / h_div")
    ap.add_argument("--tol", type=float, default=1e-6)
    args = ap.parse_args()
    model = micro.Model(k0=args.k0)
    V = (1.0 - args.d) * float(micro.critical_velocity(model).Vc)
    options = micro.Cohort(dt=args.dt, h=model.kappa * model.zbar / args.h_div, tol=args.tol, max_iter=400)
    warm_up(micro.stationary, micro.Model(k0=0.1), 0.5, method=micro.Cohort(dt=0.04))
    rows = []

    def run(variant: str) -> None:
        with Stopwatch() as sw:
            r = micro.stationary(model, V, method=options)
        row = dict(k0=args.k0, d=args.d, V=V, dt=args.dt, h_div=args.h_div, tol=args.tol, variant=variant,
                   amplitude=r.sigma_max - r.sigma_min, sigma_max=r.sigma_max, sigma_min=r.sigma_min,
                   period=r.period, converged=r.converged, message=r.message, wall_s=sw.seconds)
        if rows:
            row["amplitude_change"] = row["amplitude"] - rows[0]["amplitude"]
        rows.append(row)
        print(f"{variant:20s} amplitude {row['amplitude']:.7f} ({row.get('amplitude_change', 0.0):+.1e}), "
              f"sigma_max {r.sigma_max:.7f}, sigma_min {r.sigma_min:.7f}, period {r.period:.5f}; {sw.seconds:.1f} s",
              flush=True)

    run("baseline")
    for name, value in VARIANTS:
        with cohort_options.override(**{name: value}):
            run(f"{name} = {value:g}")
    x, w = np.polynomial.legendre.leggauss(4)
    with study_hooks.gauss_rule(0.5 * x + 0.5, 0.5 * w):
        run("Gauss-Legendre 4")
    write_csv(rows, RESULTS / "micro_cohort_other_choices.csv", keys=["k0", "d", "dt", "h_div", "variant"])


if __name__ == "__main__":
    main()
