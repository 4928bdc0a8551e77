r"""The bifurcation diagrams (Figs. 4/8), V^c(k0) of both models and D_c two ways.

Micro's exact steady branch and its stick-slip points (those that D_c (a) is fitted to,
and ``shown_points``, where the fitted D_c is a prediction) against RS with the fitted
Eq. (10) and D_c; micro's exact V^c at every k0 against RS's with D_c (a), D_c (b) and
the paper's constants.  This scenario also shows the shared stages' figures (the Eq. (10)
fit, the D_c profile) in its place and writes the D_c paragraph of the summary.
"""
from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pandas as pd

import rsf

from .. import figures, fits
from ..context import SHARED_FIGURES, Context
from ..params import PAPER_K0, Settings
from ..rs_side import rs_curves
from ..summary import fmt, pct
from ..tasks import Task, VcTask
from . import Part

NAME = "bifurcation"
PRESENTS = ("steady_fit", "dc_profile", "Dc")


def wanted(settings: Settings) -> bool:
    return NAME in settings.scenarios


def vc_k0(ctx: Context) -> list[float]:
    s = ctx.s
    return list(s.fp_k0) + [k for k, _ in s.shown_points]


def tasks(ctx: Context) -> list[Task]:
    """Micro's V^c along the V^c(k0) curve, and the stick-slip points only shown."""
    s = ctx.s
    return [VcTask(ctx.model(k0)) for k0 in ctx.phase_k0(s.k2)] + ctx.cycle_tasks(s.shown_points)


def run(ctx: Context) -> Part:
    s = ctx.s
    part = Part()
    ctx.steady_fit
    if ctx.Dc_given is None:
        ctx.dc_fit
    if s.shown_points:
        part.tables["micro_shown_points"] = ctx.points(s.shown_points, "shown")
    crit = _critical_table(ctx, part)
    if ctx.Dc_given is None:
        ctx.dc_per_k0
    Dc = ctx.Dc

    def V_range(k0: float) -> tuple[float, float]:
        vc = ctx.rs_vc(k0)
        hi = 5.0 * vc if math.isfinite(vc) else 10.0
        return 1e-3, max(hi, 10.0, 3.0 * float(crit.Vc_micro[np.isclose(crit.k0, k0)].max()))

    curves = rs_curves(sorted(set(PAPER_K0) | set(s.k0), reverse=True), ctx.law_for, Dc, V_range=V_range,
                       n=s.rs_points, label="fitted Dc")
    part.tables["rs_bifurcation"] = curves
    lower = {k0: rsf.critical_velocity(ctx.law_for(k0), k0, Dc).V_lower for k0 in curves.k0.unique()}
    part.tables["rs_unstable_band"] = pd.DataFrame(
        [{"k0": k, "V_lower": v, "Vc": ctx.rs_vc(k)} for k, v in lower.items()])
    # the RS V^c curve of each D_c and micro's, over k0 (the set of Figs. 4/8)
    rows = []
    for k0 in ctx.phase_k0(s.k2):
        law = ctx.law_for(k0)
        rows.append({"k0": k0, "Vc_micro": ctx.Vc(k0),
                     "Vc_rs": rsf.critical_velocity(law, k0, Dc).Vc,
                     "Vc_rs_dc_vc": rsf.critical_velocity(law, k0, ctx.dc_critical.Dc).Vc,
                     "Vc_rs_paper": s.rs_paper_vc(k0)})
    part.tables["vc_curves"] = pd.DataFrame(rows)
    return part


def _critical_table(ctx: Context, part: Part) -> pd.DataFrame:
    """Micro's exact V^c against RS's with each D_c, per k0 (``critical_velocity.csv``)."""
    frame = ctx.critical.copy()
    dcv = ctx.dc_critical
    frame["Vc_rs"] = [ctx.rs_vc(k) for k in frame.k0]
    frame["Vc_rs_dc_vc"] = [ctx.rs_vc(k, dcv.Dc) for k in frame.k0]
    frame["Vc_rs_paper"] = [ctx.s.rs_paper_vc(k) for k in frame.k0]
    frame["rel_diff_rs"] = frame.Vc_rs / frame.Vc_micro - 1.0
    frame["rel_diff_rs_dc_vc"] = frame.Vc_rs_dc_vc / frame.Vc_micro - 1.0
    per = dcv.per_k0.set_index("k0")
    frame["Dc_match"] = [float(per.Dc_law.get(k, math.nan)) for k in frame.k0]
    frame["Dc_match_exact_slope"] = [float(per.Dc_exact_slope.get(k, math.nan)) for k in frame.k0]
    frame["Dc"] = ctx.Dc
    frame["Dc_vc"] = dcv.Dc
    part.tables["critical_velocity"] = frame
    if ctx.Dc_given is None:
        # what D_c (b) implies for the extrema that D_c (a) was fitted to
        # (the same misfit as D_c (a)'s: the extrema where both models are in stick-slip)
        pts = ctx.dc_fit.points
        rs = fits.rs_diagram(pts, ctx.law_for, dcv.Dc)
        both = (pts.regime_micro.to_numpy() == "stick-slip") & (rs.regime.to_numpy() == "stick-slip")
        r = np.concatenate([(rs.sigma_max.to_numpy() - pts.sigma_max_micro.to_numpy())[both],
                            (rs.sigma_min.to_numpy() - pts.sigma_min_micro.to_numpy())[both]])
        part.values["Dc_vc_extrema_rms"] = float(np.sqrt(np.mean(r * r))) if r.size else math.nan
        part.values["Dc_vc_n_stick_slip"] = int(both.sum())
        part.values["Dc_vc_regime_agreement"] = float(np.mean(rs.regime.to_numpy() == pts.regime_micro.to_numpy()))
    return frame


