"""What both engines share: the constructor, the samples and events they record, the
output at requested times (``t_eval``), the stop of a run with a status, and the count of
right-hand-side evaluations against the step budget."""
from __future__ import annotations

import functools
import logging
import weakref
from dataclasses import dataclass, field

import numpy as np
from numba.core.registry import CPUDispatcher

from ..params import InitialState, Protocol, SolverOptions, SpringSlider
from ..results import Event, Status

__all__ = ["Engine", "Kernels", "Samples", "Stop", "TAU_CHUNK", "compiled", "onto_time",
           "cvode_arrays"]

logger = logging.getLogger("rsf.solver")     # the name the engines' messages have always had

#: Length of one CVODE run in the slide time tau of the a = 0 engine (its first run; see
#: :func:`rsf.engines.phase.chunk_span`) and in the natural time s of the a > 0 engine.
TAU_CHUNK = 1e4


def cvode_arrays(n: int) -> tuple[np.ndarray, np.ndarray]:
    """Arrays of the kinds that CVODE (scikit-sundae) hands to a right-hand side or an event
    function: the state ``y`` (read-only) and the output (writable), of length ``n``."""
    y = np.zeros(n)
    y.setflags(write=False)
    return y, np.zeros(n)


_COMPILED: weakref.WeakKeyDictionary = weakref.WeakKeyDictionary()


def compiled(kernel, *args):
    """The compiled function of the numba kernel ``kernel`` for the types of ``args``, to be
    called with arguments of those types.  It skips the dispatcher's type resolution, about
    0.1 us of the 0.4 us of a call, and CVODE calls the right-hand side and the event
    function thousands of times per run; the same machine code runs either way.  Kept per
    kernel (the engines always pass the same types: float64 vectors, the state read-only
    as CVODE passes it), since finding it costs tens of microseconds.  A plain-Python
    kernel (a user's law without numba) comes back unchanged, as does a kernel numba
    cannot compile so."""
    if not isinstance(kernel, CPUDispatcher):
        return kernel
    entry = _COMPILED.get(kernel)
    if entry is None:
        try:
            sig = tuple(kernel.typeof_pyval(a) for a in args)
            kernel.compile(sig)
            entry = kernel.get_overload(sig)
        except Exception:  # noqa: BLE001 - any failure: the dispatcher itself still works
            entry = kernel
        _COMPILED[kernel] = entry
    return entry


class Kernels:
    """The kernel set for one law (see :meth:`rsf.laws.SteadyStateLaw.kernels`)."""

    def __init__(self, law) -> None:
        for name, func in law.kernels().items():
            setattr(self, name, func)


class Stop(Exception):
    """Raised inside an engine to end the run with a status (and a detail for the
    message)."""

    def __init__(self, status: int, detail: str = "") -> None:
        super().__init__(detail)
        self.status = status
        self.detail = detail


@dataclass
class Samples:
    """The recorded time series, in pieces: one tuple of arrays (t, x, sigma, theta, v and,
    with a second state variable, theta2) per call of :meth:`add`, stored by one append, so
    that a Ctrl-C arriving inside :meth:`add` leaves every series the same length (with one
    list per series it could leave ``t`` a piece longer than the others, and the samples
    kept after the interrupt then failed to be written)."""

    pieces: list = field(default_factory=list)

    def add(self, t, x, sigma, theta, v, theta2=None) -> None:
        t = np.atleast_1d(np.array(t, dtype=float, copy=True))
        extra = () if theta2 is None else (theta2,)
        self.pieces.append((t, *(np.broadcast_to(np.asarray(val, dtype=float), (t.size,)).copy()
                                  for val in (x, sigma, theta, v, *extra))))

    def theta2_array(self) -> np.ndarray:
        parts = [p[5] for p in self.pieces if len(p) > 5]
        return np.concatenate(parts) if parts else np.empty(0)

    def arrays(self) -> tuple[np.ndarray, ...]:
        if not self.pieces:
            return tuple(np.empty(0) for _ in range(5))
        return tuple(np.concatenate([p[i] for p in self.pieces]) for i in range(5))


