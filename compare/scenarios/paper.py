r"""The paper's remaining micro figure: Fig. 3 (opt-in: ``paper_figures``, with the
bifurcation scenario).

Fig. 3: sigma(t) at k0 = 0.01 for V = 0.001, 5 and 9.8 from a start: transients (at
V = 0.001 the cycles' peaks still fall from cycle to cycle), which the cohort method does
not carry.  Each trace by the cheaper of the two methods that carry them: the N-block
with ``fig3_N`` blocks at the slow drive (its cost goes with the jumps, about N a cycle:
13.5 s for N = 1e5 against the Fokker-Planck equation's 85 s at the report's bin; the FP
refined to eps = 0.004 meets it, at the report's bin it is 2.5e-3 low in the first peak),
the Fokker-Planck equation at V = 5 and 9.8 (its cost
goes with the simulated time: a few seconds, where the N-block takes two minutes);
docs/validation/micro_defaults.md.

The paper's Fig. 10 (the FP's stress against its bin) is not in the report: within a
report's time its runs stop, by the FP's steady rule or a time budget, up to 2.2e-4 away from
their own long-time mean, more than the FP's error it would show (at k0 = 0.3 that error is
below 6e-5 at every bin from 0.025 to 0.0125).  ``benchmarks/micro_fp_fig10_long.py``
draws it from long runs; docs/validation/micro_defaults.md, "Fig. 10".
"""
from __future__ import annotations

from pathlib import Path

import pandas as pd

from .. import figures
from ..context import Context
from ..params import Settings
from ..summary import fmt
from ..tasks import Task, TraceTask
from . import Part

NAME = "paper"


def wanted(settings: Settings) -> bool:
    return settings.paper_figures and "bifurcation" in settings.scenarios


def vc_k0(ctx: Context) -> list[float]:
    return []


def tasks(ctx: Context) -> list[Task]:
    return _fig3_tasks(ctx)


def _fig3_tasks(ctx: Context) -> list[TraceTask]:
    s = ctx.s
    model = ctx.model(0.01)
    out = []
    for V in (0.001, 5.0, 9.8):
        w = 2.5 * 0.1 / 0.01 if V < 1 else 30 * model.kappa * model.zbar / 0.01   # drive displacement
        out.append(TraceTask(model, ((w / V, V),), s.numerics(), method="nblock" if V < 1 else "fp",
                             n_blocks=s.fig3_N))
    return out


def run(ctx: Context) -> Part:
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
    return part


def draw(ctx: Context, part: Part, out) -> dict[str, Path]:
    t = part.tables
    figs = {}
    if "fig3_traces" in t:
        figs["fig3"] = figures.fig3(t, figures.target(out, "fig3.png"))
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
    lines += ["The paper's Fig. 10 (the Fokker-Planck stress against its bin) is not drawn here: within a "
              "report's time its runs stop up to 2.2e-4 from their own long-time mean, more than the error it "
              "would show. `python benchmarks/micro_fp_fig10_long.py` draws it from long runs.", ""]
    return lines
