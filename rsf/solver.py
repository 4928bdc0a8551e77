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
from dataclasses import dataclass, field
from typing import Iterable

import numpy as np

from . import _kernels
from ._sundials import OdeSolution, integrate
from ._validation import positive
from .params import InitialState, Protocol, SolverOptions, SpringSlider
from .results import STATUS_MESSAGES, CycleResult, Event, Status, SweepResult, Trajectory

__all__ = ["simulate", "limit_cycle", "sweep"]

logger = logging.getLogger(__name__)

_THETA_FLOOR = 1e-250   # smallest theta resolved, in units of Dc (slips level off below)
_ZERO_PHASES = 20       # consecutive zero-length phases before giving up
_TAU_CHUNK = 1e4        # length of one CVODE run in the slide time tau (and in units of
                        # the natural time scale for the a > 0 ODE)


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

    def add(self, t, x, sigma, theta, v) -> None:
        self.t.append(np.atleast_1d(np.asarray(t, dtype=float)))
        n = self.t[-1].size
        for name, val in (("x", x), ("sigma", sigma), ("theta", theta), ("v", v)):
            getattr(self, name).append(np.broadcast_to(np.asarray(val, dtype=float), (n,)).copy())

    def arrays(self) -> tuple[np.ndarray, ...]:
        if not self.t:
            return tuple(np.empty(0) for _ in range(5))
        return tuple(np.concatenate(getattr(self, name)) for name in ("t", "x", "sigma", "theta", "v"))


