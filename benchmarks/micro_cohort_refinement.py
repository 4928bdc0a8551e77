"""Refinement study of the cohort method (``micro.cohort``), run time against error.

Points: Fig. 4 parameters, k0 = 0.3, 0.1, 1e-2, 1e-3 and 1e-4 (the five of the paper's
Fig. 10), V = 0.3 V^c (``--fraction`` sets V / V^c).  The two refinement
variables, the time step dt and the delta_R cell h, are halved together from
(0.02, 0.01) to (0.005, 0.0025); each level starts from the previous level's fixed point
and is converged to tol = 1e-6 (``--tol``; Aitken's extrapolation of the cycles).  The order p
and the limit come from the three levels (sigma(l) = sigma_0 + C 2^(-p l)); sigma_min
has an exact limit, f_th - kappa zbar, where shocks are total (k0 <= 0.01): the check of
the procedure.  sigma_max is the largest stress of the cycle, sigma_before and
sigma_after the stress when the shock starts and right after it.  Each row's
"distance" is its distance from the extrapolated limit: the error that its run time
bought.

Writes benchmarks/results/micro_cohort_refinement.csv after each level (a point's rows
replace its old ones, so a run with ``--k0 0.3 --fraction 0.5`` alone adds those rows,
and an interrupted run keeps the levels it finished).

    python benchmarks/micro_cohort_refinement.py        # about 20 minutes on 1 core
"""
from __future__ import annotations

import argparse
import math
from pathlib import Path

import numpy as np
import pandas as pd

import micro
from micro.cohort import cycle_cohorts

from _harness import RESULTS, timed, warm_up, write_csv

LEVELS = ((0.02, 0.01), (0.01, 0.005), (0.005, 0.0025))


def order_and_limit(s: np.ndarray) -> tuple[float, float]:
    """From three levels each halving the steps: the order and the Richardson limit."""
    d1, d2 = s[0] - s[1], s[1] - s[2]
    if d2 == 0.0 or d1 / d2 <= 0.0:
        return math.nan, float(s[2])
    p = math.log2(d1 / d2)
    return p, float(s[2] - d2 / (2.0**p - 1.0))


def save(rows: list[dict], out: Path) -> None:
    """Merge ``rows`` into the CSV at ``out`` (a point's rows, by k0 and V / V^c, replace
    all its old rows, so that a run stopped after one level does not leave it beside
    levels of an older run) and give every point with all three levels its order, limit
    and distances (NaN while it has fewer)."""
    frame = pd.DataFrame(rows)
    old = pd.read_csv(out) if out.exists() else None
    if old is not None and set(frame.columns) <= set(old.columns):  # (rows of an older layout are dropped)
        old = old[list(frame.columns)]
        key = ["k0", "V_over_Vc"]
        old = old[~old.set_index(key).index.isin(frame.set_index(key).index)]
        frame = pd.concat([old, frame], ignore_index=True).sort_values(["k0", "V_over_Vc", "dt"],
                                                                      ascending=[False, True, False])
        frame = frame.reset_index(drop=True)
    for _, grp in frame.groupby(["k0", "V_over_Vc"], sort=False):
        for col in ("sigma_max", "sigma_min", "sigma_before", "sigma_after"):
            p, lim = order_and_limit(grp[col].to_numpy()) if len(grp) == len(LEVELS) else (math.nan, math.nan)
            frame.loc[grp.index, f"{col}_order"] = p
            frame.loc[grp.index, f"{col}_limit"] = lim
            frame.loc[grp.index, f"{col}_distance"] = (grp[col] - lim).abs()
    write_csv(frame, out)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--k0", default="0.3,0.1,0.01,0.001,0.0001")
    ap.add_argument("--fraction", type=float, default=0.3, help="V / V^c")
    ap.add_argument("--tol", type=float, default=1e-6, help="each level's fixed point to this")
    ap.add_argument("--out", default=str(RESULTS / "micro_cohort_refinement.csv"))
    args = ap.parse_args()
    rows = []
    warm_up(cycle_cohorts, micro.Model(k0=0.01), 2.4, dt=0.05, h=0.02, tol=1e-2, max_iter=4)
    for k0 in (float(v) for v in args.k0.split(",")):
        model = micro.Model(k0=k0)
        V = args.fraction * micro.critical_velocity(model).Vc
        start = None
        for dt, h in LEVELS:
            res, wall = timed(cycle_cohorts, model, V, dt=dt, h=h, tol=args.tol, start=start)
            start = res
            rows.append(dict(k0=k0, V_over_Vc=args.fraction, V=V, dt=dt, h=h, sigma_max=res.sigma_max,
                             sigma_min=res.sigma_min, sigma_before=res.sigma_before, sigma_after=res.sigma_after,
                             exact_sigma_min=micro.sigma_fast_limit(model), period=res.period, error=res.error,
                             cycles=res.iterations, converged=res.converged, wall_s=wall))
            print(rows[-1], flush=True)
            save(rows, Path(args.out))  # (after each level: an interrupted run keeps its rows)
    with pd.option_context("display.width", 200, "display.max_columns", 30):
        print(pd.read_csv(args.out))


if __name__ == "__main__":
    main()
