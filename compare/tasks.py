"""Units of micro work that the runner schedules, caches and runs in parallel.

A task is a small frozen dataclass that holds everything its result depends on (the
model, the drive velocity, the numerics, the stopping rule) and can say so as canonical
JSON (:meth:`describe`).  Its cache key is the SHA-256 of that description together with
the *code version*: a hash of the source of the ``micro`` package and of this module's
format number, so that a change of the solver never serves stale numbers.

Tasks are picklable (plain fields), so that they travel to process-pool workers and to
dask workers unchanged.  :func:`execute` runs one and returns a JSON-serialisable record;
it never raises for an error of the computation itself: the record says what happened.
"""
from __future__ import annotations

import hashlib
import json
import logging
import math
import time
from dataclasses import dataclass
from functools import lru_cache
from pathlib import Path
from typing import Any, Callable, Sequence

import numpy as np

import micro

from ._validation import in_range, positive

__all__ = [
    "SteadyTask",
    "VcTask",
    "NBlockTask",
    "TraceTask",
    "StationaryTask",
    "CriticalTask",
    "SlideHoldSlideTask",
    "Task",
    "execute",
    "code_version",
    "model_description",
    "model_from_description",
    "warm_up",
]

log = logging.getLogger(__name__)

#: Bump when the meaning or layout of a task's record changes.
TASK_FORMAT = 3
#: The methods of micro.stationary a StationaryTask may ask for.
STATIONARY_METHODS = ("auto", "fp", "cohort")


@lru_cache(maxsize=1)
def code_version() -> str:
    """SHA-256 (first 16 hex digits) of the ``micro`` sources and :data:`TASK_FORMAT`."""
    digest = hashlib.sha256(f"compare-task-format-{TASK_FORMAT}".encode())
    root = Path(micro.__file__).resolve().parent
    for path in sorted(root.glob("*.py")):
        digest.update(path.name.encode())
        digest.update(path.read_bytes())
    return digest.hexdigest()[:16]


def model_description(model: micro.Model) -> dict[str, Any]:
    """The model as a canonical dict (every parameter that changes its results)."""
    if not isinstance(model, micro.Model):
        raise ValueError(f"model must be a micro.Model, got {type(model).__name__}")
    jumps = model.jumps
    if isinstance(jumps, micro.Exponential):
        jd = {"type": "Exponential", "zbar": float(jumps.zbar), "cutoff": float(jumps.cutoff)}
    elif isinstance(jumps, micro.Deterministic):
        jd = {"type": "Deterministic", "zbar": float(jumps.zbar)}
    else:
        raise ValueError("model.jumps must be micro.Exponential or micro.Deterministic for cached "
                         f"comparisons (a Tabulated density cannot be hashed), got {type(jumps).__name__}")
    return {"k0": float(model.k0), "k1": float(model.k1), "k2": float(model.k2),
            "eta_u": float(model.eta_u), "f_th": float(model.f_th), "jumps": jd}


def model_from_description(d: dict[str, Any]) -> micro.Model:
    """Inverse of :func:`model_description`."""
    jd = dict(d["jumps"])
    kind = jd.pop("type")
    jumps = micro.Exponential(**jd) if kind == "Exponential" else micro.Deterministic(**jd)
    return micro.Model(k0=d["k0"], k1=d["k1"], k2=d["k2"], eta_u=d["eta_u"], f_th=d["f_th"], jumps=jumps)


def _numerics_description(numerics: micro.Numerics, model: micro.Model) -> dict[str, Any]:
    eps = micro.default_eps(model) if numerics.eps is None else float(numerics.eps)
    return {"eps": eps, "theta_shift": float(numerics.theta_shift), "theta_relax": float(numerics.theta_relax)}


def _cohort_description(cohort: micro.Cohort, model: micro.Model) -> dict[str, Any]:
    return {"dt": float(cohort.dt), "h": float(cohort.cell(model)), "tol": float(cohort.tol),
            "max_iter": int(cohort.max_iter)}


def _convergence_description(conv: micro.Convergence) -> dict[str, Any]:
    return {"rtol": float(conv.rtol), "atol": float(conv.atol), "n": int(conv.n),
            "t_max": None if conv.t_max is None else float(conv.t_max)}


