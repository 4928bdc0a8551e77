"""Result objects: named fields, a status with a message, and ``to_frame()``.

Status codes (``STATUS_MESSAGES``): non-negative values are successes, negative values
failures.  A limit-cycle search never ends silently unconverged: it reports
``MAX_CYCLES`` (or another negative status) and ``converged = False``.
"""
from __future__ import annotations

import math
import os
from dataclasses import asdict, dataclass, field
from pathlib import Path
from typing import Any, Callable

import numpy as np
import pandas as pd

from . import _outputs

__all__ = [
    "STATUS_MESSAGES",
    "Status",
    "Event",
    "Trajectory",
    "CycleResult",
    "SweepResult",
    "write_atomically",
]


def write_atomically(path: str | os.PathLike, write: Callable[[Path], None], *,
                     fsync: bool = False, suffix: str | None = None) -> Path | None:
    """Write a file the way ``open(path, 'w')`` would leave it, but without destroying
    anything (the policy of every output: :mod:`rsf._outputs`).

    ``write(tmp)`` fills a temporary file.  A regular file (or a new one) is then replaced
    by it atomically, so that a reader (or a crash) sees either the old file or the whole
    new one: a new file gets ``0o666 & ~umask`` (mkstemp creates 0600), an existing file
    keeps its owner and mode, and a symbolic link stays a link: the data go to the file it
    points to.  A device, a FIFO or this process's standard output is written in place.
    A read-only file, or one whose owner could not be kept, is refused (ValueError).
    ``fsync``: flush the data to disk before the rename.  ``suffix``: of the temporary
    file (default the target's, so that a writer that picks a format from the name picks
    the target's).  Returns the path written (the link's target for a link; None for
    standard output).

    rsf's command line and compare write every output through this policy; micro has the
    same module (``micro/_outputs.py``, identical: micro and rsf are independent packages,
    neither imports the other).
    """
    return _outputs.write(path, write, fsync=fsync, suffix=suffix)


class Status:
    """Named outcomes (integers, like scipy's ``OdeResult.status``): values >= 0 are
    successes, negative values failures; :data:`STATUS_MESSAGES` has the message of each.

    Attributes
    ----------
    TIME_LIMIT : int
        0, the run reached ``t_end``.
    STEADY : int
        1, steady sliding reached (a stable steady state within tolerance).
    CONVERGED : int
        2, the limit cycle converged.
    MAX_CYCLES : int
        -1, no converged limit cycle within ``SolverOptions.max_cycles``.
    MAX_EVENTS : int
        -2, more events than ``SolverOptions.max_events`` in one run.
    RUNAWAY : int
        -3, a slip that never arrests: for :math:`a > 0` the slip velocity passed
        ``SolverOptions.v_max``; for :math:`a = 0` a slip whose weakening outruns the
        spring without bound.
    SOLVER_FAILED : int
        -4, CVODE or a root search failed.
    DEGENERATE : int
        -5, repeated zero-length phases at a degenerate (tangent) point, or a repeating
        "cycle" of period 0 or of no amplitude (the motion not resolved in double precision).
    STEP_BUDGET : int
        -6, the step budget ``SolverOptions.max_rhs_evals`` ran out.
    """

    TIME_LIMIT = 0        #: reached t_end
    STEADY = 1            #: steady sliding reached (a stable steady state within tolerance)
    CONVERGED = 2         #: limit cycle converged
    MAX_CYCLES = -1       #: limit cycle not converged within max_cycles
    MAX_EVENTS = -2       #: too many events
    RUNAWAY = -3          #: a slip that never arrests (unbounded weakening)
    SOLVER_FAILED = -4    #: CVODE or a root search failed
    DEGENERATE = -5       #: zero-length phases at a degenerate point, or a period-0 "cycle"
    STEP_BUDGET = -6      #: the step budget (SolverOptions.max_rhs_evals) ran out


