r"""The public entry points: :func:`simulate` (a time series), :func:`limit_cycle` (the
attractor at one velocity) and :func:`sweep` (attractors over many velocities).

The integration itself is in :mod:`rsf.engines`: with no direct effect (:math:`a = 0`, the
paper's model, Eqs. 8, 11, 12) the motion is a sequence of stick, slide and instantaneous
slip (:mod:`rsf.engines.phase`; ``docs/reference/rsf.md`` has the derivation); with
:math:`a > 0` it is a regular ODE in :math:`(\ln v, \ln\theta)` integrated by CVODE (BDF),
with events at the extrema of :math:`\sigma` (:mod:`rsf.engines.smooth`).  The
limit-cycle search is in :mod:`rsf.cycles`.
"""
from __future__ import annotations

import logging
import math
import time
from dataclasses import replace
from typing import Iterable

import numpy as np

from . import _progress
from ._validation import positive
from .cycles import CycleSearch
from .engines import Stop, make_engine
from .laws import TabulatedLaw
from .params import T_END_MAX, InitialState, Protocol, SolverOptions, SpringSlider
from .results import STATUS_MESSAGES, CycleResult, Status, SweepResult, Trajectory

__all__ = ["simulate", "limit_cycle", "sweep"]

logger = logging.getLogger(__name__)

_PROGRESS_CYCLES = 1000  # limit_cycle logs its progress (INFO) every this many cycles


def _checked(options, initial) -> tuple[SolverOptions, InitialState]:
    """``options`` and ``initial`` of their types (None: the defaults), or one ValueError
    naming the argument (``options='fast'`` was taken and failed later)."""
    if options is not None and not isinstance(options, SolverOptions):
        raise ValueError(f"options must be an rsf.SolverOptions (or None), got {options!r}")
    if initial is not None and not isinstance(initial, InitialState):
        raise ValueError(f"initial must be an rsf.InitialState (or None), got {initial!r}")
    return options or SolverOptions(), initial or InitialState()


def _protocol_from(V: float | None, protocol: Protocol | None) -> Protocol:
    if protocol is not None and V is not None:
        raise ValueError("give either V (constant driving) or protocol, not both")
    if protocol is None:
        if V is None:
            raise ValueError("V (constant driving velocity > 0) or protocol is required")
        return Protocol.constant(V)
    if not isinstance(protocol, Protocol):
        raise ValueError(f"protocol must be an rsf.Protocol, got {protocol!r}")
    return protocol


def _check_table(model: SpringSlider, velocities, thetas, where: str) -> None:
    """A :class:`~rsf.laws.TabulatedLaw` is evaluated at the state velocity
    :math:`D_c/\theta` (steady sliding: the driving velocity); warn (once per law, naming
    the table's range and the velocity) if ``velocities`` or the state velocities of
    ``thetas`` leave the table, where the law is held flat."""
    if not isinstance(model.law, TabulatedLaw):
        return
    if velocities is not None:
        model.law.check_velocities(velocities, f"{where}: the driving velocity V")
    theta = np.asarray(thetas, dtype=float).ravel()
    theta = theta[np.isfinite(theta) & (theta > 0.0)]
    if theta.size:
        model.law.check_velocities(model.Dc / np.array([theta.max(), theta.min()]),
                                   f"{where}: the state velocity Dc/theta")


