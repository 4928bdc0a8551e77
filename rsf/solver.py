r"""Orchestration: the event-driven integration of the spring-slider.

With no direct effect (:math:`a = 0`, the paper's model, Eqs. 8, 11, 12) the motion is a
sequence of phases (``docs/reference/rsf.md`` has the derivation):

* **stick** (:math:`v = 0`, :math:`\sigma < \phi(\theta)`): closed form,
  :math:`\theta = \theta_0 + t`, :math:`\sigma = \sigma_0 + k_0 V t`; its end is the first
  root of :math:`\sigma - \phi(\theta)` (:func:`rsf._kernels.stick_end`);
* **slide** (:math:`\sigma = \phi(\theta)`, :math:`v = N/D \ge 0` finite): the reduced ODE
  for :math:`\theta`, integrated by CVODE in the desingularised time
  :math:`\mathrm{d}t = D_c D/(K v_s)\,\mathrm{d}\tau`, with CVODE locating the switches
  :math:`D = 0` (slide -> slip) and :math:`N = 0` (slide -> stick);
* **slip** (instantaneous): :math:`\theta = \theta_0 e^{-\Delta x/D_c}`,
  :math:`\sigma = \sigma_0 - k_0\Delta x` until :math:`\sigma = \phi(\theta)` again (first
  root, :func:`rsf._kernels.slip_end`).

With :math:`a > 0` the model is a regular ODE in :math:`(\ln v, \ln\theta)` integrated by
CVODE (BDF), with events at the extrema of :math:`\sigma` (:math:`v = V`).

Public entry points: :func:`simulate` (a time series), :func:`limit_cycle` (the attractor
at one velocity) and :func:`sweep` (attractors over many velocities).
"""
from __future__ import annotations

import logging
import math
import time
from dataclasses import dataclass, field, replace
from typing import Iterable

import numpy as np

from . import _kernels
from ._sundials import OdeSolution, integrate, integrate_outputs
from ._validation import positive
from .laws import LogLaw
from .analysis import stability_margin
from .state_laws import NAGATA, USER
from .params import T_END_MAX, InitialState, Protocol, SolverOptions, SpringSlider
from .results import STATUS_MESSAGES, CycleResult, Event, Status, SweepResult, Trajectory

__all__ = ["simulate", "limit_cycle", "sweep"]

logger = logging.getLogger(__name__)

_THETA_FLOOR = 1e-250   # smallest theta resolved, in units of Dc (slips level off below)
_ZERO_PHASES = 20       # consecutive zero-length phases before giving up
_TAU_CHUNK = 1e4        # length of the first CVODE run in the slide time tau (and in units of
                        # the natural time scale for the a > 0 ODE)
_CHUNK_GROWTH = 30      # a = 0: the runs of one slide double in length, up to 2**30 _TAU_CHUNK,
                        # so that a long steady slide takes tens of runs, not millions (the a > 0
                        # engine follows a steady state it has reached in closed form instead)
_RUNAWAY_FACTOR = 1e3   # default runaway bound: v_max = 1e3 max V (LogLaw models)
_PROGRESS_CYCLES = 1000  # limit_cycle logs its progress (INFO) every this many cycles


def _chunk_span(chunk: int) -> float:
    """The length in tau of the ``chunk``-th CVODE run (from 0) of one slide of the a = 0
    model: ``_TAU_CHUNK``, then doubling.  CVODE ties its smallest step to the output time,
    so an open-ended run is not an option, but a settled slide lasts as long as the driving."""
    return _TAU_CHUNK * 2.0 ** min(chunk, _CHUNK_GROWTH)


class _Kernels:
    """The kernel set for one law (see :meth:`rsf.laws.SteadyStateLaw.kernels`)."""

    def __init__(self, law) -> None:
        for name, func in law.kernels().items():
            setattr(self, name, func)


class _Stop(Exception):
    """Raised inside an engine to end the run with a status."""

    def __init__(self, status: int, detail: str = "") -> None:
        super().__init__(detail)
        self.status = status
        self.detail = detail


@dataclass
class _Samples:
    t: list = field(default_factory=list)
    x: list = field(default_factory=list)
    sigma: list = field(default_factory=list)
    theta: list = field(default_factory=list)
    v: list = field(default_factory=list)
    theta2: list = field(default_factory=list)    # the second state variable, if any

    def add(self, t, x, sigma, theta, v, theta2=None) -> None:
        self.t.append(np.atleast_1d(np.array(t, dtype=float, copy=True)))
        n = self.t[-1].size
        for name, val in (("x", x), ("sigma", sigma), ("theta", theta), ("v", v)):
            getattr(self, name).append(np.broadcast_to(np.asarray(val, dtype=float), (n,)).copy())
        if theta2 is not None:
            self.theta2.append(np.broadcast_to(np.asarray(theta2, dtype=float), (n,)).copy())

    def theta2_array(self) -> np.ndarray:
        return np.concatenate(self.theta2) if self.theta2 else np.empty(0)

    def arrays(self) -> tuple[np.ndarray, ...]:
        if not self.t:
            return tuple(np.empty(0) for _ in range(5))
        return tuple(np.concatenate(getattr(self, name)) for name in ("t", "x", "sigma", "theta", "v"))


# ======================================================================================
# a = 0: stick, slide and slip
# ======================================================================================
def _charge(engine, nfev: int) -> None:
    """Add ``nfev`` right-hand-side evaluations to ``engine``'s count; past the step budget
    (``options.max_rhs_evals``) the run stops with ``STEP_BUDGET``."""
    engine.nfev += nfev
    if engine.nfev > engine.options.max_rhs_evals:
        raise _Stop(Status.STEP_BUDGET, f"{engine.nfev} evaluations, at t = {engine.t:.10g}")


