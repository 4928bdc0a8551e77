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
crossed mass is an exact integral of an exponential.  A step of length ``dt`` solves the mean-field closure for its
slip (``dX = zbar x`` the jumps it causes, a crossed block jumping again as a Poisson
process of its overshoot); the loading phase ends where the closure's smallest root
jumps (a fold), located by bisecting the step; the shock is the same closure in zero
time.  Where a near-critical avalanche runs away is then a continuous function of
the state, so the cycle-to-cycle sequence converges smoothly (geometrically, by about
0.8 per cycle) and is extrapolated by Aitken's method.

Shocks need not be total: the blocks a shock leaves unjumped stay in their cohorts
with raised floors (at k0 = 0.1 and 0.3 their cohorts live for many cycles, and the
cost per cycle grows with them).  Refinement variables: the time step ``dt`` and the cell width
``h`` (measured orders in benchmarks/micro_cohort_refinement.py).  Needs exponential
jumps, and a loading phase that ends in a shock within ``20 kappa zbar / (k0 V)``
(otherwise ``applicable=False``).
"""
from __future__ import annotations

import logging
import math
import time

import numpy as np

from . import _cohort_kernels as CK
from .cycle import CycleFixedPoint, _initial_marginal, _rows
from .params import KIND_EXPONENTIAL, Model

__all__ = ["cycle_cohorts"]

log = logging.getLogger(__name__)

_GX, _GW = np.polynomial.legendre.leggauss(2)
_GX, _GW = 0.5 * _GX + 0.5, 0.5 * _GW
#: Cohorts whose surviving mass is below this are dropped.
SURVIVOR_FLOOR = 1e-15
#: The start of a shock is located to this fraction of the time step.
FOLD_TOL = 1e-7
#: The time step is cut so that a loading phase has at least this many steps.
STEPS_PER_CYCLE = 50
#: Anderson's acceleration (close to V^c): the window, and the evaluations without progress
#: after which it stops.
ANDERSON_WINDOW = 10
ANDERSON_STALL = 8
#: Anderson's map drops the blocks a shock leaves unjumped: it is used only where they are
#: at most this fraction (the plain cycles that verify its result restore them).
ANDERSON_UNJUMPED = 1e-3
#: Most cells the cohorts may hold (about 50 MB).
MAX_CELLS = 3_000_000
#: A last step d between cycles leaves at most STILL * d to go when they contract by 0.8 a cycle.
STILL = 5.0
#: Passed as ``start``: begin from the first shock's image, without a coarser run first.
_NO_COARSE = object()


class _Cohorts:
    """The state: the cohorts (module docstring), the time, the slip and the stress."""

    def __init__(self, model: Model, V: float, h: float) -> None:
        self.model, self.V, self.h = model, V, h
        self.lam = model.kappa * model.zbar
        # delta_R lies within (k2 / kappa) * 40 lam of 0 for all but ~1e-17 of the mass
        half = int(math.ceil(45.0 * model.k2 * model.zbar / h)) + 8
        self.ylo, self.ny = -half * h, 2 * half
        cap = 1024
        self.t0, self.X0, self.s0, self.J = (np.zeros(cap) for _ in range(4))
        self.j0, self.nn, self.off = (np.zeros(cap, np.int64) for _ in range(3))
        self.co = np.zeros((cap, 6))
        self.q, self.m = np.zeros(1 << 16), np.zeros(1 << 17)
        self.n = self.pool = 0
        self.t = self.X = self.sigma = 0.0
        self.last = 0.0
        self.outside = 0.0

    # -------------------------------------------------------------- storage
    def add(self, dep: np.ndarray) -> None:
        """A new cohort born now, with node masses ``dep`` in delta_R and floors 0."""
        idx = np.flatnonzero(dep > 0.0)
        if idx.size == 0:
            return
        a, b = max(idx[0] - 1, 0), min(idx[-1] + 2, self.ny)  # a node of zero density at each end
        cells = b - a - 1
        if self.n + 1 > self.t0.size or 2 * (self.pool + cells) > self.q.size or 4 * (self.pool + cells) > self.m.size:
            self.compact()
            if self.n + 1 > self.t0.size:
                for name in ("t0", "X0", "s0", "J", "j0", "nn", "off"):
                    old = getattr(self, name)
                    setattr(self, name, np.concatenate([old, np.zeros_like(old)]))
                self.co = np.zeros((self.t0.size, 6))
            if 2 * (self.pool + cells) > self.q.size or 4 * (self.pool + cells) > self.m.size:
                extra = self.q.size + 2 * cells
                self.q = np.concatenate([self.q, np.zeros(extra)])
                self.m = np.concatenate([self.m, np.zeros(2 * extra)])
        c, p = self.n, self.pool
        self.t0[c], self.X0[c], self.s0[c], self.J[c] = self.t, self.X, self.sigma, 0.0
        self.j0[c], self.nn[c], self.off[c] = a, cells, p
        nodes = dep[a:b] / self.h
        self.q[2 * p:2 * (p + cells):2] = nodes[:-1]
        self.q[2 * p + 1:2 * (p + cells):2] = nodes[1:]
        floors = self.m[4 * p:4 * (p + cells)].reshape(cells, 4)
        floors[:] = (0.0, 0.0, 1.0, 0.0)  # (ends, no kink)
        self.pool += cells
        self.n += 1

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

    def surviving(self) -> np.ndarray:
        out = np.zeros(self.n)
        CK.survivors(self.n, self.j0, self.nn, self.off, self.q, self.m, self.h, self.lam, out)
        return out

    def compact(self, surviving: np.ndarray | None = None) -> None:
        """Drop the cohorts that have all but crossed (``surviving``: their surviving
        masses, if known), and pack the cells."""
        surviving = self.surviving() if surviving is None else surviving
        keep = np.flatnonzero(surviving > SURVIVOR_FLOOR)
        q, m = np.zeros_like(self.q), np.zeros_like(self.m)
        p = 0
        for i, c in enumerate(keep):
            k, o = self.nn[c], self.off[c]
            q[2 * p:2 * (p + k)] = self.q[2 * o:2 * (o + k)]
            m[4 * p:4 * (p + k)] = self.m[4 * o:4 * (o + k)]
            for name in ("t0", "X0", "s0", "J", "j0", "nn"):
                getattr(self, name)[i] = getattr(self, name)[c]
            self.off[i] = p
            p += k
        self.q, self.m, self.pool, self.n = q, m, p, keep.size

    # -------------------------------------------------------------- dynamics
    def prepare(self, dt: float) -> tuple[float, float]:
        md = self.model
        return CK.coefficients(self.t, dt, self.X, self.sigma, self.V, md.k0, md.k1, md.k2, md.f_th, md.gamma,
                               self.t0, self.X0, self.s0, self.J, self.n, self.co, self.j0, self.nn, self.off,
                               self.m, self.ylo, self.h)

    def closure(self, dX: float) -> tuple[float, float]:
        return CK.closure(dX, self.n, self.co, self.j0, self.nn, self.off, self.q, self.m, self.ylo, self.h,
                          self.lam, self.model.zbar, _GX, _GW)

    def root(self) -> tuple[float, int]:
        """The step's slip (after :meth:`prepare`) and 0, or 1 if the step starts a shock."""
        xmin = max(1e-9 * self.model.zbar, 0.25 * self.last)
        return CK.smallest_root(self.n, self.co, self.j0, self.nn, self.off, self.q, self.m, self.ylo, self.h,
                                self.lam, self.model.zbar, _GX, _GW, 1e-16, xmin)

    def commit(self, dX: float, dt: float, phi: float, Edt: float) -> None:
        md = self.model
        dep = np.zeros(self.ny)
        self.outside += CK.commit(dX, self.n, self.co, self.j0, self.nn, self.off, self.q, self.m, self.J, self.X0,
                                  self.s0, self.X, Edt, phi, self.ylo, self.h, self.lam, md.k2, md.kappa, md.f_th,
                                  _GX, _GW, dep)
        if dt > 0.0:
            self.last = dX
        self.t += dt
        self.X += dX
        self.sigma += md.k0 * (self.V * dt - dX)
        self.add(dep)

    def shock_root(self, x0: float) -> float:
        """The slip of the shock: the closure's root beyond its positive minimum (after
        :meth:`prepare` with dt = 0), bracketed by doubling, then bisected."""
        lo, hi = x0, max(2.0 * x0, self.model.zbar)
        while self.closure(hi)[0] > 0.0:
            lo, hi = hi, 2.0 * hi
            if hi > 1e12:
                raise RuntimeError("the shock's closure has no root")
        while hi - lo > 1e-14 * hi:
            mid = 0.5 * (lo + hi)
            if self.closure(mid)[0] > 0.0:
                lo = mid
            else:
                hi = mid
        return hi


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


