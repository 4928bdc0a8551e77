"""Orchestration of the Fokker-Planck solver: protocol runs, stationary states, the
critical velocity, sweeps and slide-hold-slide.

``simulate`` runs a driving protocol and returns the stress time series.
``stationary`` drives at constant V until the requested quantity has converged (a
steady stress, or the extrema of a stick-slip cycle) and stops there.
``critical_velocity`` bisects on the regime, as in the paper's Appendix B.
"""
from __future__ import annotations

import contextlib
import logging
import math
import threading
import time
from dataclasses import dataclass, field, replace
from typing import Iterator

import numpy as np
import pandas as pd
from scipy.stats import linregress

from . import _kernels as K
from .analysis import Records, cycle_converged, find_cycles
from .analytic import sigma_fast_limit
from .cohort import cycle_cohorts
from .cycle import CycleFixedPoint, cycle_fixed_point
from .grid import Grid, GridSettings
from .params import KIND_EXPONENTIAL, Model
from .protocols import Drive
from .renewal import critical_velocity_renewal, steady_sliding

__all__ = [
    "Numerics",
    "Convergence",
    "Run",
    "Stationary",
    "Critical",
    "default_eps",
    "simulate",
    "stationary",
    "critical_velocity",
    "sweep",
    "slide_hold_slide",
]

log = logging.getLogger(__name__)

#: Default bin: this fraction of a mean jump of delta, kappa * zbar.
EPS_FRACTION = 1.0 / 50.0


def default_eps(model: Model) -> float:
    """The default bin, ``kappa * zbar / 50`` (2e-3 for the paper's parameters)."""
    return model.kappa * model.zbar * EPS_FRACTION


@dataclass(frozen=True)
class Numerics:
    """Discretisation: bin ``eps`` (default :func:`default_eps`), the step limits, the
    memory the grid may take (``max_memory_gib``; beyond it a run raises
    :class:`~micro.grid.GridTooLarge` instead of exhausting the machine), and the cohort
    method's time step ``cohort_dt`` (``method="cohort"``: its ``eps`` is the delta_R cell,
    default kappa zbar / 20; both are its refinement variables)."""

    eps: float | None = None
    theta_shift: float = 0.5
    theta_relax: float = 0.5
    max_memory_gib: float = 4.0
    cohort_dt: float = 0.01

    def __post_init__(self) -> None:
        if not (math.isfinite(self.cohort_dt) and 0.0 < self.cohort_dt <= 0.1):
            raise ValueError(f"cohort_dt must be a finite number in (0, 0.1], got {self.cohort_dt!r}")
        if not (math.isfinite(self.max_memory_gib) and self.max_memory_gib > 0.0):
            raise ValueError(f"max_memory_gib must be a finite number > 0, got {self.max_memory_gib!r}")
        if self.eps is not None and not (math.isfinite(self.eps) and self.eps > 0.0):
            raise ValueError(f"eps must be a finite number > 0 (or None for the default), got {self.eps!r}")
        if not (0.0 < self.theta_shift <= 1.0):
            raise ValueError(f"theta_shift must be in (0, 1], got {self.theta_shift!r}")
        if not (0.0 < self.theta_relax <= 2.0):
            raise ValueError(f"theta_relax must be in (0, 2], got {self.theta_relax!r}")

    def settings(self, model: Model) -> GridSettings:
        eps = default_eps(model) if self.eps is None else float(self.eps)
        settings = GridSettings(eps=eps, theta_shift=self.theta_shift, theta_relax=self.theta_relax, dt_max=math.inf,
                                max_bytes=self.max_memory_gib * 2**30)
        settings.check(model)
        return settings


@dataclass(frozen=True)
class Convergence:
    """When a stationary run stops.

    Parameters
    ----------
    rtol : stick-slip: the last ``n`` cycles' sigma_max and sigma_min agree within
        ``rtol`` times the stress drop and their periods within ``rtol`` (the paper:
        1 % over three consecutive global shocks).  Steady: the last ``n`` stress means
        agree within ``rtol`` times the velocity weakening ``|sigma - sigma_inf|``
        (the paper: 1 % over three values) plus the grid's jitter ``k0 * eps``, plus
        ``atol``.
    atol : absolute stress tolerance added to both tests.
    n : how many consecutive values or cycles must agree.
    t_max : longest simulated time (None: 400 relaxation times, or 60 times the
        time the drive needs to load one mean jump, whichever is longer).
    """

    rtol: float = 1e-2
    atol: float = 1e-9
    n: int = 3
    t_max: float | None = None

    def __post_init__(self) -> None:
        if not (math.isfinite(self.rtol) and self.rtol > 0.0):
            raise ValueError(f"rtol must be a finite number > 0, got {self.rtol!r}")
        if not (math.isfinite(self.atol) and self.atol >= 0.0):
            raise ValueError(f"atol must be a finite number >= 0, got {self.atol!r}")
        if int(self.n) != self.n or self.n < 2:
            raise ValueError(f"n must be an integer >= 2, got {self.n!r}")
        if self.t_max is not None and not (math.isfinite(self.t_max) and self.t_max > 0.0):
            raise ValueError(f"t_max must be a finite number > 0 (or None), got {self.t_max!r}")


@dataclass
class Run:
    """A protocol run: the stress records, the shocks, and the final grid."""

    records: pd.DataFrame
    shocks: pd.DataFrame
    grid: Grid
    wall_time: float
    mass_error: float = math.nan
    min_mass: float = math.nan

    def to_frame(self) -> pd.DataFrame:
        return self.records


