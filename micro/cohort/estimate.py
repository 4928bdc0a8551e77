"""The cohort method's error estimate: how far a sequence of cycles is from the fixed point.

From the last WINDOW cycles' rows (:data:`COLUMNS`) :func:`_estimate` gives each quantity's
error (Aitken's extrapolation where the contraction ratios are steady, the tail of the
largest ratio otherwise); :func:`_state_tail` bounds what the state's last move leaves
(a stress's own steps can pass through zero while the state still moves);
:func:`_relaxation_multiplier` is the slowest multiplier the model gives beforehand
(docs/reference/micro_cohort.md, section 4).
"""
from __future__ import annotations

import math

import numpy as np

from . import options
from ..params import Model

#: The columns of a cycle's row in the history, and those whose error decides convergence.
COLUMNS = ("sigma_max", "sigma_min", "period", "sigma_mean", "sigma_before", "sigma_after")
JUDGED = (0, 1, 4, 5)
#: Cycles an estimate needs: three Aitken extrapolations, from three pairs of differences.
#: (Not an option: :func:`_estimate`'s rules are written for five cycles.)
WINDOW = 5


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
    opt = options.DEFAULT
    w = a[-WINDOW:]
    d = np.diff(w, axis=0)
    still = max(opt.STILL, slowest / (1.0 - slowest)) if slowest < 1.0 else math.inf
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
        elif (r < 0.0).any() and steps[-3:].max() <= tol / opt.STILL:
            errors[i] = still * steps[-3:].max()
            how.append("noise")
        elif ((r >= 0.0) & (r <= opt.AITKEN_MAX_RATIO)).all():
            E = w[-3:, i] + di[-3:] * r / (1.0 - r)
            # a rising ratio (a slower mode taking over) goes on rising: its next step; and
            # a mode as slow as the model's slowest may not have shown itself yet
            r_hi = max(min(r[-1] + max(r[-1] - r[0], 0.0), opt.AITKEN_MAX_RATIO), min(slowest, opt.AITKEN_MAX_RATIO))
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
    opt = options.DEFAULT
    n = np.asarray(moves, float)[1:]
    if not n[-1] > 0.0:
        return 0.0, 0.0
    w = n[-(WINDOW - 1):]
    with np.errstate(divide="ignore", invalid="ignore"):
        ratio = float(np.max(w[1:] / w[:-1]))
    m = min(max(ratio if math.isfinite(ratio) else 1.0, slowest), opt.AITKEN_MAX_RATIO)
    steps = np.asarray(steps)
    rows = (n > 0.0) & (steps[1:] == steps[:-1])  # (kinks left out)
    rows[:-opt.SENSITIVITY_WINDOW] = False
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