def _check_common(model, numerics, convergence) -> None:
    model_description(model)  # validates the model type
    if not isinstance(numerics, micro.Numerics):
        raise ValueError(f"numerics must be a micro.Numerics, got {type(numerics).__name__}")
    if not isinstance(convergence, micro.Convergence):
        raise ValueError(f"convergence must be a micro.Convergence, got {type(convergence).__name__}")
    numerics.settings(model)  # eps within the solver's range, or a ValueError naming eps


def _check_counts(task: Any, bounds: tuple[tuple[str, int], ...]) -> None:
    """Each field ``name`` of the frozen ``task`` an integer >= ``low`` (a bool and a float are
    refused), stored as an int; else a ValueError naming it."""
    for name, low in bounds:
        value = getattr(task, name)
        if isinstance(value, bool) or not isinstance(value, (int, np.integer)) or value < low:
            raise ValueError(f"{name} must be an integer >= {low}, got {value!r}")
        object.__setattr__(task, name, int(value))


class _TaskBase:
    kind: str = "task"

    def describe(self) -> dict[str, Any]:  # pragma: no cover - abstract
        raise NotImplementedError

    @property
    def key(self) -> str:
        """Cache key: SHA-256 of the canonical description and the code version."""
        text = json.dumps({"task": self.describe(), "code": code_version()}, sort_keys=True)
        return hashlib.sha256(text.encode()).hexdigest()

    def label(self) -> str:
        d = self.describe()
        m = d["model"]
        extra = f" V={d['V']:.4g}" if "V" in d else ""
        return f"{self.kind} k0={m['k0']:g} k1={m['k1']:g} k2={m['k2']:g}{extra}"


@dataclass(frozen=True)
class StationaryTask(_TaskBase):
    """``micro.stationary(model, V, method=..., numerics=..., convergence=...)``: ``"auto"``
    (the renewal chain where steady sliding is stable, the cohort method with the options
    ``cohort`` for a stick-slip cycle), ``"cohort"``, or ``"fp"`` (time-steps the
    Fokker-Planck equation at ``numerics`` even where the direct steady state exists).

    Its result is the row's :meth:`micro.Stationary.to_dict`; :func:`micro_frame` makes a
    table of such records.

    Parameters
    ----------
    model : micro.Model
        The model (exponential or deterministic jumps).
    V : float
        Drive velocity, finite and > 0.
    numerics : micro.Numerics
        The Fokker-Planck options, wherever that method runs.
    convergence : micro.Convergence
        The Fokker-Planck runs' stopping rule.
    method : str
        ``"auto"`` (default), ``"cohort"`` or ``"fp"``.
    cohort : micro.Cohort
        The cohort method's options (default ``micro.Cohort()``); not part of the
        description (nor of the cache key) when ``method="fp"``.

    Raises
    ------
    ValueError
        If ``V`` is not a finite number > 0, ``method`` is not one of the three,
        ``model``, ``numerics``, ``convergence`` or ``cohort`` is not of its type, the
        jumps are :class:`micro.Tabulated` (a density that cannot be hashed), or the bin
        or the cohort cell is out of range for the model.
    """

    model: micro.Model
    V: float
    numerics: micro.Numerics
    convergence: micro.Convergence
    method: str = "auto"
    cohort: micro.Cohort = micro.Cohort()
    kind = "stationary"

    def __post_init__(self) -> None:
        object.__setattr__(self, "V", positive("V", self.V))
        if self.method not in STATIONARY_METHODS:
            raise ValueError(f"method must be one of {', '.join(map(repr, STATIONARY_METHODS))}, got {self.method!r}")
        if not isinstance(self.cohort, micro.Cohort):
            raise ValueError(f"cohort must be a micro.Cohort, got {type(self.cohort).__name__}")
        _check_common(self.model, self.numerics, self.convergence)
        self.cohort.cell(self.model)

    def describe(self) -> dict[str, Any]:
        d = {"kind": self.kind, "model": model_description(self.model), "V": self.V, "method": self.method,
             "numerics": _numerics_description(self.numerics, self.model),
             "convergence": _convergence_description(self.convergence)}
        if self.method != "fp":
            d["cohort"] = _cohort_description(self.cohort, self.model)
        return d

    def run(self) -> dict[str, Any]:
        method = {"auto": micro.Auto(cohort=self.cohort), "cohort": self.cohort, "fp": "fp"}[self.method]
        res = micro.stationary(self.model, self.V, numerics=self.numerics, convergence=self.convergence,
                               method=method)
        return res.to_dict()