@dataclass
class Stationary:
    """The attractor at constant drive velocity: a steady stress or a stick-slip cycle.

    ``sigma_max``, ``sigma_min`` and ``sigma_mean`` are equal on steady rows;
    ``sigma_stderr`` is the statistical error of ``sigma_mean`` from the discretisation
    jitter (the solver is deterministic, but its stress jitters at the scale k0 * eps).
    ``shocks_per_cycle`` counts the global shocks (cascades of more than 8 bins) per
    cycle of a stick-slip result.
    ``converged`` says whether the stopping test was met; ``message`` says why the run
    ended.  ``mass_error`` (``abs(total probability - 1)``) and ``min_mass`` (the most negative
    cell mass ever seen, 0 if none) are the solver's own checks of the density.
    ``records`` holds the stress time series when asked for.  ``sigma_before`` and
    ``sigma_after`` (``method="cohort"`` only, NaN otherwise) are the stress when a global
    shock starts and right after it (the paper's sigma_B and sigma_A): ``sigma_max`` is
    the largest stress of the cycle, above ``sigma_before`` where the creep that precedes
    a shock outruns the drive (by up to 1e-3 at k0 = 0.3).
    """

    model: Model
    V: float
    eps: float
    regime: str
    sigma_max: float
    sigma_min: float
    sigma_mean: float
    period: float
    converged: bool
    message: str
    t_end: float
    n_cycles: int
    wall_time: float
    sigma_stderr: float = math.nan
    shocks_per_cycle: float = math.nan
    mass_error: float = math.nan
    min_mass: float = math.nan
    sigma_before: float = math.nan
    sigma_after: float = math.nan
    records: pd.DataFrame | None = field(default=None, repr=False)
    shocks: pd.DataFrame | None = field(default=None, repr=False)
    grid: Grid | None = field(default=None, repr=False)
    cycle: CycleFixedPoint | None = field(default=None, repr=False)

    def to_dict(self) -> dict:
        m = self.model
        return {
            "k0": m.k0, "k1": m.k1, "k2": m.k2, "zbar": m.zbar, "V": self.V, "regime": self.regime,
            "sigma_max": self.sigma_max, "sigma_min": self.sigma_min, "sigma_mean": self.sigma_mean,
            "sigma_before": self.sigma_before, "sigma_after": self.sigma_after, "period": self.period,
            "sigma_stderr": self.sigma_stderr, "shocks_per_cycle": self.shocks_per_cycle,
            "converged": self.converged,
            "message": self.message,
            "eps": self.eps, "t_end": self.t_end, "n_cycles": self.n_cycles, "wall_time": self.wall_time,
            "mass_error": self.mass_error, "min_mass": self.min_mass,
        }


@dataclass
class Critical:
    """The critical velocity from bisection: ``V_low`` is stick-slip, ``V_high`` steady."""

    model: Model
    Vc: float
    V_low: float
    V_high: float
    status: str
    message: str
    evaluations: list[dict]

    def to_dict(self) -> dict:
        m = self.model
        return {"k0": m.k0, "k1": m.k1, "k2": m.k2, "zbar": m.zbar, "Vc": self.Vc, "V_low": self.V_low,
                "V_high": self.V_high, "status": self.status, "message": self.message}


# ------------------------------------------------------------------------------ helpers
def _check_velocity(V: float, name: str = "V") -> float:
    V = float(V)
    if not (math.isfinite(V) and V > 0.0):
        raise ValueError(f"{name} must be a finite number > 0, got {V!r}")
    return V


def _initial_grid(model: Model, settings: GridSettings, V: float, initial) -> Grid:
    if isinstance(initial, Grid):
        if initial.model != model or initial.settings.eps != settings.eps:
            raise ValueError("initial grid was built for another model or bin width")
        grid = initial.copy()
        grid.settings = settings
        grid.prm[K.P_THETA_S] = settings.theta_shift
        grid.prm[K.P_THETA_R] = settings.theta_relax
        grid.prm[K.P_DT_MAX] = settings.dt_max
        return grid
    if initial == "auto":
        # frozen dashpots if a block jumps faster than the dashpots relax
        initial = "frozen" if V * 1.0 > model.gamma * model.zbar else "relaxed"
    return Grid(model, settings, initial=initial)


#: Peak-to-peak discretisation jitter of the stress, in units of k0 * eps (measured:
#: the standard deviation of the stress in steady sliding is about 0.15 k0 eps for
#: eps from 4e-3 to 1.6e-2 and k0 from 0.1 to 0.3, see docs/reference/micro_numerics.md).
JITTER = 1.0


def _jitter(model: Model, eps: float) -> float:
    """Peak-to-peak discretisation jitter of the stress: oscillations smaller than a
    few times this are not resolved by the grid."""
    return JITTER * model.k0 * eps


def _time_scales(model: Model, V: float) -> tuple[float, float, float]:
    """Relaxation time, cycle time of a block (zbar / V), loading time of a mean jump."""
    tau_u = 1.0 / model.gamma if model.gamma > 0.0 else math.inf
    tau_c = model.zbar / V
    tau_load = model.kappa * model.zbar / (model.k0 * V)
    return tau_u, tau_c, tau_load


#: A cycle without global shocks whose stress drop is below this many k0 * eps, or
#: below GRID_CYCLE_EPS * eps, may be an oscillation of the discretisation: seen with drops
#: of 2.2-5.6 k0 eps at large V (k0 = 1e-3, V = 175; k0 = 0.01, V = 1000), amplitudes
#: falling like eps^2, and near V^c of up to 1.6 eps (eps = 0.016) and 1.9 eps (0.008)
#: at both k0 = 0.1 and 0.3, amplitudes ~ eps (docs/validation/micro_results.md, docs/reference/micro_numerics.md §5).
MARGINAL_CYCLE = 10.0
GRID_CYCLE_EPS = 2.0


def _grid_limit(model: Model, eps: float) -> float:
    """Stress drop below which a smooth cycle may be the grid's own oscillation."""
    return min(MARGINAL_CYCLE * _jitter(model, eps), GRID_CYCLE_EPS * eps)


def _grid_sized(drop: float, shocks_per_cycle: float, limit: float) -> bool:
    """Whether a cycle may be the grid's own oscillation: smooth (no global shock, a
    cascade of more than 8 bins) and a stress drop below ``limit`` (:func:`_grid_limit`)."""
    return drop < limit and not shocks_per_cycle > 0.0


def _grid_note(drop: float, jitter: float) -> str:
    """The message for a cycle that may be the grid's own oscillation."""
    return (f"; its stress drop {drop:.3g} is only {drop / jitter:.2g} k0*eps, without global shocks: it may be "
            f"an oscillation of the grid (theirs shrink with eps), confirm at a finer eps")


def _shocks_per_cycle(shock_times: np.ndarray, cycles: pd.DataFrame) -> float:
    """Global shocks per cycle over ``cycles`` (from the first peak to the last)."""
    t0, t1 = float(cycles.t_start.iloc[0]), float(cycles.t_end.iloc[-1])
    return float(np.count_nonzero((shock_times >= t0) & (shock_times < t1)) / len(cycles))


