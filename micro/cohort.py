r"""Stick-slip cycles by cohorts of exponential margins: no grid in the margin.

A grid-free solver of the mean-field dynamics (docs/reference/micro_cohort.md).  Between
its own jumps a block's margin is linear in its state at its last jump, with
coefficients common to all blocks born at the same time:

.. math:: \delta(t) = \beta(\tau)\,\delta' + B(t; t_0) - \alpha (1 - e^{-\gamma\tau})\,\delta_R',
          \qquad \beta(\tau) = 1 - \frac{k_2}{\kappa}(1 - e^{-\gamma\tau}),

with :math:`\delta'` and :math:`\delta_R'` its margin and delta_R at birth, :math:`\tau`
its age and :math:`\alpha = (k_0 + k_1)/\kappa`.  With exponential jumps every block
that jumps leaves with :math:`\delta' \sim \mathrm{Exp}(\kappa\bar z)`, independent of the
rest.  So the blocks born in one step (a *cohort*) are Exp(kappa zbar) in
:math:`\delta'` times a density in :math:`\delta_R'`, and the members that have not
jumped again are those above a floor :math:`\delta' > m(\delta_R')`.  Nothing is
discretised in the margin: a cohort's density is piecewise linear on cells of width
``h`` in delta_R, each cell with a floor that is linear or has one kink, and every
crossed mass is an exact integral of an exponential.  A step of length ``dt`` (up to
four times longer in the middle of a loading phase many relaxation times long:
:func:`_step_length`) solves the mean-field closure for its slip (``dX = zbar x`` the
jumps it causes, a crossed block jumping again as a Poisson process of its overshoot);
the loading phase ends where the closure's smallest root
jumps (a fold), located by bisecting the step; the shock is the same closure in zero
time.  Where a near-critical avalanche runs away is then a continuous function of the
state, so the cycle-to-cycle sequence converges smoothly (geometrically) and is
extrapolated by Aitken's method.  ``sigma_max`` is the largest stress of the cycle: the creep before a
shock can outrun the drive, so the stress peaks before the shock starts
(``sigma_before``, the paper's sigma_B; 1e-3 lower at k0 = 0.3).

Shocks need not be total: the blocks a shock leaves unjumped stay in their cohorts
with raised floors (at k0 = 0.1 and 0.3 their cohorts live for many cycles, and the
cost per cycle grows with them; cells whose blocks have all but crossed are dropped).
The kernels sum the cohorts in parallel (numba threads) when there are many.
A step's newborns made their jumps, on average, half a step before its end: their own
relaxation (the terms in their margin at birth) starts there, which makes the method
second order in ``dt`` (``AGE``; first order when it started at the step's end).
Refinement variables: the time step ``dt`` and the cell width ``h`` (measured orders in
benchmarks/micro_cohort_refinement.py).  Needs exponential jumps, and a loading phase
that ends in a shock within ``20 kappa zbar / (k0 V)`` (otherwise ``applicable=False``).
"""
from __future__ import annotations

import logging
import math
import time

import numpy as np
import scipy.linalg

from . import _cohort_kernels as CK
from . import _cohort_newton
from . import _progress
from ._threads import blas_single_threaded
from .methods import CUTOFF_TAIL, cohort_not_applicable as not_applicable  # noqa: F401  (micro.cohort's names)
from .params import Model
from .results import CycleFixedPoint

__all__ = ["cycle_cohorts"]

log = logging.getLogger(__name__)

_GX, _GW = np.polynomial.legendre.leggauss(2)
_GX, _GW = 0.5 * _GX + 0.5, 0.5 * _GW
#: The transient's fixed point (at twice the step and cell) is solved to this multiple of
#: the run's tolerance, and at least to COARSE_FLOOR: its change to the run's own is the
#: run's discretisation error, so its own error must stay below that change.
COARSE_TOL = 4.0
COARSE_FLOOR = 3e-4
#: Cells whose surviving mass (a fraction of all blocks) is below this are dropped.
CELL_FLOOR = 1e-13
#: The start of a shock is located to this fraction of the time step.
FOLD_TOL = 1e-7
#: A step whose creep exceeds this fraction of the drive keeps a snapshot of the state
#: before it, from which the end of the loading phase is replayed finely for the peak.
PEAK_CREEP = 0.2
#: Where the replay found the peak less than this above the stress at the shock's start
#: (total shocks, small k0: 1e-12 and less), the next cycles of the run skip it.
PEAK_FLOOR = 1e-10
#: A loading phase shorter than this is resolved with steps ``dt * T / SHORT_PHASE`` (T its
#: length): 50 steps at the default dt = 0.01, twice as many at half the dt (so that
#: halving dt refines close to V^c too).
SHORT_PHASE = 0.5
#: Long loading phases are graded: a step ``dt`` within ``1 / gamma`` (the dashpots'
#: relaxation time) of the shock before and of the loading phase's end, longer in between
#: (``dt`` times the distance to the nearer end in units of ``1 / gamma``, at most
#: GRADED_MAX times ``dt``; :func:`_step_length`).  The end is that of a reference loading
#: phase, kept until a loading phase differs from it by more than GRADED_SLACK / gamma (a
#: grid that followed every cycle's length would feed back on the shock's start).
GRADED_MAX = 4.0
GRADED_SLACK = 0.25
#: Anderson's acceleration (close to V^c): the window, and the evaluations without progress
#: after which it stops.
ANDERSON_WINDOW = 10
ANDERSON_STALL = 8
#: Anderson's map is on the marginal of the blocks a shock made jump (the others carried
#: from one evaluation to the next): it is used only where those others are at most this
#: fraction.
ANDERSON_UNJUMPED = 1e-3
#: Anderson's iteration stops when its step (the preconditioned residual, about the
#: distance to the fixed point, in mass) is below this times ``tol``: sigma moved by about
#: 0.15 of the step there (k0 = 1e-4, 0.95 V^c), so the plain cycles after it find their
#: steps below tol / 100.
ANDERSON_TOL = 0.05
#: Halvings of a step whose cycle the map does not apply to (a changed time step, too
#: many blocks unjumped) before Anderson's iteration gives up.
ANDERSON_BACKTRACKS = 3
#: The band preconditioner of Anderson's map (:func:`_band_preconditioner`): BAND_COLOURS
#: cycles at frozen slips, each from every BAND_COLOURS-th node, and a node's image taken
#: from BAND_COLOURS - BAND_ABOVE nodes below it to BAND_ABOVE - 1 above (a block's
#: delta_R moves by a few nodes in a cycle, with an exponential tail downwards).
BAND_COLOURS = 16
BAND_ABOVE = 6
#: The forward-difference step of the full map's response to a shift of the marginal.
SHIFT_FD = 1e-4
#: Where the frozen map grows (its slowest multiplier >= 1: Anderson's preconditioner bounds
#: nothing), the fixed point is solved by Newton-Krylov on the whole cycle map
#: (:func:`_newton`), each cycle quantity to this fraction of ``tol`` (its change over the
#: last Newton step, which bounds the error of the iterate after it: at k0 = 1e-3,
#: 0.85 V^c the step that moved sigma_max by 2.8e-5 left it 2.4e-7 from the fixed point,
#: which a third step, 27 cycles, then showed at the former 0.1).
NEWTON_TOL = 0.5
#: A run whose five-cycle window contracts by more than this a cycle is accelerated (where
#: the loading phase is shorter than SHORT_PHASE and shocks all but total); one that
#: extrapolated (Aitken) such a sequence without the acceleration says in its message that
#: its error estimate can miss a slower mode (measured:
#: studies/micro_cohort_estimate_check.py).  (Steps below tol / 100 say nothing alone:
#: they can be a stress passing through zero steps; the state's move bounds what remains,
#: :func:`_state_tail`.)
SLOW_CAVEAT = 0.9
#: A step's Newton iteration for its slip starts at this fraction of the slip rate
#: extrapolated from the two steps before, times its length (:meth:`_Cohorts.root`).
WARM = 0.97
#: Most cells the cohorts may hold (about 50 MB).
MAX_CELLS = 3_000_000
#: A last step d between cycles leaves at most STILL * d to go when they contract by 0.8 a cycle.
STILL = 5.0
#: The newborns of a step made their last jumps this fraction of it before its end, on
#: average (they cross at a steady rate; the re-jumps are counted to the end).
AGE = 0.5
#: Aitken's extrapolation only where every ratio of successive steps is at most this: five
#: cycles cannot tell a ratio closer to 1 from a drift, and a ratio a hair below 1 sends
#: the extrapolation anywhere (a period of -0.43 from cycles at 0.2097, steps of 2.5e-8 a
#: cycle); such a sequence is judged as one that does not contract.
AITKEN_MAX_RATIO = 0.999
#: Passed as ``start``: begin from the first shock's image, without a coarser run first.
_NO_COARSE = object()


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
        cell = self.cell_masses() if cell is None else cell
        q, m = np.zeros_like(self.q), np.zeros_like(self.m)
        keep = np.empty(max(self.n, 1), np.int64)
        i, p, dropped = CK.compact(self.n, self.j0, self.nn, self.off, self.q, self.m, cell, CELL_FLOOR, keep, q, m)
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
        xmin = max(1e-9 * self.model.zbar, 0.25 * self.last)
        guess = below
        if guess <= 0.0 and self.last_dt > 0.0 and self.prev_rate > 0.0:
            rate = self.last / self.last_dt
            guess = WARM * rate * min(rate / self.prev_rate, 2.0) * self.pending
        return CK.smallest_root(self.n, self.co, self.j0, self.nn, self.off, self.q, self.m, self.ylo, self.h,
                                self.lam, self.model.zbar, 1e-15 * self.model.zbar, xmin, guess)

    def commit(self, dX: float, dt: float, phi: float, Edt: float) -> None:
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
        self.add(dep, AGE * dt)

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


