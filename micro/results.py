"""The result types of :mod:`micro`, in one place.

:class:`Run` (a protocol run), :class:`Stationary` (the attractor at one velocity, one
row of a sweep), :class:`Critical` (V^c) and :class:`CycleFixedPoint` (a stick-slip
cycle of the cohort method, with what continues it).  Every row says which method
produced it (``method``) and what its error covers.
"""
from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import TYPE_CHECKING

import numpy as np

from .params import Model

if TYPE_CHECKING:  # pragma: no cover  (pandas only in annotations: the renewal chain's V^c does without it)
    import pandas as pd

    from .grid import Grid

__all__ = ["Run", "Stationary", "Critical", "CycleFixedPoint"]


@dataclass
class CycleFixedPoint:
    """A stick-slip limit cycle of the cohort method (:func:`micro.cohort.cycle_cohorts`)
    at one time step and cell ``eps`` (its ``h``): extrema, period, and how the iteration
    ended.

    A cohort row of :func:`micro.stationary` keeps it as its ``cycle``; given back as
    ``initial`` (or as ``start`` to :func:`~micro.cohort.cycle_cohorts`) a run at a nearby
    V or at half the cell continues from its ``state``.

    Attributes
    ----------
    model : Model
        The model.
    V : float
        The drive velocity.
    eps : float
        The delta_R cell ``h`` of the run.
    sigma_max : float
        The largest stress of the cycle, which the creep before a shock can put above
        ``sigma_before``.
    sigma_min : float
        The smallest stress of the cycle.
    period : float
        The cycle's duration (its loading phase: a shock takes no time).
    sigma_mean : float
        The time mean of the stress over the cycle.
    mass_error : float
        The mass (a fraction of all blocks) lost by the state: what left the delta_R
        nodes plus the cells dropped for holding almost none.
    min_mass : float
        Always 0 here (the field matches :class:`Stationary`'s; the cohort method's
        check is ``mass_error``).
    iterations : int
        Cycles run, those of Anderson's iteration included.
    error : float
        An estimate of the distance of sigma_max and sigma_min from the fixed point at
        this resolution (it is not the discretisation error); NaN where not known (fewer
        cycles than the estimate needs, or a frozen map that grows: see ``message``).
    unjumped : float
        The mass the last shock left unjumped.
    converged : bool
        Whether the stopping test was met.
    message : str
        How the iteration ended, with the errors it reached.
    wall_time : float
        Seconds taken, the run at twice the step and cell included.
    applicable : bool
        False when the cohort method does not describe the cycle (a loading phase that
        ends in no shock; ``message`` says why).
    history : ndarray or None
        One row (sigma_max, sigma_min, period, sigma_mean, sigma_before, sigma_after) per
        cycle since the iteration last restarted (a new step or Anderson's iteration
        clears it).  Without convergence the result's stresses and period are the last
        row's; with it, the estimates of the fixed point.
    p : tuple of ndarray, or None
        The delta_R marginal after a total shock, ``(nodes, masses)``; None after a shock
        that left blocks unjumped.
    state : object or None
        The whole state after the last shock, from which a run at a nearby V or at half
        the cell continues; None where the method did not apply or no cycle ended, and
        on ``coarse``.
    sigma_before, sigma_after : float
        The stress when the shock starts and right after it (the paper's sigma_B and
        sigma_A).
    accelerated : bool
        Whether Anderson's preconditioned iteration was tried (close to V^c, where the
        cycles contract slowly).
    coarse : CycleFixedPoint or None
        The same cycle at twice the step and cell when the run started from it (its
        transient), if that run converged; else None.
    trace : tuple of ndarray, or None
        The last cycle's stress against time, ``(t, sigma)``: t = 0 right after the shock
        before it, then the end of each of its steps, and last the shock's drop (two
        points at t = ``period``).  The stress between step ends is not sampled, so the
        largest point can lie a little below ``sigma_max`` (the peak the creep before the
        shock makes).  None where no cycle ended.
    """

    model: Model
    V: float
    eps: float
    sigma_max: float
    sigma_min: float
    period: float
    sigma_mean: float
    mass_error: float
    min_mass: float
    iterations: int
    error: float
    unjumped: float
    converged: bool
    message: str
    wall_time: float
    applicable: bool = True
    history: np.ndarray | None = None
    p: tuple[np.ndarray, np.ndarray] | None = None
    state: object | None = field(default=None, repr=False)
    sigma_before: float = math.nan
    sigma_after: float = math.nan
    accelerated: bool = False
    coarse: "CycleFixedPoint | None" = field(default=None, repr=False)
    trace: tuple[np.ndarray, np.ndarray] | None = field(default=None, repr=False)

    @property
    def coarse_change(self) -> float:
        """The largest change of sigma_max and sigma_min from ``coarse`` (NaN without it)."""
        if self.coarse is None:
            return math.nan
        return max(abs(self.sigma_max - self.coarse.sigma_max), abs(self.sigma_min - self.coarse.sigma_min))

    @property
    def discretisation_bound(self) -> float:
        """:attr:`coarse_change` plus both fixed points' errors: a bound on the coarse
        cycle's discretisation error, so on this one's where the refinement is asymptotic
        (checked for 0.02 <= d <= 0.2 in docs/validation/micro_transition.md; beyond it
        ``micro.stationary`` does not report it).  NaN without ``coarse`` or where a fixed
        point is not certified."""
        return self.coarse_change + self.coarse.error + self.error if self.coarse is not None else math.nan


