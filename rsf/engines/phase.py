r"""The a = 0 engine: stick, slide and instantaneous slip, one phase per step.

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
"""
from __future__ import annotations

import math
from enum import IntEnum
from typing import NamedTuple

import numpy as np

from .. import _kernels, _sundials
from .._sundials import OdeSolution
from ..params import THETA_FLOOR, InitialState, Protocol, SolverOptions, SpringSlider
from ..results import Event, Status
from .base import TAU_CHUNK, Engine, Stop, compiled, cvode_arrays, logger, onto_time

__all__ = ["PhaseEngine", "SlideConstants", "SlideEvent", "chunk_span"]

ZERO_PHASES = 20        # consecutive zero-length phases before giving up
CHUNK_GROWTH = 30       # the runs of one slide double in length, up to 2**30 TAU_CHUNK, so
                        # that a long steady slide takes tens of runs, not millions (the a > 0
                        # engine follows a steady state it has reached in closed form instead)


def chunk_span(chunk: int) -> float:
    """The length in tau of the ``chunk``-th CVODE run (from 0) of one slide:
    ``TAU_CHUNK``, then doubling.  CVODE ties its smallest step to the output time, so an
    open-ended run is not an option, but a settled slide lasts as long as the driving."""
    return TAU_CHUNK * 2.0 ** min(chunk, CHUNK_GROWTH)


class SlideConstants(NamedTuple):
    """The constants of one slide, in the order of the array ``c`` that
    :func:`rsf._kernels.slide_rhs` and :func:`rsf._kernels.slide_events` read."""

    K: float            # k0 Dc
    V: float            # driving velocity
    Dc: float
    vs: float           # velocity scale of tau: max(V, u_s)
    u_s: float          # Dc / theta at the start of the slide
    s_tol: float        # |ln(u/V)| at which the slide is steady (cycle_rtol)
    t_span: float       # time to the end of the driving segment (1e300: none)
    ln_V: float
    steady_on: float    # 1: stop at a stable steady slide
    extrema_on: float   # 1: report the interior extrema of sigma (W changes sign)

    def array(self) -> np.ndarray:
        return np.array(self, dtype=float)


class SlideEvent(IntEnum):
    """The events of a slide (:func:`rsf._kernels.slide_events`), by index."""

    SLIP = 0            # D = 0: the slide turns into a slip
    STICK = 1           # N = 0: v falls to 0
    STEADY = 2          # within s_tol of the stable steady slide
    EXTREMUM = 3        # W = 0: an interior extremum of sigma (not terminal)
    SEGMENT_END = 4     # the end of the driving segment or of the run
    OUTPUT = 5          # a t_eval time (added by rsf._sundials.integrate_outputs)


_TERMINAL = (True, True, True, False, True)
_DIRECTION = (-1, -1, -1, 0, 1)