def _step_too_long(period: float, step: float, dt: float) -> bool:
    """Whether a loading phase of ``period`` has too few steps of ``step`` for the time
    step ``dt``: fewer than 0.8 of ``SHORT_PHASE / dt`` (not at every small change of the
    period: each cut of the step restarts the cycle sequence)."""
    return period < 0.8 * SHORT_PHASE / dt * step


def _phase_step(period: float, dt: float) -> float:
    """The step for loading phases of ``period`` at the time step ``dt``: ``dt``, or
    ``dt * period / SHORT_PHASE`` where the phase is shorter than SHORT_PHASE."""
    return dt * min(1.0, period / SHORT_PHASE)


def _step_off(period: float, step: float, dt: float) -> bool:
    """Whether the step ``step`` is off the one for loading phases of ``period``
    (:func:`_phase_step`) by more than a quarter: too long (:func:`_step_too_long`), or too
    short, left from a shorter phase of the transient (then the resolution would depend on
    the path to the cycle, not on ``dt``)."""
    return _step_too_long(period, step, dt) or step < 0.8 * _phase_step(period, dt)


def _step_length(since: float, ref: float, dt: float, gamma: float) -> float:
    """The loading phase's step at time ``since`` after the last shock, graded to a loading
    phase of length ``ref`` (GRADED_MAX).  A function of the step's start only, so halving
    ``dt`` halves every step."""
    return dt * min(GRADED_MAX, max(1.0, gamma * min(since, ref - since)))


def _product_cycle(model: Model, V: float, h: float, step: float, ref: float,
                   x: np.ndarray) -> tuple[_Cohorts, dict, np.ndarray | None]:
    """The cycle map on the delta_R marginal after a total shock: one cycle (steps of
    ``step``, graded to the loading phase ``ref``) from the product state of Exp margins
    and the marginal ``x``.  Returns the state after it, the cycle's row and the
    normalised marginal of the blocks its shock made jump (None if the cycle failed)."""
    return _cycle_image(_start(model, V, h, None, dep=x), step, ref)


def _cycle_image(st: _Cohorts, step: float, ref: float) -> tuple[_Cohorts, dict, np.ndarray | None]:
    """One cycle of the state ``st`` just after a shock (steps of ``step``, graded to
    ``ref``): the state after it, the cycle's row and the normalised marginal of the blocks
    its shock made jump (None if the cycle failed)."""
    st.period_ref = ref
    out = _one_cycle(st, step)
    if not out["ok"]:
        return st, out, None
    g = st.dense(st.n - 1)
    return st, out, g / g.sum()


def _carried_cycle(base: _Cohorts, step: float, ref: float,
                   x: np.ndarray) -> tuple[_Cohorts, dict, np.ndarray | None]:
    """The cycle map on the delta_R marginal after a shock, with the blocks the shock left
    unjumped carried along: one cycle (steps of ``step``, graded to ``ref``) from a copy of
    the state ``base`` just after a shock, its newborns' marginal replaced by ``x`` (scaled
    to their mass; the stress moved by the change of their mean delta_R, so that the mean
    lag stays zero: docs/reference/micro_cohort.md section 2).  Returns the state after it,
    the cycle's row and the normalised marginal of the blocks its shock made jump (None if
    the cycle failed).  Where shocks are total this is :func:`_product_cycle`."""
    st = base.copy()
    c = st.n - 1
    old = st.dense(c)
    new = x * (old.sum() / x.sum())
    st.pool -= st.nn[c]
    st.n -= 1
    st.sigma += float((new - old) @ (st.ylo + np.arange(st.ny) * st.h))
    st.add(new)
    return _cycle_image(st, step, ref)


def _frozen_cycle(model: Model, V: float, h: float, sigma: float, steps, x: np.ndarray) -> np.ndarray:
    """The cycle at frozen slips: the product state of Exp margins and node masses ``x``
    (not normalised) at stress ``sigma``, taken through a cycle's ``steps`` (its
    ``(length, slip)`` pairs, the shock's last) with their slips imposed instead of
    solved for.  Returns the node masses of the blocks the shock made jump.

    With the slips given, where each member crosses does not depend on the density, so
    this is linear in ``x`` (up to the floors' kink rule, which keeps each cell's surviving
    mass: :func:`_band_preconditioner`); from the cycle's own start it repeats the cycle."""
    st = _Cohorts(model, V, h)
    st.sigma = sigma
    st.add(x)
    for length, slip in steps:
        phi, Edt = st.prepare(length)
        st.commit(slip, length, phi, Edt)
    return st.dense(st.n - 1)


def _support(x: np.ndarray, g: np.ndarray) -> np.ndarray:
    """The nodes a map's Jacobian at ``x`` (image ``g``) lives on: where either has mass,
    with two nodes of margin below and above."""
    nodes = np.flatnonzero((x > 0.0) | (g > 0.0))
    return np.arange(max(nodes[0] - 2, 0), min(nodes[-1] + 3, x.size))


