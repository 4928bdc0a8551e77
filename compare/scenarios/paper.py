r"""The paper's remaining micro figures: Fig. 3 and Fig. 10 (opt-in: ``paper_figures``,
with the bifurcation scenario).

Fig. 3: sigma(t) at k0 = 0.01 for V = 0.001, 5 and 9.8 from a start: transients (at
V = 0.001 the cycles' peaks still fall from cycle to cycle), which the cohort method does
not carry.  Each trace by the cheaper of the two methods that carry them: the N-block
with ``fig3_N`` blocks at the slow drive (its cost goes with the jumps, about N a cycle:
13.5 s for N = 1e5 against the Fokker-Planck equation's 85 s at the report's bin; the FP
refined to eps = 0.004 meets it, at the report's bin it is 2.5e-3 low in the first peak),
the Fokker-Planck equation at V = 5 and 9.8 (its cost
goes with the simulated time: a few seconds, where the N-block takes two minutes);
docs/validation/micro_defaults.md.
Fig. 10: the FP's stress at V = 1.5 V^c against its bin eps (``fig10_k0``,
``fig10_eps``), against micro's exact steady stress, each run under the time budget
``fig10_t_max``.
"""
from __future__ import annotations

from dataclasses import replace
from pathlib import Path

import pandas as pd

import micro

from .. import figures
from ..context import Context, micro_frame
from ..params import Settings
from ..summary import fmt
from ..tasks import StationaryTask, Task, TraceTask
from . import Part

NAME = "paper"


def wanted(settings: Settings) -> bool:
    return settings.paper_figures and "bifurcation" in settings.scenarios


def vc_k0(ctx: Context) -> list[float]:
    return list(ctx.s.fig10_k0)


def tasks(ctx: Context) -> list[Task]:
    return _fig3_tasks(ctx) + _fig10_tasks(ctx)


def _fig3_tasks(ctx: Context) -> list[TraceTask]:
    s = ctx.s
    model = ctx.model(0.01)
    out = []
    for V in (0.001, 5.0, 9.8):
        w = 2.5 * 0.1 / 0.01 if V < 1 else 30 * model.kappa * model.zbar / 0.01   # drive displacement
        out.append(TraceTask(model, ((w / V, V),), s.numerics(), method="nblock" if V < 1 else "fp",
                             n_blocks=s.fig3_N))
    return out


def _fig10_tasks(ctx: Context) -> list[StationaryTask]:
    s = ctx.s
    # method "fp": above V^c the default would return the direct steady state, not the FP's;
    # each run under the time budget fig10_t_max (the grid's oscillation never settles)
    budget = replace(s.convergence(), t_max=s.fig10_t_max)
    return [replace(ctx.stationary_task(k0, 1.5 * ctx.Vc(k0), eps, "fp"), convergence=budget)
            for k0 in s.fig10_k0 for eps in s.fig10_eps if eps <= ctx.model(k0).kappa * s.zbar / 4]


def run(ctx: Context) -> Part:
    s = ctx.s
    part = Part()
    traces = []
    fig3 = _fig3_tasks(ctx)
    for task, rec in zip(fig3, ctx.run(fig3, "micro Fig. 3")):
        if rec.get("status") == "ok":
            r = rec["result"]
            traces.append(pd.DataFrame({"t": r["t"], "sigma": r["sigma"]})
                          .assign(V=task.segments[0][1], k0=task.model.k0, method=r.get("method", "fp")))
    if traces:
        part.tables["fig3_traces"] = pd.concat(traces, ignore_index=True)
    f = micro_frame(ctx.run(_fig10_tasks(ctx), "micro Fig. 10"))
    exact = {k0: float(micro.steady_sliding(ctx.model(k0), [1.5 * ctx.Vc(k0)], growth_rate=False).sigma[0])
             for k0 in s.fig10_k0}
    f["sigma_exact"] = [exact[k] for k in f.k0]
    f["error"] = f.sigma_mean - f.sigma_exact
    part.tables["fig10_eps"] = f
    return part


def draw(ctx: Context, part: Part, out) -> dict[str, Path]:
    t = part.tables
    figs = {}
    if "fig3_traces" in t:
        figs["fig3"] = figures.fig3(t, figures.target(out, "fig3.png"))
    figs["fig10"] = figures.fig10(t, figures.target(out, "fig10.png"))
    return figs


def summary(ctx: Context, part: Part) -> list[str]:
    t = part.tables
    lines = []
    if "fig3_traces" in t:
        tr = t["fig3_traces"]
        late = [(V, g[g.t >= 0.5 * g.t.max()]) for V, g in tr.groupby("V")]
        amp = ", ".join(f"V = {V:g}: {fmt(g.sigma.max() - g.sigma.min(), 3)} ({g.method.iloc[0]})" for V, g in late)
        lines += ["## The paper's Fig. 3 (sigma(t), k0 = 0.01)", "",
                  f"From a start, each trace by the cheaper method that carries a transient (the N-block with "
                  f"N = {ctx.s.fig3_N:g} at the slow drive, the Fokker-Planck equation at eps = {ctx.s.eps:g} "
                  "at the fast ones). "
                  f"Late-time stress range (second half of each trace): {amp}. Figure `fig3.png`.", ""]
    f = t["fig10_eps"]
    lines += ["## The paper's Fig. 10 (the FP's stress against the bin, V = 1.5 V^c)", "",
              "| k0 | V | eps | regime | converged | sigma_FP − sigma_exact |", "|---|---|---|---|---|---|"]
    for _, r in f.sort_values(["k0", "eps"], ascending=[False, False]).iterrows():
        lines.append(f"| {r.k0:g} | {fmt(r.V, 4)} | {r.eps:g} | {r.regime} | {bool(r.converged)} | "
                     f"{fmt(r.error, 2)} |")
    bad = f[~f.converged.astype(bool)]
    lines.append("")
    if len(bad):
        lines.append(f"As in the paper, the Fokker-Planck equation does not settle everywhere above V^c: at "
                     f"{len(bad)} of {len(f)} (k0, eps) a stress oscillation a few k0·eps high persists to the "
                     f"time budget t = {fmt(ctx.s.fig10_t_max, 3)}, a grid oscillation of the discretised density, not of the model (the direct "
                     "steady state is linearly stable there).")
    lines += ["", "Figure `fig10.png`.", ""]
    return lines
