"""Figures of a report (matplotlib, Agg backend), micro and RS on shared axes.

Conventions: a computed point is a marker (open when its run did not converge), a line
is either exact (micro's steady branch, RS) or a fitted law, and what was not computed is
marked as such.  Each function draws one figure from a report's tables; the scenarios
(:mod:`compare.scenarios`) and the shared stages (:class:`compare.context.Context`) call
them.
"""
from __future__ import annotations

import functools
import logging
import math
import os
import pickle
import tempfile
from concurrent.futures import Future
from pathlib import Path
from typing import Any, Callable

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
import pandas as pd  # noqa: E402

from micro.api import NEAR_VC  # noqa: E402

from . import fits  # noqa: E402

__all__ = ["Painter", "target"]

log = logging.getLogger(__name__)

_COLORS = {0.3: "C0", 0.1: "C1", 0.01: "C2", 0.001: "C3", 0.0001: "C4"}


class Painter:
    """Draws a report's figures on other processes while the caller goes on.

    Pass it where a figure function takes its folder (``figures.target(painter, name)``):
    the call then hands the figure's data to ``submit`` (:meth:`compare.Runner.submit`:
    a worker of the runner's pool, or this process) and returns the figure's final path
    at once.  Each figure is drawn into a temporary file of the folder, and
    :meth:`finish` waits for them and writes each into the folder
    (:meth:`ReportFolder.write`, atomically).  A figure whose worker failed is drawn
    again here, so that its error, if it is the figure's own, is raised from this process."""

    def __init__(self, folder, submit: Callable) -> None:
        self.folder = folder
        self._submit = submit
        self._jobs: list[tuple[str, Path, str, tuple, Any]] = []

    def write(self, name: str, write: Callable[[Path], None]) -> Path:
        """As :meth:`ReportFolder.write` (so that :func:`target` takes a painter for a folder)."""
        return self.folder.write(name, write)

    def submit(self, fn_name: str, data: tuple, name: str) -> Path:
        """Draw ``fn_name(*data, path)`` into the folder's file ``name``; its final path."""
        try:
            blob = pickle.dumps((fn_name, data), protocol=pickle.HIGHEST_PROTOCOL)
        except Exception:  # noqa: BLE001 - data that cannot travel: draw it here
            return globals()[fn_name].__wrapped__(*data, (self.folder, name))
        fd, tmp = tempfile.mkstemp(dir=self.folder.path, prefix=f".{name}.", suffix=".png")
        os.close(fd)
        try:
            future = self._submit(_paint, blob, tmp)
        except Exception as exc:  # noqa: BLE001 - (a broken pool): drawn here by finish()
            future = Future()
            future.set_exception(exc)
        except BaseException:  # Ctrl-C while it was drawn here (no pool): not left in the folder
            Path(tmp).unlink(missing_ok=True)
            raise
        self._jobs.append((name, Path(tmp), fn_name, data, future))
        return self.folder.path / name

    def finish(self) -> None:
        """Wait for every figure and write it into the folder; temporary files are removed
        whatever happens."""
        try:
            for name, tmp, fn_name, data, fut in self._jobs:
                try:
                    fut.result()
                except Exception as exc:  # noqa: BLE001 - redrawn here, where its own error surfaces
                    log.warning("figure %s failed on a worker (%s); drawing it here", name, exc)
                    globals()[fn_name].__wrapped__(*data, tmp)
                self.folder.write(name, lambda p, tmp=tmp: os.replace(tmp, p))
        finally:
            self.discard()

    def discard(self) -> None:
        """Forget the figures not yet written and remove their temporary files."""
        for _, tmp, _, _, fut in self._jobs:
            fut.cancel()
            tmp.unlink(missing_ok=True)
        self._jobs.clear()


def _paint(blob: bytes, tmp: str) -> str:
    """A :class:`Painter`'s job on a worker: draw the figure into the file ``tmp``."""
    fn_name, data = pickle.loads(blob)
    globals()[fn_name].__wrapped__(*data, Path(tmp))
    return tmp


