"""The cohort method's solver: the fixed point of the cycle map, and its multipliers.

:func:`cycle_cohorts` iterates the cycle map (:mod:`micro.cohort.cycle`) from a start
(a coarse transient at twice the step and cell by default) and stops on the error
estimate (:mod:`micro.cohort.estimate`).  Close to V^c, where the cycles contract slowly,
it solves the fixed point of the map on the delta_R marginal after a shock by Anderson's
iteration preconditioned by the map at frozen slips (:func:`_anderson`,
:func:`_band_preconditioner`), or where that frozen map grows by Newton-Krylov on the
whole map (:func:`_newton`, :mod:`micro.cohort.newton`).  :func:`cycle_multipliers`: the
map's leading multipliers at a converged cycle.  :func:`not_applicable`: where the
method does not apply.
"""
from __future__ import annotations

import logging
import math
import time

import numpy as np
import scipy.linalg

from . import newton as _cohort_newton
from . import options
from .._threads import blas_single_threaded
from ..methods import cohort_not_applicable as not_applicable
from ..params import Model
from ..results import CycleFixedPoint
from .cycle import (_carried_cycle, _frozen_cycle, _marginal, _one_cycle, _phase_step, _step_off, _step_too_long,
                    _trace)
from .estimate import COLUMNS, JUDGED, WINDOW, _estimate, _relaxation_multiplier, _state_tail
from .state import _Cohorts, _continued, _start

__all__ = ["cycle_cohorts", "cycle_multipliers", "not_applicable"]

log = logging.getLogger("micro.cohort")

