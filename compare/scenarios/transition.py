r"""The transition at ``hopf_k0`` (scenario ``hopf``), on both sides.

The one test of how steady sliding loses stability, for both models: the growth rate of
the unstable mode against d = (V^c - V)/V^c (micro's from the shared exact branch, RS's at
a = 0 from :func:`rsf.transition_spectrum`).  Both models' stick-slip amplitude against d,
each against its own exact V^c: micro's default method (the cohort method's cycles, with
their error where it is known) and the N-block at two sizes; RS's cycles with the
asymptote derived from its stick-slip map (:func:`rsf.stick_slip_normal_form`); micro's
total-shock law derived from its reset model, (R) of docs/reference/micro_transition.md,
where it holds (d >~ k0/k2), and the measured memory factor and linear law of the validation
record, read from the package's data file (:func:`measured_transition`).  One power law per
method (:func:`compare.fits.transition_fits`: its exponent, confidence interval and the range
of d it rests on; only points whose error is known), :func:`compare.fits.classify_transition`'s
evidence, and the verdict as one paragraph of at most :data:`VERDICT_WORDS` words
(:func:`verdict`).
"""
from __future__ import annotations

import logging
import math
from functools import lru_cache
from importlib import resources
from pathlib import Path

import numpy as np
import pandas as pd
from scipy.optimize import brentq

import micro
import rsf
from micro.api import NEAR_VC

from .. import figures, fits
from ..context import Context, micro_frame, sig
from ..params import Settings
from ..rs_side import rs_hopf
from ..summary import fmt
from ..tasks import NBlockTask, StationaryTask, Task
from . import Part

NAME = "hopf"

log = logging.getLogger(__name__)


#: d of RS's spectrum (``rs_spectrum``): the one test's near (1e-6) and far (0.5) ends and a
#: curve between them for the figure (closed forms at a = 0: no cost).
RS_SPECTRUM_D = (1e-6, 1e-5, 1e-4, 1e-3, 1e-2, 0.03, 0.1, 0.2, 0.3, 0.5, 0.7, 0.9)

#: The columns of ``hopf_points`` (the first thirteen are read by other scripts: keep them).
#: ``d_r`` and ``reset_amplitude``: micro's distance to the end of its total-shock branch and
#: the reset model's amplitude (R) there (:func:`reset_amplitude`).
POINT_COLUMNS = ["model", "method", "resolution", "k0", "V", "Vc", "d", "regime", "sigma_max", "sigma_min",
                 "amplitude", "amplitude_stderr", "period", "amplitude_error_kind", "discretisation_error",
                 "sigma_stderr", "converged", "asymptote", "d_r", "reset_amplitude"]

#: The measured constants of micro's transition the report draws, with their provenance in
#: the file's header (the validation study's command and date).
MEASURED_FILE = "micro_transition_measured.csv"


@lru_cache(maxsize=1)
def measured_transition() -> pd.DataFrame:
    """The measured constants of micro's transition shipped with the package
    (``compare/data/micro_transition_measured.csv``; its header names the study's command,
    date and page): ``quantity`` is ``'memory_factor'`` (T/T_r, the loading time over the
    reset model's, against ``d_r``) or ``'amplitude_over_d'`` (the constant A/d of the
    measured linear law deep in the partial-shock regime), at ``k0, d, d_r``."""
    with resources.files("compare").joinpath("data", MEASURED_FILE).open("r", encoding="utf-8") as fh:
        return pd.read_csv(fh, comment="#")


