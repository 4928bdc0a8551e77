"""The cost of the report's cohort cycles close to V^c, where the frozen-slip map grows and
the fixed point is certified by Newton-Krylov (docs/validation/micro_cohort.md section 5,
"A cheaper certification").

At each k0 of ``--k0`` and ``--fraction`` V^c (exact V^c), one cold
``micro.cohort.cycle_cohorts(model, V, dt=--dt, tol=--tol)`` (its coarse run included),
as the report solves its 0.85 V^c points: the wall time, the cycles, whether the run was
accelerated, sigma_max, sigma_min and the fixed-point error, and the head of the message
(which path certified it).  Compilation is done first and not counted.  Load average in
each row.

Writes benchmarks/results/micro_cohort_near_vc_cost.csv (rows merge by k0, fraction, dt, tol).

    python benchmarks/micro_cohort_near_vc_cost.py      # about 20 s
"""
from __future__ import annotations

import argparse
import os

import micro
from micro.cohort import cycle_cohorts

from _harness import RESULTS, timed, warm_up, write_csv

CSV = RESULTS / "micro_cohort_near_vc_cost.csv"


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--k0", default="0.01,0.001,0.0001")
    ap.add_argument("--fraction", type=float, default=0.85, help="V / V^c")
    ap.add_argument("--dt", type=float, default=0.02)
    ap.add_argument("--tol", type=float, default=1e-4)
    args = ap.parse_args()
    warm_up(cycle_cohorts, micro.Model(k0=0.1), 0.3, tol=1e-3, max_iter=6)
    rows = []
    for k0 in (float(v) for v in args.k0.split(",")):
        model = micro.Model(k0=k0)
        V = args.fraction * micro.critical_velocity(model).Vc
        res, wall = timed(cycle_cohorts, model, V, dt=args.dt, tol=args.tol)
        rows.append(dict(k0=k0, fraction=args.fraction, V=V, dt=args.dt, tol=args.tol, wall_s=wall,
                         cycles=res.iterations, accelerated=res.accelerated, converged=res.converged,
                         sigma_max=res.sigma_max, sigma_min=res.sigma_min, error=res.error,
                         path=res.message.split(":")[0], load=os.getloadavg()[0]))
        r = rows[-1]
        print(f"k0 = {k0:g}, {args.fraction:g} V^c: {wall:.1f} s, {r['cycles']} cycles, sigma_max "
              f"{r['sigma_max']:.10f} +- {r['error']:.1e} ({r['path']})", flush=True)
    write_csv(rows, CSV, keys=["k0", "fraction", "dt", "tol"])


if __name__ == "__main__":
    main()
