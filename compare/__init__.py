r"""compare — the microscopic model (micro) and rate-and-state friction (rsf) side by side.

The obvious entry point is :func:`report`::

    import compare
    rep = compare.report(compare.Settings.quick(), out="report")   # tables, figures, summary.md
    rep["dc_fit"]                                                  # a DataFrame
    fit = compare.fit_steady_law(rep["micro_points"])              # Eq. (10): A, B, offsets
    dc = compare.fit_dc(rep["micro_points"], fit.law)              # D_c with its uncertainty
    dc.to_frame()

or from the shell: ``python -m compare`` (``--help`` for the options).
"""
from __future__ import annotations

from .cache import NullCache, PointCache
from .fits import (
    GROWTH_LAWS,
    DcCriticalFit,
    DcFit,
    GrowthFit,
    PowerLawFit,
    SteadyLawFit,
    classify_transition,
    dc_from_critical_velocity,
    fit_dc,
    fit_dc_critical,
    fit_growth_law,
    fit_power_law,
    fit_steady_law,
    rs_diagram,
    steady_law_checks,
)
from .params import PAPER_K0, PAPER_SETS, SCENARIOS, Settings
from .report import Report, micro_frame, report
from .rs_side import classical_rs, rs_curves, rs_hopf, rs_slide_hold_slide
from .runner import Runner, RunStats
from .tasks import (
    CriticalTask,
    NBlockTask,
    SlideHoldSlideTask,
    StationaryTask,
    SteadyTask,
    TraceTask,
    VcTask,
    execute,
)

__all__ = [
    "report", "Report", "Settings", "SCENARIOS", "PAPER_K0", "PAPER_SETS",
    "fit_steady_law", "SteadyLawFit", "steady_law_checks", "fit_dc", "DcFit", "rs_diagram",
    "dc_from_critical_velocity", "fit_dc_critical", "DcCriticalFit", "classify_transition",
    "fit_power_law", "PowerLawFit", "fit_growth_law", "GrowthFit", "GROWTH_LAWS",
    "rs_curves", "rs_hopf", "rs_slide_hold_slide", "classical_rs",
    "Runner", "RunStats", "PointCache", "NullCache", "SteadyTask", "VcTask", "NBlockTask", "TraceTask",
    "StationaryTask", "CriticalTask", "SlideHoldSlideTask",
    "execute", "micro_frame",
]
