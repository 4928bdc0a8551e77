"""The question-level API of :mod:`micro`: one call per question, each dispatching to the
best method for it through one table, as ``scipy.integrate.solve_ivp`` dispatches to its
methods.

=====================  ==========================================================
question               methods (``"auto"``, the default, first)
=====================  ==========================================================
:func:`stationary`     auto: renewal chain where steady sliding is stable, cohort
                       method for stick-slip (exponential jumps), Fokker-Planck
                       where neither applies or its state is asked for;
                       ``"cohort"``, ``"fp"``
:func:`sweep`          as :func:`stationary`, one row per velocity, continued
:func:`micro.cycle_branch`  the stick-slip branch towards V^c in log d, each point the
                       default cycle with its errors (:mod:`micro.branch`)
:func:`critical_velocity`  auto = ``"renewal"`` (exact); ``"fp"`` (bisection)
:func:`simulate`       auto = ``"fp"`` (the only method that carries a transient)
:func:`slide_hold_slide`  auto = ``"fp"``
=====================  ==========================================================

``method=`` takes a name or an options object (:mod:`micro.methods`); every result
says which method produced it (``method``), and each row says what its error covers.
"""
from __future__ import annotations

import logging
import math
import time

import numpy as np
import pandas as pd

from . import _progress, fp
from .analytic import sigma_fast_limit
from .cohort import cycle_cohorts, not_applicable as cohort_not_applicable, options as cohort_options
from .methods import COHORT_STEPS_MAX, FP, Auto, Cohort, Convergence, Method, Renewal, check_velocity, resolve
from .params import Model, _number
from .protocols import Drive
from .renewal import V_RANGE, cached_vc as _vc, critical_velocity_renewal, steady_sliding
from .results import BELOW, Critical, CycleFixedPoint, Run, Stationary

__all__ = ["stationary", "sweep", "critical_velocity", "simulate", "slide_hold_slide"]

log = logging.getLogger(__name__)

#: Closer to V^c than this (d = (V^c - V) / V^c) a cohort row reports no discretisation
#: error (NaN, not known).  From d = 0.2 down to here the bound (the change from the run
#: at twice the step and cell, plus both fixed points' errors) was checked against the
#: Richardson limit of two finer levels at k0 = 0.3, 0.1, 0.01 and 1e-3
#: (``studies/micro_transition_error_check.py``,
#: docs/validation/micro_transition.md): it covers the true error 3 to 20 times over.
#: Closer, at k0 = 0.01, d = 0.01, the fixed point at dt = 0.02 is no longer certified
#: and the finer levels differ by 6 % of the amplitude.
NEAR_VC = 0.02


def _check_model(model) -> Model:
    if not isinstance(model, Model):
        raise ValueError(f"model must be a micro.Model, got {type(model).__name__}")
    return model


def _check_numerics(numerics, method: Method) -> FP | None:
    """The Fokker-Planck options: ``numerics``, or ``method`` given as a :class:`FP`
    object (not both), or None (its defaults)."""
    given = method if isinstance(method, FP) else None
    if numerics is None:
        return given
    if not isinstance(numerics, FP):
        raise ValueError(f"numerics must be a micro.FP (micro.Numerics), got {type(numerics).__name__}")
    if given is not None and given != numerics:
        raise ValueError("give the Fokker-Planck options once: as method=micro.FP(...) or as numerics=, not both")
    return numerics


# ------------------------------------------------------------------------------ stationary
def _renewal_row(model: Model, V: float, opts: Renewal) -> Stationary | None:
    """The steady state from the renewal chain if steady sliding is stable at V, else None."""
    start = time.perf_counter()
    res = steady_sliding(model, V, tol=opts.tol, growth_rate=False)
    if not bool(res.stable):
        return None
    sigma = float(res.sigma)
    error = float(res.sigma_error)
    return Stationary(
        model=model, V=V, eps=math.nan, regime="steady", sigma_max=sigma, sigma_min=sigma, sigma_mean=sigma,
        period=math.nan, converged=bool(res.converged),
        message=(f"steady sliding is stable (branching ratio {float(res.branching_ratio):.6g} < 1): "
                 f"stress from the renewal chain ({int(res.n_nodes)} nodes, error {error:.1e})"),
        t_end=0.0, n_cycles=0, wall_time=time.perf_counter() - start, sigma_stderr=error,
        shocks_per_cycle=0.0, mass_error=0.0, min_mass=0.0, method="renewal", discretisation_error=error)