class Engine:
    """The common part of :class:`~rsf.engines.phase.PhaseEngine` (a = 0) and
    :class:`~rsf.engines.smooth.SmoothEngine` (a > 0).

    An engine holds the state of one run.  :meth:`start` sets the initial state,
    ``step(t_end)`` runs to the next event and returns it (``'end'`` at ``t_end``,
    ``'steady'`` on a stable steady slide when ``stop_at_steady``), and a failure ends the
    run by raising :class:`Stop` with its status.  With ``record`` the samples go to
    :attr:`samples` (every internal step, or only the times of ``t_eval``); the events go
    to :attr:`events` either way.  For the limit-cycle search both also give
    :attr:`integral` (of the absolute sigma dt), :meth:`section` (the variable of the cycle
    map) and :meth:`restart_at_section`.
    """

    def __init__(self, model: SpringSlider, protocol: Protocol, options: SolverOptions,
                 record: bool, stop_at_steady: bool, t_eval: np.ndarray | None = None) -> None:
        self.model = model
        self.protocol = protocol
        self.options = options
        self.record = record
        self.stop_at_steady = stop_at_steady
        self.t_eval = t_eval
        self.next_out = 0          # index of the next t_eval point to output
        self.p = model.law.kernel_params
        self.mu_ref = model.law.mu_ref
        self.k = Kernels(model.law)
        self.law_fn = self.k.law_eval
        self.samples = Samples()
        self.events: list[Event] = []
        self.nfev = 0              # right-hand-side evaluations so far, against the budget

    @functools.cached_property
    def law_compiled(self):
        """The law's kernel (v, p) -> (mu_ss - mu_ref, W), compiled for a float and ``p``
        (:func:`compiled`): the samples evaluate it once each."""
        return compiled(self.k.law_eval, 1.0, self.p)

    # -- the step budget -------------------------------------------------------------------
    def charge(self, nfev: int) -> None:
        """Add ``nfev`` right-hand-side evaluations to the count; past the step budget
        (``options.max_rhs_evals``) the run stops with ``STEP_BUDGET``."""
        self.nfev += nfev
        if self.nfev > self.options.max_rhs_evals:
            raise Stop(Status.STEP_BUDGET, f"{self.nfev} evaluations, at t = {self.t:.10g}")

    # -- the start ---------------------------------------------------------------------------
    def initial_theta(self, initial: InitialState) -> float:
        """theta at t = 0: given, or the steady state at the first velocity times
        ``1 + perturbation``."""
        V0 = float(self.protocol.velocities[0])
        if initial.theta is not None:
            return initial.theta
        if V0 > 0.0:
            return self.model.Dc / V0 * (1.0 + (initial.perturbation or 0.0))
        raise ValueError("initial.theta is required when the driving starts with V = 0")

    def segment_stop(self, t_end: float) -> float:
        """The end of the current driving segment, or ``t_end`` if sooner."""
        return min(self.protocol.segment_end(self.t), t_end)

    # -- output at requested times (t_eval) ----------------------------------------------------
    def pending(self, t_hi: float, inclusive: bool) -> np.ndarray:
        """The t_eval points not yet output, up to ``t_hi`` (included if ``inclusive``)."""
        te = self.t_eval
        j1 = int(np.searchsorted(te, t_hi, side="right" if inclusive else "left"))
        return te[self.next_out:j1]

    def take_pending(self, t_hi: float, inclusive: bool) -> np.ndarray:
        """:meth:`pending`, and mark those points as output."""
        out = self.pending(t_hi, inclusive)
        self.next_out += out.size
        return out

    # -- an event ------------------------------------------------------------------------------
    def add_event(self, event: Event) -> Event:
        self.events.append(event)
        return event


def onto_time(rhs, y: np.ndarray, t_target: float, index: int = 4) -> np.ndarray:
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
