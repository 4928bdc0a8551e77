r"""An independent check of the Fokker-Planck solver: the mean-field N-block model itself.

N blocks at positions :math:`h_i` with dashpot elongations :math:`u_i` follow the mean-field
limit of Eqs. (1)-(2) of Landes, Rosso & Jagla (2015) in the narrow-wells approximation
with instantaneous avalanches (:math:`\tau_0 \to 0`):

.. math::
    \eta_0 \partial_t h_i &= k_0 (w - h_i) + (k_1 + k_2)(\bar h - h_i) - k_2 u_i + f_i^{dis}(h_i) \\
    \eta_u \partial_t u_i &= k_2 (\bar h - h_i) - k_2 u_i, \qquad \sigma = k_0 (w - \bar h) \quad (3)

A block is pinned while :math:`\delta_i = f_{th} - k_0(w - h_i) - (k_1+k_2)(\bar h - h_i) + k_2 u_i > 0`
(Eq. (B1)); when :math:`\delta_i \le 0` it jumps to its next well, :math:`h_i \to h_i + z`
with z drawn from :math:`g(z)`, and :math:`u_i` does not change. Between jumps the
:math:`u_i` relax in closed form (Eq. (B3)).

The simulation is event driven and exact up to round-off: there is no time step. See
``docs/reference/micro_nblock.md`` for the derivations (jump and redistribution increments, the
O(log N) lazy representation, the analytic limits used by the tests).

This module shares nothing with the Fokker-Planck solver but :mod:`micro.params`.

Entry points
------------
:func:`simulate_nblock`
    one run under a constant drive velocity or a piecewise-constant schedule.
:func:`stationary_stress_nblock`
    the stationary stress with a batch-means standard error.
:func:`stick_slip_extrema_nblock`
    :math:`\sigma_{max}`, :math:`\sigma_{min}` of the stick-slip cycle with standard errors.
"""
from __future__ import annotations

import logging
import math
import numbers
import time
import warnings
from dataclasses import dataclass, field
from typing import Sequence, Union

import numpy as np
import pandas as pd

from micro import _nblock_kernels as K
from micro.analytic import sigma_deterministic_steady, sigma_fast_limit, sigma_slow_limit
from micro.params import Deterministic, Exponential, JumpDistribution, Model, Tabulated

__all__ = [
    "NBlockState",
    "NBlockResult",
    "StationaryStress",
    "StickSlipExtrema",
    "initial_state",
    "simulate_nblock",
    "stationary_stress_nblock",
    "stick_slip_extrema_nblock",
    "sigma_deterministic_steady",
    "sigma_deterministic_steady_finite_n",
    "sigma_fast_limit",
    "sigma_slow_limit",
]

logger = logging.getLogger(__name__)

Schedule = Sequence[tuple[float, float]]
Velocity = Union[float, Schedule]

#: The largest number of blocks (block indices and tree nodes are 64-bit, memory is the limit).
MAX_BLOCKS = 2**27
#: The largest number of output bins of one run.
MAX_BINS = 50_000_000
_SIZE_HIST_BINS = 64

STATUS_MESSAGES = {
    K.STATUS_COMPLETED: ("completed", "reached t_max"),
    K.STATUS_SHOCK_LIMIT: ("shock_limit", "stopped after the requested number of global shocks"),
    K.STATUS_JUMP_LIMIT: ("jump_limit", "stopped at max_jumps before t_max"),
}


# ---------------------------------------------------------------------------------------
# validation
# ---------------------------------------------------------------------------------------
def _check_model(model: Model) -> None:
    if not isinstance(model, Model):
        raise ValueError(f"model must be a micro.params.Model, got {type(model).__name__}")


def _check_int(name: str, value, low: int, high: int) -> int:
    if isinstance(value, bool) or not isinstance(value, (numbers.Integral, np.integer)):
        raise ValueError(f"{name} must be an integer in [{low}, {high}], got {value!r}")
    value = int(value)
    if not low <= value <= high:
        raise ValueError(f"{name} must be an integer in [{low}, {high}], got {value!r}")
    return value


def _check_float(name: str, value, *, low: float = -math.inf, strict: bool = False, allow_none: bool = False):
    if value is None and allow_none:
        return None
    if isinstance(value, bool) or not isinstance(value, (numbers.Real, np.floating, np.integer)):
        raise ValueError(f"{name} must be a finite number {'>' if strict else '>='} {low}, got {value!r}")
    value = float(value)
    ok = math.isfinite(value) and (value > low if strict else value >= low)
    if not ok:
        raise ValueError(f"{name} must be a finite number {'>' if strict else '>='} {low}, got {value!r}")
    return value


def _segments(velocity: Velocity, t_max: float | None) -> tuple[np.ndarray, np.ndarray, float]:
    """Turn a velocity or a schedule [(duration, velocity), ...] into segment end times.

    With a schedule and no t_max, the run lasts the schedule's total duration; with a
    shorter t_max the schedule is cut; with a longer one the last velocity is held.
    """
    if isinstance(velocity, (numbers.Real, np.floating, np.integer)) and not isinstance(velocity, bool):
        v = _check_float("velocity", velocity, low=0.0)
        if t_max is None:
            raise ValueError("t_max must be given (a finite number > 0) with a constant velocity")
        t_max = _check_float("t_max", t_max, low=0.0, strict=True)
        return np.array([t_max]), np.array([v]), t_max
    try:
        items = list(velocity)  # type: ignore[arg-type]
    except TypeError:
        raise ValueError(
            "velocity must be a finite number >= 0 or a schedule [(duration, velocity), ...], "
            f"got {velocity!r}"
        ) from None
    if len(items) == 0:
        raise ValueError("velocity schedule must hold at least one (duration, velocity) pair")
    ends, vels = [], []
    total = 0.0
    for k, item in enumerate(items):
        try:
            duration, v = item
        except (TypeError, ValueError):
            raise ValueError(f"velocity schedule entry {k} must be a (duration, velocity) pair, got {item!r}") from None
        duration = _check_float(f"velocity schedule entry {k} duration", duration, low=0.0, strict=True)
        v = _check_float(f"velocity schedule entry {k} velocity", v, low=0.0)
        total += duration
        ends.append(total)
        vels.append(v)
    if t_max is None:
        t_max = total
    t_max = _check_float("t_max", t_max, low=0.0, strict=True)
    seg_end = np.minimum(np.array(ends), t_max)
    keep = np.concatenate([[True], seg_end[1:] > seg_end[:-1]]) & (np.concatenate([[0.0], seg_end[:-1]]) < t_max)
    seg_end, seg_vel = seg_end[keep], np.array(vels)[keep]
    seg_end[-1] = t_max
    return seg_end, seg_vel, t_max