def draw(ctx: Context, part: Part, out) -> dict[str, Path]:
    t, v = part.view(ctx)
    figs = {"bifurcation": figures.bifurcation(t, ctx.Dc, ctx.s.fp_k0, figures.target(out, "bifurcation.png"))}
    for name in SHARED_FIGURES:
        path = ctx.figure(name, out)
        if path is not None:
            figs[name] = path
    figs["critical_velocity"] = figures.critical_velocity(t, v, figures.target(out, "critical_velocity.png"))
    return figs


def summary(ctx: Context, part: Part) -> list[str]:
    t, v = part.view(ctx)
    return _critical(t) + _dc(ctx, t, v) + _bifurcation(ctx, t)


def _critical(t) -> list[str]:
    crit = t["critical_velocity"]
    rel = (crit.Vc_micro_err / crit.Vc_micro).to_numpy(float)
    rel = rel[np.isfinite(rel)]
    err = f"relative error at most {fmt(float(rel.max()), 2)}" if rel.size else "error not known"
    lines = ["## Critical velocity per k0", "",
             f"Micro: exact (the root of branching ratio = 1; {err}); RS: linear stability "
             "with the fitted law and each D_c.", "",
             "| k0 | V^c micro | small-k0 asymptote | V^c RS, D_c (a) | V^c RS, D_c (b) | V^c RS (paper's law, D_c) |",
             "|---|---|---|---|---|---|"]

    def rs(vc, rel):
        return "none (steady at every V)" if not math.isfinite(vc) else f"{fmt(vc)} ({pct(rel)})"

    for _, r in t["critical_velocity"].iterrows():
        lines.append(f"| {r.k0:g} | {fmt(r.Vc_micro, 8)} | {fmt(r.Vc_micro_small_k0)} | {rs(r.Vc_rs, r.rel_diff_rs)} | "
                     f"{rs(r.Vc_rs_dc_vc, r.rel_diff_rs_dc_vc)} | {rs(r.Vc_rs_paper, math.nan).split(' (')[0]} |")
    lines.append("")
    return lines


