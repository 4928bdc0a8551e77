"""The cohort method's state: the cohorts of blocks born in one step, and the delta_R marginal.

:class:`_Cohorts` holds every cohort (its scalars, and per cell in delta_R the density at
the cell's ends and the floor of its margins), the time, the slip and the stress, and
steps itself through one loading step or a shock with the kernels of
:mod:`micro.cohort.kernels` (:meth:`_Cohorts.prepare`, :meth:`_Cohorts.root`,
:meth:`_Cohorts.commit`).  The helpers below make a state from a delta_R marginal (after a
total shock: :func:`_start`) or from a previous result (:func:`_continued`).  The method
itself: :mod:`micro.cohort` (docs/reference/micro_cohort.md).
"""
from __future__ import annotations

import math

import numpy as np

from . import kernels as CK
from . import options
from ..params import Model

#: The quadrature of a step's re-jumps over the step (two-point Gauss-Legendre on [0, 1]);
#: a study may replace it (:func:`micro.study_hooks.gauss_rule`).
_GX, _GW = np.polynomial.legendre.leggauss(2)
_GX, _GW = 0.5 * _GX + 0.5, 0.5 * _GW


class _Cohorts:
    """The state: the cohorts (module docstring), the time, the slip and the stress."""

    #: A cohort's scalars (the kernels' layout), and its cells' layout.
    SCALARS = ("t0", "X0", "s0", "J", "Ej")
    LAYOUT = ("j0", "nn", "off")
    cycles_run = 0  # cycles run from this state and its copies (for the progress line)

    def __init__(self, model: Model, V: float, h: float) -> None:
        self.model, self.V, self.h = model, V, h
        self.lam = model.kappa * model.zbar
        # delta_R lies within (k2 / kappa) * 40 lam of 0 for all but ~1e-17 of the mass
        half = int(math.ceil(45.0 * model.k2 * model.zbar / h)) + 8
        self.ylo, self.ny = -half * h, 2 * half
        cap = 1024
        for name in self.SCALARS:
            setattr(self, name, np.zeros(cap))
        for name in self.LAYOUT:
            setattr(self, name, np.zeros(cap, np.int64))
        self.co = np.zeros((cap, 6))
        self.q, self.m = np.zeros(1 << 16), np.zeros(1 << 17)
        self.n = self.pool = 0
        self.t = self.X = self.sigma = 0.0
        self.last = 0.0
        self.last_dt = 0.0  # the length of the step that slipped ``last``
        self.prev_rate = 0.0  # the slip rate of the step before that
        self.pending = 0.0  # the length of the step being prepared
        self.outside = 0.0
        self.dropped = 0.0  # the mass of the cells dropped by compact()
        self.dt = math.nan  # the time step of the run that left this state
        self.peak_excess = math.inf  # how far the stress peaked above its value at the last shock's start
        self.period_ref = 0.0  # the loading phase the steps are graded to (0: none yet, uniform steps)

    # -------------------------------------------------------------- storage
    def add(self, dep: np.ndarray, age: float = 0.0) -> None:
        """A new cohort born now, with node masses ``dep`` in delta_R and floors 0; its
        members' last jumps were made ``age`` ago on average (half the step they were born
        in), and their margins have relaxed by that much since (``Ej``)."""
        idx = np.flatnonzero(dep > 0.0)
        if idx.size == 0:
            return
        a, b = max(idx[0] - 1, 0), min(idx[-1] + 2, self.ny)  # a node of zero density at each end
        nodes = dep[a:b] / self.h
        cells = b - a - 1
        floors = np.empty((cells, 4))
        floors[:] = (0.0, 0.0, 1.0, 0.0)  # (ends, no kink)
        scalars = (self.t, self.X, self.sigma, 0.0, math.exp(-self.model.gamma * age))
        self._append(scalars, a, np.column_stack([nodes[:-1], nodes[1:]]), floors)

    def _append(self, scalars: tuple[float, float, float, float, float], j0: int, q: np.ndarray, m: np.ndarray) -> None:
        """Store a cohort: its (t0, X0, s0, J, Ej), first node ``j0``, and per cell the density
        at both ends ``q`` (cells x 2) and the floor ``m`` (cells x 4)."""
        cells = q.shape[0]
        if self.n + 1 > self.t0.size or 2 * (self.pool + cells) > self.q.size or 4 * (self.pool + cells) > self.m.size:
            self.compact()
            if self.n + 1 > self.t0.size:
                for name in self.SCALARS + self.LAYOUT:
                    old = getattr(self, name)
                    setattr(self, name, np.concatenate([old, np.zeros_like(old)]))
                self.co = np.zeros((self.t0.size, 6))
            if 2 * (self.pool + cells) > self.q.size or 4 * (self.pool + cells) > self.m.size:
                extra = self.q.size + 2 * cells
                self.q = np.concatenate([self.q, np.zeros(extra)])
                self.m = np.concatenate([self.m, np.zeros(2 * extra)])
        c, p = self.n, self.pool
        for name, value in zip(self.SCALARS, scalars):
            getattr(self, name)[c] = value
        self.j0[c], self.nn[c], self.off[c] = j0, cells, p
        self.q[2 * p:2 * (p + cells)] = q.ravel()
        self.m[4 * p:4 * (p + cells)] = m.ravel()
        self.pool += cells
        self.n += 1

    def _scalars(self, c: int) -> tuple[float, ...]:
        """Cohort ``c``'s scalars, in the order of SCALARS."""
        return tuple(float(getattr(self, name)[c]) for name in self.SCALARS)

    def copy(self) -> _Cohorts:
        """An independent copy (a snapshot to replay steps from)."""
        st = _Cohorts.__new__(_Cohorts)
        st.__dict__.update(self.__dict__)
        n = max(self.n, 1)
        for name in self.SCALARS + self.LAYOUT + ("co",):
            setattr(st, name, getattr(self, name)[:n].copy())
        st.q, st.m = self.q[:2 * self.pool + 2].copy(), self.m[:4 * self.pool + 4].copy()
        return st

    def moved(self, V: float, h: float) -> _Cohorts | None:
        """The same blocks driven at ``V``, on cells of width ``h``: this state's ``h``
        (a copy) or half of it (every cell split in two; the density and the floors are
        the same piecewise-linear functions, so nothing is approximated); None for other
        ``h``.  Cells that fall outside the new nodes count as ``outside``."""
        split = 2 if math.isclose(self.h, 2.0 * h, rel_tol=1e-12) else 1
        if split == 1 and not math.isclose(self.h, h, rel_tol=1e-12):
            return None
        st = _Cohorts(self.model, V, h)
        shift = int(round((self.ylo - st.ylo) / h))  # the new index of this state's node 0
        st.outside = self.outside
        for c in range(self.n):
            o, k = self.off[c], self.nn[c]
            q = self.q[2 * o:2 * (o + k)].reshape(k, 2)
            m = self.m[4 * o:4 * (o + k)].reshape(k, 4)
            if split == 2:
                q, m = _split_cells(q, m)
            j0 = shift + split * self.j0[c]
            lo, hi = max(0, -j0), max(min(q.shape[0], st.ny - 1 - j0), 0)
            if lo > 0 or hi < q.shape[0]:
                cut = np.ones(q.shape[0], bool)
                cut[lo:hi] = False
                lost = np.empty(int(cut.sum()))
                CK.cell_survivors(lost.size, q[cut].ravel(), m[cut].ravel(), h, self.lam, lost)
                st.outside += float(lost.sum())
            if hi > lo:
                st._append(self._scalars(c), j0 + lo, q[lo:hi], m[lo:hi])
        st.t, st.X, st.sigma, st.last, st.last_dt, st.dt = self.t, self.X, self.sigma, self.last, self.last_dt, self.dt
        st.prev_rate = self.prev_rate
        st.period_ref = self.period_ref
        st.dropped = self.dropped
        return st

    def marginal(self, c: int) -> tuple[np.ndarray, np.ndarray]:
        """Cohort ``c``'s delta_R density as masses on its nodes (those with mass), as
        (nodes, masses): after a total shock, with ``c`` its newborn cohort, the state's
        marginal."""
        masses = self.dense(c)
        keep = masses > 0.0
        return self.ylo + np.flatnonzero(keep) * self.h, masses[keep]

    def dense(self, c: int) -> np.ndarray:
        """Cohort ``c``'s delta_R density as masses on all the state's nodes."""
        o, k = self.off[c], self.nn[c]
        out = np.zeros(self.ny)
        out[self.j0[c]:self.j0[c] + k + 1] = np.concatenate([self.q[2 * o:2 * (o + k):2], [self.q[2 * (o + k) - 1]]])
        return out * self.h

    def cell_masses(self) -> np.ndarray:
        """The mass of every cell that has not crossed yet."""
        out = np.empty(self.pool)
        CK.cell_survivors(self.pool, self.q, self.m, self.h, self.lam, out)
        return out

    def node_masses(self, cell: np.ndarray | None = None) -> np.ndarray:
        """The delta_R marginal of every block that has not crossed yet (all cohorts), as
        masses on the nodes (each cell's surviving mass on its lower node; from ``cell``,
        the cells' masses, if known).  The cells are packed in cohort order."""
        cell = self.cell_masses() if cell is None else cell
        node = np.repeat(self.j0[:self.n] - self.off[:self.n], self.nn[:self.n]) + np.arange(self.pool)
        return np.bincount(node, weights=cell, minlength=self.ny)

    def surviving(self, cell: np.ndarray | None = None) -> np.ndarray:
        """The mass of every cohort that has not crossed yet (from ``cell``, the cells'
        masses, if known)."""
        cell = self.cell_masses() if cell is None else cell
        return np.add.reduceat(cell, self.off[:self.n]) if self.n else np.zeros(0)

    def compact(self, cell: np.ndarray | None = None) -> None:
        """Drop the cells whose surviving mass is below CELL_FLOOR (their density set to 0,
        and the cohort trimmed to the cells that remain: its blocks with margins so far
        above the threshold that they have all but crossed; their mass is counted in
        ``dropped``), the cohorts with no cell left, and pack the cells.  ``cell``: the
        cells' masses, if known."""
        opt = options.DEFAULT
        cell = self.cell_masses() if cell is None else cell
        q, m = np.zeros_like(self.q), np.zeros_like(self.m)
        keep = np.empty(max(self.n, 1), np.int64)
        i, p, dropped = CK.compact(self.n, self.j0, self.nn, self.off, self.q, self.m, cell, opt.CELL_FLOOR, keep, q, m)
        for name in self.SCALARS:
            column = getattr(self, name)
            column[:i] = column[keep[:i]]
        self.dropped += dropped
        self.q, self.m, self.pool, self.n = q, m, p, i

    # -------------------------------------------------------------- dynamics
    def prepare(self, dt: float) -> tuple[float, float]:
        md = self.model
        self.pending = dt
        return CK.coefficients(self.t, dt, self.X, self.sigma, self.V, md.k0, md.k1, md.k2, md.f_th, md.gamma,
                               self.t0, self.X0, self.s0, self.J, self.Ej, self.n, self.co, self.j0, self.nn, self.off,
                               self.q, self.m, self.ylo, self.h)

    def closure(self, dX: float) -> tuple[float, float]:
        return CK.closure(dX, self.n, self.co, self.j0, self.nn, self.off, self.q, self.m, self.ylo, self.h,
                          self.lam, self.model.zbar)

    def root(self, below: float = 0.0) -> tuple[float, int]:
        """The step's slip (after :meth:`prepare`) and 0, or 1 if the step starts a shock.
        ``below``: a slip known to be short of the root (0: none), where Newton starts;
        otherwise it starts at WARM times the slip rate extrapolated from the last two
        steps, times this step."""
        opt = options.DEFAULT
        xmin = max(1e-9 * self.model.zbar, 0.25 * self.last)
        guess = below
        if guess <= 0.0 and self.last_dt > 0.0 and self.prev_rate > 0.0:
            rate = self.last / self.last_dt
            guess = opt.WARM * rate * min(rate / self.prev_rate, 2.0) * self.pending
        return CK.smallest_root(self.n, self.co, self.j0, self.nn, self.off, self.q, self.m, self.ylo, self.h,
                                self.lam, self.model.zbar, 1e-15 * self.model.zbar, xmin, guess)

    def commit(self, dX: float, dt: float, phi: float, Edt: float) -> None:
        opt = options.DEFAULT
        md = self.model
        dep = np.zeros(self.ny)
        self.outside += CK.commit(dX, self.n, self.co, self.j0, self.nn, self.off, self.q, self.m, self.J, self.X0,
                                  self.s0, self.X, Edt, phi, self.ylo, self.h, self.lam, md.k2, md.kappa, md.f_th,
                                  _GX, _GW, dep)
        if dt > 0.0:
            self.prev_rate = self.last / self.last_dt if self.last_dt > 0.0 else 0.0
            self.last, self.last_dt = dX, dt
        else:
            # a shock: the creep before it says nothing of the next loading phase's, so
            # its first two steps start Newton from 0 (``last`` still sets the step cap)
            self.prev_rate = self.last_dt = 0.0
        self.t += dt
        self.X += dX
        self.sigma += md.k0 * (self.V * dt - dX)
        self.add(dep, opt.AGE * dt)

    def shock(self) -> float:
        """Apply the shock that starts now (the closure in zero time, run to its root beyond
        its positive minimum: :meth:`shock_root`) and return its slip; RuntimeError if the
        closure has no root."""
        self.prepare(0.0)
        x, _ = self.root()
        slip = self.shock_root(max(x, 1e-12 * self.model.zbar))
        self.commit(slip, 0.0, 0.0, 1.0)
        return slip

    def shock_root(self, x0: float) -> float:
        """The slip of the shock: the closure's root beyond its positive minimum (after
        :meth:`prepare` with dt = 0), bracketed by doubling, bisected to a hundredth,
        then safeguarded Newton in the bracket (a bisection step where Newton leaves it)."""
        lo, hi = x0, max(2.0 * x0, self.model.zbar)
        while self.closure(hi)[0] > 0.0:
            lo, hi = hi, 2.0 * hi
            if hi > 1e12:
                raise RuntimeError("the shock's closure has no root")
        while hi - lo > 1e-14 * hi:
            if hi - lo > 1e-2 * hi:  # (so the first pass bisects, and sets x, H, dH)
                x = 0.5 * (lo + hi)
                H, dH = self.closure(x)
            else:
                step = -H / dH if dH < 0.0 else math.inf
                if abs(step) <= 1e-14 * x:
                    return x
                x = x + step if lo < x + step < hi else 0.5 * (lo + hi)
                H, dH = self.closure(x)
            if H > 0.0:
                lo = x
            else:
                hi = x
        return hi


