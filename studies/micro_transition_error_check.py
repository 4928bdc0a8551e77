"""Does the default cohort row's error bound cover its true error close to V^c?
(issue 36, item 1: the transition's points need an error bar covering every
discretisation choice, not only the fixed point's).

At each k0 of ``--k0`` and d = (V^c - V) / V^c of ``--d`` (exact V^c), the default row
``micro.stationary(model, V, method=micro.Cohort(dt=--dt, tol=--tol))`` is computed
(its own run at twice the step and cell included), then the same cycle at ``--levels``
finer levels, the step and the cell halved together at each (each level continued from
the one before, so every level is micro's own path).  The bound the default row would
report is the change of sigma_max and sigma_min from the coarse level plus both fixed
points' errors (``CycleFixedPoint.discretisation_bound``, what ``micro.api`` reports).  The reference is the Richardson limit of the
two finest levels, with the order measured from the last three levels (kept in
[1, 3]); the default row's true error is its distance from that limit, in sigma_max,
sigma_min and the amplitude.  A level whose fixed point is not certified (error NaN)
is kept, and no limit is drawn through it.

Writes benchmarks/results/micro_transition_error_check.csv (one row per point and level;
rows merge by k0, d, dt) and the figure micro_transition_error_check.png: the amplitude
against d on log-log axes, each k0's default rows with their bars (twice the bound: both
extrema) and the Richardson limits, the N-block at each N of
``micro_transition_nblock_check.csv`` where it exists (k0 = 0.1); and each error over the
amplitude.  ``--plot`` redraws the figure from the CSVs alone.

    python -m studies micro_transition_error_check --k0 0.01 --d 0.2,0.1,0.05,0.02,0.01   # about 1 h of CPU
    python -m studies micro_transition_error_check --plot
"""
from __future__ import annotations

import argparse
import math

import numpy as np
import pandas as pd

import micro
from micro.cohort import cycle_cohorts

from benchmarks._harness import RESULTS, Stopwatch, pyplot, save_figure, warm_up, write_csv
from studies.micro_transition_nblock_check import pooled, separated

CSV = RESULTS / "micro_transition_error_check.csv"
NBLOCK_CSV = RESULTS / "micro_transition_nblock_check.csv"


def _row(k0, d, V, vc, level, dt, h, res, cpu):
    return dict(k0=k0, d=d, V=V, Vc=vc, level=level, dt=dt, h=h, sigma_max=res.sigma_max,
                sigma_min=res.sigma_min, amplitude=res.sigma_max - res.sigma_min, period=res.period,
                error=res.error, certified=bool(res.converged and math.isfinite(res.error)),
                unjumped=res.unjumped, cycles=res.iterations, cpu_s=round(cpu, 1))


def check(frame: pd.DataFrame) -> dict:
    """The default row's bound against its distance from the Richardson limit."""
    f = frame.sort_values("level")
    d0 = f[f.level == 0].iloc[0]
    out = dict(bound=d0.bound)
    if not f.certified.all() or len(f) < 3:
        return {**out, "order": math.nan, "limit_amplitude": math.nan, "true_sigma_max": math.nan,
                "true_sigma_min": math.nan, "true_amplitude": math.nan, "true_over_bound": math.nan}
    a = f.amplitude.to_numpy()
    x = f.sigma_max.to_numpy()
    y = f.sigma_min.to_numpy()
    # the order from the last three levels (the largest of the three quantities' orders that is
    # defined: a quantity whose changes have the same sign)
    orders = []
    for q in (x, y, a):
        d1, d2 = q[-3] - q[-2], q[-2] - q[-1]
        if d1 * d2 > 0:
            orders.append(math.log2(d1 / d2))
    p = float(np.clip(np.median(orders), 1.0, 3.0)) if orders else 1.0

    def limit(q):
        return q[-1] + (q[-1] - q[-2]) / (2 ** p - 1)

    lx, ly, la = limit(x), limit(y), limit(a)
    tx, ty = abs(d0.sigma_max - lx), abs(d0.sigma_min - ly)
    return {**out, "order": p, "limit_amplitude": la, "true_sigma_max": tx, "true_sigma_min": ty,
            "true_amplitude": abs(d0.amplitude - la), "true_over_bound": max(tx, ty) / out["bound"]}