def _band_preconditioner(model: Model, V: float, h: float, G, x: np.ndarray, out: dict, g: np.ndarray):
    """``M``, approximately ``(I - J)^-1`` for the Jacobian ``J`` of the cycle map ``G``
    (x -> (state, row, image)) at ``x`` (its cycle ``out``, its image ``g``), and the
    slowest multipliers of the frozen map.

    The cycle map is slow because of the single blocks: between shocks each block's
    delta_R relaxes alone, by about ``1 - alpha (1 - exp(-gamma T))`` a cycle, so the
    marginal's moments relax like its powers (the multipliers 0.98, 0.97, ... close to
    V^c, a continuum of them).  With the cycle's slips frozen the map is linear in the
    marginal and moves each node's mass by a few nodes: ``L``, banded, found from
    BAND_COLOURS cycles at frozen slips (:func:`_frozen_cycle`), each from every
    BAND_COLOURS-th node at once.  What the frozen map lacks is the slips' response to the
    marginal, of low rank: the normalisation (the map's mass is 1) is taken out of ``L``,
    and the full map's response to a shift of the marginal by one node (in the frozen map
    the mean relaxes like a block; in the full map the stress follows it) is measured by
    one more cycle and put in; Anderson's mixing deals with the rest
    (docs/reference/micro_cohort.md, section 4)."""
    S = _support(x, g)
    n = S.size
    L = np.zeros((n, n))
    for c in range(min(BAND_COLOURS, n)):
        cols = np.arange(c, n, BAND_COLOURS)
        e = np.zeros(x.size)
        e[S[cols]] = 1.0
        image = _frozen_cycle(model, V, h, out["start"], out["steps"], e)[S]
        for j in cols:
            lo, hi = max(j - BAND_COLOURS + BAND_ABOVE, 0), min(j + BAND_ABOVE, n)
            L[lo:hi, j] = image[lo:hi]
    gS = g[S] / g[S].sum()
    L -= np.outer(gS, L.sum(axis=0))
    # the marginal moved up by one node: the full map's response, by a forward difference
    y = S * h  # (node positions up to an offset, which acts on the mass alone: zero in a residual)
    shift = np.zeros(x.size)
    shift[1:] = x[:-1] - x[1:]
    shift[0] = -x[0]
    _, _, g_shift = G(x + SHIFT_FD * shift)
    v, Jv = shift[S], (g_shift[S] - gS) / SHIFT_FD
    L += np.outer(Jv - L @ v, y) / (y @ v)
    lu = scipy.linalg.lu_factor(np.eye(n) - L)
    slowest = np.sort(np.abs(np.linalg.eigvals(L)))[::-1][:3]

    def M(r: np.ndarray) -> np.ndarray:
        out = r.copy()
        out[S] = scipy.linalg.lu_solve(lu, r[S])
        return out
    return M, slowest


def _applied_cycle(base: _Cohorts, step: float, ref: float, dt: float, v: np.ndarray):
    """:func:`_carried_cycle` from ``base`` with the marginal ``v``, its image ``g`` None
    where the cycle map does not apply: the cycle failed, left more than ANDERSON_UNJUMPED
    of the blocks unjumped, or needs a shorter step than ``step`` (the accelerations'
    common rule)."""
    st, out, g = _carried_cycle(base, step, ref, v)
    if g is None or out["unjumped"] > ANDERSON_UNJUMPED or _step_too_long(out["period"], step, dt):
        return st, out, None
    return st, out, g


def _marginal(state: _Cohorts) -> np.ndarray:
    """The delta_R marginal of the blocks ``state``'s last shock made, normalised."""
    dep = state.dense(state.n - 1)
    return dep / dep.sum()


def _anderson(model: Model, V: float, h: float, step: float, dt: float, base: _Cohorts, ref: float,
              tol: float, max_evals: int) -> tuple[_Cohorts | None, int, float]:
    """Anderson's acceleration of the cycle map on the delta_R marginal after a shock
    (:func:`_carried_cycle`, from the state ``base`` just after one), for the sequences
    that contract slowly (close to V^c), preconditioned by the map at frozen slips
    (:func:`_band_preconditioner`).

    One evaluation is one cycle (its steps graded to the loading phase ``ref``), the blocks
    the last shock left unjumped (at most ANDERSON_UNJUMPED of the mass) carried from the
    evaluation before.  Type-II Anderson mixing of the preconditioned map
    x + M (G(x) - x) with a window of ANDERSON_WINDOW, stopped when its step (about the
    distance to the fixed point) is below ``tol`` of the mass, when ANDERSON_STALL
    evaluations did not improve on the best one, or after the first evaluation if the
    frozen map's slowest multiplier is >= 1.  Returns the state after the best
    evaluation's cycle (a state of the full dynamics), or None if the map does not apply,
    the evaluations used, the frozen map's slowest multiplier (NaN if the preconditioner
    was not built) and the best evaluation's step (inf if none).
    """
    xs: list[np.ndarray] = []
    gs: list[np.ndarray] = []
    x, best, best_f = _marginal(base), None, math.inf
    since, M, slow = 0, None, math.nan
    backtracks = 0
    for k in range(1, max_evals + 1):
        st, out, g = _applied_cycle(base, step, ref, dt, x)
        if g is None:
            if not xs or backtracks >= ANDERSON_BACKTRACKS:
                return best, k, slow, best_f
            # far from the fixed point (a sweep's first cycles) a step can overshoot into
            # a state the map does not apply to: halve it towards the last evaluated one
            backtracks += 1
            x = 0.5 * (x + xs[-1])
            continue
        backtracks = 0
        if M is None:
            M, slowest = _band_preconditioner(model, V, h, lambda v, b=base: _carried_cycle(b, step, ref, v),
                                              x, out, g)
            slow = float(slowest[0])
            log.debug("anderson: frozen map's slowest multipliers %s", slowest)
        step_x = M(g - x)  # about the distance to the fixed point
        f = float(np.abs(step_x).sum())
        log.debug("anderson %d: sigma_max %.10f, the cycle moves %.2e of the mass, the step %.2e", k,
                  out["sigma_max"], float(np.abs(g - x).sum()), f)
        base = st  # (the next evaluation carries the blocks this shock left)
        if f < best_f:
            best, best_f, since = st, f, 0
        else:
            since += 1
        # (where the frozen map grows along some mode the preconditioned iteration does not
        # contract: at k0 = 1e-3, 0.85 V^c its 35 evaluations wandered between 1e-3 and 4e-1
        # of the mass; the caller solves by Newton-Krylov instead)
        if best_f <= tol or since >= ANDERSON_STALL or slow >= 1.0:
            return best, k, slow, best_f
        xs.append(x)
        gs.append(x + step_x)
        del xs[:-ANDERSON_WINDOW - 1], gs[:-ANDERSON_WINDOW - 1]
        if len(xs) < 2:
            x = np.maximum(gs[-1], 0.0)
            x /= x.sum()
            continue
        F = np.array([b - a for a, b in zip(xs, gs)])
        dF, dG = np.diff(F, axis=0).T, np.diff(np.array(gs), axis=0).T
        gamma = np.linalg.lstsq(dF, F[-1], rcond=None)[0]
        x = np.maximum(gs[-1] - dG @ gamma, 0.0)
        x /= x.sum()
    return best, max_evals, slow, best_f