# ---------------------------------------------------------------------------------------
# the pinning-distance distribution, as the kernels need it
# ---------------------------------------------------------------------------------------
def _jump_tables(dist: JumpDistribution) -> tuple[int, float, float, np.ndarray, np.ndarray]:
    """(kind, zbar, norm, u-knots, z-knots) for :func:`micro._nblock_kernels.draw_distance`.

    Exponential and deterministic distances are drawn in closed form (the same inverse
    cumulative distribution as :meth:`Exponential.quantile`). A :class:`Tabulated`
    distribution is drawn by interpolating its own cumulative distribution at its own nodes,
    which reproduces :meth:`Tabulated.quantile`; any other distribution through a dense
    table of its quantile function.
    """
    dummy = np.zeros(2)
    if isinstance(dist, Exponential):
        return K.KIND_EXPONENTIAL, float(dist.zbar), float(-math.expm1(-dist.cutoff / dist.zbar)), dummy, dummy
    if isinstance(dist, Deterministic):
        return K.KIND_DETERMINISTIC, float(dist.zbar), 1.0, dummy, dummy
    if isinstance(dist, Tabulated):
        z = np.linspace(0.0, float(dist.support_max), int(dist.n))
        u = np.asarray(dist.cdf(z), dtype=float)
        keep = np.concatenate([[True], np.diff(u) > 0.0])
        return K.KIND_TABLE, float(dist.mean), 1.0, np.ascontiguousarray(u[keep]), np.ascontiguousarray(z[keep])
    u = np.linspace(0.0, 1.0, 2**16 + 1)
    z = np.minimum(np.asarray(dist.quantile(u), dtype=float), float(dist.z_max))
    return K.KIND_TABLE, float(dist.mean), 1.0, u, z


def _residual_quantile(dist: JumpDistribution, q: np.ndarray, n_grid: int = 200_001) -> np.ndarray:
    r"""Quantiles of the equilibrium residual of a renewal process with increments z ~ g.

    Its density is :math:`(1 - G(r)) / \langle z\rangle` (G the cumulative distribution);
    tabulated by the midpoint rule on [0, z_max], which is exact for deterministic g.
    """
    edges = np.linspace(0.0, float(dist.z_max), n_grid)
    mid = 0.5 * (edges[1:] + edges[:-1])
    survival = 1.0 - np.asarray(dist.cdf(mid), dtype=float)
    cum = np.concatenate([[0.0], np.cumsum(survival * np.diff(edges))])
    cum /= cum[-1]
    keep = np.concatenate([[True], np.diff(cum) > 0.0])
    return np.interp(q, cum[keep], edges[keep])


# ---------------------------------------------------------------------------------------
# states and results
# ---------------------------------------------------------------------------------------
@dataclass(frozen=True)
class NBlockState:
    """Positions ``h``, dashpot elongations ``u`` and drive position ``w`` at time ``t``.

    Parameters
    ----------
    h, u : ndarray
        The blocks' positions and dashpot elongations, one per block.
    w : float
        The drive's position.
    t : float
        The time (:func:`simulate_nblock` starts every run at 0 and ignores it).
    """

    h: np.ndarray
    u: np.ndarray
    w: float
    t: float = 0.0

    @property
    def hbar(self) -> float:
        return float(np.mean(self.h))

    def sigma(self, model: Model) -> float:
        """The stress, Eq. (3)."""
        return model.k0 * (self.w - self.hbar)

    def delta(self, model: Model) -> np.ndarray:
        """The stability margins, Eq. (B1)."""
        hbar = self.hbar
        return (
            model.f_th
            - model.k0 * (self.w - self.h)
            - (model.k1 + model.k2) * (hbar - self.h)
            + model.k2 * self.u
        )


def initial_state(
    model: Model,
    n_blocks: int,
    kind: str = "relaxed",
    phases: str = "stratified",
    seed: int = 0,
) -> NBlockState:
    r"""An initial state whose margins are an equilibrium renewal residual.

    Every block gets :math:`h_i = r_i`, with :math:`r_i` a quantile of the equilibrium
    residual of a renewal process with increments z ~ g (density
    :math:`(1-G(r))/\langle z\rangle`), and :math:`\bar h` is the sample mean.

    ``kind="relaxed"``
        :math:`u_i = \bar h - h_i` (dashpots relaxed) and w set so that
        :math:`\delta_i = (k_0+k_1) r_i`: the quasi-static state (V -> 0, k0 > k2).
    ``kind="frozen"``
        :math:`u_i = 0` and w set so that :math:`\delta_i = (k_0+k_1+k_2) r_i`: the
        :math:`V \to \infty` state (dashpots have no time to relax).

    ``phases="stratified"`` takes the quantiles :math:`(i + 1/2)/N` (for deterministic g:
    evenly spaced phases, the steady state of Appendix C); ``phases="random"`` draws them
    independently (seeded by ``seed``). Both have :math:`\langle u_i\rangle = 0`.
    The paper notes that the initial condition only affects transients.

    Parameters
    ----------
    model : Model
        The model.
    n_blocks : int
        N, an integer in [2, 2**27].
    kind : {'relaxed', 'frozen'}
        As above.
    phases : {'stratified', 'random'}
        As above.
    seed : int
        Seed of the random phases, in [0, 2**63 - 1].

    Returns
    -------
    NBlockState
        At t = 0.

    Raises
    ------
    ValueError
        If ``model`` is not a :class:`~micro.params.Model`, ``n_blocks`` or ``seed`` is out
        of range, or ``kind`` or ``phases`` is not one of its choices.
    """
    _check_model(model)
    n = _check_int("n_blocks", n_blocks, 2, MAX_BLOCKS)
    if phases == "stratified":
        q = (np.arange(n) + 0.5) / n
    elif phases == "random":
        q = np.random.default_rng(_check_int("seed", seed, 0, 2**63 - 1)).random(n)
    else:
        raise ValueError(f"phases must be 'stratified' or 'random', got {phases!r}")
    r = _residual_quantile(model.jumps, q)
    h = r.copy()
    hbar = float(np.mean(h))
    if kind == "relaxed":
        u = hbar - h
        stiffness = model.k0 + model.k1
    elif kind == "frozen":
        u = np.zeros(n)
        stiffness = model.kappa
    else:
        raise ValueError(f"initial kind must be 'relaxed' or 'frozen', got {kind!r}")
    # delta_i = f_th - sigma0 + stiffness (h_i - hbar) = stiffness r_i
    sigma0 = model.f_th - stiffness * hbar
    w = hbar + sigma0 / model.k0
    return NBlockState(h=h, u=u, w=w, t=0.0)


