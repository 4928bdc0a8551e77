"""``summary.md`` of a report: what was computed, with its uncertainty, and what disagrees."""
from __future__ import annotations

import math
from typing import Any

import numpy as np

import micro
import rsf
from micro.api import NEAR_VC

from .params import PAPER_K0

__all__ = ["summary"]


def _fmt(x: Any, digits: int = 4) -> str:
    try:
        xf = float(x)
    except (TypeError, ValueError):
        return str(x)
    return "nan" if not math.isfinite(xf) else f"{xf:.{digits}g}"


def _pct(x: float) -> str:
    return "nan" if not math.isfinite(x) else f"{100 * x:+.1f} %"


def _steady(study, t, v) -> list[str]:
    if "steady_fit" not in t:
        return []
    s = study.s
    chk = t["steady_fit_checks"]
    lines = ["## Eq. (10) fitted to micro's exact steady branch", "",
             f"mu_ss = mu_inf(k0) + A/(V + B) fitted to {len(t['steady_fit_residuals'])} exact steady points "
             f"(micro's direct method, to 1e-11; V from just above V^c to {_fmt(s.branch_span, 3)} V^c at each k0, "
             f"and the reference branch at k0 = {s.reference_k0:g}, steady at every V):", "",
             f"A = {_fmt(v['A'])} ± {_fmt(v['A_err'], 2)}, B = {_fmt(v['B'])} ± {_fmt(v['B_err'], 2)} "
             f"(paper: A = {rsf.PAPER_A}, B = {rsf.PAPER_B}); rms residual {_fmt(v['steady_rms'], 3)}, "
             f"largest {_fmt(v['steady_max_residual'], 3)}.", "",
             "| k0 | mu_inf | exact sigma(V→∞) | offset error | A / exact tail C | largest residual (at V) | "
             "residual / (sigma − sigma_∞) at the largest V |", "|---|---|---|---|---|---|---|"]
    for _, r in chk.iterrows():
        lines.append(f"| {r.k0:g} | {_fmt(r.mu_inf, 6)} | {_fmt(r.sigma_inf_exact, 6)} | {_fmt(r.offset_error, 3)} | "
                     f"{_fmt(r.tail_ratio, 3)} | {_fmt(r.max_abs_residual, 2)} (V = {_fmt(r.V_at_max, 3)}) | "
                     f"{_pct(r.tail_residual)} (V = {_fmt(r.V_max, 3)}) |")
    worst = chk.iloc[int(np.argmax(chk.max_abs_residual.to_numpy()))]
    lines += ["", f"Where the form fails: exact micro decays as sigma_∞ + C/V with C = k2 γ Var(R) = "
                  f"{_fmt(chk.tail_exact.iloc[0], 4)} (micro.sigma_fast_limit), Eq. (10) as mu_inf + A/V, so its "
                  f"tail is off by the factor A/C = {_fmt(chk.tail_ratio.iloc[0], 3)} and its offset by "
                  f"{_fmt(chk.offset_error.abs().min(), 2)} to {_fmt(chk.offset_error.abs().max(), 2)} "
                  f"(mu_inf − sigma_∞). The largest residual, {_fmt(worst.max_abs_residual, 2)}, is at k0 = "
                  f"{worst.k0:g}, V = {_fmt(worst.V_at_max, 3)}. Residuals: `steady_fit_residuals.csv`, figure "
                  f"`steady_fit.png`.", ""]
    return lines