# ------------------------------------------------------------------------------ the delta_R marginal
def _rows(delta_R: np.ndarray, mass: np.ndarray, eps: float, j_lo: int, n_rows: int) -> tuple[np.ndarray, float]:
    """The delta_R marginal as masses on the nodes ``(j_lo + i) eps``, each atom shared
    linearly between its two neighbours (mass and first moment kept; the map is then
    continuous in the atoms' positions); also the mass that fell outside the nodes."""
    u = delta_R / eps - j_lo
    i = np.floor(u).astype(np.int64)
    f = u - i
    x = np.zeros(n_rows)
    outside = 0.0
    for idx, w in ((i, mass * (1.0 - f)), (i + 1, mass * f)):
        inside = (idx >= 0) & (idx < n_rows)
        np.add.at(x, idx[inside], w[inside])
        outside += float(w[~inside].sum())
    return x, outside


def _initial_marginal(model: Model, eps: float, j_lo: int, n_rows: int) -> np.ndarray:
    """A start: every dashpot relaxed to the lag of an Exp(kappa zbar) margin, the
    marginal of ``(k2 / kappa) (<delta> - delta)`` (the first shock's image)."""
    lam = model.kappa * model.zbar
    delta = (np.arange(4000) + 0.5) * (lam * 40.0 / 4000)
    w = np.exp(-delta / lam)
    y = model.k2 / model.kappa * (lam - delta)
    x, _ = _rows(y, w / w.sum(), eps, j_lo, n_rows)
    return x


