r"""The stick-slip branch below V^c, point by point in log d: :func:`cycle_branch`.

``d = 1 - V / V^c`` is the distance from the critical velocity.  The branch is walked from
a start ``V`` towards ``d_min`` with a step in ``log d`` that adapts to how well a secant
through the last two points predicted the next one; each point is the default stick-slip
cycle of :func:`micro.stationary` (the cohort method), so each carries its own errors:

* ``fixed_point_error``: the iteration's distance from the cycle map's fixed point at the
  point's resolution (:attr:`micro.CycleFixedPoint.error`);
* ``discretisation_error``: the change of sigma_max and sigma_min from the same cycle at
  twice the time step and cell, plus both fixed points' errors
  (:attr:`micro.CycleFixedPoint.discretisation_bound`), where the refinement was checked
  to be asymptotic (``micro.api.NEAR_VC``: d >= 0.02); NaN closer to V^c.

A point is *certified* when both are known and their sum is at most ``max_error`` times the
cycle's amplitude.  The walk stops at ``d_min``, or at the first point that is not
certified (kept, with ``certified`` False), or at a point that fails (not kept), and says
which in :attr:`Branch.reason`: everything computed before is returned.  Closer to V^c
than d = 0.02 today's cohort method does not know its discretisation error, so a branch
asked for ``d_min`` below that ends at d = 0.02, saying so (``complete`` False).  The
points are not continued from one another: each starts from its own run at twice the step
and cell, which gives its discretisation error.
"""
from __future__ import annotations

import math
import time
from dataclasses import dataclass, field
from typing import Callable

import numpy as np
import pandas as pd

from . import _progress
from ._branch_checks import check_arguments, check_start
from .api import NEAR_VC, _vc, check_cohort_work, stationary
from .cohort import cycle_multipliers
from .methods import Auto, Cohort
from .params import Model

__all__ = ["Branch", "cycle_branch", "COLUMNS"]

#: The columns of :attr:`Branch.points` (and of ``python -m micro branch``'s CSV).
COLUMNS = ("k0", "k1", "k2", "zbar", "V", "d", "sigma_max", "sigma_min", "sigma_before", "sigma_after",
           "sigma_mean", "period", "amplitude", "fixed_point_error", "discretisation_error", "certified",
           "floquet_1", "floquet_1_angle", "floquet_2", "method", "n_cycles", "wall_time", "message")

#: The first step in log10 d, and the bounds the adaptive step stays within.
FIRST_STEP = 0.15
STEP_RANGE = (0.02, 0.4)
#: The secant predictor's error the step aims at, as a fraction of the amplitude: the step
#: is scaled by sqrt(target / error) (the secant's error is second order in the step),
#: within [1/2, 2] per point.
PREDICTION_TARGET = 0.02


@dataclass
class Branch:
    """A stick-slip branch computed by :func:`cycle_branch`.

    Attributes
    ----------
    model : Model
        The model.
    Vc : float
        The critical velocity (renewal chain).
    points : pandas.DataFrame
        One row per point, in the order computed (d decreasing), columns :data:`COLUMNS`.
    complete : bool
        Whether the walk reached ``d_min`` with every point certified.
    reason : str
        Why the walk ended.
    wall_time : float
        Seconds taken.
    """

    model: Model
    Vc: float
    points: pd.DataFrame = field(repr=False)
    complete: bool
    reason: str
    wall_time: float


def _check_inputs(model: Model, V_start, d_min, max_error, max_points, method,
                  multipliers) -> tuple[float, float, Auto]:
    """Every argument, before anything long is computed (V^c takes milliseconds)."""
    d_min, method = check_arguments(model, d_min, max_error, max_points, method, multipliers)
    V_start = check_start(V_start, d_min, _vc(model))
    method.cohort.cell(model)
    check_cohort_work(model, V_start, method.cohort)
    return V_start, d_min, method


def _point(res, d: float, max_error: float, multipliers: bool) -> dict:
    m = res.model
    mu, note = np.full(2, np.nan), ""
    if multipliers and res.cycle is not None and res.converged:
        try:
            mu = cycle_multipliers(res.cycle, k=2)
        except (ValueError, ArithmeticError, RuntimeError) as exc:  # (the cycle itself stands)
            note = f"; multipliers not found: {exc}"
    amplitude = res.sigma_max - res.sigma_min
    fixed = float(res.sigma_stderr)
    disc = float(res.discretisation_error)
    certified = (res.regime == "stick-slip" and res.method == "cohort" and bool(res.converged)
                 and math.isfinite(fixed) and math.isfinite(disc) and fixed + disc <= max_error * amplitude)
    return {"k0": m.k0, "k1": m.k1, "k2": m.k2, "zbar": m.zbar, "V": res.V, "d": d,
            "sigma_max": res.sigma_max, "sigma_min": res.sigma_min, "sigma_before": res.sigma_before,
            "sigma_after": res.sigma_after, "sigma_mean": res.sigma_mean, "period": res.period,
            "amplitude": amplitude, "fixed_point_error": fixed, "discretisation_error": disc,
            "certified": certified, "floquet_1": float(abs(mu[0])), "floquet_1_angle": float(np.angle(mu[0])),
            "floquet_2": float(abs(mu[1])), "method": res.method, "n_cycles": res.n_cycles,
            "wall_time": res.wall_time, "message": res.message + note}