def simulate(model: SpringSlider, V: float | None = None, *, t_end: float,
             protocol: Protocol | None = None, initial: InitialState | None = None,
             options: SolverOptions | None = None, stop_at_steady: bool = False,
             t_eval: np.ndarray | None = None) -> Trajectory:
    r"""Integrate the spring-slider from ``t = 0`` to ``t_end`` and return the time series.

    Parameters
    ----------
    model : SpringSlider
        The slider and its friction law.
    V : float, optional
        Constant load-point velocity (> 0); or give ``protocol``.
    t_end : float
        End time, in (0, ``rsf.params.T_END_MAX`` = 1e8].  A stable steady slide is followed
        to it in a few integrator runs (once within the tolerance of the steady state, in
        closed form for :math:`a > 0`).
    protocol : Protocol, optional
        Driving history (velocity steps, slide-hold-slide, a sampled V(t)).
    initial : InitialState, optional
        Default: the exact steady state at the first velocity for a protocol that changes
        the velocity; for constant driving the steady state with theta perturbed by 1e-3.
    options : SolverOptions, optional
        Tolerances, budgets and the runaway bound; default ``SolverOptions()``.
    stop_at_steady : bool
        End the run as soon as a stable steady slide is reached (status ``STEADY``).
    t_eval : array_like, optional
        Times (sorted, strictly increasing, in ``[0, t_end]``) at which to return the
        samples, like ``scipy.integrate.solve_ivp``: for :math:`a > 0` CVODE stops at each
        of them with its own interpolant (no interpolation of the output).  Events keep
        their exact times.  Default: every internal step of the integrator.  A run that
        stops early (runaway, failure) returns the samples up to there.

    Returns
    -------
    Trajectory
        ``t, x, sigma, theta, v`` samples, the events (time, kind, sigma, theta, x) and the
        status.  A slip appears as two samples at one instant.  A run that cannot go on
        (runaway, solver failure, the step budget, ``options.max_events``) is not an
        exception: it returns what it computed with a negative ``status`` and its message
        (and logs a warning).

    Raises
    ------
    ValueError
        If ``model`` is not a :class:`~rsf.params.SpringSlider`, ``t_end`` is not in
        (0, 1e8], both or neither of ``V`` and ``protocol`` are given, ``t_eval`` is not
        finite, strictly increasing and within ``[0, t_end]``, a sampled (linear) protocol
        is given for :math:`a = 0`, or the driving starts at V = 0 without
        ``initial.theta``.

    Examples
    --------
    >>> import rsf
    >>> run = rsf.simulate(rsf.SpringSlider(k0=0.1), V=0.5, t_end=20.0)
    >>> run.success, list(run.to_frame().columns)
    (True, ['t', 'x', 'sigma', 'theta', 'v'])
    """
    if not isinstance(model, SpringSlider):
        raise ValueError(f"model must be an rsf.SpringSlider, got {model!r}")
    t_end = positive("t_end", t_end)
    if t_end > T_END_MAX:
        raise ValueError(f"t_end must be <= {T_END_MAX:g} (rsf.params.T_END_MAX), got {t_end:g}")
    protocol = _protocol_from(V, protocol)
    options, initial = _checked(options, initial)
    initial = initial.resolved(InitialState.DEFAULT_PERTURBATION if protocol.is_constant else 0.0)
    t_eval = _check_t_eval(t_eval, t_end)
    if model.a == 0.0 and protocol.is_linear:
        raise ValueError("a sampled (linearly interpolated) load history needs a direct "
                         "effect a > 0; for a = 0 use piecewise-constant steps")
    for v in np.unique(protocol.velocities[protocol.velocities > 0.0]):
        model.check_resolved(float(v))
    started = time.perf_counter()
    with _progress.stage("loading the integrator"):
        engine = make_engine(model, protocol, options, record=True, stop_at_steady=stop_at_steady,
                             t_eval=t_eval)
        engine.start(initial)
    status = Status.TIME_LIMIT
    detail = ""
    n = 0

    def trajectory(message: str = "") -> Trajectory:
        t, x, sigma, theta, v = engine.samples.arrays()
        message = message or STATUS_MESSAGES[status] + (f" ({detail})" if detail else "")
        theta2 = engine.samples.theta2_array() if model.second_state is not None else None
        return Trajectory(t=t, x=x, sigma=sigma, theta=theta, v=v, theta2=theta2, events=engine.events,
                          status=status, message=message, params=model.describe())

    try:
        with _progress.stage(lambda: _time_done(engine.t, t_end, n, started)):
            while True:
                ev = engine.step(t_end)
                n += 1
                _progress.beat()
                if ev.kind == "end":
                    break
                if ev.kind == "steady":
                    status = Status.STEADY
                    break
                if n >= options.max_events:
                    status = Status.MAX_EVENTS
                    break
                if n in _PROJECT_AT and protocol.is_constant:
                    too_many = _too_many_events(n, engine.t, t_end, options.max_events, started)
                    if too_many:
                        status, detail = Status.MAX_EVENTS, too_many
                        break
    except Stop as stop:
        status, detail = stop.status, stop.detail
    except KeyboardInterrupt:
        # Ctrl-C: the samples so far, for a caller that keeps them (rsf run writes them)
        # (a failure status: it did not reach t_end; the message says why)
        status = Status.MAX_EVENTS
        raise _progress.Interrupted(trajectory=trajectory(f"interrupted (Ctrl-C) at t = {engine.t:.6g}")) from None
    run = trajectory()
    if status < 0:
        logger.warning("simulate: %s", run.message)
    velocities = np.asarray(protocol.velocities, dtype=float)
    _check_table(model, velocities[velocities > 0.0], np.concatenate([run.theta, [e.theta for e in engine.events]]),
                 "simulate")
    return run


#: Event counts at which :func:`simulate` projects the events of the whole run (constant
#: driving): a run that would need more than PROJECT_FACTOR times ``max_events`` stops there
#: instead of after them (near k_c the cycle's period is tiny: k0 = 0.3739316239, V = 0.078
#: has a period of 5.7e-5, so t_end = 1000 spans 1.8e7 cycles, 5.3e7 events, which the
#: event budget of 2e6 would stop after about 40 minutes, at t = 38).
_PROJECT_AT = (2_000, 20_000, 200_000)
PROJECT_FACTOR = 4.0


