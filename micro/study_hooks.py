"""Hooks for the validation studies (``studies/``) and the benchmarks (``benchmarks/``).

A study sometimes has to see inside a solver: run one cycle of the cohort map on a state,
replay the method's error rules on a sequence, call its Newton-Krylov, solve the renewal
chain on a grid it chooses.  These functions give that access under public names, so that
no code outside ``micro`` reaches a private one.  They are **for studies**: thin wrappers
of the solvers' internals, with no promise of stability to users (use :mod:`micro.api`).
Each says which internal it wraps; the internal's own docstring is the reference.

Cohort method (:mod:`micro.cohort`)
    ``CohortState`` (the state: cohorts, time, slip, stress), ``NO_COARSE``,
    ``start_state``, ``continued``, ``one_cycle``, ``fold_start``, ``phase_step``, ``step_off``,
    ``relaxation_multiplier``, ``error_estimate``, ``state_tail``, ``product_cycle``,
    ``carried_cycle``, ``support``, ``newton_krylov``, ``NEWTON_FD_STEP``, ``gauss_rule``.
Renewal chain (:mod:`micro.renewal`)
    ``quadrature``, ``map_width``, ``chain_grid``, ``chain_on_grid``, ``waiting_time``.
N-block (:mod:`micro.nblock`)
    ``correlated_stderr``, ``drifts``.
"""
from __future__ import annotations

import contextlib
from collections.abc import Iterator

import numpy as np

from . import _renewal_kernels, nblock, renewal
from .cohort import cycle as _cycle, estimate as _estimate, options as _options, solver as _solver, state as _state
from .params import Model

__all__ = [
    "CohortState", "NO_COARSE", "start_state", "continued", "one_cycle", "fold_start", "phase_step", "step_off",
    "relaxation_multiplier", "error_estimate", "state_tail", "product_cycle", "carried_cycle",
    "support", "map_multipliers", "newton_krylov", "NEWTON_FD_STEP", "gauss_rule",
    "quadrature", "map_width", "chain_grid", "chain_on_grid", "waiting_time",
    "correlated_stderr", "drifts",
]

# --- cohort method ---------------------------------------------------------------------

#: The cohort method's state class (``micro.cohort.state._Cohorts``); a study may subclass it to
#: observe a cycle (its methods are the ones ``one_cycle`` calls).
CohortState = _state._Cohorts
#: ``cycle_cohorts(..., start=NO_COARSE)``: no coarse transient first (``micro.cohort.solver._NO_COARSE``).
NO_COARSE = _solver._NO_COARSE
#: The relative step of the Newton-Krylov's difference quotients (``FD_STEP`` of
#: ``micro.cohort.options.DEFAULT``).
NEWTON_FD_STEP = _options.DEFAULT.FD_STEP


def start_state(model: Model, V: float, h: float, p=None, dep=None) -> _state._Cohorts:
    """For studies: the state after a total shock (``micro.cohort.state._start``)."""
    return _state._start(model, V, h, p, dep)


def continued(start, model: Model, V: float, h: float) -> _state._Cohorts | None:
    """For studies: the whole state of a result ``start`` moved to ``V`` with cells ``h``,
    or None (``micro.cohort.state._continued``)."""
    return _state._continued(start, model, V, h)


def one_cycle(state: _state._Cohorts, step: float) -> dict:
    """For studies: one cycle of the cohort map from ``state`` (changed in place) with
    loading steps ``step``; its extrema, period and unjumped fraction (``micro.cohort.cycle._one_cycle``)."""
    return _cycle._one_cycle(state, step)


def fold_start(state: _state._Cohorts, step: float) -> tuple[float, float]:
    """For studies: where in a step of ``step`` from ``state`` that starts a shock the fold
    appears, as (the longest part without a fold, its slip) (``micro.cohort.cycle._fold_start``)."""
    return _cycle._fold_start(state, step)


def phase_step(period: float, dt: float) -> float:
    """For studies: the loading step a run takes for a cycle of ``period`` at ``dt``
    (``micro.cohort.cycle._phase_step``)."""
    return _cycle._phase_step(period, dt)


def step_off(period: float, step: float, dt: float) -> bool:
    """For studies: whether ``step`` is no longer the step for ``period`` (a run starts its
    sequence again; ``micro.cohort.cycle._step_off``)."""
    return _cycle._step_off(period, step, dt)


def relaxation_multiplier(model: Model, period: float) -> float:
    """For studies: the slowest relaxation's multiplier over one period
    (``micro.cohort.estimate._relaxation_multiplier``)."""
    return _estimate._relaxation_multiplier(model, period)


