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
import pandas as pd

from .params import Model

if TYPE_CHECKING:  # pragma: no cover
    from .grid import Grid

__all__ = ["Run", "Stationary", "Critical", "CycleFixedPoint"]


@dataclass
class CycleFixedPoint:
    """A stick-slip limit cycle of the cohort method (:func:`micro.cohort.cycle_cohorts`)
    at one time step and cell ``eps`` (its ``h``): extrema, period, and how the iteration
    ended.

    ``error`` estimates the distance of sigma_max and sigma_min from the fixed point at
    this resolution (it is not the discretisation error); ``unjumped`` is the mass the
    last shock left unjumped; ``applicable`` is False when the cohort method does not
    describe the cycle (a loading phase that ends in no shock); ``history`` holds the rows
    (sigma_max, sigma_min, period, sigma_mean, sigma_before, sigma_after) of every cycle,
    ``p`` the delta_R marginal after a total shock (nodes, masses); ``state``, the whole
    state after the last shock, from which a run at a nearby V or at half the cell
    continues; ``sigma_before`` and ``sigma_after``, the stress when the shock starts and
    right after it (the paper's sigma_B and sigma_A: ``sigma_max`` is the largest stress
    of the cycle, which the creep before a shock can put above ``sigma_before``);
    ``coarse``, the same cycle at twice the step and cell when the run started from it
    (its transient), or None.
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


@dataclass
class Run:
    """A protocol run: the stress records, the shocks, the final grid, and the ``method``
    that produced them."""

    records: pd.DataFrame
    shocks: pd.DataFrame
    grid: Grid
    wall_time: float
    mass_error: float = math.nan
    min_mass: float = math.nan
    method: str = "fp"

    def to_frame(self) -> pd.DataFrame:
        return self.records


@dataclass
class Stationary:
    """The attractor at constant drive velocity: a steady stress or a stick-slip cycle.

    ``sigma_max``, ``sigma_min`` and ``sigma_mean`` are equal on steady rows;
    ``sigma_stderr`` is the statistical error of ``sigma_mean`` from the discretisation
    jitter (the solver is deterministic, but its stress jitters at the scale k0 * eps).
    ``shocks_per_cycle`` counts the global shocks (cascades of more than 8 bins) per
    cycle of a stick-slip result.
    ``converged`` says whether the stopping test was met; ``message`` says why the run
    ended.  ``mass_error`` (``abs(total probability - 1)``) and ``min_mass`` (the most negative
    cell mass ever seen, 0 if none) are the solver's own checks of the density.
    ``records`` holds the stress time series when asked for.

    ``method`` names the method that produced the row (``"renewal"``, ``"cohort"`` or
    ``"fp"``).  ``discretisation_error`` bounds the row's error from its discretisation
    where that is known: the renewal chain's own error estimate on steady rows; on cohort
    rows the largest change of sigma_max and sigma_min from the run at twice the time
    step and cell (its transient) plus both runs' fixed-point errors, away from V^c
    (``micro.api.NEAR_VC``); NaN where it is not known (close to V^c the cohort's cell refinement is
    not monotone, and on Fokker-Planck rows it takes a study in eps).  ``sigma_stderr``
    is then the error of the iteration alone (cohort: the fixed point's; FP: the
    statistical error of the time means).  ``sigma_before`` and
    ``sigma_after`` (``method="cohort"`` only, NaN otherwise) are the stress when a global
    shock starts and right after it (the paper's sigma_B and sigma_A): ``sigma_max`` is
    the largest stress of the cycle, above ``sigma_before`` where the creep that precedes
    a shock outruns the drive (by up to 1e-3 at k0 = 0.3).
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


@dataclass
class Critical:
    """The critical velocity V^c, with ``V_low`` (stick-slip) and ``V_high`` (steady) around
    it: the renewal chain's root and its error, or the Fokker-Planck bisection's bracket
    (``method``)."""

    model: Model
    Vc: float
    V_low: float
    V_high: float
    status: str
    message: str
    evaluations: list[dict]
    method: str = "renewal"

    def to_dict(self) -> dict:
        m = self.model
        return {"k0": m.k0, "k1": m.k1, "k2": m.k2, "zbar": m.zbar, "Vc": self.Vc, "V_low": self.V_low,
                "V_high": self.V_high, "status": self.status, "message": self.message, "method": self.method}