@dataclass
class NBlockResult:
    """The outcome of :func:`simulate_nblock`.

    Attributes
    ----------
    timeseries : one row per output bin (width ``record_every``): ``t`` (bin end), ``w``
        and ``sigma`` at ``t``, ``sigma_mean`` (exact time average of sigma over the bin),
        ``sigma_max`` / ``sigma_min`` over the bin, ``n_jumps``, ``n_avalanches``,
        ``max_avalanche`` (in jumps) and ``mean_u`` at ``t``.
    shocks : one row per global shock (an avalanche of at least ``shock_min_size`` jumps):
        ``t``, ``sigma_before``, ``sigma_after``, ``size`` (jumps), ``delta_hbar``.
    status : ``"completed"``, ``"shock_limit"`` or ``"jump_limit"``; ``message`` says why.
    final_state : the state at the end, positions in absolute coordinates.
    avalanche_size_histogram : counts of avalanche sizes s in [2^b, 2^(b+1)), b = 0..63.
    """

    timeseries: pd.DataFrame
    shocks: pd.DataFrame
    status: str
    message: str
    n_blocks: int
    n_jumps: int
    n_avalanches: int
    n_swaps: int
    n_rebases: int
    n_shocks_lost: int
    shock_min_size: int
    avalanche_size_histogram: np.ndarray
    final_state: NBlockState
    sigma_integral: float
    wall_time: float
    model: Model
    seed: int
    schedule: tuple[tuple[float, float], ...] = field(default=())

    @property
    def success(self) -> bool:
        return self.status in ("completed", "shock_limit")

    def to_frame(self) -> pd.DataFrame:
        """The time series ``t, w, sigma, ...`` as a pandas DataFrame (a copy of
        :attr:`timeseries`)."""
        return self.timeseries.copy()

    def to_dataframe(self) -> pd.DataFrame:
        """Deprecated alias of :meth:`to_frame` (the name every other result uses).

        .. deprecated:: 0.1.0
           Use :meth:`to_frame`.
        """
        warnings.warn("NBlockResult.to_dataframe is deprecated, use NBlockResult.to_frame",
                      DeprecationWarning, stacklevel=2)
        return self.to_frame()