@dataclass
class Run:
    """A protocol run: the stress records, the shocks, the final grid, and the ``method``
    that produced them.

    Returned by :func:`micro.simulate`.

    Attributes
    ----------
    records : pandas.DataFrame
        The stress time series, columns ``t, w, sigma, sigma_min, sigma_max, sigma_mean``:
        the time since the run started, the drive's position, the stress, and its extrema
        and time mean over the window since the previous row.
    shocks : pandas.DataFrame
        One row per global shock (a step whose cascade shifted delta_F by more than 8
        bins), columns ``t, sigma_before, sigma_after, shift`` (the shift in bins).
    grid : micro.grid.Grid
        The final density; as ``initial`` it starts another run from here.
    wall_time : float
        Seconds taken.
    mass_error : float
        ``abs(total probability - 1)`` of the final density.
    min_mass : float
        The most negative cell mass of the final density, 0 if none.
    method : str
        The method that produced the run, ``"fp"``.
    """

    records: pd.DataFrame
    shocks: pd.DataFrame
    grid: Grid
    wall_time: float
    mass_error: float = math.nan
    min_mass: float = math.nan
    method: str = "fp"

    def to_frame(self) -> pd.DataFrame:
        """The stress records, :attr:`records`."""
        return self.records


@dataclass
class Stationary:
    """The attractor at constant drive velocity: a steady stress or a stick-slip cycle.

    Returned by :func:`micro.stationary`; :meth:`to_dict` is one row of
    :func:`micro.sweep`.  Each row says which method produced it (``method``) and what
    its error covers: ``discretisation_error`` what the discretisation may have moved,
    ``sigma_stderr`` the iteration's own error.

    Attributes
    ----------
    model : Model
        The model.
    V : float
        The drive velocity.
    eps : float
        The resolution: the Fokker-Planck bin, or the cohort method's delta_R cell; NaN
        on renewal rows.
    regime : str
        ``"steady"``, ``"stick-slip"``, or ``"unknown"`` (a Fokker-Planck run that
        ended still loading, or with an oscillation it could not classify).
    sigma_max, sigma_min, sigma_mean : float
        The largest, smallest and time-mean stress; all three equal on steady rows.
        ``sigma_max`` is the largest stress of the cycle, above ``sigma_before`` where
        the creep that precedes a shock outruns the drive (by up to 1e-3 at k0 = 0.3).
    period : float
        The cycle's period; NaN on steady rows.
    converged : bool
        Whether the stopping test was met.
    message : str
        Why the run ended (on cohort rows also what the errors cover).
    t_end : float
        Simulated time: the Fokker-Planck run's length, the sum of the cohort cycles'
        periods in its history, 0 on renewal rows.
    n_cycles : int
        Fokker-Planck: the cycles found in the stress records; cohort: the cycles
        iterated; renewal: 0.
    wall_time : float
        Seconds taken.
    sigma_stderr : float
        The error of the iteration alone.  Fokker-Planck: the statistical error of
        ``sigma_mean`` from the discretisation jitter (the solver is deterministic, but
        its stress jitters at the scale k0 * eps), over the time means; cohort: the
        fixed point's error (:attr:`CycleFixedPoint.error`); renewal: the chain's error
        estimate.
    shocks_per_cycle : float
        The global shocks (cascades of more than 8 bins) per cycle of a stick-slip
        result: 1 on cohort rows, 0 on renewal rows, NaN on steady Fokker-Planck rows.
    mass_error : float
        ``abs(total probability - 1)``; with ``min_mass``, the solver's own check of the
        density.
    min_mass : float
        The most negative cell mass ever seen, 0 if none.
    sigma_before, sigma_after : float
        ``method="cohort"`` only, NaN otherwise: the stress when a global shock starts
        and right after it (the paper's sigma_B and sigma_A).
    method : str
        The method that produced the row: ``"renewal"``, ``"cohort"`` or ``"fp"``.
    discretisation_error : float
        A bound on the row's error from its discretisation, where that is known: the
        renewal chain's own error estimate on steady rows; on cohort rows the largest
        change of sigma_max and sigma_min from the run at twice the time step and cell
        (its transient) plus both runs' fixed-point errors, away from V^c
        (``micro.api.NEAR_VC``, d = 0.02); NaN where it is not known (closer to V^c, and on
        Fokker-Planck rows, where it takes a study in eps).
    records : pandas.DataFrame or None
        The stress time series (columns ``t, sigma, sigma_min, sigma_max,
        sigma_mean``) of a Fokker-Planck run asked for ``keep_records``; else None.
    shocks : pandas.DataFrame or None
        With ``records``, its global shocks (columns ``t, sigma_before, sigma_after,
        shift``); else None.
    grid : micro.grid.Grid or None
        The final density of a Fokker-Planck run asked for ``keep_grid``; else None.
    cycle : CycleFixedPoint or None
        The cohort method's cycle on cohort rows (``initial`` for a run that continues
        it); else None.
    """

    model: Model
    V: float
    eps: float
    regime: str
    sigma_max: float
    sigma_min: float
    sigma_mean: float
    period: float
    converged: bool
    message: str
    t_end: float
    n_cycles: int
    wall_time: float
    sigma_stderr: float = math.nan
    shocks_per_cycle: float = math.nan
    mass_error: float = math.nan
    min_mass: float = math.nan
    sigma_before: float = math.nan
    sigma_after: float = math.nan
    method: str = "fp"
    discretisation_error: float = math.nan
    records: pd.DataFrame | None = field(default=None, repr=False)
    shocks: pd.DataFrame | None = field(default=None, repr=False)
    grid: Grid | None = field(default=None, repr=False)
    cycle: CycleFixedPoint | None = field(default=None, repr=False)

    def to_dict(self) -> dict:
        """The row as a flat dict: the model's ``k0, k1, k2, zbar`` and every scalar field
        (not ``records``, ``shocks``, ``grid`` or ``cycle``)."""
        m = self.model
        return {
            "k0": m.k0, "k1": m.k1, "k2": m.k2, "zbar": m.zbar, "V": self.V, "method": self.method,
            "regime": self.regime,
            "sigma_max": self.sigma_max, "sigma_min": self.sigma_min, "sigma_mean": self.sigma_mean,
            "sigma_before": self.sigma_before, "sigma_after": self.sigma_after, "period": self.period,
            "sigma_stderr": self.sigma_stderr, "discretisation_error": self.discretisation_error,
            "shocks_per_cycle": self.shocks_per_cycle,
            "converged": self.converged,
            "message": self.message,
            "eps": self.eps, "t_end": self.t_end, "n_cycles": self.n_cycles, "wall_time": self.wall_time,
            "mass_error": self.mass_error, "min_mass": self.min_mass,
        }