#: A cohort cycle of more loading steps than this is announced up front with its cost.
SLOW_CYCLE_STEPS = 2e5


def cohort_steps_per_cycle(model: Model, V: float, dt: float) -> float:
    """About how many time steps one loading phase of the cohort method takes at V: the
    stress rises by the velocity weakening ``f_th - sigma_fast_limit`` at the rate
    ``k0 V``, in steps of up to ``GRADED_MAX dt`` (4 dt) away from the shocks."""
    return (model.f_th - sigma_fast_limit(model)) / (model.k0 * V) / (cohort_options.DEFAULT.GRADED_MAX * dt)


def check_cohort_work(model: Model, V: float, opts: Cohort) -> None:
    """Refuse (one ValueError naming ``Cohort dt``) a stick-slip row whose loading phase
    would take more than ``COHORT_STEPS_MAX`` steps (:func:`cohort_steps_per_cycle`), before
    anything is computed.  Rows above V^c are steady (the renewal chain): not checked."""
    if not V < _vc(model) or cohort_not_applicable(model):
        return
    steps = cohort_steps_per_cycle(model, V, opts.dt)
    if steps > COHORT_STEPS_MAX:
        dt_min = opts.dt * steps / COHORT_STEPS_MAX
        raise ValueError(f"Cohort dt must be >= {dt_min:.3g} at V = {V:g} (k0 = {model.k0:g}): with dt = {opts.dt:g} "
                         f"a cycle's loading would take about {steps:.2g} steps, more than {COHORT_STEPS_MAX:.0e} "
                         f"(hours per cycle, and 10-20 cycles are needed)"
                         + ("" if dt_min <= 0.1 else "; no dt up to 0.1 will do: a larger V or k0 will"))


def _cohort_row(model: Model, V: float, opts: Cohort, warn: bool,
                start: CycleFixedPoint | None) -> Stationary | None:
    """The stick-slip cycle by the cohort method, or None where it does not apply."""
    h = opts.cell(model)
    steps = cohort_steps_per_cycle(model, V, opts.dt)
    if steps > SLOW_CYCLE_STEPS:
        # (a slow drive: each cycle's loading phase is long; said before the first cycle, so that a
        # user is not left waiting in silence; -v shows each cycle as it ends)
        log.warning("micro.stationary(k0=%g, V=%g): a slow drive for the cohort method: each cycle loads for "
                    "about %.2g time units, %.2g steps of dt = %g, and 10-20 cycles are needed; this may take "
                    "%s", model.k0, V, steps * cohort_options.DEFAULT.GRADED_MAX * opts.dt, steps, opts.dt,
                    "hours" if steps > 1e7 else "minutes")
    res = cycle_cohorts(model, V, dt=opts.dt, h=h, tol=opts.tol, max_iter=opts.max_iter, start=start)
    if not res.applicable:
        return None
    d = 1.0 - V / _vc(model)
    if d >= NEAR_VC and math.isfinite(res.discretisation_bound):
        # the change of the cycle from twice the step and cell, plus what the two fixed points
        # may still be off (a bound on the coarse cycle's discretisation error, so on this one's)
        disc = res.discretisation_bound
        covers = (f"; discretisation error at most {disc:.1e} (the change {res.coarse_change:.1e} from "
                  f"dt = {2 * opts.dt:g}, "
                  f"h = {2 * h:.3g}, plus both fixed points' errors); fixed-point error {res.error:.1e}")
    else:
        disc = math.nan
        why = (f"d = (V^c - V)/V^c = {d:.3g} < {NEAR_VC:g}, closer to V^c than the bound was checked"
               if d < NEAR_VC else "no run at twice the step and cell to compare with" if res.coarse is None
               else "a fixed point is not certified")
        covers = (f"; discretisation error not known ({why}); " +
                  (f"the fixed-point error {res.error:.1e} covers the iteration only" if math.isfinite(res.error)
                   else "nor is the fixed-point error"))
    if not res.converged and warn:
        log.warning("micro.stationary(k0=%g, V=%g, method='cohort'): %s", model.k0, V, res.message)
    return Stationary(
        model=model, V=V, eps=h, regime="stick-slip", sigma_max=res.sigma_max, sigma_min=res.sigma_min,
        sigma_mean=res.sigma_mean, period=res.period, converged=res.converged, message=res.message + covers,
        t_end=float(np.nansum(res.history[:, 2])) if res.history is not None else math.nan,
        n_cycles=res.iterations, wall_time=res.wall_time, sigma_stderr=res.error, shocks_per_cycle=1.0,
        mass_error=res.mass_error, min_mass=res.min_mass, cycle=res, sigma_before=res.sigma_before,
        sigma_after=res.sigma_after, method="cohort", discretisation_error=disc)