# ------------------------------------------------------------------------------ simulate
def simulate(
    model: Model,
    drive: Drive | float,
    *,
    duration: float | None = None,
    numerics: Numerics | None = None,
    initial="auto",
    record_dsigma: float | None = None,
    record_dt: float | None = None,
    progress: bool = False,
) -> Run:
    """Run a driving protocol and return the stress time series.

    Parameters
    ----------
    model : the model.
    drive : a :class:`Drive`, or a constant velocity (then ``duration`` is required).
    numerics : bin and step limits.
    initial : ``"auto"``, ``"frozen"``, ``"relaxed"``, ``"uniform"`` (see :class:`~micro.grid.Grid`) or a :class:`~micro.grid.Grid` to
        start from (it is copied).
    record_dsigma, record_dt : record the stress whenever it has moved by
        ``record_dsigma`` and at least every ``record_dt`` (defaults from the model).
    progress : show a progress bar of the simulated time, with its ETA, on stderr (tqdm).
        A watcher thread reads the time while the kernel runs (the kernels release the
        GIL); the computation is the same with or without it.

    Returns
    -------
    Run
        ``records`` has columns ``t, w, sigma, sigma_min, sigma_max, sigma_mean`` (the
        extrema and time mean over the window since the previous row).
    """
    if not isinstance(drive, Drive):
        if duration is None:
            raise ValueError("duration is required when drive is a velocity")
        drive = Drive.uniform(float(drive), float(duration))
    numerics = numerics or Numerics()
    settings = numerics.settings(model)
    first_v = next((v for _, v in drive.segments if v > 0.0), 1.0)
    grid = _initial_grid(model, settings, first_v, initial)
    t0 = grid.t
    if record_dsigma is None:
        record_dsigma = 0.25 * _jitter(model, settings.eps)
    if record_dt is None:
        record_dt = drive.duration / 2000.0
    start = time.perf_counter()
    recs, shocks = [], []
    w0 = float(grid.fst[K.F_W])
    with _progress_watch(grid, t0, drive.duration, progress):
        for seg_start, seg_end, v in drive.boundaries():
            r, s, code = grid.advance(v, t0 + seg_end, record_dsigma=record_dsigma, record_dt=record_dt)
            recs.append(r)
            shocks.append(s)
    rec = np.concatenate(recs) if recs else np.zeros((0, 5))
    shk = np.concatenate(shocks) if shocks else np.zeros((0, 4))
    t_rel = rec[:, 0] - t0
    w = np.array([w0 + _drive_position(drive, tt) for tt in t_rel])
    records = pd.DataFrame({"t": t_rel, "w": w, "sigma": rec[:, 1], "sigma_min": rec[:, 2],
                            "sigma_max": rec[:, 3], "sigma_mean": rec[:, 4]})
    shock_frame = pd.DataFrame(shk - np.array([t0, 0.0, 0.0, 0.0]), columns=["t", "sigma_before", "sigma_after", "shift"])
    checks = _density_checks(grid)
    return Run(records=records, shocks=shock_frame, grid=grid, wall_time=time.perf_counter() - start, **checks)


@contextlib.contextmanager
def _progress_watch(grid: Grid, t0: float, duration: float, enabled: bool) -> Iterator[None]:
    """While the block runs, a daemon thread shows the simulated time of ``grid`` against
    ``duration`` as a tqdm bar (with its ETA); nothing if not ``enabled``."""
    if not enabled:
        yield
        return
    from tqdm.auto import tqdm

    done = threading.Event()

    def watch() -> None:
        with tqdm(total=float(duration), unit="t", desc="micro run", leave=False, mininterval=1.0,
                  bar_format="{desc}: {percentage:3.0f}% t = {n:.4g} of {total:.4g} "
                             "[{elapsed} elapsed, ETA {remaining}]") as bar:
            while not done.wait(0.5):
                now = min(max(float(grid.fst[K.F_T]) - t0, 0.0), float(duration))
                bar.update(now - bar.n)  # drawn at most once a second (mininterval)

    thread = threading.Thread(target=watch, name="micro-progress", daemon=True)
    thread.start()
    try:
        yield
    finally:
        done.set()
        thread.join()


def _drive_position(drive: Drive, t: float) -> float:
    w = 0.0
    for t0, t1, v in drive.boundaries():
        if t <= t0:
            break
        w += v * (min(t, t1) - t0)
    return w


# ------------------------------------------------------------------------------ stationary
#: The methods of :func:`stationary` and :func:`sweep`.
METHODS = ("auto", "fp", "cycle", "cohort")
#: Default bin of ``method="cycle"``, in units of a mean jump kappa * zbar.
CYCLE_EPS_FRACTION = 1.0 / 8.0


def _cycle(model: Model, V: float, numerics: Numerics, convergence: Convergence, warn: bool,
           start: CycleFixedPoint | None = None, method: str = "cycle") -> Stationary:
    """``stationary(method="cycle")`` and ``method="cohort"``: steady rows from the renewal
    chain, stick-slip rows from the fixed point of the shock-to-shock map
    (:mod:`micro.cycle`) or from the cohort method (:mod:`micro.cohort`), and the
    Fokker-Planck time-stepping where they do not apply (shocks that are not total,
    jumps that are not exponential)."""
    direct = _direct_steady(model, V)
    if direct is not None:
        return direct
    if method == "cohort":
        eps = numerics.eps if numerics.eps is not None else model.kappa * model.zbar / 20.0
    else:
        eps = numerics.eps if numerics.eps is not None else model.kappa * model.zbar * CYCLE_EPS_FRACTION
    tol = convergence.rtol * (model.f_th - sigma_fast_limit(model)) + convergence.atol
    fallback = "jumps are not exponential"
    if model.jumps.kind == KIND_EXPONENTIAL:
        if method == "cohort":
            res = cycle_cohorts(model, V, dt=numerics.cohort_dt, h=eps, tol=tol, start=start)
        else:
            res = cycle_fixed_point(model, V, eps, tol=tol, theta_shift=numerics.theta_shift,
                                    theta_relax=numerics.theta_relax, start=start)
        if res.applicable:
            if not res.converged and warn:
                log.warning("micro.stationary(k0=%g, V=%g, method=%r): %s", model.k0, V, method, res.message)
            return Stationary(
                model=model, V=V, eps=eps, regime="stick-slip", sigma_max=res.sigma_max, sigma_min=res.sigma_min,
                sigma_mean=res.sigma_mean, period=res.period, converged=res.converged, message=res.message,
                t_end=float(np.nansum(res.history[:, 2])) if res.history is not None else math.nan,
                n_cycles=res.iterations, wall_time=res.wall_time, sigma_stderr=res.error, shocks_per_cycle=1.0,
                mass_error=res.mass_error, min_mass=res.min_mass, cycle=res, sigma_before=res.sigma_before,
                sigma_after=res.sigma_after)
        fallback = res.message
    out = stationary(model, V, numerics=replace(numerics, eps=eps), convergence=convergence, warn=warn, method="fp")
    out.message = f"{method} method not applicable ({fallback}): Fokker-Planck time-stepping; {out.message}"
    return out


