"""The Fokker-Planck method: the equation for P(delta_F, delta_R) at finite driving
velocity (the paper's Appendix B), time-stepped on the grid of :mod:`micro.grid` by the
kernels of :mod:`micro._fp_kernels`.

The fallback of :mod:`micro`'s question-level API (:mod:`micro.api`): it runs where no
better method applies (non-exponential jumps), and wherever the density itself is asked
for (a protocol's transient, a slide-hold-slide, a state to continue).
``simulate_fp`` runs a driving protocol and returns the stress time series;
``stationary_fp`` drives at constant V until the requested quantity has converged (a
steady stress, or the extrema of a stick-slip cycle) and stops there;
``critical_velocity_fp`` bisects on the regime, as in the paper's Appendix B;
``slide_hold_slide_fp`` holds and resumes from one steady state.
"""
from __future__ import annotations

import contextlib
import logging
import math
import threading
import time
from dataclasses import replace
from typing import Iterator

import numpy as np
import pandas as pd

from . import _fp_kernels as K
from . import _progress
from ._progress import Interrupted
from .analysis import Records, cycle_converged, find_cycles
from .analytic import sigma_fast_limit
from .grid import Grid, GridSettings
from .params import Model
from .protocols import Drive
from .methods import Convergence, Numerics, check_velocity as _check_velocity
from .results import ABOVE, BELOW, Critical, Run, Stationary


__all__ = ["simulate_fp", "stationary_fp", "critical_velocity_fp", "slide_hold_slide_fp"]

log = logging.getLogger(__name__)