def _fp_row(model: Model, V: float, numerics: FP | None, convergence: Convergence, warn: bool, initial="auto",
            keep_records: bool = False, keep_grid: bool = False, why: str = "") -> Stationary:
    out = fp.stationary_fp(model, V, numerics=numerics, convergence=convergence, initial=initial,
                           keep_records=keep_records, keep_grid=keep_grid, warn=warn)
    if why:
        out.message = f"{why}: Fokker-Planck time-stepping; {out.message}"
    return out


def _direct_then_cycle(model: Model, V: float, opts: Auto, numerics: FP | None, convergence: Convergence,
                       warn: bool, start: CycleFixedPoint | None) -> Stationary:
    """The best answer at V without the Fokker-Planck state: renewal if steady sliding
    is stable, else the cohort cycle, else (non-exponential jumps, or a loading phase
    that ends in no shock) the Fokker-Planck equation."""
    direct = _renewal_row(model, V, opts.renewal)
    if direct is not None:
        return direct
    why = cohort_not_applicable(model)
    if why:
        return _fp_row(model, V, numerics, convergence, warn, why=why)
    row = _cohort_row(model, V, opts.cohort, warn, start)
    if row is not None:
        return row
    return _fp_row(model, V, numerics, convergence, warn, why="the cohort method does not apply (no shock ends "
                                                               "the loading phase)")