def _direct_steady(model: Model, V: float) -> Stationary | None:
    """The steady state from the renewal chain if steady sliding is stable at V, else None."""
    start = time.perf_counter()
    res = steady_sliding(model, V, growth_rate=False)
    if not bool(res.stable):
        return None
    sigma = float(res.sigma)
    return Stationary(
        model=model, V=V, eps=math.nan, regime="steady", sigma_max=sigma, sigma_min=sigma, sigma_mean=sigma,
        period=math.nan, converged=bool(res.converged),
        message=(f"steady sliding is stable (branching ratio {float(res.branching_ratio):.6g} < 1): "
                 f"stress from the renewal chain ({int(res.n_nodes)} nodes, error {float(res.sigma_error):.1e})"),
        t_end=0.0, n_cycles=0, wall_time=time.perf_counter() - start, sigma_stderr=float(res.sigma_error),
        shocks_per_cycle=0.0, mass_error=0.0, min_mass=0.0)


def stationary(
    model: Model,
    V: float,
    *,
    numerics: Numerics | None = None,
    convergence: Convergence | None = None,
    initial="auto",
    keep_records: bool = False,
    keep_grid: bool = False,
    warn: bool = True,
    method: str = "auto",
) -> Stationary:
    """The attractor at constant drive velocity ``V``: a steady stress or a stick-slip cycle.

    ``method="cycle"``: where steady sliding is unstable, the stick-slip cycle is the
    fixed point of its shock-to-shock return map (:func:`micro.cycle.cycle_fixed_point`):
    the state after a total global shock is Exp(kappa zbar) in delta times the marginal
    of delta_R, the Fokker-Planck grid carries it through one loading phase, and the
    shock is solved in closed form, so no shock is time-stepped and the cost per cycle
    does not grow as k0 falls (k0 = 1e-3 and 1e-4 cost what k0 = 0.01 does).  It stops
    when ``n = 10`` cycles show no drift and their mean is known to ``rtol * (f_th -
    sigma_fast_limit(model)) + atol`` (``sigma_stderr`` holds that error; 1e-3 with the
    defaults); the default bin is ``kappa * zbar / 8``.  Where shocks are not total (large
    k0, or close to V^c) or jumps are not exponential, it falls back to time-stepping
    and says so in ``message``.  ``result.cycle`` holds the fixed point; passing it as
    ``initial`` at a nearby V starts the map there (fewer cycles).

    ``method="cohort"``: the same rows from the cohort method
    (:func:`micro.cohort.cycle_cohorts`), which keeps no grid in the margin: the blocks
    born in one step are Exp(kappa zbar) in their margin at birth times a density in
    delta_R, every crossed mass is an exact integral, and where a shock starts is a
    continuous function of the state, so the cycles converge smoothly and are
    extrapolated (``eps`` is its delta_R cell, default ``kappa * zbar / 20``; time step
    0.01).  Shocks need not be total; it falls back to time-stepping only where jumps
    are not exponential or no shock ends a loading phase.  Continuation as with
    ``"cycle"``.

    ``method="auto"`` (the default) asks the renewal chain first
    (:func:`micro.steady_sliding`): where steady sliding is stable its stress is exact
    (to ~1e-11, in milliseconds) and no time-stepping is done; elsewhere, and whenever
    the Fokker-Planck state is wanted (``keep_grid``, ``keep_records`` or an ``initial``
    grid), the Fokker-Planck equation is time-stepped as with ``method="fp"``, which
    always time-steps.

    Time-stepping drives at constant ``V`` until the attractor's stress has converged,
    and stops there.

    A steady state is reached when the stress stays flat (within the jitter of the
    discretisation) and the means of ``n`` consecutive spans agree (see
    :class:`Convergence`); a stick-slip cycle when ``n`` consecutive cycles agree.  If
    neither happens by ``t_max`` the result says so (``converged=False``) and gives
    the last estimates, with the regime judged from the trend of the oscillation.
    That, and a converged cycle small enough to be the grid's, is also logged as a
    warning unless ``warn`` is False (for callers that report it themselves, such as
    :func:`critical_velocity`); ``converged`` and ``message`` say it either way.
    """
    V = _check_velocity(V)
    if method not in METHODS:
        raise ValueError(f"method must be one of {', '.join(repr(m) for m in METHODS)}, got {method!r}")
    numerics = numerics or Numerics()
    convergence = convergence or Convergence()
    if method in ("cycle", "cohort"):
        if not (isinstance(initial, CycleFixedPoint) or (isinstance(initial, str) and initial == "auto")):
            raise ValueError(f"with method={method!r}, initial must be 'auto' or a previous result's .cycle "
                             f"(a micro.cycle.CycleFixedPoint), got {type(initial).__name__}")
        return _cycle(model, V, numerics, convergence, warn,
                      start=initial if isinstance(initial, CycleFixedPoint) else None, method=method)
    settings = numerics.settings(model)
    wants_fp_state = keep_grid or keep_records or not (isinstance(initial, str) and initial == "auto")
    if method == "auto" and not wants_fp_state:
        direct = _direct_steady(model, V)
        if direct is not None:
            return direct
    grid = _initial_grid(model, settings, V, initial)
    start = time.perf_counter()

    tau_u, tau_c, tau_load = _time_scales(model, V)
    t_max = convergence.t_max
    if t_max is None:
        t_max = max(400.0 * tau_u if math.isfinite(tau_u) else 0.0, 60.0 * tau_load)
    jitter = _jitter(model, settings.eps)
    resolution = 0.25 * jitter  # records resolve the jitter...
    hysteresis = 2.0 * jitter  # ...but only wiggles above it count as cycles
    span = max(tau_u if math.isfinite(tau_u) else 0.0, 20.0 * tau_c)  # one averaging span
    chunk = max(span, min(tau_load, 0.05 * t_max))
    s_inf = sigma_fast_limit(model)
    n = convergence.n

    rec = Records.empty()
    shock_rows: list[np.ndarray] = []
    t_begin = grid.t
    regime, converged, message = "unknown", False, ""
    out: dict = {}
    while True:
        t_now = grid.t
        # (the last chunk may overshoot t_max; stopping exactly at t_max shortened the
        # runs of the phase diagram's coarse-bin bisection and flipped their labels,
        # see docs/validation/micro_results.md)
        r, s, code = grid.advance(V, t_now + chunk, record_dsigma=resolution, record_dt=span / 20.0)
        rec = rec.extend(Records.from_array(r))
        if len(s):
            shock_rows.append(s)
        t_now = grid.t
        elapsed = t_now - t_begin
        # --- a converged limit cycle?
        cycles = find_cycles(rec, hysteresis)
        if len(cycles) >= n and cycle_converged(cycles, convergence.rtol, convergence.atol + jitter, n):
            last = cycles.iloc[-n:]
            regime, converged = "stick-slip", True
            message = f"limit cycle converged over {n} cycles"
            drop = float((last.sigma_max - last.sigma_min).mean())
            per_cycle = _shocks_per_cycle(_shock_times(shock_rows), last)
            if _grid_sized(drop, per_cycle, _grid_limit(model, settings.eps)):
                message += _grid_note(drop, jitter)
                if warn:
                    log.warning("micro.stationary(k0=%g, V=%g): %s", model.k0, V, message)
            out = dict(sigma_max=float(last.sigma_max.mean()), sigma_min=float(last.sigma_min.mean()),
                       sigma_mean=float(last.sigma_mean.mean()), period=float(last.period.mean()),
                       sigma_stderr=float(last.sigma_mean.std(ddof=1) / math.sqrt(n)), shocks_per_cycle=per_cycle)
            break
        # --- a steady state?  No cycle in the last n spans, and span means that agree
        # within the tolerance plus their own statistical error (the jitter).
        if elapsed >= (n + 1) * span:
            t_from = t_now - n * span
            recent = cycles[cycles.t_end > t_from] if len(cycles) else cycles
            means, errors = _span_means(rec, t_from, span, n)
            # rtol of the velocity weakening, floored at rtol of the jitter (where the
            # weakening vanishes, e.g. k2 = 0, differences below the grid's resolution
            # carry no information)
            tol = convergence.rtol * (abs(float(np.mean(means)) - s_inf) + jitter) + convergence.atol
            agree = all(abs(means[i] - means[k]) <= tol + 2.0 * math.hypot(errors[i], errors[k])
                        for i in range(n) for k in range(i + 1, n))
            # a loading phase (blocks stuck, the stress rising at k0 V) can look flat when
            # k0 V span is below the tolerance: require the blocks to keep up with the drive
            loading = abs(means[-1] - means[0]) > 0.25 * model.k0 * V * (n - 1) * span
            if len(recent) == 0 and np.all(np.isfinite(means)) and agree and not loading:
                regime, converged = "steady", True
                message = f"steady: {n} span means agree within {tol:.3g} plus their statistical error"
                sigma = float(np.mean(means))
                out = dict(sigma_max=sigma, sigma_min=sigma, sigma_mean=sigma, period=math.nan,
                           sigma_stderr=float(math.sqrt(np.sum(np.square(errors))) / n))
                break
        if elapsed >= t_max or code != K.DONE:
            regime, message, out = _unconverged(rec, cycles, hysteresis, t_now, span, elapsed, t_max, code,
                                                load_rate=model.k0 * V, shock_times=_shock_times(shock_rows),
                                                grid_limit=_grid_limit(model, settings.eps))
            break
        # lengthen the chunks while no cycle has shown up (slow stick-slip)
        if len(cycles) == 0:
            chunk = min(2.0 * chunk, max(span, 0.25 * t_max))
        else:
            chunk = max(span, 2.0 * float(cycles.period.iloc[-1]))
    shocks = np.concatenate(shock_rows) if shock_rows else np.zeros((0, 4))
    result = Stationary(
        model=model, V=V, eps=settings.eps, regime=regime, converged=converged, message=message,
        t_end=grid.t - t_begin, n_cycles=int(len(find_cycles(rec, hysteresis))),
        wall_time=time.perf_counter() - start, **out, **_density_checks(grid),
    )
    if keep_records:
        result.records = rec.to_frame()
        result.shocks = pd.DataFrame(shocks, columns=["t", "sigma_before", "sigma_after", "shift"])
    if keep_grid:
        result.grid = grid
    if not converged and warn:
        log.warning("micro.stationary(k0=%g, V=%g): %s", model.k0, V, message)
    return result


