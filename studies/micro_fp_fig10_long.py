"""The Fokker-Planck stress at V = 1.5 V^c against its bin, from long runs (the paper's Fig. 10
as the report drew it, checked).

The report's Fig. 10 (``python -m compare --paper``) stops each run by the FP's steady rule
(three span means within 1 % of the velocity weakening plus the jitter, about 2.5e-4 at
k0 = 0.3 and 9e-5 at 0.1) or at t = 120, and plots sigma_FP - sigma_exact.  This script
runs the same (k0, V, eps) for ``--duration`` time units from the frozen start with
``micro.simulate`` (no stopping rule) and takes the solver's own time means
(``Records.time_mean``, exact between records) over fixed windows.  (Averaging the sampled
stress instead, by the trapezoid rule, is biased low by up to 2.5e-4 at k0 = 0.3, where the
grid's jitter is 4-8e-3 peak to peak: an earlier version did, and was wrong.)  The FP's stationary stress at a bin is the mean over the later windows
(t >= ``--settle``), and its uncertainty the spread of those windows' means (half their
range): the runs wander by about that much over hundreds of time units, settled or not.

Reference: the exact steady stress of the renewal chain (``micro.steady_sliding``).
V^c from ``micro.critical_velocity`` (the chain's), as in the report.

Writes ``benchmarks/results/micro_fp_fig10_long.csv`` (one row per (k0, eps, window) and one
``window = "late"`` row per run with the late mean, its half range and the error) and
``docs/figures/micro_fp_fig10_long.png``.  About
5 minutes on one core.

    python -m studies micro_fp_fig10_long
    python -m studies micro_fp_fig10_long --k0 0.1 --eps 0.025 --duration 240
    python -m studies micro_fp_fig10_long --plot-only
    python -m studies micro_fp_fig10_long --check-report 60,120   # the report's runs against these
"""
from __future__ import annotations

import argparse
from dataclasses import replace

import numpy as np
import pandas as pd

import compare
import micro
from micro.analysis import Records
from benchmarks._harness import FIGURES, RESULTS, Stopwatch, pyplot, save_figure, warm_up, write_csv

WINDOWS = ((0, 30), (30, 60), (60, 120), (120, 240), (240, 360), (360, 480))


def window_means(run: micro.results.Run, windows) -> list[float]:
    """Time means of the stress over ``windows``, from the solver's own per-record means
    (``micro.analysis.Records.time_mean``, exact between records)."""
    r = run.records
    rec = Records(*(r[c].to_numpy() for c in ("t", "sigma", "sigma_min", "sigma_max", "sigma_mean")))
    return [rec.time_mean(a, b) for a, b in windows]


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--k0", default="0.3,0.1")
    ap.add_argument("--eps", default="0.025,0.02,0.016,0.0125")
    ap.add_argument("--duration", type=float, default=480.0)
    ap.add_argument("--settle", type=float, default=120.0, help="windows from this time on make the late mean")
    ap.add_argument("--plot-only", action="store_true", help="redraw the figure from the CSV")
    ap.add_argument("--check-report", metavar="T_MAX", help="instead: the report's runs (the FP's stopping rule, "
                    "stopped at each of these t_max) against the long runs' late means in the CSV")
    args = ap.parse_args()
    if args.plot_only:
        draw(pd.read_csv(RESULTS / "micro_fp_fig10_long.csv"))
        return
    if args.check_report:
        check_report([float(x) for x in args.check_report.split(",")], args)
        return
    windows = [w for w in WINDOWS if w[1] <= args.duration]
    warm_up(lambda: micro.simulate(micro.Model(k0=0.1), 1.0, duration=0.5, numerics=micro.FP(eps=0.025)))
    rows = []
    for k0 in (float(x) for x in args.k0.split(",")):
        model = micro.Model(k0=k0)
        V = float(f"{1.5 * float(micro.critical_velocity(model).Vc):.6g}")  # as the report placed it
        exact = float(micro.steady_sliding(model, [V], growth_rate=False).sigma[0])
        for eps in (float(x) for x in args.eps.split(",")):
            with Stopwatch() as sw:
                run = micro.simulate(model, V, duration=args.duration, numerics=micro.FP(eps=eps), initial="frozen")
            means = window_means(run, windows)
            for (a, b), m in zip(windows, means):
                rows.append(dict(k0=k0, V=V, eps=eps, window=f"{a}-{b}", sigma=m, error=m - exact, exact=exact))
            late = np.array([m for (a, _), m in zip(windows, means) if a >= args.settle])
            mean = float(late.mean())
            half = float(0.5 * (late.max() - late.min()))
            rows.append(dict(k0=k0, V=V, eps=eps, window="late", sigma=mean, error=mean - exact, exact=exact,
                             half_range=half, duration=args.duration, wall_s=sw.seconds))
            print(f"k0 = {k0:g}, V = {V:g}, eps = {eps:g}: windows " + ", ".join(f"{m:.7f}" for m in means)
                  + f"; late mean {mean:.7f} +- {half:.1e}, error {mean - exact:+.1e} (exact {exact:.7f}); "
                  f"{sw.seconds:.1f} s", flush=True)
    table = write_csv(pd.DataFrame(rows), RESULTS / "micro_fp_fig10_long.csv", keys=["k0", "eps", "window"])
    draw(table)