#: The statuses of a V^c search that ends at an end of its range (the command line names
#: --V-min and --V-max instead).
BELOW = "V^c below V_min"
ABOVE = "V^c above V_max"


@dataclass
class Critical:
    """The critical velocity V^c, with ``V_low`` (stick-slip) and ``V_high`` (steady) around
    it: the renewal chain's root and its error, or the Fokker-Planck bisection's bracket
    (``method``).

    Returned by :func:`micro.critical_velocity`.

    Attributes
    ----------
    model : Model
        The model.
    Vc : float
        V^c: the root of b(V) = 1, or the geometric mean of the bisection's bracket; NaN
        with status ``"no stick-slip"`` (there is no critical velocity; rsf's encoding of
        "stable at every V" too) and with ``"V^c below V_min"`` (it lies below the range),
        ``inf`` with ``"V^c above V_max"``.
    V_low : float
        Below V^c (stick-slip): ``Vc`` minus its error, or the bracket's lower end; 0
        with ``"no stick-slip"`` and ``"V^c below V_min"``, ``V_max`` with ``"V^c above V_max"``.
    V_high : float
        Above V^c (steady): ``Vc`` plus its error, or the bracket's upper end;
        ``V_min`` with ``"no stick-slip"`` and ``"V^c below V_min"``, ``inf`` with
        ``"V^c above V_max"``.
    status : str
        ``"converged"``, ``"no stick-slip"`` (steady sliding is stable at every V:
        ``k0 >= k2``), ``"V^c below V_min"`` (stable already at ``V_min``, though unstable
        at smaller V) or ``"V^c above V_max"`` (still stick-slip at ``V_max``).
    message : str
        How the search ended.
    evaluations : list of dict
        One dict per evaluation: renewal, ``V, branching_ratio, error`` of each b(V);
        Fokker-Planck, each run's :meth:`Stationary.to_dict` with the ``label`` the
        bisection used, the velocity it ``started_from``, its cycle ``amplitude``,
        ``amplitude_fine`` and ``wall_time_fine`` (:func:`micro.fp.critical_velocity_fp`).
        Empty where a closed form decided (``k0 >= k2`` or ``k2 = 0``).
    method : str
        ``"renewal"`` or ``"fp"``.
    """

    model: Model
    Vc: float
    V_low: float
    V_high: float
    status: str
    message: str
    evaluations: list[dict]
    method: str = "renewal"

    def to_dict(self) -> dict:
        """The model's ``k0, k1, k2, zbar`` and every field but ``evaluations``, as a flat
        dict."""
        m = self.model
        return {"k0": m.k0, "k1": m.k1, "k2": m.k2, "zbar": m.zbar, "Vc": self.Vc, "V_low": self.V_low,
                "V_high": self.V_high, "status": self.status, "message": self.message, "method": self.method}