STATUS_MESSAGES: dict[int, str] = {
    Status.TIME_LIMIT: "reached the end time",
    Status.STEADY: "steady sliding reached",
    Status.CONVERGED: "limit cycle converged",
    Status.MAX_CYCLES: "limit cycle not converged within max_cycles",
    Status.MAX_EVENTS: "too many events",
    Status.RUNAWAY: "runaway slip: the slip velocity blows up (weakening exceeds the spring)",
    Status.SOLVER_FAILED: "the integrator or a root search failed",
    Status.DEGENERATE: "degenerate: zero-length phases or a cycle of period 0, not a limit cycle",
    Status.STEP_BUDGET: "the step budget (max_rhs_evals) ran out",
}


@dataclass(frozen=True)
class Event:
    """A switch of phase (``kind`` like ``'stick->slip'``) or another marked instant
    (``'steady'``, ``'drive'``, ``'extremum'``, ``'restart'``, ``'sigma_max'``,
    ``'sigma_min'``).

    Attributes
    ----------
    t : float
        Its time.
    kind : str
        What happened.
    sigma, theta, x : float
        Friction, state variable and slider position at that instant.
    """

    t: float
    kind: str
    sigma: float
    theta: float
    x: float


def _events_frame(events: list[Event]) -> pd.DataFrame:
    return pd.DataFrame([asdict(e) for e in events], columns=["t", "kind", "sigma", "theta", "x"])


@dataclass
class Trajectory:
    """A time series from :func:`rsf.simulate`.

    Attributes
    ----------
    t, x, sigma, theta, v : ndarray
        Samples (a slip appears as two samples at the same time), at the integrator's steps
        or at ``t_eval``.  ``sigma`` is the friction; with radiation damping the spring
        force is ``sigma + eta_rad * v``.
    theta2 : ndarray or None
        The second state variable at the same samples (a model with a
        :class:`~rsf.state_laws.SecondState`), else None.
    events : list of Event
        Every event of the run.
    status : int
        One of :class:`Status`; ``success`` is ``status >= 0``.
    message : str
        Human-readable status.
    params : dict
        Model parameters.
    """

    t: np.ndarray
    x: np.ndarray
    sigma: np.ndarray
    theta: np.ndarray
    v: np.ndarray
    events: list[Event]
    status: int
    message: str
    params: dict[str, Any] = field(default_factory=dict)
    theta2: np.ndarray | None = None

    @property
    def success(self) -> bool:
        return self.status >= 0

    def to_frame(self) -> pd.DataFrame:
        """Columns t, x, sigma, theta, v, and theta2 for two state variables."""
        columns = {"t": self.t, "x": self.x, "sigma": self.sigma, "theta": self.theta, "v": self.v}
        if self.theta2 is not None:
            columns["theta2"] = self.theta2
        return pd.DataFrame(columns)

    def events_frame(self) -> pd.DataFrame:
        """Columns t, kind, sigma, theta, x."""
        return _events_frame(self.events)

    def thinned(self, dt: float) -> Trajectory:
        """The same run with at most one sample per ``dt`` of time, except at events.

        The first and last samples, every sample at an event's time (a slip's two samples,
        the extrema of sigma, the changes of phase) and every sample that shares its time
        with a neighbour are kept; of the others, a sample is kept when it lies at least
        ``dt`` after the last one kept.  So a run of ``t_end`` keeps at most
        ``t_end / dt + 1`` samples besides those at events, however many steps the
        integrator took.  ``dt = 0`` keeps every sample.  The samples kept are exact (no
        interpolation); the events are unchanged.

        Parameters
        ----------
        dt : float
            Smallest time between two samples kept apart from events, >= 0.

        Returns
        -------
        Trajectory
            A new trajectory (this one if nothing is dropped).
        """
        dt = float(dt)
        if not (math.isfinite(dt) and dt >= 0.0):
            raise ValueError(f"dt must be a finite number >= 0, got {dt:g}")
        n = self.t.size
        if dt == 0.0 or n <= 2:
            return self
        t = self.t
        forced = np.isin(t, np.array([e.t for e in self.events], dtype=float))
        forced[[0, -1]] = True
        same = np.diff(t) == 0.0
        forced[:-1] |= same
        forced[1:] |= same
        keep = forced.copy()
        last = -math.inf
        for i in range(n):
            if forced[i] or t[i] - last >= dt:
                keep[i] = True
                last = t[i]
        if keep.all():
            return self
        return Trajectory(t=t[keep], x=self.x[keep], sigma=self.sigma[keep], theta=self.theta[keep],
                          v=self.v[keep], events=self.events, status=self.status, message=self.message,
                          params=self.params, theta2=None if self.theta2 is None else self.theta2[keep])


