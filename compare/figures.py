"""Figures of a report (matplotlib, Agg backend): one PNG per scenario, micro and RS on
shared axes.  Called by :func:`compare.report` with the computed tables."""
from __future__ import annotations

import math
from pathlib import Path
from typing import Any

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
import pandas as pd  # noqa: E402

from . import fits  # noqa: E402

__all__ = ["draw"]

_COLORS = {0.3: "C0", 0.1: "C1", 0.01: "C2", 0.001: "C3", 0.0001: "C4"}


def _save(fig, path: Path) -> Path:
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)
    return path


def _color(k0: float, i: int) -> str:
    for k, c in _COLORS.items():
        if math.isclose(k, k0, rel_tol=1e-9):
            return c
    return f"C{5 + i % 5}"


def bifurcation(t: dict[str, pd.DataFrame], Dc: float, path: Path) -> Path:
    """Figs. 4 and 8: micro (left) and RS with the fitted law and D_c (right), shared axes;
    micro points repeated as markers on the RS panel."""
    pts = t["micro_points"]
    pts = pts[(pts.role == "diagram") & pts.regime.isin(["steady", "stick-slip"])]
    rs = t["rs_bifurcation"]
    fig, axes = plt.subplots(1, 2, figsize=(11, 4.5), sharex=True, sharey=True)
    for i, (k0, grp) in enumerate(rs.groupby("k0", sort=False)):
        c = _color(k0, i)
        for ax in axes[1:]:
            ax.semilogx(grp.V, grp.sigma_max, "-", color=c, lw=1.2, label=f"k0 = {k0:g}")
            ax.semilogx(grp.V, grp.sigma_min, "-", color=c, lw=1.2)
    for i, (k0, grp) in enumerate(pts.groupby("k0", sort=False)):
        c = _color(k0, i)
        grp = grp.sort_values("V")
        axes[0].semilogx(grp.V, grp.sigma_max, "o-", color=c, ms=4, label=f"k0 = {k0:g}")
        axes[0].semilogx(grp.V, grp.sigma_min, "s--", color=c, ms=4)
        axes[1].semilogx(grp.V, grp.sigma_max, "o", color=c, ms=4, mfc="none")
        axes[1].semilogx(grp.V, grp.sigma_min, "s", color=c, ms=4, mfc="none")
    axes[0].set_title("micro model (Fig. 4): sigma_max (o), sigma_min (s)")
    axes[1].set_title(f"RS, fitted Eq. (10), D_c = {Dc:.3g} (Fig. 8); open: micro")
    for ax in axes:
        ax.set_xlabel("driving velocity V")
        ax.legend(fontsize=7)
    axes[0].set_ylabel("sigma_max, sigma_min")
    return _save(fig, path)


def dc_profile(t: dict[str, pd.DataFrame], values: dict[str, Any], path: Path) -> Path:
    prof = t["dc_profile"]
    fig, ax = plt.subplots(figsize=(5.5, 4))
    ax.loglog(prof.Dc, prof.rms, "o-", ms=3)
    ax.axvline(values["Dc"], color="k", lw=0.8, label=f"fit D_c = {values['Dc']:.3g} ± {values['Dc_err']:.2g}")
    ax.axvspan(*values["Dc_profile"], color="k", alpha=0.1)
    ax.axvline(0.06, color="r", ls=":", label="paper D_c = 0.06")
    ax.set_xlabel("D_c")
    ax.set_ylabel("rms(sigma_RS - sigma_micro)")
    ax.legend(fontsize=8)
    return _save(fig, path)


def hopf(t: dict[str, pd.DataFrame], path: Path) -> Path:
    pts, fit = t["hopf_points"], t["hopf_fit"]
    fig, ax = plt.subplots(figsize=(6, 4.5))
    for i, (name, grp) in enumerate(pts.groupby("model")):
        grp = grp[(grp.regime == "stick-slip") & (grp.amplitude > 0)]
        gap = grp.Vc - grp.V
        ax.loglog(gap, grp.amplitude, "o" if name == "micro" else "s", color=f"C{i}", label=name)
        for _, f in fit[fit.model == name].iterrows():
            x = np.geomspace(max(gap.min(), 1e-12) * 0.8, gap.max() * 1.2, 50)
            if f.Vc_fitted:  # the fit is in V; plot against the bisection gap
                Vc0 = grp.Vc.iloc[0]
                V = Vc0 - x
                y = f.prefactor * np.clip(f.Vc - V, 1e-300, None) ** f.exponent
                style = ":"
            else:
                y = f.prefactor * x ** f.exponent
                style = "-"
            ax.loglog(x, y, style, color=f"C{i}", lw=1,
                      label=f"{name} ({f.Vc_mode}): beta = {f.exponent:.2f} ± {f.exponent_err:.2f}")
    ax.set_xlabel("Vc - V")
    ax.set_ylabel("sigma_max - sigma_min")
    ax.set_title(f"Hopf scaling at k0 = {pts.k0.iloc[0]:g}")
    ax.legend(fontsize=7)
    return _save(fig, path)