def _figure(fn: Callable) -> Callable:
    """A figure function (its last argument the path): with a :class:`Painter` for the
    folder, drawn by the painter."""
    @functools.wraps(fn)
    def draw(*args: Any) -> Path:
        *data, path = args
        if isinstance(path, tuple) and isinstance(path[0], Painter):
            return path[0].submit(fn.__name__, tuple(data), path[1])
        return fn(*args)
    return draw


def _save(fig, path) -> Path:
    """Save ``fig`` as the PNG ``path``: a file name in a :class:`ReportFolder` (written
    atomically) or a plain path."""
    fig.tight_layout()
    try:
        if isinstance(path, tuple):
            folder, name = path
            return folder.write(name, lambda p: fig.savefig(p, dpi=110, format="png"))
        fig.savefig(path, dpi=110)
        return path
    finally:
        plt.close(fig)


def _color(k0: float, i: int = 0) -> str:
    for k, c in _COLORS.items():
        if math.isclose(k, k0, rel_tol=1e-9):
            return c
    return f"C{5 + i % 5}"


def _converged(frame: pd.DataFrame) -> np.ndarray:
    if "converged" not in frame:
        return np.ones(len(frame), bool)
    return frame.converged.fillna(False).astype(bool).to_numpy()


@_figure
def bifurcation(t: dict[str, pd.DataFrame], Dc: float, fp_k0, path: Path) -> Path:
    """Figs. 4 and 8: micro (left: exact steady branch, stick-slip points: those the D_c
    fit matches and those only shown) and RS with the fitted law and D_c (right), shared
    axes."""
    branch = t["micro_branch"]
    branch = branch[branch.role == "branch"]
    cols = ["k0", "V", "regime", "sigma_max", "sigma_min", "method"]
    frames = [t[name][[c for c in cols + ["converged"] if c in t[name]]]
              for name in ("micro_points", "micro_shown_points") if name in t and len(t[name])]
    pts = pd.concat(frames, ignore_index=True) if frames else pd.DataFrame(columns=cols)
    computed = set(fp_k0) | set(pts.k0[pts.regime == "stick-slip"]) if len(pts) else set(fp_k0)
    cycles = pts[pts.regime == "stick-slip"] if len(pts) else pts
    method = ", ".join(sorted(set(cycles.method.astype(str)))) if len(cycles) else "none"
    rs = t["rs_bifurcation"]
    band = t.get("rs_unstable_band")
    fig, axes = plt.subplots(1, 2, figsize=(12, 5), sharex=True, sharey=True)
    ax = axes[0]
    for i, (k0, grp) in enumerate(branch.groupby("k0", sort=False)):
        c = _color(k0, i)
        grp = grp.sort_values("V")
        st, un = grp[grp.stable.astype(bool)], grp[~grp.stable.astype(bool)]
        ax.semilogx(st.V, st.sigma, "-", color=c, lw=1.3, label=f"k0 = {k0:g}")
        ax.semilogx(un.V, un.sigma, ":", color=c, lw=1.0)
        vc = float(grp.Vc.iloc[0])
        if vc > 0:
            y = float(np.interp(math.log(vc), np.log(grp.V), grp.sigma))
            ax.plot([vc], [y], "|", color=c, ms=14, mew=2)
            if not any(math.isclose(k0, k, rel_tol=1e-9) for k in computed):
                ax.annotate("stick-slip not computed", (vc, y), xytext=(0, 12), textcoords="offset points",
                            ha="center", va="bottom", rotation=90, fontsize=6, color=c)
        p = pts[np.isclose(pts.k0, k0) & (pts.regime == "stick-slip")] if len(pts) else pts
        if len(p):
            ok = _converged(p)
            for sel, fill in ((ok, c), (~ok, "none")):
                ax.semilogx(p.V[sel], p.sigma_max[sel], "o", color=c, mfc=fill, ms=5)
                ax.semilogx(p.V[sel], p.sigma_min[sel], "s", color=c, mfc=fill, ms=5)
    ax.set_title("micro (Fig. 4): exact steady branch (dotted: unstable), | = V^c;\n"
                 f"stick-slip sigma_max (o), sigma_min (s) by {method}; open: not converged", fontsize=9)
    ax = axes[1]
    for i, (k0, grp) in enumerate(rs.groupby("k0", sort=False)):
        c = _color(k0, i)
        grp = grp.sort_values("V")
        ax.semilogx(grp.V, grp.sigma_max, "-", color=c, lw=1.2, label=f"k0 = {k0:g}")
        ax.semilogx(grp.V, grp.sigma_min, "-", color=c, lw=1.2)
        if band is not None:
            b = band[np.isclose(band.k0, k0)]
            if len(b):
                for V, mark in ((b.Vc.iloc[0], "|"), (b.V_lower.iloc[0], "x")):
                    if math.isfinite(V) and V > 0:
                        y = float(np.interp(math.log(V), np.log(grp.V), grp.sigma_mean))
                        ax.plot([V], [y], mark, color=c, ms=10, mew=2)
        p = pts[np.isclose(pts.k0, k0) & (pts.regime == "stick-slip")] if len(pts) else pts
        if len(p):
            ax.semilogx(p.V, p.sigma_max, "o", color=c, mfc="none", ms=5)
            ax.semilogx(p.V, p.sigma_min, "s", color=c, mfc="none", ms=5)
    ax.set_title(f"RS, fitted Eq. (10), D_c = {Dc:.3g} (Fig. 8): | = V^c, x = V_- (steady again below);\n"
                 "open: micro's stick-slip points", fontsize=9)
    for ax in axes:
        ax.set_xlabel("driving velocity V")
        ax.legend(fontsize=7, loc="lower left")
    axes[0].set_ylabel("sigma_max, sigma_min (steady: sigma)")
    return _save(fig, path)