def _step_too_long(period: float, dt: float) -> bool:
    """Whether a loading phase of ``period`` has too few steps of ``dt``: fewer than 0.8
    STEPS_PER_CYCLE (not at every small change of the period: each cut of the step
    restarts the cycle sequence)."""
    return period < 0.8 * STEPS_PER_CYCLE * dt


def _anderson(model: Model, V: float, h: float, dt: float, dep: np.ndarray, tol: float,
              max_evals: int) -> tuple[_Cohorts | None, int]:
    """Anderson's acceleration of the cycle map on the delta_R marginal ``dep`` after a
    total shock (a product state), for the sequences that contract slowly (close to V^c).

    One evaluation is one cycle from a product state; the blocks its shock leaves unjumped
    (at most ANDERSON_UNJUMPED of the mass) are dropped.  Type-II Anderson
    mixing with a window of ANDERSON_WINDOW, stopped when a cycle moves less than ``tol``
    of the mass, or when ANDERSON_STALL evaluations did not improve on the best one.
    Returns the state after the best evaluation's cycle (its newborn marginal the best
    image, with the blocks that cycle's shock left: a state of the full dynamics), or None
    if the map does not apply, and the evaluations used.
    """
    xs: list[np.ndarray] = []
    gs: list[np.ndarray] = []
    x, best, best_f = dep / dep.sum(), None, math.inf
    since = 0
    for k in range(1, max_evals + 1):
        st = _start(model, V, h, None, dep=x)
        out = _one_cycle(st, dt)
        if not out["ok"] or out["unjumped"] > ANDERSON_UNJUMPED or _step_too_long(out["period"], dt):
            return best, k
        g = st.dense(st.n - 1)
        g /= g.sum()
        f = float(np.abs(g - x).sum())
        log.debug("anderson %d: sigma_max %.10f, the cycle moves %.2e of the mass", k, out["sigma_max"], f)
        if f < best_f:
            best, best_f, since = st, f, 0
        else:
            since += 1
        if best_f <= tol or since >= ANDERSON_STALL:
            return best, k
        xs.append(x)
        gs.append(g)
        del xs[:-ANDERSON_WINDOW - 1], gs[:-ANDERSON_WINDOW - 1]
        if len(xs) < 2:
            x = g
            continue
        F = np.array([b - a for a, b in zip(xs, gs)])
        dF, dG = np.diff(F, axis=0).T, np.diff(np.array(gs), axis=0).T
        gamma = np.linalg.lstsq(dF, F[-1], rcond=None)[0]
        x = np.maximum(g - dG @ gamma, 0.0)
        x /= x.sum()
    return best, max_evals