# ======================================================================================
# a = 0: stick, slide and slip
# ======================================================================================
class _PhaseEngine:
    """Event-driven integration of the a = 0 model (one phase per :meth:`step`)."""

    def __init__(self, model: SpringSlider, protocol: Protocol, options: SolverOptions,
                 record: bool, stop_at_steady: bool) -> None:
        self.model = model
        self.protocol = protocol
        self.options = options
        self.record = record
        self.stop_at_steady = stop_at_steady
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
        if self.record:
            self.samples.add(self.t, self.x, self.mu_ref + self.sigma, self.theta, v)

    def decide(self) -> int:
        return int(self.k.decide(self.p, self.theta, self.K, self.velocity(), self.Dc))

    def start(self, initial: InitialState) -> None:
        V0 = float(self.protocol.velocities[0])
        if initial.theta is not None:
            theta = initial.theta
        elif V0 > 0.0:
            theta = self.Dc / V0 * (1.0 + initial.perturbation)
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
        return ev

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
        if self.record and dt > 0.0:
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

    def _integrate_chunks(self, rhs, events, atol) -> OdeSolution:
        """CVODE over the slide in chunks of tau (CVODE ties its smallest step to the
        output time, so an open-ended output time is not an option)."""
        opts = self.options
        y0 = np.zeros(3)
        tau0 = 0.0
        ts, ys, evs = [], [], []
        nfev = 0
        for _ in range(100000):
            sol = integrate(rhs, y0, tau0, tau0 + _TAU_CHUNK, events=events,
                            terminal=(True, True, True, False, True), direction=(-1, -1, -1, 0, 1),
                            rtol=opts.rtol, atol=atol, method=opts.method,
                            max_num_steps=opts.max_num_steps, save_steps=self.record)
            nfev += sol.nfev
            if not sol.success:
                raise _Stop(Status.SOLVER_FAILED, f"CVODE in a slide at t = {self.t:g}: {sol.message}")
            ts.append(sol.t if not ts else sol.t[1:])
            ys.append(sol.y if not ys else sol.y[1:])
            evs.extend(sol.events)
            if sol.terminal_event is not None:
                sol.t = np.concatenate(ts)
                sol.y = np.concatenate(ys)
                sol.events = evs
                sol.nfev = nfev
                return sol
            tau0 = float(sol.t[-1])
            y0 = sol.y[-1].copy()
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
        sol = self._integrate_chunks(rhs, events, atol)
        t0 = self.t
        x_lp0 = self.load_point(t0)
        if self.record:
            ys = sol.y[1:]
            theta_arr = theta_s * np.exp(ys[:, 0])
            u_arr = self.Dc / theta_arr
            mu_arr = np.array([law(u, p)[0] for u in u_arr])
            w_arr = np.array([law(u, p)[1] for u in u_arr])
            d_arr = self.K - w_arr
            with np.errstate(divide="ignore", invalid="ignore"):
                v_arr = (self.K * V - u_arr * w_arr) / d_arr
            v_arr[d_arr <= 0.0] = np.inf     # the slide ends where v diverges (D = 0)
            t_arr = t0 + ys[:, 1]
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
    """CVODE (BDF) on ``y = [ln v, ln(theta/Dc), x, int (sigma - mu_ref) dt, t]`` for a > 0,
    in the slip-regularised variable s of :func:`rsf._kernels.rs_rhs`."""

    def __init__(self, model: SpringSlider, protocol: Protocol, options: SolverOptions,
                 record: bool, stop_at_steady: bool) -> None:
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
        self.y = np.zeros(5)
        self.nfev = 0
        self.at_root = False       # the state sits on an event root (after a terminal event)

    @property
    def t(self) -> float:
        return float(self.y[4])

    @property
    def integral(self) -> float:
        """Running integral of the absolute sigma dt."""
        return float(self.y[3]) + self.mu_ref * float(self.y[4])

    def sigma_of(self, y: np.ndarray) -> float:
        u = math.exp(-y[1])
        return self.mu_ref + float(self.law_fn(u, self.p)[0]) + self.model.a * (y[0] + y[1])

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
            theta = m.Dc / V0 * (1.0 + initial.perturbation)
        else:
            raise ValueError("initial.theta is required when the driving starts with V = 0")
        u = m.Dc / theta
        if initial.sigma is None:
            if V0 <= 0.0:
                raise ValueError("initial.sigma is required when the driving starts with V = 0")
            lv = math.log(V0)
        else:
            lv = math.log(u) + (initial.sigma - self.mu_ref - float(self.law_fn(u, self.p)[0])) / m.a
        self.y = np.array([lv, math.log(theta / m.Dc), 0.0, 0.0, 0.0])
        self.y[2] = self.protocol.load_point(0.0) - self.sigma_of(self.y) / m.k0
        self.at_root = True        # v = V is a root of the extremum events
        if self.record:
            self._record(self.y[None, :])
        self.emit("start")

    def set_state(self, lv: float, q: float) -> None:
        """Restart at (ln v, q) (used by the cycle extrapolation); x follows the spring."""
        self.y = np.array([lv, q, 0.0, self.y[3], self.y[4]])
        self.y[2] = self.protocol.load_point(self.t) - self.sigma_of(self.y) / self.model.k0
        self.at_root = True
        self.emit("restart")

    def _record(self, y: np.ndarray) -> None:
        m = self.model
        u = np.exp(-y[:, 1])
        mu = np.array([self.law_fn(ui, self.p)[0] for ui in u])
        with np.errstate(over="ignore"):
            v = np.exp(y[:, 0])
        self.samples.add(y[:, 4], y[:, 2], self.mu_ref + mu + m.a * (y[:, 0] + y[:, 1]),
                         m.Dc * np.exp(y[:, 1]), v)

    def step(self, t_end: float, stop_on_min: bool) -> Event:
        m = self.model
        opts = self.options
        t_now = self.t
        V = self.protocol.velocity_at(t_now)
        t_stop = min(self.protocol.segment_end(t_now), t_end)
        lnV = math.log(V) if V > 0.0 else 0.0
        q_ss = -lnV
        w_ss = float(self.law_fn(V, self.p)[1]) if V > 0.0 else 0.0
        steady_on = 1.0 if (self.stop_at_steady and V > 0.0 and m.K - w_ss > 0.0) else 0.0
        if steady_on and abs(self.y[0] - lnV) + abs(self.y[1] - q_ss) <= opts.cycle_rtol:
            return self.emit("steady")
        vs = V if V > 0.0 else max(math.exp(-self.y[1]), 1e-300)
        lvs = math.log(vs)
        c = np.array([m.K, V, m.Dc, m.a, 0.0 if m.state_law == "aging" else 1.0, vs,
                      lnV - lvs if V > 0.0 else 0.0, lvs - lnV if V > 0.0 else 0.0,
                      opts.cycle_rtol, steady_on, t_stop if math.isfinite(t_stop) else 1e300])
        k, p = self.k, self.p

        def rhs(s, y, yp):
            k.rs_rhs(y, yp, p, c)

        def events(s, y, e):
            k.rs_events(y, e, p, c)

        def to_local(y: np.ndarray) -> np.ndarray:      # [ln v, q, ...] -> [w, r, ...]
            out = y.copy()
            out[0] = y[0] - lvs
            out[1] = y[1] + lvs
            return out

        def to_global(y: np.ndarray) -> np.ndarray:
            out = np.array(y, dtype=float, copy=True)
            out[..., 0] += lvs
            out[..., 1] -= lvs
            return out

        t_scale = m.Dc / vs
        atol = np.array([opts.atol, opts.atol, opts.atol * m.Dc,
                         opts.atol * t_scale * max(1.0, abs(self.sigma_of(self.y) - self.mu_ref)),
                         opts.atol * t_scale])
        y_loc = to_local(self.y)
        if self.at_root:
            # step off an event root without events (CVODE rejects a root at the start)
            sol = integrate(rhs, y_loc, 0.0, 1e-6, rtol=opts.rtol, atol=atol, method="BDF",
                            max_num_steps=opts.max_num_steps)
            if not sol.success:
                raise _Stop(Status.SOLVER_FAILED, f"CVODE at t = {self.t:g}: {sol.message}")
            y_loc = sol.y[-1].copy()
            self.at_root = False
        s0 = 0.0
        for _ in range(100000):
            sol = integrate(rhs, y_loc, s0, s0 + _TAU_CHUNK, events=events,
                            terminal=(False, stop_on_min, True, True), direction=(1, -1, -1, 1),
                            rtol=opts.rtol, atol=atol, method="BDF",
                            max_num_steps=opts.max_num_steps, save_steps=self.record)
            self.nfev += sol.nfev
            if not sol.success:
                raise _Stop(Status.SOLVER_FAILED, f"CVODE at t = {self.t:g}: {sol.message}")
            if self.record:
                self._record(to_global(sol.y[1:]))
            for (_s, y_ev, idx, _sign) in sol.events:
                if idx == 0:
                    self.emit("sigma_max", to_global(y_ev))
                elif idx == 1 and not stop_on_min:
                    self.emit("sigma_min", to_global(y_ev))
            s0 = float(sol.t[-1])
            y_loc = sol.y[-1].copy()
            self.y = to_global(y_loc)
            if sol.terminal_event is not None:
                break
        else:
            raise _Stop(Status.SOLVER_FAILED, f"no progress at t = {self.t:g}")
        if sol.terminal_event == 1:
            self.at_root = True
            return self.emit("sigma_min")
        if sol.terminal_event == 2:
            return self.emit("steady")
        # terminal_event == 3: end of the window or a change of driving
        self.y[4] = t_stop
        self.at_root = True
        if t_stop >= t_end:
            return self.emit("end")
        return self.emit("drive")


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
             options: SolverOptions | None = None, stop_at_steady: bool = False) -> Trajectory:
    r"""Integrate the spring-slider from ``t = 0`` to ``t_end`` and return the time series.

    Parameters
    ----------
    model : SpringSlider
        The slider and its friction law.
    V : float, optional
        Constant load-point velocity (> 0); or give ``protocol``.
    t_end : float
        End time, > 0.
    protocol : Protocol, optional
        Piecewise-constant driving (velocity steps, slide-hold-slide).
    initial : InitialState, optional
        Default: the steady state at the first velocity, theta perturbed by 1e-3.
    options : SolverOptions, optional
    stop_at_steady : bool
        End the run as soon as a stable steady slide is reached (status ``STEADY``).

    Returns
    -------
    Trajectory
        ``t, x, sigma, theta, v`` samples, the events (time, kind, sigma, theta, x) and the
        status.  A slip appears as two samples at one instant.
    """
    if not isinstance(model, SpringSlider):
        raise ValueError(f"model must be an rsf.SpringSlider, got {model!r}")
    t_end = positive("t_end", t_end)
    protocol = _protocol_from(V, protocol)
    initial = initial or InitialState()
    options = options or SolverOptions()
    engine_cls = _PhaseEngine if model.a == 0.0 else _SmoothEngine
    engine = engine_cls(model, protocol, options, record=True, stop_at_steady=stop_at_steady)
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
    return Trajectory(t=t, x=x, sigma=sigma, theta=theta, v=v, events=engine.events,
                      status=status, message=message, params=model.describe())


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
    out = 0.0
    for x, y in ((a.sigma_max, b.sigma_max), (a.sigma_min, b.sigma_min), (a.period, b.period)):
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
    initial = initial or InitialState()
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
                    break
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