class _PhaseEngine:
    """Event-driven integration of the a = 0 model (one phase per :meth:`step`)."""

    def __init__(self, model: SpringSlider, protocol: Protocol, options: SolverOptions,
                 record: bool, stop_at_steady: bool, t_eval: np.ndarray | None = None) -> None:
        self.model = model
        self.protocol = protocol
        self.options = options
        self.record = record
        self.stop_at_steady = stop_at_steady
        self.t_eval = t_eval
        self.next_out = 0
        self.p = model.law.kernel_params
        self.mu_ref = model.law.mu_ref
        self.k = _Kernels(model.law)
        self.law_fn = self.k.law_eval
        self.k0 = model.k0
        self.Dc = model.Dc
        self.K = model.K
        w_lo, w_hi = model.law.weakening_bounds()
        self.w_neg = max(0.0, -w_lo)
        self.lipschitz = self.K + max(abs(w_lo), abs(w_hi)) + 1e-300
        self.extrema_on = 1.0 if (w_lo < 0.0 < w_hi) else 0.0
        self.concave_sup = model.law.concave_sup
        self.samples = _Samples()
        self.events: list[Event] = []
        self.t = 0.0
        self.x = 0.0
        self.sigma = 0.0        # relative to mu_ref (see _kernels)
        self.theta = 1.0
        self.integral = 0.0     # running integral of the (absolute) sigma dt
        self.phase = _kernels.STICK
        self.zero_phases = 0
        self.nfev = 0

    # -- helpers ------------------------------------------------------------------------
    def phi(self, theta: float) -> float:
        """Threshold phi(theta) relative to mu_ref."""
        return float(self.law_fn(self.Dc / theta, self.p)[0])

    def velocity(self) -> float:
        return self.protocol.velocity_at(self.t)

    def load_point(self, t: float) -> float:
        return self.protocol.load_point(t)

    def emit(self, kind: str) -> Event:
        ev = Event(self.t, kind, self.mu_ref + self.sigma, self.theta, self.x)
        self.events.append(ev)
        return ev

    def sample_now(self, v: float = 0.0) -> None:
        if not self.record:
            return
        if self.t_eval is None:
            self.samples.add(self.t, self.x, self.mu_ref + self.sigma, self.theta, v)
            return
        te = self.t_eval        # only the requested times that fall on this instant
        while self.next_out < te.size and te[self.next_out] <= self.t:
            if te[self.next_out] < self.t * (1.0 - 1e-14) - 1e-300:
                logger.warning("t_eval point %.17g skipped (passed over at t = %.17g)",
                               te[self.next_out], self.t)
            else:
                self.samples.add(te[self.next_out], self.x, self.mu_ref + self.sigma,
                                 self.theta, v)
            self.next_out += 1

    def decide(self) -> int:
        return int(self.k.decide(self.p, self.theta, self.K, self.velocity(), self.Dc))

    def start(self, initial: InitialState) -> None:
        V0 = float(self.protocol.velocities[0])
        if initial.theta is not None:
            theta = initial.theta
        elif V0 > 0.0:
            theta = self.Dc / V0 * (1.0 + (initial.perturbation or 0.0))
        else:
            raise ValueError("initial.theta is required when the driving starts with V = 0")
        self.theta = theta
        self.sigma = self.phi(theta) if initial.sigma is None else initial.sigma - self.mu_ref
        self.x = self.load_point(0.0) - (self.mu_ref + self.sigma) / self.k0
        self.t = 0.0
        gap = self.sigma - self.phi(theta)
        if gap > 1e-13 * max(1.0, abs(self.sigma)):
            self.phase = _kernels.SLIP
        elif gap < -1e-13 * max(1.0, abs(self.sigma)):
            self.phase = _kernels.STICK
        else:
            self.sigma = self.phi(theta)
            self.phase = self.decide()
        self.sample_now()
        self.emit("start")

    def set_on_threshold(self, theta: float) -> None:
        """Restart on the threshold at ``theta`` (used by the cycle extrapolation)."""
        self.theta = theta
        self.sigma = self.phi(theta)
        self.x = self.load_point(self.t) - (self.mu_ref + self.sigma) / self.k0
        self.phase = self.decide()
        self.emit("restart")

    # -- phases -------------------------------------------------------------------------
    def step(self, t_end: float) -> Event:
        """Run the current phase to its end; return the event that ends it."""
        if self.phase == _kernels.STICK:
            ev = self._stick(t_end)
        elif self.phase == _kernels.SLIP:
            ev = self._slip()
        else:
            ev = self._slide(t_end)
        if self.t_eval is not None:
            self.sample_now(self.slip_rate())
        return ev

    def slip_rate(self) -> float:
        """The slip velocity in the current phase (inf for a slip)."""
        if self.phase == _kernels.STICK:
            return 0.0
        if self.phase == _kernels.SLIP:
            return math.inf
        u = self.Dc / self.theta
        w = float(self.law_fn(u, self.p)[1])
        d = self.K - w
        return (self.K * self.velocity() - u * w) / d if d > 0.0 else math.inf

    def _zero_guard(self, duration: float) -> None:
        if duration == 0.0:
            self.zero_phases += 1
            if self.zero_phases > _ZERO_PHASES:
                raise _Stop(Status.DEGENERATE, f"at t = {self.t:g}, theta = {self.theta:g}")
        else:
            self.zero_phases = 0

    def _stick(self, t_end: float) -> Event:
        V = self.velocity()
        t_stop = min(self.protocol.segment_end(self.t), t_end)
        horizon = t_stop - self.t
        phi0 = self.phi(self.theta)
        h0 = self.sigma - phi0
        if abs(h0) <= 1e-14 * max(1.0, abs(phi0)):
            h0 = 0.0
        dt, flag = self.k.stick_end(self.p, h0, self.theta, self.k0 * V, self.Dc,
                                    horizon, self.w_neg, self.concave_sup)
        if flag == _kernels.FAILED:
            raise _Stop(Status.SOLVER_FAILED, f"stick-end search failed at t = {self.t:g}")
        sigma_new = self.sigma + self.k0 * V * dt
        if self.record and self.t_eval is not None:
            tt = self._pending_upto(self.t + dt)       # closed form: exact samples
            ts = tt - self.t
            if ts.size:
                self.samples.add(tt, self.x, self.mu_ref + self.sigma + self.k0 * V * ts,
                                 self.theta + ts, 0.0)
        elif self.record and dt > 0.0:
            ts = np.linspace(0.0, dt, 17)[1:]
            self.samples.add(self.t + ts, self.x, self.mu_ref + self.sigma + self.k0 * V * ts,
                             self.theta + ts, 0.0)
        self.integral += (self.mu_ref + 0.5 * (self.sigma + sigma_new)) * dt
        self.t += dt
        self.theta += dt
        self.sigma = sigma_new
        self._zero_guard(dt)
        if flag == _kernels.FOUND:
            nxt = self.decide()
            if nxt == _kernels.STICK:           # a tangent touch: keep sticking
                return self.emit("touch")
            self.phase = nxt
            return self.emit("stick->slide" if nxt == _kernels.SLIDE else "stick->slip")
        if self.t >= t_end:
            self.t = t_end
            return self.emit("end")
        return self._drive_change()

    def _drive_change(self) -> Event:
        """A change of the load-point velocity: pick the phase again."""
        gap = self.sigma - self.phi(self.theta)
        if gap < -1e-13 * max(1.0, abs(self.sigma)):
            self.phase = _kernels.STICK
        elif gap > 1e-13 * max(1.0, abs(self.sigma)):
            self.phase = _kernels.SLIP
        else:
            self.phase = self.decide()
        return self.emit("drive")

    def _slip(self) -> Event:
        phi0 = self.phi(self.theta)
        g0 = self.sigma - phi0
        if abs(g0) <= 1e-14 * max(1.0, abs(phi0)):
            g0 = 0.0
        floor = _THETA_FLOOR * self.Dc
        s, flag = self.k.slip_end(self.p, g0, self.theta, self.K, self.Dc,
                                  self.lipschitz, floor)
        if flag == _kernels.HORIZON:
            raise _Stop(Status.RUNAWAY, f"at t = {self.t:g}, theta = {self.theta:g}")
        if flag == _kernels.FAILED:
            raise _Stop(Status.SOLVER_FAILED, f"slip-end search failed at t = {self.t:g}")
        self.theta = floor if flag == _kernels.FLOOR else self.theta * math.exp(-s)
        self.x += self.Dc * s
        if flag in (_kernels.FOUND, _kernels.FLOOR):
            self.sigma = self.phi(self.theta)   # the root: on the threshold
        else:
            self.sigma -= self.K * s
        self.sample_now()
        self._zero_guard(s)
        nxt = self.decide()
        if flag == _kernels.NO_SLIP and nxt == _kernels.SLIP:
            # not over-stressed after all: move on according to the sign of N
            u = self.Dc / self.theta
            w = float(self.law_fn(u, self.p)[1])
            nxt = _kernels.SLIDE if self.K * self.velocity() - u * w > 0.0 else _kernels.STICK
        self.phase = nxt
        return self.emit({_kernels.STICK: "slip->stick", _kernels.SLIDE: "slip->slide",
                          _kernels.SLIP: "slip->slip"}[nxt])

    def _pending_upto(self, t_hi: float) -> np.ndarray:
        """The pending t_eval points up to ``t_hi`` (inclusive), marked as done."""
        te = self.t_eval
        j1 = int(np.searchsorted(te, t_hi, side="right"))
        out = te[self.next_out:j1]
        self.next_out = max(self.next_out, j1)
        return out

    def _integrate_chunks(self, rhs, events, atol, out_times=None) -> OdeSolution:
        """CVODE over the slide in chunks of tau (CVODE ties its smallest step to the
        output time, so an open-ended output time is not an option).  ``out_times``
        (slide-local times): also stop at those (output events, index 5)."""
        opts = self.options
        y0 = np.zeros(3)
        tau0 = 0.0
        ts, ys, evs = [], [], []
        nfev = 0
        terminal = (True, True, True, False, True)
        direction = (-1, -1, -1, 0, 1)
        for chunk in range(100000):
            span = _chunk_span(chunk)
            save_steps = self.record and self.t_eval is None
            if (out_times is not None and out_times.size) or save_steps:
                sol = integrate_outputs(rhs, y0, tau0, tau0 + span, out_index=1,
                                        out_times=out_times, events=events, terminal=terminal,
                                        direction=direction, rtol=opts.rtol, atol=atol,
                                        method=opts.method, max_num_steps=opts.max_num_steps,
                                        save_steps=save_steps)
                n_found = sum(1 for ev in sol.events if ev[2] == len(terminal))
                if out_times is not None:
                    out_times = out_times[n_found:]
            else:
                sol = integrate(rhs, y0, tau0, tau0 + span, events=events,
                                terminal=terminal, direction=direction,
                                rtol=opts.rtol, atol=atol, method=opts.method,
                                max_num_steps=opts.max_num_steps)
            nfev += sol.nfev
            _charge(self, sol.nfev)
            if not sol.success:
                t_fail = self.t + float(sol.y[-1][1]) if np.all(np.isfinite(sol.y[-1])) else self.t
                raise _Stop(Status.SOLVER_FAILED, f"CVODE in a slide at t = {t_fail:.10g}: "
                                                  f"{sol.message}")
            ts.append(sol.t if not ts else sol.t[1:])
            ys.append(sol.y if not ys else sol.y[1:])
            evs.extend(sol.events)
            if sol.terminal_event is not None:
                sol.t = np.concatenate(ts)
                sol.y = np.concatenate(ys)
                sol.events = evs
                sol.nfev = nfev
                return sol
            y0 = sol.y[-1].copy()     # autonomous in tau: the next chunk restarts at 0
        raise _Stop(Status.SOLVER_FAILED, f"slide at t = {self.t:g} did not end")

    def _slide(self, t_end: float) -> Event:
        V = self.velocity()
        opts = self.options
        t_stop = min(self.protocol.segment_end(self.t), t_end)
        theta_s = self.theta
        u_s = self.Dc / theta_s
        vs = max(V, u_s)
        law, p = self.law_fn, self.p
        steady_on = 0.0
        lnV = 0.0
        if V > 0.0:
            lnV = math.log(V)
            w_ss = float(law(V, p)[1])
            if self.stop_at_steady and self.K - w_ss > 0.0:
                steady_on = 1.0
                if abs(math.log(u_s) - lnV) <= opts.cycle_rtol or (
                        t_stop == math.inf and self.k.slide_converges(self.p, u_s, V, self.K)):
                    # already steady, or certain to converge to it with no switch on the way
                    return self.emit("steady")
        c = np.array([self.K, V, self.Dc, vs, u_s, opts.cycle_rtol,
                      t_stop - self.t if math.isfinite(t_stop) else 1e300, lnV, steady_on,
                      self.extrema_on])
        k = self.k

        def rhs(tau, y, yp):
            k.slide_rhs(y, yp, p, c)

        def events(tau, y, e):
            k.slide_events(y, e, p, c)

        t_scale = self.Dc / vs
        atol = np.array([opts.atol, opts.atol * t_scale, opts.atol * t_scale * max(1.0, abs(self.sigma))])
        t0 = self.t
        out_times = None
        if self.record and self.t_eval is not None:
            te = self.t_eval
            j1 = int(np.searchsorted(te, t_stop, side="right"))
            out_times = np.ascontiguousarray(te[self.next_out:j1] - t0)
            out_times = out_times[out_times > 0.0]
        sol = self._integrate_chunks(rhs, events, atol, out_times)
        x_lp0 = self.load_point(t0)
        if self.record:
            if self.t_eval is None:
                ys = sol.y[1:]
            else:               # the output events, moved exactly onto the requested times
                found = []
                for (_tau, y, idx, _sign) in sol.events:
                    if idx == 5:
                        found.append(_onto_time(rhs, y, float(out_times[len(found)]), 1))
                ys = np.array(found).reshape(-1, 3)
                t_exact = self.t_eval[self.next_out:self.next_out + ys.shape[0]]
                self.next_out += ys.shape[0]
            theta_arr = theta_s * np.exp(ys[:, 0])
            u_arr = self.Dc / theta_arr
            mu_arr = np.array([law(u, p)[0] for u in u_arr])
            w_arr = np.array([law(u, p)[1] for u in u_arr])
            d_arr = self.K - w_arr
            with np.errstate(divide="ignore", invalid="ignore"):
                v_arr = (self.K * V - u_arr * w_arr) / d_arr
            v_arr[d_arr <= 0.0] = np.inf     # the slide ends where v diverges (D = 0)
            t_arr = t0 + ys[:, 1] if self.t_eval is None else t_exact
            self.samples.add(t_arr, x_lp0 + V * ys[:, 1] - (self.mu_ref + mu_arr) / self.k0,
                             self.mu_ref + mu_arr, theta_arr, v_arr)
        for (tau, y, idx, _sign) in sol.events:
            if idx == 3:   # interior extremum of sigma (W = 0)
                th = theta_s * math.exp(y[0])
                sg = self.phi(th)
                self.events.append(Event(t0 + y[1], "extremum", self.mu_ref + sg, th,
                                         x_lp0 + V * y[1] - (self.mu_ref + sg) / self.k0))
        z, t_loc, integral = sol.y[-1]
        self.theta = theta_s * math.exp(z)
        self.sigma = self.phi(self.theta)
        self.t = t0 + t_loc
        self.x = x_lp0 + V * t_loc - (self.mu_ref + self.sigma) / self.k0
        self.integral += integral + self.mu_ref * t_loc
        self._zero_guard(t_loc)
        which = sol.terminal_event
        if which == 0:
            self.phase = _kernels.SLIP
            return self.emit("slide->slip")
        if which == 1:
            self.phase = _kernels.STICK
            return self.emit("slide->stick")
        if which == 2:
            return self.emit("steady")
        # which == 4: end of the time window or a change of driving
        if self.t >= t_end * (1.0 - 1e-15):
            self.t = t_end
            return self.emit("end")
        self.t = t_stop
        return self._drive_change()