def reset_amplitude(model: micro.Model, V) -> np.ndarray:
    r"""The amplitude of micro's reset model with total shocks, (R) of
    docs/reference/micro_transition.md §3.1:
    :math:`A_r = k_2\bar z\,q\,\tau_r(q)` with :math:`q = V/V^c_r = 1 - d_r`,
    :math:`V^c_r = k_2\gamma\bar z/k_0` (:func:`micro.vc_small_k0`) and :math:`\tau_r` the root
    of :math:`(1 - e^{-\tau})/\tau = q`; :math:`A_r = 2k_2\bar z\,d_r(1 - d_r/3 + O(d_r^2))`.
    Derived for exponential jumps of mean ``zbar`` (``jumps.mean_residual``); NaN where
    :math:`q \notin (0, 1)`.  Micro's cycle is :math:`c_m A_r` while shocks are total
    (d >~ k0/k2), with the memory factor :math:`c_m` measured, not derived.

    Examples
    --------
    >>> import micro
    >>> from compare.scenarios.transition import reset_amplitude
    >>> m = micro.Model(k0=0.001)
    >>> V = 0.99 * micro.vc_small_k0(m)          # d_r = 0.01
    >>> a = float(reset_amplitude(m, V))
    >>> round(a / (2 * m.k2 * 0.1 * 0.01 * (1 - 0.01 / 3)), 4)
    1.0
    """
    zbar = model.jumps.mean_residual
    q = np.atleast_1d(np.asarray(V, dtype=float)) / micro.vc_small_k0(model)
    out = np.full(q.shape, math.nan)
    for i, qi in enumerate(q):
        if 0.0 < qi < 1.0:
            tau = brentq(lambda t: -math.expm1(-t) / t - qi, 1e-12, 2.0 / qi + 50.0, xtol=1e-14, rtol=1e-13)
            out[i] = model.k2 * zbar * qi * tau
    return out if np.ndim(V) else out[0]


def micro_laws(model: micro.Model, vc: float, d_max: float, n: int = 60) -> pd.DataFrame:
    """Micro's amplitude laws on a d grid, for ``hopf.png`` and the table ``hopf_micro_laws``:
    the reset model's total-shock law (R) from d = k0/k2 (where shocks become total) to
    ``d_max`` (``law = 'reset (R), derived'``), the same times the memory factor measured
    at small k0 (interpolated in d_r over its measured range only; ``'reset (R) x measured
    memory factor'``), and the measured linear law A = (A/d) d at this k0 over the d it was
    measured at, if the package's data has it (``'linear, measured'``).  Columns ``law, d,
    d_r, amplitude, source``."""
    k0 = model.k0
    vcr = micro.vc_small_k0(model)
    rows = []
    d0 = k0 / model.k2
    if vc > 0 and d_max > d0:
        d = np.geomspace(d0, d_max, n)
        V = vc * (1.0 - d)
        d_r = 1.0 - V / vcr
        a_r = reset_amplitude(model, V)
        rows.append(pd.DataFrame({"law": "reset (R), derived", "d": d, "d_r": d_r, "amplitude": a_r,
                                  "source": "docs/reference/micro_transition.md (R)"}))
        m = measured_transition()
        cm = m[m.quantity == "memory_factor"].groupby("d_r", as_index=False).value.mean().sort_values("d_r")
        inside = (d_r >= cm.d_r.min()) & (d_r <= cm.d_r.max())
        if inside.any():
            c = np.interp(np.log(d_r[inside]), np.log(cm.d_r.to_numpy()), cm.value.to_numpy())
            rows.append(pd.DataFrame({"law": "reset (R) x measured memory factor", "d": d[inside],
                                      "d_r": d_r[inside], "amplitude": c * a_r[inside],
                                      "source": f"compare/data/{MEASURED_FILE}"}))
    lin = measured_transition()
    lin = lin[(lin.quantity == "amplitude_over_d") & np.isclose(lin.k0, k0, rtol=1e-9)]
    if len(lin) and vc > 0:
        d = np.geomspace(float(lin.d.min()), float(lin.d.max()), 10)
        rows.append(pd.DataFrame({"law": "linear, measured", "d": d, "d_r": 1.0 - vc * (1.0 - d) / vcr,
                                  "amplitude": float(lin.value.mean()) * d,
                                  "source": f"compare/data/{MEASURED_FILE}"}))
    return pd.concat(rows, ignore_index=True) if rows else pd.DataFrame(columns=["law", "d", "d_r", "amplitude",
                                                                               "source"])