@_figure
def steady_fit(t: dict[str, pd.DataFrame], values: dict[str, Any], path: Path) -> Path:
    """Fig. 6 (micro's velocity weakening, exact, log-log) and the Eq. (10) residual."""
    b = t["micro_branch"]
    chk = t["steady_fit_checks"].set_index("k0")
    res = t["steady_fit_residuals"]
    fig, axes = plt.subplots(1, 2, figsize=(11, 4.3))
    for i, (k0, grp) in enumerate(b[b.stable.astype(bool)].groupby("k0", sort=False)):
        if k0 not in chk.index:
            continue
        c = _color(k0, i)
        grp = grp.sort_values("V")
        axes[0].loglog(grp.V, grp.sigma - chk.sigma_inf_exact[k0], "-", color=c, label=f"k0 = {k0:g}")
        axes[0].loglog(grp.V, values["A"] / (grp.V + values["B"]) + chk.mu_inf[k0] - chk.sigma_inf_exact[k0],
                       "--", color=c, lw=0.8)
        r = res[np.isclose(res.k0, k0)].sort_values("V")
        axes[1].semilogx(r.V, r.residual, ".-", color=c, ms=3, lw=0.8, label=f"k0 = {k0:g}")
    V = np.geomspace(b.V.min(), b.V.max(), 50)
    axes[0].loglog(V, chk.tail_exact.iloc[0] / V, "k:", lw=1, label="exact tail C/V")
    axes[0].set_ylabel("sigma(V) - sigma(V→∞)")
    axes[0].set_title("Fig. 6: micro's exact steady branch (solid), Eq. (10) fit (dashed)", fontsize=9)
    axes[1].axhline(0, color="k", lw=0.6)
    axes[1].set_ylabel("micro - Eq. (10)")
    axes[1].set_title(f"Eq. (10) residual: A = {values['A']:.4g}, B = {values['B']:.4g}, "
                      f"rms {values['steady_rms']:.2g}", fontsize=9)
    for ax in axes:
        ax.set_xlabel("V")
        ax.legend(fontsize=7)
    return _save(fig, path)