def _dc(ctx: Context, t, v) -> list[str]:
    lines = ["## D_c two ways", ""]
    s = ctx.s
    dcv = ctx.dc_critical
    rows = ["| method | D_c | interval | what it matches | what it implies for the other |",
            "|---|---|---|---|---|"]
    crit = t.get("critical_velocity")
    if "Dc" in v:
        lo, hi = v["Dc_profile"]
        factor = v["Dc_profile_factor"]
        profile = f"misfit within a factor {factor:.3g} of its minimum: [{fmt(lo, 3)}, {fmt(hi, 3)}]"
        if v.get("Dc_one_sided"):
            bound = "≤" if v["Dc_one_sided"] == "upper" else "≥"
            interval = (f"one-sided: D_c {bound} {fmt(v['Dc_switch'], 4)} (the optimum sits on a point's regime "
                        f"switch); {profile}")
        else:
            interval = f"± {fmt(v['Dc_err'], 2)} (bootstrap 16-84 %); {profile}"
        implied = ""
        if crit is not None:
            c = crit[np.isfinite(crit.rel_diff_rs)]
            implied = ("RS V^c off micro's by " + ", ".join(f"{pct(r)} (k0 = {k:g})"
                                                           for k, r in zip(c.k0, c.rel_diff_rs)))
            none = crit[~np.isfinite(crit.Vc_rs)]
            if len(none):
                implied += "; no RS stick-slip at all at k0 = " + ", ".join(f"{k:g}" for k in none.k0)
        pts = t["dc_points"]
        n_cyc = int((pts.regime_micro == "stick-slip").sum())
        rows.append(f"| (a) stick-slip extrema | {fmt(v['Dc'])} | {interval} | sigma_max, sigma_min where both models "
                    f"are in stick-slip: {v['Dc_n_stick_slip']} of micro's {n_cyc} cycles at k0 = "
                    f"{', '.join(f'{k:g}' for k in s.fp_k0)} (rms {fmt(v['Dc_rms'], 3)}) | {implied} |")
    elif ctx.Dc_given is not None:
        rows.append(f"| given | {ctx.Dc_given:g} | | | |")
    implied_b = ""
    if "Dc_vc_extrema_rms" in v:
        implied_b = (f"extrema rms {fmt(v['Dc_vc_extrema_rms'], 3)} over the {v['Dc_vc_n_stick_slip']} points in "
                     f"stick-slip in both (against {fmt(v['Dc_rms'], 3)} at (a)); regime agreement "
                     f"{100 * v['Dc_vc_regime_agreement']:.0f} %")
    rows.append(f"| (b) V^c matching | {fmt(dcv.Dc)} | ± {fmt(dcv.Dc_err, 2)} (standard error); per-k0 values "
                f"{fmt(dcv.Dc_range[0], 3)} to {fmt(dcv.Dc_range[1], 3)} | micro's exact V^c at "
                f"{len(dcv.per_k0)} k0 (rms {100 * dcv.rms_log:.1f} % in V^c) | {implied_b} |")
    lines += rows + [""]
    if "Dc" in v:
        lines += _regimes(t, v)
    per = dcv.per_k0
    lines += ["Per k0, k0 D_c = W(V^c) = −V dmu_ss/dV at micro's exact V^c, with the fitted law's slope and with "
              "micro's own:", "", "| k0 | V^c micro | D_c (law) | D_c (micro's slope) |", "|---|---|---|---|"]
    for _, r in per.iterrows():
        lines.append(f"| {r.k0:g} | {fmt(r.Vc_micro, 6)} | {fmt(r.Dc_law)} | {fmt(r.Dc_exact_slope)} |")
    lines.append("")
    if "Dc" in v:
        a, b = v["Dc"], dcv.Dc
        lo_a, hi_a = v["Dc_profile"]
        lo_b, hi_b = dcv.Dc_range
        if lo_a <= hi_b and lo_b <= hi_a:
            lines.append(f"**The two D_c overlap**: (a) = {fmt(a)} with its interval [{fmt(lo_a, 3)}, {fmt(hi_a, 3)}] "
                         f"meets (b)'s per-k0 range [{fmt(lo_b, 3)}, {fmt(hi_b, 3)}] ((a)/(b) = {fmt(a / b, 3)}).")
        else:
            lines.append(f"**The two D_c disagree**: (a) = {fmt(a)} from the stick-slip extrema, interval "
                         f"[{fmt(lo_a, 3)}, {fmt(hi_a, 3)}], (b) = {fmt(b)} from V^c, per-k0 range "
                         f"[{fmt(lo_b, 3)}, {fmt(hi_b, 3)}]; with (a) RS misplaces micro's V^c by up to "
                         f"{pct(float(crit.rel_diff_rs.abs().max()))}: one RS law with one D_c cannot carry both "
                         "micro's cycle amplitudes and its stability boundary.")
        lines.append("")
    per_a = t.get("dc_per_k0")
    if per_a is not None and len(per_a) > 1:
        lines += _per_k0(per_a)
    lines.append("Figure `critical_velocity.png`: V^c(k0) of micro (exact) and of RS with each D_c; `dc_profile.png`: "
                 "the misfit against D_c, all k0 and each alone, with every point's regime switch (tables "
                 "`dc_profile`, `dc_profile_per_k0`).")
    lines.append("")
    return lines


def _regimes(t, v) -> list[str]:
    """Regime agreement at D_c (a), apart from the misfit: the points whose regimes differ."""
    pts = t["dc_points"]
    bad = pts[~pts.regime_agrees.astype(bool)]
    head = (f"Regime agreement at D_c (a), apart from the misfit: {len(pts) - len(bad)} of {len(pts)} micro points "
            f"(stick-slip and steady) have RS's regime")
    if not len(bad):
        return [head + ".", ""]
    vc = t["critical_velocity"].set_index("k0").Vc_micro
    lines = [head + "; these do not (RS is in stick-slip at a point for D_c below its switch W(V)/k0):", "",
             "| k0 | V / V^c | micro | RS | switch W(V)/k0 |", "|---|---|---|---|---|"]
    for _, r in bad.iterrows():
        lines.append(f"| {r.k0:g} | {fmt(r.V / float(vc.get(r.k0, math.nan)), 3)} | {r.regime_micro} | "
                     f"{r.regime_rs} | {fmt(r.Dc_switch, 4)} |")
    return lines + [""]