class PhaseEngine(Engine):
    """Event-driven integration of the a = 0 model (one phase per :meth:`step`)."""

    def __init__(self, model: SpringSlider, protocol: Protocol, options: SolverOptions,
                 record: bool, stop_at_steady: bool, t_eval: np.ndarray | None = None) -> None:
        super().__init__(model, protocol, options, record, stop_at_steady, t_eval)
        self.k0 = model.k0
        self.Dc = model.Dc
        self.K = model.K
        w_lo, w_hi = model.law.weakening_bounds()
        self.w_neg = max(0.0, -w_lo)
        self.lipschitz = self.K + max(abs(w_lo), abs(w_hi)) + 1e-300
        self.extrema_on = 1.0 if (w_lo < 0.0 < w_hi) else 0.0
        self.concave_sup = model.law.concave_sup
        self._slide_kernels = None
        self.t = 0.0
        self.x = 0.0
        self.sigma = 0.0        # relative to mu_ref (see _kernels)
        self.theta = 1.0
        self.integral = 0.0     # running integral of the (absolute) sigma dt
        self.phase = _kernels.STICK
        self.zero_phases = 0

    # -- helpers ------------------------------------------------------------------------
    def phi(self, theta: float) -> float:
        """Threshold phi(theta) relative to mu_ref."""
        return float(self.law_fn(self.Dc / theta, self.p)[0])

    def velocity(self) -> float:
        return self.protocol.velocity_at(self.t)

    def load_point(self, t: float) -> float:
        return self.protocol.load_point(t)

    def emit(self, kind: str) -> Event:
        return self.add_event(Event(self.t, kind, self.mu_ref + self.sigma, self.theta, self.x))

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
        theta = self.initial_theta(initial)
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

    # -- the limit-cycle search ---------------------------------------------------------
    def section(self) -> float:
        """The variable of the cycle map: ln theta."""
        return math.log(self.theta)

    def restart_at_section(self, value: float) -> None:
        self.set_on_threshold(math.exp(value))

    # -- phases -------------------------------------------------------------------------
    def step(self, t_end: float, stop_on_min: bool = False) -> Event:
        """Run the current phase to its end; return the event that ends it.
        (``stop_on_min`` is for the a > 0 engine: here a cycle is anchored at the slips.)"""
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
            if self.zero_phases > ZERO_PHASES:
                raise Stop(Status.DEGENERATE, f"at t = {self.t:g}, theta = {self.theta:g}")
        else:
            self.zero_phases = 0

    def _stick(self, t_end: float) -> Event:
        V = self.velocity()
        horizon = self.segment_stop(t_end) - self.t
        phi0 = self.phi(self.theta)
        h0 = self.sigma - phi0
        if abs(h0) <= 1e-14 * max(1.0, abs(phi0)):
            h0 = 0.0
        dt, flag = self.k.stick_end(self.p, h0, self.theta, self.k0 * V, self.Dc,
                                    horizon, self.w_neg, self.concave_sup)
        if flag == _kernels.FAILED:
            raise Stop(Status.SOLVER_FAILED, f"stick-end search failed at t = {self.t:g}")
        sigma_new = self.sigma + self.k0 * V * dt
        if self.record and self.t_eval is not None:
            tt = self.take_pending(self.t + dt, inclusive=True)     # closed form: exact samples
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
        floor = THETA_FLOOR * self.Dc
        s, flag = self.k.slip_end(self.p, g0, self.theta, self.K, self.Dc,
                                  self.lipschitz, floor)
        if flag == _kernels.HORIZON:
            raise Stop(Status.RUNAWAY, f"at t = {self.t:g}, theta = {self.theta:g}")
        if flag == _kernels.FAILED:
            raise Stop(Status.SOLVER_FAILED, f"slip-end search failed at t = {self.t:g}")
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

    # -- the slide ----------------------------------------------------------------------
    def slide_kernels(self):
        """The right-hand side and event kernels of a slide, compiled for the arrays CVODE
        passes (found at the first slide: many runs of the paper's model never slide)."""
        if self._slide_kernels is None:
            y, out = cvode_arrays(3)
            c = np.zeros(len(SlideConstants._fields))
            self._slide_kernels = (compiled(self.k.slide_rhs, y, out, self.p, c),
                                   compiled(self.k.slide_events, y, np.zeros(len(_TERMINAL)),
                                            self.p, c))
        return self._slide_kernels

    def _integrate_chunks(self, rhs, events, atol, out_times=None) -> OdeSolution:
        """CVODE over the slide in chunks of tau (CVODE ties its smallest step to the
        output time, so an open-ended output time is not an option).  ``out_times``
        (slide-local times): also stop at those (output events, ``SlideEvent.OUTPUT``)."""
        opts = self.options
        y0 = np.zeros(3)
        tau0 = 0.0
        ts, ys, evs = [], [], []
        nfev = 0
        for chunk in range(100000):
            span = chunk_span(chunk)
            save_steps = self.record and self.t_eval is None
            if (out_times is not None and out_times.size) or save_steps:
                sol = _sundials.integrate_outputs(
                    rhs, y0, tau0, tau0 + span, out_index=1, out_times=out_times, events=events,
                    terminal=_TERMINAL, direction=_DIRECTION, rtol=opts.rtol, atol=atol,
                    method=opts.method, max_num_steps=opts.max_num_steps, save_steps=save_steps)
                n_found = sum(1 for ev in sol.events if ev[2] == SlideEvent.OUTPUT)
                if out_times is not None:
                    out_times = out_times[n_found:]
            else:
                sol = _sundials.integrate(rhs, y0, tau0, tau0 + span, events=events,
                                          terminal=_TERMINAL, direction=_DIRECTION,
                                          rtol=opts.rtol, atol=atol, method=opts.method,
                                          max_num_steps=opts.max_num_steps)
            nfev += sol.nfev
            self.charge(sol.nfev)
            if not sol.success:
                t_fail = self.t + float(sol.y[-1][1]) if np.all(np.isfinite(sol.y[-1])) else self.t
                raise Stop(Status.SOLVER_FAILED, f"CVODE in a slide at t = {t_fail:.10g}: "
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
        raise Stop(Status.SOLVER_FAILED, f"slide at t = {self.t:g} did not end")

    def _slide(self, t_end: float) -> Event:
        V = self.velocity()
        opts = self.options
        t_stop = self.segment_stop(t_end)
        theta_s = self.theta
        u_s = self.Dc / theta_s
        vs = max(V, u_s)
        steady_on = 0.0
        lnV = 0.0
        if V > 0.0:
            lnV = math.log(V)
            w_ss = float(self.law_fn(V, self.p)[1])
            if self.stop_at_steady and self.K - w_ss > 0.0:
                steady_on = 1.0
                if abs(math.log(u_s) - lnV) <= opts.cycle_rtol or (
                        t_stop == math.inf and self.k.slide_converges(self.p, u_s, V, self.K)):
                    # already steady, or certain to converge to it with no switch on the way
                    return self.emit("steady")
        c = SlideConstants(K=self.K, V=V, Dc=self.Dc, vs=vs, u_s=u_s, s_tol=opts.cycle_rtol,
                           t_span=t_stop - self.t if math.isfinite(t_stop) else 1e300,
                           ln_V=lnV, steady_on=steady_on, extrema_on=self.extrema_on).array()
        p = self.p
        slide_rhs, slide_events = self.slide_kernels()

        def rhs(tau, y, yp):
            slide_rhs(y, yp, p, c)

        def events(tau, y, e):
            slide_events(y, e, p, c)

        t_scale = self.Dc / vs
        atol = np.array([opts.atol, opts.atol * t_scale, opts.atol * t_scale * max(1.0, abs(self.sigma))])
        t0 = self.t
        out_times = None
        if self.record and self.t_eval is not None:
            out_times = np.ascontiguousarray(self.pending(t_stop, inclusive=True) - t0)
            out_times = out_times[out_times > 0.0]
        sol = self._integrate_chunks(rhs, events, atol, out_times)
        x_lp0 = self.load_point(t0)
        if self.record:
            self._record_slide(sol, rhs, theta_s, t0, x_lp0, V, out_times)
        for (_tau, y, idx, _sign) in sol.events:
            if idx == SlideEvent.EXTREMUM:   # interior extremum of sigma (W = 0)
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
        if which == SlideEvent.SLIP:
            self.phase = _kernels.SLIP
            return self.emit("slide->slip")
        if which == SlideEvent.STICK:
            self.phase = _kernels.STICK
            return self.emit("slide->stick")
        if which == SlideEvent.STEADY:
            return self.emit("steady")
        # SEGMENT_END: the end of the time window or a change of driving
        if self.t >= t_end * (1.0 - 1e-15):
            self.t = t_end
            return self.emit("end")
        self.t = t_stop
        return self._drive_change()

    def _record_slide(self, sol: OdeSolution, rhs, theta_s: float, t0: float, x_lp0: float,
                      V: float, out_times: np.ndarray | None) -> None:
        """The samples of a slide: every internal step, or the t_eval times (the output
        events, moved exactly onto the requested times)."""
        law, p = self.law_compiled, self.p
        if self.t_eval is None:
            ys = sol.y[1:]
        else:
            found = []
            for (_tau, y, idx, _sign) in sol.events:
                if idx == SlideEvent.OUTPUT:
                    found.append(onto_time(rhs, y, float(out_times[len(found)]), 1))
            ys = np.array(found).reshape(-1, 3)
            t_exact = self.t_eval[self.next_out:self.next_out + ys.shape[0]]
            self.next_out += ys.shape[0]
        theta_arr = theta_s * np.exp(ys[:, 0])
        u_arr = self.Dc / theta_arr
        mu_w = [law(u, p) for u in u_arr]
        mu_arr = np.array([mu for mu, _ in mu_w])
        w_arr = np.array([w for _, w in mu_w])
        d_arr = self.K - w_arr
        with np.errstate(divide="ignore", invalid="ignore"):
            v_arr = (self.K * V - u_arr * w_arr) / d_arr
        v_arr[d_arr <= 0.0] = np.inf     # the slide ends where v diverges (D = 0)
        t_arr = t0 + ys[:, 1] if self.t_eval is None else t_exact
        self.samples.add(t_arr, x_lp0 + V * ys[:, 1] - (self.mu_ref + mu_arr) / self.k0,
                         self.mu_ref + mu_arr, theta_arr, v_arr)