def _one_cycle(st: _Cohorts, dt: float) -> dict:
    """Load in steps of ``dt`` until a step starts a shock, locate the shock's start by
    bisecting that step, then apply the shock."""
    t_start, sigma_start, integral = st.t, st.sigma, 0.0
    t_max = 20.0 * st.lam / (st.model.k0 * st.V)
    while True:
        if st.t - t_start > t_max:
            return dict(ok=False, message=f"no shock within t = {t_max:.3g} of the last one")
        phi, Edt = st.prepare(dt)
        x, status = st.root()
        if status == 2:
            return dict(ok=False, message="the closure of a step did not converge")
        if status == 0:
            s0 = st.sigma
            st.commit(x, dt, phi, Edt)
            integral += 0.5 * (s0 + st.sigma) * dt
            continue
        lo, hi = 0.0, dt
        while hi - lo > FOLD_TOL * dt:
            mid = 0.5 * (lo + hi)
            st.prepare(mid)
            if st.root()[1] == 0:
                lo = mid
            else:
                hi = mid
        if lo > 0.0:
            phi, Edt = st.prepare(lo)
            x, _ = st.root()
            s0 = st.sigma
            st.commit(x, lo, phi, Edt)
            integral += 0.5 * (s0 + st.sigma) * lo
        break
    sigma_max, period = st.sigma, st.t - t_start
    st.prepare(0.0)
    x, _ = st.root()
    n_old = st.n
    try:
        slip = st.shock_root(max(x, 1e-12 * st.model.zbar))
    except RuntimeError as err:
        return dict(ok=False, message=str(err))
    st.commit(slip, 0.0, 0.0, 1.0)
    surviving = st.surviving()
    unjumped = float(surviving[:n_old].sum())
    st.compact(surviving)
    return dict(ok=True, sigma_max=sigma_max, sigma_min=st.sigma, period=period,
                sigma_mean=integral / period if period > 0 else sigma_max, unjumped=unjumped,
                start=sigma_start)