@dataclass(frozen=True)
class CriticalTask(_TaskBase):
    """``micro.critical_velocity(model, V_min=..., V_max=..., rel_tol=..., V_guess=..., factor=..., refine=...)``
    (bracketing outward from ``V_guess`` by ``factor``, then bisection; with ``refine``
    oscillations smaller than 2 eps are checked at eps / 2).

    This is the Fokker-Planck bisection (``method="fp"``, minutes); :class:`VcTask` is
    the renewal chain's exact V^c.  Its result is :meth:`micro.Critical.to_dict` with the
    bisection's ``evaluations``.

    Parameters
    ----------
    model : micro.Model
        The model (exponential or deterministic jumps).
    V_min, V_max : float
        The search range, finite, > 0, with ``V_max > V_min``.
    rel_tol : float
        The bracket's relative width at which the bisection stops, in (0, 1).
    numerics : micro.Numerics
        The Fokker-Planck options (the bin ``eps``).
    convergence : micro.Convergence
        The runs' stopping rule.
    V_guess : float
        The first velocity tried, in [V_min, V_max] (default 1).
    factor : float
        The step of the outward bracketing, in (1, 1e3] (default 4).
    refine : bool
        Check small oscillations at eps / 2 (default True).

    Raises
    ------
    ValueError
        If a velocity, ``rel_tol`` or ``factor`` is out of range, ``model``,
        ``numerics`` or ``convergence`` is not of its type, the jumps are
        :class:`micro.Tabulated`, or the bin is out of range for the model.
    """

    model: micro.Model
    V_min: float
    V_max: float
    rel_tol: float
    numerics: micro.Numerics
    convergence: micro.Convergence
    V_guess: float = 1.0
    factor: float = 4.0
    refine: bool = True
    kind = "critical"

    def __post_init__(self) -> None:
        object.__setattr__(self, "V_min", positive("V_min", self.V_min))
        object.__setattr__(self, "V_max", positive("V_max", self.V_max))
        if not self.V_max > self.V_min:
            raise ValueError(f"V_max must be > V_min = {self.V_min!r}, got {self.V_max!r}")
        object.__setattr__(self, "rel_tol", in_range("rel_tol", self.rel_tol, 0.0, 1.0,
                                                     low_open=True, high_open=True))
        object.__setattr__(self, "V_guess", in_range("V_guess", self.V_guess, self.V_min, self.V_max))
        object.__setattr__(self, "factor", in_range("factor", self.factor, 1.0, 1e3, low_open=True))
        _check_common(self.model, self.numerics, self.convergence)

    def describe(self) -> dict[str, Any]:
        return {"kind": self.kind, "model": model_description(self.model), "V_min": self.V_min,
                "V_max": self.V_max, "rel_tol": self.rel_tol,
                "V_guess": self.V_guess, "factor": self.factor, "refine": bool(self.refine),
                "numerics": _numerics_description(self.numerics, self.model),
                "convergence": _convergence_description(self.convergence)}

    def run(self) -> dict[str, Any]:
        crit = micro.critical_velocity(self.model, V_min=self.V_min, V_max=self.V_max, rel_tol=self.rel_tol,
                                       V_guess=self.V_guess, factor=self.factor, numerics=self.numerics,
                                       convergence=self.convergence, refine=self.refine, method="fp")
        out = crit.to_dict()
        out["evaluations"] = crit.evaluations
        return out