# ======================================================================================
# a > 0: the regular rate-and-state ODE
# ======================================================================================
class _SmoothEngine:
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
        self.model = model
        self.protocol = protocol
        self.options = options
        self.record = record
        self.stop_at_steady = stop_at_steady
        self.p = model.law.kernel_params
        self.mu_ref = model.law.mu_ref
        self.k = _Kernels(model.law)
        self.law_fn = self.k.law_eval
        self.samples = _Samples()
        self.events: list[Event] = []
        self.second = model.second_state
        self.n_vars = 5 if self.second is None else 6
        self.y = np.zeros(self.n_vars)
        self.nfev = 0
        self.at_root = False       # the state sits on an event root (after a terminal event)
        self.t_eval = t_eval
        self.eta = model.eta_rad
        state = model.state
        self.state_code = float(state.code)
        self.user_rate = state.func if state.code == USER else None
        self.c_over_b = 0.0
        if state.code == NAGATA:
            b = state.b if state.b is not None else model.law.b
            self.c_over_b = state.c / b
        self.ln_v0 = math.log(model.law.v0) if isinstance(model.law, LogLaw) else 0.0
        self.next_out = 0          # index of the next t_eval point to output
        self.v_max = _runaway_bound(model, protocol, options)
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
        ev = Event(float(y[4]), kind, self.sigma_of(y), self.theta_of(y), float(y[2]))
        self.events.append(ev)
        return ev

    def start(self, initial: InitialState) -> None:
        m = self.model
        V0 = float(self.protocol.velocities[0])
        if initial.theta is not None:
            theta = initial.theta
        elif V0 > 0.0:
            theta = m.Dc / V0 * (1.0 + (initial.perturbation or 0.0))
        else:
            raise ValueError("initial.theta is required when the driving starts with V = 0")
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

    def _record(self, y: np.ndarray) -> None:
        m = self.model
        u = np.exp(-y[:, 1])
        mu = np.array([self.law_fn(ui, self.p)[0] for ui in u])
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
            if self.t_eval is None:
                ts = np.array([t_stop])
            else:
                te = self.t_eval
                j1 = int(np.searchsorted(te, t_stop, side="left"))
                ts = te[self.next_out:j1]
                self.next_out = max(self.next_out, j1)
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

    def step(self, t_end: float, stop_on_min: bool) -> Event:
        m = self.model
        opts = self.options
        t_now = self.t
        V = self.protocol.velocity_at(t_now)
        t_stop = min(self.protocol.segment_end(t_now), t_end)
        lnV = math.log(V) if V > 0.0 else 0.0
        q_ss = -lnV
        steady_on = 1.0 if (self.stop_at_steady and V > 0.0
                            and stability_margin(m, V) < 0.0) else 0.0
        slope = self.protocol.slope_at(t_now)
        if slope != 0.0:
            steady_on = 0.0
        distance = abs(self.y[0] - lnV) + abs(self.y[1] - q_ss)
        if self.second is not None:
            distance += abs(self.y[5] - q_ss)
        if steady_on and distance <= opts.cycle_rtol:
            return self.emit("steady")
        if V > 0.0 and slope == 0.0 and self._steady_exactly(lnV):
            if math.isfinite(t_stop):
                return self._advance_steady(V, t_stop, t_end)
            return self.emit("steady")       # on a fixed point for ever
        vs = V if V > 0.0 else max(math.exp(-self.y[1]), 1e-300)
        lvs = math.log(vs)
        second = self.second
        c = np.array([m.K, V, m.Dc, m.a, self.state_code, vs,
                      lnV - lvs if V > 0.0 else 0.0, lvs - lnV if V > 0.0 else 0.0,
                      opts.cycle_rtol, steady_on, t_stop if math.isfinite(t_stop) else 1e300,
                      math.log(self.v_max) - lvs if math.isfinite(self.v_max) else 1e300,
                      self.eta, self.c_over_b, second.b2 if second is not None else 0.0,
                      m.Dc / second.Dc2 if second is not None else 0.0, self.ln_v0 - lvs,
                      slope, t_now])
        k, p = self.k, self.p
        user_rate = self.user_rate
        Dc = m.Dc
        output = self.record and self.t_eval is not None
        if output:
            j1 = int(np.searchsorted(self.t_eval, t_stop, side="left"))
            grid = self.t_eval[self.next_out:j1]
            grid = np.ascontiguousarray(grid[grid > t_now])
        else:
            grid = np.empty(0)

        if user_rate is None:
            def rhs(s, y, yp):
                k.rs_rhs(y, yp, p, c)
        else:
            def rhs(s, y, yp):
                # d ln(theta)/ds = (dtheta/dt / theta) dt/ds, with dt/ds = Dc f / vs
                w = y[0]
                f = 1.0 / (1.0 + math.exp(w)) if w <= 0.0 else math.exp(-w) / (1.0 + math.exp(-w))
                theta = Dc * math.exp(y[1]) / vs
                rate = user_rate(vs * math.exp(min(w, 700.0)), theta)
                k.rs_rhs_dr(y, yp, p, c, rate / theta * Dc * f / vs)

        def events(s, y, e):
            k.rs_events(y, e, p, c)

        terminal = (False, stop_on_min, True, True, True)
        direction = (1, -1, -1, 1, 1)

        def to_local(y: np.ndarray) -> np.ndarray:      # [ln v, q, ...] -> [w, r, ...]
            out = y.copy()
            out[0] = y[0] - lvs
            out[1] = y[1] + lvs
            if second is not None:
                out[5] = y[5] + lvs
            return out

        def to_global(y: np.ndarray) -> np.ndarray:
            out = np.array(y, dtype=float, copy=True)
            out[..., 0] += lvs
            out[..., 1] -= lvs
            if second is not None:
                out[..., 5] -= lvs
            return out

        t_scale = m.Dc / vs
        atol = np.array([opts.atol, opts.atol, opts.atol * m.Dc,
                         opts.atol * t_scale * max(1.0, abs(self.sigma_of(self.y) - self.mu_ref)),
                         opts.atol * t_scale] + ([opts.atol] if second is not None else []))
        y_loc = to_local(self.y)
        save_steps = self.record and not output

        def failed(sol: OdeSolution) -> _Stop:
            # keep the trajectory up to the failure and say where it happened
            if sol.y.size and np.all(np.isfinite(sol.y[-1])):
                self.y = to_global(sol.y[-1])
            v_now = f"{math.exp(self.y[0]):.3g}" if self.y[0] < 700.0 else f"exp({self.y[0]:.4g})"
            return _Stop(Status.SOLVER_FAILED, f"CVODE at t = {self.t:.10g} (v = {v_now}): "
                                               f"{sol.message}")

        def run(y_start, s_start, s_stop, with_events):
            if (output and grid.size) or (save_steps and with_events):
                return integrate_outputs(
                    rhs, y_start, s_start, s_stop, out_index=4, out_times=grid,
                    events=events if with_events else None,
                    terminal=terminal if with_events else (),
                    direction=direction if with_events else (), rtol=opts.rtol, atol=atol,
                    method="BDF", max_num_steps=opts.max_num_steps, save_steps=save_steps)
            if not with_events:
                return integrate(rhs, y_start, s_start, s_stop, rtol=opts.rtol, atol=atol,
                                 method="BDF", max_num_steps=opts.max_num_steps)
            return integrate(rhs, y_start, s_start, s_stop, events=events, terminal=terminal,
                             direction=direction, rtol=opts.rtol, atol=atol, method="BDF",
                             max_num_steps=opts.max_num_steps, save_steps=save_steps)

        def take_outputs(sol: OdeSolution, n_user: int) -> None:
            nonlocal grid
            used = 0
            for (_s, y_ev, idx, _sign) in sol.events:
                if idx == n_user:
                    tj = float(grid[used])
                    used += 1
                    self._record(to_global(_onto_time(rhs, y_ev, tj))[None, :])
            self.next_out += used
            grid = grid[used:]

        if self.at_root:
            # step off an event root without events (CVODE rejects a root at the start)
            sol = run(y_loc, 0.0, 1e-6, False)
            _charge(self, sol.nfev)
            if not sol.success:
                raise failed(sol)
            take_outputs(sol, 0)
            y_loc = sol.y[-1].copy()
            self.at_root = False
        s0 = 0.0
        # a stable steady state, reached to within the integrator's tolerance, is followed in
        # closed form to the end of the segment: at round-off distance CVODE's steps shrink
        # to the noise of the right-hand side and a long run would never end
        snap = (V > 0.0 and slope == 0.0 and math.isfinite(t_stop)
                and stability_margin(m, V) < 0.0)
        snap_tol = max(opts.rtol, opts.atol)
        for _ in range(100000):
            sol = run(y_loc, s0, s0 + _TAU_CHUNK, True)
            if save_steps:
                self._record(to_global(sol.y[1:]))
            if not sol.success:
                raise failed(sol)
            _charge(self, sol.nfev)
            for (_s, y_ev, idx, _sign) in sol.events:
                if idx == 0 or (idx == 1 and not stop_on_min):
                    # a time series drops extrema at round-off distance from steady state;
                    # a limit-cycle search keeps them all (tiny cycles near a Hopf point)
                    if stop_on_min or abs(y_ev[1] - c[7]) > self.extremum_floor:
                        self.emit("sigma_max" if idx == 0 else "sigma_min", to_global(y_ev))
            take_outputs(sol, len(terminal))
            y_loc = sol.y[-1].copy()       # the system is autonomous in s: restart at 0
            self.y = to_global(y_loc)
            if sol.terminal_event is not None:
                break
            if snap and self._distance_to_steady(lnV) <= snap_tol:
                self.y[0], self.y[1] = lnV, -lnV
                if second is not None:
                    self.y[5] = -lnV
                self.y[2] = self.protocol.load_point(self.t) - self.spring_of(self.y) / m.k0
                return self._advance_steady(V, t_stop, t_end)
        else:
            raise _Stop(Status.SOLVER_FAILED, f"no progress at t = {self.t:.10g}")
        if sol.terminal_event == 1:
            self.at_root = True
            return self.emit("sigma_min")
        if sol.terminal_event == 2:
            return self.emit("steady")
        if sol.terminal_event == 4:
            self.emit("runaway")
            raise _Stop(Status.RUNAWAY, f"v passed v_max = {self.v_max:.3g} at t = {self.t:.10g}")
        # terminal_event == 3: end of the window or a change of driving
        self.y[4] = t_stop
        self.at_root = True
        if output:
            self._output_here()
        if t_stop >= t_end:
            return self.emit("end")
        return self.emit("drive")