def _dc(study, t, v) -> list[str]:
    if "critical_velocity" not in t:
        if study.Dc_given is not None:
            return ["## D_c", "", f"D_c = {study.Dc_given:g} given (not fitted).", ""]
        return []
    lines = ["## D_c two ways", ""]
    s = study.s
    dcv = study.dc_critical
    rows = ["| method | D_c | interval | what it matches | what it implies for the other |",
            "|---|---|---|---|---|"]
    crit = t.get("critical_velocity")
    if "Dc" in v:
        lo, hi = v["Dc_profile"]
        if v.get("Dc_one_sided"):
            bound = "≤" if v["Dc_one_sided"] == "upper" else "≥"
            interval = (f"one-sided: D_c {bound} {_fmt(v['Dc_switch'], 4)} (a regime switch of the RS diagram: "
                        f"the optimum sits on it); profile [{_fmt(lo, 3)}, {_fmt(hi, 3)}]")
        else:
            interval = f"± {_fmt(v['Dc_err'], 2)} (bootstrap 16-84 %); profile [{_fmt(lo, 3)}, {_fmt(hi, 3)}]"
        implied = ""
        if crit is not None:
            c = crit[np.isfinite(crit.rel_diff_rs)]
            implied = ("RS V^c off micro's by " + ", ".join(f"{_pct(r)} (k0 = {k:g})"
                                                           for k, r in zip(c.k0, c.rel_diff_rs)))
            none = crit[~np.isfinite(crit.Vc_rs)]
            if len(none):
                implied += "; no RS stick-slip at all at k0 = " + ", ".join(f"{k:g}" for k in none.k0)
        rows.append(f"| (a) stick-slip extrema | {_fmt(v['Dc'])} | {interval} | sigma_max, sigma_min of "
                    f"{int(t['dc_fit'].n_points.iloc[0])} micro points at k0 = {', '.join(f'{k:g}' for k in s.fp_k0)} "
                    f"(rms {_fmt(v['Dc_rms'], 3)}, regime agreement {100 * v['regime_agreement']:.0f} %) | {implied} |")
    elif study.Dc_given is not None:
        rows.append(f"| given | {study.Dc_given:g} | | | |")
    implied_b = ""
    if "Dc_vc_extrema_rms" in v:
        implied_b = (f"rms of the extrema {_fmt(v['Dc_vc_extrema_rms'], 3)} (against {_fmt(v['Dc_rms'], 3)} at (a)), "
                     f"regime agreement {100 * v['Dc_vc_regime_agreement']:.0f} %")
    rows.append(f"| (b) V^c matching | {_fmt(dcv.Dc)} | ± {_fmt(dcv.Dc_err, 2)} (standard error); per-k0 values "
                f"{_fmt(dcv.Dc_range[0], 3)} to {_fmt(dcv.Dc_range[1], 3)} | micro's exact V^c at "
                f"{len(dcv.per_k0)} k0 (rms {100 * dcv.rms_log:.1f} % in V^c) | {implied_b} |")
    lines += rows + [""]
    per = dcv.per_k0
    lines += ["Per k0, k0 D_c = W(V^c) = −V dmu_ss/dV at micro's exact V^c, with the fitted law's slope and with "
              "micro's own:", "", "| k0 | V^c micro | D_c (law) | D_c (micro's slope) |", "|---|---|---|---|"]
    for _, r in per.iterrows():
        lines.append(f"| {r.k0:g} | {_fmt(r.Vc_micro, 6)} | {_fmt(r.Dc_law)} | {_fmt(r.Dc_exact_slope)} |")
    lines.append("")
    if "Dc" in v:
        a, b = v["Dc"], dcv.Dc
        lo_b, hi_b = dcv.Dc_range
        agree = lo_b <= a <= hi_b
        if agree and abs(math.log(a / b)) < 0.1:
            lines.append(f"**The two D_c agree**: (a) {_fmt(a)} lies within the per-k0 range of (b) and within 10 % "
                         f"of it.")
        else:
            lines.append(f"**The two D_c disagree**: (a) = {_fmt(a)} from the stick-slip extrema, (b) = {_fmt(b)} "
                         f"from V^c ({_pct(a / b - 1)}); with (a) RS misplaces micro's V^c by up to "
                         f"{_pct(float(crit.rel_diff_rs.abs().max()))}, and no single D_c reproduces V^c at every k0 "
                         f"(per-k0 values {_fmt(lo_b, 3)} to {_fmt(hi_b, 3)}): one RS law with one D_c cannot "
                         f"carry both micro's cycle amplitudes and its stability boundary.")
        lines.append("")
    lines.append("Figure `critical_velocity.png`: V^c(k0) of micro (exact) and of RS with each D_c.")
    lines.append("")
    return lines


def _critical(study, t) -> list[str]:
    if "critical_velocity" not in t:
        return []
    lines = ["## Critical velocity per k0", "",
             "Micro: exact (the root of branching ratio = 1; error below 1e-9 relative); RS: linear stability "
             "with the fitted law and each D_c.", "",
             "| k0 | V^c micro | small-k0 asymptote | V^c RS, D_c (a) | V^c RS, D_c (b) | V^c RS (paper's law, D_c) |",
             "|---|---|---|---|---|---|"]
    def rs(vc, rel):
        return "none (steady at every V)" if not math.isfinite(vc) else f"{_fmt(vc)} ({_pct(rel)})"

    for _, r in t["critical_velocity"].iterrows():
        lines.append(f"| {r.k0:g} | {_fmt(r.Vc_micro, 8)} | {_fmt(r.Vc_micro_small_k0)} | {rs(r.Vc_rs, r.rel_diff_rs)} | "
                     f"{rs(r.Vc_rs_dc_vc, r.rel_diff_rs_dc_vc)} | {rs(r.Vc_rs_paper, math.nan).split(' (')[0]} |")
    lines.append("")
    return lines