# ---------------------------------------------------------------------------------------
# the simulation
# ---------------------------------------------------------------------------------------
def simulate_nblock(
    model: Model,
    velocity: Velocity,
    n_blocks: int,
    t_max: float | None = None,
    seed: int = 0,
    record_every: float | None = None,
    initial: str | NBlockState = "relaxed",
    phases: str = "stratified",
    shock_fraction: float = 0.25,
    stop_after_shocks: int | None = None,
    max_jumps: int | None = None,
) -> NBlockResult:
    r"""Simulate the mean-field N-block model, event by event.

    Parameters
    ----------
    model : the parameters (:class:`micro.params.Model`).
    velocity : the drive velocity V >= 0 (then ``w = w_0 + V t``), or a schedule
        ``[(duration, velocity), ...]`` of piecewise-constant velocities (0 for a hold).
    n_blocks : the number of blocks N, an integer >= 2.
    t_max : the end time; required with a constant velocity; with a schedule it defaults to
        the schedule's duration (a shorter t_max cuts it, a longer one holds its last velocity).
    seed : fixes the pinning landscape: the k-th well distance of block i is a hash of
        (seed, i, k), so the run is reproducible and avalanches are order independent.
    record_every : output bin width (default ``t_max / 1000``).
    initial : ``"relaxed"`` or ``"frozen"`` (see :func:`initial_state`) or an explicit
        :class:`NBlockState` (its ``t`` is ignored: runs start at t = 0).
    phases : ``"stratified"`` or ``"random"`` initial residuals (see :func:`initial_state`).
    shock_fraction : an avalanche of at least ``ceil(shock_fraction * N)`` jumps is recorded
        as a global shock.
    stop_after_shocks : stop right after this many global shocks (default: never).
    max_jumps : stop after this many jumps (default: never); the status then says so.

    Returns
    -------
    NBlockResult
        The binned time series, the global shocks, the final state and the counts; a run
        stopped by ``stop_after_shocks`` or ``max_jumps`` says so in ``status``.

    Raises
    ------
    ValueError
        If ``model`` is not a :class:`~micro.params.Model`, ``n_blocks`` is not an integer
        in [2, 2**27], a velocity is negative or not finite, a constant velocity comes
        without ``t_max``, a schedule entry is not a (duration > 0, velocity >= 0) pair,
        ``record_every`` makes more than 5e7 bins, ``shock_fraction`` is not > 0, a count
        is not a positive integer, or ``initial`` is neither a kind nor an
        :class:`NBlockState` of N finite blocks.

    Examples
    --------
    >>> import micro
    >>> from micro import nblock as nb
    >>> run = nb.simulate_nblock(micro.Model(k0=0.1), 2.0, 2000, t_max=5.0, record_every=0.5)
    >>> run.status, len(run.to_frame())
    ('completed', 10)

    Notes
    -----
    Exact event-driven dynamics: between events, :math:`\bar h` is constant and every
    :math:`\delta_i(t) = \alpha_i + \beta_i e^{-\gamma (t-t_0)} - k_0 V (t-t_0)` in closed form
    (Eq. (B3)); the next instability is the root of this function for the least stable block,
    which a kinetic tournament tree maintains in O(log N) per jump. An avalanche is processed
    at frozen time, least stable block first, until every :math:`\delta_i > 0`.
    """
    _check_model(model)
    n = _check_int("n_blocks", n_blocks, 2, MAX_BLOCKS)
    seed = _check_int("seed", seed, 0, 2**64 - 1)
    seg_end, seg_vel, t_max = _segments(velocity, t_max)
    if record_every is None:
        record_every = t_max / 1000.0
    record_every = _check_float("record_every", record_every, low=0.0, strict=True)
    n_bins = int(math.ceil(t_max / record_every - 1e-9))
    n_bins = max(n_bins, 1)
    if n_bins > MAX_BINS:
        raise ValueError(f"record_every must be >= t_max / {MAX_BINS} = {t_max / MAX_BINS!r}, got {record_every!r}")
    shock_fraction = _check_float("shock_fraction", shock_fraction, low=0.0, strict=True)
    shock_min_size = max(1, int(math.ceil(shock_fraction * n)))
    stop_shocks = 2**62 if stop_after_shocks is None else _check_int("stop_after_shocks", stop_after_shocks, 1, 2**62)
    max_jumps_int = 2**62 if max_jumps is None else _check_int("max_jumps", max_jumps, 1, 2**62)

    if isinstance(initial, NBlockState):
        h0 = np.asarray(initial.h, dtype=float)
        u0 = np.asarray(initial.u, dtype=float)
        if h0.shape != (n,) or u0.shape != (n,):
            raise ValueError(f"initial state arrays h and u must have shape ({n},), got {h0.shape} and {u0.shape}")
        if not (np.all(np.isfinite(h0)) and np.all(np.isfinite(u0)) and math.isfinite(float(initial.w))):
            raise ValueError("initial state h, u and w must be finite")
        state0 = NBlockState(h=h0.copy(), u=u0.copy(), w=float(initial.w))
    elif isinstance(initial, str):
        state0 = initial_state(model, n, kind=initial, phases=phases, seed=seed % (2**63))
    else:
        raise ValueError(f"initial must be 'relaxed', 'frozen' or an NBlockState, got {initial!r}")

    kind, zbar, norm, qtab_u, qtab_z = _jump_tables(model.jumps)
    par = np.zeros(K.N_PARAMS)
    par[K.P_K0], par[K.P_K1], par[K.P_K2] = model.k0, model.k1, model.k2
    par[K.P_GAMMA], par[K.P_FTH], par[K.P_INVN] = model.gamma, model.f_th, 1.0 / n
    par[K.P_KIND], par[K.P_ZBAR], par[K.P_NORM] = kind, zbar, norm
    par[K.P_POSBOUND] = 1e3 * max(float(model.jumps.mean), 1e-300)

    # lazy state: s_i = u_i + h_i = m + x S_i with m = hbar and x = 1 at t = 0
    h = state0.h.copy()
    hbar = float(np.mean(h))
    s_coef = h + state0.u - hbar
    fs = np.zeros(K.N_FSTATE)
    fs[K.F_T], fs[K.F_TREF], fs[K.F_X] = 0.0, 0.0, 1.0
    fs[K.F_W], fs[K.F_HBAR], fs[K.F_M] = state0.w, hbar, hbar
    fs[K.F_SUMS] = float(np.sum(s_coef))
    counters = np.zeros(K.N_COUNTERS, dtype=np.int64)
    n_jumps = np.zeros(n, dtype=np.int64)
    n_leaves = 1 << int(math.ceil(math.log2(n)))
    win = np.empty(2 * n_leaves, dtype=np.int64)
    tree = np.empty((2 * n_leaves, K.N_TREE_COLS))
    K.tree_build(h, s_coef, par, n_leaves, win, tree, 1.0)

    out = {name: np.zeros(n_bins) for name in ("t", "w", "sigma", "sigma_mean", "sigma_max", "sigma_min", "mean_u")}
    out_int = {name: np.zeros(n_bins, dtype=np.int64) for name in ("n_jumps", "n_avalanches", "max_avalanche")}
    n_shock_slots = int(min(stop_shocks, 1_000_000))
    shock_t = np.zeros(n_shock_slots)
    shock_sb = np.zeros(n_shock_slots)
    shock_sa = np.zeros(n_shock_slots)
    shock_size = np.zeros(n_shock_slots, dtype=np.int64)
    shock_dh = np.zeros(n_shock_slots)
    size_hist = np.zeros(_SIZE_HIST_BINS, dtype=np.int64)

    logger.info("N-block run: N=%d, t_max=%g, %d segment(s), seed=%d", n, t_max, len(seg_end), seed)
    start = time.perf_counter()
    K.run_events(
        par, fs, counters, h, s_coef, n_jumps, np.uint64(seed), qtab_u, qtab_z,
        n_leaves, win, tree, seg_end, seg_vel, record_every, n_bins, t_max,
        out["t"], out["w"], out["sigma"], out["sigma_mean"], out["sigma_max"], out["sigma_min"],
        out_int["n_jumps"], out_int["n_avalanches"], out_int["max_avalanche"], out["mean_u"],
        shock_min_size, stop_shocks, shock_t, shock_sb, shock_sa, shock_size, shock_dh,
        size_hist, max_jumps_int,
    )
    wall = time.perf_counter() - start
    filled = int(counters[K.C_BINS])
    n_shocks = int(counters[K.C_SHOCKS])
    status, message = STATUS_MESSAGES[int(counters[K.C_STATUS])]
    if counters[K.C_SHOCKS_LOST] > 0:
        message += f"; {int(counters[K.C_SHOCKS_LOST])} global shocks beyond the first {n_shock_slots} were not recorded"
    timeseries = pd.DataFrame({**{k: v[:filled] for k, v in out.items()}, **{k: v[:filled] for k, v in out_int.items()}})
    timeseries = timeseries[
        ["t", "w", "sigma", "sigma_mean", "sigma_max", "sigma_min", "n_jumps", "n_avalanches", "max_avalanche", "mean_u"]
    ]
    shocks = pd.DataFrame(
        {
            "t": shock_t[:n_shocks],
            "sigma_before": shock_sb[:n_shocks],
            "sigma_after": shock_sa[:n_shocks],
            "size": shock_size[:n_shocks],
            "delta_hbar": shock_dh[:n_shocks],
        }
    )
    offset = fs[K.F_OFFSET]
    x = fs[K.F_X]
    u_final = fs[K.F_M] + x * s_coef - h
    final = NBlockState(h=h + offset, u=u_final, w=float(fs[K.F_W] + offset), t=float(fs[K.F_T]))
    sigma_integral = float(np.sum(timeseries["sigma_mean"].to_numpy() * np.diff(np.concatenate([[0.0], timeseries["t"].to_numpy()]))))
    logger.info(
        "N-block run done in %.3g s: %d jumps, %d avalanches, %d tree swaps, status %s",
        wall, counters[K.C_JUMPS], counters[K.C_AVALANCHES], counters[K.C_SWAPS], status,
    )
    return NBlockResult(
        timeseries=timeseries,
        shocks=shocks,
        status=status,
        message=message,
        n_blocks=n,
        n_jumps=int(counters[K.C_JUMPS]),
        n_avalanches=int(counters[K.C_AVALANCHES]),
        n_swaps=int(counters[K.C_SWAPS]),
        n_rebases=int(counters[K.C_REBASES]),
        n_shocks_lost=int(counters[K.C_SHOCKS_LOST]),
        shock_min_size=shock_min_size,
        avalanche_size_histogram=size_hist,
        final_state=final,
        sigma_integral=sigma_integral,
        wall_time=wall,
        model=model,
        seed=seed,
        schedule=tuple(zip(np.diff(np.concatenate([[0.0], seg_end])).tolist(), seg_vel.tolist())),
    )