def stationary(
    model: Model,
    V: float,
    *,
    method: Method = "auto",
    numerics: FP | None = None,
    convergence: Convergence | None = None,
    initial="auto",
    keep_records: bool = False,
    keep_grid: bool = False,
    warn: bool = True,
) -> Stationary:
    """The attractor at constant drive velocity ``V``: a steady stress or a stick-slip cycle.

    Parameters
    ----------
    model : the model.
    V : drive velocity, > 0.
    method : ``"auto"`` (default), ``"cohort"``, ``"fp"``, or an options object
        (:class:`micro.Auto`, :class:`micro.Cohort`, :class:`micro.FP`).

        * ``"auto"``: where steady sliding is stable, its stress from the renewal chain
          (exact to ~1e-11, milliseconds); elsewhere the stick-slip cycle by the cohort
          method (:func:`micro.cohort.cycle_cohorts`: the fixed point of the cycle map,
          seconds at every k0); the Fokker-Planck equation only where the cohort method
          does not apply (non-exponential jumps), or when its state is asked for
          (``keep_grid``, ``keep_records`` or an ``initial`` grid).
        * ``"cohort"``: as ``"auto"`` without the Fokker-Planck state.
        * ``"fp"``: always time-steps the Fokker-Planck equation (bin ``numerics.eps``).
    numerics : the Fokker-Planck options (:class:`micro.FP`), wherever it runs.
    convergence : the Fokker-Planck runs' stopping rule (:class:`micro.Convergence`); the
        cohort's fixed point is solved to its own ``Cohort.tol``.
    initial : ``"auto"``; a previous result's ``.cycle`` (cohort: continue from it); or a
        Fokker-Planck ``Grid`` or start name (``"frozen"``, ``"relaxed"``, ``"uniform"``).
    keep_records, keep_grid : keep the Fokker-Planck run's stress records or final grid.
    warn : log a warning for a result that did not converge.

    Returns
    -------
    Stationary
        ``method`` says which method produced it; ``discretisation_error`` what its
        discretisation may have moved (NaN where not known), ``sigma_stderr`` the
        iteration's own error.

    Raises
    ------
    ValueError
        For a bad argument or a method that does not answer this question (``"cycle"``
        is retired: use ``"cohort"``), before anything is computed.
    """
    _check_model(model)
    V = check_velocity(V)
    opts = resolve(method, ("auto", "cohort", "fp"), "stationary")
    numerics = _check_numerics(numerics, method)
    if numerics is not None:
        numerics.settings(model)  # (a bin out of range fails now)
    convergence = convergence or Convergence()
    if not isinstance(convergence, Convergence):
        raise ValueError(f"convergence must be a micro.Convergence, got {type(convergence).__name__}")
    cycle_start = initial if isinstance(initial, CycleFixedPoint) else None
    fp_state = keep_grid or keep_records or not (cycle_start is not None
                                                 or (isinstance(initial, str) and initial == "auto"))
    if isinstance(opts, FP):
        if cycle_start is not None:
            raise ValueError("initial: a cohort cycle cannot start a Fokker-Planck run; give a Grid or 'auto'")
        return _fp_row(model, V, numerics, convergence, warn, initial, keep_records, keep_grid)
    if isinstance(opts, Cohort):
        if fp_state:
            raise ValueError("keep_grid, keep_records and an initial grid belong to method='fp' (or 'auto'); "
                             "method='cohort' keeps no grid")
        opts = Auto(cohort=opts)
    elif fp_state:
        if cycle_start is not None:
            raise ValueError("initial: a cohort cycle cannot start a Fokker-Planck run; give a Grid or 'auto'")
        return _fp_row(model, V, numerics, convergence, warn, initial, keep_records, keep_grid)
    opts.cohort.cell(model)  # (a cell out of range fails now)
    check_cohort_work(model, V, opts.cohort)
    return _direct_then_cycle(model, V, opts, numerics, convergence, warn, cycle_start)


# ------------------------------------------------------------------------------ sweep
def sweep(
    model: Model,
    velocities,
    *,
    method: Method = "auto",
    numerics: FP | None = None,
    convergence: Convergence | None = None,
    continuation: bool = True,
    on_row=None,
) -> pd.DataFrame:
    """Stationary states for each velocity, one row each (:func:`stationary`).

    Parameters
    ----------
    model : the model.
    velocities : drive velocities, each > 0, visited in the given order.
    method, numerics, convergence : as in :func:`stationary`.
    continuation : start each Fokker-Planck row from the previous row's final density,
        which shortens transients.  Cohort rows always start from their own run at twice
        the step and cell (an eighth of the cost), whose change is the row's
        ``discretisation_error``.
    on_row : called with the frame of the rows so far after each row (a CLI writes it,
        so that nothing computed is lost if a later row fails).

    Returns
    -------
    pandas.DataFrame
        One row per velocity (:meth:`Stationary.to_dict`), with a ``method`` column.
    """
    _check_model(model)
    opts = resolve(method, ("auto", "cohort", "fp"), "sweep")
    numerics = _check_numerics(numerics, method)
    velocities = [check_velocity(V) for V in np.atleast_1d(velocities).tolist()]
    if numerics is not None:
        numerics.settings(model)
    if isinstance(opts, (Auto, Cohort)):
        cohort = opts.cohort if isinstance(opts, Auto) else opts
        cohort.cell(model)
        for V in velocities:     # every row's work before the first is computed
            check_cohort_work(model, V, cohort)
    rows: list[dict] = []
    seed_grid = None
    for i, V in enumerate(velocities):
        with _progress.stage(f"row {i + 1} of {len(velocities)}, V={V:.10g}"):
            row, seed_grid = _sweep_row(model, V, opts, numerics, convergence, continuation, seed_grid)
        rows.append(row)
        if on_row is not None:
            on_row(pd.DataFrame(rows))
    return pd.DataFrame(rows)


