r"""The transition at ``hopf_k0`` (scenario ``hopf``), on both sides.

The one test of how steady sliding loses stability, for both models: the growth rate of
the unstable mode against d = (V^c - V)/V^c (micro's from the shared exact branch, RS's at
a = 0 from :func:`rsf.transition_spectrum`).  Both models' stick-slip amplitude against d,
each against its own exact V^c: micro's default method (the cohort method's cycles, with
their error where it is known) and the N-block at two sizes; RS's cycles with the
asymptote derived from its stick-slip map (:func:`rsf.stick_slip_normal_form`; micro has
none derived yet).  One power law per method (:func:`compare.fits.transition_fits`: its
exponent, confidence interval and the range of d it rests on; only points whose error is
known), :func:`compare.fits.classify_transition`'s evidence, and the verdict as one
paragraph (:func:`verdict`).
"""
from __future__ import annotations

import logging
import math
from pathlib import Path

import numpy as np
import pandas as pd

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
POINT_COLUMNS = ["model", "method", "resolution", "k0", "V", "Vc", "d", "regime", "sigma_max", "sigma_min",
                 "amplitude", "amplitude_stderr", "period", "amplitude_error_kind", "discretisation_error",
                 "sigma_stderr", "converged", "asymptote"]

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
    micro: none derived yet)."""
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
            text.append("none derived" if r.model == "micro" else "")
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


def verdict(s: Settings, t: dict[str, pd.DataFrame], v: dict) -> str:
    """The transition's verdict, one paragraph: how each model loses stability (the one
    test: the unstable mode's growth rate against d), RS's derived amplitude law and
    micro's fitted ones with their ranges and intervals, and where micro's is not settled."""
    tr, rs_tr = v.get("transition", {}), v.get("rs_transition") or {}
    law = v.get("rs_amplitude_law", {})
    fit = t.get("hopf_fit", pd.DataFrame())
    pts = t.get("hopf_points", pd.DataFrame())
    out = []
    micro_div, rs_div = tr.get("growth_diverges"), rs_tr.get("growth_diverges")
    if micro_div and rs_div:
        out.append("At a = 0 both models lose stability at V^c in the same singular way, and neither by a Hopf "
                   "bifurcation: the growth rate of the unstable mode of steady sliding diverges as V → V^c instead "
                   f"of vanishing, micro's from {fmt(tr['growth_far'], 3)} at d = {tr['d_far']:.2g} to "
                   f"{fmt(tr['growth_near'], 3)} at d = {tr['d_near']:.2g} (a real eigenvalue entering from "
                   "infinity where the branching ratio reaches 1), RS's from "
                   f"{fmt(rs_tr['growth_far'], 3)} at d = {rs_tr['d_far']:.2g} to {fmt(rs_tr['growth_near'], 3)} "
                   f"at d = {rs_tr['d_near']:.2g} (the limit a → 0 of the Hopf pair of a > 0, whose frequency grows "
                   "like a^(-1/2); its partner is the instantaneous slip). They differ in the nonlinear mechanism "
                   "that sets the amplitude.")
    else:
        said = []
        for who, x in (("micro", tr), ("RS (a = 0)", rs_tr)):
            if "growth_diverges" in x:
                how = "diverges" if x["growth_diverges"] else "vanishes"
                said.append(f"the growth rate of {who}'s unstable mode {how}"
                            f" as V → V^c ({fmt(x['growth_far'], 3)} at d = {x['d_far']:.2g}, "
                            f"{fmt(x['growth_near'], 3)} at d = {x['d_near']:.2g})")
        if said:
            out.append("By one test, " + "; ".join(said) + ".")
    rs_fit = fit[fit.model == "RS"] if len(fit) else fit
    if math.isfinite(law.get("c0", math.nan)):
        rs = pts[(pts.model == "RS") & pts.fitted.astype(bool)].sort_values("d") if len(pts) else pts
        check = ""
        if len(rs) and math.isfinite(rs.asymptote.iloc[0]):
            dev = abs(rs.amplitude.iloc[0] / rs.asymptote.iloc[0] - 1)
            check = f"; the simulated amplitude differs from it by a relative {dev:.1g} at d = {rs.d.iloc[0]:.2g}"
        out.append("In RS the cycle is a stick and an instantaneous slip, whose return map gives "
                   f"sigma_max − sigma_min = c0 d^(1/2) (1 + c2 d) with c0 = {fmt(law['c0'], 4)} and "
                   f"c2 = {fmt(law['c2'], 3)} (derived, not fitted{check})"
                   + (f"; a power law fitted to it gives {_beta(rs_fit.iloc[0])}" if len(rs_fit) else "") + ".")
    elif len(rs_fit):
        out.append(f"RS's amplitude, fitted: {_beta(rs_fit.iloc[0])}.")
    mf = fit[fit.model == "micro"] if len(fit) else fit
    said = []
    for _, r in mf.iterrows():
        how = ("the cohort method" if r.method == "cohort" else f"the N-block at N = {r.resolution:.0f}"
               if r.method == "N-block" else f"the {r.method} at {_resolution(r, s)}")
        said.append(f"{_beta(r)} by {how} ({int(r.n_points)} points)")
    out.append("In micro the amplitude is set by the size of its shocks: each starts where the branching ratio "
               "reaches 1, at a fold of the creep, and runs to a far root, a drop of about 2 kappa zbar times the "
               "excess branching ratio of the margins beyond the layer the creep has emptied.")
    out.append("It has no single power law (one is rejected at k0 = 0.1 and 0.01): while shocks are total it "
               "depends on k0 V alone and is about linear in d (derived up to a measured memory factor of "
               "0.72-0.92); below a crossover at d of about k0/k2 shocks stop being total, and once a shock moves "
               "only a thin layer of margins a scaling argument makes the amplitude linear in d again, with a "
               "prefactor not derived.")
    out.append("There the unstable mode's time scale is itself proportional to d (derived), and the amplitude, "
               "the loading time and the pre-shock distance from steady sliding all scale with d: constant to 5 % "
               "at k0 = 0.3, d = 0.005-0.02 (A ≈ 0.25 d), and at k0 = 0.1 the local exponent rises from 0.59 at "
               "the crossover to 0.95 at d = 0.001-0.002 (A ≈ 0.63 d) (docs/reference/micro_transition.md, "
               "docs/validation/micro_transition.md).")
    out.append("Fitted: " + "; ".join(said) + "." if said else "No amplitude law could be fitted.")
    if micro_div and rs_div:
        out.append("An exponent near 1/2 is therefore no evidence of a Hopf bifurcation.")
    nb = mf[mf.method == "N-block"] if len(mf) else mf
    each_N = ", ".join(f"{r.beta:.2f} at N = {r.resolution:.0f}" for _, r in nb.iterrows())
    moves = f"; the N-block's exponent moves with N ({each_N})" if len(nb) > 1 else ""
    out.append(f"The cohort method's error bars are bounds (the change from twice its time step and cell, plus "
               "both fixed points' errors), checked against the Richardson limit of two finer levels at k0 = 0.3, "
               f"0.1, 0.01 and 1e-3 down to d = {NEAR_VC:g}, where they cover the true error several times over "
               "(docs/validation/micro_transition.md); closer to V^c they are not known, and at k0 = 0.01, d = 0.01 "
               f"the report's step no longer certifies the fixed point{moves}.")
    return " ".join(out)


def summary(ctx: Context, part: Part) -> list[str]:
    s, t, v = ctx.s, part.tables, part.values
    fit, pts = t["hopf_fit"], t["hopf_points"]
    lines = [f"## The transition at k0 = {s.hopf_k0:g}", "",
             f"**Verdict: both models by one test.** {v['transition_verdict']}", "",
             ("Amplitude sigma_max − sigma_min ∝ d^beta, d = (V^c − V)/V^c with each model's own exact V^c "
              "(table `hopf_fit`; figure `hopf.png`):"), "",
             "| model | method | resolution | beta | 95 % CI | s.e. | d range | points | asymptote |",
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
              f"exact to CVODE's tolerance. Closer to V^c than d = {NEAR_VC:g} the cohort's discretisation error "
              "is not known (the bound is checked only down to there): such points are drawn open "
              "and not fitted" + (f" ({len(near)} here)" if len(near) else " (none here)") + ". The 95 % interval "
              "combines Student's t on the scatter about the line (n − 2 degrees of freedom, so it is wide with few "
              "points) with what the points' error bars can move the slope (column `ci_basis`)."
              + (f" {len(fp)} Fokker-Planck points (eps = {', '.join(f'{e:g}' for e in sorted(set(fp.resolution)))})"
                 " are shown open but not fitted: they are not converged in eps (no study in eps here)."
                 if len(fp) else ""), ""]
    tr = v.get("transition", {})
    if tr.get("text"):
        lines += [tr["text"], ""]
    return lines