# ---------------------------------------------------------------------------------------
# what a comparison needs: stationary stress and stick-slip extrema, with errors
# ---------------------------------------------------------------------------------------
@dataclass
class StationaryStress:
    r"""The stationary stress of a steady-sliding run, by batch means.

    ``sigma_mean`` is the mean of ``n_batches`` exact time averages of sigma over
    consecutive windows of length ``batch_length`` after a discarded transient of
    ``t_transient``; ``sigma_stderr_naive`` their standard deviation over sqrt(n_batches),
    and ``sigma_stderr`` the same inflated by :math:`\sqrt{(1+\rho)/(1-\rho)}` (the AR(1)
    correction) when the lag-1 autocorrelation :math:`\rho` of the batch means is positive.
    A large :math:`\rho` means the batches are too short. ``regime`` is ``"stick-slip"`` if global
    shocks occurred during the measurement (the mean is then not a stationary stress).

    Attributes
    ----------
    sigma_mean, sigma_stderr, sigma_stderr_naive : float
        As above.
    batch_means : ndarray
        The exact time average of sigma over each batch (``n_batches`` is their number).
    batch_length, t_transient : float
        The batches' length and the time discarded before them (a whole number of
        batches).
    lag1_autocorrelation : float
        :math:`\rho`.
    n_global_shocks : int
        Global shocks during the measurement.
    regime : str
        ``'steady'`` or ``'stick-slip'`` (two shocks or more).
    status : str
        ``'ok'``, ``'stick-slip'`` or ``'correlated'`` (:math:`\rho > 0.3`); ``message``
        says why.
    message : str
        Human-readable status.
    velocity : float
        The drive velocity.
    n_blocks : int
        N.
    wall_time : float
        Seconds the run took.
    result : NBlockResult
        The whole run.
    """

    sigma_mean: float
    sigma_stderr: float
    sigma_stderr_naive: float
    batch_means: np.ndarray
    batch_length: float
    t_transient: float
    lag1_autocorrelation: float
    n_global_shocks: int
    regime: str
    status: str
    message: str
    velocity: float
    n_blocks: int
    wall_time: float
    result: NBlockResult = field(repr=False)

    @property
    def n_batches(self) -> int:
        return int(self.batch_means.size)


def _lag1(values: np.ndarray) -> float:
    if values.size < 3:
        return float("nan")
    d = values - values.mean()
    denom = float(np.dot(d, d))
    return float(np.dot(d[1:], d[:-1]) / denom) if denom > 0.0 else 0.0


def _correlated_stderr(values: np.ndarray) -> float:
    """The standard error of the mean of a sequence with AR(1) correlation (lag-1
    autocorrelation clipped to [0, 0.9])."""
    naive = float(values.std(ddof=1) / math.sqrt(values.size))
    lag1 = _lag1(values)
    rho = min(max(lag1, 0.0), 0.9) if math.isfinite(lag1) else 0.0
    return naive * math.sqrt((1.0 + rho) / (1.0 - rho))


def _drifts(values: np.ndarray) -> bool:
    """Whether ``values`` has a linear trend: a least-squares slope of more than three
    standard errors (from the residuals, with their lag-1 autocorrelation)."""
    n = values.size
    if n < 6:
        return False
    x = np.arange(n) - 0.5 * (n - 1)
    sxx = float(x @ x)
    slope = float(x @ (values - values.mean())) / sxx
    resid = values - values.mean() - slope * x
    lag1 = _lag1(resid)
    rho = min(max(lag1, 0.0), 0.9) if math.isfinite(lag1) else 0.0
    err = math.sqrt(float(resid @ resid) / (n - 2) / sxx * (1.0 + rho) / (1.0 - rho))
    return abs(slope) > 3.0 * err