#: Largest tolerated departure of the total probability from 1, and most negative cell
#: mass: both are round-off in an exact scheme (measured ~1e-13 and 0).
MASS_TOL = 1e-9


def _density_checks(grid: Grid) -> dict:
    """The density's total-probability error and most negative mass; warns if either
    is more than round-off."""
    mass_error = abs(grid.mass() - 1.0)
    min_mass = min(grid.min_mass(), 0.0)
    if not (mass_error <= MASS_TOL and min_mass >= -MASS_TOL):
        log.warning("micro: density check failed: |mass - 1| = %.3g, most negative cell mass %.3g",
                    mass_error, min_mass)
    return {"mass_error": mass_error, "min_mass": min_mass}


def _span_means(rec: Records, start: float, span: float, n: int, parts: int = 8) -> tuple[np.ndarray, np.ndarray]:
    """Time means of ``n`` consecutive spans from ``start``, and their standard errors
    from ``parts`` sub-spans each."""
    means = np.empty(n)
    errors = np.empty(n)
    for i in range(n):
        a = start + i * span
        sub = np.array([rec.time_mean(a + p * span / parts, a + (p + 1) * span / parts) for p in range(parts)])
        sub = sub[np.isfinite(sub)]
        means[i] = rec.time_mean(a, a + span)
        errors[i] = float(np.std(sub, ddof=1) / math.sqrt(sub.size)) if sub.size > 2 else math.inf
    return means, errors


