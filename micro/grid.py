"""The discretised density P(delta_F, delta_R) and the loop that advances it.

:class:`Grid` owns the arrays the numba kernels in :mod:`micro._fp_kernels` work on: it
allocates them, grows them when the density spreads, builds the initial densities and
calls :func:`micro._fp_kernels.advance` until a requested time, collecting what it records.
"""
from __future__ import annotations

import logging
import math
import time
from dataclasses import dataclass
from typing import Callable

import numpy as np

from . import _fp_kernels as K
from . import _progress
from ._progress import Interrupted
from .params import KIND_DETERMINISTIC, KIND_EXPONENTIAL, Model

__all__ = ["Grid", "GridSettings"]

log = logging.getLogger(__name__)

#: Mass of the jump-length distribution left beyond the grid's last column.
TAIL_MASS = 1e-12
#: Kernel steps of the first call of :meth:`Grid.advance`, and the bounds of the later
#: ones (tuned to about ``micro._progress.CHUNK_SECONDS`` of wall time each).
CHUNK_FIRST = 16
CHUNK_MIN = 1
CHUNK_MAX = 50_000_000


def _joined(parts: list[np.ndarray], width: int) -> np.ndarray:
    """The rows of ``parts`` in one array (``(0, width)`` if none)."""
    return np.concatenate(parts) if parts else np.zeros((0, width))


class GridTooLarge(MemoryError):
    """The density's support outgrew the memory allowed for the grid
    (``Numerics.max_memory_gib``).

    Raised by the Fokker-Planck solver (``method="fp"`` of :func:`micro.simulate`,
    :func:`micro.stationary` and the functions built on them) before it allocates the grid;
    a :class:`MemoryError`.  Its message gives the grid's size, k0, eps and the time, and
    the ways out: a coarser ``eps``, a larger ``max_memory_gib``, or the N-block solver.
    It takes the message as its one argument.
    """


@dataclass(frozen=True)
class GridSettings:
    """Numerical settings of the Fokker-Planck grid.

    Parameters
    ----------
    eps : bin width of delta_F and delta_R.  Must resolve a mean jump,
        ``kappa * zbar / 1000 <= eps <= kappa * zbar / 4``.
    theta_shift : largest shift of delta_F per time step, in bins (0 < theta_shift <= 1).
    theta_relax : how far (in bins) a cell near the threshold may relax between two
        synchronisations of the stored delta_R (the relaxation itself is exact; this
        bounds how stale the stored positions get), 0 < theta_relax <= 2.
    dt_max : largest time step (may be infinite).
    max_bytes : largest memory for the grid's arrays; growing past it raises
        :class:`GridTooLarge`.
    """

    eps: float = 2e-3
    theta_shift: float = 0.5
    theta_relax: float = 0.5
    dt_max: float = 1.0
    max_bytes: float = 4.0 * 2**30

    def __post_init__(self) -> None:
        for name in ("eps", "theta_shift", "theta_relax"):
            v = float(getattr(self, name))
            if not (math.isfinite(v) and v > 0.0):
                raise ValueError(f"{name} must be a finite number > 0, got {v!r}")
        if not float(self.dt_max) > 0.0:
            raise ValueError(f"dt_max must be > 0, got {self.dt_max!r}")
        if self.theta_shift > 1.0:
            raise ValueError(f"theta_shift must be in (0, 1], got {self.theta_shift!r}")
        if self.theta_relax > 2.0:
            raise ValueError(f"theta_relax must be in (0, 2], got {self.theta_relax!r}")

    def check(self, model: Model) -> None:
        """Check that ``eps`` resolves the model's mean jump ``kappa * zbar``."""
        limit = model.kappa * model.zbar / 4.0
        floor = model.kappa * model.zbar / 1000.0
        if not floor <= self.eps <= limit:
            raise ValueError(
                f"eps must be in [kappa*zbar/1000, kappa*zbar/4] = [{floor:.4g}, {limit:.4g}] for this model "
                f"(at least 4 bins per mean jump; finer grids exceed memory and run time), got {self.eps!r}"
            )


