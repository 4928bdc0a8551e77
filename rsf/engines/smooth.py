r"""The a > 0 engine: the regular rate-and-state ODE, integrated by CVODE (BDF).

The state is ``y = [ln v, ln(theta/Dc), x, int (sigma - mu_ref) dt, t (, ln(theta2/Dc2))]``;
CVODE integrates it in the slip-regularised variable s of :func:`rsf._kernels.rs_rhs_dr`
and in local variables relative to the velocity scale of the segment (:class:`Segment`),
with events at the extrema of :math:`\sigma` (:math:`v = V`, :class:`RsEvent`).
"""
from __future__ import annotations

import math
from enum import IntEnum
from typing import NamedTuple

import numpy as np

from .. import _sundials
from .._sundials import OdeSolution
from ..laws import LogLaw
from ..params import InitialState, Protocol, SolverOptions, SpringSlider
from ..results import Event, Status
from ..stability import stability_margin
from ..state_laws import NAGATA, USER
from .base import TAU_CHUNK, Engine, Stop, compiled, cvode_arrays, onto_time

__all__ = ["SmoothEngine", "RsConstants", "RsEvent", "Segment", "runaway_bound"]

RUNAWAY_FACTOR = 1e3    # default runaway bound: v_max = 1e3 max V (LogLaw models)


class RsConstants(NamedTuple):
    """The constants of one segment, in the order of the array ``c`` that
    :func:`rsf._kernels.rs_rhs_dr` and :func:`rsf._kernels.rs_events` read.  The local
    variables are :math:`w = \\ln(v/v_s)`, :math:`r = \\ln(v_s\\theta/D_c)`."""

    K: float             # k0 Dc
    V: float             # driving velocity (at t0 for a ramp)
    Dc: float
    a: float
    state_law: float     # code of the state law (rsf.state_laws: 0 aging ... 4 user)
    vs: float            # velocity scale of the segment
    w_steady: float      # ln(V/vs): w in steady sliding (0 if V = 0)
    r_steady: float      # ln(vs/V): r in steady sliding (0 if V = 0)
    s_tol: float         # distance to steady sliding at which the run is steady
    steady_on: float     # 1: stop at a stable steady state
    t_stop: float        # end of the segment (1e300: none)
    w_max: float         # ln(v_max/vs), the runaway bound (1e300: none)
    eta: float           # radiation damping
    c_over_b: float      # Nagata's c/b
    b2: float            # second state variable: its b2 (0: none)
    Dc_over_Dc2: float
    ln_v0_over_vs: float
    slope: float         # dV/dt of a sampled history (0 for steps)
    t0: float            # start of the ramp

    def array(self) -> np.ndarray:
        return np.array(self, dtype=float)


class RsEvent(IntEnum):
    """The events of the a > 0 ODE (:func:`rsf._kernels.rs_events`), by index."""

    SIGMA_MAX = 0        # v rises through V (never terminal)
    SIGMA_MIN = 1        # v falls through V (terminal in a limit-cycle search)
    STEADY = 2           # within s_tol of a stable steady state
    SEGMENT_END = 3      # t reaches the end of the driving segment or of the run
    RUNAWAY = 4          # v passes v_max
    OUTPUT = 5           # a t_eval time (added by rsf._sundials.integrate_outputs)


_DIRECTION = (1, -1, -1, 1, 1)


