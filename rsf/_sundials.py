"""The one place that knows scikit-sundae's CVODE conventions.

scikit-sundae differs from ``scipy.integrate.solve_ivp``: one ``eventsfn(t, y, events)``
fills an array, ``num_events`` is required, ``eventsfn.terminal`` and
``eventsfn.direction`` are lists (``terminal`` defaults to True), ``y`` is shaped
``(n_times, n_vars)``, and ``max_num_steps`` counts steps per output interval.  Everything
else in :mod:`rsf` calls :func:`integrate` and gets an :class:`OdeSolution`.
"""
from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Callable, Sequence

import numpy as np
import sksundae as sun

__all__ = ["OdeSolution", "integrate", "integrate_outputs"]


@dataclass
class OdeSolution:
    """Outcome of one CVODE run.

    ``t`` and ``y`` (shape ``(n_times, n_vars)``) are the saved points (every internal step
    if ``save_steps``, otherwise only the end point); ``events`` lists every event as
    ``(t, y, index, direction)``; ``terminal_event`` is the index of the event that stopped
    the run, or None.
    """

    t: np.ndarray
    y: np.ndarray
    events: list[tuple[float, np.ndarray, int, int]]
    terminal_event: int | None
    status: int
    message: str
    success: bool
    nfev: int


def integrate(rhs: Callable[[float, np.ndarray, np.ndarray], None], y0: np.ndarray, t0: float,
              t1: float, *, events: Callable[[float, np.ndarray, np.ndarray], None] | None = None,
              terminal: Sequence[bool] = (), direction: Sequence[int] = (), rtol: float = 1e-10,
              atol: float | np.ndarray = 1e-12, method: str = "Adams",
              max_num_steps: int = 1_000_000, save_steps: bool = False,
              jac: Callable | None = None) -> OdeSolution:
    """Integrate ``y' = rhs(t, y)`` from ``t0`` to ``t1`` with CVODE, stopping at the first
    terminal event.

    ``rhs(t, y, yp)`` fills ``yp``; ``events(t, y, e)`` fills ``e`` (length
    ``len(terminal)``).  ``jac(t, y, yp, J)`` optionally fills the dense Jacobian.
    """
    options: dict = dict(rtol=rtol, atol=atol, method=method, max_num_steps=int(max_num_steps))
    n_events = len(terminal)
    if events is not None:
        if len(direction) != n_events or n_events == 0:
            raise ValueError("terminal and direction must list one entry per event")

        def eventsfn(t, y, e):
            events(t, y, e)

        eventsfn.terminal = [bool(x) for x in terminal]
        eventsfn.direction = [int(x) for x in direction]
        options.update(eventsfn=eventsfn, num_events=n_events)
    if jac is not None:
        options["jacfn"] = jac
    solver = sun.cvode.CVODE(rhs, **options)
    y0 = np.ascontiguousarray(y0, dtype=float)
    if save_steps:  # two points: scikit-sundae saves every internal step
        tspan = np.array([t0, t1], dtype=float)
    else:  # more than two: 'normal' mode, output only at tspan (cheaper per step)
        tspan = np.array([t0, t0 + 0.5 * (t1 - t0), t1], dtype=float)
    sol = solver.solve(tspan, y0)
    t = np.asarray(sol.t, dtype=float)
    y = np.asarray(sol.y, dtype=float).reshape(t.size, y0.size)
    found: list[tuple[float, np.ndarray, int, int]] = []
    terminal_event = None
    if sol.i_events is not None:
        i_ev = np.asarray(sol.i_events).reshape(-1, n_events)
        t_ev = np.asarray(sol.t_events, dtype=float).ravel()
        y_ev = np.asarray(sol.y_events, dtype=float).reshape(-1, y0.size)
        for k in range(t_ev.size):
            for idx in np.flatnonzero(i_ev[k]):
                found.append((float(t_ev[k]), y_ev[k].copy(), int(idx), int(np.sign(i_ev[k, idx]))))
        stopped_at_event = t.size > 0 and t_ev.size > 0 and t_ev[-1] == t[-1] and t[-1] != t1
        if stopped_at_event:
            for idx in np.flatnonzero(i_ev[-1]):
                if terminal[idx]:
                    terminal_event = int(idx)
                    break
    if not save_steps:
        t = t[[0, -1]]
        y = y[[0, -1]]
    return OdeSolution(t=t, y=y, events=found, terminal_event=terminal_event,
                       status=int(sol.status), message=str(sol.message), success=bool(sol.success),
                       nfev=int(sol.nfev))