#: The order of ``hopf_fit``'s rows: RS, then micro's default (the cohort), the N-block by N, the FP.
_ORDER = {("RS", "CVODE"): 0, ("micro", "cohort"): 1, ("micro", "N-block"): 2, ("micro", "fp"): 3, ("micro", "FP"): 3}


def wanted(settings: Settings) -> bool:
    return NAME in settings.scenarios


def vc_k0(ctx: Context) -> list[float]:
    return [ctx.s.hopf_k0]


def tasks(ctx: Context) -> list[Task]:
    return _cycle_tasks(ctx) + _nblock_tasks(ctx)


def _cycle_tasks(ctx: Context) -> list[StationaryTask]:
    """The transition's cycles by micro's default (``cycle_method``), one per distance."""
    s = ctx.s
    vc = ctx.Vc(s.hopf_k0)
    if not vc > 0:  # (NaN: no stick-slip)
        return []
    return [ctx.cycle_task(s.hopf_k0, sig(vc * (1 - d))) for d in s.hopf_distances]


def _nblock_tasks(ctx: Context) -> list[NBlockTask]:
    s = ctx.s
    vc = ctx.Vc(s.hopf_k0)
    if not vc > 0:  # (NaN: no stick-slip)
        return []
    return [NBlockTask(ctx.model(s.hopf_k0), sig(vc * (1 - d)), int(N), n_cycles=s.nblock_cycles,
                       n_discard=s.nblock_discard) for N in s.nblock_N for d in s.nblock_distances]


def cycle_errors(frame: pd.DataFrame) -> pd.DataFrame:
    """``frame`` (micro's cycles, as from :func:`micro.stationary`) with the error bar of
    each amplitude, ``amplitude_stderr``, and how it is known, ``amplitude_error_kind``.

    The bar is twice the sum of the row's ``discretisation_error`` and ``sigma_stderr``
    (each extremum's error, both extrema): a ``'bound'`` where the discretisation error
    is known (the cohort method at d >= ``micro.api.NEAR_VC``), ``'not known'`` (NaN)
    where it is not: the cohort closer to V^c, and every Fokker-Planck row (micro's
    fallback where the cohort method does not apply, or ``cycle_method='fp'``), which has
    no study in eps here, so that no FP point enters a fit unless it is converged in eps.
    """
    f = frame.copy()
    disc = f.discretisation_error if "discretisation_error" in f else pd.Series(math.nan, index=f.index)
    stderr = f.sigma_stderr if "sigma_stderr" in f else pd.Series(math.nan, index=f.index)
    f["amplitude_stderr"] = 2.0 * (disc.astype(float) + stderr.astype(float))
    f["amplitude_error_kind"] = np.where(np.isfinite(f.amplitude_stderr), "bound", "not known")
    return f


