"""The cohort method's cycle map: a loading phase stepped to the shock's start, and the shock.

:func:`_one_cycle` takes a state just after a shock (:class:`~micro.cohort.state._Cohorts`)
through one loading phase (steps :func:`_step_length`, graded to a reference loading phase;
shorter ones close to V^c: :func:`_phase_step`), locates the shock's start by bisecting the
step that starts it, replays the end of the loading phase finely for the stress's peak
(:func:`_peak_before`) and applies the shock.  The map on the delta_R marginal after a shock
(:func:`_product_cycle`, :func:`_carried_cycle`) and the same cycle at frozen slips
(:func:`_frozen_cycle`, linear in the marginal) are what the solver
(:mod:`micro.cohort.solver`) accelerates and linearises.
"""
from __future__ import annotations

import numpy as np

from . import options
from .. import _progress
from ..params import Model
from .state import _Cohorts, _start


def _step_too_long(period: float, step: float, dt: float) -> bool:
    """Whether a loading phase of ``period`` has too few steps of ``step`` for the time
    step ``dt``: fewer than 0.8 of ``SHORT_PHASE / dt`` (not at every small change of the
    period: each cut of the step restarts the cycle sequence)."""
    opt = options.DEFAULT
    return period < 0.8 * opt.SHORT_PHASE / dt * step


def _phase_step(period: float, dt: float) -> float:
    """The step for loading phases of ``period`` at the time step ``dt``: ``dt``, or
    ``dt * period / SHORT_PHASE`` where the phase is shorter than SHORT_PHASE."""
    opt = options.DEFAULT
    return dt * min(1.0, period / opt.SHORT_PHASE)


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
    opt = options.DEFAULT
    return dt * min(opt.GRADED_MAX, max(1.0, gamma * min(since, ref - since)))


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


def _marginal(state: _Cohorts) -> np.ndarray:
    """The delta_R marginal of the blocks ``state``'s last shock made, normalised."""
    dep = state.dense(state.n - 1)
    return dep / dep.sum()


def _peak_before(st: _Cohorts, t_start: float, dt: float) -> float:
    """The largest stress on a graded mesh from the snapshot ``st`` to the shock's start
    at ``t_start`` (steps of half the time left): where the creep outruns the drive just
    before the shock (like (t* - t)^(-1/2)), the stress peaks within a step of the
    start, between the regular steps' ends.  The replay only measures; the cycle goes on
    from the regular steps (a graded mesh in the cycle itself would make the map
    discontinuous in where the start falls).  The replay stops at the first step in which
    the stress falls."""
    opt = options.DEFAULT
    peak = st.sigma
    rest = t_start - st.t
    while rest > opt.FOLD_TOL * dt:
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


def _fold_start(st: _Cohorts, step: float) -> tuple[float, float]:
    """Where in a step of ``step`` that starts a shock the fold appears: the step bisected
    to FOLD_TOL of its length, as (the longest part found without a fold, its slip); 0 and
    0 if the fold is at the step's start.  Leaves ``st`` prepared for a part of the step."""
    opt = options.DEFAULT
    lo, hi, x_lo = 0.0, step, 0.0
    while hi - lo > opt.FOLD_TOL * step:
        mid = 0.5 * (lo + hi)
        st.prepare(mid)
        x, status = st.root(below=x_lo)  # (a longer step slips more)
        if status == 0:
            lo, x_lo = mid, x
        else:
            hi = mid
    return lo, x_lo


def _one_cycle_steps(st: _Cohorts, dt: float, t_start: float, sigma_start: float, t_max: float) -> dict:
    """The steps of :func:`_one_cycle` (within its progress stage)."""
    opt = options.DEFAULT
    integral = 0.0
    peak = trough = st.sigma
    snapshot = None
    steps = []  # (length, slip) of every step the cycle committed, the shock's last
    replay = st.peak_excess > opt.PEAK_FLOOR
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
            snapshot = st.copy() if replay and x > opt.PEAK_CREEP * st.V * step else None
            advance(x, step, phi, Edt)
            continue
        here = st.copy() if replay and snapshot is None else None
        lo, x_lo = _fold_start(st, step)
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
    if abs(period - st.period_ref) > opt.GRADED_SLACK / gamma:
        st.period_ref = period
    try:
        slip = st.shock()
    except RuntimeError as err:
        return dict(ok=False, message=str(err))
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


