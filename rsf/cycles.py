r"""The limit-cycle search behind :func:`rsf.limit_cycle`: cycles cut at an anchor event,
the convergence test between consecutive cycles, and the Aitken extrapolation of the
cycle map.

A cycle runs from one anchor to the next: a slip landing (``'slip->...'``; with no slips
after 200 events, ``'slide->stick'``) for the a = 0 engine, a minimum of :math:`\sigma`
for the a > 0 engine.  It has converged when :math:`\sigma_{max}`, :math:`\sigma_{min}`,
the period and the amplitude of two consecutive simulated cycles with the same sequence
of events differ by less than ``cycle_rtol`` (relative).  Two equal "cycles" of period 0
or of no amplitude are not a limit cycle: the status is then ``DEGENERATE``.
"""
from __future__ import annotations

import logging
import math
from dataclasses import dataclass, field

from . import _progress
from .engines import Engine, Stop
from .params import SolverOptions
from .results import Event, Status

__all__ = ["Cycle", "CycleSearch", "relative_change"]

logger = logging.getLogger("rsf.solver")    # the logger limit_cycle has always used

_FALLBACK_EVENTS = 200   # events with no slip after which cycles are anchored at slide->stick


@dataclass
class Cycle:
    """One simulated cycle."""

    sigma_max: float
    sigma_min: float
    period: float
    mean: float
    sequence: tuple[str, ...]
    section: float          # the variable of the cycle map at its end
    events: list[Event]


def relative_change(a: Cycle, b: Cycle) -> float:
    """Largest relative change of sigma_max, sigma_min, the period and the amplitude
    sigma_max - sigma_min (the amplitude: so that a slowly decaying oscillation of small
    amplitude is not taken for a converged cycle)."""
    out = 0.0
    for x, y in ((a.sigma_max, b.sigma_max), (a.sigma_min, b.sigma_min), (a.period, b.period),
                 (a.sigma_max - a.sigma_min, b.sigma_max - b.sigma_min)):
        scale = max(abs(x), abs(y), 1e-300)
        out = max(out, abs(x - y) / scale)
    return out


@dataclass
class _Anchor:
    t: float
    integral: float
    section: float
    index: int              # of its event in engine.events
    sigma: float


@dataclass
class CycleSearch:
    """Run ``engine`` (started, at constant velocity ``V``) until the motion is steady or
    a cycle has converged: :meth:`run` sets ``status`` (and ``detail``), ``cycles``,
    ``result`` (the cycle reported) and ``relative_change``."""

    engine: Engine
    V: float
    options: SolverOptions
    smooth: bool                    # the a > 0 engine: cycles from one minimum to the next
    progress_every: int = 1000      # log the progress (INFO) every this many cycles
    status: int = Status.MAX_CYCLES
    detail: str = ""
    cycles: list[Cycle] = field(default_factory=list)
    result: Cycle | None = None
    relative_change: float = math.nan

    def run(self) -> CycleSearch:
        try:
            self._search()
        except Stop as stop:
            self.status, self.detail = stop.status, stop.detail
            if self.cycles:
                self.result = self.cycles[-1]
        return self

    def _search(self) -> None:
        engine, options = self.engine, self.options
        anchor: _Anchor | None = None
        since_restart = 0       # cycles since the last extrapolation
        sections: list[float] = []
        n_events = 0
        fallback = False        # no slips: cycles of stick and slide only
        while True:
            ev = engine.step(math.inf, stop_on_min=True)
            n_events += 1
            _progress.beat()
            if n_events > options.max_events:
                self.status = Status.MAX_EVENTS
                return
            if ev.kind == "steady":
                self.status = Status.STEADY
                return
            if self.smooth:
                is_anchor = ev.kind == "sigma_min"
            elif not fallback:
                is_anchor = ev.kind.startswith("slip->")
                if anchor is None and n_events > _FALLBACK_EVENTS and not any(
                        e.kind.startswith("slip->") for e in engine.events[-_FALLBACK_EVENTS:]):
                    fallback = True
            else:
                is_anchor = ev.kind == "slide->stick"
            if not is_anchor:
                continue
            now = self._anchor_here()
            if anchor is not None:
                self.cycles.append(self._cycle(anchor, now))
                since_restart += 1
                if self._done(since_restart):
                    return
            sections.append(now.section)
            if (options.accelerate and since_restart >= 2 and len(sections) >= 3
                    and self.cycles[-1].sequence == self.cycles[-2].sequence):
                target = _aitken(sections[-3:])
                if target is not None:
                    engine.restart_at_section(target)
                    since_restart = 0
                    sections = [target]
                    now = self._anchor_here()
            anchor = now

    def _anchor_here(self) -> _Anchor:
        e = self.engine
        index = len(e.events) - 1
        return _Anchor(e.t, e.integral, e.section(), index, e.events[index].sigma)

    def _cycle(self, start: _Anchor, end: _Anchor) -> Cycle:
        evs = self.engine.events[start.index + 1: end.index + 1]
        sig = [start.sigma] + [e.sigma for e in evs]
        period = end.t - start.t
        return Cycle(max(sig), min(sig), period,
                     (end.integral - start.integral) / period if period > 0 else math.nan,
                     tuple(e.kind for e in evs), end.section, evs)

    def _done(self, since_restart: int) -> bool:
        """After a new cycle: converged, or out of cycles (and log the progress)."""
        cycles, options = self.cycles, self.options
        if len(cycles) >= 2 and since_restart >= 2:
            prev, last = cycles[-2], cycles[-1]
            if prev.sequence == last.sequence:
                self.relative_change = relative_change(prev, last)
                if self.relative_change <= options.cycle_rtol:
                    self.status = Status.CONVERGED
                    self.result = last
                    if not (last.period > 0.0 and last.sigma_max > last.sigma_min):
                        # two equal cycles, but no cycle: no time passed or no stress moved
                        self.status = Status.DEGENERATE
                        self.detail = (f"period {last.period:g}, sigma_max - sigma_min = "
                                       f"{last.sigma_max - last.sigma_min:g}, sequence "
                                       f"{' '.join(last.sequence)}: the motion is not resolved "
                                       f"in double precision")
                    return True
        if len(cycles) > options.max_cycles:
            self.status = Status.MAX_CYCLES
            self.result = cycles[-1]
            if len(cycles) >= 2:
                self.relative_change = relative_change(cycles[-2], cycles[-1])
            self.detail = (f"{options.max_cycles} cycles; the last relative change "
                           f"{self.relative_change:.3g} against cycle_rtol {options.cycle_rtol:.3g}")
            return True
        if len(cycles) % self.progress_every == 0:     # progress within a slow search
            logger.info("limit_cycle(V=%g): %d of at most %d cycles, relative change %.3g "
                        "(converged below %.3g)", self.V, len(cycles), options.max_cycles,
                        relative_change(cycles[-2], cycles[-1]), options.cycle_rtol)
        return False


def _aitken(sections: list[float]) -> float | None:
    """The Aitken extrapolation of the map section -> next section from its last three
    values, or None where the map is not a contraction to extrapolate safely."""
    x0, x1, x2 = sections
    d1, d2 = x1 - x0, x2 - x1
    if d1 != 0.0 and abs(d2) > 1e-12 * max(1.0, abs(x2)):
        lam = d2 / d1
        if 0.02 < abs(lam) < 0.9999:
            jump = max(-2.0, min(2.0, lam * d2 / (1.0 - lam)))
            return x2 + jump
    return None