def _newton(step: float, dt: float, base: _Cohorts, tol: float, max_evals: int) -> _cohort_newton.NewtonKrylov:
    """The fixed point of the cycle map on the delta_R marginal after a shock
    (:func:`_carried_cycle` from the state ``base`` just after one, at the step ``step``
    and its graded-grid reference), by Newton-Krylov on the whole map
    (:mod:`micro._cohort_newton`: GMRES with Jacobian-vector products by differences of
    the map, no frozen-slip linearisation), each judged column to NEWTON_TOL * ``tol``,
    in at most ``max_evals`` cycles.  The map does not apply (the evaluation is refused)
    where a cycle fails, leaves more than ANDERSON_UNJUMPED of the blocks unjumped or
    needs a shorter step.  At k0 = 0.01, 0.9 V^c, cell kappa zbar / 40, where the frozen
    map grows (multiplier 1.03), a solve to 1e-9 from near the fixed point takes 50-80
    cycles and ends at a residual of 1e-10 to 1e-8 of the mass (the map's round-off;
    docs/validation/micro_cohort.md section 5)."""
    ref = base.period_ref
    if max_evals < 4 or not base.dense(base.n - 1).sum() > 0.0:
        return _cohort_newton.NewtonKrylov(message="no budget left for Newton-Krylov")

    def cycle_map(state: _Cohorts):
        """The map from ``state`` (carrying the blocks its last shock left), and its marginal."""
        return (lambda v: _applied_cycle(state, step, ref, dt, v)), _marginal(state)
    G, x0 = cycle_map(base)
    return _cohort_newton.solve(G, x0, tol=NEWTON_TOL * tol, max_evals=max_evals,
                                columns=tuple(COLUMNS[i] for i in JUDGED), log=log.debug, rebase=cycle_map)


#: The leading multipliers: Arnoldi's Krylov space and its tolerance (scipy's ``eigs``).
#: (12 vectors to 1e-3: 14 cycles at k0 = 0.01 and 0.1, 0.5 V^c, the leading multiplier within
#: 3e-4 of the one from 25 vectors to 1e-4, which takes four times as many cycles.)
MULTIPLIER_NCV = 12
MULTIPLIER_TOL = 1e-3


def cycle_multipliers(cycle: CycleFixedPoint, k: int = 3) -> np.ndarray:
    """The ``k`` largest multipliers of the cycle map at a converged cycle (its Floquet
    multipliers, as the map on the delta_R marginal after a shock sees them), by modulus.

    Arnoldi's method (``scipy.sparse.linalg.eigs``, a Krylov space of ``MULTIPLIER_NCV``
    vectors, tolerance ``MULTIPLIER_TOL``) on the map's Jacobian, each product ``J v`` a
    forward difference of one cycle from the cycle's last state
    (:func:`_carried_cycle`, the step of the Newton-Krylov, ``micro._cohort_newton.FD_STEP``
    of the mass), on the nodes where the marginal holds more than 1e-12 of the mass (a
    perturbation of an empty node leaves the positive densities, and its quotient is not
    the Jacobian's).  The marginal is normalised by the map, so the mass is no direction
    of it, and the stress follows the newborns' mean delta_R (the mean lag stays zero),
    so a shift of the lags is none either: the cycle is stable where every multiplier
    lies inside the unit circle.  About 10-15 cycles (twice what the cycle's own
    fixed point took far from V^c).

    Only where the shocks are total (at most ``ANDERSON_UNJUMPED``, 1e-3, of the blocks
    left unjumped): the map keeps the blocks a shock leaves as they were in the cycle's
    state, so where they matter its Jacobian is not the cycle's.  At k0 = 0.1,
    d = 0.058 (15 % left) it has a multiplier 1.32 (Arnoldi; power iteration on it
    grows by 1.36 a cycle) while the full cycles contract by 0.91 a cycle.

    Raises
    ------
    ValueError
        If ``cycle`` has no state to linearise about (not a converged cohort cycle), or
        its shocks leave more than ``ANDERSON_UNJUMPED`` of the blocks.
    """
    base = getattr(cycle, "state", None)
    if base is None or not cycle.converged:
        raise ValueError("cycle must be a converged cohort cycle with its state (micro.stationary(...).cycle)")
    if cycle.unjumped > ANDERSON_UNJUMPED:
        raise ValueError(f"cycle: its shocks leave {cycle.unjumped:.2g} of the blocks unjumped (more than "
                         f"{ANDERSON_UNJUMPED:g}); the map on the newborns' marginal carries those blocks frozen, "
                         "and its multipliers are not the cycle's (measured: 1.32 at k0 = 0.1, d = 0.058, where "
                         "the cycles themselves contract)")
    dep = base.dense(base.n - 1)
    return _map_multipliers(base, base.dt, base.period_ref, dep / dep.sum(), k)[0]


def _map_multipliers(base: _Cohorts, step: float, ref: float, x: np.ndarray, k: int,
                     ncv: int = MULTIPLIER_NCV, tol: float = MULTIPLIER_TOL) -> tuple[np.ndarray, int]:
    """The ``k`` largest multipliers, by modulus, of the map :func:`_carried_cycle` from
    ``base`` (steps of ``step`` graded to ``ref``) at the marginal ``x``: Arnoldi on its
    forward differences (:func:`cycle_multipliers`); and the cycles it took."""
    import scipy.sparse.linalg as sla

    _, out, g = _carried_cycle(base, step, ref, x)
    if g is None:
        raise ValueError(f"cycle: the map does not apply at its own state ({out.get('message', '')})")
    S = np.flatnonzero(x > 1e-12)
    cycles = [1]

    def jv(v: np.ndarray) -> np.ndarray:
        cycles[0] += 1
        full = np.zeros_like(x)
        full[S] = np.ravel(v)
        e = _cohort_newton.FD_STEP / max(np.abs(full).sum(), 1e-300)
        gp = _carried_cycle(base, step, ref, x + e * full)[2]
        if gp is None:
            raise ArithmeticError("a perturbed cycle failed while the multipliers were computed")
        return ((gp - g) / e)[S]

    op = sla.LinearOperator((S.size, S.size), matvec=jv, dtype=float)
    v0 = (g - x)[S]   # (the residual's direction: smooth, with tails as small as the marginal's)
    v0 = v0 if np.linalg.norm(v0) > 0.0 else np.ones(S.size)
    vals = sla.eigs(op, k=k, which="LM", ncv=min(ncv, S.size - 1), tol=tol, v0=v0 / np.linalg.norm(v0),
                    return_eigenvectors=False)
    return vals[np.argsort(-np.abs(vals))], cycles[0]


def _peak_before(st: _Cohorts, t_start: float, dt: float) -> float:
    """The largest stress on a graded mesh from the snapshot ``st`` to the shock's start
    at ``t_start`` (steps of half the time left): where the creep outruns the drive just
    before the shock (like (t* - t)^(-1/2)), the stress peaks within a step of the
    start, between the regular steps' ends.  The replay only measures; the cycle goes on
    from the regular steps (a graded mesh in the cycle itself would make the map
    discontinuous in where the start falls).  The replay stops at the first step in which
    the stress falls."""
    peak = st.sigma
    rest = t_start - st.t
    while rest > FOLD_TOL * dt:
        step = 0.5 * rest
        phi, Edt = st.prepare(step)
        x, status = st.root()
        if status != 0:
            rest = step
            continue
        before = st.sigma
        st.commit(x, step, phi, Edt)
        if st.sigma < before:
            # the creep outran the drive in this step: it only accelerates towards the
            # fold, so the stress falls from here on and the peak is behind
            break
        peak = max(peak, st.sigma)
        rest -= step
    return peak