def _per_k0(per_a) -> list[str]:
    """D_c (a) at each k0 alone, with its interval, and the (a)/(b) ratio explained."""
    lines = ["D_c (a) fitted at each k0 alone beside D_c (b) at that k0 (`dc_per_k0.csv`); the interval is the D_c "
             "range where that k0's misfit stays within the stated factor, 1 + 1/(n − 1) for its n points in the "
             "misfit, of its minimum:", "",
             "| k0 | micro cycles | in the misfit | D_c (a) alone | interval | factor | rms | regime disagreements | "
             "D_c (b) | (a)/(b) | small-k0 closed form of (a) | its ratio to (b) |",
             "|---|---|---|---|---|---|---|---|---|---|---|---|"]
    for _, r in per_a.iterrows():
        side = f" ({r.one_sided} bound)" if isinstance(r.one_sided, str) and r.one_sided else ""
        lines.append(f"| {r.k0:g} | {int(r.n_cycles)} | {int(r.n_stick_slip)} | {fmt(r.Dc_a)}{side} | "
                     f"[{fmt(r.Dc_a_lo, 3)}, {fmt(r.Dc_a_hi, 3)}] | {r.profile_factor:.3g} | {fmt(r.rms_a, 3)} | "
                     f"{int(r.n_disagree)} | {fmt(r.Dc_b)} | {fmt(r.ratio_a_b, 3)} | {fmt(r.Dc_a_small_k0)} | "
                     f"{fmt(r.ratio_small_k0, 3)} |")
    small = per_a[per_a.k0 <= per_a.k0.min() * 100]       # the two decades above the smallest k0
    big = per_a[~per_a.index.isin(small.index)]
    lines += ["", "Why (a)/(b) is constant at small k0 (derived; `compare.fits.dc_small_k0`): there RS's cycle at "
              "a = 0 runs from sigma_min = mu_inf to sigma_max = mu_inf + (A − k0 V D_c)/B, a function of k0 V D_c "
              "alone, while micro's cycles and k0 V^c depend on the loading rate k0 V alone "
              "(docs/reference/micro_transition.md, (L) and (V)); at fixed V/V^c both D_c (a) and D_c (b) = "
              "W(V^c)/k0 ≈ A/(k0 V^c) then tend to constants. Measured: (a)/(b) = "
              + ", ".join(f"{fmt(r.ratio_a_b, 3)}" for _, r in small.iterrows())
              + f" at k0 = {', '.join(f'{k:g}' for k in small.k0)} (closed form "
              + ", ".join(f"{fmt(r.ratio_small_k0, 3)}" for _, r in small.iterrows()) + ")"
              + ("; at k0 = " + ", ".join(f"{r.k0:g}: {fmt(r.ratio_a_b, 3)}" for _, r in big.iterrows())
                 + ", where the slip no longer empties the state and V is not large against B" if len(big) else "")
              + ".", ""]
    return lines


def _bifurcation(ctx: Context, t) -> list[str]:
    s = ctx.s
    how = ("micro's default method, the cohort method (limit cycles as fixed points of the cycle map, to "
           f"{s.cycle_rtol:g} of the velocity weakening)" if s.cycle_method == "cohort"
           else f"the Fokker-Planck equation (eps = {s.eps:g})")
    shown = sorted({k for k, _ in s.shown_points}, reverse=True)
    lines = ["## Bifurcation diagrams (Figs. 4/8)", "",
             f"`bifurcation.png`: micro's exact steady branch (line; dotted where unstable) at every k0, its "
             f"stick-slip extrema (sigma_max the largest stress of the cycle) from {how} at k0 = "
             f"{', '.join(f'{k:g}' for k in s.fp_k0) or 'none'} (points the D_c fit matches)"
             + (f" and {', '.join(f'{k:g}' for k in shown)} (shown, not fitted: there the fitted D_c is a "
                "prediction)" if shown else "") + "; "]
    missing = [k for k in sorted(set(PAPER_K0) | set(s.k0), reverse=True) if k not in s.fp_k0 and k not in shown]
    if missing:
        lines[-1] += (f"micro's stick-slip below V^c at k0 = {', '.join(f'{k:g}' for k in missing)} is not computed, ")
    lines[-1] += "RS with the fitted law and D_c on the right; V^c of each model marked."
    band = t.get("rs_unstable_band")
    if band is not None:
        low = band[np.isfinite(band.V_lower) & (band.V_lower > 0)]
        if len(low):
            lines += ["", "RS returns to steady sliding below V_- (the lower root of k0 D_c = W(V); marked on "
                          "the figure): " + ", ".join(f"k0 = {r.k0:g}: V_- = {fmt(r.V_lower, 3)}"
                                                      for _, r in low.iterrows()) + "."]
    lines.append("")
    return lines
