r"""Newton-Krylov on the cohort method's cycle map: a fixed point whose error is measured by
its residual.

The cycle map ``G`` (:func:`micro.cohort.cycle._carried_cycle`) takes the delta_R marginal ``x``
of the blocks a shock made jump (node masses, summing to 1) through one loading phase and
shock to the marginal of the blocks the next shock makes jump.  Close to V^c its
multipliers crowd towards 1 (a continuum 0.98, 0.97, ...: docs/reference/micro_cohort.md,
section 4) and Anderson's iteration, preconditioned by the map at frozen slips, can stall
where that linearisation grows along some mode (docs/validation/micro_cohort.md,
section 5).  Here the fixed point is solved by Newton's method on the whole map,

.. math:: x \leftarrow x + d, \qquad (I - J)\,d = G(x) - x,

each linear system by GMRES with the Jacobian-vector products by forward differences of
the map, ``J v ~ (G(x + e v) - G(x)) / e`` with ``e |v|_1 = FD_STEP`` (one cycle each).
The map is piecewise smooth (the number of steps in a loading phase, thresholds crossing
cell edges, cells dropped below ``CELL_FLOOR``): at k0 = 0.01, 0.9 V^c, cell
kappa zbar / 20, forward and central differences at a step of 1e-5 of the mass differ by
3 % of ``|J v|``, and the map's round-off is a few 1e-8 of the mass, where the residual
stalls (docs/validation/micro_cohort.md section 5; studies/micro_cohort_newton_krylov.py).
Its evaluations do not depend on the number of numba threads (the kernels sum fixed
chunks in a fixed order).

The error of a cycle quantity (sigma_max, ...) is its change over the last full Newton
step: that step solves ``(I - J) d = r`` to GMRES_RTOL, so it is the quantity's distance
from the fixed point to first order at the iterate before it; the iterate after it (the
one reported) is closer, its residual lower.  Where no halving of a step lowers the
residual (the map's round-off) the iterate before it is kept, with the full step's
change as its error.  Nothing here relies on the frozen-slip map.
"""
from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Callable

import numpy as np
import scipy.sparse.linalg as sla

from . import options

# (its constants, FD_STEP, GMRES_RTOL, GMRES_MAX, NEWTON_BACKTRACKS and NEWTON_MAX, are fields of
# micro.cohort.options.CohortOptions, with the measurements that set them)

__all__ = ["NewtonKrylov", "solve"]


@dataclass
class NewtonKrylov:
    """The outcome of :func:`solve`.

    ``state``, ``row``, ``x``: the cycle of the final iterate (the map's state after it, its
    row and its marginal); ``residual``: ``|G(x) - x|_1`` there; ``errors``: each judged
    column's change over the last full Newton step (inf if none was taken); ``evals``: map
    evaluations (cycles); ``certified``: the last full step changed every judged column by
    at most the tolerance; ``history``: (evaluations, residual, sigma_max) per iterate;
    ``message``: how it ended."""

    state: object = None
    row: dict = field(default_factory=dict)
    x: np.ndarray | None = None
    residual: float = math.inf
    errors: dict = field(default_factory=dict)
    evals: int = 0
    certified: bool = False
    history: list = field(default_factory=list)
    message: str = ""

    @property
    def error(self) -> float:
        """The largest of :attr:`errors` (inf if none)."""
        return max(self.errors.values(), default=math.inf)


class _MapFailed(Exception):
    pass


def _normalised(x: np.ndarray) -> np.ndarray:
    x = np.maximum(x, 0.0)
    return x / x.sum()