def _one_cycle(st: _Cohorts, dt: float) -> dict:
    """Load in steps of ``dt`` (longer ones in the middle of a long loading phase:
    :func:`_step_length`) until a step starts a shock, locate the shock's start by
    bisecting that step (one partial step up to it: the cycle map stays continuous in
    where the start falls), then apply the shock.

    The stress peaks where the creep overtakes the drive, which can be before the shock
    starts (the creep accelerates like (t* - t)^(-1/2) towards the fold):
    ``sigma_max`` is that peak (the largest stress of the cycle), ``sigma_before`` the
    stress when the shock starts, ``sigma_min`` the smallest stress of the loading (it
    starts at the last shock's ``sigma_after``).  (Approaching the start on a graded
    mesh instead, halving the rest of the step, makes the map discontinuous in where the
    start falls, and at k0 = 0.3, 0.2 V^c its cycles alternate by 5.6e-5 in
    sigma_before.)"""
    t_start, sigma_start = st.t, st.sigma
    t_max = 20.0 * st.lam / (st.model.k0 * st.V)
    st.cycles_run += 1
    with _progress.stage(lambda: f"cohort V={st.V:.10g} (dt={dt:.3g}, h={st.h:.3g}): cycle {st.cycles_run}, "
                                 f"loading t = {st.t - t_start:.4g}"):
        return _one_cycle_steps(st, dt, t_start, sigma_start, t_max)


def _one_cycle_steps(st: _Cohorts, dt: float, t_start: float, sigma_start: float, t_max: float) -> dict:
    """The steps of :func:`_one_cycle` (within its progress stage)."""
    integral = 0.0
    peak = trough = st.sigma
    snapshot = None
    steps = []  # (length, slip) of every step the cycle committed, the shock's last
    replay = st.peak_excess > PEAK_FLOOR
    gamma = st.model.gamma

    def advance(x, length, phi, Edt):
        nonlocal integral, peak, trough
        s0 = st.sigma
        st.commit(x, length, phi, Edt)
        steps.append((length, x))
        integral += 0.5 * (s0 + st.sigma) * length
        peak, trough = max(peak, st.sigma), min(trough, st.sigma)

    while True:
        _progress.beat()
        if st.t - t_start > t_max:
            return dict(ok=False, message=f"no shock within t = {t_max:.3g} of the last one")
        step = _step_length(st.t - t_start, st.period_ref, dt, gamma)
        phi, Edt = st.prepare(step)
        x, status = st.root()
        if status == 2:
            return dict(ok=False, message="the closure of a step did not converge")
        if status == 0:
            # keep the state before a step in which the creep approaches the drive: the
            # stress may peak in it, or in the next one, close to the shock's start
            snapshot = st.copy() if replay and x > PEAK_CREEP * st.V * step else None
            advance(x, step, phi, Edt)
            continue
        here = st.copy() if replay and snapshot is None else None
        lo, hi, x_lo = 0.0, step, 0.0
        while hi - lo > FOLD_TOL * step:
            mid = 0.5 * (lo + hi)
            st.prepare(mid)
            x, status = st.root(below=x_lo)  # (a longer step slips more)
            if status == 0:
                lo, x_lo = mid, x
            else:
                hi = mid
        if lo > 0.0:
            phi, Edt = st.prepare(lo)
            x, _ = st.root(below=x_lo)
            advance(x, lo, phi, Edt)
        if replay:
            fine = _peak_before(snapshot if snapshot is not None else here, st.t, dt)
            st.peak_excess = fine - st.sigma  # (if negligible, the next cycles skip the replay)
            peak = max(peak, fine)
        break
    sigma_before, period = st.sigma, st.t - t_start
    if abs(period - st.period_ref) > GRADED_SLACK / gamma:
        st.period_ref = period
    st.prepare(0.0)
    x, _ = st.root()
    try:
        slip = st.shock_root(max(x, 1e-12 * st.model.zbar))
    except RuntimeError as err:
        return dict(ok=False, message=str(err))
    st.commit(slip, 0.0, 0.0, 1.0)
    steps.append((0.0, slip))
    cell = st.cell_masses()
    # (the shock's newborns are the last cohort; not counted by index from before the
    # shock, since storing them may have compacted the cohorts)
    unjumped = float(st.surviving(cell)[:-1].sum())
    marginal = st.node_masses(cell)
    st.compact(cell)
    return dict(ok=True, sigma_max=peak, sigma_min=trough, period=period,
                sigma_mean=integral / period if period > 0 else sigma_before, sigma_before=sigma_before,
                sigma_after=st.sigma, unjumped=unjumped, start=sigma_start, steps=steps, marginal=marginal)


def _trace(out: dict, k0: float, V: float) -> tuple[np.ndarray, np.ndarray]:
    """A cycle's stress at its steps' ends, from the stress after the shock before it
    (``out`` from :func:`_one_cycle`; a step of length ``l`` and slip ``x`` moves the
    stress by ``k0 (V l - x)``, the shock is the last step, of length 0)."""
    length, slip = np.array(out["steps"], float).reshape(-1, 2).T
    t = np.concatenate(([0.0], np.cumsum(length)))
    sigma = out["start"] + np.concatenate(([0.0], np.cumsum(k0 * (V * length - slip))))
    return t, sigma


#: The columns of a cycle's row in the history, and those whose error decides convergence.
COLUMNS = ("sigma_max", "sigma_min", "period", "sigma_mean", "sigma_before", "sigma_after")
JUDGED = (0, 1, 4, 5)
#: Cycles an estimate needs: three Aitken extrapolations, from three pairs of differences.
WINDOW = 5
#: The stresses' response to the state's move (:func:`_state_tail`) is the largest over this
#: many cycles.  It falls as the fast modes die (at k0 = 0.3, 0.95 V^c from 1e-2 to 1e-3 of
#: stress per unit of mass over 40 cycles: the largest over a whole run claimed 30 times the
#: distance, and at 0.99 V^c took 146 cycles where 86 do) and rises as the slowest mode takes
#: over after a kink (at 0.99 V^c from 2e-4 to 4.8e-4): over 10 or 15 cycles it claimed 0.8
#: of the distance at two cycles there, over 5 cycles 0.8 at another path's stop; over 20 it
#: covered every cycle of the sequences replayed (studies/micro_cohort_state_tail_check.py,
#: docs/validation/micro_cohort.md section 5).
SENSITIVITY_WINDOW = 20