def _amplitude_trend(amp: np.ndarray) -> tuple[float, bool]:
    """Per-cycle ratio of the cycle amplitudes ``amp`` and whether they clearly decay.

    With at least 6 cycles in the later half of the run, the ratio is the slope of
    log(amplitude) over that half, and the decay counts only if the slope is negative by
    more than twice its standard error and the amplitude fell by 5 % over the half: a
    limit cycle whose amplitude fluctuates with the grid (by ~1 % from cycle to cycle)
    was called steady from three falling amplitudes (k0 = 0.3, V = 0.135, eps = 0.008:
    a cycle of 0.048, as in the N-block).  With fewer cycles, the ratio of the last three.
    """
    k = max(3, amp.size // 2)
    a = amp[-k:]
    if k < 6 or not np.all(a > 0.0):
        ratio = float(a[-1] / a[-3]) ** 0.5 if a[-3] > 0 else math.nan
        return ratio, ratio < 0.999
    fit = linregress(np.arange(k), np.log(a))
    ratio = float(math.exp(fit.slope))
    return ratio, bool(fit.slope + 2.0 * fit.stderr < 0.0 and ratio ** k < 0.95)


def _shock_times(shock_rows: list[np.ndarray]) -> np.ndarray:
    return np.concatenate([s[:, 0] for s in shock_rows]) if shock_rows else np.zeros(0)


def _unconverged(rec: Records, cycles: pd.DataFrame, hysteresis: float, t_now: float, span: float,
                 elapsed: float, t_max: float, code: int, load_rate: float,
                 shock_times: np.ndarray | None = None, grid_limit: float = 0.0) -> tuple[str, str, dict]:
    """Regime and best estimates of a run that did not meet its stopping test (cycles
    smaller than ``grid_limit`` without shocks are flagged as possibly the grid's)."""
    why = f"not converged by t_max = {t_max:.4g}" if code == K.DONE else f"stopped early (kernel code {code})"
    if len(cycles) >= 3:
        amp = (cycles.sigma_max - cycles.sigma_min).to_numpy()
        last = cycles.iloc[-3:]
        ratio, decays = _amplitude_trend(amp)
        # a stick-slip transient also decays, but towards a finite cycle: extrapolate the
        # amplitudes geometrically (Aitken) when they fall monotonically and are well
        # above the grid's resolution (near V^c the amplitudes are noise-dominated)
        d1, d2 = amp[-2] - amp[-3], amp[-1] - amp[-2]
        limit = math.nan
        if d1 < 0.0 and d2 < 0.0 and d2 / d1 < 1.0 and amp[-1] > 20.0 * hysteresis:
            limit = float(amp[-1] - d2 * (d2 / d1) / (1.0 - d2 / d1))
        towards_cycle = limit > 0.5 * amp[-1]
        if decays and not towards_cycle:
            detail = f"; the oscillation decays by {ratio:.4f} per cycle (steady attractor)"
            sigma = rec.time_mean(float(last.t_start.iloc[0]), float(last.t_end.iloc[-1]))
            return "steady", why + detail, dict(sigma_max=sigma, sigma_min=sigma, sigma_mean=sigma, period=math.nan)
        if decays:
            detail = f"; the oscillation decays towards a cycle of amplitude {limit:.3g} (stick-slip attractor)"
        else:
            detail = f"; the oscillation persists (amplitude ratio {ratio:.4f} per cycle)"
        drop = float((last.sigma_max - last.sigma_min).mean())
        per_cycle = _shocks_per_cycle(np.zeros(0) if shock_times is None else shock_times, last)
        if _grid_sized(drop, per_cycle, grid_limit):
            detail += _grid_note(drop, 0.5 * hysteresis)  # (hysteresis = 2 k0 eps)
        return "stick-slip", why + detail, dict(sigma_max=float(last.sigma_max.mean()), sigma_min=float(last.sigma_min.mean()),
                                                sigma_mean=float(last.sigma_mean.mean()), period=float(last.period.mean()),
                                                shocks_per_cycle=per_cycle)
    sigma = rec.time_mean(t_now - span, t_now)
    lo = rec.since(t_now - span)
    amplitude = float(lo.sigma_max.max() - lo.sigma_min.min()) if len(lo) else math.nan
    rise = float(lo.sigma[-1] - lo.sigma[0]) if len(lo) else math.nan
    if rise > 0.25 * load_rate * span:  # blocks lag the drive: still loading towards a slip
        return "unknown", why + f"; still loading (the stress rose {rise:.3g} over the last span)", dict(
            sigma_max=float(lo.sigma_max.max()), sigma_min=float(lo.sigma_min.min()), sigma_mean=sigma, period=math.nan)
    regime = "steady" if amplitude <= 4.0 * hysteresis else "unknown"
    return regime, why + f"; last span amplitude {amplitude:.3g}", dict(
        sigma_max=sigma if regime == "steady" else float(lo.sigma_max.max()),
        sigma_min=sigma if regime == "steady" else float(lo.sigma_min.min()),
        sigma_mean=sigma, period=math.nan)


# ------------------------------------------------------------------------------ critical velocity
def _bisection_label(res: Stationary) -> str:
    """The regime the bisection goes by without the check at a finer bin: a smooth cycle
    (no global shock) whose stress drop is below ``min(MARGINAL_CYCLE * k0 * eps,
    GRID_CYCLE_EPS * eps)`` counts as steady (the grid cannot tell it from its own
    oscillations, whose amplitude scales with eps)."""
    if res.regime == "stick-slip" and _grid_sized(res.sigma_max - res.sigma_min, res.shocks_per_cycle,
                                                  _grid_limit(res.model, res.eps)):
        return "steady"
    return res.regime


#: With ``refine``, an oscillation is taken for the grid's when its amplitude at eps / 2
#: is below this fraction of its amplitude at eps.  Measured stepping down from steady
#: sliding (docs/reference/micro_numerics.md, section 5): physical cycles keep 0.77-1.0 of their
#: amplitude when eps halves (k0 = 0.1, V <= 0.7; k0 = 0.3, V <= 0.15), the grid's keep
#: 0.31-0.65 (k0 = 0.1, V >= 0.75; k0 = 0.3, V >= 0.2), where the N-block has no cycle.
REFINE_RATIO = 0.7


def _cycle_amplitude(res: Stationary) -> float:
    """Median stress drop of the cycles in the later half of a run with records; the
    run's own ``sigma_max - sigma_min`` if fewer than two cycles lie there (a slow cycle
    converged early); 0 for a steady run."""
    if res.regime == "steady":
        return 0.0
    own = float(res.sigma_max - res.sigma_min)
    own = own if math.isfinite(own) else 0.0
    if res.records is None or len(res.records) < 3:
        return own
    rec = Records.from_array(res.records[["t", "sigma", "sigma_min", "sigma_max", "sigma_mean"]].to_numpy())
    rec = rec.since(0.5 * (rec.t[0] + rec.t[-1]))
    cycles = find_cycles(rec, 2.0 * _jitter(res.model, res.eps))
    if len(cycles) < 2:
        return own
    return float(np.median(cycles.sigma_max - cycles.sigma_min))


def critical_velocity(
    model: Model,
    *,
    V_min: float = 1e-4,
    V_max: float | None = None,
    V_guess: float = 1.0,
    factor: float = 8.0,
    rel_tol: float = 1e-2,
    numerics: Numerics | None = None,
    convergence: Convergence | None = None,
    refine: bool = True,
    method: str = "renewal",
) -> Critical:
    """Critical velocity V^c: where steady sliding loses stability.

    ``method="renewal"`` (the default) solves it directly: V^c is the root of
    ``b(V) = 1``, the branching ratio of steady sliding from the renewal chain
    (:func:`micro.steady_sliding`; derivation in docs/reference/micro_renewal.md), to ~1e-10
    relative in a fraction of a second.  ``V_min`` and ``V_max`` (default 1e7 here, 1e3
    for the bisection) bound the search; the other options belong to ``method="fp"``.
    ``k0 >= k2``: Vc = 0 at once (steady sliding is stable at every V).  ``V_low`` and
    ``V_high`` are ``Vc`` minus and plus its error estimate.

    ``method="fp"``: bisection on the regime of Fokker-Planck runs (the paper's
    Appendix B), kept for cross-checks.

    The regime is evaluated at ``V_guess``, then at velocities ``factor`` times smaller
    or larger (within ``[V_min, V_max]``) until it changes; the bracket is then halved
    geometrically until ``V_high / V_low - 1 <= rel_tol``.  If the
    system is steady already at ``V_min`` (e.g. ``k0 >= k2``), ``Vc`` is reported as 0
    with status ``"no stick-slip"``; if it is stick-slip at ``V_max``, as ``inf`` with
    status ``"above range"``.

    V^c is where steady sliding loses stability, and each evaluation is decided from
    close to it: a run below the slowest velocity found steady so far starts from that
    run's final density (a small velocity step from a steady state), not from a fresh
    one whose large transient decays ever more slowly near V^c.

    Near V^c the grid itself sustains smooth oscillations of up to ~2 eps (the jitter of
    the stress drives the weakly damped mode), which a bisection on the regime would
    take for stick-slip.  With ``refine`` (the default) an oscillation whose median
    stress drop is below ``GRID_CYCLE_EPS * eps`` is run again at eps / 2, stepped down
    from steady sliding at eps / 2 in the same way, and counts as stick-slip only if it
    keeps at least ``REFINE_RATIO`` (0.7) of its amplitude: a physical cycle converges
    in eps, the grid's shrinks with it.  A check costs 7-12 runs at eps, and near V^c
    most runs need one.  Measured against the N-block's V^c (0.70-0.75 at k0 = 0.1,
    0.19-0.21 at k0 = 0.3): 0.73 and 0.186 at eps = 0.016 (docs/reference/micro_numerics.md,
    section 5).  Without ``refine`` a cycle counts as stick-slip only if it has global
    shocks or a stress drop of at least ``min(MARGINAL_CYCLE * k0 * eps, GRID_CYCLE_EPS *
    eps)``, which is cheaper but leaves V^c the discretisation error of the cycle near
    threshold (k0 = 0.1: 0.90 and 0.84 at eps = 0.016 and 0.008) and, at coarse bins,
    takes small physical cycles for the grid's.

    Runs that miss their stopping test (near V^c most do) are reported in one warning
    when the bisection ends, not each by its own; every run is logged at INFO.

    ``evaluations`` records each run, with the ``label`` the bisection used, the
    velocity it ``started_from``, its median cycle ``amplitude`` and, where checked,
    ``amplitude_fine`` at eps / 2 and the ``wall_time_fine`` of the runs at eps / 2 it
    took (NaN otherwise; ``amplitude`` is NaN without ``refine``).
    """
    if method not in ("renewal", "fp"):
        raise ValueError(f"method must be 'renewal' or 'fp', got {method!r}")
    V_min = _check_velocity(V_min, "V_min")
    V_max = _check_velocity((1e7 if method == "renewal" else 1e3) if V_max is None else V_max, "V_max")
    if not V_max > V_min:
        raise ValueError(f"V_max must be > V_min, got V_min={V_min!r}, V_max={V_max!r}")
    V_guess = _check_velocity(V_guess, "V_guess")
    if not (math.isfinite(factor) and factor > 1.0):
        raise ValueError(f"factor must be a finite number > 1, got {factor!r}")
    if not (math.isfinite(rel_tol) and 0.0 < rel_tol < 1.0):
        raise ValueError(f"rel_tol must be in (0, 1), got {rel_tol!r}")
    if method == "renewal":
        Vc, error, status, message, evaluations = critical_velocity_renewal(model, V_min=V_min, V_max=V_max)
        low, high = (Vc - error, Vc + error) if math.isfinite(Vc) and Vc > 0.0 else (
            (0.0, V_min) if Vc == 0.0 else (V_max, math.inf))
        if status != "converged":
            log.info("micro.critical_velocity(k0=%g, k1=%g, k2=%g): %s", model.k0, model.k1, model.k2, message)
        return Critical(model, Vc, low, high, status, message, evaluations)
    if model.k2 == 0.0 or model.k0 >= model.k2:
        # closed form: steady sliding is stable at every V, nothing to bisect
        return _reported(Critical(model, 0.0, 0.0, V_min, "no stick-slip",
                                  f"k0 = {model.k0:g} >= k2 = {model.k2:g}: steady sliding is stable at every V "
                                  "(branching ratio below 1), no stick-slip", []))
    evaluations: list[dict] = []

    convergence = convergence or Convergence()
    numerics = numerics or Numerics()
    eps = numerics.settings(model).eps
    fine_numerics = replace(numerics, eps=0.5 * eps)
    # the slowest velocity decided steady, with its final density, at eps and at eps / 2
    slowest_steady: dict = {"V": math.inf, "grid": None}
    fine_steady: dict = {"V": math.inf, "grid": None}

    def run(V: float, conv: Convergence, num: Numerics, chain: dict) -> tuple[Stationary, float]:
        """A run at V, from the chain's steady state if it is faster than V."""
        started_from = chain["V"] if V < chain["V"] and chain["grid"] is not None else math.nan
        res = stationary(model, V, numerics=num, convergence=conv, keep_grid=True, keep_records=refine,
                         initial=chain["grid"] if math.isfinite(started_from) else "auto", warn=False)
        return res, started_from

    def regime(V: float) -> str:
        conv = convergence
        if conv.t_max is None:
            # Only the regime is needed: near V^c the finite-eps dynamics is a noisy
            # oscillation that never meets the stopping test, and its trend is clear
            # well before the default t_max.
            tau_u, _, tau_load = _time_scales(model, V)
            t_max = max(100.0 * tau_u if math.isfinite(tau_u) else 0.0, 30.0 * tau_load)
            conv = Convergence(rtol=conv.rtol, atol=conv.atol, n=conv.n, t_max=t_max)
        res, started_from = run(V, conv, numerics, slowest_steady)
        amplitude, fine_amplitude, fine_wall = math.nan, math.nan, math.nan
        if not refine:
            label = _bisection_label(res)
        else:
            label = res.regime
            amplitude = _cycle_amplitude(res)
            if res.regime == "stick-slip" and amplitude < GRID_CYCLE_EPS * eps:
                # too small to tell from the grid's own oscillation: does it survive at eps / 2?
                fine_wall = 0.0
                if fine_steady["grid"] is None and math.isfinite(slowest_steady["V"]):
                    base, _ = run(slowest_steady["V"], conv, fine_numerics, fine_steady)
                    fine_steady.update(V=slowest_steady["V"], grid=base.grid)
                    fine_wall += base.wall_time
                fine, _ = run(V, conv, fine_numerics, fine_steady)
                fine_wall += fine.wall_time
                fine_amplitude = _cycle_amplitude(fine)
                if fine_amplitude < REFINE_RATIO * amplitude:
                    label = "steady"
                    if V < fine_steady["V"]:
                        fine_steady.update(V=V, grid=fine.grid)
        if label == "steady" and V < slowest_steady["V"]:
            slowest_steady.update(V=V, grid=res.grid)
        evaluations.append(dict(res.to_dict(), label=label, started_from=started_from, amplitude=amplitude,
                                amplitude_fine=fine_amplitude, wall_time_fine=fine_wall))
        log.info("bisection k0=%g V=%.6g -> %s (%s; amplitude %.3g, at eps/2 %.3g)", model.k0, V, label,
                 res.message, amplitude, fine_amplitude)
        return label

    # Bracket by expanding geometrically from V_guess: evaluations far from V^c are
    # the expensive ones (cost grows like V at large V and like 1/V at small V).
    V = min(max(V_guess, V_min), V_max)
    steady = regime(V) == "steady"
    lo, hi = (V_min, V) if steady else (V, V_max)
    while True:
        if steady:
            if V <= V_min:
                return _reported(Critical(model, 0.0, 0.0, V_min, "no stick-slip",
                                          f"steady already at V_min = {V_min:g}", evaluations))
            V = max(V / factor, V_min)
            if regime(V) != "steady":
                lo = V
                break
            hi = V
        else:
            if V >= V_max:
                return _reported(Critical(model, math.inf, V_max, math.inf, "above range",
                                          f"not steady at V_max = {V_max:g}", evaluations))
            V = min(V * factor, V_max)
            if regime(V) == "steady":
                hi = V
                break
            lo = V
    while hi / lo - 1.0 > rel_tol:
        mid = math.sqrt(lo * hi)
        if regime(mid) == "steady":
            hi = mid
        else:
            lo = mid
    return _reported(Critical(model, math.sqrt(lo * hi), lo, hi, "converged",
                              f"bracket [{lo:.6g}, {hi:.6g}] within rel_tol {rel_tol:g}", evaluations))


def _reported(crit: Critical) -> Critical:
    """``crit``, after one warning for the bisection's runs that missed their stopping
    test (near V^c most do: the damping vanishes there).  The runs themselves do not
    warn; each is logged at INFO and recorded in ``crit.evaluations``."""
    missed = [e for e in crit.evaluations if not e["converged"]]
    if missed:
        log.warning("micro.critical_velocity(k0=%g, k1=%g, k2=%g): %s (%s); %d of %d runs did not converge by "
                    "their t_max and were labelled from the trend of their oscillation (V = %s; see "
                    "Critical.evaluations)", crit.model.k0, crit.model.k1, crit.model.k2, crit.status, crit.message,
                    len(missed), len(crit.evaluations), ", ".join(f"{e['V']:.4g}" for e in missed))
    return crit


# ------------------------------------------------------------------------------ sweep
def sweep(
    model: Model,
    velocities,
    *,
    numerics: Numerics | None = None,
    convergence: Convergence | None = None,
    continuation: bool = True,
    method: str = "auto",
) -> pd.DataFrame:
    """Stationary states for each velocity, one row each.

    With ``method="auto"`` a velocity where steady sliding is stable takes its row from
    the renewal chain (no time-stepping); the others are Fokker-Planck runs
    (``method="fp"``: all of them).  ``method="cycle"``: stick-slip rows from the
    return map's fixed point (see :func:`stationary`), each started, with
    ``continuation``, from the previous row's (10-15 cycles instead of 20-35).  With ``continuation`` every Fokker-Planck run starts
    from the previous run's final density (points are visited in the given order),
    which shortens transients.
    """
    if method not in METHODS:
        raise ValueError(f"method must be one of {', '.join(repr(m) for m in METHODS)}, got {method!r}")
    velocities = [_check_velocity(V) for V in velocities]
    rows = []
    grid = None
    start = None
    for V in velocities:
        if method in ("cycle", "cohort"):
            res = stationary(model, V, numerics=numerics, convergence=convergence, method=method,
                             initial=start if (continuation and start is not None) else "auto")
            start = res.cycle if res.cycle is not None and res.cycle.applicable else start
            rows.append(res.to_dict())
            continue
        direct = _direct_steady(model, V) if method == "auto" else None
        if direct is not None:
            rows.append(direct.to_dict())
            continue
        res = stationary(model, V, numerics=numerics, convergence=convergence, method="fp",
                         initial=grid if (continuation and grid is not None) else "auto", keep_grid=continuation)
        grid = res.grid
        res.grid = None
        rows.append(res.to_dict())
    return pd.DataFrame(rows)


# ------------------------------------------------------------------------------ slide-hold-slide
def slide_hold_slide(
    model: Model,
    V: float,
    hold_times,
    *,
    numerics: Numerics | None = None,
    convergence: Convergence | None = None,
    resume: float | None = None,
) -> pd.DataFrame:
    """Stress peak after a hold, for each hold time (the paper's Fig. 7).

    Drives at ``V`` until stationary (steady sliding is required), then for each hold
    time: stop the drive for ``hold``, resume at ``V`` for ``resume`` (default: 20
    cycle times plus 2 relaxation times), and record the largest stress after
    resuming.  One stationary run serves every hold time.  Returns ``hold_time,
    sigma_steady, sigma_peak, delta_sigma_max`` per hold.
    """
    V = _check_velocity(V)
    holds = [float(h) for h in np.atleast_1d(hold_times)]
    for h in holds:
        if not (math.isfinite(h) and h >= 0.0):
            raise ValueError(f"hold times must be finite numbers >= 0, got {h!r}")
    base = stationary(model, V, numerics=numerics, convergence=convergence, keep_grid=True, method="fp")
    if base.regime != "steady":
        raise ValueError(f"slide-hold-slide needs steady sliding at V = {V:g}; the attractor is {base.regime}")
    tau_u, tau_c, _ = _time_scales(model, V)
    if resume is None:
        resume = 20.0 * tau_c + (2.0 * tau_u if math.isfinite(tau_u) else 0.0)
    settings = base.grid.settings
    resolution = 0.25 * _jitter(model, settings.eps)
    rows = []
    for h in holds:
        grid = base.grid.copy()
        t0 = grid.t
        if h > 0.0:
            grid.advance(0.0, t0 + h, record_dsigma=resolution, record_dt=max(h, 1e-300) / 50.0)
        r, _, _ = grid.advance(V, grid.t + resume, record_dsigma=resolution / 4.0, record_dt=resume / 400.0)
        peak = float(max(r[:, 3].max(), r[:, 1].max())) if len(r) else math.nan
        rows.append({"hold_time": h, "sigma_steady": base.sigma_mean, "sigma_peak": peak,
                     "delta_sigma_max": peak - base.sigma_mean})
    return pd.DataFrame(rows)