@_figure
def dc_profile(t: dict[str, pd.DataFrame], values: dict[str, Any], path: Path) -> Path:
    prof = t["dc_profile"]
    fig, ax = plt.subplots(figsize=(6.5, 4.3))
    ax.loglog(prof.Dc, prof.rms, "o-", ms=3, label="rms(sigma_RS - sigma_micro) on the scan grid")
    sw = t["dc_points"].Dc_switch.to_numpy(float)
    for j, s in enumerate(sw[np.isfinite(sw) & (sw > 0)]):
        ax.axvline(s, color="0.6", ls=":", lw=0.7, label="regime switch of a point" if j == 0 else None)
    Dc = values["Dc"]
    lo, hi = values["Dc_profile"]
    if values.get("Dc_one_sided"):
        bound = "<=" if values["Dc_one_sided"] == "upper" else ">="
        lab = f"(a) D_c = {Dc:.3g}: on a switch, one-sided D_c {bound} {values['Dc_switch']:.3g}"
    else:
        lab = f"(a) D_c = {Dc:.3g} ± {values['Dc_err']:.2g}"
    ax.axvline(Dc, color="k", lw=1, label=lab)
    ax.axvspan(lo, hi, color="k", alpha=0.1, label=f"profile interval [{lo:.3g}, {hi:.3g}]")
    if "Dc_vc" in values:  # (b) is computed by the scenarios that need V^c (not by shs alone)
        b_lo, b_hi = values["Dc_vc_range"]
        ax.axvline(values["Dc_vc"], color="C3", lw=1, label=f"(b) V^c matching: {values['Dc_vc']:.3g}")
        ax.axvspan(b_lo, b_hi, color="C3", alpha=0.1, label=f"(b) per-k0 range [{b_lo:.3g}, {b_hi:.3g}]")
    ax.axvline(0.06, color="C2", ls="--", lw=0.8, label="paper D_c = 0.06")
    ax.set_xlabel("D_c")
    ax.set_ylabel("rms residual of sigma_max, sigma_min")
    ax.legend(fontsize=6, loc="upper right")
    return _save(fig, path)


@_figure
def critical_velocity(t: dict[str, pd.DataFrame], values: dict[str, Any], path: Path) -> Path:
    """V^c(k0): micro exact against RS with each D_c (and the paper's law)."""
    cur, crit = t["vc_curves"], t["critical_velocity"]
    fig, ax = plt.subplots(figsize=(6.5, 4.8))
    ax.loglog(cur.k0, cur.Vc_micro, "o", color="k", ms=3, label="micro, exact")
    ax.loglog(crit.k0, crit.Vc_micro, "o", color="k", ms=7, mfc="none")
    ax.loglog(crit.k0, crit.Vc_micro_small_k0, "k:", lw=0.8, label="micro small-k0 asymptote")
    if "Dc" in values:
        ax.loglog(cur.k0, cur.Vc_rs, "-", color="C0", label=f"RS, D_c (a) = {values['Dc']:.3g} (extrema)")
    else:
        ax.loglog(cur.k0, cur.Vc_rs, "-", color="C0", label=f"RS, D_c = {crit.Dc.iloc[0]:.3g} (given)")
    ax.loglog(cur.k0, cur.Vc_rs_dc_vc, "--", color="C3", label=f"RS, D_c (b) = {values['Dc_vc']:.3g} (V^c match)")
    ax.loglog(cur.k0, cur.Vc_rs_paper, ":", color="C2", label="RS, paper's A, B, D_c")
    ax.set_xlabel("k0")
    ax.set_ylabel("V^c (stick-slip below, steady above)")
    ax.set_title("Critical velocity: micro (exact) and RS with each D_c", fontsize=9)
    ax.legend(fontsize=7)
    return _save(fig, path)