def run(ctx: Context) -> Part:
    """The transition at ``hopf_k0``: micro's spectrum and its stick-slip amplitude
    against (V^c - V)/V^c (micro's default method, the cohort's cycles with their
    error where it is known; the N-block at two sizes) next to RS's spectrum, amplitude
    and derived asymptote, each against its own V^c; the fits (``hopf_fit``) and the
    verdict (``values['transition_verdict']``)."""
    s = ctx.s
    part = Part()
    k0 = s.hopf_k0
    vc = ctx.Vc(k0)
    rows = []
    cyc, nb = _cycle_tasks(ctx), _nblock_tasks(ctx)
    f = micro_frame(ctx.run(cyc, "micro amplitude"))
    if len(f):
        f["resolution"] = f["eps"]
        rows.append(cycle_errors(f))
    for N in s.nblock_N:
        tasks_N = [t for t in nb if t.n_blocks == N]
        recs = ctx.run(tasks_N, "micro amplitude (N-block)")
        f = pd.DataFrame([{**(r.get("result") or {"V": t.V, "regime": "failed"}), "error": r.get("error", "")}
                          for t, r in zip(tasks_N, recs)])
        f["method"], f["resolution"] = "N-block", float(N)
        rows.append(f)
    rows = [f for f in rows if len(f)]
    micro_pts = pd.concat(rows, ignore_index=True) if rows else pd.DataFrame()
    if len(micro_pts):
        micro_pts["model"], micro_pts["k0"], micro_pts["Vc"] = "micro", k0, vc
        micro_pts["d"] = 1.0 - micro_pts.V / vc
        micro_pts["amplitude"] = micro_pts.sigma_max - micro_pts.sigma_min
        nb_rows = micro_pts.method == "N-block"
        if "sigma_max_stderr" in micro_pts:
            micro_pts.loc[nb_rows, "amplitude_stderr"] = np.hypot(micro_pts.sigma_max_stderr,
                                                                  micro_pts.sigma_min_stderr)[nb_rows]
        micro_pts.loc[nb_rows, "amplitude_error_kind"] = np.where(
            np.isfinite(micro_pts.amplitude_stderr[nb_rows].astype(float)), "standard error", "not known")
        micro_pts["d_r"] = 1.0 - micro_pts.V / micro.vc_small_k0(ctx.model(k0))
        micro_pts["reset_amplitude"] = reset_amplitude(ctx.model(k0), micro_pts.V.to_numpy(float))
    model = rsf.SpringSlider(law=ctx.law_for(k0), k0=k0, Dc=ctx.Dc)
    rs = rs_hopf(model, s.rs_hopf_distances)
    rs["model"], rs["k0"], rs["method"], rs["resolution"] = "RS", k0, "CVODE", math.nan
    rs["amplitude_error_kind"] = "solver tolerance"
    # RS by the same test as micro (the growth rate of the unstable mode against d), and its
    # amplitude law from the stick-slip map (rsf.normal_form: sigma_max - sigma_min =
    # c0 d^(1/2) (1 + c2 d), derived, not fitted)
    c0 = c2 = math.nan
    try:
        rs_spec = rsf.transition_spectrum(model, RS_SPECTRUM_D)
        part.tables["rs_spectrum"] = rs_spec
        part.values["rs_transition"] = rsf.classify_spectrum(rs_spec)
        nf = rsf.stick_slip_normal_form(model)
        c0, c2 = float(nf.prefactor), float(nf.correction)
        part.values["rs_amplitude_law"] = {"c0": c0, "c2": c2}
    except ValueError as exc:  # (no finite RS V^c at this k0 and D_c)
        log.warning("RS transition at k0 = %g: %s", k0, exc)
    rs["asymptote"] = c0 * np.sqrt(rs.d) * (1.0 + c2 * rs.d)
    points = pd.concat([micro_pts, rs], ignore_index=True).reindex(columns=POINT_COLUMNS)
    points["amplitude_error_kind"] = points.amplitude_error_kind.fillna("not known")
    points["fitted"] = ((points.regime == "stick-slip") & (points.amplitude > 0)
                        & (points.amplitude_error_kind != "not known"))
    part.tables["hopf_points"] = points
    shown = points.d[(points.model == "micro") & (points.regime == "stick-slip") & (points.amplitude > 0)]
    part.tables["hopf_micro_laws"] = micro_laws(ctx.model(k0), vc, float(shown.max()) if len(shown) else 0.0)
    part.tables["hopf_fit"] = _fit_table(points)
    b = ctx.branch
    spec = b[(b.role == "branch") & np.isclose(b.k0, k0) & (b.V < vc)].sort_values("V")
    part.tables["micro_spectrum"] = spec[["k0", "V", "Vc", "branching_ratio", "stable", "growth_rate"]].assign(
        d=1.0 - spec.V / vc,
        growth_rate_asymptote=micro.growth_rate_near_vc(ctx.model(k0), spec.branching_ratio.to_numpy(float)))
    part.values["transition"] = fits.classify_transition(part.tables["micro_spectrum"], part.tables["hopf_fit"],
                                                         points)
    part.values["transition_verdict"] = verdict(s, part.tables, part.values)
    return part