def _sweep_row(model, V, opts, numerics, convergence, continuation, seed_grid) -> tuple[dict, object]:
    """One row of :func:`sweep`, and the grid the next row starts from (a continued
    Fokker-Planck row's final density; else None)."""
    if isinstance(opts, FP):
        res = stationary(model, V, method="fp", numerics=numerics, convergence=convergence,
                         initial=seed_grid if (continuation and seed_grid is not None) else "auto",
                         keep_grid=continuation)
        grid, res.grid = res.grid, None
        return res.to_dict(), grid
    res = stationary(model, V, method=opts, numerics=numerics, convergence=convergence)
    return res.to_dict(), None


# ------------------------------------------------------------------------------ critical velocity
def _in_velocity_range(V: float, name: str) -> float:
    """``V`` within the velocities the steady branch takes (``micro.renewal.V_RANGE``), or one
    ValueError naming it."""
    low, high = V_RANGE
    if not low <= V <= high:
        raise ValueError(f"{name} must be in [{low:g}, {high:g}] (the velocities of the steady branch), got {V:g}")
    return V


def critical_velocity(
    model: Model,
    *,
    method: Method = "auto",
    V_min: float = 1e-4,
    V_max: float | None = None,
    V_guess: float = 1.0,
    factor: float = 8.0,
    rel_tol: float = 1e-2,
    numerics: FP | None = None,
    convergence: Convergence | None = None,
    refine: bool = True,
) -> Critical:
    """Critical velocity V^c: where steady sliding loses stability.

    Parameters
    ----------
    model : the model.
    method : ``"auto"`` = ``"renewal"`` (the default): V^c is the root of ``b(V) = 1``,
        the branching ratio of steady sliding from the renewal chain (derivation in
        docs/reference/micro_renewal.md), to ~1e-10 relative in a fraction of a second;
        ``V_low`` and ``V_high`` are ``Vc`` minus and plus its error estimate.
        ``"fp"``: bisection on the regime of Fokker-Planck runs (the paper's Appendix B;
        minutes, uncertain by the bin; :func:`micro.fp.critical_velocity_fp`), kept for
        cross-checks; ``V_guess``, ``factor``, ``rel_tol``, ``numerics``, ``convergence``
        and ``refine`` are its options.
    V_min, V_max : the search range (``V_max`` default 1e7 for the renewal chain, 1e3 for
        the bisection).

    Returns
    -------
    Critical
        ``Vc = nan`` with status ``"no stick-slip"`` where steady sliding is stable at every
        V (``k0 >= k2``) and with ``"V^c below V_min"`` where it lies below the range;
        ``inf`` with ``"V^c above V_max"`` beyond ``V_max``.
    """
    _check_model(model)
    opts = resolve(method, ("auto", "renewal", "fp"), "critical_velocity")
    numerics = _check_numerics(numerics, method)
    bisect = isinstance(opts, FP)
    V_min = _in_velocity_range(check_velocity(V_min, "V_min"), "V_min")
    V_max = _in_velocity_range(check_velocity((1e3 if bisect else 1e7) if V_max is None else V_max, "V_max"),
                               "V_max")
    if not V_max > V_min:
        raise ValueError(f"V_max must be > V_min, got V_min={V_min:g}, V_max={V_max:g}")
    V_guess = check_velocity(V_guess, "V_guess")
    if not (math.isfinite(factor) and factor > 1.0):
        raise ValueError(f"factor must be a finite number > 1, got {factor!r}")
    if not (math.isfinite(rel_tol) and 0.0 < rel_tol < 1.0):
        raise ValueError(f"rel_tol must be in (0, 1), got {rel_tol!r}")
    if bisect:
        if numerics is not None:
            numerics.settings(model)
        return fp.critical_velocity_fp(model, V_min=V_min, V_max=V_max, V_guess=V_guess, factor=factor,
                                       rel_tol=rel_tol, numerics=numerics, convergence=convergence, refine=refine)
    renewal = opts.renewal if isinstance(opts, Auto) else opts
    Vc, error, status, message, evaluations = critical_velocity_renewal(model, V_min=V_min, V_max=V_max,
                                                                         tol=renewal.tol)
    if status in ("no stick-slip", BELOW):
        Vc = math.nan  # (no critical velocity in the range: rsf's encoding of 'stable at every V' too)
    low, high = (Vc - error, Vc + error) if math.isfinite(Vc) and Vc > 0.0 else (
        (0.0, V_min) if status in ("no stick-slip", BELOW) else (V_max, math.inf))
    if status != "converged":
        log.info("micro.critical_velocity(k0=%g, k1=%g, k2=%g): %s", model.k0, model.k1, model.k2, message)
    return Critical(model, Vc, low, high, status, message, evaluations, method="renewal")