@dataclass(frozen=True)
class SlideHoldSlideTask(_TaskBase):
    """``micro.slide_hold_slide(model, V, hold_times, ...)``.

    Its result is ``{"rows": [...]}``, one dict per hold (the frame's columns
    ``hold_time, sigma_steady, sigma_peak, delta_sigma_max, method``).

    Parameters
    ----------
    model : micro.Model
        The model (exponential or deterministic jumps).
    V : float
        Drive velocity, finite and > 0, where steady sliding is the attractor (else the
        record holds the ``ValueError``).
    hold_times : sequence of float
        The hold durations, at least one, each finite and >= 0; kept as a tuple.
    numerics : micro.Numerics
        The Fokker-Planck options.
    convergence : micro.Convergence
        The stopping rule of the stationary run before the holds.

    Raises
    ------
    ValueError
        If ``V`` or a hold time is out of range, ``hold_times`` is empty, ``model``,
        ``numerics`` or ``convergence`` is not of its type, the jumps are
        :class:`micro.Tabulated`, or the bin is out of range for the model.
    """

    model: micro.Model
    V: float
    hold_times: tuple[float, ...]
    numerics: micro.Numerics
    convergence: micro.Convergence
    kind = "slide_hold_slide"

    def __post_init__(self) -> None:
        object.__setattr__(self, "V", positive("V", self.V))
        holds = tuple(float(h) for h in self.hold_times)
        if not holds or any(not (math.isfinite(h) and h >= 0.0) for h in holds):
            raise ValueError(f"hold_times must be a non-empty sequence of finite numbers >= 0, got {self.hold_times!r}")
        object.__setattr__(self, "hold_times", holds)
        _check_common(self.model, self.numerics, self.convergence)

    def describe(self) -> dict[str, Any]:
        return {"kind": self.kind, "model": model_description(self.model), "V": self.V,
                "hold_times": list(self.hold_times),
                "numerics": _numerics_description(self.numerics, self.model),
                "convergence": _convergence_description(self.convergence)}

    def run(self) -> dict[str, Any]:
        frame = micro.slide_hold_slide(self.model, self.V, list(self.hold_times), numerics=self.numerics,
                                       convergence=self.convergence)
        return {"rows": frame.to_dict("records")}


# ------------------------------------------------------------------ direct methods (ms per V)
@dataclass(frozen=True)
class SteadyTask(_TaskBase):
    """``micro.steady_sliding(model, V)``: the exact steady state (either branch) at every
    velocity of ``V``, with the branching ratio and the growth rate of the unstable mode.

    Its result is ``{"rows": [...], "message": ...}``: one dict per velocity
    (:meth:`micro.SteadySliding.to_frame`'s columns and ``branching_error``) and the
    chain's message.

    Parameters
    ----------
    model : micro.Model
        The model (exponential or deterministic jumps).
    V : sequence of float
        The drive velocities, at least one, each finite and > 0; kept as a tuple.
        (:func:`micro.steady_sliding` takes [1e-6, 1e7]: a velocity outside makes the
        record an error.)
    tol : float
        Tolerance of the chain's grid, in [1e-14, 1e-3] (default 1e-11).

    Raises
    ------
    ValueError
        If ``V`` is empty or holds a velocity that is not a finite number > 0, ``tol`` is
        out of range, ``model`` is not a :class:`micro.Model`, or its jumps are
        :class:`micro.Tabulated`.

    Examples
    --------
    >>> import micro
    >>> from compare import SteadyTask, execute
    >>> record = execute(SteadyTask(micro.Model(k0=0.1), (0.5, 2.0)))
    >>> record["status"], [row["stable"] for row in record["result"]["rows"]]
    ('ok', [False, True])
    """

    model: micro.Model
    V: tuple[float, ...]
    tol: float = 1e-11
    kind = "steady"

    def __post_init__(self) -> None:
        V = tuple(float(v) for v in self.V)
        if not V or any(not (math.isfinite(v) and v > 0.0) for v in V):
            raise ValueError(f"V must be a non-empty sequence of finite velocities > 0, got {self.V!r}")
        object.__setattr__(self, "V", V)
        object.__setattr__(self, "tol", in_range("tol", self.tol, 1e-14, 1e-3))
        model_description(self.model)

    def describe(self) -> dict[str, Any]:
        return {"kind": self.kind, "model": model_description(self.model), "V": list(self.V), "tol": self.tol}

    def label(self) -> str:
        m = self.model
        return f"steady k0={m.k0:g} k1={m.k1:g} k2={m.k2:g} ({len(self.V)} V)"

    def run(self) -> dict[str, Any]:
        res = micro.steady_sliding(self.model, list(self.V), tol=self.tol, growth_rate=True, warn=False)
        frame = res.to_frame()
        frame["branching_error"] = np.ravel(res.branching_error)
        return {"rows": frame.to_dict("records"), "message": res.message}