def solve(G: Callable, x0: np.ndarray, *, tol: float, max_evals: int,
          columns: tuple[str, ...] = ("sigma_max", "sigma_min", "sigma_before", "sigma_after"),
          log: Callable[[str], None] | None = None, rebase: Callable | None = None) -> NewtonKrylov:
    """The fixed point of the cycle map ``G`` (a marginal -> (state, row, image), the image
    None where the map does not apply) from ``x0``, by Newton-Krylov (module docstring).

    ``rebase`` (a state -> (map, marginal)): the map carries more than the marginal (the
    blocks a shock left unjumped, kept from the state it starts from); after each accepted
    Newton step the map is taken again from the state that step's cycle left, and the
    iteration goes on from that state's marginal (its residual the plain cycle's change),
    so that what the map carries is that of the fixed point's own cycle, not of the start.

    Stops when a full Newton step changed each of ``columns`` (keys of the row) by at most
    ``tol`` (certified, with those changes as the errors), when a step no longer lowers the
    residual after NEWTON_BACKTRACKS halvings (the map's round-off), after NEWTON_MAX steps, or
    when ``max_evals`` cycles are used."""
    opt = options.DEFAULT
    res = NewtonKrylov()

    def G1(v: np.ndarray):
        if res.evals >= max_evals:
            raise _MapFailed(f"the budget of {max_evals} cycles is used up")
        res.evals += 1
        return G(v)

    x = _normalised(np.asarray(x0, float))
    try:
        st, row, g = G1(x)
    except _MapFailed as err:
        res.message = str(err)
        return res
    if g is None:
        res.message = "the map does not apply at the start"
        return res
    r = g - x
    norm = float(np.abs(r).sum())
    res.state, res.row, res.x, res.residual = st, row, x, norm
    res.history.append((res.evals, norm, row["sigma_max"]))
    for newton in range(opt.NEWTON_MAX):
        def matvec(v: np.ndarray, x=x, g=g) -> np.ndarray:
            v = np.ravel(v)
            nv = float(np.abs(v).sum())
            if nv == 0.0:
                return np.zeros_like(v)
            e = opt.FD_STEP / nv
            _, _, gp = G1(x + e * v)
            if gp is None:
                raise _MapFailed("a Jacobian-vector product left the map's domain")
            return v - (gp - g) / e

        A = sla.LinearOperator((x.size, x.size), matvec=matvec, dtype=float)
        room = max_evals - res.evals - 1
        if room < 2:
            res.message = f"the budget of {max_evals} cycles is used up"
            break
        try:
            d, _ = sla.gmres(A, r, rtol=opt.GMRES_RTOL, atol=0.0, restart=min(opt.GMRES_MAX, room), maxiter=1)
        except _MapFailed as err:
            res.message = str(err)
            break
        lam, accepted, full = 1.0, None, None
        for _ in range(opt.NEWTON_BACKTRACKS + 1):
            xn = _normalised(x + lam * d)
            try:
                stn, rown, gn = G1(xn)
            except _MapFailed as err:
                res.message = str(err)
                break
            if gn is not None:
                if lam == 1.0:
                    full = {c: abs(float(rown[c]) - float(row[c])) for c in columns}
                rn = gn - xn
                normn = float(np.abs(rn).sum())
                if normn < norm:
                    accepted = (xn, stn, rown, gn, rn, normn)
                    break
            lam *= 0.5
        if accepted is None:
            if full is not None:
                # the residual is at the map's round-off: the full step, a solution of
                # (I - J) d = r, is still the iterate's distance from the fixed point to first
                # order, and its change of each column that iterate's error
                res.errors = full
                res.certified = max(full.values()) <= tol
            if not res.message:
                res.message = (f"Newton-Krylov: residual {norm:.1e} of the mass (the map's round-off: no halving "
                               f"of step {newton + 1} lowered it), {res.evals} cycles; the full step moved "
                               f"sigma_max by {res.errors.get('sigma_max', math.inf):.1e}")
            break
        xn, stn, rown, gn, rn, normn = accepted
        if rebase is not None:
            # one cycle more, the map now carrying what this cycle's shock left
            G, xn = rebase(stn)
            try:
                stn, rown, gn = G1(xn)
            except _MapFailed as err:
                res.message = str(err)
                break
            if gn is None:
                res.message = "the map does not apply after a Newton step"
                break
            rn = gn - xn
            normn = float(np.abs(rn).sum())
        change = {c: abs(float(rown[c]) - float(row[c])) for c in columns}
        if log is not None:
            log(f"newton-krylov step {newton + 1} (x{lam:g}): residual {norm:.2e} -> {normn:.2e}, "
                f"sigma_max {rown['sigma_max']:.10f} (moved {change['sigma_max']:.1e}), {res.evals} cycles")
        x, st, row, g, r, norm = xn, stn, rown, gn, rn, normn
        res.state, res.row, res.x, res.residual = st, row, x, norm
        res.history.append((res.evals, norm, row["sigma_max"]))
        if lam == 1.0:
            res.errors = change
            if max(change.values()) <= tol:
                res.certified = True
                res.message = (f"Newton-Krylov: residual {norm:.1e} of the mass after {newton + 1} steps, "
                               f"{res.evals} cycles; the last step moved sigma_max by {change['sigma_max']:.1e}")
                break
    else:
        res.message = f"no certified fixed point in {opt.NEWTON_MAX} Newton steps"
    if not res.certified and not res.message:
        res.message = "no certified fixed point"
    return res
