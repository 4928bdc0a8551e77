"""Convergence of the stationary stress in the bin eps (the paper's Fig. 10).

For each of the paper's five k0 (k1 = 0.1, k2 = 0.9, zbar = 0.1, exponential g) the
Fokker-Planck stress is computed at a velocity just above V^c (1.5 times the RS V^c of
Eq. (12) with the paper's A, B and D_c, which lies above the micro V^c where that is
known) for a sequence of bins, each run capped at a wall-time budget.

Reference: the exact stationary stress of the renewal chain, ``micro.steady_sliding``
(error ~1e-12, docs/reference/micro_renewal.md), for every k0; the error of each bin is a number,
and ``order`` is the least-squares slope of log |error| on log eps.  The columns
``extrapolation`` and ``extrapolation_order`` keep the eps -> 0 extrapolation sigma_0 of
sigma(eps) = sigma_0 + c eps^p that served as reference before the chain existed: at
k0 = 0.1 it is 2e-5 off, because the FP's error stalls there.

The paper's difficulty at small k0 is scale: the velocity weakening it must resolve,
sigma(V) - sigma_inf ~ k2 gamma Var(R) / V ~ k0 zbar, shrinks with k0 while the
discretisation error does not.  The table says, per k0, which bins reached an error below
1 % of the weakening.

Writes benchmarks/results/micro_fp_eps_convergence.csv and docs/figures/micro_fp_eps_convergence.png.

    python -m studies micro_fp_eps_convergence            # about 15 minutes on one core
    python -m studies micro_fp_eps_convergence --budget 60  # shorter cap per run (seconds)
    python -m studies micro_fp_eps_convergence --k0 0.001 --eps 0.008,0.004 --t-max 40
        # some points only, capped in simulated time; replaces those rows of the CSV
"""
from __future__ import annotations

import argparse
import math

import matplotlib.ticker
import numpy as np
import pandas as pd
from scipy.optimize import curve_fit

import micro
from benchmarks._harness import (FIGURES, K0, RESULTS, VC_RS, Stopwatch, capped_t_max, merged, pyplot, save_figure, warm_up,
                      write_csv)

EPS = (0.024, 0.016, 0.012, 0.008, 0.006, 0.004)


def run_point(k0: float, V: float, eps: float, budget: float, t_max: float | None = None) -> dict:
    model = micro.Model(k0=k0)
    if t_max is None:
        t_max = capped_t_max(model, V, eps, budget)
    sw = Stopwatch()
    r = micro.stationary(model, V, numerics=micro.Numerics(eps=eps), convergence=micro.Convergence(t_max=t_max), method="fp")
    return dict(k0=k0, V=V, eps=eps, regime=r.regime, converged=r.converged, sigma=r.sigma_mean,
                sigma_stderr=r.sigma_stderr, t_end=r.t_end, t_max=t_max, wall_s=sw.seconds,
                mass_error=r.mass_error, min_mass=r.min_mass, message=r.message)


