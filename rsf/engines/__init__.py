"""The two integration engines behind :func:`rsf.simulate` and :func:`rsf.limit_cycle`.

* :mod:`~rsf.engines.base`: what both share -- the constructor, the samples and events,
  the output at requested times, the stop with a status, the count of right-hand-side
  evaluations against the step budget;
* :mod:`~rsf.engines.phase`: the a = 0 model, one phase (stick, slide, slip) per step;
* :mod:`~rsf.engines.smooth`: the a > 0 model, the regular rate-and-state ODE.
"""
from __future__ import annotations

from ..params import Protocol, SolverOptions, SpringSlider
from .base import Engine, Samples, Stop
from .phase import PhaseEngine
from .smooth import SmoothEngine

__all__ = ["Engine", "PhaseEngine", "SmoothEngine", "Samples", "Stop", "make_engine"]


def make_engine(model: SpringSlider, protocol: Protocol, options: SolverOptions, *, record: bool,
                stop_at_steady: bool, t_eval=None) -> Engine:
    """The engine for ``model``: :class:`PhaseEngine` for a = 0, :class:`SmoothEngine`
    for a > 0."""
    cls = PhaseEngine if model.a == 0.0 else SmoothEngine
    return cls(model, protocol, options, record=record, stop_at_steady=stop_at_steady,
               t_eval=t_eval)