def _fit_table(points: pd.DataFrame) -> pd.DataFrame:
    """``hopf_fit``: one row per method (:func:`compare.fits.transition_fits`), in the
    order RS, micro's cohort, the N-block by N, the FP; with each model's V^c and its
    asymptote (RS: derived, and the simulated amplitude over it at the smallest fitted d;
    micro: the reset model's total-shock law, derived where shocks are total, off by a
    measured memory factor; ``hopf_micro_laws``)."""
    fit = fits.transition_fits(points)
    if not len(fit):
        return fit
    fit.insert(3, "Vc_mode", np.where(fit.model == "micro", "exact (direct)", "exact (linear stability)"))
    key = [_ORDER.get((m, k), 9) for m, k in zip(fit.model, fit.method)]
    fit = fit.assign(_key=key).sort_values(["_key", "resolution"], kind="stable").drop(columns="_key")
    fit = fit.reset_index(drop=True)
    ratio, text = [], []
    for _, r in fit.iterrows():
        grp = points[(points.model == r.model) & (points.method == r.method) & points.fitted.astype(bool)
                     & ((points.resolution == r.resolution) | (points.resolution.isna() & pd.isna(r.resolution)))]
        near = grp.sort_values("d").iloc[0] if len(grp) else None
        if r.model == "RS" and near is not None and math.isfinite(near.asymptote):
            ratio.append(float(near.amplitude / near.asymptote))
            text.append("c0 d^(1/2) (1 + c2 d), derived")
        else:
            ratio.append(math.nan)
            text.append("reset model (R) derived for d >~ k0/k2, times a measured memory factor"
                        if r.model == "micro" else "")
    fit["asymptote"], fit["asymptote_ratio_at_d_min"] = text, ratio
    return fit


def draw(ctx: Context, part: Part, out) -> dict[str, Path]:
    t, v = part.view(ctx)
    return {"hopf": figures.hopf(t, v, figures.target(out, "hopf.png"))}


def _resolution(r, s: Settings) -> str:
    """A fit row's or point's resolution as text (N, the cohort's cell and step, the FP's bin)."""
    res = float(r.resolution)
    if not math.isfinite(res):
        return ""
    if r.method == "N-block":
        return f"N = {res:.0f}"
    if r.method == "cohort":
        return f"h = {res:.3g}, dt = {s.cycle_dt:g}"
    return f"eps = {res:g}"


def _beta(r) -> str:
    """beta and its interval, for a sentence."""
    return (f"beta = {r.beta:.2f} ({100 * r.ci_level:.0f} % CI {r.beta_low:.2f} to {r.beta_high:.2f}) over "
            f"d = {fmt(r.d_min, 2)} to {fmt(r.d_max, 2)}")


#: The most words :func:`verdict` may take: a paragraph a physicist can quote.
VERDICT_WORDS = 150


def memory_ratio(points: pd.DataFrame, k0: float, k2: float) -> tuple[float, float, int]:
    """(smallest, largest, count) of micro's cohort amplitude over the reset model's (R)
    at the fitted cohort points where shocks are total (d >= k0/k2): the memory factor
    at this k0, as this run measures it (NaN, NaN, 0 if none)."""
    if not len(points) or "reset_amplitude" not in points:
        return math.nan, math.nan, 0
    c = points[(points.model == "micro") & (points.method == "cohort") & points.fitted.astype(bool)
               & (points.d >= k0 / k2)]
    r = (c.amplitude / c.reset_amplitude).to_numpy(float)
    r = r[np.isfinite(r)]
    return (float(r.min()), float(r.max()), int(r.size)) if r.size else (math.nan, math.nan, 0)