def _aitken(a: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Aitken's extrapolation of the last three rows of ``a`` (one column per quantity),
    and the ratio of the last two differences."""
    d1, d2 = a[-2] - a[-3], a[-1] - a[-2]
    with np.errstate(divide="ignore", invalid="ignore"):
        rho = np.where(d1 != 0.0, d2 / d1, 0.0)
        corr = np.where((rho >= 0.0) & (rho < 1.0), d2 * rho / (1.0 - rho), 0.0)
    return a[-1] + corr, rho


def _estimate(a: np.ndarray, extrapolated: np.ndarray, previous: np.ndarray, rho: np.ndarray,
              tol: float) -> tuple[np.ndarray, list[str], np.ndarray]:
    """Each quantity's (column of ``a``, one row per cycle) error, how it was estimated
    and its best value, from the last three cycles, their Aitken extrapolation (and the
    previous one) and the ratio ``rho`` of their last two differences:

    - ratio in [0, 0.95]: the differences contract steadily, Aitken's extrapolation, with
      twice its change as the error;
    - the cycles agree to ``tol / 100``, or alternate (noise, not a drift) by less than
      ``tol / STILL``: the last cycle, with STILL times the last steps as the error;
    - otherwise (slow, ratio near 1, or irregular): the last cycle, with the tail of a
      contraction by the ratio, ``step / (1 - ratio)``.

    Each quantity is judged on its own: one that alternates at round-off must not hide
    another that still drifts.
    """
    steps = np.abs(a[-1] - a[-2])
    last_two = np.maximum(steps, np.abs(a[-2] - a[-3]))
    errors, how, best = np.empty(a.shape[1]), [], a[-1].copy()
    for i in range(a.shape[1]):
        if 0.0 <= rho[i] <= 0.95:
            errors[i], best[i] = 2.0 * abs(extrapolated[i] - previous[i]), extrapolated[i]
            how.append("Aitken")
        elif steps[i] <= tol / 100.0 or (rho[i] < 0.0 and last_two[i] <= tol / STILL):
            errors[i] = STILL * last_two[i]
            how.append("last steps")
        else:
            errors[i] = steps[i] / max(1.0 - rho[i], 1e-3)
            how.append("slow")
    return errors, how, best


def cycle_cohorts(model: Model, V: float, *, dt: float = 0.01, h: float | None = None, tol: float = 1e-5,
                  max_iter: int = 200, start=None) -> CycleFixedPoint:
    """The stick-slip limit cycle at drive velocity ``V`` with total global shocks, by the
    cohort method (module docstring), iterated cycle to cycle from ``start`` (a result at
    a nearby V or another ``h``, of this method or :func:`micro.cycle.cycle_fixed_point`).
    Without one (or when it has no delta_R marginal: its shocks were not total), the
    transient cycles run at twice ``dt`` and ``h`` first (from the first shock's image),
    and their fixed point is the start.

    The sequence of cycle extrema converges geometrically; each of sigma_max and sigma_min
    gets its error from the last three cycles (:func:`_estimate`: Aitken's extrapolation
    where the contraction ratio lies in [0, 0.95], ``step / (1 - ratio)`` where it is
    slower), and the iteration stops when both are within ``tol``.  Close to V^c, where
    the ratio nears 1 and the shocks are all but total, the marginal after a shock is
    accelerated by Anderson's method (:func:`_anderson`) and the result verified by plain
    cycles again.  ``error`` is the error of the fixed point at this ``dt`` and
    ``h``, not their discretisation error (``h`` defaults to ``kappa zbar / 20``).  ``dt``
    is cut to a fiftieth of the loading phase where that is shorter (close to V^c).
    ``eps`` in the result is ``h``.
    """
    begin = time.perf_counter()
    if model.jumps.kind != KIND_EXPONENTIAL:
        raise ValueError("the cohort method needs exponential jumps (a jumped block's margin is then Exp(kappa zbar))")
    h = model.kappa * model.zbar / 20.0 if h is None else h
    for name, value in (("V", V), ("dt", dt), ("h", h), ("tol", tol)):
        if not (math.isfinite(value) and value > 0.0):
            raise ValueError(f"{name} must be a finite number > 0, got {value!r}")
    if not h <= model.kappa * model.zbar:
        raise ValueError(f"h must be at most kappa * zbar = {model.kappa * model.zbar:g}, got {h!r}")
    if int(max_iter) != max_iter or max_iter < 4:
        raise ValueError(f"max_iter must be an integer >= 4, got {max_iter!r}")
    if (start is None or (start is not _NO_COARSE and start.p is None)) and h <= 0.5 * model.kappa * model.zbar:
        # the transient cycles at twice the steps and cells (an eighth of the cost), to a
        # looser tolerance: the fixed point there is the start (as a coarser h in a sweep)
        coarse = cycle_cohorts(model, V, dt=2.0 * dt, h=2.0 * h, tol=max(4.0 * tol, 1e-4), max_iter=max_iter,
                               start=_NO_COARSE)
        if coarse.applicable and coarse.p is not None:
            start = coarse
    st = _start(model, V, h, start.p if start is not None and start is not _NO_COARSE else None)
    hist: list[tuple[float, float, float, float]] = []
    error, converged, applicable, message = math.nan, False, True, ""
    value = np.full(4, math.nan)
    previous = None
    out: dict = {}
    it, accelerated = 0, False
    while it < max_iter:
        it += 1
        out = _one_cycle(st, dt)
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
        if _step_too_long(out["period"], dt):
            # close to V^c the loading phase is short: resolve it with STEPS_PER_CYCLE
            # steps, and start the sequence again at the new step
            dt = out["period"] / STEPS_PER_CYCLE
            hist.clear()
            previous = None
            continue
        hist.append((out["sigma_max"], out["sigma_min"], out["period"], out["sigma_mean"]))
        log.debug("cohort cycle %d: sigma_max %.10f sigma_min %.10f", it, out["sigma_max"], out["sigma_min"])
        if len(hist) >= 3:
            extrapolated, rho = _aitken(np.array(hist))
            if previous is not None:
                errors, how, best = _estimate(np.array(hist), extrapolated, previous, rho, tol)
                error = float(errors[:2].max())
                slow = [i for i in (0, 1) if how[i] == "slow" and rho[i] > 0.9]
                if not accelerated and error > tol and slow and out["unjumped"] <= ANDERSON_UNJUMPED:
                    # a product state contracting slowly (close to V^c): accelerate it,
                    # then verify the result by the plain cycles again
                    accelerated = True
                    fast, used = _anderson(model, V, h, dt, st.dense(st.n - 1), tol, int(max_iter) - it)
                    it += used
                    if fast is not None:
                        st = fast
                        hist.clear()
                        previous = None
                        continue
                if error <= tol:
                    converged, value = True, best
                    message = (f"limit cycle by cohorts: cycles {it - 2}-{it} (of {it}) give sigma_max to "
                               f"{errors[0]:.1e} ({how[0]}) and sigma_min to {errors[1]:.1e} ({how[1]})")
                    break
            previous = extrapolated
    if not converged and not message:
        message = f"no fixed point to {tol:g} in {max_iter} cycles (error estimate {error:.2g})"
    values = np.array(hist).reshape(-1, 4)
    if not converged and len(values):
        value = values[-1]
    res = CycleFixedPoint(
        model=model, V=V, eps=h, sigma_max=float(value[0]), sigma_min=float(value[1]), period=float(value[2]),
        sigma_mean=float(value[3]), mass_error=float(st.outside), min_mass=0.0, iterations=it, error=error,
        unjumped=out.get("unjumped", math.nan), converged=converged, message=message,
        wall_time=time.perf_counter() - begin, applicable=applicable, history=values)
    if applicable and len(hist) and st.n == 1:  # (after a total shock the state is its delta_R marginal)
        res.p = st.marginal(0)
    return res
