r"""The scenarios of a report, one module each.

=====================  =================  ====================================================
module                 name               what it compares
=====================  =================  ====================================================
:mod:`.bifurcation`    ``bifurcation``    Figs. 4/8: micro's exact branch and stick-slip
                                          points against RS; V^c(k0) of both; D_c two ways
:mod:`.transition`     ``hopf``           the transition near V^c: micro's spectrum and
                                          amplitudes (cohort, N-block) against RS's Hopf
:mod:`.phase`          ``phase``          Fig. 5: V^c(k0) per (k1, k2) set
:mod:`.shs`            ``shs``            Fig. 7: slide-hold-slide peaks and growth laws
:mod:`.paper`          ``paper``          Figs. 3 and 10 (``paper_figures``, with the
                                          bifurcation scenario)
=====================  =================  ====================================================

Each module is a scenario: it reads the settings and the shared stages from a
:class:`~compare.context.Context` (``ctx.s``, ``ctx.Vc``, ``ctx.law_for``, ``ctx.Dc``, ...)
and defines

``NAME``
    Its name (``Settings.scenarios`` selects it by this name).
``wanted(settings) -> bool``
    Whether the report runs it.
``vc_k0(ctx) -> list[float]``
    The k0 whose exact V^c its tasks are placed at (the report runs these first).
``tasks(ctx) -> list[Task]``
    Its micro tasks, declared so that the report runs every scenario's in one batch
    (the process pool stays full).  Called once the V^c above are known.
``run(ctx) -> Part``
    Its tables and values.
``draw(ctx, part, out) -> dict[str, Path]``
    Its figures, drawn into the folder ``out`` (see :func:`compare.figures.target`).
``summary(ctx, part) -> list[str]``
    Its paragraph of ``summary.md`` (Markdown lines).

and optionally ``PRESENTS``, the shared stages' outputs that it shows among its own (a
figure name of :data:`compare.context.SHARED_FIGURES`, or ``"Dc"`` for the D_c
paragraph); the report shows the others before every scenario's.

A new scenario is a module here and a line in :data:`compare.report.REGISTRY`.
"""
from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

import pandas as pd

__all__ = ["Part"]


@dataclass
class Part:
    """What a scenario computed: its tables (written as ``<name>.csv``) and its values
    (merged into :attr:`compare.Report.values`)."""

    tables: dict[str, pd.DataFrame] = field(default_factory=dict)
    values: dict[str, Any] = field(default_factory=dict)

    def view(self, ctx) -> tuple[dict[str, pd.DataFrame], dict[str, Any]]:
        """Its tables and values together with the shared stages' (``ctx.tables``,
        ``ctx.values``)."""
        return {**ctx.tables, **self.tables}, {**ctx.values, **self.values}