def check_report(t_maxes: list[float], args) -> None:
    """The report's Fig. 10 runs (``micro.stationary(method="fp")`` with the report's
    stopping rule, ``compare.Settings.paper().convergence()``, cut at ``t_max``; an unsettled grid-sized oscillation reports its time mean over
    the run's later half) against the long runs' late means.  Writes
    ``benchmarks/results/micro_fp_fig10_report_check.csv``."""
    late = pd.read_csv(RESULTS / "micro_fp_fig10_long.csv")
    late = late[late.window == "late"].set_index(["k0", "eps"])
    warm_up(lambda: micro.stationary(micro.Model(k0=0.1), 1.2, method="fp", numerics=micro.FP(eps=0.025),
                                     convergence=micro.Convergence(t_max=2.0), warn=False))
    report = compare.Settings.paper()
    rows = []
    for t_max in t_maxes:
        for k0 in (float(x) for x in args.k0.split(",")):
            model = micro.Model(k0=k0)
            V = float(f"{1.5 * float(micro.critical_velocity(model).Vc):.6g}")
            for eps in (float(x) for x in args.eps.split(",")):
                with Stopwatch() as sw:
                    r = micro.stationary(model, V, method="fp", numerics=report.numerics(eps),
                                         convergence=replace(report.convergence(), t_max=t_max), warn=False)
                ref = late.loc[(k0, eps)]
                rows.append(dict(t_max=t_max, k0=k0, V=V, eps=eps, t_end=r.t_end, converged=r.converged,
                                 regime=r.regime, error=r.sigma_mean - ref.exact, long_error=ref.error,
                                 report_minus_long=r.sigma_mean - ref.sigma, long_half_range=ref.half_range,
                                 wall_s=sw.seconds))
                print(f"t_max = {t_max:g}, k0 = {k0:g}, eps = {eps:g}: stopped at t = {r.t_end:.1f} "
                      f"({'settled' if r.converged else 'open'}, {r.regime}), error {rows[-1]['error']:+.2e}, "
                      f"report - long {rows[-1]['report_minus_long']:+.1e}; {sw.seconds:.1f} s", flush=True)
    table = write_csv(pd.DataFrame(rows), RESULTS / "micro_fp_fig10_report_check.csv", keys=["t_max", "k0", "eps"])
    for t_max, g in table.groupby("t_max"):
        print(f"t_max = {t_max:g}: max |report - long| {g.report_minus_long.abs().max():.1e}, "
              f"summed wall {g.wall_s.sum():.1f} s")


def draw(table: pd.DataFrame) -> None:
    """The late means' errors against eps, with their half ranges as bars (a point whose bar
    reaches zero is drawn open: its sign is not resolved)."""
    plt = pyplot()
    fig, ax = plt.subplots(figsize=(6, 4))
    late = table[table.window == "late"]
    for (k0, g), c in zip(late.groupby("k0", sort=False), ("C0", "C1", "C2", "C3", "C4")):
        g = g.sort_values("eps")
        e, h = g.error.abs().to_numpy(), g.half_range.to_numpy()
        ok = e > h
        y = np.maximum(e, 1e-7)
        ax.errorbar(g.eps, y, yerr=[np.minimum(h, y - 1e-7), h], fmt="none", ecolor=c, lw=0.8)
        ax.loglog(g.eps[ok], e[ok], "o", color=c, label=f"k0 = {k0:g}, V = {g.V.iloc[0]:.4g}")
        ax.loglog(g.eps[~ok], y[~ok], "o", color=c, mfc="none")
    eps = np.sort(late.eps.unique())
    ax.set_xticks(eps, [f"{e:g}" for e in eps])
    ax.xaxis.set_minor_locator(plt.NullLocator())
    ax.set_xlabel("bin eps")
    ax.set_ylabel("|sigma_FP - sigma_exact| (late time mean)")
    ax.set_title("The paper's Fig. 10 from long runs (t = 120-480): bars = half range of the window means;\n"
                 "open: the error is within its bar", fontsize=8)
    ax.legend(fontsize=7)
    save_figure(fig, FIGURES / "micro_fp_fig10_long.png")


if __name__ == "__main__":
    main()