def integrate_outputs(rhs: Callable[[float, np.ndarray, np.ndarray], None], y0: np.ndarray,
                      t0: float, t1: float, *, out_index: int = 0,
                      out_times: np.ndarray | None = None,
                      events: Callable[[float, np.ndarray, np.ndarray], None] | None = None,
                      terminal: Sequence[bool] = (), direction: Sequence[int] = (),
                      rtol: float = 1e-10, atol: float | np.ndarray = 1e-12,
                      method: str = "BDF", max_num_steps: int = 1_000_000,
                      save_steps: bool = False) -> OdeSolution:
    """Like :func:`integrate`, one CVODE step at a time under our own control, and also
    stop at every time where ``y[out_index]`` reaches the next of ``out_times`` (sorted,
    all beyond ``y0``): those points come back as events of index ``len(terminal)`` with
    CVODE's own interpolated state at the root.

    Stepping one internal step at a time lets the output event always target the next
    pending time (one sign change per output: a step spanning several outputs cannot hide
    them), and bounds the work: at most ``max_num_steps`` internal steps, and a run whose
    step has fallen below the round-off of the independent variable (``t + h == t``, a
    solution that blows up) stops with status -3 instead of stalling.  With ``save_steps``
    every internal step is returned (``t``, ``y``), else the end points.

    With ``save_steps``, events and no ``out_times`` the run is first made in one call of
    scikit-sundae's ``solve`` (:func:`_steps_in_one_call`: the steps are saved in compiled
    code, no Python round trip per step) and gives the same result to the last bit; only
    where the two could differ (a stall, the step bound, a root at ``t1`` or on a step) is
    it made again one step at a time.
    """
    if save_steps and events is not None and n_out_times(out_times) == 0:
        sol = _steps_in_one_call(rhs, y0, t0, t1, events=events, terminal=terminal,
                                 direction=direction, rtol=rtol, atol=atol, method=method,
                                 max_num_steps=max_num_steps)
        if sol is not None:
            return sol
    n_events = len(terminal)
    out_times = np.ascontiguousarray(out_times if out_times is not None else [], dtype=float)
    pending = [0]
    n_out = out_times.size
    has_out = n_out > 0
    n_all = n_events + (1 if has_out else 0)
    options: dict = dict(rtol=rtol, atol=atol, method=method, max_num_steps=int(max_num_steps))
    if n_all:
        if has_out:
            def eventsfn(t, y, e):
                if events is not None:
                    events(t, y, e)
                j = pending[0]
                e[n_events] = y[out_index] - out_times[j] if j < n_out else -1.0
        else:
            def eventsfn(t, y, e):
                events(t, y, e)
        eventsfn.terminal = [bool(x) for x in terminal] + ([False] if has_out else [])
        eventsfn.direction = [int(x) for x in direction] + ([1] if has_out else [])
        options.update(eventsfn=eventsfn, num_events=n_all)
    solver = sun.cvode.CVODE(rhs, **options)
    y0 = np.ascontiguousarray(y0, dtype=float)
    solver.init_step(t0, y0)
    found: list[tuple[float, np.ndarray, int, int]] = []
    terminal_event = None
    t_now, y_now = t0, y0.copy()
    ts, ys = [t0], [y0.copy()]
    status, message, success, nfev = 0, "", True, 0
    stalled = 0
    eps = np.finfo(float).eps
    for _ in range(int(max_num_steps)):
        sol = solver.step(t1, method="onestep", tstop=t1)
        status, message, success = int(sol.status), str(sol.message), bool(sol.success)
        nfev = int(sol.nfev)
        if not success:
            break
        t_prev = t_now
        t_now = float(sol.t)
        y_now = np.asarray(sol.y, dtype=float).copy()
        if save_steps:
            ts.append(t_now)
            ys.append(y_now)
        if status == 2:                                    # CV_ROOT_RETURN
            i_ev = np.asarray(sol.i_events).reshape(-1, n_all)[-1]
            for idx in np.flatnonzero(i_ev):
                found.append((t_now, y_now.copy(), int(idx), int(np.sign(i_ev[idx]))))
                if idx == n_events:
                    pending[0] += 1
                elif terminal[idx] and terminal_event is None:
                    terminal_event = int(idx)
            # forget the stored events: the next step reports only its own
            eventsfn._i.clear()
            eventsfn._t.clear()
            eventsfn._y.clear()
            if terminal_event is not None:
                break
        elif t_now - t_prev <= 8.0 * eps * max(abs(t_now), 1.0):
            stalled += 1
            if stalled >= 3:
                status, success = -3, False
                message = "step size below the round-off of the independent variable"
                break
        else:
            stalled = 0
        if status == 1 or t_now >= t1:                     # CV_TSTOP_RETURN
            break
    else:
        status, message, success = -1, "Could not reach endpoint after 'max_num_steps'.", False
    if save_steps:
        t_arr, y_arr = np.array(ts), np.array(ys)
    else:
        t_arr, y_arr = np.array([t0, t_now]), np.vstack([y0, y_now])
    return OdeSolution(t=t_arr, y=y_arr, events=found, terminal_event=terminal_event,
                       status=status, message=message, success=success, nfev=nfev)