@dataclass(frozen=True)
class VcTask(_TaskBase):
    """``micro.critical_velocity(model)`` by the direct method: the root of b(V) = 1.

    Its result is :meth:`micro.Critical.to_dict`.

    Parameters
    ----------
    model : micro.Model
        The model (exponential or deterministic jumps).

    Raises
    ------
    ValueError
        If ``model`` is not a :class:`micro.Model`, or its jumps are
        :class:`micro.Tabulated`.
    """

    model: micro.Model
    kind = "vc"

    def __post_init__(self) -> None:
        model_description(self.model)

    def describe(self) -> dict[str, Any]:
        return {"kind": self.kind, "model": model_description(self.model)}

    def run(self) -> dict[str, Any]:
        crit = micro.critical_velocity(self.model)
        return crit.to_dict()


@dataclass(frozen=True)
class NBlockTask(_TaskBase):
    """The stick-slip extrema of ``n_blocks`` blocks (``micro.nblock.stick_slip_extrema_nblock``):
    means over ``n_cycles`` global shocks after ``n_discard``, with their standard errors.

    Its result holds ``V, n_blocks, regime, sigma_max, sigma_max_stderr, sigma_min,
    sigma_min_stderr, period, period_stderr, n_cycles, status, message``.

    Parameters
    ----------
    model : micro.Model
        The model (exponential or deterministic jumps).
    V : float
        Drive velocity, finite and > 0.
    n_blocks : int
        Number of blocks, >= 10.
    n_cycles : int
        Global shocks to average over, >= 2 (default 10).
    n_discard : int
        Global shocks discarded first as the transient, >= 0 (default 5).
    seed : int
        Seed of the random pinning distances, >= 0 (default 0).

    Raises
    ------
    ValueError
        If ``V`` is not a finite number > 0, a count is not an integer (a bool is
        refused) or is below its bound, ``model`` is not a :class:`micro.Model`, or its
        jumps are :class:`micro.Tabulated`.
    """

    model: micro.Model
    V: float
    n_blocks: int
    n_cycles: int = 10
    n_discard: int = 5
    seed: int = 0
    kind = "nblock"

    def __post_init__(self) -> None:
        object.__setattr__(self, "V", positive("V", self.V))
        _check_counts(self, (("n_blocks", 10), ("n_cycles", 2), ("n_discard", 0), ("seed", 0)))
        model_description(self.model)

    def describe(self) -> dict[str, Any]:
        return {"kind": self.kind, "model": model_description(self.model), "V": self.V, "n_blocks": self.n_blocks,
                "n_cycles": self.n_cycles, "n_discard": self.n_discard, "seed": self.seed}

    def run(self) -> dict[str, Any]:
        from micro.nblock import stick_slip_extrema_nblock
        r = stick_slip_extrema_nblock(self.model, self.V, self.n_blocks, n_cycles=self.n_cycles,
                                      n_discard=self.n_discard, seed=self.seed)
        return {"V": self.V, "n_blocks": self.n_blocks, "regime": r.regime, "sigma_max": r.sigma_max,
                "sigma_max_stderr": r.sigma_max_stderr, "sigma_min": r.sigma_min,
                "sigma_min_stderr": r.sigma_min_stderr, "period": r.period, "period_stderr": r.period_stderr,
                "n_cycles": r.n_cycles, "status": r.status, "message": r.message}


