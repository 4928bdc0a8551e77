r"""Slide-hold-slide (Fig. 7): the peak stress after a hold against the hold time.

Micro's peaks (:func:`micro.slide_hold_slide`, the Fokker-Planck equation) and its
sigma(t) around the reload after the longest hold; RS with Eq. (11) (the fitted law,
a = 0) and the classical Eq. (7) tangent to it at V; each fitted with the three growth
laws of :data:`compare.GROWTH_LAWS`.
"""
from __future__ import annotations

import logging
from pathlib import Path

import numpy as np
import pandas as pd

import rsf

from .. import figures, fits
from ..context import Context
from ..params import Settings
from ..rs_side import classical_rs, rs_slide_hold_slide
from ..summary import fmt
from ..tasks import SlideHoldSlideTask, Task, TraceTask
from . import Part

NAME = "shs"

log = logging.getLogger(__name__)


def wanted(settings: Settings) -> bool:
    return NAME in settings.scenarios


def vc_k0(ctx: Context) -> list[float]:
    return [ctx.s.shs_k0]


def tasks(ctx: Context) -> list[Task]:
    s = ctx.s
    return [SlideHoldSlideTask(ctx.model(s.shs_k0), s.shs_V, s.hold_times, s.numerics(), s.convergence()),
            _trace_task(ctx)]


def _trace_task(ctx: Context) -> TraceTask:
    """Fig. 7 (left): sigma(t) around the reload after the longest hold."""
    s = ctx.s
    model = ctx.model(s.shs_k0)
    slide = 30.0 * model.kappa * model.zbar / (s.shs_k0 * s.shs_V)   # 30 loading times: steady
    hold = max(s.hold_times)
    reload = 10.0 * model.kappa * model.zbar / (s.shs_k0 * s.shs_V)
    return TraceTask(model, ((slide, s.shs_V), (hold, 0.0), (reload, s.shs_V)), s.numerics())


def run(ctx: Context) -> Part:
    s = ctx.s
    part = Part()
    k0, V = s.shs_k0, s.shs_V
    rec, trace = ctx.run(tasks(ctx), "micro slide-hold-slide")
    frames = []
    if rec.get("status") == "ok":
        m = pd.DataFrame(rec["result"]["rows"])
        m["model"] = "micro"
        frames.append(m[["model", "hold_time", "sigma_steady", "sigma_peak", "delta_sigma_max"]])
    else:
        log.warning("micro slide-hold-slide failed: %s", rec.get("error"))
    if trace.get("status") == "ok":
        segs = trace["task"]["segments"]
        t0 = segs[0][0] + segs[1][0]
        part.tables["shs_trace"] = pd.DataFrame({"t": np.asarray(trace["result"]["t"]) - t0,
                                                 "sigma": trace["result"]["sigma"]}).assign(
            k0=k0, V=V, hold_time=segs[1][0])
    law = ctx.law_for(k0)
    rs11 = rs_slide_hold_slide(rsf.SpringSlider(law=law, k0=k0, Dc=ctx.Dc), V, s.hold_times)
    rs11["model"] = "RS Eq. (11)"
    W = float(law.weakening(np.array([V]))[0])
    b = max(s.classical_b, 1.5 * W)
    rs7 = rs_slide_hold_slide(classical_rs(law, V, b, k0, ctx.Dc), V, s.hold_times)
    rs7["model"] = "classical RS Eq. (7)"
    for f in (rs11, rs7):
        frames.append(f[["model", "hold_time", "sigma_steady", "sigma_peak", "delta_sigma_max"]])
    points = pd.concat(frames, ignore_index=True)
    part.tables["shs_points"] = points
    rows = []
    for name, grp in points.groupby("model", sort=False):
        for law_name in fits.GROWTH_LAWS:
            g = fits.fit_growth_law(grp.hold_time, grp.delta_sigma_max, law_name)
            rows.append({"model": name, **g.to_dict()})
    table = pd.DataFrame(rows)
    table["best"] = table.groupby("model").rel_rms.transform(lambda r: r == r.min())
    part.tables["shs_fit"] = table
    part.values.update(shs_b=b, shs_A_over_B=law.A / law.B)
    return part


def draw(ctx: Context, part: Part, out) -> dict[str, Path]:
    return {"shs": figures.shs(part.tables, figures.target(out, "shs.png"))}


def summary(ctx: Context, part: Part) -> list[str]:
    s, t, v = ctx.s, part.tables, part.values
    lines = ["## Slide-hold-slide peak vs hold time (Fig. 7)", "",
             f"k0 = {s.shs_k0:g}, V = {s.shs_V:g}; classical RS with b = {fmt(v['shs_b'], 3)}; "
             f"A/B of the fitted law = {fmt(v['shs_A_over_B'])}.", "",
             "| model | law | p1 | p2 | rel. rms | best |", "|---|---|---|---|---|---|"]
    for _, r in t["shs_fit"].iterrows():
        lines.append(f"| {r.model} | {r.law} | {r.p1_name} = {fmt(r.p1)} | {r.p2_name} = {fmt(r.p2)} | "
                     f"{fmt(r.rel_rms, 2)} | {'yes' if r.best else ''} |")
    lines.append("")
    return lines
