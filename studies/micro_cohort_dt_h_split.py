"""The cohort method's two discretisation variables apart: the time step ``dt`` at the
default cell, and the cell ``h`` at dt = 0.02, at stick-slip points from 0.15 to 0.9 V^c.

Question: which of the two sets the error of a cycle's extrema, and what each costs; so
what time step the report's cycles need (``compare.Settings.cycle_dt``).  Each row is one
call of ``micro.stationary`` (its own coarse run at 2 dt, 2 h included) to micro's default
fixed-point tolerance; ``cpu_s`` is its CPU time (both cores' worth when numba's threads
run; compare rows of one point, not absolute numbers, under load).

Run: ``python -m studies micro_cohort_dt_h_split`` (about 6 minutes on 2 cores);
writes benchmarks/results/micro_cohort_dt_h_split.csv.  Recorded in
docs/validation/micro_defaults.md, "The report's time step".
"""
from __future__ import annotations

import argparse

import micro
import pandas as pd
from benchmarks._harness import RESULTS, Stopwatch, warm_up, write_csv

#: (k0, V / V^c) of the points, and the (dt, kappa zbar / h) of the runs at each.
POINTS = ((0.3, 0.15), (0.1, 0.4), (0.01, 0.4), (0.001, 0.4), (0.1, 0.8), (0.01, 0.9))
RUNS = ((0.04, 20), (0.02, 20), (0.01, 20), (0.02, 10), (0.02, 40), (0.02, 80))


def main() -> None:
    argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter).parse_args()  # no options: --help only
    warm_up(lambda: micro.stationary(micro.Model(k0=0.1), 0.3, method=micro.Cohort(dt=0.02, tol=1e-3)))
    rows = []
    for k0, ratio in POINTS:
        model = micro.Model(k0=k0)
        Vc = micro.critical_velocity(model).Vc
        for dt, h_div in RUNS:
            with Stopwatch(cpu=True) as sw:
                r = micro.stationary(model, ratio * Vc, method=micro.Cohort(dt=dt, h=model.kappa * model.zbar / h_div))
            rows.append(dict(k0=k0, V_over_Vc=ratio, V=ratio * Vc, dt=dt, h_div=h_div, sigma_max=r.sigma_max,
                             sigma_min=r.sigma_min, period=r.period, fixed_point_error=r.sigma_stderr,
                             discretisation_error=r.discretisation_error, cpu_s=sw.seconds))
            print(rows[-1], flush=True)
            write_csv(pd.DataFrame(rows), RESULTS / "micro_cohort_dt_h_split.csv")


if __name__ == "__main__":
    main()