def verdict(s: Settings, t: dict[str, pd.DataFrame], v: dict) -> str:
    """The transition's verdict, one paragraph of at most :data:`VERDICT_WORDS` words, every
    number computed in this run: how each model loses stability (the one test, the unstable
    mode's growth rate against d), RS's derived amplitude law and how its simulation meets
    it, micro's cycles against its derived total-shock law (the memory factor) and the
    single power law fitted to them; the derivation is named by its page."""
    tr, rs_tr = v.get("transition", {}), v.get("rs_transition") or {}
    law = v.get("rs_amplitude_law", {})
    fit = t.get("hopf_fit", pd.DataFrame())
    pts = t.get("hopf_points", pd.DataFrame())
    out = []

    def growth(x: dict) -> str:
        return (f"{fmt(x['growth_far'], 3)} at d = {x['d_far']:.2g} to {fmt(x['growth_near'], 3)} at "
                f"d = {x['d_near']:.2g}")

    micro_div, rs_div = tr.get("growth_diverges"), rs_tr.get("growth_diverges")
    if micro_div and rs_div:
        out.append("At a = 0 both models lose stability at V^c the same singular way, not by a Hopf bifurcation: "
                   f"the unstable mode's growth rate diverges at V^c (micro: {growth(tr)}; RS: {growth(rs_tr)}).")
    else:
        said = [f"{who}'s growth rate {'diverges' if x['growth_diverges'] else 'vanishes'} as V → V^c "
                f"({growth(x)})" for who, x in (("micro", tr), ("RS", rs_tr)) if "growth_diverges" in x]
        if said:
            out.append("By one test, " + "; ".join(said) + ".")
    if math.isfinite(law.get("c0", math.nan)):
        rs = pts[(pts.model == "RS") & pts.fitted.astype(bool)].sort_values("d") if len(pts) else pts
        check = ""
        if len(rs) and math.isfinite(rs.asymptote.iloc[0]):
            dev = abs(rs.amplitude.iloc[0] / rs.asymptote.iloc[0] - 1)
            check = f" (simulation within {dev:.1g} at d = {rs.d.iloc[0]:.2g})"
        out.append("RS's amplitude follows its derived law c0 d^(1/2) (1 + c2 d), "
                   f"c0 = {fmt(law['c0'], 4)}, c2 = {fmt(law['c2'], 3)}{check}.")
    lo, hi, n = memory_ratio(pts, s.hopf_k0, s.k2)
    total = (f": above d = k0/k2 = {s.hopf_k0 / s.k2:.2g} (total shocks) the {n} cycles lie at {fmt(lo, 2)}-"
             f"{fmt(hi, 2)} times the reset model's derived law (memory and O(k0) effects); below, it crosses over"
             if n else ": it crosses over at d of about k0/k2")
    out.append("Micro's amplitude follows no single power law" + total
               + " (docs/reference/micro_transition.md).")
    mf = fit[(fit.model == "micro") & (fit.method == "cohort")] if len(fit) else fit
    if len(mf):
        r = mf.iloc[0]
        out.append(f"A power law fitted to the cohort's {int(r.n_points)} points gives {_beta(r)}"
                   + (": an exponent near 1/2 is no evidence of a Hopf bifurcation." if micro_div and rs_div
                      else "."))
    return " ".join(out)


