"""The cohort method's cell error close to V^c, now that its fixed points are certified
there (issue 36, item 1: does a transition point's error bar cover the cell?).

At k0 = ``--k0`` and each d = (V^c - V) / V^c of ``--d``, micro's default path
(``micro.stationary`` with ``micro.Cohort(dt=--dt, h=kappa zbar / h_div)``: the coarse run,
Anderson, Newton-Krylov where the frozen map grows) at the default cell kappa zbar / 20
and at kappa zbar / 40.  The change of sigma_max, sigma_min and the amplitude from /20 to
/40 times 4/3 (second order in the cell, measured at k0 = 0.01, d = 0.1 in
docs/validation/micro_cohort.md section 5) estimates the default cell's error; a row whose
fixed point is not certified (error NaN) is kept and says so.  Writes
benchmarks/results/micro_cohort_cell_near_vc.csv (rows merge by k0, d, dt, h_div).

    python -m studies micro_cohort_cell_near_vc --k0 0.01 --d 0.2,0.1,0.05,0.02   # about 10 min of CPU
"""
from __future__ import annotations

import argparse

import pandas as pd

import micro
from benchmarks._harness import RESULTS, Stopwatch, warm_up, write_csv

CSV = RESULTS / "micro_cohort_cell_near_vc.csv"


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--k0", type=float, default=0.01)
    ap.add_argument("--d", default="0.2,0.1,0.05,0.02")
    ap.add_argument("--dt", type=float, default=0.02)
    ap.add_argument("--h-div", default="20,40")
    args = ap.parse_args()
    model = micro.Model(k0=args.k0)
    vc = float(micro.critical_velocity(model).Vc)
    warm_up(micro.stationary, micro.Model(k0=0.05), 0.77, method=micro.Cohort(dt=0.04))
    for d in [float(x) for x in args.d.split(",")]:
        V = (1.0 - d) * vc
        for h_div in [float(x) for x in args.h_div.split(",")]:
            cpu = Stopwatch(cpu=True)
            res = micro.stationary(model, V, method=micro.Cohort(dt=args.dt, h=model.kappa * model.zbar / h_div),
                                   warn=False)
            row = dict(k0=args.k0, d=d, V=V, Vc=vc, dt=args.dt, h_div=h_div, method=res.method,
                       sigma_max=res.sigma_max, sigma_min=res.sigma_min, amplitude=res.sigma_max - res.sigma_min,
                       period=res.period, error=res.sigma_stderr, converged=res.converged,
                       cycles=res.n_cycles, cpu_s=round(cpu.seconds, 1), message=res.message)
            print({k: row[k] for k in ("d", "h_div", "sigma_max", "sigma_min", "error", "cycles", "cpu_s")}, flush=True)
            write_csv(pd.DataFrame([row]), CSV, keys=["k0", "d", "dt", "h_div"])


if __name__ == "__main__":
    main()