def _landing_parameters(model: Model, eps: float) -> tuple[np.ndarray, np.ndarray, float]:
    """Distribution constants for the kernels, the tabulated CDF and the largest landing displacement."""
    kappa = model.kappa
    jumps = model.jumps
    dp = np.zeros(3)
    if jumps.kind == KIND_EXPONENTIAL:
        scale = jumps.zbar  # the exponential's scale parameter
        dp[:] = (kappa * scale, kappa * jumps.cutoff, -math.expm1(-jumps.cutoff / scale))
        s_max = kappa * min(jumps.cutoff, scale * math.log(1.0 / TAIL_MASS))
        table = np.zeros(2)
    elif jumps.kind == KIND_DETERMINISTIC:
        dp[0] = kappa * jumps.zbar
        s_max = kappa * jumps.zbar + eps
        table = np.zeros(2)
    else:
        z_max = jumps.z_max
        n = 1 + int(min(1 << 22, max(4096, 64 * z_max * kappa / eps)))
        z = np.linspace(0.0, z_max, n)
        table = np.ascontiguousarray(jumps.cdf(z), dtype=float)
        dp[:] = (kappa * z_max / (n - 1), kappa * z_max, 0.0)
        s_max = kappa * z_max
    return dp, table, s_max


class Grid:
    """The density of (delta_F, delta_R) on a grid of bin ``eps``, with its scalar state.

    Parameters
    ----------
    model : the model.
    settings : numerical settings.
    initial : ``"frozen"`` (all delta_R = 0 and delta distributed as the overshoot of a
        renewal process with increments kappa z: the V -> infinity state),
        ``"relaxed"`` (every dashpot relaxed and delta distributed with increments
        (k0 + k1) z: the V -> 0 state) or ``"uniform"`` (all delta_R = 0 and delta
        uniform on [0, kappa zbar]: a start away from every stationary state, whose mean
        margin is half the V -> infinity one, for transients and convergence tests).
    """

    #: kernel steps per call of the kernel (tuned by :meth:`advance`)
    _chunk_steps: int = CHUNK_FIRST

    def __init__(self, model: Model, settings: GridSettings, initial: str = "frozen") -> None:
        if initial not in ("frozen", "relaxed", "uniform"):
            raise ValueError(f"initial must be 'frozen', 'relaxed' or 'uniform', got {initial!r}")
        self._setup(model, settings)
        self._build_initial(initial)
        self._mean_delta_R()

    def _setup(self, model: Model, settings: GridSettings) -> None:
        """The constants of the kernels and the empty scalar state."""
        settings.check(model)
        self.model = model
        self.settings = settings
        eps = settings.eps
        dp, self.table, s_max = _landing_parameters(model, eps)
        self.cols_needed = int(math.ceil(s_max / eps)) + 4
        prm = np.zeros(K.N_PARAM)
        prm[K.P_K0] = model.k0
        prm[K.P_K1] = model.k1
        prm[K.P_K2] = model.k2
        prm[K.P_KAPPA] = model.kappa
        prm[K.P_GAMMA] = model.gamma
        prm[K.P_FTH] = model.f_th
        prm[K.P_EPS] = eps
        prm[K.P_ZMEAN] = model.zbar
        prm[K.P_KIND] = model.jumps.kind
        prm[K.P_D0 : K.P_D2 + 1] = dp
        prm[K.P_THETA_S] = settings.theta_shift
        prm[K.P_THETA_R] = settings.theta_relax
        prm[K.P_DT_MAX] = settings.dt_max
        prm[K.P_SHOCK] = 8.0
        prm[K.P_S_MAX] = s_max
        # a landing after a jump of z pulls delta_R by up to about k2 z (plus what the
        # jumping mass already had): bound it by the z that only 1e-12 of jumps exceed
        z_hi = float(np.asarray(model.jumps.quantile(np.array([1.0 - 1e-12])))[0])
        prm[K.P_PULL_LAND] = 2.0 * model.k2 * z_hi / eps
        prm[K.P_STOP_SHIFT] = math.inf
        self.prm = prm
        self.ist = np.zeros(K.N_ISTATE, dtype=np.int64)
        self.fst = np.zeros(K.N_FSTATE)

    def _mean_delta_R(self) -> None:
        cells = self.cells()
        self.fst[K.F_YMEAN] = float(np.sum(cells["mass"] * cells["delta_R"]) / np.sum(cells["mass"]))

    # ----------------------------------------------------------------------------- set-up
    def _allocate(self, nrow: int, ncol: int) -> None:
        needed = 3 * 2 * 8 * nrow * ncol  # three float arrays, two buffers each
        if needed > self.settings.max_bytes:
            m = self.model
            t = float(self.fst[K.F_T]) if hasattr(self, "fst") else 0.0
            raise GridTooLarge(
                f"micro: the density needs a {nrow} x {ncol} grid ({needed / 2**30:.1f} GiB) at k0 = {m.k0:g}, "
                f"eps = {self.settings.eps:g}, t = {t:.4g}, over the limit of "
                f"{self.settings.max_bytes / 2**30:.1f} GiB (Numerics.max_memory_gib); the grid has "
                f"{int(math.ceil(1.0 / self.settings.eps))} bins per unit of delta; use a coarser eps, a larger "
                f"max_memory_gib, or the N-block solver (micro.nblock)"
            )
        self.bufM = np.zeros((2, nrow, ncol))
        self.bufW = np.zeros((2, nrow, ncol))
        self.bufO = np.zeros((2, nrow, ncol))
        self.bufchi = np.zeros((2, nrow), dtype=np.int64)
        self.bufclo = np.full((2, nrow), ncol, dtype=np.int64)
        # exits waiting to land (kept across calls if a landing needs more room)
        self.ex_m = np.zeros(nrow)
        self.ex_y = np.zeros(nrow)
        self.ex_d = np.zeros(nrow)
        self.cand = np.zeros(((2 * K.SCAN + 1) * nrow, 3))

    def _build_initial(self, initial: str) -> None:
        model, eps = self.model, self.settings.eps
        stiffness = model.kappa if initial == "frozen" else model.k0 + model.k1
        # density of delta: overshoot of a renewal process with increments stiffness * z
        n_sub = 8
        s_max = stiffness * model.jumps.z_max
        n_bins = int(math.ceil(s_max / eps)) + 1
        delta = (np.arange(n_bins * n_sub) + 0.5) * (eps / n_sub)
        if initial == "uniform":
            density = (delta < model.kappa * model.zbar).astype(float)
        else:
            density = 1.0 - np.asarray(model.jumps.cdf(delta / stiffness))
        weight = density / density.sum()
        mean_delta = float(np.sum(weight * delta))
        if initial != "relaxed":
            y = np.zeros_like(delta)
        else:
            y = model.k2 / (model.k0 + model.k1) * (mean_delta - delta)
        self._fill(delta, y, weight)

    @classmethod
    def from_cells(cls, model: Model, settings: GridSettings, j: np.ndarray, eta: np.ndarray, d: np.ndarray,
                   weight: np.ndarray, omega: np.ndarray) -> "Grid":
        """A grid from its cells: mass ``weight`` in the cell of delta_R bin ``j`` and delta
        bin ``d``, at delta_R ``(j + eta) eps`` (``-0.5 <= eta < 0.5``), spread uniformly over
        the upper fraction ``omega`` of the cell (its delta from ``(d + 1 + eta - omega) eps``
        to ``(d + 1 + eta) eps``, which must be >= 0).  Normalised to total mass 1; the
        stress is ``f_th - <delta_F>`` of the cells."""
        j, d = (np.asarray(a, dtype=np.int64).ravel() for a in (j, d))
        eta, weight, omega = (np.asarray(a, dtype=float).ravel() for a in (eta, weight, omega))
        keep = weight > 0.0
        if not (np.all(omega[keep] > 0.0) and np.all(omega[keep] <= 1.0) and np.all(np.abs(eta) <= 0.5)
                and np.all(d[keep] + 1 + eta[keep] - omega[keep] >= -1e-9) and weight.sum() > 0.0):
            raise ValueError("cells must have 0 < omega <= 1, |eta| <= 1/2, delta >= 0 and a positive mass")
        grid = object.__new__(cls)
        grid._setup(model, settings)
        grid._fill_cells(j[keep], eta[keep], d[keep], weight[keep] / weight[keep].sum(), omega[keep])
        grid._mean_delta_R()
        return grid

    def _fill(self, delta: np.ndarray, y: np.ndarray, weight: np.ndarray) -> None:
        """Allocate the arrays and put the masses ``weight`` at (delta, delta_R = y)."""
        eps = self.settings.eps
        j = np.floor(y / eps + 0.5).astype(np.int64)
        eta = y / eps - j
        d = np.floor(delta / eps - eta).astype(np.int64)
        self._fill_cells(j, eta, d, weight, np.ones_like(weight))

    def _fill_cells(self, j: np.ndarray, eta: np.ndarray, d: np.ndarray, weight: np.ndarray,
                    omega: np.ndarray) -> None:
        model, eps = self.model, self.settings.eps
        jbase = int(j.min()) - 4
        nrow = int(j.max()) - jbase + 5
        off = 3
        ncol = max(2 * self.cols_needed, int(d.max()) + 1) + 16
        self._allocate(nrow, ncol)
        r = j - jbase
        c = off + d
        M = self.bufM[0]
        W = self.bufW[0]
        np.add.at(M, (r, c), weight)
        np.add.at(W, (r, c), weight * eta)
        np.add.at(self.bufO[0], (r, c), weight * omega)
        occupied = M > 0.0
        for row in range(nrow):
            cols = np.flatnonzero(occupied[row])
            if cols.size:
                self.bufclo[0, row] = cols[0]
                self.bufchi[0, row] = cols[-1] + 1
        rows = np.flatnonzero(occupied.any(axis=1))
        ist, fst = self.ist, self.fst
        ist[K.I_OFF] = off
        ist[K.I_JBASE] = jbase
        ist[K.I_RLO] = rows[0]
        ist[K.I_RHI] = rows[-1] + 1
        ist[K.I_CUR] = 0
        # x (delta_F) centre of every cell, from its bin
        k = d - j
        mean_x = float(np.sum(weight * (k + 1.0 - 0.5 * omega) * eps))
        fst[K.F_SUMX] = mean_x
        fst[K.F_MASS] = 1.0
        fst[K.F_SIGMA] = model.f_th - mean_x
        fst[K.F_LAM] = 1.0
        fst[K.F_LAM_SYNC] = 1.0  # synchronise (and schedule) at the first step
        fst[K.F_WIN_MIN] = fst[K.F_SIGMA]
        fst[K.F_WIN_MAX] = fst[K.F_SIGMA]
        fst[K.F_REC_SIGMA] = fst[K.F_SIGMA]

    # ----------------------------------------------------------------------------- state
    @property
    def t(self) -> float:
        return float(self.fst[K.F_T])

    @property
    def sigma(self) -> float:
        """Stress ``k0 (w - hbar)``."""
        return float(self.fst[K.F_SIGMA])

    @property
    def sigma_grid(self) -> float:
        """Stress from the grid, ``f_th - <delta_F>`` (equal to :attr:`sigma` up to discretisation)."""
        return float(self.model.f_th - self.fst[K.F_SUMX] / self.fst[K.F_MASS])

    def density(self) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """The current cell masses, delta_R offsets ``eta`` and filled fractions ``omega``."""
        cur = int(self.ist[K.I_CUR])
        M = self.bufM[cur]
        safe = np.where(M > 0.0, M, 1.0)
        eta = np.where(M > 0.0, self.bufW[cur] / safe, 0.0)
        omega = np.where(M > 0.0, self.bufO[cur] / safe, 0.0)
        return M, eta, omega

    def mass(self) -> float:
        return float(self.density()[0].sum())

    def min_mass(self) -> float:
        """Most negative cell mass (0 if the density is non-negative everywhere)."""
        return float(min(self.density()[0].min(), self.fst[K.F_NEG]))

    def cells(self) -> dict[str, np.ndarray]:
        """Occupied cells as arrays: mass, delta_F (centre), delta_R and delta, at the
        current time (the stored delta_R are corrected for the relaxation since the last
        synchronisation)."""
        M, eta, omega = self.density()
        eps = self.settings.eps
        r, c = np.nonzero(M)
        j = r + int(self.ist[K.I_JBASE])
        d = c - int(self.ist[K.I_OFF])
        phi = float(self.fst[K.F_PHI])
        x = (d - j + 1 - phi - 0.5 * omega[r, c]) * eps
        y_stored = (j + eta[r, c]) * eps
        m = self.model
        target = m.k2 / m.kappa * (self.fst[K.F_SUMX] / self.fst[K.F_MASS] - x) - m.k2 * (self.fst[K.F_HBAR] - self.fst[K.F_HREF])
        y = y_stored + (1.0 - self.fst[K.F_LAM]) * (target - y_stored) + self.fst[K.F_DRIFT]
        return {"mass": M[r, c], "delta_F": x, "delta_R": y, "delta": x + y}

    # ----------------------------------------------------------------------------- growth
    def _tighten_extents(self) -> None:
        """Reset the occupied rows and each row's occupied columns to where mass is.

        The kernels only widen these extents between synchronisations (mass that jumps
        leaves its cell, and the cell's column stays inside them); during a long
        cascade, e.g. a global shock at small k0 that slips ~0.1 / k0, the stale low
        columns made the grid grow without bound (k0 = 1e-4, V = 700 asked for 4.5 GiB
        while the mass spanned 38 rows and ~200 columns).
        """
        cur = int(self.ist[K.I_CUR])
        M = self.bufM[cur]
        chi, clo = self.bufchi[cur], self.bufclo[cur]
        rlo, rhi = int(self.ist[K.I_RLO]), int(self.ist[K.I_RHI])
        ncol = M.shape[1]
        occupied = M[rlo:rhi] != 0.0
        any_mass = occupied.any(axis=1)
        first = np.where(any_mass, occupied.argmax(axis=1), ncol)
        last = np.where(any_mass, ncol - occupied[:, ::-1].argmax(axis=1), 0)
        clo[rlo:rhi] = first
        chi[rlo:rhi] = last
        rows = np.flatnonzero(any_mass)
        if rows.size:
            self.ist[K.I_RLO] = rlo + int(rows[0])
            self.ist[K.I_RHI] = rlo + int(rows[-1]) + 1

    def _grow_rows(self) -> None:
        cur = int(self.ist[K.I_CUR])
        M = self.bufM[cur]
        chi, clo = self.bufchi[cur], self.bufclo[cur]
        # rows a full relaxation can reach; landings of pre-compensated jumps can reach
        # further, so grow generously on both sides
        rmin, rmax, _ = K.bounds(self.ist, self.fst, self.prm, clo, chi)
        nrow = M.shape[0]
        add_lo = max(0, 2 - rmin) + 16 + nrow // 2
        add_hi = max(0, rmax - (nrow - 3)) + 16 + nrow // 2
        new_rows = nrow + add_lo + add_hi
        self._reshape(new_rows, M.shape[1], add_lo, 0)
        log.debug("grid rows %d -> %d", nrow, new_rows)

    def _recentre_or_grow_cols(self) -> None:
        cur = int(self.ist[K.I_CUR])
        M = self.bufM[cur]
        chi, clo = self.bufchi[cur], self.bufclo[cur]
        off = int(self.ist[K.I_OFF])
        rlo, rhi = int(self.ist[K.I_RLO]), int(self.ist[K.I_RHI])
        occupied = chi[rlo:rhi] > clo[rlo:rhi]
        c_first = min(int(clo[rlo:rhi][occupied].min()) if occupied.any() else off, off - K.SCAN - 2)
        c_last = max(int(chi[rlo:rhi][occupied].max()) if occupied.any() else off, off + self.cols_needed)
        ncol = M.shape[1]
        width = c_last - c_first
        # live columns need the window plus room for relaxation to move mass up
        need = width + self.cols_needed // 2 + 16
        new_ncol = ncol if need <= ncol else int(need * 1.5)
        shift = c_first - 4
        if off - shift + self.cols_needed + K.SCAN + 3 > new_ncol:
            new_ncol = off - shift + self.cols_needed + K.SCAN + 16
        self._reshape(M.shape[0], new_ncol, 0, -shift)
        log.debug("grid columns %d -> %d, shifted by %d", ncol, new_ncol, -shift)

    def _reshape(self, nrow: int, ncol: int, row_shift: int, col_shift: int) -> None:
        """Copy the live buffer into arrays of shape (nrow, ncol), moving rows down by
        ``row_shift`` and columns right by ``col_shift``."""
        cur = int(self.ist[K.I_CUR])
        oldM, oldW, oldO = self.bufM[cur], self.bufW[cur], self.bufO[cur]
        oldchi, oldclo = self.bufchi[cur], self.bufclo[cur]
        r_old, c_old = np.nonzero(oldM)
        vals_m = oldM[r_old, c_old]
        vals_w = oldW[r_old, c_old]
        vals_o = oldO[r_old, c_old]
        pending = [a.copy() for a in (self.ex_m, self.ex_y, self.ex_d)]
        self._allocate(nrow, ncol)
        for new, old in zip((self.ex_m, self.ex_y, self.ex_d), pending):
            new[row_shift:row_shift + old.size] = old
        r_new = r_old + row_shift
        c_new = c_old + col_shift
        if c_new.size and (c_new.min() < 0 or c_new.max() >= ncol or r_new.min() < 0 or r_new.max() >= nrow):
            raise RuntimeError("internal error: grid reshape would drop mass")
        self.bufM[0][r_new, c_new] = vals_m
        self.bufW[0][r_new, c_new] = vals_w
        self.bufO[0][r_new, c_new] = vals_o
        nr_old = oldchi.shape[0]
        for r in range(nr_old):
            if oldchi[r] > oldclo[r]:
                self.bufchi[0, r + row_shift] = oldchi[r] + col_shift
                self.bufclo[0, r + row_shift] = oldclo[r] + col_shift
        self.ist[K.I_CUR] = 0
        self.ist[K.I_JBASE] -= row_shift
        self.ist[K.I_RLO] += row_shift
        self.ist[K.I_RHI] += row_shift
        self.ist[K.I_OFF] += col_shift

    # ----------------------------------------------------------------------------- stepping
    def copy(self) -> "Grid":
        """An independent copy of the grid and its state (to branch a protocol)."""
        new = object.__new__(Grid)
        new.__dict__.update(self.__dict__)
        for name in ("bufM", "bufW", "bufO", "bufchi", "bufclo", "ex_m", "ex_y", "ex_d", "cand", "ist", "fst", "prm"):
            setattr(new, name, getattr(self, name).copy())
        return new

    def advance(
        self,
        velocity: float,
        t_stop: float,
        *,
        record_dsigma: float,
        record_dt: float,
        stop_after_shocks: int = 0,
        shock_bins: float = 8.0,
        stop_shift: float = math.inf,
        max_steps: int = 1 << 62,
        watch: Callable[[], None] | None = None,
    ) -> tuple[np.ndarray, np.ndarray, int]:
        """Advance to ``t_stop`` at constant drive velocity.

        Records (rows ``t, sigma, min, max, mean`` over the window since the previous
        record) are written whenever the stress has moved by ``record_dsigma``, after at
        most ``record_dt``, and just before and after every shock.  Shocks (rows
        ``t, sigma_before, sigma_after, shift``) are the steps whose cascade shifted delta_F
        by more than ``shock_bins`` bins.  A cascade that has shifted ``stop_shift`` bins
        and goes on stops the advance there, mid-cascade, with code ``STOP_EVENT`` (the
        rest of its shift is owed).  ``watch``, if given, is called after every chunk of
        steps (about ``_progress.CHUNK_SECONDS`` of wall time; it may raise to stop the
        run).  Returns ``(records, shocks, code)``.
        """
        self.prm[K.P_SHOCK] = shock_bins
        self.prm[K.P_STOP_SHIFT] = stop_shift
        self.prm[K.P_REC_DSIGMA] = record_dsigma
        records: list[np.ndarray] = []
        shocks: list[np.ndarray] = []
        rec = np.zeros((8192, 5))
        shk = np.zeros((1024, 4))
        seen_shocks = 0
        steps_left = int(max_steps)
        try:
            while True:
                self.ist[K.I_NREC] = 0
                self.ist[K.I_NSHOCK] = 0
                remaining_shocks = stop_after_shocks - seen_shocks if stop_after_shocks > 0 else 0
                # the kernel runs at most `chunk` steps per call, about CHUNK_SECONDS of wall
                # time, then comes back here (Ctrl-C, progress); stopping between two steps and
                # going on gives the same result to the last bit
                chunk = min(self._chunk_steps, steps_left)
                steps_before = int(self.ist[K.I_STEPS])
                started = time.perf_counter()
                code = K.advance(
                    self.bufM, self.bufW, self.bufO, self.bufchi, self.bufclo, self.ist, self.fst, self.prm,
                    self.table, self.ex_m, self.ex_y, self.ex_d, self.cand, float(velocity), float(t_stop), chunk,
                    self.cols_needed, rec, float(record_dt), shk, remaining_shocks,
                )
                done = int(self.ist[K.I_STEPS]) - steps_before
                steps_left -= done
                self._tune_chunk(done, time.perf_counter() - started, code == K.MAX_STEPS)
                n_rec = int(self.ist[K.I_NREC])
                n_shk = min(int(self.ist[K.I_NSHOCK]), shk.shape[0])
                if n_rec:
                    records.append(rec[:n_rec].copy())
                if n_shk:
                    shocks.append(shk[:n_shk].copy())
                seen_shocks += n_shk
                _progress.beat()
                if watch is not None:
                    watch()
                if code in (K.NEED_ROWS, K.NEED_COLS):
                    self._tighten_extents()
                if code == K.NEED_ROWS:
                    self._grow_rows()
                elif code == K.NEED_COLS:
                    self._recentre_or_grow_cols()
                elif code in (K.RECORDS_FULL, K.SHOCKS_FULL):
                    continue
                elif code == K.MAX_STEPS and steps_left > 0:
                    continue  # (the end of a chunk, not of the caller's budget)
                elif code == K.INTERNAL_ERROR:
                    raise RuntimeError("internal error in the Fokker-Planck kernel: a synchronisation left the grid")
                else:
                    break
        except KeyboardInterrupt:
            # keep what was recorded: the caller may write it (micro run, Ctrl-C)
            raise Interrupted(records=_joined(records, 5), shocks=_joined(shocks, 4)) from None
        out_rec = _joined(records, 5)
        out_shk = _joined(shocks, 4)
        return out_rec, out_shk, code

    def _tune_chunk(self, steps: int, seconds: float, whole: bool) -> None:
        """Steps per kernel call for about :data:`micro._progress.CHUNK_SECONDS` of wall
        time, from the last call's rate (only a call that ran its whole chunk tells it)."""
        if whole and steps > 0:
            target = steps * _progress.CHUNK_SECONDS / max(seconds, 1e-6)
            self._chunk_steps = int(min(max(target, CHUNK_MIN), 4.0 * steps, CHUNK_MAX))
        elif seconds > 2.0 * _progress.CHUNK_SECONDS and steps > 0:
            self._chunk_steps = int(max(steps * _progress.CHUNK_SECONDS / seconds, CHUNK_MIN))

