r"""The phase diagram (Fig. 5): V^c(k0) per (k1, k2) set.

Per set of ``phase_sets``: micro's exact V^c at ``phase_points`` k0 from ``phase_k0_min``
to 0.98 k2 and its small-k0 asymptote; Eq. (10) fitted to the set's exact reference
branch (at k0 = max(reference_k0, 1.2 k2), steady at every V); RS's V^c(k0) with that law
and each D_c.
"""
from __future__ import annotations

import logging
import math
from pathlib import Path

import numpy as np
import pandas as pd

import micro
import rsf

from .. import figures, fits
from ..context import Context, sig
from ..params import Settings
from ..summary import fmt
from ..tasks import SteadyTask, Task, VcTask
from . import Part

NAME = "phase"

log = logging.getLogger(__name__)


def wanted(settings: Settings) -> bool:
    return NAME in settings.scenarios


def vc_k0(ctx: Context) -> list[float]:
    return []


def tasks(ctx: Context) -> list[Task]:
    """Micro's V^c along each set's curve, and each set's reference branch."""
    s = ctx.s
    vcs = [VcTask(ctx.model(k0, k1, k2)) for k1, k2 in s.phase_sets for k0 in ctx.phase_k0(k2)]
    return vcs + _reference_tasks(ctx)


def _reference_tasks(ctx: Context) -> list[SteadyTask]:
    s = ctx.s
    return [SteadyTask(ctx.model(max(s.reference_k0, 1.2 * k2), k1, k2), tuple(sig(v) for v in s.phase_reference_V))
            for k1, k2 in s.phase_sets]


def run(ctx: Context) -> Part:
    s = ctx.s
    part = Part()
    Dc, Dc_vc = ctx.Dc, ctx.dc_critical.Dc
    recs = ctx.run(_reference_tasks(ctx), "micro phase reference")
    laws, law_rows, refs = {}, [], []
    for (k1, k2), rec in zip(s.phase_sets, recs):
        f = pd.DataFrame(rec["result"]["rows"])
        refs.append(f)
        try:
            fit = fits.fit_steady_law(f.assign(regime="steady", sigma_mean=f.sigma))
        except ValueError as exc:
            log.warning("phase set (k1=%g, k2=%g): no Eq. (10) fit: %s", k1, k2, exc)
            continue
        laws[(k1, k2)] = fit
        law_rows.append({"k1": k1, "k2": k2, "A": fit.A, "A_err": fit.A_err, "B": fit.B, "B_err": fit.B_err,
                         "mu_inf": float(fit.offsets.mu_inf.iloc[0]), "rms": fit.rms,
                         "k0_max_rs": fit.A / (4 * fit.B * Dc), "k0_max_rs_dc_vc": fit.A / (4 * fit.B * Dc_vc)})
    part.tables["phase_reference"] = pd.concat(refs, ignore_index=True)
    part.tables["phase_laws"] = pd.DataFrame(law_rows)
    rows = []
    for k1, k2 in s.phase_sets:
        for k0 in ctx.phase_k0(k2):
            rec = ctx.run([VcTask(ctx.model(k0, k1, k2))], "micro phase Vc")[0]
            r = rec.get("result") or {}
            rows.append({"k1": k1, "k2": k2, "k0": k0, "Vc": r.get("Vc", math.nan),
                         "Vc_err": 0.5 * (r.get("V_high", math.nan) - r.get("V_low", math.nan)),
                         "asymptote": micro.vc_small_k0(ctx.model(k0, k1, k2)), "status": r.get("status", "failed")})
    part.tables["phase_micro"] = pd.DataFrame(rows)
    rows = []
    for (k1, k2), f in laws.items():
        for k0 in np.geomspace(s.phase_k0_min, 1.0, 81):
            law = f.law(mu_inf=0.0)
            rows.append({"k1": k1, "k2": k2, "k0": float(k0),
                         "Vc": rsf.critical_velocity(law, float(k0), Dc).Vc,
                         "Vc_dc_vc": rsf.critical_velocity(law, float(k0), Dc_vc).Vc,
                         "asymptote": f.A / (k0 * Dc), "k0_max_rs": f.A / (4 * f.B * Dc)})
    part.tables["phase_rs"] = pd.DataFrame(rows)
    return part


def draw(ctx: Context, part: Part, out) -> dict[str, Path]:
    t, v = part.view(ctx)
    if not len(t["phase_laws"]):
        return {}
    return {"phase": figures.phase(t, v, figures.target(out, "phase.png"))}


#: The k0 at which the phase table compares micro's V^c with RS's (a), in every set.
RATIO_K0 = 1e-3


def summary(ctx: Context, part: Part) -> list[str]:
    t = part.tables
    lines = ["## Phase diagram (Fig. 5)", "",
             "Micro's exact V^c(k0) at each (k1, k2) set (points), its small-k0 asymptote "
             "V^c ≈ k2 γ⟨z²⟩/(2 zbar k0) and its end at k0 = k2; RS with Eq. (10) fitted to each set's exact "
             "reference branch and each D_c:", "",
             f"| k1 | k2 | micro k0 points | A | B | RS k0_max = A/(4 B D_c) (a), (b) | micro V^c / RS V^c (a) at "
             f"k0 = {RATIO_K0:g} |",
             "|---|---|---|---|---|---|---|"]
    pm, rs = t["phase_micro"], t["phase_rs"]
    for _, r in t["phase_laws"].iterrows():
        m = pm[np.isclose(pm.k1, r.k1) & np.isclose(pm.k2, r.k2)]
        x = rs[np.isclose(rs.k1, r.k1) & np.isclose(rs.k2, r.k2)]
        ratio = math.nan
        if len(m) and len(x):
            ratio = float(np.exp(np.interp(math.log(RATIO_K0), np.log(m.k0), np.log(np.clip(m.Vc, 1e-300, None))) -
                                 np.interp(math.log(RATIO_K0), np.log(x.k0), np.log(np.clip(x.Vc, 1e-300, None)))))
        lines.append(f"| {r.k1:g} | {r.k2:g} | {len(m)} | {fmt(r.A)} | {fmt(r.B)} | {fmt(r.k0_max_rs, 3)}, "
                     f"{fmt(r.k0_max_rs_dc_vc, 3)} | {fmt(ratio, 3)} |")
    lines.append("")
    return lines