@_figure
def hopf(t: dict[str, pd.DataFrame], values: dict[str, Any], path: Path) -> Path:
    """The transition on both sides.  Left: the one test, the growth rate of the unstable
    mode of steady sliding against d = (V^c - V)/V^c (micro's, and RS's at a = 0 where
    ``rs_spectrum`` is given).  Right: both models' amplitude sigma_max - sigma_min
    against d, log-log, each against its own exact V^c: the points with their error bars
    (filled: the error is known and the point is fitted; open: not known, not fitted),
    each method's fitted law over the d it rests on with its interval, and RS's derived
    asymptote c0 d^(1/2) (1 + c2 d) (``values['rs_amplitude_law']``); micro's amplitude has
    no derived prefactor, and the figure says so.  On the left, micro's derived growth-rate asymptote
    (``micro_spectrum.growth_rate_asymptote``, :func:`micro.growth_rate_near_vc`)."""
    pts, fit, spec = t["hopf_points"], t["hopf_fit"], t["micro_spectrum"]
    k0 = float(pts.k0.iloc[0]) if len(pts) else math.nan
    fig, axes = plt.subplots(1, 2, figsize=(13.5, 5.4), gridspec_kw={"width_ratios": [1, 1.45]})
    ax = axes[0]
    sp = spec[np.isfinite(spec.growth_rate) & (spec.growth_rate > 0)]
    ax.loglog(sp.d, sp.growth_rate, "o-", ms=3, color="C1", label="micro: real mode (branching ratio -> 1 at V^c)")
    if "growth_rate_asymptote" in sp:
        ax.loglog(sp.d, sp.growth_rate_asymptote, "--", color="C1", lw=0.9,
                  label="micro, derived: k2 gamma b / ((k1 + k2)(b - 1)) - gamma")
    rs_sp = t.get("rs_spectrum")
    if rs_sp is not None and len(rs_sp):
        r = rs_sp[np.isfinite(rs_sp.growth_rate) & (rs_sp.growth_rate > 0)]
        ax.loglog(r.d, r.growth_rate, "s-", ms=3, color="C0", label="RS, a = 0: slow real mode (its partner: +inf)")
    ax.set_xlabel("d = (V^c - V) / V^c")
    ax.set_ylabel("growth rate of the unstable mode (per unit time)")
    ax.set_title(f"The one test (k0 = {k0:g}): the growth rate diverges at V^c in both models\n"
                 "(a Hopf bifurcation would have it vanish at a finite frequency)", fontsize=9)
    ax.legend(fontsize=7)
    ax = axes[1]
    nb_N = sorted(pts.resolution[pts.method == "N-block"].dropna().unique())
    nb_colors = ["C2", "C3", "C5", "C6", "C8"]
    handles: list = []   # (handle, label) in the order drawn: each method's points, then its fit

    def keep(handle, label):
        handles.append((handle[0] if isinstance(handle, list) else handle, label))

    for (name, method, res), grp in pts.groupby(["model", "method", "resolution"], dropna=False, sort=False):
        grp = grp[(grp.regime == "stick-slip") & (grp.amplitude > 0)].sort_values("d")
        if not len(grp):
            continue
        fp = str(method).lower() == "fp"
        if method == "N-block":
            mark, c = "D", nb_colors[nb_N.index(res) % len(nb_colors)]
        else:
            mark, c = {"cohort": ("o", "C1"), "CVODE": ("s", "C0")}.get(method, ("v", "C4") if fp else ("^", "C9"))
        lab = f"{name} {'FP' if fp else method}" + ("" if not math.isfinite(res) else (
            f" N={res:.0f}" if method == "N-block" else f" h={res:.3g}" if method == "cohort" else f" eps={res:g}"))
        known = grp.amplitude_error_kind.astype(str) != "not known" if "amplitude_error_kind" in grp else \
            pd.Series(True, index=grp.index)
        ok, no = grp[known], grp[~known]
        # (micro's default on top: where it agrees with the N-block, its circle sits inside the diamond)
        ms, z = (4.5, 4) if method == "cohort" else (6, 3) if method == "N-block" else (5, 3)
        if len(ok):
            yerr = ok.amplitude_stderr.fillna(0.0) if name != "RS" else None
            kinds = set(ok.amplitude_error_kind.astype(str)) if "amplitude_error_kind" in ok else set()
            bars = ("" if name == "RS" else " (bars: error bound)" if kinds == {"bound"} else
                    " (bars: standard error)" if kinds == {"standard error"} else " (bars: error)")
            keep(ax.errorbar(ok.d, ok.amplitude, yerr=yerr, fmt=mark, color=c, ms=ms, capsize=2, lw=1, zorder=z),
                 lab + bars)
        if len(no):
            why = "not converged in eps, not fitted" if fp else "error not known, not fitted"
            keep(ax.plot(no.d, no.amplitude, mark, color=c, mfc="none", ms=ms, zorder=z), f"{lab}: {why}")
        f = fit[(fit.model == name) & (fit.method == method)
                & ((fit.resolution == res) | (fit.resolution.isna() & (not math.isfinite(res))))] if len(fit) else fit
        if len(f):
            f = f.iloc[0]
            d = np.geomspace(f.d_min, f.d_max, 50)
            keep(ax.plot(d, f.prefactor * (f.Vc * d) ** f.exponent, "-", color=c, lw=0.8),
                 f"  fit: beta = {f.beta:.2f} [{f.beta_low:.2f}, {f.beta_high:.2f}], d = {f.d_min:.2g}-{f.d_max:.2g}")
    law = values.get("rs_amplitude_law") or {}
    rs = pts[(pts.model == "RS") & (pts.regime == "stick-slip")]
    shown = pts.d[(pts.regime == "stick-slip") & (pts.amplitude > 0)]
    lo, hi = float(shown.min()) / 2 if len(shown) else 1e-3, min(float(shown.max()) * 1.3, 1.0) if len(shown) else 1.0
    if math.isfinite(law.get("c0", math.nan)) and len(rs):
        d = np.geomspace(lo, rs.d.max(), 100)
        keep(ax.plot(d, law["c0"] * np.sqrt(d) * (1 + law["c2"] * d), "--", color="k", lw=1),
             f"RS asymptote c0 d^1/2 (1 + c2 d), c0 = {law['c0']:.4g}, c2 = {law['c2']:.3g} (derived)")
    ax.set_xscale("log")
    ax.set_yscale("log")
    ax.set_xlim(lo, hi)
    if lo < NEAR_VC:
        keep(ax.axvspan(lo, min(NEAR_VC, hi), color="0.5", alpha=0.1, lw=0),
             f"d < {NEAR_VC:g}: micro's law not settled (the cohort's error not known)")
    ax.text(0.02, 0.97, "micro: no single power law; crossover at d ~ k0/k2,\nlinear in d again deep below it "
            "(scaling argument, prefactor not derived)", transform=ax.transAxes, ha="left", va="top",
            fontsize=8, color="C1")
    ax.set_xlabel("d = (V^c - V) / V^c (each model's own exact V^c)")
    ax.set_ylabel("sigma_max - sigma_min")
    ax.set_title("Amplitude near V^c: points with their errors, fitted laws [95 % CI] over the d they rest on,\n"
                 "RS's derived asymptote (micro: no prefactor derived)", fontsize=9)
    ax.legend([hd for hd, _ in handles], [lb for _, lb in handles], fontsize=6, loc="lower right")
    return _save(fig, path)