def _not_certified(row: dict, regime: str, max_error: float) -> str:
    d = row["d"]
    if row["method"] != "cohort" or regime != "stick-slip":
        return f"at d = {d:.4g} the answer is not a cohort stick-slip cycle ({row['message']})"
    if not math.isfinite(row["discretisation_error"]):
        if d < NEAR_VC:
            return (f"at d = {d:.4g} the discretisation error is not known: today's cohort method resolves the "
                    f"cycle with a step and cell that do not follow its scale, and its refinement was checked "
                    f"to be asymptotic for d >= {NEAR_VC:g} only")
        return f"at d = {d:.4g} the discretisation error is not known ({row['message']})"
    if not math.isfinite(row["fixed_point_error"]):
        return f"at d = {d:.4g} the fixed point is not certified ({row['message']})"
    return (f"at d = {d:.4g} the errors (fixed point {row['fixed_point_error']:.1e} + discretisation "
            f"{row['discretisation_error']:.1e}) exceed {max_error:g} of the amplitude {row['amplitude']:.3g}")


def _next_step(ds: list[float], amps: list[float], maxs: list[float], step: float) -> float:
    """The next step in log10 d: the secant in d through the two points before the last
    predicts the last one's sigma_max (exact where the cycle is linear in d, as it becomes
    near V^c); the step is scaled by sqrt(target / prediction error), by 1/2 to 2."""
    if len(ds) < 3:
        return step
    x = ds[-3:]
    y = maxs[-3:]
    predicted = y[1] + (y[1] - y[0]) * (x[2] - x[1]) / (x[1] - x[0])
    error = abs(predicted - y[2]) / max(amps[-1], 1e-300)
    factor = 2.0 if error == 0.0 else min(2.0, max(0.5, math.sqrt(PREDICTION_TARGET / error)))
    return min(STEP_RANGE[1], max(STEP_RANGE[0], step * factor))


def cycle_branch(
    model: Model,
    V_start: float | None = None,
    *,
    d_min: float = 1e-3,
    max_error: float = 0.1,
    max_points: int = 60,
    method: Cohort | Auto | None = None,
    multipliers: bool = False,
    on_point: Callable[[pd.DataFrame], None] | None = None,
) -> Branch:
    """The stick-slip branch from ``V_start`` towards ``d_min = 1 - V/V^c``.

    Parameters
    ----------
    model : the model; exponential jumps (the cohort method).
    V_start : the first point's drive velocity, in (0, V^c); default ``0.2 V^c``.
    d_min : where to stop, in (0, 1) and below the start's d (default 1e-3).
    max_error : a point is certified when its fixed-point and discretisation errors sum to
        at most this fraction of its amplitude, in (0, 1] (default 0.1); the walk stops
        after the first point that is not.
    max_points : most points computed, >= 2 (default 60).
    method : the cohort method's options (:class:`micro.Cohort`); default its defaults.
    multipliers : also the cycle map's two leading multipliers at each point (its
        Floquet multipliers, :func:`micro.cohort.cycle_multipliers`): columns
        ``floquet_1`` (the largest modulus; the cycle is stable where it is below 1),
        ``floquet_1_angle`` (its argument, radians) and ``floquet_2``.  About 14 more
        cycles a point, which doubles its cost far from V^c; NaN when not asked, and
        where the shocks leave more than 1e-3 of the blocks (the message says so).
    on_point : called with the frame of the points so far after each point (a command line
        writes it, so that a later failure or a kill loses nothing).

    Returns
    -------
    Branch
        The points computed, whether the walk reached ``d_min``, and why it ended.

    Raises
    ------
    ValueError
        For a bad argument (one line naming it and its range), before anything long is
        computed: ``d_min`` outside (0, 1), a ``V_start`` at or above V^c, jumps that are
        not exponential.
    """
    started = time.perf_counter()
    V_start, d_min, opts = _check_inputs(model, V_start, d_min, max_error, max_points,
                                         Auto() if method is None else method, multipliers)
    Vc = _vc(model)
    rows: list[dict] = []
    d = 1.0 - V_start / Vc
    step = FIRST_STEP
    # closer than NEAR_VC no point can be certified (its discretisation error is not known):
    # the walk ends there rather than compute a point it must then report uncertified
    floor = max(d_min, min(NEAR_VC, d))
    reason = (f"reached d_min = {d_min:g}" if floor == d_min else
              f"stopped at d = {floor:g} before d_min = {d_min:g}: closer to V^c today's cohort method does not "
              f"know its discretisation error (its step and cell do not follow the cycle's scale, and its "
              f"refinement was checked to be asymptotic for d >= {NEAR_VC:g} only)")
    complete = False
    while True:
        V = Vc * (1.0 - d)
        try:
            with _progress.stage(f"point {len(rows) + 1}, d={d:.4g}, V={V:.6g}"):
                res = stationary(model, V, method=opts, warn=False)
                row = _point(res, d, max_error, multipliers)
        except (ValueError, ArithmeticError, RuntimeError) as exc:
            reason = f"the point at d = {d:.4g} (V = {V:.10g}) failed: {exc}"
            break
        if not row["certified"]:
            reason = _not_certified(row, res.regime, max_error)
        rows.append(row)
        if on_point is not None:
            on_point(pd.DataFrame(rows, columns=COLUMNS))
        if not row["certified"]:
            break
        if d <= floor * (1.0 + 1e-12):
            complete = floor == d_min
            break
        if len(rows) >= max_points:
            reason = f"max_points = {max_points} reached at d = {d:.4g}, before d_min = {d_min:g}"
            break
        step = _next_step([r["d"] for r in rows], [r["amplitude"] for r in rows],
                          [r["sigma_max"] for r in rows], step)
        d *= 10.0 ** (-step)
        if d < floor * 10.0 ** STEP_RANGE[0]:   # (no remainder shorter than the shortest step)
            d = floor
    frame = pd.DataFrame(rows, columns=COLUMNS)
    return Branch(model=model, Vc=Vc, points=frame, complete=complete, reason=reason,
                  wall_time=time.perf_counter() - started)