# ------------------------------------------------------------------------------ transients
def _transient_method(method: Method, numerics, question: str) -> FP | None:
    opts = resolve(method, ("auto", "fp", "cohort"), question)
    if isinstance(opts, Cohort):
        raise ValueError(f"{question}: the cohort method does not carry transients (it solves cycles as fixed "
                         "points of the cycle map); use method='auto' or 'fp'")
    return _check_numerics(numerics, method)


def simulate(
    model: Model,
    drive: Drive | float,
    *,
    method: Method = "auto",
    duration: float | None = None,
    numerics: FP | None = None,
    initial="auto",
    record_dsigma: float | None = None,
    record_dt: float | None = None,
    progress: bool = False,
    max_wall_time: float | None = None,
) -> Run:
    """Run a driving protocol and return the stress time series.

    ``method="auto"`` is the Fokker-Planck equation (:func:`micro.fp.simulate_fp`), the
    method that carries a transient under any :class:`~micro.Drive`; its options go in
    ``numerics`` (or ``method=micro.FP(...)``).

    Parameters
    ----------
    model : the model.
    drive : a :class:`~micro.Drive`, or a constant velocity (then ``duration`` is required).
    method : ``"auto"`` or ``"fp"`` (or :class:`micro.FP`).
    duration : run length for a constant velocity.
    numerics : the Fokker-Planck options.
    initial : ``"auto"``, ``"frozen"``, ``"relaxed"``, ``"uniform"`` or a Grid to start from.
    record_dsigma, record_dt : record the stress whenever it moved by ``record_dsigma``
        and at least every ``record_dt``.
    progress : a progress bar of the simulated time on stderr.
    max_wall_time : the longest the run may take, in seconds, > 0 (default: no bound): a
        run whose wall time projected at its pace over its first second exceeds it stops
        with a ``ValueError`` giving the longest duration the bound allows
        (:func:`micro.fp.simulate_fp`).

    Returns
    -------
    Run
        ``records``: columns ``t, w, sigma, sigma_min, sigma_max, sigma_mean``.
    """
    _check_model(model)
    numerics = _transient_method(method, numerics, "simulate")
    drive, duration = _check_drive(drive, duration)
    for name, value in (("record_dsigma", record_dsigma), ("record_dt", record_dt)):
        if value is not None and not (math.isfinite(_number(name, value)) and float(value) > 0.0):
            raise ValueError(f"{name} must be a finite number > 0 (or None for the default), got {_shown(value)}")
    if max_wall_time is not None and not (math.isfinite(_number("max_wall_time", max_wall_time))
                                          and float(max_wall_time) > 0.0):
        raise ValueError(f"max_wall_time must be a finite number > 0 (or None), got {_shown(max_wall_time)}")
    return fp.simulate_fp(model, drive, duration=duration, numerics=numerics, initial=initial,
                          record_dsigma=record_dsigma, record_dt=record_dt, progress=progress,
                          max_wall_time=None if max_wall_time is None else float(max_wall_time))


#: The longest simulated time a protocol may ask for (as the command line's).
T_MAX = 1e8


def _shown(value) -> str:
    """``repr(value)`` with numpy scalars as plain Python values (``'x'``, not ``np.str_('x')``)."""
    return repr(value.item() if isinstance(value, np.generic) else value)


