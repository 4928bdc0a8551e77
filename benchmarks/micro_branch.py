"""The stick-slip branch's cost and errors point by point: ``micro.cycle_branch`` with its
defaults (from 0.2 V^c towards d_min = 1e-3), against issue 52's targets.

At each k0 of ``--k0``: one ``micro.cycle_branch(micro.Model(k0=k0))`` after a warm-up
(compilation not counted), one row per point: d, V, sigma_max, sigma_min, the amplitude,
the fixed-point and discretisation errors, whether it is certified, its wall time; the
branch's total wall time, how many points it has, where and why it ended, and the load
average.  The targets (2 idle cores): a 40-point branch at k0 = 0.1 from 0.2 V^c to
d = 1e-3 in 30 s or less, every point certified; a d = 0.01 point in 10 s or less.

Writes benchmarks/results/micro_branch.csv (rows merge by k0, d).

    python benchmarks/micro_branch.py               # k0 = 0.1: about 5 minutes
"""
from __future__ import annotations

import argparse
import os

import micro

from _harness import RESULTS, timed, warm_up, write_csv

CSV = RESULTS / "micro_branch.csv"


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--k0", default="0.1", help="comma-separated k0 values")
    ap.add_argument("--d-min", type=float, default=1e-3)
    args = ap.parse_args()
    warm_up(micro.stationary, micro.Model(k0=0.1), 0.3)
    rows = []
    for k0 in (float(v) for v in args.k0.split(",")):
        model = micro.Model(k0=k0)
        res, wall = timed(micro.cycle_branch, model, d_min=args.d_min)
        pts = res.points
        for _, p in pts.iterrows():
            rows.append(dict(k0=k0, d=p.d, V=p.V, sigma_max=p.sigma_max, sigma_min=p.sigma_min,
                             amplitude=p.amplitude, fixed_point_error=p.fixed_point_error,
                             discretisation_error=p.discretisation_error, certified=p.certified,
                             wall_s=p.wall_time, branch_wall_s=wall, branch_points=len(pts),
                             complete=res.complete, reason=res.reason, load=os.getloadavg()[0]))
        print(f"k0 = {k0:g}: {len(pts)} points in {wall:.1f} s to d = {pts.d.iloc[-1]:.3g} "
              f"({'complete' if res.complete else 'ended early'}: {res.reason})", flush=True)
    write_csv(rows, CSV, keys=["k0", "d"])


if __name__ == "__main__":
    main()