def _estimate(a: np.ndarray, tol: float, slowest: float = 0.0) -> tuple[np.ndarray, list[str], np.ndarray, np.ndarray]:
    """Each quantity's (column of ``a``, one row per cycle, at least WINDOW rows) error,
    how it was estimated, its best value and its contraction ratio (the smallest of the
    three), from the last WINDOW
    cycles: four differences, three ratios ``r`` of successive differences, and the
    three Aitken extrapolations ``a_k + d_k r_k / (1 - r_k)`` they give.  ``slowest``:
    the multiplier of the map's slowest mode as far as it is known beforehand
    (:func:`_relaxation_multiplier`); a step ``d`` along it leaves ``d m / (1 - m)``.

    - the last two steps are below ``tol / 100``: converged (to the map's noise), the
      last cycle, with ``F`` = max(STILL, slowest / (1 - slowest)) times those steps as
      the error;
    - a ratio is negative (the cycles alternate) and the last three steps are below
      ``tol / STILL``: noise, not a drift; the last cycle, ``F`` times the steps;
    - all three ratios in [0, AITKEN_MAX_RATIO]: a geometric tail; the last extrapolation, with twice
      the spread of the three, plus the tail that the ratio's last rise, repeated once,
      would add (a slow mode taking over from a faster one raises the ratio), or if
      larger the tail a mode of multiplier ``slowest`` would add beyond the
      extrapolation (one that has not shown itself in the window: at k0 = 0.1,
      0.98 V^c, ratios of 0.97 and m0 = 0.982, the extrapolation claimed 1.4e-5 where
      3.9e-5 remained), as the error;
    - otherwise (irregular, or not contracting): the last cycle, with the tail of the
      largest ratio, ``steps / (1 - r)`` (a thousand steps if r >= 1).

    Each quantity is judged on its own: one that alternates at round-off must not hide
    another that still drifts.
    """
    w = a[-WINDOW:]
    d = np.diff(w, axis=0)
    still = max(STILL, slowest / (1.0 - slowest)) if slowest < 1.0 else math.inf
    errors, how, best, rho = np.empty(a.shape[1]), [], w[-1].copy(), np.zeros(a.shape[1])
    for i in range(a.shape[1]):
        di = d[:, i]
        with np.errstate(divide="ignore", invalid="ignore"):
            r = np.where(di[:-1] != 0.0, di[1:] / di[:-1], 0.0)
        steps = np.abs(di)
        rho[i] = float(r.min())
        if steps[-2:].max() <= tol / 100.0:
            errors[i] = still * steps[-2:].max()
            how.append("last steps")
        elif (r < 0.0).any() and steps[-3:].max() <= tol / STILL:
            errors[i] = still * steps[-3:].max()
            how.append("noise")
        elif ((r >= 0.0) & (r <= AITKEN_MAX_RATIO)).all():
            E = w[-3:, i] + di[-3:] * r / (1.0 - r)
            # a rising ratio (a slower mode taking over) goes on rising: its next step; and
            # a mode as slow as the model's slowest may not have shown itself yet
            r_hi = max(min(r[-1] + max(r[-1] - r[0], 0.0), AITKEN_MAX_RATIO), min(slowest, AITKEN_MAX_RATIO))
            tail = steps[-1] * (r_hi / (1.0 - r_hi) - r[-1] / (1.0 - r[-1]))
            errors[i], best[i] = tail + 2.0 * float(np.abs(E - E[-1]).max()), E[-1]
            how.append("Aitken")
        else:
            errors[i] = steps[-3:].max() / max(1.0 - r.max(), 1e-3)
            how.append("slow")
    return errors, how, best, rho


def _state_tail(a: np.ndarray, moves: np.ndarray, steps: np.ndarray, slowest: float = 0.0) -> tuple[float, float]:
    """How far the judged quantities (JUDGED columns of ``a``, one row per cycle: stresses
    of the cycle) can still be from the fixed point, as the state's last move bounds it,
    and the multiplier used.  ``moves``: the state's move over each cycle, the L1 norm of
    the change of the surviving blocks' delta_R marginal (row k: from cycle k - 1 to k;
    row 0 unused); ``steps``: the number of steps of each row's cycle.  A row whose
    loading phase took a different number of steps than the row before is a kink (the
    map's discontinuity, where a stress jumps by the discretisation's sawtooth whatever
    the state does).

    A quantity's own steps can pass through zero while the state still moves (modes of
    opposite signs, the new transient after a kink): at k0 = 0.3, 0.99 V^c (dt = 0.01)
    the steps of sigma_max fell below tol / 100 for two cycles where 3.7e-5 remained
    (docs/validation/micro_cohort.md, section 5, "A stress passing through zero steps").  The state's move, a norm, cannot
    pass through zero.  So each stress is at least ``S n m / (1 - m)`` from the fixed
    point: ``n`` the state's last move; ``m`` the larger of its largest ratio of
    successive moves over the last WINDOW cycles and ``slowest`` (the model's slowest
    multiplier), at most AITKEN_MAX_RATIO; ``S`` the largest step of any judged stress per
    unit of the state's move over the last SENSITIVITY_WINDOW rows but kinks (the stresses
    of one cycle respond alike: one of them can be passing through zero when another is
    not).  0 where the state did not move."""
    n = np.asarray(moves, float)[1:]
    if not n[-1] > 0.0:
        return 0.0, 0.0
    w = n[-(WINDOW - 1):]
    with np.errstate(divide="ignore", invalid="ignore"):
        ratio = float(np.max(w[1:] / w[:-1]))
    m = min(max(ratio if math.isfinite(ratio) else 1.0, slowest), AITKEN_MAX_RATIO)
    steps = np.asarray(steps)
    rows = (n > 0.0) & (steps[1:] == steps[:-1])  # (kinks left out)
    rows[:-SENSITIVITY_WINDOW] = False
    if not rows.any():
        rows = n > 0.0
    change = np.abs(np.diff(a[:, list(JUDGED)], axis=0))[rows]
    return float((change / n[rows, None]).max()) * float(n[-1]) * m / (1.0 - m), m


def _relaxation_multiplier(model: Model, period: float) -> float:
    """The cycle map's slowest multiplier as the model gives it beforehand: between shocks a
    block's delta_R relaxes alone, by ``1 - alpha (1 - exp(-gamma T))`` over a cycle of
    period ``T`` (alpha = (k0 + k1) / kappa), and the marginal's moments relax like its
    powers (:func:`_band_preconditioner`).  At k0 = 1e-3 it is 0.90 far from V^c and 0.9992
    at d = 0.005 (T = 0.0088), where plain cycles moved by 8e-8 a cycle and drifted 3.1e-5
    over the next 300 (docs/validation/micro_cohort.md section 5)."""
    if not period > 0.0:
        return 0.0
    alpha = (model.k0 + model.k1) / model.kappa
    return 1.0 - alpha * (1.0 - math.exp(-model.gamma * period))