def summary(ctx: Context, part: Part) -> list[str]:
    s, t, v = ctx.s, part.tables, part.values
    fit, pts = t["hopf_fit"], t["hopf_points"]
    level = f"{100 * float(fit.ci_level.iloc[0]):.0f} %" if len(fit) else "the"
    lines = [f"## The transition at k0 = {s.hopf_k0:g}", "",
             f"**Verdict: both models by one test.** {v['transition_verdict']}", "",
             ("Amplitude sigma_max − sigma_min ∝ d^beta, d = (V^c − V)/V^c with each model's own exact V^c "
              "(table `hopf_fit`; figure `hopf.png`):"), "",
             f"| model | method | resolution | beta | {level} CI | s.e. | d range | points | asymptote |",
             "|---|---|---|---|---|---|---|---|---|"]
    for _, r in fit.iterrows():
        lines.append(f"| {r.model} | {r.method} | {_resolution(r, s)} | {fmt(r.beta, 3)} | "
                     f"{r.beta_low:.2f} to {r.beta_high:.2f} | {fmt(r.exponent_err, 2)} | {fmt(r.d_min, 2)} to "
                     f"{fmt(r.d_max, 2)} | {int(r.n_points)} | {r.asymptote} |")
    unknown = pts[(pts.model == "micro") & (pts.regime == "stick-slip") & ~pts.fitted.astype(bool)]
    fp = unknown[unknown.method.astype(str).str.lower() == "fp"]
    near = unknown[unknown.method == "cohort"]
    lines += ["", "A fit rests only on points whose error is known: the cohort method's bars are bounds (twice the "
              "sum of its discretisation error, the change from twice the time step and cell, and its fixed-point "
              "error), the N-block's standard errors (the N-block sizes differ by their finite-N error), RS is "
              f"exact to CVODE's tolerance. Closer to V^c than d = {NEAR_VC:g} (micro.api.NEAR_VC) the cohort's "
              "discretisation error is not known: such points are drawn open and not fitted"
              + (f" ({len(near)} here)" if len(near) else " (none here)") + ". How far down in d the bound is "
              "checked at each k0 is stated, with its command, in docs/validation/micro_transition.md (section 1; "
              "`python -m studies micro_transition_error_check`). The interval combines Student's t on the "
              "scatter about the line (n − 2 degrees of freedom, so it is wide with few points) with what the "
              "points' error bars can move the slope (column `ci_basis`)."
              + (f" {len(fp)} Fokker-Planck points (eps = {', '.join(f'{e:g}' for e in sorted(set(fp.resolution)))})"
                 " are shown open but not fitted: they are not converged in eps (no study in eps here)."
                 if len(fp) else ""), ""]
    lines += _laws_summary(s, t)
    tr = v.get("transition", {})
    if tr.get("text"):
        lines += [tr["text"], ""]
    return lines


def _laws_summary(s: Settings, t: dict[str, pd.DataFrame]) -> list[str]:
    """What ``hopf.png`` draws for micro besides its points, with where each law comes from."""
    laws = t.get("hopf_micro_laws")
    if laws is None or not len(laws):
        return []
    said = []
    r = laws[laws.law == "reset (R), derived"]
    if len(r):
        said.append(f"the reset model's total-shock law (R), A_r = k2 zbar q tau_r(q) ≈ 2 k2 zbar d_r (1 − d_r/3) "
                    "with d_r = 1 − k0 V/(k2 gamma zbar), derived (docs/reference/micro_transition.md, "
                    f"section 3.1), "
                    f"from d = k0/k2 = {fmt(r.d.min(), 3)}, where shocks become total, to d = {fmt(r.d.max(), 2)}")
    m = laws[laws.law == "reset (R) x measured memory factor"]
    if len(m):
        said.append(f"the same times the memory factor c_m measured at small k0 (d_r = {fmt(m.d_r.min(), 2)} to "
                    f"{fmt(m.d_r.max(), 2)} here), not derived")
    lin = laws[laws.law == "linear, measured"]
    if len(lin):
        c = float((lin.amplitude / lin.d).mean())
        said.append(f"the linear law deep in the partial-shock regime, A = {fmt(c, 2)} d, "
                    f"measured at d = {fmt(lin.d.min(), 2)} to {fmt(lin.d.max(), 2)} (prefactor not derived)")
    return ["`hopf.png` also draws micro's laws (table `hopf_micro_laws`): " + "; ".join(said) + ". The measured "
            f"constants come from `compare/data/{MEASURED_FILE}`, whose header names the study, its command "
            "(`python -m studies micro_transition_fits`) and its date; the page is docs/validation/"
            "micro_transition.md (sections 3 and 4).", ""]