def _bifurcation(study, t, v) -> list[str]:
    if "rs_bifurcation" not in t:
        return []
    s = study.s
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
                          "the figure): " + ", ".join(f"k0 = {r.k0:g}: V_- = {_fmt(r.V_lower, 3)}"
                                                      for _, r in low.iterrows()) + "."]
    lines.append("")
    return lines


def s_dt(study) -> str:
    """The cohort method's time step of the report's cycles."""
    return f"{micro.Cohort().dt:g}"


def _hopf(study, t, v) -> list[str]:
    if "hopf_fit" not in t:
        return []
    s = study.s
    lines = [f"## The transition at k0 = {s.hopf_k0:g}", "",
             "Amplitude sigma_max − sigma_min ∝ d^beta, d = (V^c − V)/V^c with each model's own exact V^c:", "",
             "| model | method | resolution | beta | ± | points |", "|---|---|---|---|---|---|"]
    for _, r in t["hopf_fit"].iterrows():
        res = "" if not math.isfinite(r.resolution) else (
            f"N = {r.resolution:.0f}" if r.method == "N-block" else
            f"h = {r.resolution:.3g}, dt = {s_dt(study)}" if r.method == "cohort" else f"eps = {r.resolution:g}")
        lines.append(f"| {r.model} | {r.method} | {res} | {_fmt(r.exponent, 3)} | {_fmt(r.exponent_err, 2)} | "
                     f"{int(r.n_points)} |")
    tr = v.get("transition", {})
    lines += ["", tr.get("text", ""), "",
              "Micro's cycles come from its default method, the cohort method: each point's error bar in "
              "`hopf.png` is twice the sum of its discretisation error (the change from twice the time step and "
              f"cell) and its fixed-point error; closer to V^c than d = {NEAR_VC:g} the discretisation error is "
              "not known (the cell refinement is not yet shown to converge there), and such points carry no bar. "
              "The N-block sizes differ by their finite-N error.", ""]
    return lines


def _phase(study, t) -> list[str]:
    if "phase_micro" not in t:
        return []
    lines = ["## Phase diagram (Fig. 5)", "",
             "Micro's exact V^c(k0) at each (k1, k2) set (points), its small-k0 asymptote "
             "V^c ≈ k2 γ⟨z²⟩/(2 zbar k0) and its end at k0 = k2; RS with Eq. (10) fitted to each set's exact "
             "reference branch and each D_c:", "",
             "| k1 | k2 | micro k0 points | A | B | RS k0_max = A/(4 B D_c) (a), (b) | micro V^c / RS V^c (a) at k0 = 1e-3 |",
             "|---|---|---|---|---|---|---|"]
    pm, rs = t["phase_micro"], t["phase_rs"]
    for _, r in t["phase_laws"].iterrows():
        m = pm[np.isclose(pm.k1, r.k1) & np.isclose(pm.k2, r.k2)]
        x = rs[np.isclose(rs.k1, r.k1) & np.isclose(rs.k2, r.k2)]
        ratio = math.nan
        if len(m) and len(x):
            ratio = float(np.exp(np.interp(math.log(1e-3), np.log(m.k0), np.log(np.clip(m.Vc, 1e-300, None))) -
                                 np.interp(math.log(1e-3), np.log(x.k0), np.log(np.clip(x.Vc, 1e-300, None)))))
        lines.append(f"| {r.k1:g} | {r.k2:g} | {len(m)} | {_fmt(r.A)} | {_fmt(r.B)} | {_fmt(r.k0_max_rs, 3)}, "
                     f"{_fmt(r.k0_max_rs_dc_vc, 3)} | {_fmt(ratio, 3)} |")
    lines.append("")
    return lines


def _shs(study, t, v) -> list[str]:
    if "shs_fit" not in t:
        return []
    s = study.s
    lines = ["## Slide-hold-slide peak vs hold time (Fig. 7)", "",
             f"k0 = {s.shs_k0:g}, V = {s.shs_V:g}; classical RS with b = {_fmt(v['shs_b'], 3)}; "
             f"A/B of the fitted law = {_fmt(v['shs_A_over_B'])}.", "",
             "| model | law | p1 | p2 | rel. rms | best |", "|---|---|---|---|---|---|"]
    for _, r in t["shs_fit"].iterrows():
        lines.append(f"| {r.model} | {r.law} | {r.p1_name} = {_fmt(r.p1)} | {r.p2_name} = {_fmt(r.p2)} | "
                     f"{_fmt(r.rel_rms, 2)} | {'yes' if r.best else ''} |")
    lines.append("")
    return lines