@dataclass
class CycleResult:
    """The attractor at one driving velocity, from :func:`rsf.limit_cycle`.

    Attributes
    ----------
    V : float
        The driving velocity.
    regime : str
        ``'steady'`` or ``'stick-slip'`` (any converged oscillation), or ``'unknown'`` when
        the search failed.
    sigma_max, sigma_min, sigma_mean : float
        Extrema and time average of sigma over the last cycle (all equal to
        :math:`\\mu_{ss}(V)` for steady sliding).
    period : float
        Duration of the last cycle (nan for steady sliding).
    converged : bool
        Whether the cycle (or the steady state) was reached within tolerance.
    status : int
        Outcome (:class:`Status`); ``success`` is ``status >= 0``.
    message : str
        Human-readable status.
    n_cycles : int
        Cycles simulated.
    relative_change : float
        Largest relative change of (sigma_max, sigma_min, period) between the last two
        cycles.
    sequence : tuple of str
        Event kinds of the last cycle.
    events : list of Event
        Events of the last cycle.
    params : dict
        Model parameters and ``V``.
    run_time : float
        Wall time of the search, in seconds.
    """

    V: float
    regime: str
    sigma_max: float
    sigma_min: float
    sigma_mean: float
    period: float
    converged: bool
    status: int
    message: str
    n_cycles: int = 0
    relative_change: float = math.nan
    sequence: tuple[str, ...] = ()
    events: list[Event] = field(default_factory=list)
    params: dict[str, Any] = field(default_factory=dict)
    run_time: float = math.nan

    @property
    def success(self) -> bool:
        return self.status >= 0

    @property
    def amplitude(self) -> float:
        """sigma_max - sigma_min."""
        return self.sigma_max - self.sigma_min

    def row(self) -> dict[str, Any]:
        out: dict[str, Any] = {}
        out.update({k: self.params[k] for k in ("k0", "Dc") if k in self.params})
        out.update(V=self.V, regime=self.regime, sigma_max=self.sigma_max,
                   sigma_min=self.sigma_min, sigma_mean=self.sigma_mean, period=self.period,
                   converged=self.converged, status=self.status, message=self.message,
                   n_cycles=self.n_cycles, relative_change=self.relative_change,
                   sequence=" ".join(self.sequence))
        return out

    def to_frame(self) -> pd.DataFrame:
        """One row: k0, Dc, V, regime, sigma_max, sigma_min, sigma_mean, period, ..."""
        return pd.DataFrame([self.row()])

    def events_frame(self) -> pd.DataFrame:
        return _events_frame(self.events)


@dataclass
class SweepResult:
    """Limit cycles over a list of driving velocities (:func:`rsf.sweep`).

    It is a sequence of its :class:`CycleResult` (``len``, iteration, indexing).

    Attributes
    ----------
    results : list of CycleResult
        One per velocity, in the order given.
    params : dict
        Model parameters.
    """

    results: list[CycleResult]
    params: dict[str, Any] = field(default_factory=dict)

    def __len__(self) -> int:
        return len(self.results)

    def __iter__(self):
        return iter(self.results)

    def __getitem__(self, i: int) -> CycleResult:
        return self.results[i]

    @property
    def all_converged(self) -> bool:
        return all(r.converged for r in self.results)

    @property
    def status(self) -> int:
        """The worst status of the sweep."""
        return min((r.status for r in self.results), default=Status.CONVERGED)

    @property
    def message(self) -> str:
        bad = [r for r in self.results if not r.converged]
        if not bad:
            return f"all {len(self.results)} points converged"
        return (f"{len(bad)} of {len(self.results)} points not converged: "
                + "; ".join(f"V={r.V:g}: {r.message}" for r in bad[:5]))

    def to_frame(self) -> pd.DataFrame:
        """One row per V with k0, Dc, V, regime, sigma_max, sigma_min, sigma_mean, period."""
        return pd.DataFrame([r.row() for r in self.results])