def stationary_stress_nblock(
    model: Model,
    velocity: float,
    n_blocks: int,
    *,
    t_transient: float | None = None,
    batch_length: float | None = None,
    n_batches: int = 20,
    seed: int = 0,
    initial: str | NBlockState = "relaxed",
    phases: str = "stratified",
    shock_fraction: float = 0.25,
    max_jumps: int | None = None,
) -> StationaryStress:
    r"""The stationary stress :math:`\sigma(V)` of the N-block model with its standard error.

    Parameters
    ----------
    model, velocity, n_blocks, seed, initial, phases, shock_fraction, max_jumps :
        as in :func:`simulate_nblock` (``velocity`` > 0 here).
    t_transient : discarded time; default ``10 / gamma`` (ten relaxation times), or
        ``200 zbar / V`` if k2 = 0. It is rounded up to a whole number of batches.
    batch_length : length of one batch; default ``5 / gamma`` (or ``100 zbar / V``).
    n_batches : number of batches, >= 2.

    Returns
    -------
    StationaryStress
        The mean, its standard errors, the batch means and the regime seen.

    Raises
    ------
    ValueError
        If an argument is refused (as by :func:`simulate_nblock`; ``velocity`` must be
        > 0, ``batch_length`` > 0, ``t_transient`` >= 0, ``n_batches`` an integer >= 2).
    RuntimeError
        If the run stopped before its end (``max_jumps``).

    Examples
    --------
    >>> import micro
    >>> from micro import nblock as nb
    >>> st = nb.stationary_stress_nblock(micro.Model(k0=0.1), 2.0, 20_000, t_transient=5.0, batch_length=1.0)
    >>> st.regime, round(st.sigma_mean, 3)         # at N = 2000 finite-size avalanches read as shocks
    ('steady', 0.894)
    """
    _check_model(model)
    v = _check_float("velocity", velocity, low=0.0, strict=True)
    n_batches = _check_int("n_batches", n_batches, 2, 10**7)
    scale = 1.0 / model.gamma if model.k2 > 0.0 else 20.0 * model.jumps.mean / v
    t_transient = _check_float("t_transient", 10.0 * scale if t_transient is None else t_transient, low=0.0)
    batch_length = _check_float("batch_length", 5.0 * scale if batch_length is None else batch_length, low=0.0, strict=True)
    n_skip = int(math.ceil(t_transient / batch_length - 1e-9))
    t_max = (n_skip + n_batches) * batch_length
    res = simulate_nblock(
        model, v, n_blocks, t_max=t_max, seed=seed, record_every=batch_length, initial=initial,
        phases=phases, shock_fraction=shock_fraction, max_jumps=max_jumps,
    )
    ts = res.timeseries
    batches = ts["sigma_mean"].to_numpy()[n_skip:]
    if res.status != "completed" or batches.size < 2:
        raise RuntimeError(f"N-block run stopped early ({res.status}: {res.message}); raise max_jumps")
    shocks = res.shocks
    n_shocks = int(np.sum(shocks["t"].to_numpy() > n_skip * batch_length)) if len(shocks) else 0
    regime = "stick-slip" if n_shocks >= 2 else "steady"
    lag1 = _lag1(batches)
    message = "stationary stress by batch means"
    status = "ok"
    if regime == "stick-slip":
        status = "stick-slip"
        message = f"{n_shocks} global shocks during the measurement: not a steady state"
        logger.warning("stationary_stress_nblock(V=%g): %s", v, message)
    elif lag1 > 0.3:
        status = "correlated"
        message = f"batch means are correlated (lag-1 autocorrelation {lag1:.2f}): use longer batches"
        logger.warning("stationary_stress_nblock(V=%g): %s", v, message)
    naive = float(batches.std(ddof=1) / math.sqrt(batches.size))
    rho = min(max(lag1, 0.0), 0.9) if math.isfinite(lag1) else 0.0
    inflation = math.sqrt((1.0 + rho) / (1.0 - rho))
    return StationaryStress(
        sigma_mean=float(batches.mean()),
        sigma_stderr=naive * inflation,
        sigma_stderr_naive=naive,
        batch_means=batches,
        batch_length=batch_length,
        t_transient=n_skip * batch_length,
        lag1_autocorrelation=lag1,
        n_global_shocks=n_shocks,
        regime=regime,
        status=status,
        message=message,
        velocity=v,
        n_blocks=res.n_blocks,
        wall_time=res.wall_time,
        result=res,
    )


@dataclass
class StickSlipExtrema:
    r"""Mean stress just before (``sigma_max``) and just after (``sigma_min``) the global shocks.

    Means over ``n_cycles`` shocks after ``n_discard`` discarded ones, with standard errors
    (standard deviation over sqrt(n_cycles), times :math:`\sqrt{(1+r)/(1-r)}` with r the
    lag-1 autocorrelation of the sequence, clipped to [0, 0.9]: close to V^c successive
    cycles are strongly correlated); ``period`` is the mean time between them.
    ``regime`` is ``"steady"`` if fewer than ``n_discard + 2`` global shocks occurred by
    ``t_max`` (then the extrema are NaN).  ``status`` is ``"transient"`` when the means of
    the first and second halves of the cycles differ by more than three standard errors:
    the cycle was still converging, so ``n_discard`` was too small (the cycle map contracts
    by about 0.96 per cycle at k0 = 0.01, 0.9 V^c: hundreds of cycles).

    Attributes
    ----------
    sigma_max, sigma_max_stderr, sigma_min, sigma_min_stderr : float
        The means and their standard errors (NaN without cycles).
    period, period_stderr : float
        Mean time between the shocks and its standard error.
    n_cycles : int
        Shocks averaged over.
    regime : str
        ``'stick-slip'`` or ``'steady'`` (too few shocks).
    status : str
        ``'ok'``, ``'transient'``, ``'fewer_cycles'`` (the run ended with fewer than
        ``n_cycles`` shocks after the discarded ones) or ``'no_cycles'``.
    message : str
        Human-readable status.
    velocity : float
        The drive velocity.
    n_blocks : int
        N.
    wall_time : float
        Seconds the run took.
    shocks : pandas.DataFrame
        The shocks averaged over (``t, sigma_before, sigma_after, size, delta_hbar``).
    result : NBlockResult
        The whole run.
    """

    sigma_max: float
    sigma_max_stderr: float
    sigma_min: float
    sigma_min_stderr: float
    period: float
    period_stderr: float
    n_cycles: int
    regime: str
    status: str
    message: str
    velocity: float
    n_blocks: int
    wall_time: float
    shocks: pd.DataFrame = field(repr=False)
    result: NBlockResult = field(repr=False)


