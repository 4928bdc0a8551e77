"""Run time against error: the cohort method against the Fokker-Planck solvers and the N-block.

Reads the results of other benchmarks (no new runs) and plots wall time against the
error of sigma_max and sigma_min (the larger of the two), log-log:

* k0 = 0.01, V = 1 (about V^c / 8): the reference is the N-block at N = 1e6
  (benchmarks/results/micro_fp_vs_nblock_stickslip.csv, which also holds the Fokker-Planck
  time-stepping at eps = 0.024 ... 0.006 and the N-block at N = 1e3 ... 1e6); the cohort
  rows are benchmarks/micro_cohort_refinement.py --k0 0.01 --fraction 0.12482899.
* k0 = 1e-3 and 0.01, V = 0.3 V^c: the reference is the cohorts' Richardson limit for
  sigma_max and the exact f_th - kappa zbar for sigma_min; Fokker-Planck rows (the
  shock-to-shock map and time-stepping) from benchmarks/results/micro_cycle_speed.csv.

Writes benchmarks/results/micro_cohort_vs_fp.csv and micro_cohort_vs_fp.png.

    python benchmarks/micro_cohort_vs_fp.py
"""
from __future__ import annotations

import pandas as pd

from _harness import RESULTS, pyplot, save_figure, write_csv


def main() -> None:
    rows = []
    # k0 = 0.01, V = 1: against the N-block at N = 1e6
    speed = pd.read_csv(RESULTS / "micro_fp_vs_nblock_stickslip.csv")
    ref = speed[(speed.solver == "nblock") & (speed.resolution == speed[speed.solver == "nblock"].resolution.max())]
    ref_max, ref_min = float(ref.sigma_max.iloc[0]), float(ref.sigma_min.iloc[0])
    for _, r in speed[speed.solver.isin(["fp", "nblock"])].iterrows():
        if r.solver == "nblock" and r.resolution == ref.resolution.iloc[0]:
            continue
        rows.append(dict(point="k0=0.01, V=1", method="time-stepping (FP)" if r.solver == "fp" else "N-block",
                         resolution=r.resolution, wall_s=r.wall_s,
                         error=max(abs(r.sigma_max - ref_max), abs(r.sigma_min - ref_min))))
    coh = pd.read_csv(RESULTS / "micro_cohort_refinement.csv")
    for _, r in coh[(coh.k0 == 0.01) & (coh.V_over_Vc.round(6) == 0.124829)].iterrows():
        rows.append(dict(point="k0=0.01, V=1", method="cohorts", resolution=r.h, wall_s=r.wall_s,
                         error=max(abs(r.sigma_max - ref_max), abs(r.sigma_min - ref_min))))
    # V = 0.3 V^c: against the cohorts' limit (sigma_max) and the exact sigma_min
    cycle = pd.read_csv(RESULTS / "micro_cycle_speed.csv")
    for k0 in (0.01, 0.001):
        c = coh[(coh.k0 == k0) & (coh.V_over_Vc == 0.3)]
        lim = float(c.sigma_max_limit.iloc[0])
        point = f"k0={k0:g}, V=0.3 Vc"
        for _, r in c.iterrows():
            rows.append(dict(point=point, method="cohorts", resolution=r.h, wall_s=r.wall_s,
                             error=max(abs(r.sigma_max - lim), abs(r.sigma_min - r.exact_sigma_min))))
        for _, r in cycle[(cycle.k0 == k0) & cycle.converged].iterrows():
            rows.append(dict(point=point, method="shock-to-shock map (FP)" if r.method == "cycle" else "time-stepping (FP)",
                             resolution=r.eps, wall_s=r.wall_s,
                             error=max(abs(r.sigma_max - lim), abs(r.sigma_min - r.sigma_min_exact))))
    frame = write_csv(pd.DataFrame(rows), RESULTS / "micro_cohort_vs_fp.csv")
    print(frame.to_string())
    points = list(dict.fromkeys(frame.point))
    plt = pyplot()
    fig, axes = plt.subplots(1, len(points), figsize=(4.2 * len(points), 3.8), sharey=True)
    markers = {"cohorts": "o-", "time-stepping (FP)": "s-", "shock-to-shock map (FP)": "^-", "N-block": "d-"}
    for ax, point in zip(axes, points):
        for method, grp in frame[frame.point == point].groupby("method"):
            grp = grp.sort_values("wall_s")
            ax.loglog(grp.wall_s, grp.error, markers[method], label=method, ms=5)
        ax.set_title(point, fontsize=9)
        ax.set_xlabel("wall time (s)")
        ax.axhline(1e-4, color="0.7", lw=0.8)
    axes[0].set_ylabel("error of sigma_max, sigma_min")
    axes[0].legend(fontsize=7)
    fig.tight_layout()
    save_figure(fig, RESULTS / "micro_cohort_vs_fp.png")


if __name__ == "__main__":
    main()