class Segment:
    """One CVODE segment of the a > 0 run (constant driving, or one ramp of a sampled
    history): its constants, the right-hand side and events in the local variables, the
    tolerances and the pending output times."""

    def __init__(self, engine: SmoothEngine, V: float, lnV: float, t_stop: float, slope: float,
                 steady_on: float, stop_on_min: bool) -> None:
        m = engine.model
        opts = engine.options
        second = engine.second
        self.V, self.lnV, self.t_stop, self.slope = V, lnV, t_stop, slope
        self.has_second = second is not None
        vs = V if V > 0.0 else max(math.exp(-engine.y[1]), 1e-300)
        self.vs = vs
        self.lvs = lvs = math.log(vs)
        self.consts = RsConstants(
            K=m.K, V=V, Dc=m.Dc, a=m.a, state_law=engine.state_code, vs=vs,
            w_steady=lnV - lvs if V > 0.0 else 0.0, r_steady=lvs - lnV if V > 0.0 else 0.0,
            s_tol=opts.cycle_rtol, steady_on=steady_on,
            t_stop=t_stop if math.isfinite(t_stop) else 1e300,
            w_max=math.log(engine.v_max) - lvs if math.isfinite(engine.v_max) else 1e300,
            eta=engine.eta, c_over_b=engine.c_over_b,
            b2=second.b2 if second is not None else 0.0,
            Dc_over_Dc2=m.Dc / second.Dc2 if second is not None else 0.0,
            ln_v0_over_vs=engine.ln_v0 - lvs, slope=slope, t0=engine.t)
        self.rhs, self.events = self._functions(engine, self.consts.array(), vs)
        self.terminal = (False, stop_on_min, True, True, True)
        t_scale = m.Dc / vs
        self.atol = np.array([opts.atol, opts.atol, opts.atol * m.Dc,
                              opts.atol * t_scale * max(1.0, abs(engine.sigma_of(engine.y) - engine.mu_ref)),
                              opts.atol * t_scale] + ([opts.atol] if second is not None else []))
        self.output = engine.record and engine.t_eval is not None
        self.save_steps = engine.record and not self.output
        if self.output:
            grid = engine.pending(t_stop, inclusive=False)
            self.grid = np.ascontiguousarray(grid[grid > engine.t])
        else:
            self.grid = np.empty(0)

    @staticmethod
    def _functions(engine: SmoothEngine, c: np.ndarray, vs: float):
        """CVODE's right-hand side and event function for the constants ``c`` (velocity
        scale ``vs``)."""
        p = engine.p
        rs_events = engine.rs_events
        if engine.user_rate is None:
            rs_rhs = engine.rs_rhs

            def rhs(s, y, yp):
                rs_rhs(y, yp, p, c)
        else:
            rs_rhs_dr = engine.k.rs_rhs_dr
            user_rate = engine.user_rate
            Dc = engine.model.Dc

            def rhs(s, y, yp):
                # d ln(theta)/ds = (dtheta/dt / theta) dt/ds, with dt/ds = Dc f / vs
                w = y[0]
                f = 1.0 / (1.0 + math.exp(w)) if w <= 0.0 else math.exp(-w) / (1.0 + math.exp(-w))
                theta = Dc * math.exp(y[1]) / vs
                rate = user_rate(vs * math.exp(min(w, 700.0)), theta)
                rs_rhs_dr(y, yp, p, c, rate / theta * Dc * f / vs)

        def events(s, y, e):
            rs_events(y, e, p, c)

        return rhs, events

    def to_local(self, y: np.ndarray) -> np.ndarray:
        """[ln v, q, ...] -> [w, r, ...]."""
        out = y.copy()
        out[0] = y[0] - self.lvs
        out[1] = y[1] + self.lvs
        if self.has_second:
            out[5] = y[5] + self.lvs
        return out

    def to_global(self, y: np.ndarray) -> np.ndarray:
        """[w, r, ...] -> [ln v, q, ...] (also for an array of states)."""
        out = np.array(y, dtype=float, copy=True)
        out[..., 0] += self.lvs
        out[..., 1] -= self.lvs
        if self.has_second:
            out[..., 5] -= self.lvs
        return out