# ------------------------------------------------------------------------------ helpers
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
def simulate_fp(
    model: Model,
    drive: Drive | float,
    *,
    duration: float | None = None,
    numerics: Numerics | None = None,
    initial="auto",
    record_dsigma: float | None = None,
    record_dt: float | None = None,
    progress: bool = False,
    max_wall_time: float | None = None,
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
    max_wall_time : the longest the run may take, in seconds (default: no bound).  Once it
        has computed for :data:`PACE_AFTER` seconds, a run whose wall time projected at its
        pace so far exceeds this stops with a :class:`TooLong` error (a ``ValueError``)
        that gives the longest duration the bound allows: the pace is measured, not
        derived (the step depends on how hard the dashpots pull near the threshold).

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

    def run_so_far(checks: bool = True) -> Run:
        rec = np.concatenate(recs) if recs else np.zeros((0, 5))
        shk = np.concatenate(shocks) if shocks else np.zeros((0, 4))
        t_rel = rec[:, 0] - t0
        w = np.array([w0 + _drive_position(drive, tt) for tt in t_rel])
        records = pd.DataFrame({"t": t_rel, "w": w, "sigma": rec[:, 1], "sigma_min": rec[:, 2],
                                "sigma_max": rec[:, 3], "sigma_mean": rec[:, 4]})
        shock_frame = pd.DataFrame(shk - np.array([t0, 0.0, 0.0, 0.0]),
                                   columns=["t", "sigma_before", "sigma_after", "shift"])
        # (an interrupted run skips the density's checks: seconds on a large grid)
        found = _density_checks(grid) if checks else {"mass_error": math.nan, "min_mass": math.nan}
        return Run(records=records, shocks=shock_frame, grid=grid, wall_time=time.perf_counter() - start, **found)

    def pace() -> None:
        elapsed, done = time.perf_counter() - start, grid.t - t0
        if elapsed < PACE_AFTER or not done > 0.0:
            return
        projected = elapsed * drive.duration / done
        if projected > max_wall_time:
            raise TooLong(f"duration {drive.duration:g} would take about {_hours(projected)} at the pace of the "
                          f"first {elapsed:.1f} s (t = {done:.3g} done), more than the {_hours(max_wall_time)} "
                          f"allowed; give a duration <= {drive.duration * max_wall_time / projected:.3g}")

    try:
        with _progress_watch(grid, t0, drive.duration, progress), \
                _progress.stage(lambda: _time_done(grid.t - t0, drive.duration, start)):
            for seg_start, seg_end, v in drive.boundaries():
                r, s, code = grid.advance(v, t0 + seg_end, record_dsigma=record_dsigma, record_dt=record_dt,
                                          watch=None if max_wall_time is None else pace)
                recs.append(r)
                shocks.append(s)
    except KeyboardInterrupt as stop:
        # Ctrl-C: the records so far (those of the interrupted segment included) as a Run
        partial = getattr(stop, "partial", {})
        recs.append(partial.get("records", np.zeros((0, 5))))
        shocks.append(partial.get("shocks", np.zeros((0, 4))))
        raise Interrupted(run=run_so_far(checks=False)) from None
    return run_so_far()


#: ``max_wall_time``: the seconds of computing after which the pace is judged.
PACE_AFTER = 1.0


class TooLong(ValueError):
    """A run whose projected wall time exceeds its ``max_wall_time``."""


def _hours(seconds: float) -> str:
    return f"{seconds / 3600.0:.3g} h" if seconds >= 3600.0 else f"{seconds:.3g} s"


def _time_done(t: float, total: float, start: float) -> str:
    """``t = 3.2 of 20 (16 %), ETA 41 s``: simulated time against its end, the ETA at the
    mean rate so far."""
    t = min(max(t, 0.0), total)
    elapsed = time.perf_counter() - start
    eta = f", ETA {elapsed * (total - t) / t:.0f} s" if t > 0.0 else ""
    return f"t = {t:.4g} of {total:.4g} ({100.0 * t / total:.0f} %){eta}"


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
def stationary_fp(
    model: Model,
    V: float,
    *,
    numerics: Numerics | None = None,
    convergence: Convergence | None = None,
    initial="auto",
    keep_records: bool = False,
    keep_grid: bool = False,
    warn: bool = True,
) -> Stationary:
    """The attractor at constant drive velocity ``V`` by time-stepping the Fokker-Planck
    equation (``micro.stationary(method="fp")``): a steady stress or a stick-slip cycle.

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
    numerics = numerics or Numerics()
    convergence = convergence or Convergence()
    settings = numerics.settings(model)
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
        with _progress.stage(lambda: f"Fokker-Planck V={V:g} eps={settings.eps:g}: t = {grid.t - t_begin:.4g} "
                                     f"of at most {t_max:.4g}"):
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
        wall_time=time.perf_counter() - start, **out, **_density_checks(grid), method="fp",
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
    slope, stderr = _slope(np.log(a))
    ratio = float(math.exp(slope))
    return ratio, bool(slope + 2.0 * stderr < 0.0 and ratio ** k < 0.95)


def _slope(y: np.ndarray) -> tuple[float, float]:
    """The least-squares slope of ``y`` against 0, 1, 2, ... and its standard error (what
    ``scipy.stats.linregress`` gives, without importing scipy.stats, 0.35 s of every
    command's start-up)."""
    x = np.arange(y.size, dtype=float)
    x -= x.mean()
    sxx = float(x @ x)
    slope = float(x @ (y - y.mean())) / sxx
    resid = y - y.mean() - slope * x
    return slope, math.sqrt(float(resid @ resid) / (y.size - 2) / sxx)


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
        sigma_mean = float(last.sigma_mean.mean())
        if _grid_sized(drop, per_cycle, grid_limit):
            detail += _grid_note(drop, 0.5 * hysteresis)  # (hysteresis = 2 k0 eps)
            # the grid's oscillation is irregular, not a cycle: its mean stress is the time
            # mean over the run's later half, not over its last three peaks (measured against
            # runs of 480 time units: within 2e-5 where the three peaks are 1e-4 off;
            # docs/validation/micro_defaults.md, "Fig. 10")
            sigma_mean = rec.time_mean(t_now - 0.5 * elapsed, t_now)
            detail += "; sigma_mean is the time mean over the run's later half"
        return "stick-slip", why + detail, dict(sigma_max=float(last.sigma_max.mean()), sigma_min=float(last.sigma_min.mean()),
                                                sigma_mean=sigma_mean, period=float(last.period.mean()),
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


def critical_velocity_fp(
    model: Model,
    *,
    V_min: float,
    V_max: float,
    V_guess: float = 1.0,
    factor: float = 8.0,
    rel_tol: float = 1e-2,
    numerics: Numerics | None = None,
    convergence: Convergence | None = None,
    refine: bool = True,
) -> Critical:
    """Critical velocity V^c by bisection on the regime of Fokker-Planck runs (the paper's
    Appendix B; ``micro.critical_velocity(method="fp")``), kept for cross-checks: the
    default, the renewal chain's root of b(V) = 1, is exact.  The arguments are checked
    by :func:`micro.critical_velocity`.

    The regime is evaluated at ``V_guess``, then at velocities ``factor`` times smaller
    or larger (within ``[V_min, V_max]``) until it changes; the bracket is then halved
    geometrically until ``V_high / V_low - 1 <= rel_tol``.  If the
    system is steady already at ``V_min`` (e.g. ``k0 >= k2``), ``Vc`` is reported as NaN
    with status ``"V^c below V_min"``; if it is stick-slip at ``V_max``, as ``inf`` with
    status ``"V^c above V_max"``.

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
    if model.k2 == 0.0 or model.k0 >= model.k2:
        # closed form: steady sliding is stable at every V, nothing to bisect
        return _reported(Critical(model, math.nan, 0.0, V_min, "no stick-slip",
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
        with _progress.stage(f"bisection k0={model.k0:g}: run {len(evaluations) + 1} at V = {V:.6g}"):
            res = stationary_fp(model, V, numerics=num, convergence=conv, keep_grid=True, keep_records=refine,
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
                return _reported(Critical(model, math.nan, 0.0, V_min, BELOW,
                                          f"steady already at V_min = {V_min:g}: V^c lies below V_min", evaluations))
            V = max(V / factor, V_min)
            if regime(V) != "steady":
                lo = V
                break
            hi = V
        else:
            if V >= V_max:
                return _reported(Critical(model, math.inf, V_max, math.inf, ABOVE,
                                          f"not steady at V_max = {V_max:g}: V^c lies above V_max", evaluations))
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
    crit.method = "fp"
    missed = [e for e in crit.evaluations if not e["converged"]]
    if missed:
        log.warning("micro.critical_velocity(k0=%g, k1=%g, k2=%g): %s (%s); %d of %d runs did not converge by "
                    "their t_max and were labelled from the trend of their oscillation (V = %s; see "
                    "Critical.evaluations)", crit.model.k0, crit.model.k1, crit.model.k2, crit.status, crit.message,
                    len(missed), len(crit.evaluations), ", ".join(f"{e['V']:.4g}" for e in missed))
    return crit


# ------------------------------------------------------------------------------ slide-hold-slide
def slide_hold_slide_fp(
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
    base = stationary_fp(model, V, numerics=numerics, convergence=convergence, keep_grid=True)
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
                     "delta_sigma_max": peak - base.sigma_mean, "method": "fp"})
    return pd.DataFrame(rows)