@blas_single_threaded
def cycle_cohorts(model: Model, V: float, *, dt: float = 0.01, h: float | None = None, tol: float = 1e-5,
                  max_iter: int = 200, start=None) -> CycleFixedPoint:
    """The stick-slip limit cycle at drive velocity ``V``, by the cohort method (module
    docstring), iterated cycle to cycle from ``start``: a result at a nearby V (same
    model) or at twice ``h`` of this method, whose whole state it continues, or a result
    with a delta_R marginal (total shocks; after a total shock).
    Without one, the transient cycles run at twice ``dt`` and ``h`` first (from the first
    shock's image), and their whole state, each cell split in two, is the start.  The
    sequence of cycle
    extrema converges geometrically; each of sigma_max, sigma_min, sigma_before and
    sigma_after gets its error from the last WINDOW cycles (:func:`_estimate`: Aitken's
    extrapolation where the contraction ratios are steady), and the iteration stops when
    all are within ``tol`` in two cycles in a row.  Close to V^c, where
    the ratio nears 1 and the shocks are all but total, the fixed point of the map on the
    marginal after a shock is solved by Anderson's method preconditioned by the cycle at
    frozen slips (:func:`_anderson`), the result verified by plain cycles again, and each
    error is then at least the last step times m / (1 - m), m the map's slowest
    multiplier.  Where that frozen map grows (m >= 1, and the bound does not hold) the
    fixed point is solved by Newton-Krylov on the whole cycle map instead (:func:`_newton`),
    and each error is the largest of its last Newton step's change, the plain cycles'
    estimate after it and their distance from its fixed point.  ``error`` is the error of
    the fixed point at this ``dt`` and ``h``, not
    their discretisation error (``h`` defaults to ``kappa zbar / 20``).  Without the
    acceleration each error is also at least what the state's last move leaves
    (:func:`_state_tail`: a stress's own steps can pass through zero while the state still
    moves).  Close to V^c without the acceleration (shocks that leave many blocks,
    k0 = 0.1, 0.3) five cycles can hide a slower mode, and the message then says so.  ``dt``
    is the step of loading phases longer than SHORT_PHASE, within ``1 / gamma`` of their
    ends (up to four times longer between: :func:`_step_length`); shorter ones (close to
    V^c) get steps ``dt * T / SHORT_PHASE`` (a fiftieth of T at the default dt).
    ``eps`` in the result is ``h``.  BLAS runs on one thread inside (Anderson's least
    squares and its preconditioner's factorisation: with two threads their last bits, and
    so the path and the step of a run close to V^c, differed from one thread's; the map's
    own sums do not depend on numba's thread count).
    """
    begin = time.perf_counter()
    why = not_applicable(model)
    if why:
        raise ValueError(why)
    h = model.kappa * model.zbar / 20.0 if h is None else h
    for name, value in (("V", V), ("dt", dt), ("h", h), ("tol", tol)):
        if not (math.isfinite(value) and value > 0.0):
            raise ValueError(f"{name} must be a finite number > 0, got {value!r}")
    if not h <= model.kappa * model.zbar:
        raise ValueError(f"h must be at most kappa * zbar = {model.kappa * model.zbar:g}, got {h!r}")
    if int(max_iter) != max_iter or max_iter < 4:
        raise ValueError(f"max_iter must be an integer >= 4, got {max_iter!r}")
    given = start if start is not None and start is not _NO_COARSE else None
    coarse, from_coarse = None, False
    st = _continued(given, model, V, h)
    step = dt
    if st is None and start is not _NO_COARSE and (given is None or given.p is None) \
            and h <= 0.5 * model.kappa * model.zbar:
        # the transient cycles at twice the steps and cells (an eighth of the cost), to a
        # looser tolerance: the fixed point there is the start (its whole state, with the
        # blocks its shocks left, each cell split in two)
        coarse = cycle_cohorts(model, V, dt=2.0 * dt, h=2.0 * h, tol=max(COARSE_TOL * tol, COARSE_FLOOR), max_iter=max_iter,
                               start=_NO_COARSE)
        if coarse.applicable:
            st = _continued(coarse, model, V, h)
            if st is not None:
                step = _phase_step(coarse.period, dt)  # (the coarse cycle's loading phase, SHORT_PHASE / dt steps)
                # (a coarse fixed point certified to this run's tol: Newton-Krylov's start, below)
                from_coarse = coarse.converged and coarse.error <= tol
            elif coarse.p is not None:
                given = coarse
    if st is None:
        st = _start(model, V, h, given.p if given is not None else None)
    # a start whose run was accelerated (the coarse transient, or a nearby V) is close to
    # V^c: this run is accelerated at its first cycle, not after WINDOW plain ones
    eager = bool(getattr(given if given is not None else coarse, "accelerated", False))
    hist: list[tuple[float, ...]] = []
    # the state's move over each cycle of hist (the L1 change of the surviving blocks'
    # delta_R marginal; nan for the first after a new start), and the marginal it is from
    moves: list[float] = []
    previous = st.node_masses()
    counts: list[int] = []  # (the number of steps of each cycle of hist: where it changes, a kink)
    error, converged, applicable, message = math.nan, False, True, ""
    value = np.full(len(COLUMNS), math.nan)
    out: dict = {}
    it, accelerated, passed = 0, False, 0
    slow_multiplier = math.nan
    newton, newton_tries = None, 0  # Newton-Krylov's result, where the frozen map grows
    while it < max_iter:
        it += 1
        out = _one_cycle(st, step)
        if not out["ok"]:
            applicable, message = False, out["message"]
            break
        if st.pool > MAX_CELLS:
            message = (f"more than {MAX_CELLS} cells alive (blocks that shocks leave unjumped survive for many "
                       "cycles); use a larger h or method='fp'")
            break
        if st.outside > 1e-12:
            message = f"the delta_R marginal left the nodes ({st.outside:.2g} of the mass)"
            break
        if not out["period"] > 1e-9:
            applicable, message = False, "a shock started with no loading phase (the state is past its fold)"
            break
        if _step_off(out["period"], step, dt):
            # close to V^c the loading phase is short: resolve it with SHORT_PHASE / dt
            # steps, and start the sequence again at the new step
            step = _phase_step(out["period"], dt)
            hist.clear()
            moves.clear()
            counts.clear()
            previous = out["marginal"]
            passed = 0
            continue
        hist.append(tuple(out[name] for name in COLUMNS))
        moves.append(float(np.abs(out["marginal"] - previous).sum()) if len(hist) > 1 else math.nan)
        previous = out["marginal"]
        counts.append(len(out["steps"]))
        # (INFO: the progress within a row that `micro sweep -v` shows; each cycle is one step of the iteration)
        log.info("cohort k0=%g V=%g h=%.3g cycle %d: sigma_max %.10f sigma_min %.10f sigma_before %.10f",
                 model.k0, V, h, it, out["sigma_max"], out["sigma_min"], out["sigma_before"])
        if len(hist) >= WINDOW:
            slowest = _relaxation_multiplier(model, out["period"])
            a = np.array(hist)
            errors, how, best, rho = _estimate(a, tol, slowest)
            if not accelerated:
                # a quantity's steps can pass through zero while the state still moves: its
                # error is at least what the state's last move leaves (:func:`_state_tail`)
                tail, _ = _state_tail(a, np.array(moves), np.array(counts), slowest)
                for i in JUDGED:
                    if tail > errors[i]:
                        errors[i], how[i] = tail, "state's move"
            if accelerated and 0.0 < slow_multiplier < 1.0:
                # after the acceleration the sequence holds what the map's slowest modes
                # left: a last step d leaves up to d m / (1 - m) to go (m the slowest
                # multiplier, of the map at frozen slips)
                last = np.abs(np.diff(a[-2:], axis=0)[0])
                errors = np.maximum(errors, last * slow_multiplier / (1.0 - slow_multiplier))
            error = float(errors[list(JUDGED)].max())
            # (steps too small to show a ratio, but not small enough for the slowest mode's
            # tail: a slow sequence as well)
            slow = any((how[i] in ("Aitken", "slow") and rho[i] > SLOW_CAVEAT)
                       or (how[i] in ("last steps", "noise", "state's move") and errors[i] > tol) for i in JUDGED)
        elif eager and not accelerated:
            slow = True  # (the start's own run was accelerated: so is this one, at once)
        else:
            continue
        # (only a short loading phase makes the blocks' relaxation slow from cycle to
        # cycle: the slowest multiplier is about exp(-0.19 T); from 0.7 V^c down a ratio
        # above 0.9 is noise, and the acceleration there cost more than it saved)
        if not accelerated and slow and out["period"] < SHORT_PHASE and out["unjumped"] <= ANDERSON_UNJUMPED:
            # a state after all but total shocks contracting slowly (close to V^c): solve
            # the fixed point, then verify it by the plain cycles again (with at least half the
            # cycles left: below the map's roughness, about 1e-6 of the mass at tol = 1e-6,
            # Anderson's residual creeps down without stalling and used to take them all)
            accelerated = True
            fast, used, slow_multiplier, residual = _anderson(model, V, h, step, dt, st, st.period_ref,
                                                              ANDERSON_TOL * tol, max((int(max_iter) - it) // 2, 1))
            it += used
            if slow_multiplier >= 1.0:
                # the frozen map grows along some mode, so neither Anderson's iteration nor the
                # bound m / (1 - m) holds: Newton-Krylov on the whole cycle map, whose error is
                # its last step, with half the cycles left (from far off, as in a coarse run's
                # first cycles, its steps are halved and the budget can run out: the plain
                # cycles then go on from Anderson's state, with a second try below).  Where this
                # run continues a coarse fixed point certified to tol and Anderson did not meet
                # its tolerance, it starts from the state Anderson started from: at k0 = 1e-3,
                # V = 70 it certified from there in 44 cycles, and from Anderson's stalled state
                # not in 190 (docs/validation/micro_cohort.md section 5)
                origin = st if from_coarse and not residual <= ANDERSON_TOL * tol else fast
                newton = _newton(step, dt, origin if origin is not None else st, tol, (int(max_iter) - it) // 2)
                newton_tries += 1
                it += newton.evals
                if newton.certified:
                    fast = newton.state
            if fast is not None:
                st = fast
                hist.clear()
                moves.clear()
                counts.clear()
                previous = st.node_masses()
                passed = 0
                continue
        if len(hist) < WINDOW:
            continue
        passed = passed + 1 if error <= tol else 0
        if passed >= 2 and accelerated and slow_multiplier >= 1.0:
            # the frozen map grows along some mode (Anderson's bound does not hold)
            if newton is not None and newton.certified:
                # the plain cycles from Newton's fixed point: the error is the larger of Newton's
                # (its last step), the cycles' own estimate, and how far they moved from it
                drift = np.abs(np.array(hist)[-WINDOW:, list(JUDGED)]
                               - np.array([newton.row[COLUMNS[i]] for i in JUDGED])).max(axis=0)
                error = float(max(np.max(errors[list(JUDGED)]), newton.error, drift.max()))
                converged, value = True, best
                message = (f"limit cycle by cohorts, by Newton-Krylov on the cycle map (the frozen map's slowest "
                           f"multiplier is {slow_multiplier:.4f} >= 1, so Anderson's bound does not hold): residual "
                           f"{newton.residual:.1e} of the mass in {newton.evals} cycles, its last step moved the "
                           f"stresses by {newton.error:.1e}; cycles {it - WINDOW + 1}-{it} (of {it}) stay within "
                           f"{drift.max():.1e} of it; error {error:.1e}")
                break
            if newton_tries < 2:
                # the plain cycles' test is not enough where the frozen map grows: a second try of
                # Newton-Krylov from where they passed it (closer to the fixed point), then the
                # plain cycles again (leaving them at least 2 WINDOW of the budget)
                newton = _newton(step, dt, st, tol, max(int(max_iter) - it - 2 * WINDOW, 0))
                newton_tries += 1
                it += newton.evals
                if newton.certified:
                    st = newton.state
                    hist.clear()
                    moves.clear()
                    counts.clear()
                    previous = st.node_masses()
                    passed = 0
                    continue
            # the frozen map grows along some mode: it gives no bound on what a slower mode of
            # the full map leaves, and the plain cycles' test alone is not enough (at k0 = 0.01,
            # 0.9 V^c, h = kappa zbar / 40 it passed 3e-5 short of the fixed point that 450
            # cycles reach, against an estimate of 1.9e-6; docs/validation/micro_cohort.md
            # section 5): the stopping test is met, but the fixed point's error is not known
            converged, value, error = True, best, math.nan
            message = (f"limit cycle by cohorts, its error not known: the cycles pass the stopping test after "
                       f"Anderson's iteration (its last step {residual:.1e} of the mass), but the frozen map's "
                       f"slowest multiplier is {slow_multiplier:.4f} >= 1, so nothing bounds a slower mode of "
                       f"the cycle map (no certified fixed point; such runs were 3e-5 to 4e-4 off where checked), and "
                       f"Newton-Krylov on the whole map did not certify one "
                       f"({newton.message if newton is not None else 'not run'})")
            break
        if passed >= 2:  # (two cycles in a row: one estimate may pass by chance)
            converged, value = True, best
            worst = max(JUDGED, key=lambda i: errors[i])
            message = (f"limit cycle by cohorts: cycles {it - WINDOW + 1}-{it} (of {it}) give sigma_max to "
                       f"{errors[0]:.1e} ({how[0]}), sigma_min to {errors[1]:.1e} ({how[1]}); the least certain, "
                       f"{COLUMNS[worst]}, to {errors[worst]:.1e}")
            extrapolated = [rho[i] for i in JUDGED if how[i] == "Aitken"]
            ratio = max(extrapolated, default=0.0)
            if accelerated and 0.0 < slow_multiplier < 1.0:
                message += (f"; after Anderson's preconditioned iteration, each error at least the last step "
                            f"times m / (1 - m), m = {slow_multiplier:.4f} the map's slowest multiplier")
            elif extrapolated and ratio > SLOW_CAVEAT:
                message += (f"; the cycles contract by {ratio:.2f} a cycle, five cycles can hide a slower mode "
                            "(docs/reference/micro_cohort.md, section 4)")
            break
    if not converged and not message:
        message = f"no fixed point to {tol:g} in {max_iter} cycles (error estimate {error:.2g})"
    values = np.array(hist).reshape(-1, len(COLUMNS))
    if not converged and len(values):
        value = values[-1]
    res = CycleFixedPoint(
        model=model, V=V, eps=h, sigma_max=float(value[0]), sigma_min=float(value[1]), period=float(value[2]),
        sigma_mean=float(value[3]), mass_error=float(st.outside + st.dropped), min_mass=0.0, iterations=it, error=error,
        unjumped=out.get("unjumped", math.nan), converged=converged, message=message,
        wall_time=time.perf_counter() - begin, applicable=applicable, history=values,
        sigma_before=float(value[4]), sigma_after=float(value[5]), accelerated=accelerated,
        coarse=coarse if coarse is not None and coarse.applicable and coarse.converged else None)
    if res.coarse is not None:
        res.coarse.state = None  # (the fine run continued it; keep only its numbers)
    if out.get("ok"):
        res.trace = _trace(out, model.k0, V)
    if applicable and len(hist):
        st.dt = step
        res.state = st
        if st.n == 1:  # (after a total shock the state is its delta_R marginal)
            res.p = st.marginal(0)
    return res