def error_estimate(a: np.ndarray, tol: float, slowest: float = 0.0):
    """For studies: the run's error rule from its cycles' values ``a`` (``micro.cohort.estimate._estimate``):
    errors, how each was found, the best values, and the extrapolated ones."""
    return _estimate._estimate(a, tol, slowest)


def state_tail(a: np.ndarray, moves: np.ndarray, steps: np.ndarray, slowest: float = 0.0) -> tuple[float, float]:
    """For studies: the bound from the state's move (``micro.cohort.estimate._state_tail``)."""
    return _estimate._state_tail(a, moves, steps, slowest)


def product_cycle(model: Model, V: float, h: float, step: float, ref: float, x: np.ndarray):
    """For studies: the cycle map on the normalised delta_R marginal ``x`` (``micro.cohort.cycle._product_cycle``)."""
    return _cycle._product_cycle(model, V, h, step, ref, x)


def carried_cycle(base: _state._Cohorts, step: float, ref: float, v: np.ndarray):
    """For studies: one cycle from ``base`` with its cells' masses ``v`` (``micro.cohort.cycle._carried_cycle``)."""
    return _cycle._carried_cycle(base, step, ref, v)


def support(x: np.ndarray, g: np.ndarray) -> np.ndarray:
    """For studies: the cells the cycle map acts on (``micro.cohort.solver._support``)."""
    return _solver._support(x, g)


def map_multipliers(base: _state._Cohorts, step: float, ref: float, x: np.ndarray, k: int = 3,
                    ncv: int = 25, tol: float = 1e-4) -> tuple[np.ndarray, int]:
    """For studies: the ``k`` largest multipliers of the cycle map from ``base`` at the
    marginal ``x``, and the cycles taken (``micro.cohort.solver._map_multipliers``, which
    :func:`micro.cohort.cycle_multipliers` uses with a smaller Krylov space)."""
    return _solver._map_multipliers(base, step, ref, x, k, ncv, tol)


def newton_krylov(step: float, dt: float, base: _state._Cohorts, tol: float, max_evals: int):
    """For studies: the Newton-Krylov fixed point of the whole cycle map that
    ``cycle_cohorts`` falls back on (``micro.cohort.solver._newton``)."""
    return _solver._newton(step, dt, base, tol, max_evals)


@contextlib.contextmanager
def gauss_rule(x: np.ndarray, w: np.ndarray) -> Iterator[None]:
    """For studies: the cohort method's Gauss nodes ``x`` and weights ``w`` on [0, 1]
    (``micro.cohort.state._GX``, ``_GW``; two-point Gauss-Legendre by default) replaced inside
    the ``with`` block, restored after it."""
    old = _state._GX, _state._GW
    _state._GX, _state._GW = np.asarray(x, float), np.asarray(w, float)
    try:
        yield
    finally:
        _state._GX, _state._GW = old


# --- renewal chain ---------------------------------------------------------------------

def quadrature(model: Model, V: float):
    """For studies: the chain's quadrature in the wait (``micro.renewal._quadrature``)."""
    return renewal._quadrature(model, V)


def map_width(model: Model) -> float:
    """For studies: the width of the chain's grid (``micro.renewal._map_width``)."""
    return renewal._map_width(model)


def chain_grid(n: int, width: float | None = None, model: Model | None = None):
    """For studies: the chain's grid of ``n`` nodes over [0, ``width``] (or the map's width
    of ``model``), which ``steady_sliding`` chooses itself (``micro.renewal._Grid.build``)."""
    if width is None:
        if model is None:
            raise ValueError("chain_grid: give width or model")
        width = renewal._map_width(model)
    return renewal._Grid.build(n, 0.0, width)


def chain_on_grid(model: Model, V: float, quad, grid):
    """For studies: the renewal chain solved on a fixed ``grid`` (:func:`chain_grid`) with
    the quadrature ``quad`` (:func:`quadrature`; ``micro.renewal._Chain.solve``)."""
    return renewal._Chain.solve(model, V, quad, grid)


def waiting_time(zeta: float, D: float, alpha: float, beta: float) -> float:
    """For studies: the chain's Newton waiting time (``micro._renewal_kernels.waiting_time``)."""
    return _renewal_kernels.waiting_time(zeta, D, alpha, beta)


# --- N-block ---------------------------------------------------------------------------

def correlated_stderr(values: np.ndarray) -> float:
    """For studies: the standard error of a mean with AR(1) correlation (``micro.nblock._correlated_stderr``)."""
    return nblock._correlated_stderr(values)


def drifts(values: np.ndarray) -> bool:
    """For studies: whether ``values`` has a linear trend (``micro.nblock._drifts``)."""
    return nblock._drifts(values)