@_figure
def phase(t: dict[str, pd.DataFrame], values: dict[str, Any], path: Path) -> Path:
    rs, mic, laws = t["phase_rs"], t["phase_micro"], t["phase_laws"]
    sets = list(laws[["k1", "k2"]].itertuples(index=False, name=None))
    n = max(len(sets), 1)
    fig, axes = plt.subplots(1, n, figsize=(3.6 * n + 0.6, 4.2), sharex=True, sharey=True, squeeze=False)
    for ax, (k1, k2) in zip(axes[0], sets):
        r = rs[np.isclose(rs.k1, k1) & np.isclose(rs.k2, k2)]
        ax.loglog(r.k0, r.Vc, "-", color="C0", label="RS, D_c (a)")
        ax.loglog(r.k0, r.Vc_dc_vc, "--", color="C3", label="RS, D_c (b)")
        ax.axvline(r.k0_max_rs.iloc[0], color="C0", ls="-.", lw=0.7, label="RS k0_max (a)")
        m = mic[np.isclose(mic.k1, k1) & np.isclose(mic.k2, k2) & (mic.Vc > 0)]
        ax.loglog(m.k0, m.Vc, "o", color="k", ms=3, label="micro, exact")
        ax.loglog(m.k0, m.asymptote, "k:", lw=0.8, label="micro 1/k0 asymptote")
        ax.axvline(k2, color="k", ls="--", lw=0.7, label="micro: V^c → 0 at k0 = k2")
        ax.set_title(f"k1 = {k1:g}, k2 = {k2:g}", fontsize=9)
        ax.set_xlabel("k0")
    axes[0][0].set_ylabel("V^c (stick-slip below, steady above)")
    axes[0][0].set_ylim(1e-3, 1e5)
    axes[0][0].legend(fontsize=6)
    fig.suptitle("Phase diagram (Fig. 5)", fontsize=10)
    return _save(fig, path)