def extrapolate(d: pd.DataFrame) -> tuple[float, float]:
    """sigma(eps) = sigma_0 + c eps^p fitted to the converged bins (three bins: the exact
    solution, i.e. Richardson extrapolation with the observed order): (sigma_0, p)."""
    d = d[d.converged.astype(bool)].sort_values("eps")
    if len(d) < 3:
        return math.nan, math.nan

    def law(eps, s0, c, p):
        return s0 + c * eps ** p

    # start from the second-order line through the finest and coarsest bins (c = 0
    # would leave p without a gradient)
    c0 = (d.sigma.iloc[-1] - d.sigma.iloc[0]) / (d.eps.iloc[-1] ** 2 - d.eps.iloc[0] ** 2)
    try:
        (s0, _, p), _ = curve_fit(law, d.eps, d.sigma, p0=(d.sigma.iloc[0] - c0 * d.eps.iloc[0] ** 2, c0, 2.0),
                                  bounds=([-np.inf, -np.inf, 0.5], [np.inf, np.inf, 4.0]))
    except RuntimeError:
        return math.nan, math.nan
    return float(s0), float(p)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--budget", type=float, default=60.0, help="wall-time cap per run, seconds (default 60)")
    ap.add_argument("--k0", type=str, default=",".join(map(str, K0)), help="comma-separated k0 values")
    ap.add_argument("--t-max", type=float, default=None,
                    help="cap each run at this simulated time instead of a wall-time budget")
    ap.add_argument("--eps", type=str, default=",".join(map(str, EPS)), help="comma-separated bins, coarse to fine")
    ap.add_argument("--replot", action="store_true", help="redo the table and plot from the CSV of a previous run")
    args = ap.parse_args()
    out = RESULTS / "micro_fp_eps_convergence.csv"
    columns = ["k0", "V", "eps", "regime", "converged", "sigma", "sigma_stderr", "t_end", "t_max", "wall_s",
               "mass_error", "min_mass", "message"]
    if args.replot:
        table = pd.read_csv(out)[columns]
    else:
        k0s = [float(x) for x in args.k0.split(",")]
        bins = [float(x) for x in args.eps.split(",")]
        warm_up(micro.stationary, micro.Model(k0=0.1), 2.0, numerics=micro.Numerics(eps=0.024), method="fp")
        rows = []
        for k0 in k0s:
            V = 1.5 * VC_RS[k0]
            for eps in bins:
                row = run_point(k0, V, eps, args.budget, args.t_max)
                rows.append(row)
                print({k: row[k] for k in ("k0", "V", "eps", "regime", "converged", "sigma", "wall_s")}, flush=True)
                if args.t_max is None and row["wall_s"] > args.budget:
                    break  # the next (finer) bin would not fit either
        # keep the other k0 (and bins) of a previous run; the requested ones are replaced
        requested = pd.DataFrame([(k0, eps) for k0 in k0s for eps in bins], columns=["k0", "eps"])
        table = merged(out, pd.DataFrame(rows), ["k0", "eps"], replace=requested)[columns]
        table = table.sort_values(["k0", "eps"], ascending=[False, False], ignore_index=True)
    table["reference"] = [float(micro.steady_sliding(micro.Model(k0=k0), V, growth_rate=False).sigma)
                          for k0, V in zip(table.k0, table.V)]
    table["weakening"] = [micro.sigma_fast_limit(micro.Model(k0=k0), V) - micro.sigma_fast_limit(micro.Model(k0=k0))
                          for k0, V in zip(table.k0, table.V)]
    table["error"] = table.sigma - table.reference
    summary = []
    for k0, d in table.groupby("k0", sort=False):
        extrap, p = extrapolate(d)
        ok = d[d.converged.astype(bool)]
        order = float(np.polyfit(np.log(ok.eps), np.log(np.abs(ok.error)), 1)[0]) if len(ok) >= 2 else math.nan
        summary.append(dict(k0=k0, V=d.V.iloc[0], weakening=d.weakening.iloc[0], reference=d.reference.iloc[0],
                            order=order, extrapolation=extrap, extrapolation_order=p))
    table = table.merge(pd.DataFrame(summary)[["k0", "order", "extrapolation", "extrapolation_order"]], on="k0")
    table["within_1pct_of_weakening"] = np.abs(table.error) <= 0.01 * np.abs(table.weakening)
    write_csv(table, out)
    pd.set_option("display.width", 200)
    print(table[["k0", "V", "eps", "converged", "sigma", "sigma_stderr", "error", "weakening",
                 "within_1pct_of_weakening", "wall_s"]].to_string(index=False))
    print(pd.DataFrame(summary).to_string(index=False))

    fig, axes = pyplot().subplots(1, 2, figsize=(10, 4))
    for k0, d in table.groupby("k0", sort=False):
        ok = d[d.converged]
        line, = axes[0].plot(d.eps, d.sigma, "o-", label=f"k0 = {k0:g}, V = {d.V.iloc[0]:.3g}")
        axes[0].plot(d[~d.converged].eps, d[~d.converged].sigma, "x", color=line.get_color(), ms=9)
        axes[0].axhline(d.reference.iloc[0], color=line.get_color(), ls="--", lw=0.8)
        axes[1].loglog(ok.eps, np.abs(ok.error), "o-", color=line.get_color(), label=f"k0 = {k0:g}")
        axes[1].axhline(0.01 * abs(d.weakening.iloc[0]), color=line.get_color(), ls=":", lw=0.8)
    axes[0].set_xlabel("bin eps")
    axes[0].set_ylabel("stationary sigma (x: not converged by the cap)")
    axes[0].set_title("Fig. 10: sigma(eps) just above V^c (dashed: exact)")
    axes[0].legend(fontsize=7)
    axes[1].xaxis.set_minor_formatter(matplotlib.ticker.NullFormatter())
    axes[1].set_xlabel("bin eps")
    axes[1].set_ylabel("|sigma - exact|")
    axes[1].set_title("error (dotted: 1 % of the velocity weakening)")
    for ax in axes:
        ax.grid(True, which="both", alpha=0.3)
    fig.tight_layout()
    save_figure(fig, FIGURES / "micro_fp_eps_convergence.png")


if __name__ == "__main__":
    main()