def _paper(t) -> list[str]:
    lines = []
    if "fig3_traces" in t:
        tr = t["fig3_traces"]
        late = [(V, g[g.t >= 0.5 * g.t.max()]) for V, g in tr.groupby("V")]
        amp = ", ".join(f"V = {V:g}: {_fmt(g.sigma.max() - g.sigma.min(), 3)}" for V, g in late)
        lines += ["## The paper's Fig. 3 (sigma(t), k0 = 0.01)", "",
                  f"Late-time stress range (second half of each trace, FP): {amp}. Figure `fig3.png`.", ""]
    if "fig10_eps" in t:
        f = t["fig10_eps"]
        lines += ["## The paper's Fig. 10 (the FP's stress against the bin, V = 1.5 V^c)", "",
                  "| k0 | V | eps | regime | converged | sigma_FP − sigma_exact |", "|---|---|---|---|---|---|"]
        for _, r in f.sort_values(["k0", "eps"], ascending=[False, False]).iterrows():
            lines.append(f"| {r.k0:g} | {_fmt(r.V, 4)} | {r.eps:g} | {r.regime} | {bool(r.converged)} | "
                         f"{_fmt(r.error, 2)} |")
        bad = f[~f.converged.astype(bool)]
        lines.append("")
        if len(bad):
            lines.append(f"As in the paper, the Fokker-Planck equation does not settle everywhere above V^c: at "
                         f"{len(bad)} of {len(f)} (k0, eps) a stress oscillation a few k0·eps high persists to the "
                         "time limit, a grid oscillation of the discretised density, not of the model (the direct "
                         "steady state is linearly stable there).")
        lines += ["", "Figure `fig10.png`.", ""]
    return lines


def _warnings(study, t) -> list[str]:
    notes = []
    b = t.get("micro_branch")
    if b is not None and (~b.converged.astype(bool)).any():
        bad = b[~b.converged.astype(bool)]
        notes.append(f"{len(bad)} exact steady points did not reach the tolerance 1e-11 (largest sigma_error "
                     f"{_fmt(bad.sigma_error.max(), 2)}, branching_error {_fmt(bad.branching_error.max(), 2)}; "
                     f"V = {_fmt(bad.V.min(), 3)} to {_fmt(bad.V.max(), 3)}).")
    for name in ("micro_points", "hopf_points"):
        f = t.get(name)
        if f is not None and "converged" in f and "method" in f:
            fp = f[(f.method == "FP") | (f.method == "fp")]
            bad = fp[~fp.converged.fillna(False).astype(bool)]
            if len(bad):
                notes.append(f"{name}: {len(bad)} Fokker-Planck points stopped at their time limit before the "
                             "cycle met the stopping test (kept, drawn open): " +
                             ", ".join(f"k0 = {r.k0:g}, V = {_fmt(r.V, 3)}" for _, r in bad.iterrows()) + ".")
        if f is not None and "error" in f:
            err = f[f.error.fillna("").astype(str) != ""]
            if len(err):
                notes.append(f"{name}: {len(err)} micro tasks failed: " + "; ".join(sorted(set(err.error.astype(str)))))
    if not notes:
        return []
    return ["## Warnings", ""] + [f"- {n}" for n in notes] + [""]


def summary(study, rep) -> str:
    s, t, v = study.s, study.tables, study.values
    st = rep.stats
    lines = ["# micro vs rate-and-state: comparison report", "",
             f"Preset `{s.preset}`; scenarios: {', '.join(s.scenarios)}; wall time {rep.wall_time:.1f} s "
             f"({st.computed} micro tasks computed, {st.cached} from the cache, {st.compute_seconds:.1f} s of micro "
             f"compute, {st.warm_up_seconds:.1f} s loading or compiling kernels).", "",
             f"Model: k1 = {s.k1:g}, k2 = {s.k2:g}, exponential jumps zbar = {s.zbar:g} (cutoff {s.cutoff:g}), "
             f"eta_u = f_th = 1. Micro's steady branch and V^c are exact (the renewal chain, micro's default for "
             f"them); its stick-slip cycles come from "
             + ("the cohort method (micro's default for cycles)" if s.cycle_method == "cohort"
                else f"the Fokker-Planck equation at eps = {s.eps:g}")
             + ", checked by the N-block simulation in the transition study; slide-hold-slide and the traces "
             f"come from the Fokker-Planck equation at eps = {s.eps:g} (micro's only method for a transient).", ""]
    lines += _warnings(study, t)
    lines += _steady(study, t, v)
    lines += _critical(study, t)
    lines += _dc(study, t, v)
    lines += _bifurcation(study, t, v)
    lines += _hopf(study, t, v)
    lines += _phase(study, t)
    lines += _shs(study, t, v)
    lines += _paper(t)
    if rep.figures:
        lines += ["## Figures", ""] + [f"![{name}]({p.name})" for name, p in rep.figures.items()] + [""]
    lines += ["## Tables", "", ", ".join(f"`{n}.csv`" for n in sorted(t)), ""]
    return "\n".join(lines)