def _split_cells(q: np.ndarray, m: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Every cell (densities ``q`` at its ends, floor ``m``: ends, kink position, kink
    value) as its two halves, the same functions."""
    m0, m1, sk, mk = m.T
    mid_q = 0.5 * (q[:, 0] + q[:, 1])
    with np.errstate(divide="ignore", invalid="ignore"):
        mid_m = np.where(sk >= 0.5, m0 + (mk - m0) * np.where(sk > 0.0, 0.5 / sk, 0.0),
                         mk + (m1 - mk) * (0.5 - sk) / (1.0 - sk))
    left_kink = (sk > 0.0) & (sk < 0.5)
    right_kink = (sk > 0.5) & (sk < 1.0)
    left = np.column_stack([m0, mid_m, np.where(left_kink, 2.0 * sk, 1.0), np.where(left_kink, mk, mid_m)])
    right = np.column_stack([mid_m, m1, np.where(right_kink, 2.0 * sk - 1.0, 1.0), np.where(right_kink, mk, m1)])
    q_out = np.empty((2 * q.shape[0], 2))
    q_out[0::2] = np.column_stack([q[:, 0], mid_q])
    q_out[1::2] = np.column_stack([mid_q, q[:, 1]])
    m_out = np.empty((2 * m.shape[0], 4))
    m_out[0::2], m_out[1::2] = left, right
    return q_out, m_out


def _start(model: Model, V: float, h: float, p: tuple[np.ndarray, np.ndarray] | None,
           dep: np.ndarray | None = None) -> _Cohorts:
    """The state after a total shock: Exp(kappa zbar) margins times a delta_R marginal,
    ``p`` (nodes, masses), or ``dep`` (masses on the state's own nodes), or every dashpot
    relaxed to the lag of an Exp margin."""
    st = _Cohorts(model, V, h)
    j_lo = int(round(st.ylo / h))
    if dep is not None:
        dep = dep / dep.sum()
    elif p is None:
        dep = _initial_marginal(model, h, j_lo, st.ny)
    else:
        # (the nodes' range depends on h: negligible tails may fall off)
        dep, outside = _rows(p[0], p[1] / p[1].sum(), h, j_lo, st.ny)
        if outside > 1e-12:
            raise ValueError(f"the starting delta_R marginal lies outside the nodes ({outside:.2g} of its mass)")
    st.sigma = model.f_th - st.lam + float(dep @ (st.ylo + np.arange(st.ny) * h))
    st.add(dep)
    return st


def _continued(start, model: Model, V: float, h: float) -> _Cohorts | None:
    """The whole state of a previous result ``start`` (same model) to continue from at
    ``V`` with cells ``h``, or None if it has none or it cannot be moved there."""
    state = getattr(start, "state", None)
    if state is None or start.model != model:
        return None
    return state.moved(V, h)