#: Passed as ``start``: begin from the first shock's image, without a coarser run first.
_NO_COARSE = object()


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
    opt = options.DEFAULT
    S = _support(x, g)
    n = S.size
    L = np.zeros((n, n))
    for c in range(min(opt.BAND_COLOURS, n)):
        cols = np.arange(c, n, opt.BAND_COLOURS)
        e = np.zeros(x.size)
        e[S[cols]] = 1.0
        image = _frozen_cycle(model, V, h, out["start"], out["steps"], e)[S]
        for j in cols:
            lo, hi = max(j - opt.BAND_COLOURS + opt.BAND_ABOVE, 0), min(j + opt.BAND_ABOVE, n)
            L[lo:hi, j] = image[lo:hi]
    gS = g[S] / g[S].sum()
    L -= np.outer(gS, L.sum(axis=0))
    # the marginal moved up by one node: the full map's response, by a forward difference
    y = S * h  # (node positions up to an offset, which acts on the mass alone: zero in a residual)
    shift = np.zeros(x.size)
    shift[1:] = x[:-1] - x[1:]
    shift[0] = -x[0]
    _, _, g_shift = G(x + opt.SHIFT_FD * shift)
    v, Jv = shift[S], (g_shift[S] - gS) / opt.SHIFT_FD
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
    opt = options.DEFAULT
    st, out, g = _carried_cycle(base, step, ref, v)
    if g is None or out["unjumped"] > opt.ANDERSON_UNJUMPED or _step_too_long(out["period"], step, dt):
        return st, out, None
    return st, out, g


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
    opt = options.DEFAULT
    xs: list[np.ndarray] = []
    gs: list[np.ndarray] = []
    x, best, best_f = _marginal(base), None, math.inf
    since, M, slow = 0, None, math.nan
    backtracks = 0
    for k in range(1, max_evals + 1):
        st, out, g = _applied_cycle(base, step, ref, dt, x)
        if g is None:
            if not xs or backtracks >= opt.ANDERSON_BACKTRACKS:
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
        if best_f <= tol or since >= opt.ANDERSON_STALL or slow >= 1.0:
            return best, k, slow, best_f
        xs.append(x)
        gs.append(x + step_x)
        del xs[:-opt.ANDERSON_WINDOW - 1], gs[:-opt.ANDERSON_WINDOW - 1]
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
    (:mod:`micro.cohort.newton`: GMRES with Jacobian-vector products by differences of
    the map, no frozen-slip linearisation), each judged column to NEWTON_TOL * ``tol``,
    in at most ``max_evals`` cycles.  The map does not apply (the evaluation is refused)
    where a cycle fails, leaves more than ANDERSON_UNJUMPED of the blocks unjumped or
    needs a shorter step.  At k0 = 0.01, 0.9 V^c, cell kappa zbar / 40, where the frozen
    map grows (multiplier 1.03), a solve to 1e-9 from near the fixed point takes 50-80
    cycles and ends at a residual of 1e-10 to 1e-8 of the mass (the map's round-off;
    docs/validation/micro_cohort.md section 5)."""
    opt = options.DEFAULT
    ref = base.period_ref
    if max_evals < 4 or not base.dense(base.n - 1).sum() > 0.0:
        return _cohort_newton.NewtonKrylov(message="no budget left for Newton-Krylov")

    def cycle_map(state: _Cohorts):
        """The map from ``state`` (carrying the blocks its last shock left), and its marginal."""
        return (lambda v: _applied_cycle(state, step, ref, dt, v)), _marginal(state)
    G, x0 = cycle_map(base)
    return _cohort_newton.solve(G, x0, tol=opt.NEWTON_TOL * tol, max_evals=max_evals,
                                columns=tuple(COLUMNS[i] for i in JUDGED), log=log.debug, rebase=cycle_map)


def cycle_multipliers(cycle: CycleFixedPoint, k: int = 3) -> np.ndarray:
    """The ``k`` largest multipliers of the cycle map at a converged cycle (its Floquet
    multipliers, as the map on the delta_R marginal after a shock sees them), by modulus.

    Arnoldi's method (``scipy.sparse.linalg.eigs``, a Krylov space of ``MULTIPLIER_NCV``
    vectors, tolerance ``MULTIPLIER_TOL``) on the map's Jacobian, each product ``J v`` a
    forward difference of one cycle from the cycle's last state
    (:func:`_carried_cycle`, the step of the Newton-Krylov, ``micro.cohort.newton.FD_STEP``
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
    opt = options.DEFAULT
    base = getattr(cycle, "state", None)
    if base is None or not cycle.converged:
        raise ValueError("cycle must be a converged cohort cycle with its state (micro.stationary(...).cycle)")
    if cycle.unjumped > opt.ANDERSON_UNJUMPED:
        raise ValueError(f"cycle: its shocks leave {cycle.unjumped:.2g} of the blocks unjumped (more than "
                         f"{opt.ANDERSON_UNJUMPED:g}); the map on the newborns' marginal carries those blocks frozen, "
                         "and its multipliers are not the cycle's (measured: 1.32 at k0 = 0.1, d = 0.058, where "
                         "the cycles themselves contract)")
    dep = base.dense(base.n - 1)
    return _map_multipliers(base, base.dt, base.period_ref, dep / dep.sum(), k)[0]


def _map_multipliers(base: _Cohorts, step: float, ref: float, x: np.ndarray, k: int,
                     ncv: int | None = None, tol: float | None = None) -> tuple[np.ndarray, int]:
    """The ``k`` largest multipliers, by modulus, of the map :func:`_carried_cycle` from
    ``base`` (steps of ``step`` graded to ``ref``) at the marginal ``x``: Arnoldi on its
    forward differences (:func:`cycle_multipliers`); and the cycles it took.  ``ncv``,
    ``tol``: Arnoldi's Krylov space and tolerance (None: MULTIPLIER_NCV, MULTIPLIER_TOL of
    the options)."""
    import scipy.sparse.linalg as sla

    opt = options.DEFAULT
    ncv = opt.MULTIPLIER_NCV if ncv is None else ncv
    tol = opt.MULTIPLIER_TOL if tol is None else tol

    _, out, g = _carried_cycle(base, step, ref, x)
    if g is None:
        raise ValueError(f"cycle: the map does not apply at its own state ({out.get('message', '')})")
    S = np.flatnonzero(x > 1e-12)
    cycles = [1]

    def jv(v: np.ndarray) -> np.ndarray:
        cycles[0] += 1
        full = np.zeros_like(x)
        full[S] = np.ravel(v)
        e = opt.FD_STEP / max(np.abs(full).sum(), 1e-300)
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
    opt = options.DEFAULT
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
        coarse = cycle_cohorts(model, V, dt=2.0 * dt, h=2.0 * h, tol=max(opt.COARSE_TOL * tol, opt.COARSE_FLOOR),
                               max_iter=max_iter, start=_NO_COARSE)
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
        if st.pool > opt.MAX_CELLS:
            message = (f"more than {opt.MAX_CELLS} cells alive (blocks that shocks leave unjumped survive for many "
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
            slow = any((how[i] in ("Aitken", "slow") and rho[i] > opt.SLOW_CAVEAT)
                       or (how[i] in ("last steps", "noise", "state's move") and errors[i] > tol) for i in JUDGED)
        elif eager and not accelerated:
            slow = True  # (the start's own run was accelerated: so is this one, at once)
        else:
            continue
        # (only a short loading phase makes the blocks' relaxation slow from cycle to
        # cycle: the slowest multiplier is about exp(-0.19 T); from 0.7 V^c down a ratio
        # above 0.9 is noise, and the acceleration there cost more than it saved)
        if not accelerated and slow and out["period"] < opt.SHORT_PHASE and out["unjumped"] <= opt.ANDERSON_UNJUMPED:
            # a state after all but total shocks contracting slowly (close to V^c): solve
            # the fixed point, then verify it by the plain cycles again (with at least half the
            # cycles left: below the map's roughness, about 1e-6 of the mass at tol = 1e-6,
            # Anderson's residual creeps down without stalling and used to take them all)
            accelerated = True
            fast, used, slow_multiplier, residual = _anderson(model, V, h, step, dt, st, st.period_ref,
                                                              opt.ANDERSON_TOL * tol, max((int(max_iter) - it) // 2, 1))
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
                origin = st if from_coarse and not residual <= opt.ANDERSON_TOL * tol else fast
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
            elif extrapolated and ratio > opt.SLOW_CAVEAT:
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
