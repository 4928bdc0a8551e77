"""The cohort method's error estimate against the true distance to its fixed point.

For each point (Fig. 4 parameters, k0 and V / V^c), ``micro.cohort.cycle_cohorts`` is run
at the resolution ``--dt``, ``--h`` (default twice the default steps and cells, where a
cycle costs an eighth) to the tolerance ``--tol``, from the first shock's image.  The
state it returns is then continued by ``--continue`` plain cycles at the same step:
the last of them is the fixed point at that resolution (its own uncertainty is how far
the last 50 cycles still moved), and the distance of the returned sigma_max and
sigma_min from it is the true error that the claimed ``error`` estimates.

Writes benchmarks/results/micro_cohort_estimate_check.csv (rows merge by k0, V / V^c,
dt, h and tol).

    python -m studies micro_cohort_estimate_check          # about 7 minutes on 2 cores
"""
from __future__ import annotations

import argparse
from pathlib import Path

import numpy as np
import pandas as pd

import micro
# the check starts cycle_cohorts without its coarse first run (NO_COARSE) and continues
# the state it returns (res.state) by single plain cycles (one_cycle): hooks for studies
from micro import cohort as C
from micro import study_hooks as H

from benchmarks._harness import RESULTS, Stopwatch, warm_up, write_csv

POINTS = "0.0001:0.95,0.001:0.95,0.01:0.95,0.1:0.95,0.3:0.95,0.001:0.9,0.01:0.9,0.1:0.9"


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--points", default=POINTS, help="k0:V/V^c, comma separated")
    ap.add_argument("--dt", type=float, default=0.02)
    ap.add_argument("--h", type=float, default=None, help="default kappa zbar / 10")
    ap.add_argument("--tol", type=float, default=5e-5)
    ap.add_argument("--continue", dest="more", type=int, default=400, help="plain cycles after the result")
    ap.add_argument("--out", default=str(RESULTS / "micro_cohort_estimate_check.csv"))
    args = ap.parse_args()
    out = Path(args.out)
    warm_up(C.cycle_cohorts, micro.Model(k0=0.1), 0.3, tol=1e-3, max_iter=6)
    for point in args.points.split(","):
        k0, frac = (float(v) for v in point.split(":"))
        model = micro.Model(k0=k0)
        h = model.kappa * model.zbar / 10.0 if args.h is None else args.h
        V = frac * micro.critical_velocity(model).Vc
        res = C.cycle_cohorts(model, V, dt=args.dt, h=h, tol=args.tol, max_iter=2000, start=H.NO_COARSE)
        st, sw = res.state, Stopwatch()
        seq = np.array([[o["sigma_max"], o["sigma_min"]] for o in (H.one_cycle(st, st.dt) for _ in range(args.more))])
        true = np.abs(np.array([res.sigma_max, res.sigma_min]) - seq[-1])
        row = dict(k0=k0, V_over_Vc=frac, dt=args.dt, h=h, tol=args.tol, sigma_max=res.sigma_max,
                   sigma_min=res.sigma_min, claimed=res.error, converged=res.converged, cycles=res.iterations,
                   wall_s=res.wall_time, fixed_sigma_max=seq[-1, 0], fixed_sigma_min=seq[-1, 1],
                   fixed_moved_last_50=float(np.abs(seq[-1] - seq[-51]).max()), true_sigma_max=true[0],
                   true_sigma_min=true[1], true_over_claimed=float(true.max() / res.error),
                   continued_s=sw.seconds, message=res.message)
        print(f"k0 = {k0:g}, {frac:g} V^c: claimed {res.error:.1e}, true {true.max():.1e} (sigma_max "
              f"{true[0]:.1e}, sigma_min {true[1]:.1e}); {res.iterations} cycles, {res.wall_time:.1f} s", flush=True)
        write_csv(pd.DataFrame([row]), out, keys=["k0", "V_over_Vc", "dt", "h", "tol"])


if __name__ == "__main__":
    main()
