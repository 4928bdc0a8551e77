"""Driving protocols: piecewise-constant schedules of the drive velocity.

Uniform driving ``w = V t`` is one segment; slide-hold-slide is drive at V, hold
(V = 0), drive at V again.  A schedule is a tuple of ``(duration, velocity)`` segments.
"""
from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Iterable

__all__ = ["Drive"]


@dataclass(frozen=True)
class Drive:
    """A piecewise-constant drive velocity: ``segments`` of ``(duration, velocity)``.

    Durations must be finite and > 0, velocities finite and >= 0 (the drive never
    moves backwards).
    """

    segments: tuple[tuple[float, float], ...]

    def __post_init__(self) -> None:
        segs = tuple((float(d), float(v)) for d, v in self.segments)
        if not segs:
            raise ValueError("segments must hold at least one (duration, velocity) pair")
        for i, (d, v) in enumerate(segs):
            if not (math.isfinite(d) and d > 0.0):
                raise ValueError(f"segment {i}: duration must be a finite number > 0, got {d!r}")
            if not (math.isfinite(v) and v >= 0.0):
                raise ValueError(f"segment {i}: velocity must be a finite number >= 0, got {v!r}")
        object.__setattr__(self, "segments", segs)

    @classmethod
    def uniform(cls, velocity: float, duration: float) -> "Drive":
        """Drive at constant ``velocity`` for ``duration``: ``w = V t``."""
        return cls(((duration, velocity),))

    @classmethod
    def schedule(cls, segments: Iterable[tuple[float, float]]) -> "Drive":
        """Any piecewise-constant schedule of ``(duration, velocity)`` pairs."""
        return cls(tuple(segments))

    @classmethod
    def slide_hold_slide(cls, velocity: float, slide: float, hold: float, resume: float) -> "Drive":
        """Drive at ``velocity`` for ``slide``, stop for ``hold``, drive again for ``resume``."""
        return cls(((slide, velocity), (hold, 0.0), (resume, velocity)))

    @property
    def duration(self) -> float:
        return sum(d for d, _ in self.segments)

    def boundaries(self) -> list[tuple[float, float, float]]:
        """``(t_start, t_end, velocity)`` of each segment."""
        out = []
        t = 0.0
        for d, v in self.segments:
            out.append((t, t + d, v))
            t += d
        return out
