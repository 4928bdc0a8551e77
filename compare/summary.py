"""``summary.md`` of a report: what was computed, with its uncertainty, and what disagrees.

This module holds the frame of the text (the run, the warnings, the list of figures and
tables) and the number formats; the paragraphs are written by the shared stages
(:meth:`compare.context.Context.summary`) and by each scenario (``summary`` in
:mod:`compare.scenarios`), next to the code that computes what they report.
"""
from __future__ import annotations

import math
from typing import Any, Sequence

from .tasks import SteadyTask

__all__ = ["summary", "fmt", "pct", "STEADY_TOL"]

#: The tolerance of micro's exact steady branch in a report (:class:`SteadyTask`'s ``tol``),
#: quoted by the summary from the task, not copied.
STEADY_TOL: float = SteadyTask.tol


def fmt(x: Any, digits: int = 4) -> str:
    """``x`` to ``digits`` significant digits ("nan" if not finite; as text if not a number)."""
    try:
        xf = float(x)
    except (TypeError, ValueError):
        return str(x)
    return "nan" if not math.isfinite(xf) else f"{xf:.{digits}g}"


def pct(x: float) -> str:
    """A relative difference as a signed percentage."""
    return "nan" if not math.isfinite(x) else f"{100 * x:+.1f} %"


def _warnings(ctx, t) -> list[str]:
    """Points that missed their tolerance or failed, in any table ``t`` of the report."""
    notes = []
    b = t.get("micro_branch")
    if b is not None and (~b.converged.astype(bool)).any():
        bad = b[~b.converged.astype(bool)]
        notes.append(f"{len(bad)} exact steady points did not reach the tolerance {STEADY_TOL:g} (largest "
                     f"sigma_error "
                     f"{fmt(bad.sigma_error.max(), 2)}, branching_error {fmt(bad.branching_error.max(), 2)}; "
                     f"V = {fmt(bad.V.min(), 3)} to {fmt(bad.V.max(), 3)}).")
    for name in ("micro_points", "hopf_points"):
        f = t.get(name)
        if f is not None and "converged" in f and "method" in f:
            fp = f[(f.method == "FP") | (f.method == "fp")]
            bad = fp[~fp.converged.fillna(False).astype(bool)]
            if len(bad):
                notes.append(f"{name}: {len(bad)} Fokker-Planck points stopped at their time limit before the "
                             "cycle met the stopping test (kept, drawn open): " +
                             ", ".join(f"k0 = {r.k0:g}, V = {fmt(r.V, 3)}" for _, r in bad.iterrows()) + ".")
        if f is not None and "error" in f:
            err = f[f.error.fillna("").astype(str) != ""]
            if len(err):
                notes.append(f"{name}: {len(err)} micro tasks failed: " + "; ".join(sorted(set(err.error.astype(str)))))
    if not notes:
        return []
    return ["## Warnings", ""] + [f"- {n}" for n in notes] + [""]


def summary(ctx, rep, paragraphs: Sequence[Sequence[str]]) -> str:
    """``summary.md``: the run, the warnings, then ``paragraphs`` (the shared stages' and
    each scenario's, in the report's order), the figures and the tables."""
    s, t = ctx.s, rep.tables
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
             + ", checked by the N-block simulation in the transition study; slide-hold-slide "
             + ("and Fig. 3's fast traces come from the Fokker-Planck equation at eps = "
                f"{s.eps:g} (micro's default for a transient), its slow trace from the N-block; Fig. 10 is the "
                "Fokker-Planck equation against its bin."
                if s.paper_figures and "bifurcation" in s.scenarios else
                f"comes from the Fokker-Planck equation at eps = {s.eps:g} (micro's default for a transient)."), ""]
    lines += _warnings(ctx, t)
    for paragraph in paragraphs:
        lines += paragraph
    if rep.figures:
        lines += ["## Figures", ""] + [f"![{name}]({p.name})" for name, p in rep.figures.items()] + [""]
    lines += ["## Tables", "", ", ".join(f"`{n}.csv`" for n in sorted(t)), ""]
    return "\n".join(lines)