#: ``n_discard="auto"``: at least this many shocks are discarded (and at least
#: ``n_cycles``); while the last ``2 n_cycles`` drift, the run goes on by ``n_cycles``
#: shocks at a time, up to ``max_discard``.
AUTO_MIN_DISCARD = 10


def _continued_seed(seed: int, segment: int) -> int:
    """The pinning landscape of a run's ``segment``-th continuation: wells are independent
    of the past (they are renewed at each jump), so a fresh landscape continues the run
    exactly, where the same seed would repeat each block's well sequence from its start."""
    if segment == 0:
        return seed
    return (seed ^ ((segment * 0x9E3779B97F4A7C15) & 0xFFFFFFFFFFFFFFFF)) % 2**64


def stick_slip_extrema_nblock(
    model: Model,
    velocity: float,
    n_blocks: int,
    *,
    n_cycles: int = 20,
    n_discard: int | str = "auto",
    max_discard: int = 1000,
    t_max: float | None = None,
    seed: int = 0,
    initial: str | NBlockState = "relaxed",
    phases: str = "stratified",
    shock_fraction: float = 0.25,
    record_every: float | None = None,
    max_jumps: int | None = None,
) -> StickSlipExtrema:
    r"""The stick-slip extrema :math:`\sigma_{max}`, :math:`\sigma_{min}` with standard errors.

    Runs until ``n_discard + n_cycles`` global shocks (avalanches of at least
    ``shock_fraction * N`` jumps) have occurred, or until ``t_max`` (default
    ``(n_discard + n_cycles + 1) * 2 f_th / (k0 V)``, twice the time the drive needs to load
    the stress by f_th per cycle). The first ``n_discard`` shocks are the transient.
    With ``n_discard="auto"`` (the default) the transient is as long as it needs to be: at
    least ``max(AUTO_MIN_DISCARD, n_cycles)`` shocks (``AUTO_MIN_DISCARD`` = 10), then,
    while the last ``2 n_cycles`` shocks drift (a linear trend in sigma_max or sigma_min of
    more than three standard errors, their correlation included: the cycles to be used and
    as many before them, a longer window than the status's own test, which sees less), the
    run goes on by ``n_cycles`` more shocks and the window moves with it, up to
    ``max_discard`` discarded shocks (close to V^c the cycle map contracts by about 0.96 a
    cycle: hundreds of shocks).  Each continuation draws a
    fresh pinning landscape (the wells are renewed at every jump, so this continues the
    same process).

    Parameters
    ----------
    model, n_blocks, seed, initial, phases, shock_fraction, record_every, max_jumps :
        As in :func:`simulate_nblock` (``record_every`` defaults to ``t_max / 2000``).
    velocity : float
        The drive velocity, > 0.
    n_cycles : int
        Shocks to average over, an integer in [2, 1e6] (default 20).
    n_discard : int or "auto"
        Shocks discarded first, in [0, 1e6], or ``"auto"`` (default; above).
    max_discard : int
        With ``n_discard="auto"``, the most shocks discarded, an integer in
        [10, 1e6] (default 1000).
    t_max : float, optional
        The longest run (of each continuation, with ``"auto"``), > 0 (default as above).

    Returns
    -------
    StickSlipExtrema
        The means with their standard errors, the period and the status
        (``'transient'`` when the cycles still drift; with ``"auto"``, after
        ``max_discard`` discarded shocks).  ``result`` is the run (with ``"auto"``, its
        last continuation); ``shocks`` the shocks averaged over, their times counted from
        the start of the whole run.

    Raises
    ------
    ValueError
        If an argument is refused (as by :func:`simulate_nblock`; ``velocity`` must be
        > 0).

    Examples
    --------
    >>> import micro
    >>> from micro import nblock as nb
    >>> cycle = nb.stick_slip_extrema_nblock(micro.Model(k0=0.1), 0.05, 2000, n_cycles=5, n_discard=3)
    >>> cycle.regime, bool(cycle.sigma_max > cycle.sigma_min)
    ('stick-slip', True)
    """
    _check_model(model)
    v = _check_float("velocity", velocity, low=0.0, strict=True)
    n_cycles = _check_int("n_cycles", n_cycles, 2, 10**6)
    auto = isinstance(n_discard, str)
    if auto and n_discard != "auto":
        raise ValueError(f"n_discard must be an integer in [0, 1000000] or 'auto', got {n_discard!r}")
    if auto:
        max_discard = _check_int("max_discard", max_discard, AUTO_MIN_DISCARD, 10**6)
        first = max(AUTO_MIN_DISCARD, n_cycles) + n_cycles
    else:
        n_discard = _check_int("n_discard", n_discard, 0, 10**6)
        first = n_discard + n_cycles
    if t_max is not None:
        t_max = _check_float("t_max", t_max, low=0.0, strict=True)
    seed = _check_int("seed", seed, 0, 2**64 - 1)

    def run(state, shocks: int, segment: int) -> NBlockResult:
        span = (shocks + 1) * 2.0 * model.f_th / (model.k0 * v) if t_max is None else t_max
        return simulate_nblock(
            model, v, n_blocks, t_max=span, seed=_continued_seed(seed, segment),
            record_every=span / 2000.0 if record_every is None else record_every, initial=state, phases=phases,
            shock_fraction=shock_fraction, stop_after_shocks=shocks, max_jumps=max_jumps,
        )

    res = run(initial, first, 0)
    frames, offset, segment, wall = [res.shocks], 0.0, 0, res.wall_time
    while auto:
        shocks = pd.concat(frames, ignore_index=True)
        window = shocks.iloc[-2 * n_cycles:]  # (the cycles to use and as many before them)
        # (a run that ended short of its shocks, by t_max or max_jumps, is not continued)
        done = (len(shocks) < first + segment * n_cycles
                or not any(_drifts(window[c].to_numpy()) for c in ("sigma_before", "sigma_after")))
        if done or len(shocks) - n_cycles >= max_discard:
            break
        offset += res.final_state.t
        segment += 1
        res = run(res.final_state, n_cycles, segment)
        wall += res.wall_time
        frames.append(res.shocks.assign(t=res.shocks["t"] + offset))
    shocks = pd.concat(frames, ignore_index=True)
    if auto:
        n_discard = max(len(shocks) - n_cycles, AUTO_MIN_DISCARD)
    used = shocks.iloc[n_discard:]
    nan = float("nan")
    if len(used) < 2:
        msg = f"only {len(shocks)} global shocks by t = {offset + res.final_state.t:g} ({res.status}): no stick-slip cycle"
        logger.info("stick_slip_extrema_nblock(V=%g): %s", v, msg)
        return StickSlipExtrema(nan, nan, nan, nan, nan, nan, int(len(used)), "steady", "no_cycles", msg,
                                v, res.n_blocks, wall, shocks, res)
    before = used["sigma_before"].to_numpy()
    after = used["sigma_after"].to_numpy()
    periods = np.diff(used["t"].to_numpy())
    status = "ok" if len(used) == n_cycles else "fewer_cycles"
    msg = f"{len(used)} cycles after {n_discard} discarded shocks{' (chosen by the drift test)' if auto else ''}"
    if status != "ok":
        logger.warning("stick_slip_extrema_nblock(V=%g): only %s", v, msg)
    else:
        drift = [name for name, x in (("sigma_max", before), ("sigma_min", after)) if _drifts(x)]
        if drift:
            status = "transient"
            half = len(before) // 2
            msg += (f"; {' and '.join(drift)} still drift (sigma_max {before[:half].mean():.6g} over the first "
                    f"half, {before[half:].mean():.6g} over the second): "
                    + ("raise max_discard" if auto else "raise n_discard"))
            logger.warning("stick_slip_extrema_nblock(V=%g): %s", v, msg)
    return StickSlipExtrema(
        sigma_max=float(before.mean()),
        sigma_max_stderr=_correlated_stderr(before),
        sigma_min=float(after.mean()),
        sigma_min_stderr=_correlated_stderr(after),
        period=float(periods.mean()),
        period_stderr=_correlated_stderr(periods) if len(periods) > 1 else nan,
        n_cycles=int(len(used)),
        regime="stick-slip",
        status=status,
        message=msg,
        velocity=v,
        n_blocks=res.n_blocks,
        wall_time=wall,
        shocks=used.reset_index(drop=True),
        result=res,
    )