def n_out_times(out_times) -> int:
    """The number of output times (0 for None)."""
    return 0 if out_times is None else int(np.size(out_times))


#: Steps in a row whose advance is below the round-off of the independent variable after
#: which :func:`integrate_outputs` ends a run (status -3).
STALL_STEPS = 3
_STALL_MESSAGE = "step size below the round-off of the independent variable"


def _stalled(t: np.ndarray, is_root: np.ndarray) -> bool:
    """Whether :func:`integrate_outputs`'s stall test fires on the returns ``t[1:]``
    (``is_root``: root returns, which the test skips without resetting its count)."""
    d = np.diff(t)
    tiny = d <= 8.0 * np.finfo(float).eps * np.maximum(np.abs(t[1:]), 1.0)
    flags = tiny[~is_root[1:]]
    if flags.size < STALL_STEPS:
        return False
    run = flags[:flags.size - STALL_STEPS + 1].copy()
    for k in range(1, STALL_STEPS):
        run &= flags[k:flags.size - STALL_STEPS + 1 + k]
    return bool(run.any())


def _steps_in_one_call(rhs, y0, t0, t1, *, events, terminal, direction, rtol, atol, method,
                       max_num_steps) -> OdeSolution | None:
    """What :func:`integrate_outputs` returns with ``save_steps`` and no output times, from
    one call of scikit-sundae's ``solve`` over ``[t0, t1]`` (CVODE's one-step mode with the
    stop time ``t1``: the same CVODE calls, the steps saved in compiled code instead of one
    Python round trip and result object per step).

    ``solve`` keeps a root return only in its event list (the step loop also saves it as a
    point), saves the point of a failed step (the loop does not), and has no step bound
    and no stall test.  The points are merged back in time order, and the function returns
    None -- the caller then steps one at a time -- wherever the results could differ: a
    root at or beyond ``t1`` or at the time of a step, more than ``max_num_steps`` returns,
    or :data:`STALL_STEPS` steps in a row below the round-off of the independent variable.
    A stall would never end inside ``solve``: a hidden extra event, watched in the event
    function, then turns terminal and ends the call.
    """
    n_events = len(terminal)
    if len(direction) != n_events or n_events == 0:
        raise ValueError("terminal and direction must list one entry per event")
    eps8 = 8.0 * np.finfo(float).eps
    max_steps = int(max_num_steps)
    # the watch: the latest step end, the time beyond which a step end is a real advance,
    # stalled steps in a row, whether the last call was at the step end, steps, hidden event
    top, beyond, stalls, at_top, steps, flag = -math.inf, -math.inf, 0, False, 0, 1.0

    def eventsfn(t, y, e):
        nonlocal top, beyond, stalls, at_top, steps, flag
        events(t, y, e)
        if t > beyond:          # the end of a new step (the usual case)
            top = t
            beyond = t + eps8 * (t if t > 1.0 else (-t if t < -1.0 else 1.0))
            stalls = 0
            at_top = True
            steps += 1
            if steps > max_steps:
                flag = -1.0
        elif t > top or (t == top and at_top):   # a step that advanced below the round-off
            top = t
            at_top = True
            stalls += 1
            if stalls >= STALL_STEPS:
                flag = -1.0
        else:                   # the root finder looks below the step end
            at_top = False
        e[n_events] = flag

    eventsfn.terminal = [bool(x) for x in terminal] + [True]
    eventsfn.direction = [int(x) for x in direction] + [-1]
    solver = sun.cvode.CVODE(rhs, rtol=rtol, atol=atol, method=method,
                             max_num_steps=int(max_num_steps), eventsfn=eventsfn,
                             num_events=n_events + 1)
    y0 = np.ascontiguousarray(y0, dtype=float)
    sol = solver.solve(np.array([t0, t1], dtype=float), y0)
    if flag < 0.0:
        return None
    status = int(sol.status)
    t = np.asarray(sol.t, dtype=float)
    y = np.asarray(sol.y, dtype=float).reshape(t.size, y0.size)
    n_returns = t.size - 1
    if status < 0:                  # the step loop keeps the last successful step
        t, y = t[:-1], y[:-1]
    found: list[tuple[float, np.ndarray, int, int]] = []
    terminal_event = None
    is_root = np.zeros(t.size, dtype=bool)
    if sol.i_events is not None:
        i_ev = np.asarray(sol.i_events).reshape(-1, n_events + 1)[:, :n_events]
        t_ev = np.asarray(sol.t_events, dtype=float).ravel()
        y_ev = np.asarray(sol.y_events, dtype=float).reshape(-1, y0.size)
        for k in range(t_ev.size):
            for idx in np.flatnonzero(i_ev[k]):
                found.append((float(t_ev[k]), y_ev[k].copy(), int(idx), int(np.sign(i_ev[k, idx]))))
        inner = t_ev.size
        if status == 2:             # stopped at a terminal root, saved as the last point
            for idx in np.flatnonzero(i_ev[-1]):
                if terminal[idx]:
                    terminal_event = int(idx)
                    break
            inner -= 1
            is_root[-1] = True
        n_returns += inner
        if inner:
            t_in, y_in = t_ev[:inner], y_ev[:inner]
            if np.any(t_in >= t1):
                return None
            pos = np.searchsorted(t, t_in, side="left")
            if np.any(t[np.minimum(pos, t.size - 1)] == t_in):
                return None
            t = np.insert(t, pos, t_in)
            y = np.insert(y, pos, y_in, axis=0)
            is_root = np.insert(is_root, pos, True)
    if n_returns > max_num_steps or np.any(t[:-1] >= t1) or _stalled(t, is_root):
        return None
    return OdeSolution(t=t, y=y, events=found, terminal_event=terminal_event, status=status,
                       message=str(sol.message), success=bool(sol.success), nfev=int(sol.nfev))