class SmoothEngine(Engine):
    """CVODE (BDF) on ``y = [ln v, ln(theta/Dc), x, int (sigma - mu_ref) dt, t
    (, ln(theta2/Dc2))]`` for a > 0, in the slip-regularised variable s of
    :func:`rsf._kernels.rs_rhs_dr`.

    With ``t_eval`` the engine records samples only at those times: CVODE's root finder
    stops at each of them (an output event in :func:`rsf._sundials.integrate_outputs`) and
    returns its own interpolant there, which one Newton correction along the flow moves
    exactly onto the requested time.
    """

    def __init__(self, model: SpringSlider, protocol: Protocol, options: SolverOptions,
                 record: bool, stop_at_steady: bool, t_eval: np.ndarray | None = None) -> None:
        super().__init__(model, protocol, options, record, stop_at_steady, t_eval)
        self.second = model.second_state
        self.n_vars = 5 if self.second is None else 6
        self.y = np.zeros(self.n_vars)
        self.at_root = False       # the state sits on an event root (after a terminal event)
        self.eta = model.eta_rad
        state = model.state
        self.state_code = float(state.code)
        self.user_rate = state.func if state.code == USER else None
        self.c_over_b = 0.0
        if state.code == NAGATA:
            b = state.b if state.b is not None else model.law.b
            self.c_over_b = state.c / b
        self.ln_v0 = math.log(model.law.v0) if isinstance(model.law, LogLaw) else 0.0
        self.v_max = runaway_bound(model, protocol, options)
        # the kernels CVODE calls, compiled for the arrays it passes (c: 19 constants)
        y, out = cvode_arrays(self.n_vars)
        c = np.zeros(len(RsConstants._fields))
        self.rs_rhs = compiled(self.k.rs_rhs, y, out, self.p, c)
        self.rs_events = compiled(self.k.rs_events, y, np.zeros(len(RsEvent) - 1), self.p, c)
        # extrema of sigma closer than this (in ln theta) to the steady state are round-off
        self.extremum_floor = 100.0 * max(options.rtol, options.atol)

    @property
    def t(self) -> float:
        return float(self.y[4])

    @property
    def integral(self) -> float:
        """Running integral of the absolute sigma dt."""
        return float(self.y[3]) + self.mu_ref * float(self.y[4])

    def sigma_of(self, y: np.ndarray) -> float:
        """The friction mu (the spring force is mu + eta_rad v)."""
        u = math.exp(-y[1])
        out = self.mu_ref + float(self.law_fn(u, self.p)[0]) + self.model.a * (y[0] + y[1])
        if self.second is not None:
            out += self.second.b2 * (y[5] + self.ln_v0)
        return out

    def spring_of(self, y: np.ndarray) -> float:
        """The spring force k0 (X - x) = mu + eta_rad v."""
        out = self.sigma_of(y)
        if self.eta > 0.0:
            out += self.eta * math.exp(y[0])
        return out

    def theta_of(self, y: np.ndarray) -> float:
        return self.model.Dc * math.exp(y[1])

    def emit(self, kind: str, y: np.ndarray | None = None) -> Event:
        y = self.y if y is None else y
        return self.add_event(Event(float(y[4]), kind, self.sigma_of(y), self.theta_of(y), float(y[2])))

    def start(self, initial: InitialState) -> None:
        m = self.model
        V0 = float(self.protocol.velocities[0])
        theta = self.initial_theta(initial)
        u = m.Dc / theta
        if initial.sigma is None:
            if V0 <= 0.0:
                raise ValueError("initial.sigma is required when the driving starts with V = 0")
            lv = math.log(V0)
        else:
            lv = math.log(u) + (initial.sigma - self.mu_ref - float(self.law_fn(u, self.p)[0])) / m.a
        self.y = np.zeros(self.n_vars)
        self.y[:2] = [lv, math.log(theta / m.Dc)]
        if self.second is not None:           # theta2 at steady state for the same ratio
            self.y[5] = self.y[1]
            if initial.sigma is not None:
                raise ValueError("initial.sigma is not supported with a second state variable")
        if initial.theta is None and (initial.perturbation or 0.0) == 0.0 and V0 > 0.0:
            self.y[1] = -lv             # the exact steady state, free of the round-off of log
            if self.second is not None:
                self.y[5] = -lv
        self.y[2] = self.protocol.load_point(0.0) - self.spring_of(self.y) / m.k0
        self.at_root = True        # v = V is a root of the extremum events
        if self.record:
            if self.t_eval is None:
                self._record(self.y[None, :])
            else:
                self._output_here()
        self.emit("start")

    def set_state(self, lv: float, q: float) -> None:
        """Restart at (ln v, q) (used by the cycle extrapolation); x follows the spring."""
        y = self.y.copy()
        y[0], y[1] = lv, q
        if self.second is not None:         # the second state keeps its distance to steady
            y[5] += q - self.y[1]
        self.y = y
        self.y[2] = self.protocol.load_point(self.t) - self.spring_of(self.y) / self.model.k0
        self.at_root = True
        self.emit("restart")

    # -- the limit-cycle search ---------------------------------------------------------
    def section(self) -> float:
        """The variable of the cycle map: ln(theta/Dc)."""
        return float(self.y[1])

    def restart_at_section(self, value: float) -> None:
        """Restart at v = V with ln(theta/Dc) = ``value``."""
        self.set_state(math.log(self.protocol.velocity_at(self.t)), value)

    # -- samples ------------------------------------------------------------------------
    def _record(self, y: np.ndarray) -> None:
        m = self.model
        u = np.exp(-y[:, 1])
        law, p = self.law_compiled, self.p
        mu = np.array([law(ui, p)[0] for ui in u])
        with np.errstate(over="ignore"):
            v = np.exp(y[:, 0])
        sigma = self.mu_ref + mu + m.a * (y[:, 0] + y[:, 1])
        if self.second is not None:
            sigma = sigma + self.second.b2 * (y[:, 5] + self.ln_v0)
        theta2 = None if self.second is None else self.second.Dc2 * np.exp(y[:, 5])
        self.samples.add(y[:, 4], y[:, 2], sigma, m.Dc * np.exp(y[:, 1]), v, theta2)

    def _output_here(self) -> None:
        """Record the pending t_eval points that coincide with the current time."""
        te = self.t_eval
        t = self.t
        while self.next_out < te.size and te[self.next_out] <= t:
            if te[self.next_out] == t:
                self._record(self.y[None, :])
            self.next_out += 1

    # -- steady sliding -----------------------------------------------------------------
    def _distance_to_steady(self, lnV: float) -> float:
        """|ln v - ln V| + |ln(theta/Dc) + ln V| (+ the same for theta2)."""
        out = abs(self.y[0] - lnV) + abs(self.y[1] + lnV)
        if self.second is not None:
            out += abs(self.y[5] + lnV)
        return float(out)

    def _steady_exactly(self, lnV: float) -> bool:
        tol = 4.0 * np.finfo(float).eps * (1.0 + abs(lnV))
        if self.second is not None and abs(self.y[5] + lnV) > tol:
            return False
        return abs(self.y[0] - lnV) <= tol and abs(self.y[1] + lnV) <= tol

    def _advance_steady(self, V: float, t_stop: float, t_end: float) -> Event:
        """Exact steady sliding up to t_stop: closed form, no integrator (and no event
        function that is identically zero)."""
        t0 = self.t
        y0 = self.y.copy()
        sigma_rel = self.sigma_of(y0) - self.mu_ref
        if self.record:
            ts = np.array([t_stop]) if self.t_eval is None else self.take_pending(t_stop, inclusive=False)
            if ts.size:
                ys = np.repeat(y0[None, :], ts.size, axis=0)
                ys[:, 2] = y0[2] + V * (ts - t0)
                ys[:, 3] = y0[3] + sigma_rel * (ts - t0)
                ys[:, 4] = ts
                self._record(ys)
        dt = t_stop - t0
        self.y[2] = y0[2] + V * dt
        self.y[3] = y0[3] + sigma_rel * dt
        self.y[4] = t_stop
        self.at_root = True
        if self.record and self.t_eval is not None:
            self._output_here()
        if t_stop >= t_end:
            return self.emit("end")
        return self.emit("drive")

    def _snap_to_steady(self, seg: Segment, t_end: float) -> Event:
        """Put the state exactly on the steady state at V and follow it in closed form."""
        lnV = seg.lnV
        self.y[0], self.y[1] = lnV, -lnV
        if self.second is not None:
            self.y[5] = -lnV
        self.y[2] = self.protocol.load_point(self.t) - self.spring_of(self.y) / self.model.k0
        return self._advance_steady(seg.V, seg.t_stop, t_end)

    # -- one step: to the next event --------------------------------------------------------
    def step(self, t_end: float, stop_on_min: bool = False) -> Event:
        """Integrate to the next event and return it: an extremum of sigma (a minimum ends
        the step when ``stop_on_min``), steady sliding, the end of the driving segment
        (``'drive'``) or of the run (``'end'``); a runaway or a failure raises
        :class:`~rsf.engines.base.Stop`."""
        opts = self.options
        t_now = self.t
        V = self.protocol.velocity_at(t_now)
        t_stop = min(self.protocol.segment_end(t_now), t_end)
        lnV = math.log(V) if V > 0.0 else 0.0
        slope = self.protocol.slope_at(t_now)
        # steady sliding at V linearly stable (asked only where it matters)
        stable = (V > 0.0 and (self.stop_at_steady or (slope == 0.0 and math.isfinite(t_stop)))
                  and stability_margin(self.model, V) < 0.0)
        steady_on = 1.0 if (self.stop_at_steady and stable and slope == 0.0) else 0.0
        if steady_on and self._distance_to_steady(lnV) <= opts.cycle_rtol:
            return self.emit("steady")
        if V > 0.0 and slope == 0.0 and self._steady_exactly(lnV):
            if math.isfinite(t_stop):
                return self._advance_steady(V, t_stop, t_end)
            return self.emit("steady")       # on a fixed point for ever
        seg = Segment(self, V, lnV, t_stop, slope, steady_on, stop_on_min)
        y_loc = seg.to_local(self.y)
        if self.at_root:
            y_loc = self._step_off_root(seg, y_loc)
        # a stable steady state, reached to within the integrator's tolerance, is followed in
        # closed form to the end of the segment: at round-off distance CVODE's steps shrink
        # to the noise of the right-hand side and a long run would never end
        snap = stable and slope == 0.0 and math.isfinite(t_stop)
        snap_tol = max(opts.rtol, opts.atol)
        for _ in range(100000):
            sol = self._run(seg, y_loc, 0.0, TAU_CHUNK, True)
            if seg.save_steps:
                self._record(seg.to_global(sol.y[1:]))
            if not sol.success:
                raise self._failed(seg, sol)
            self.charge(sol.nfev)
            self._emit_extrema(seg, sol, stop_on_min)
            self._take_outputs(seg, sol, RsEvent.OUTPUT)
            y_loc = sol.y[-1].copy()       # the system is autonomous in s: restart at 0
            self.y = seg.to_global(y_loc)
            if sol.terminal_event is not None:
                return self._terminal(seg, RsEvent(sol.terminal_event), t_end)
            if snap and self._distance_to_steady(lnV) <= snap_tol:
                return self._snap_to_steady(seg, t_end)
        raise Stop(Status.SOLVER_FAILED, f"no progress at t = {self.t:.10g}")

    def _run(self, seg: Segment, y_start: np.ndarray, s_start: float, s_stop: float,
             with_events: bool) -> OdeSolution:
        """One CVODE run over [s_start, s_stop] in the local variables (BDF)."""
        opts = self.options
        if (seg.output and seg.grid.size) or (seg.save_steps and with_events):
            return _sundials.integrate_outputs(
                seg.rhs, y_start, s_start, s_stop, out_index=4, out_times=seg.grid,
                events=seg.events if with_events else None,
                terminal=seg.terminal if with_events else (),
                direction=_DIRECTION if with_events else (), rtol=opts.rtol, atol=seg.atol,
                method="BDF", max_num_steps=opts.max_num_steps, save_steps=seg.save_steps)
        if not with_events:
            return _sundials.integrate(seg.rhs, y_start, s_start, s_stop, rtol=opts.rtol,
                                       atol=seg.atol, method="BDF",
                                       max_num_steps=opts.max_num_steps)
        return _sundials.integrate(seg.rhs, y_start, s_start, s_stop, events=seg.events,
                                   terminal=seg.terminal, direction=_DIRECTION, rtol=opts.rtol,
                                   atol=seg.atol, method="BDF", max_num_steps=opts.max_num_steps,
                                   save_steps=seg.save_steps)

    def _step_off_root(self, seg: Segment, y_loc: np.ndarray) -> np.ndarray:
        """A short run without events off an event root (CVODE rejects a root at the
        start)."""
        sol = self._run(seg, y_loc, 0.0, 1e-6, False)
        self.charge(sol.nfev)
        if not sol.success:
            raise self._failed(seg, sol)
        self._take_outputs(seg, sol, 0)
        self.at_root = False
        return sol.y[-1].copy()

    def _failed(self, seg: Segment, sol: OdeSolution) -> Stop:
        """The stop of a failed CVODE run: keep the trajectory up to the failure and say
        where it happened."""
        if sol.y.size and np.all(np.isfinite(sol.y[-1])):
            self.y = seg.to_global(sol.y[-1])
        v_now = f"{math.exp(self.y[0]):.3g}" if self.y[0] < 700.0 else f"exp({self.y[0]:.4g})"
        return Stop(Status.SOLVER_FAILED, f"CVODE at t = {self.t:.10g} (v = {v_now}): {sol.message}")

    def _emit_extrema(self, seg: Segment, sol: OdeSolution, stop_on_min: bool) -> None:
        """The events of the extrema of sigma met in a run.  A time series drops extrema at
        round-off distance from steady state; a limit-cycle search keeps them all (tiny
        cycles near a Hopf point)."""
        for (_s, y_ev, idx, _sign) in sol.events:
            if idx == RsEvent.SIGMA_MAX or (idx == RsEvent.SIGMA_MIN and not stop_on_min):
                if stop_on_min or abs(y_ev[1] - seg.consts.r_steady) > self.extremum_floor:
                    self.emit("sigma_max" if idx == RsEvent.SIGMA_MAX else "sigma_min",
                              seg.to_global(y_ev))

    def _take_outputs(self, seg: Segment, sol: OdeSolution, output_index: int) -> None:
        """Record the output events (index ``output_index``) of a run, moved exactly onto
        their t_eval times."""
        used = 0
        for (_s, y_ev, idx, _sign) in sol.events:
            if idx == output_index:
                tj = float(seg.grid[used])
                used += 1
                self._record(seg.to_global(onto_time(seg.rhs, y_ev, tj))[None, :])
        self.next_out += used
        seg.grid = seg.grid[used:]

    def _terminal(self, seg: Segment, event: RsEvent, t_end: float) -> Event:
        """The event that ended a run."""
        if event == RsEvent.SIGMA_MIN:
            self.at_root = True
            return self.emit("sigma_min")
        if event == RsEvent.STEADY:
            return self.emit("steady")
        if event == RsEvent.RUNAWAY:
            self.emit("runaway")
            raise Stop(Status.RUNAWAY, f"v passed v_max = {self.v_max:.3g} at t = {self.t:.10g}")
        # SEGMENT_END: the end of the window or a change of driving
        self.y[4] = seg.t_stop
        self.at_root = True
        if seg.output:
            self._output_here()
        if seg.t_stop >= t_end:
            return self.emit("end")
        return self.emit("drive")


def runaway_bound(model: SpringSlider, protocol: Protocol, options: SolverOptions) -> float:
    """The velocity at which a run is declared a runaway (see ``SolverOptions.v_max``)."""
    if options.v_max is not None:
        return float(options.v_max)
    if isinstance(model.law, LogLaw) and model.eta_rad == 0.0:
        return RUNAWAY_FACTOR * float(np.max(protocol.velocities))
    return math.inf