def _too_many_events(n: int, t: float, t_end: float, max_events: int, started: float) -> str:
    """Why a run at constant driving that has had ``n`` events by time ``t`` cannot reach
    ``t_end`` within ``max_events`` (its events projected at the rate so far, with a margin
    of :data:`PROJECT_FACTOR`), or "" if it may."""
    if not t > 0.0:
        return ""
    projected = n * t_end / t
    if projected <= PROJECT_FACTOR * max_events:
        return ""
    hours = (time.perf_counter() - started) / n * max_events / 3600.0
    return (f"stopped at t = {t:.6g} after {n} events: at that rate t_end = {t_end:g} needs about "
            f"{projected:.2g} events, more than max_events = {max_events} (about {t / n:.2g} time units "
            f"per event; the budget alone would take about {hours:.2g} h and end near t = "
            f"{t * max_events / n:.3g}); a shorter t_end, or the attractor from limit_cycle / rsf sweep")


def _time_done(t: float, t_end: float, n: int, started: float) -> str:
    """``t = 3.2 of 20 (16 %), 1234 events, ETA 41 s``: the simulated time against its end,
    the ETA at the mean rate so far."""
    t = min(max(t, 0.0), t_end)
    elapsed = time.perf_counter() - started
    eta = f", ETA {elapsed * (t_end - t) / t:.0f} s" if t > 0.0 else ""
    return f"t = {t:.6g} of {t_end:g} ({100.0 * t / t_end:.0f} %), {n} events{eta}"


def _check_t_eval(t_eval, t_end: float) -> np.ndarray | None:
    if t_eval is None:
        return None
    arr = np.atleast_1d(np.asarray(t_eval, dtype=float)).ravel()
    if arr.size == 0:
        raise ValueError("t_eval must hold at least one time")
    if not np.all(np.isfinite(arr)) or np.any(np.diff(arr) <= 0.0):
        raise ValueError("t_eval must be finite and strictly increasing")
    if arr[0] < 0.0 or arr[-1] > t_end:
        raise ValueError(f"t_eval must lie in [0, t_end = {t_end:g}], got [{arr[0]:g}, {arr[-1]:g}]")
    arr = arr.copy()
    arr.setflags(write=False)
    return arr


