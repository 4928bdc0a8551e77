"""The paper's Fig. 10 at all five k0: the steady branch and the stick-slip extrema against V.

Fig. 4 parameters, k0 = 0.3, 0.1, 0.01, 1e-3, 1e-4.  Steady rows come from the renewal
chain (exact to ~1e-11), stick-slip rows from the cohort method
(``micro.sweep(..., method="cohort")``, each row started from the previous row's
cycle, ``rtol = 1e-4`` so that the error of each cycle at its resolution is 1e-5; the
discretisation error at the default resolution, 2-4e-5, is measured by
benchmarks/micro_cohort_refinement.py).  V runs from 0.1 V^c to 0.95 V^c in the
stick-slip range (exact V^c from the renewal chain) and on to 3 V^c on the steady
branch.

Writes benchmarks/results/micro_fig10_cohort.csv and micro_fig10_cohort.png.

    python -m studies micro_fig10_cohort        # about 5 minutes on 2 cores
"""
from __future__ import annotations

import argparse
from pathlib import Path

import numpy as np
import pandas as pd

import micro

from benchmarks._harness import K0, RESULTS, Stopwatch, pyplot, save_figure, warm_up, write_csv

FRACTIONS = (0.1, 0.2, 0.3, 0.5, 0.7, 0.9, 0.95, 1.05, 1.5, 3.0)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--k0", default=",".join(str(k) for k in K0))
    ap.add_argument("--out", default=str(RESULTS / "micro_fig10_cohort.csv"))
    args = ap.parse_args()
    frames = []
    warm_up(micro.stationary, micro.Model(k0=0.1), 0.3, method=micro.Cohort(tol=1e-3, max_iter=6))
    for k0 in (float(v) for v in args.k0.split(",")):
        model = micro.Model(k0=k0)
        Vc = micro.critical_velocity(model).Vc
        sw = Stopwatch()
        # (the fixed point to 1e-5 in stress, what Convergence(rtol=1e-4) meant for the cohort
        # method before it had options of its own)
        frame = micro.sweep(model, [f * Vc for f in FRACTIONS], method=micro.Cohort(tol=1e-5))
        frame.insert(0, "Vc", Vc)
        frame.insert(1, "V_over_Vc", list(FRACTIONS))
        print(f"k0 = {k0:g}: {len(frame)} rows in {sw.seconds:.1f} s; slowest row "
              f"{frame.wall_time.max():.1f} s; all converged: {bool(frame.converged.all())}", flush=True)
        frames.append(frame)
    frame = write_csv(pd.concat(frames, ignore_index=True), args.out)
    with pd.option_context("display.width", 200, "display.max_columns", 12):
        print(frame[["k0", "V_over_Vc", "regime", "sigma_max", "sigma_min", "sigma_stderr", "converged",
                     "wall_time"]])
    plt = pyplot()
    fig, ax = plt.subplots(figsize=(6.5, 4.5))
    for (k0, grp), color in zip(frame.groupby("k0", sort=False), plt.cm.viridis(np.linspace(0, 0.9, len(frames)))):
        ss = grp[grp.regime == "stick-slip"]
        st = grp[grp.regime == "steady"]
        ax.plot(st.V_over_Vc, st.sigma_max, "-", color=color, label=f"k0 = {k0:g}")
        ax.plot(ss.V_over_Vc, ss.sigma_max, "^", color=color, ms=4)
        ax.plot(ss.V_over_Vc, ss.sigma_min, "v", color=color, ms=4)
    ax.set_xscale("log")
    ax.set_xlabel("V / V^c")
    ax.set_ylabel("stress: steady (lines), stick-slip max and min (triangles)")
    ax.legend(fontsize=8)
    fig.tight_layout()
    save_figure(fig, Path(args.out).with_suffix(".png"))


if __name__ == "__main__":
    main()