@_figure
def shs(t: dict[str, pd.DataFrame], path: Path) -> Path:
    pts, fit = t["shs_points"], t["shs_fit"]
    trace = t.get("shs_trace")
    models = list(dict.fromkeys(pts.model))
    own = {"micro": "exponential", "RS Eq. (11)": "algebraic", "classical RS Eq. (7)": "logarithmic"}
    extra = 1 if trace is not None else 0
    fig, axes = plt.subplots(1, len(models) + extra, figsize=(4 * (len(models) + extra), 4), squeeze=False)
    if trace is not None:
        ax = axes[0][0]
        sel = trace[(trace.t > -0.3 * trace.hold_time.iloc[0])]
        ax.plot(sel.t, sel.sigma, "-", color="k", lw=0.8)
        ax.axvline(0, color="C3", lw=0.7, ls=":")
        ax.set_xlabel("t (0: the drive restarts)")
        ax.set_ylabel("sigma")
        ax.set_title(f"Fig. 7 (left): micro, hold {trace.hold_time.iloc[0]:g}, V = {trace.V.iloc[0]:g}", fontsize=9)
    for ax, name in zip(axes[0][extra:], models):
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
    axes[0][extra].set_ylabel("peak - steady stress")
    fig.suptitle("Slide-hold-slide (Fig. 7): growth laws (solid: the model's expected law)", fontsize=10)
    return _save(fig, path)


@_figure
def fig3(t: dict[str, pd.DataFrame], path: Path) -> Path:
    d = t["fig3_traces"]
    fig, ax = plt.subplots(figsize=(6.5, 3.8))
    for V, g in d.groupby("V"):
        ax.plot(g.t * V, g.sigma, lw=0.8, label=f"V = {V:g} ({g['method'].iloc[0] if 'method' in g else 'fp'})")
    ax.set_xlabel("drive displacement w = V t")
    ax.set_ylabel("sigma")
    ax.set_title(f"Fig. 3: micro, k0 = {d.k0.iloc[0]:g}, from a start", fontsize=9)
    ax.legend(fontsize=7)
    return _save(fig, path)


@_figure
def fig10(t: dict[str, pd.DataFrame], path: Path) -> Path:
    d = t["fig10_eps"]
    fig, ax = plt.subplots(figsize=(6, 4))
    for i, (k0, g) in enumerate(d.groupby("k0", sort=False)):
        g = g.sort_values("eps")
        ok = _converged(g)
        c = _color(k0, i)
        ax.loglog(g.eps, np.abs(g.error), "-", color=c, lw=0.7)
        e = np.abs(g.error[ok].to_numpy())
        order = (f", order {np.polyfit(np.log(g.eps[ok]), np.log(e), 1)[0]:.2f}"
                 if ok.sum() >= 2 and (e > 0).all() else "")
        ax.loglog(g.eps[ok], e, "o", color=c, label=f"k0 = {k0:g}, V = {g.V.iloc[0]:.3g}{order}")
        ax.loglog(g.eps[~ok], np.abs(g.error[~ok]), "o", color=c, mfc="none")
    eps = np.sort(d.eps.unique())
    ax.set_xticks(eps, [f"{e:g}" for e in eps])
    ax.xaxis.set_minor_locator(plt.NullLocator())
    ax.set_xlabel("bin eps")
    ax.set_ylabel("|sigma_FP - sigma_exact|")
    ax.set_title("Fig. 10: the FP's stress against the bin, V = 1.5 V^c (exact: direct method)\n"
                 "open: not converged (a grid oscillation persists; order fitted on the filled points)", fontsize=8)
    ax.legend(fontsize=7)
    return _save(fig, path)


def target(out, name: str):
    """Where a figure ``name`` goes in the folder ``out``: a
    :class:`~compare.output.ReportFolder` (written atomically) or a plain path."""
    return (out, name) if hasattr(out, "write") else Path(out) / name