def limit_cycle(model: SpringSlider, V: float, *, initial: InitialState | None = None,
                options: SolverOptions | None = None) -> CycleResult:
    r"""Run at constant velocity ``V`` until the motion is steady or a limit cycle has
    converged, and describe the attractor.

    A cycle runs from one slip landing (``'slip->...'`` event; for :math:`a > 0` from one
    minimum of :math:`\sigma`) to the next.  The cycle is converged when
    :math:`\sigma_{max}`, :math:`\sigma_{min}` and the period of two consecutive simulated
    cycles, with the same sequence of events, differ by less than ``options.cycle_rtol``
    (relative).  The run stops as soon as a stable steady slide is within
    ``cycle_rtol`` of the steady state.  With ``options.accelerate`` the cycle-to-cycle map
    of :math:`\ln\theta` at the section is extrapolated (Aitken) to skip slow transients
    (not with a second state variable, whose map has two dimensions).

    Parameters
    ----------
    model : SpringSlider
        The slider and its friction law.
    V : float
        Constant load-point velocity, > 0.
    initial : InitialState, optional
        Where the run starts; default the steady state at ``V`` with theta perturbed by
        ``InitialState.DEFAULT_PERTURBATION`` (1e-3), so that an unstable steady state
        departs.
    options : SolverOptions, optional
        ``cycle_rtol``, ``max_cycles``, ``accelerate`` and the integrator's tolerances;
        default ``SolverOptions()``.

    Returns
    -------
    CycleResult
        regime ('steady', 'stick-slip', or 'unknown' if the search failed), sigma_max,
        sigma_min, sigma_mean, period, converged, status and message.  A search that does
        not converge returns ``converged=False`` with a negative status (and logs a
        warning) rather than raising.

    Raises
    ------
    ValueError
        If ``model`` is not a :class:`~rsf.params.SpringSlider`, the model's stick-slip at
        ``V`` cannot be resolved in double precision
        (:meth:`~rsf.params.SpringSlider.check_resolved`), or ``V`` is not a finite
        number > 0.

    Examples
    --------
    >>> import rsf
    >>> model = rsf.SpringSlider(k0=0.1)
    >>> rsf.limit_cycle(model, 0.05).regime, rsf.limit_cycle(model, 2.0).regime
    ('stick-slip', 'steady')
    """
    if not isinstance(model, SpringSlider):
        raise ValueError(f"model must be an rsf.SpringSlider, got {model!r}")
    V = positive("V", V)
    model.check_resolved(V)
    options, initial = _checked(options, initial)
    if model.second_state is not None and options.accelerate:
        # the cycle map has two dimensions: no one-variable extrapolation
        options = replace(options, accelerate=False)
    initial = initial.resolved(InitialState.DEFAULT_PERTURBATION)
    started = time.perf_counter()
    engine = make_engine(model, Protocol.constant(V), options, record=False, stop_at_steady=True)
    engine.start(initial)
    params = model.describe()
    params["V"] = V
    search = CycleSearch(engine, V, options, smooth=model.a > 0.0, progress_every=_PROGRESS_CYCLES)
    with _progress.stage(lambda: f"limit cycle at V={V:.10g}: {len(search.cycles)} cycles, t = {engine.t:.6g}"):
        search.run()
    status = search.status
    run_time = time.perf_counter() - started
    message = STATUS_MESSAGES[status] + (f" ({search.detail})" if search.detail else "")
    _check_table(model, [V], [e.theta for e in (search.result.events if search.result else ())],
                 f"limit_cycle(V={V:g})")
    if status == Status.STEADY:
        sigma_ss = model.sigma_steady(V)
        return CycleResult(V=V, regime="steady", sigma_max=sigma_ss, sigma_min=sigma_ss,
                           sigma_mean=sigma_ss, period=math.nan, converged=True, status=status,
                           message=message, n_cycles=len(search.cycles), relative_change=0.0,
                           sequence=(), events=engine.events[-3:], params=params,
                           run_time=run_time)
    if status < 0:
        logger.warning("limit_cycle(V=%g): %s", V, message)
    c = search.result
    return CycleResult(
        V=V, regime="stick-slip" if status == Status.CONVERGED else "unknown",
        sigma_max=c.sigma_max if c else math.nan, sigma_min=c.sigma_min if c else math.nan,
        sigma_mean=c.mean if c else math.nan, period=c.period if c else math.nan,
        converged=status == Status.CONVERGED, status=status, message=message,
        n_cycles=len(search.cycles), relative_change=search.relative_change,
        sequence=c.sequence if c else (), events=list(c.events) if c else [], params=params,
        run_time=run_time)


def sweep(model: SpringSlider, velocities: Iterable[float], *, options: SolverOptions | None = None,
          initial: InitialState | None = None, progress: bool = False) -> SweepResult:
    """:func:`limit_cycle` at each velocity (in the given order).

    Parameters
    ----------
    model : SpringSlider
        The slider and its friction law.
    velocities : iterable of float
        Driving velocities, > 0.
    options : SolverOptions, optional
        Passed to every :func:`limit_cycle`; default ``SolverOptions()``.
    initial : InitialState, optional
        Used at every velocity (default: perturbed steady state at that velocity).
    progress : bool
        Log progress at INFO level every 10 % of the points.

    Returns
    -------
    SweepResult
        ``to_frame()`` has one row per V: k0, Dc, V, regime, sigma_max, sigma_min,
        sigma_mean, period, converged, status, message, ...

    Raises
    ------
    ValueError
        If ``velocities`` is empty or holds a value that is not a finite number > 0 or at
        which the stick-slip cannot be resolved (checked for all before the first), or
        ``model`` is not a :class:`~rsf.params.SpringSlider`.

    Examples
    --------
    >>> import rsf
    >>> table = rsf.sweep(rsf.SpringSlider(k0=0.1), [0.05, 2.0]).to_frame()
    >>> list(table.regime)
    ['stick-slip', 'steady']
    """
    vel = [positive(f"velocities[{i}]", v) for i, v in enumerate(velocities)]
    if not vel:
        raise ValueError("velocities must hold at least one velocity > 0")
    if not isinstance(model, SpringSlider):
        raise ValueError(f"model must be an rsf.SpringSlider, got {model!r}")
    _checked(options, initial)
    for V in vel:     # every velocity before the first is computed
        model.check_resolved(V)
    results = []
    try:
        for i, V in enumerate(vel):
            with _progress.stage(f"V {i + 1} of {len(vel)}"):
                results.append(limit_cycle(model, V, initial=initial, options=options))
            if progress and (i + 1) % max(1, len(vel) // 10) == 0:
                logger.info("sweep: %d / %d velocities done", i + 1, len(vel))
    except KeyboardInterrupt:
        # Ctrl-C: the finished points, for a caller that keeps them (rsf sweep writes them)
        raise _progress.Interrupted(result=SweepResult(results=results, params=model.describe())
                                    if results else None) from None
    return SweepResult(results=results, params=model.describe())