def _check_drive(drive, duration):
    """``drive`` a :class:`~micro.Drive` (then no ``duration``) or a velocity with a ``duration``
    in (0, T_MAX], strictly numbers, or one ValueError naming the argument."""
    if isinstance(drive, Drive):
        if duration is not None:
            raise ValueError("duration goes with a constant velocity only: a Drive sets its own length")
        if drive.duration > T_MAX:
            raise ValueError(f"drive must last at most {T_MAX:g}, got {drive.duration:g}")
        return drive, None
    V = _number("drive", drive)
    if not (math.isfinite(V) and V >= 0.0):
        raise ValueError(f"drive must be a micro.Drive or a finite velocity >= 0, got {_shown(drive)}")
    if duration is None:
        raise ValueError("duration is required when drive is a velocity")
    duration = _number("duration", duration)
    if not (math.isfinite(duration) and 0.0 < duration <= T_MAX):
        raise ValueError(f"duration must be in (0, {T_MAX:g}], got {duration:g}")
    return V, duration


def _hold_times(hold_times) -> list[float]:
    """The hold times as floats (a number or a non-empty sequence of numbers, each finite
    and in [0, T_MAX]), or one ValueError naming ``hold_times``."""
    raw = np.atleast_1d(np.asarray(hold_times, dtype=object)).ravel().tolist()
    if not raw:
        raise ValueError("hold_times must hold at least one hold time, got an empty sequence")
    holds = []
    for i, h in enumerate(raw):
        try:
            value = _number(f"hold_times item {i + 1}", h)
        except ValueError:
            raise ValueError(f"hold_times item {i + 1} of {len(raw)} must be a number, got {_shown(h)}") from None
        if not (math.isfinite(value) and 0.0 <= value <= T_MAX):
            raise ValueError(f"hold_times item {i + 1} of {len(raw)} must be in [0, {T_MAX:g}], got {value:g}")
        holds.append(value)
    return holds


def slide_hold_slide(
    model: Model,
    V: float,
    hold_times,
    *,
    method: Method = "auto",
    numerics: FP | None = None,
    convergence: Convergence | None = None,
    resume: float | None = None,
) -> pd.DataFrame:
    """Stress peak after a hold, for each hold time (the paper's Fig. 7).

    Drives at ``V`` until stationary (steady sliding is required), then for each hold
    time stops the drive for ``hold``, resumes at ``V`` for ``resume`` (default: 20 cycle
    times plus 2 relaxation times) and records the largest stress after resuming, by the
    Fokker-Planck equation (``method="auto"`` or ``"fp"``: the cohort method does not
    carry transients).  One stationary run serves every hold time.

    Parameters
    ----------
    model : Model
        The model.
    V : float
        Drive velocity, finite and > 0, where steady sliding is the attractor.
    hold_times : float or array_like
        The hold durations, each finite and >= 0 (0: no hold).
    method : str or FP
        ``"auto"`` (the default) or ``"fp"``, or a :class:`micro.FP` options object.
    numerics : FP, optional
        The Fokker-Planck options (or give them as ``method``, not both).
    convergence : Convergence, optional
        The stopping rule of the stationary run before the holds.
    resume : float, optional
        How long the drive runs after each hold (default ``20 zbar / V + 2 / gamma``;
        without the second term where gamma = 0).

    Returns
    -------
    pandas.DataFrame
        One row per hold: ``hold_time``; ``sigma_steady``, the steady stress at ``V``;
        ``sigma_peak``, the largest stress after resuming; ``delta_sigma_max =
        sigma_peak - sigma_steady``; ``method`` (``"fp"``).

    Raises
    ------
    ValueError
        For a bad argument (``model`` not a :class:`micro.Model`, ``V``, a hold time or
        the bin out of range, or a method other than ``"auto"`` and ``"fp"``), before
        anything is computed; or, after the stationary run, if the attractor at ``V`` is
        not steady sliding.
    micro.GridTooLarge
        If the Fokker-Planck grid would outgrow ``numerics.max_memory_gib``.
    """
    _check_model(model)
    numerics = _transient_method(method, numerics, "slide_hold_slide")
    V = check_velocity(V)
    hold_times = _hold_times(hold_times)
    if resume is not None:
        resume = _number("resume", resume)
        if not (math.isfinite(resume) and 0.0 < resume <= T_MAX):
            raise ValueError(f"resume must be in (0, {T_MAX:g}] (or None for the default), got {resume:g}")
    return fp.slide_hold_slide_fp(model, V, hold_times, numerics=numerics, convergence=convergence, resume=resume)