# ---------------------------------------------------------------------------------------
# analytic results the tests compare with (derived in docs/reference/micro_nblock.md)
# ---------------------------------------------------------------------------------------


def sigma_deterministic_steady_finite_n(model: Model, velocity: float, n_blocks: int) -> float:
    r"""Eq. (4) for N blocks: the exact time-averaged stress of the evenly spaced steady state.

    With deterministic jumps and phases spaced by :math:`\bar z / N`, the blocks jump one at
    a time, in turn, every :math:`\Delta = \bar z/(N V)`. Just before a jump
    :math:`\bar h - h_i = y_b = \frac{\bar z}{2}(1 - \frac1N)` and, between its own jumps,
    block i sees the staircase :math:`\bar h - h_i = y_b - j\,\bar z/N` (j steps before its
    next jump). Solving Eq. (2) for the periodic :math:`u_i` with :math:`q = e^{-\gamma\Delta}`,

    .. math::
        \sigma_b &= f_{th} - (k_0+k_1)\, y_b - k_2 \frac{\bar z}{N}
                    \frac{q\,(1 - N q^{N-1} + (N-1) q^N)}{(1-q)(1-q^N)}, \\
        \langle\sigma\rangle &= \sigma_b - \frac{k_0 \bar z}{2N},

    which tends to Eq. (4) as :math:`N \to \infty`. Derived in ``docs/reference/micro_nblock.md``.

    Parameters
    ----------
    model : Model
        The model (its ``jumps`` taken as deterministic, at their mean).
    velocity : float
        The drive velocity, > 0.
    n_blocks : int
        N, an integer >= 2.

    Returns
    -------
    float
        :math:`\langle\sigma\rangle`.

    Raises
    ------
    ValueError
        If ``model`` is not a :class:`~micro.params.Model`, ``velocity`` is not a finite
        number > 0 or ``n_blocks`` is not an integer >= 2.

    Examples
    --------
    >>> import micro
    >>> from micro import nblock as nb
    >>> model = micro.Model(k0=1.0, jumps=micro.Deterministic(0.1))
    >>> round(nb.sigma_deterministic_steady_finite_n(model, 0.5, 1000) - nb.sigma_deterministic_steady(model, 0.5), 8)
    5e-05
    """
    _check_model(model)
    v = _check_float("velocity", velocity, low=0.0, strict=True)
    n = _check_int("n_blocks", n_blocks, 2, 2**62)
    zbar, k0, k1, k2 = model.jumps.mean, model.k0, model.k1, model.k2
    q = math.exp(-model.gamma * zbar / (n * v))
    y_b = 0.5 * zbar * (1.0 - 1.0 / n)
    if q == 1.0:  # k2 = 0: no dashpot
        lag = 0.0
    else:
        qn1 = q ** (n - 1)
        lag = (zbar / n) * q * (1.0 - n * qn1 + (n - 1) * qn1 * q) / ((1.0 - q) * (1.0 - qn1 * q))
    sigma_before = model.f_th - (k0 + k1) * y_b - k2 * lag
    return sigma_before - 0.5 * k0 * zbar / n