@dataclass(frozen=True)
class TraceTask(_TaskBase):
    """The stress against time under a piecewise-constant drive (``segments`` of
    (duration, velocity)), from a start, recorded at least every ``duration / n_samples``:
    by ``micro.simulate(model, drive)`` (``method="fp"``, the Fokker-Planck equation), or by
    ``micro.nblock.simulate_nblock`` with ``n_blocks`` blocks (``method="nblock"``).

    Its result is ``{"t": [...], "sigma": [...], "method": ...}``.  The FP's records:
    besides the ``n_samples`` intervals, :func:`micro.simulate` records whenever the stress
    has moved by a quarter of k0 eps (the grid's jitter), so a trace through stick-slip
    holds many more samples.  The N-block's: the stress at the end of each of the
    ``n_samples`` intervals, and each global shock's stress before and after it (so a
    sawtooth keeps its peaks).

    Parameters
    ----------
    model : micro.Model
        The model (exponential or deterministic jumps).
    segments : sequence of (float, float)
        The drive's ``(duration, velocity)`` segments, as :class:`micro.Drive` takes them;
        kept as a tuple of float pairs.
    numerics : micro.Numerics
        The Fokker-Planck options (not used by the N-block, nor part of its description).
    n_samples : int
        The duration over the longest interval between records (default 4000).
    method : str
        ``"fp"`` (default) or ``"nblock"``.
    n_blocks : int
        The N-block's number of blocks, >= 10 (default 100 000).
    seed : int
        The N-block's seed of the pinning distances, >= 0 (default 0).

    Raises
    ------
    ValueError
        If a segment is refused by :class:`micro.Drive`, ``method`` is neither, ``numerics``
        is not a :class:`micro.Numerics` or its bin is out of range for the model, a count
        is not an integer at least its bound, or the jumps are :class:`micro.Tabulated`.
    """

    model: micro.Model
    segments: tuple[tuple[float, float], ...]
    numerics: micro.Numerics
    n_samples: int = 4000
    method: str = "fp"
    n_blocks: int = 100_000
    seed: int = 0
    kind = "trace"

    def __post_init__(self) -> None:
        segs = tuple((float(d), float(v)) for d, v in self.segments)
        micro.Drive(segs)  # validates durations and velocities
        object.__setattr__(self, "segments", segs)
        if self.method not in ("fp", "nblock"):
            raise ValueError(f"method must be 'fp' or 'nblock', got {self.method!r}")
        if not isinstance(self.numerics, micro.Numerics):
            raise ValueError(f"numerics must be a micro.Numerics, got {type(self.numerics).__name__}")
        _check_counts(self, (("n_samples", 1), ("n_blocks", 10), ("seed", 0)))
        if self.method == "fp":
            self.numerics.settings(self.model)
        model_description(self.model)

    def describe(self) -> dict[str, Any]:
        d = {"kind": self.kind, "model": model_description(self.model),
             "segments": [list(s) for s in self.segments], "n_samples": int(self.n_samples)}
        if self.method == "fp":
            d["numerics"] = _numerics_description(self.numerics, self.model)
        else:
            d.update(method=self.method, n_blocks=self.n_blocks, seed=self.seed)
        return d

    def label(self) -> str:
        m = self.model
        return f"trace k0={m.k0:g} V={max(v for _, v in self.segments):g}"

    def run(self) -> dict[str, Any]:
        duration = sum(d for d, _ in self.segments)
        if self.method == "nblock":
            from micro.nblock import simulate_nblock
            r = simulate_nblock(self.model, list(self.segments), self.n_blocks, seed=self.seed,
                                record_every=duration / self.n_samples)
            ts, sh = r.timeseries, r.shocks
            t = np.concatenate((ts.t, sh.t, sh.t))
            sigma = np.concatenate((ts.sigma, sh.sigma_before, sh.sigma_after))
            # (at a shock's time: the stress before it, then after it)
            rank = np.concatenate((np.ones(len(ts)), np.zeros(len(sh)), np.full(len(sh), 2.0)))
            order = np.lexsort((rank, t))
            return {"t": t[order].tolist(), "sigma": sigma[order].tolist(), "method": "nblock",
                    "n_blocks": self.n_blocks}
        run = micro.simulate(self.model, micro.Drive(self.segments), numerics=self.numerics,
                             record_dt=duration / self.n_samples)
        rec = run.records
        return {"t": np.asarray(rec.t, float).tolist(), "sigma": np.asarray(rec.sigma, float).tolist(),
                "method": "fp"}


