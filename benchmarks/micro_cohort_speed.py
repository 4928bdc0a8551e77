"""Run time and error of one stick-slip point by the cohort method, at every k0 of the paper.

Fig. 4 parameters, k0 = 0.3, 0.1, 0.01, 1e-3, 1e-4, V / V^c = 0.1 ... 0.95 (exact V^c
from the renewal chain).  Each point is a cold start (``micro.cohort.cycle_cohorts`` at
its default resolution, dt = 0.01, h = kappa zbar / 20) at the tolerance ``--tol``; with
``--reference`` it is also run at ``--ref-tol`` to score the error estimate against the
true distance to the fixed point.  Compilation is done first and not counted.

Writes benchmarks/results/micro_cohort_speed.csv (rows merge by k0, V / V^c, tol, so an
interrupted run keeps its rows).

    python benchmarks/micro_cohort_speed.py                 # about 3 minutes on 2 cores
    python benchmarks/micro_cohort_speed.py --reference     # and the references: ~30 minutes
"""
from __future__ import annotations

import argparse
import os
from pathlib import Path

import numba
import pandas as pd

import micro
from micro.cohort import cycle_cohorts

from _harness import K0, RESULTS, Stopwatch, warm_up, write_csv

FRACTIONS = (0.1, 0.3, 0.5, 0.7, 0.9, 0.95)
QUANTITIES = ("sigma_max", "sigma_min", "sigma_before", "sigma_after")


def run(model: micro.Model, V: float, tol: float) -> dict:
    sw = Stopwatch()
    res = cycle_cohorts(model, V, tol=tol)
    row = {name: getattr(res, name) for name in QUANTITIES}
    row.update(error=res.error, cycles=res.iterations, unjumped=res.unjumped, period=res.period,
               converged=res.converged, wall_s=sw.seconds, message=res.message)
    return row


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--k0", default=",".join(str(k) for k in K0))
    ap.add_argument("--fractions", default=",".join(str(f) for f in FRACTIONS))
    ap.add_argument("--tol", type=float, default=2e-5)
    ap.add_argument("--reference", action="store_true", help="also run each point at --ref-tol")
    ap.add_argument("--ref-tol", type=float, default=1e-7)
    ap.add_argument("--out", default=str(RESULTS / "micro_cohort_speed.csv"))
    args = ap.parse_args()
    out = Path(args.out)
    warm_up(cycle_cohorts, micro.Model(k0=0.1), 0.3, tol=1e-3, max_iter=6,
            label="compilation (or loading numba's cache) and a first cycle")
    print(f"{numba.get_num_threads()} threads, load average {os.getloadavg()[0]:.2f}", flush=True)
    for k0 in (float(v) for v in args.k0.split(",")):
        model = micro.Model(k0=k0)
        Vc = micro.critical_velocity(model).Vc
        for frac in (float(v) for v in args.fractions.split(",")):
            row = dict(k0=k0, Vc=Vc, V_over_Vc=frac, V=frac * Vc, tol=args.tol, threads=numba.get_num_threads(),
                       **run(model, frac * Vc, args.tol))
            if args.reference:
                ref = run(model, frac * Vc, args.ref_tol)
                row.update({f"ref_{name}": ref[name] for name in QUANTITIES})
                row.update(ref_error=ref["error"], ref_converged=ref["converged"], ref_wall_s=ref["wall_s"])
                row["true_error"] = max(abs(row[name] - ref[name]) for name in QUANTITIES)
            print(f"k0 = {k0:g}, {frac:g} V^c: sigma_max {row['sigma_max']:.6f} sigma_min {row['sigma_min']:.6f} "
                  f"(before/after the shock {row['sigma_before']:.6f} / {row['sigma_after']:.6f}), error "
                  f"{row['error']:.1e}" + (f" (true {row['true_error']:.1e})" if args.reference else "") +
                  f", {row['cycles']} cycles, {row['wall_s']:.1f} s, converged {row['converged']}", flush=True)
            write_csv(pd.DataFrame([row]), out, keys=["k0", "V_over_Vc", "tol"])


if __name__ == "__main__":
    main()
