"""The arguments of :func:`micro.cycle_branch`, checked in two steps: those that need no
computation (:func:`check_arguments`), then the start against V^c (:func:`check_start`).

Apart from :mod:`micro.branch`, whose imports load pandas, scipy and the cohort's and
Fokker-Planck's numba kernels (most of a second), so that ``python -m micro branch``
refuses a bad argument before it loads them; :func:`micro.cycle_branch` runs the same
checks, in the same order.
"""
from __future__ import annotations

from .analytic import _check_model
from .methods import Auto, Cohort, cohort_not_applicable
from .params import Model, _number

__all__ = ["check_d", "check_arguments", "check_start"]


def check_d(value, name: str) -> float:
    """``value`` (a distance ``d = 1 - V/V^c``) in (0, 1), or one ValueError naming it."""
    value = _number(name, value)
    if not 0.0 < value < 1.0:
        raise ValueError(f"{name} must be in (0, 1) (d = 1 - V/V^c: 0 is V^c itself, 1 is V = 0); "
                         f"the branch of stick-slip cycles is continued below V^c only, got {value!r}")
    return value


def check_arguments(model: Model, d_min, max_error, max_points, method, multipliers) -> tuple[float, Auto]:
    """Every argument of :func:`micro.cycle_branch` that needs no V^c: ``d_min`` as a float
    and ``method`` as a :class:`micro.Auto`, or one ValueError naming the first that is wrong."""
    _check_model(model)
    why = cohort_not_applicable(model)
    if why:
        raise ValueError(f"model: cycle_branch computes its cycles by the cohort method, and {why}; other jump "
                         "laws have the Fokker-Planck time-stepping only: micro.sweep(model, V, method='fp')")
    d_min = check_d(d_min, "d_min")
    if not 0.0 < _number("max_error", max_error) <= 1.0:
        raise ValueError(f"max_error must be in (0, 1] (a fraction of the amplitude), got {max_error!r}")
    if not (isinstance(max_points, int) and not isinstance(max_points, bool) and max_points >= 2):
        raise ValueError(f"max_points must be an integer >= 2, got {max_points!r}")
    if not isinstance(multipliers, bool):
        raise ValueError(f"multipliers must be True or False, got {multipliers!r}")
    if isinstance(method, Cohort):
        method = Auto(cohort=method)
    if not isinstance(method, Auto):
        raise ValueError(f"method must be a micro.Cohort or micro.Auto (the cohort method's options), got "
                         f"{type(method).__name__}")
    return d_min, method


def check_start(V_start, d_min: float, Vc: float) -> float:
    """The start's drive velocity (``V_start``; None: ``0.2 V^c``) in (0, V^c) and its
    ``d`` above ``d_min``, or one ValueError naming the first that is not."""
    if V_start is None:
        V_start = 0.2 * Vc
    if not 0.0 < _number("V_start", V_start) < Vc:
        raise ValueError(f"V_start must be in (0, V^c = {Vc:.6g}) (stick-slip; above V^c steady sliding is stable "
                         f"and there is no cycle to start from), got {V_start!r}")
    d_start = 1.0 - V_start / Vc
    if not d_start > d_min:
        raise ValueError(f"d_min must be below the start's d = {d_start:.4g} (V_start = {V_start:g}, "
                         f"V^c = {Vc:.6g}), got {d_min!r}")
    return float(V_start)