def plot() -> None:
    """The figure, from the CSVs."""
    f = pd.read_csv(CSV)
    nb = pd.read_csv(NBLOCK_CSV) if NBLOCK_CSV.exists() else pd.DataFrame()
    plt = pyplot()
    fig, (ax, ax2) = plt.subplots(1, 2, figsize=(11, 4.4))
    colour = {k0: f"C{i}" for i, k0 in enumerate(sorted(f.k0.unique()))}
    for k0, g in f.groupby("k0"):
        c = colour[k0]
        row = g[g.level == 0].sort_values("d")
        ok = row.certified.astype(bool)
        ax.errorbar(row.d[ok], row.amplitude[ok], yerr=2 * row.bound[ok], fmt="o", color=c, ms=4, capsize=2,
                    label=f"k0 = {k0:g}: default row (dt = {row.dt.iloc[0]:g}), bar = 2 x its bound")
        ax.plot(row.d[~ok], row.amplitude[~ok], "o", mfc="none", color=c, ms=5)
        lim = row[np.isfinite(row.limit_amplitude)]
        ax.plot(lim.d, lim.limit_amplitude, "x", color=c, ms=7)
        ax2.plot(lim.d, lim.bound / lim.amplitude, "o-", color=c, label=f"k0 = {k0:g}: bound / A")
        ax2.plot(lim.d, np.maximum(lim.true_sigma_max, lim.true_sigma_min) / lim.amplitude, "x--", color=c,
                 label=f"k0 = {k0:g}: true error / A")
    nb = nb[nb.k0.isin(list(colour)) & separated(nb) & (nb.status == "ok")] if len(nb) else nb
    sizes = {N: 3 + j for j, N in enumerate(sorted(nb.N.unique()))} if len(nb) else {}
    for (k0, N), g in (nb.groupby(["k0", "N"]) if len(nb) else []):
        p = pooled(g, "amplitude", "d")  # (each (k0, N): the seeds pooled; squares grow with N)
        ax.errorbar(p.index, p.value, yerr=p.stderr, fmt="s", mfc="none", ms=sizes[N], color=colour[k0], alpha=0.6,
                    lw=0.8)
    if len(nb):
        ax.plot([], [], "s", mfc="none", color="k", label="N-block (seeds pooled; shocks separated), larger: larger N "
                f"({', '.join(f'{N:.0e}' for N in sizes)})")
    ax.plot([], [], "x", color="k", label="Richardson limit of two finer levels")
    ax.plot([], [], "o", mfc="none", color="k", label="fixed point not certified")
    for a in (ax, ax2):
        a.set_xscale("log")
        a.set_yscale("log")
        a.set_xlabel("d = (V^c - V) / V^c")
    ax.set_ylabel("amplitude sigma_max - sigma_min")
    ax2.set_ylabel("error / amplitude")
    ax.set_ylim(top=0.2)  # room for the legend above the points
    ax.legend(fontsize=6.5, loc="upper left")
    ax2.legend(fontsize=6.5)
    ax.set_title("the cohort method near V^c, checked (default rows, finer levels, N-block)", fontsize=9)
    ax2.set_title("the default row's bound against its true error", fontsize=9)
    fig.tight_layout()
    save_figure(fig, RESULTS / "micro_transition_error_check.png")


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--k0", default="0.3,0.1,0.01,0.001")
    ap.add_argument("--d", default="0.2,0.1,0.05,0.02,0.01")
    ap.add_argument("--dt", type=float, default=0.02, help="the default row's step (the report's cycle_dt)")
    ap.add_argument("--tol", type=float, default=1e-4, help="the fixed points' tolerance (the report's)")
    ap.add_argument("--levels", type=int, default=2, help="finer levels (dt and h halved at each)")
    ap.add_argument("--plot", action="store_true", help="only redraw the figure from the CSVs")
    args = ap.parse_args()
    if args.plot:
        plot()
        return
    warm_up(micro.stationary, micro.Model(k0=0.05), 0.77, method=micro.Cohort(dt=0.04))
    for k0 in [float(v) for v in args.k0.split(",")]:
        model = micro.Model(k0=k0)
        vc = float(micro.critical_velocity(model).Vc)
        for d in [float(v) for v in args.d.split(",")]:
            V = (1.0 - d) * vc
            cpu = Stopwatch(cpu=True)
            row = micro.stationary(model, V, method=micro.Cohort(dt=args.dt, tol=args.tol), warn=False)
            res = row.cycle
            rows = []
            if res is None or res.coarse is None:
                print(f"k0 = {k0:g}, d = {d:g}: {row.method}, no coarse run ({row.message})", flush=True)
                continue
            h = res.eps
            rows.append(_row(k0, d, V, vc, -1, 2 * args.dt, 2 * h, res.coarse, math.nan))
            rows.append(_row(k0, d, V, vc, 0, args.dt, h, res, cpu.seconds))
            prev = res
            for lev in range(1, args.levels + 1):
                cpu = Stopwatch(cpu=True)
                dt_l, h_l = args.dt / 2 ** lev, h / 2 ** lev
                prev = cycle_cohorts(model, V, dt=dt_l, h=h_l, tol=args.tol, start=prev, max_iter=300)
                rows.append(_row(k0, d, V, vc, lev, dt_l, h_l, prev, cpu.seconds))
                print(f"  k0 = {k0:g}, d = {d:g}, level {lev}: sigma_max {prev.sigma_max:.7f} "
                      f"error {prev.error:.1e} cpu {cpu.seconds:.0f} s", flush=True)
            f = pd.DataFrame(rows).assign(bound=res.discretisation_bound)
            chk = check(f)
            for key, value in chk.items():
                f[key] = value
            f["dt_default"] = args.dt
            print(f"k0 = {k0:g}, d = {d:g}: amplitude {row.sigma_max - row.sigma_min:.6f}, bound {chk['bound']:.1e}, "
                  f"true {max(chk['true_sigma_max'], chk['true_sigma_min']):.1e}, order {chk['order']:.2f}", flush=True)
            write_csv(f, CSV, keys=["k0", "d", "dt_default", "level"])
    plot()


if __name__ == "__main__":
    main()