def _onto_time(rhs, y: np.ndarray, t_target: float, index: int = 4) -> np.ndarray:
    """Move a state found by CVODE's root finder (time ``y[index]`` within the root
    tolerance of ``t_target``) exactly onto ``t_target`` with one Newton step along the
    flow."""
    yp = np.empty_like(y)
    rhs(0.0, y, yp)
    out = y.copy()
    if yp[index] > 0.0:
        out += (t_target - y[index]) / yp[index] * yp
    out[index] = t_target
    return out


def _runaway_bound(model: SpringSlider, protocol: Protocol, options: SolverOptions) -> float:
    """The velocity at which a run is declared a runaway (see ``SolverOptions.v_max``)."""
    if options.v_max is not None:
        return float(options.v_max)
    if isinstance(model.law, LogLaw) and model.eta_rad == 0.0:
        return _RUNAWAY_FACTOR * float(np.max(protocol.velocities))
    return math.inf


# ======================================================================================
# public entry points
# ======================================================================================
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
        status.  A slip appears as two samples at one instant.
    """
    if not isinstance(model, SpringSlider):
        raise ValueError(f"model must be an rsf.SpringSlider, got {model!r}")
    t_end = positive("t_end", t_end)
    if t_end > T_END_MAX:
        raise ValueError(f"t_end must be <= {T_END_MAX:g} (rsf.params.T_END_MAX), got {t_end:g}")
    protocol = _protocol_from(V, protocol)
    initial = initial or InitialState()
    initial = initial.resolved(InitialState.DEFAULT_PERTURBATION if protocol.is_constant else 0.0)
    options = options or SolverOptions()
    t_eval = _check_t_eval(t_eval, t_end)
    if model.a == 0.0 and protocol.is_linear:
        raise ValueError("a sampled (linearly interpolated) load history needs a direct "
                         "effect a > 0; for a = 0 use piecewise-constant steps")
    if model.a == 0.0:
        engine = _PhaseEngine(model, protocol, options, record=True,
                              stop_at_steady=stop_at_steady, t_eval=t_eval)
    else:
        engine = _SmoothEngine(model, protocol, options, record=True,
                               stop_at_steady=stop_at_steady, t_eval=t_eval)
    engine.start(initial)
    status = Status.TIME_LIMIT
    detail = ""
    try:
        n = 0
        while True:
            if model.a == 0.0:
                ev = engine.step(t_end)
            else:
                ev = engine.step(t_end, stop_on_min=False)
            n += 1
            if ev.kind == "end":
                break
            if ev.kind == "steady":
                status = Status.STEADY
                break
            if n >= options.max_events:
                status = Status.MAX_EVENTS
                break
    except _Stop as stop:
        status, detail = stop.status, stop.detail
    t, x, sigma, theta, v = engine.samples.arrays()
    message = STATUS_MESSAGES[status] + (f" ({detail})" if detail else "")
    if status < 0:
        logger.warning("simulate: %s", message)
    theta2 = engine.samples.theta2_array() if model.second_state is not None else None
    return Trajectory(t=t, x=x, sigma=sigma, theta=theta, v=v, theta2=theta2, events=engine.events,
                      status=status, message=message, params=model.describe())


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


@dataclass
class _Cycle:
    sigma_max: float
    sigma_min: float
    period: float
    mean: float
    sequence: tuple[str, ...]
    section: float
    events: list[Event]


def _relative_change(a: _Cycle, b: _Cycle) -> float:
    """Largest relative change of sigma_max, sigma_min, the period and the amplitude
    sigma_max - sigma_min (the amplitude: so that a slowly decaying oscillation of small
    amplitude is not taken for a converged cycle)."""
    out = 0.0
    for x, y in ((a.sigma_max, b.sigma_max), (a.sigma_min, b.sigma_min), (a.period, b.period),
                 (a.sigma_max - a.sigma_min, b.sigma_max - b.sigma_min)):
        scale = max(abs(x), abs(y), 1e-300)
        out = max(out, abs(x - y) / scale)
    return out


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
    of :math:`\ln\theta` at the section is extrapolated (Aitken) to skip slow transients.

    Returns
    -------
    CycleResult
        regime ('steady' or 'stick-slip'), sigma_max, sigma_min, sigma_mean, period,
        converged, status and message.
    """
    if not isinstance(model, SpringSlider):
        raise ValueError(f"model must be an rsf.SpringSlider, got {model!r}")
    V = positive("V", V)
    options = options or SolverOptions()
    if model.second_state is not None and options.accelerate:
        # the cycle map has two dimensions: no one-variable extrapolation
        options = replace(options, accelerate=False)
    initial = (initial or InitialState()).resolved(InitialState.DEFAULT_PERTURBATION)
    started = time.perf_counter()
    protocol = Protocol.constant(V)
    smooth = model.a > 0.0
    engine = (_SmoothEngine if smooth else _PhaseEngine)(model, protocol, options, record=False,
                                                         stop_at_steady=True)
    engine.start(initial)
    params = model.describe()
    params["V"] = V

    cycles: list[_Cycle] = []
    since_restart = 0
    anchor: tuple[float, float, float, int] | None = None  # t, integral, section, event index
    status = Status.MAX_CYCLES
    detail = ""
    n_events = 0
    result_cycle: _Cycle | None = None
    rel = math.nan
    fallback_anchor = False
    sections: list[float] = []
    anchor_sigma = math.nan

    def integral_now() -> float:
        return engine.integral

    def section_now() -> float:
        return math.log(engine.theta) if not smooth else float(engine.y[1])

    try:
        while True:
            ev = engine.step(math.inf) if not smooth else engine.step(math.inf, stop_on_min=True)
            n_events += 1
            if n_events > options.max_events:
                status = Status.MAX_EVENTS
                break
            if ev.kind == "steady":
                status = Status.STEADY
                break
            if smooth:
                is_anchor = ev.kind == "sigma_min"
            elif not fallback_anchor:
                is_anchor = ev.kind.startswith("slip->")
                if anchor is None and n_events > 200 and not any(
                        e.kind.startswith("slip->") for e in engine.events[-200:]):
                    fallback_anchor = True     # no slips: cycles of stick and slide only
            else:
                is_anchor = ev.kind == "slide->stick"
            if not is_anchor:
                continue
            now = (engine.t, integral_now(), section_now(), len(engine.events) - 1)
            if anchor is not None:
                t0, i0, _, e0 = anchor
                evs = engine.events[e0 + 1: now[3] + 1]
                sig = [anchor_sigma] + [e.sigma for e in evs]
                period = now[0] - t0
                cyc = _Cycle(max(sig), min(sig), period,
                             (now[1] - i0) / period if period > 0 else math.nan,
                             tuple(e.kind for e in evs), now[2], evs)
                cycles.append(cyc)
                since_restart += 1
                if len(cycles) >= 2 and since_restart >= 2:
                    prev, last = cycles[-2], cycles[-1]
                    if prev.sequence == last.sequence:
                        rel = _relative_change(prev, last)
                        if rel <= options.cycle_rtol:
                            status = Status.CONVERGED
                            result_cycle = last
                            break
                if len(cycles) > options.max_cycles:
                    status = Status.MAX_CYCLES
                    result_cycle = cycles[-1]
                    if len(cycles) >= 2:
                        rel = _relative_change(cycles[-2], cycles[-1])
                    detail = (f"{options.max_cycles} cycles; the last relative change {rel:.3g} against "
                              f"cycle_rtol {options.cycle_rtol:.3g}")
                    break
                if len(cycles) % _PROGRESS_CYCLES == 0:     # progress within a slow search
                    logger.info("limit_cycle(V=%g): %d of at most %d cycles, relative change %.3g "
                                "(converged below %.3g)", V, len(cycles), options.max_cycles,
                                _relative_change(cycles[-2], cycles[-1]), options.cycle_rtol)
            sections.append(now[2])
            # Aitken extrapolation of the map section -> next section
            if (options.accelerate and since_restart >= 2 and len(sections) >= 3
                    and cycles[-1].sequence == cycles[-2].sequence):
                x0, x1, x2 = sections[-3:]
                d1, d2 = x1 - x0, x2 - x1
                if d1 != 0.0 and abs(d2) > 1e-12 * max(1.0, abs(x2)):
                    lam = d2 / d1
                    if 0.02 < abs(lam) < 0.9999:
                        jump = max(-2.0, min(2.0, lam * d2 / (1.0 - lam)))
                        target = x2 + jump
                        if smooth:
                            engine.set_state(math.log(V), target)
                        else:
                            engine.set_on_threshold(math.exp(target))
                        since_restart = 0
                        sections = [target]
                        now = (engine.t, integral_now(), section_now(), len(engine.events) - 1)
            anchor = now
            anchor_sigma = engine.events[now[3]].sigma
    except _Stop as stop:
        status, detail = stop.status, stop.detail
        if cycles:
            result_cycle = cycles[-1]

    run_time = time.perf_counter() - started
    message = STATUS_MESSAGES[status] + (f" ({detail})" if detail else "")
    if status == Status.STEADY:
        sigma_ss = model.sigma_steady(V)
        return CycleResult(V=V, regime="steady", sigma_max=sigma_ss, sigma_min=sigma_ss,
                           sigma_mean=sigma_ss, period=math.nan, converged=True, status=status,
                           message=message, n_cycles=len(cycles), relative_change=0.0,
                           sequence=(), events=engine.events[-3:], params=params,
                           run_time=run_time)
    if status < 0:
        logger.warning("limit_cycle(V=%g): %s", V, message)
    c = result_cycle
    return CycleResult(
        V=V, regime="stick-slip" if status == Status.CONVERGED else "unknown",
        sigma_max=c.sigma_max if c else math.nan, sigma_min=c.sigma_min if c else math.nan,
        sigma_mean=c.mean if c else math.nan, period=c.period if c else math.nan,
        converged=status == Status.CONVERGED, status=status, message=message,
        n_cycles=len(cycles), relative_change=rel, sequence=c.sequence if c else (),
        events=list(c.events) if c else [], params=params, run_time=run_time)


def sweep(model: SpringSlider, velocities: Iterable[float], *, options: SolverOptions | None = None,
          initial: InitialState | None = None, progress: bool = False) -> SweepResult:
    """:func:`limit_cycle` at each velocity (in the given order).

    Parameters
    ----------
    model : SpringSlider
    velocities : iterable of float
        Driving velocities, > 0.
    options : SolverOptions, optional
    initial : InitialState, optional
        Used at every velocity (default: perturbed steady state at that velocity).
    progress : bool
        Log progress at INFO level every 10 % of the points.

    Returns
    -------
    SweepResult
        ``to_frame()`` has one row per V: k0, Dc, V, regime, sigma_max, sigma_min,
        sigma_mean, period, converged, status, message, ...
    """
    vel = [positive(f"velocities[{i}]", v) for i, v in enumerate(velocities)]
    if not vel:
        raise ValueError("velocities must hold at least one velocity > 0")
    results = []
    for i, V in enumerate(vel):
        results.append(limit_cycle(model, V, initial=initial, options=options))
        if progress and (i + 1) % max(1, len(vel) // 10) == 0:
            logger.info("sweep: %d / %d velocities done", i + 1, len(vel))
    return SweepResult(results=results, params=model.describe())