def phase(t: dict[str, pd.DataFrame], Dc: float, path: Path) -> Path:
    rs, mic, laws = t["phase_rs"], t["phase_micro"], t["phase_laws"]
    sets = list(laws[["k1", "k2"]].itertuples(index=False, name=None))
    n = max(len(sets), 1)
    fig, axes = plt.subplots(1, n, figsize=(3.4 * n + 0.6, 4), sharex=True, sharey=True, squeeze=False)
    for ax, (k1, k2) in zip(axes[0], sets):
        r = rs[np.isclose(rs.k1, k1) & np.isclose(rs.k2, k2)]
        ax.loglog(r.k0, r.Vc, "-", color="C0", label="RS Vc")
        ax.loglog(r.k0, r.asymptote, ":", color="C0", lw=0.8, label="A/(k0 D_c)")
        ax.axvline(r.k0_max_rs.iloc[0], color="C0", ls="--", lw=0.8, label="RS k0_max")
        ax.axvline(k2, color="C1", ls="--", lw=0.8, label="micro limit k0 = k2")
        m = mic[np.isclose(mic.k1, k1) & np.isclose(mic.k2, k2) & (mic.status == "converged")]
        if len(m):
            ax.errorbar(m.k0, m.Vc, yerr=[m.Vc - m.V_low, m.V_high - m.Vc], fmt="o", color="C1", label="micro Vc")
        ax.set_title(f"k1 = {k1:g}, k2 = {k2:g}", fontsize=9)
        ax.set_xlabel("k0")
    axes[0][0].set_ylabel("Vc (stick-slip below, steady above)")
    axes[0][0].set_ylim(1e-3, 1e4)
    axes[0][0].legend(fontsize=6)
    fig.suptitle(f"Phase diagram (Fig. 5), D_c = {Dc:.3g}", fontsize=10)
    return _save(fig, path)


def shs(t: dict[str, pd.DataFrame], path: Path) -> Path:
    pts, fit = t["shs_points"], t["shs_fit"]
    models = list(dict.fromkeys(pts.model))
    own = {"micro": "exponential", "RS Eq. (11)": "algebraic", "classical RS Eq. (7)": "logarithmic"}
    fig, axes = plt.subplots(1, len(models), figsize=(4 * len(models), 4), sharex=True, squeeze=False)
    for ax, name in zip(axes[0], models):
        grp = pts[pts.model == name]
        ax.semilogx(grp.hold_time, grp.delta_sigma_max, "o", color="k", label=name)
        x = np.geomspace(grp.hold_time.min() * 0.7, grp.hold_time.max() * 1.5, 100)
        for j, law in enumerate(fits.GROWTH_LAWS):
            f = fit[(fit.model == name) & (fit.law == law)]
            if not len(f):
                continue
            f = f.iloc[0]
            y = fits.GROWTH_LAWS[law][0](x, f.p1, f.p2)
            ax.semilogx(x, y, "-" if law == own.get(name) else ":", color=f"C{j}", lw=1.4 if law == own.get(name) else 0.8,
                        label=f"{law}: {f.p1_name}={f.p1:.3g}, {f.p2_name}={f.p2:.3g}")
        ax.set_title(name, fontsize=9)
        ax.set_xlabel("hold time")
        ax.legend(fontsize=6)
    axes[0][0].set_ylabel("peak - steady stress")
    fig.suptitle("Slide-hold-slide (Fig. 7): growth laws (solid: the model's expected law)", fontsize=10)
    return _save(fig, path)


def draw(study, out: Path) -> dict[str, Path]:
    """Every figure whose tables the study computed; returns name -> path."""
    t, v = study.tables, study.values
    figs: dict[str, Path] = {}
    if "rs_bifurcation" in t:
        figs["bifurcation"] = bifurcation(t, study.Dc, out / "bifurcation.png")
    if "dc_profile" in t:
        figs["dc_profile"] = dc_profile(t, v, out / "dc_profile.png")
    if "hopf_points" in t:
        figs["hopf"] = hopf(t, out / "hopf.png")
    if "phase_rs" in t and len(t["phase_laws"]):
        figs["phase"] = phase(t, study.Dc, out / "phase.png")
    if "shs_points" in t:
        figs["shs"] = shs(t, out / "shs.png")
    return figs