Task = SteadyTask | VcTask | NBlockTask | TraceTask | StationaryTask | CriticalTask | SlideHoldSlideTask

#: Exceptions that are a deterministic answer for these inputs (cached like a result).
DETERMINISTIC_ERRORS = (ValueError,)


def execute(task: Task) -> dict[str, Any]:
    """Run ``task`` and return its record (JSON-serialisable).

    ``status`` is ``"ok"`` with ``result``, or ``"error"`` with ``error`` (the exception
    type and message); ``cacheable`` says whether the record is a deterministic answer
    (results and ``ValueError``) that may be stored.

    Parameters
    ----------
    task : Task
        One of :class:`SteadyTask`, :class:`VcTask`, :class:`NBlockTask`,
        :class:`TraceTask`, :class:`StationaryTask`, :class:`CriticalTask`,
        :class:`SlideHoldSlideTask`.

    Returns
    -------
    dict
        ``key`` (the task's cache key), ``task`` (its description), ``code_version``,
        ``status``, ``result`` or ``error``, ``cacheable`` and ``wall_time`` (seconds).

    Notes
    -----
    An exception raised while the task runs is caught and recorded, never raised; an
    unexpected one (not a ``ValueError``) is also logged with its traceback and is not
    cacheable.

    Examples
    --------
    >>> import micro
    >>> from compare import VcTask, execute
    >>> record = execute(VcTask(micro.Model(k0=0.3)))
    >>> record["status"], record["cacheable"], round(record["result"]["Vc"], 4)
    ('ok', True, 0.1947)
    """
    start = time.perf_counter()
    record: dict[str, Any] = {"key": task.key, "task": task.describe(), "code_version": code_version()}
    try:
        record["result"] = task.run()
        record["status"] = "ok"
        record["cacheable"] = True
    except DETERMINISTIC_ERRORS as exc:
        record.update(status="error", error=f"{type(exc).__name__}: {exc}", cacheable=True)
    except Exception as exc:  # noqa: BLE001 - reported in the record, never hidden
        log.exception("task %s failed", task.label())
        record.update(status="error", error=f"{type(exc).__name__}: {exc}", cacheable=False)
    record["wall_time"] = time.perf_counter() - start
    return record


def _warm_fp() -> None:
    model = micro.Model(k0=0.5)
    micro.simulate(model, 5.0, duration=0.5, numerics=micro.Numerics(eps=model.kappa * model.zbar / 4.0))


def _warm_cohort() -> None:
    coarse = micro.Model(k0=0.3)
    micro.stationary(coarse, 0.1, method=micro.Cohort(dt=0.1, h=coarse.kappa * coarse.zbar / 2.0, tol=1e-2,
                                                      max_iter=4), warn=False)


def _warm_nblock() -> None:
    from micro.nblock import simulate_nblock

    simulate_nblock(micro.Model(k0=0.3), 0.1, 64, t_max=1.0)


#: micro's kernels in groups that compile independently, the costliest first (CPU seconds
#: to compile on one core, measured with an empty numba cache on an idle machine: cohort
#: 15.6, fp 8.2, nblock 7.8; cohort 11.9 on a loaded one since its pool workers compile
#: serial twins of its parallel kernels).  Cohort's run compiles the renewal kernels as
#: well (micro.stationary calls the renewal chain): a group of their own compiled nothing
#: after it, and with three workers or more compiled them a second time beside it.  A pool
#: compiles the groups on its workers at once (:meth:`compare.runner.Runner`), and every
#: later process loads them from numba's disk cache.
WARM_GROUPS: dict[str, Callable[[], None]] = {
    "cohort": _warm_cohort, "fp": _warm_fp, "nblock": _warm_nblock,
}


def warm_up(groups: Sequence[str] | None = None) -> float:
    """Compile (or load from numba's disk cache) micro's kernels in this process with a
    tiny run of each method in ``groups`` (names of :data:`WARM_GROUPS`; default all);
    returns the seconds it took."""
    start = time.perf_counter()
    for name in WARM_GROUPS if groups is None else groups:
        WARM_GROUPS[name]()
    return time.perf_counter() - start
