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
    moves backwards).  The segments follow one another from t = 0; :meth:`uniform`,
    :meth:`slide_hold_slide` and :meth:`schedule` build the usual ones, and
    :func:`micro.simulate` runs any.

    Parameters
    ----------
    segments : iterable of (float, float)
        The ``(duration, velocity)`` of each segment, in order; kept as a tuple of float
        pairs.

    Raises
    ------
    ValueError
        If ``segments`` is empty, or a duration is not a finite number > 0 or a velocity
        not a finite number >= 0 (the message names the segment).

    Examples
    --------
    >>> from micro import Drive
    >>> drive = Drive.slide_hold_slide(1.0, slide=50.0, hold=10.0, resume=20.0)
    >>> drive.duration, drive.boundaries()[1]
    (80.0, (50.0, 60.0, 0.0))
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
        """Drive at constant ``velocity`` for ``duration``: ``w = V t``.

        Parameters
        ----------
        velocity : float
            The drive velocity V, finite and >= 0.
        duration : float
            How long, finite and > 0.

        Returns
        -------
        Drive
            One segment, ``(duration, velocity)``.

        Raises
        ------
        ValueError
            If ``velocity`` or ``duration`` is out of range (as :class:`Drive`).
        """
        return cls(((duration, velocity),))

    @classmethod
    def schedule(cls, segments: Iterable[tuple[float, float]]) -> "Drive":
        """Any piecewise-constant schedule of ``(duration, velocity)`` pairs.

        Parameters
        ----------
        segments : iterable of (float, float)
            The ``(duration, velocity)`` of each segment, in order.

        Returns
        -------
        Drive
            The schedule, ``Drive(tuple(segments))``.

        Raises
        ------
        ValueError
            As :class:`Drive`.
        """
        return cls(tuple(segments))

    @classmethod
    def slide_hold_slide(cls, velocity: float, slide: float, hold: float, resume: float) -> "Drive":
        """Drive at ``velocity`` for ``slide``, stop for ``hold``, drive again for ``resume``.

        Parameters
        ----------
        velocity : float
            The drive velocity of both slides, finite and >= 0.
        slide, hold, resume : float
            The durations of the first slide, the hold (velocity 0) and the second
            slide, each finite and > 0.

        Returns
        -------
        Drive
            Three segments: ``(slide, velocity), (hold, 0), (resume, velocity)``.

        Raises
        ------
        ValueError
            If a duration or the velocity is out of range (as :class:`Drive`).

        See Also
        --------
        micro.slide_hold_slide : the peak stress after each of several holds, from
            steady sliding.
        """
        return cls(((slide, velocity), (hold, 0.0), (resume, velocity)))

    @property
    def duration(self) -> float:
        """The total duration, the sum of the segments' durations."""
        return sum(d for d, _ in self.segments)

    def boundaries(self) -> list[tuple[float, float, float]]:
        """``(t_start, t_end, velocity)`` of each segment."""
        out = []
        t = 0.0
        for d, v in self.segments:
            out.append((t, t + d, v))
            t += d
        return out
