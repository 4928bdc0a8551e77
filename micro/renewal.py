r"""Steady sliding and its stability, solved directly: the jump-to-jump renewal chain.

In steady sliding the mean position moves at the drive velocity V, so every block is an
independent renewal process driven at V (the derivation is in ``docs/reference/micro_renewal.md``).
Between jumps a block's lag behind the mean grows at rate V and its k2-spring stretch
``e`` relaxes towards ``V tau`` (``tau = eta_u / k2 = 1/gamma``); it jumps when its
margin reaches 0, and a jump lowers both by z ~ g.  Just before a jump the margin is 0,
so the block's state there is one number, the spring's deficit ``d = V tau - e``; in
units of ``V tau``, ``x = d / (V tau)`` lives on [0, 1] and jump to jump it is a Markov
chain (:func:`micro._renewal_kernels.waiting_time`).  Its stationary measure gives

* the stress :math:`\sigma = f_{th} - \langle\delta\rangle` (the time-averaged margin,
  a positive integrand: no cancellation at large V),
* the mean waiting time, which must equal :math:`\bar z / V` (a check),
* the density of blocks at the threshold, and with it the branching ratio of an
  avalanche in steady sliding :math:`b = p_0 \bar z (k_1 + k_2) = (k_1 + k_2)\,
  E_\pi[1/(k_0 + k_1 + k_2 x)]`.

Linear stability: perturbing the mean slip velocity by :math:`\nu e^{\lambda t}` and
closing the loop through :math:`\dot{\bar h} = \bar z \times` (jump rate) gives the
characteristic equation :math:`G(\lambda) = 1`, with :math:`G(0) = k_1/(k_0 + k_1)` and
:math:`G(+\infty) = b`.  Steady sliding loses stability where b crosses 1: a real root
enters from :math:`\lambda = +\infty` (:func:`unstable_mode_count` checks that no other
root is in the right half-plane).

Discretisation: Chebyshev collocation of the chain's expectation operator in x (a
moment method: the stationary measure, however narrow, need not be resolved), on an
affine map, or a sinh map clustered at x = 0 on the scale (k0 + k1)/k2 when that is
small, and composite Gauss-Legendre in z, graded towards z = 0.  The stationary weights are quadrature weights
(they may be negative), not a density; they are refined against the generator's own
entries (near the identity, at large V or small k0 + k1, forming the system rounds them
away), and sigma, b and G are renewal-reward ratios over the mean wait they give.
Deterministic jumps have no density: the chain is a 1-D map whose fixed point is closed
form (it reproduces Eq. (4)).

Threads: the systems are small (32 to 384 unknowns) and solved thousands of times in a
growth-rate root, where multithreaded BLAS gains nothing and its waiting threads spin
against other work (``steady_sliding(Model(k0=0.1), np.logspace(-1, 3, 100))`` under
load: 6.4 s before, 1.1 s with one thread; three at once 64 s and 2.0 s each).  Every public function here runs with BLAS held at one
thread (:func:`micro._threads.single_blas_thread`), the previous limits restored after.
"""
from __future__ import annotations

import logging
import math
import numbers
from dataclasses import dataclass, field
from functools import lru_cache
from typing import TYPE_CHECKING

import numpy as np
from numpy.polynomial.legendre import leggauss
from scipy.optimize import brentq

from . import _renewal_kernels as RK
from ._threads import blas_single_threaded
from .analytic import _check_model
from .params import KIND_DETERMINISTIC, KIND_EXPONENTIAL, Model
from .results import ABOVE, BELOW

if TYPE_CHECKING:  # pragma: no cover  (pandas only for the tables: V^c does without it)
    import pandas as pd

__all__ = ["SteadySliding", "steady_sliding", "critical_velocity_renewal", "characteristic_function",
           "growth_rate_near_vc", "unstable_mode_count", "vc_small_k0"]

log = logging.getLogger(__name__)

#: Gauss-Legendre nodes per panel of the z quadrature.
Z_NODES = 12
#: Smallest and largest collocation grids tried by the adaptive solve.
N_START, N_MAX = 32, 384
#: Velocity range in which the chain is documented and tested.
V_RANGE = (1e-6, 1e7)


def _fractions(model: Model) -> tuple[float, float]:
    """alpha = (k0 + k1) / kappa and beta = k2 / kappa, the chain's two stiffness fractions."""
    return (model.k0 + model.k1) / model.kappa, model.k2 / model.kappa


def _stress(model: Model, V: float, mean_integral: float, mean_wait: float) -> float:
    """sigma = f_th - <delta>: the mean margin integral over the mean wait (renewal-reward),
    in physical units."""
    return model.f_th - model.kappa * (V / model.gamma) * mean_integral / mean_wait


def _is_number(x) -> bool:
    """A real number, not a bool (an int to Python) or a string (float('1') would take it)."""
    return not isinstance(x, (bool, np.bool_, str, bytes)) and isinstance(x, (numbers.Real, np.number))


def _check_velocities(V) -> np.ndarray:
    """``V`` (a number or an array of numbers, strictly: no strings, no bools) as floats in
    the velocity range, or one ValueError."""
    shown = repr(V) if len(repr(V)) <= 60 else repr(V)[:57] + "..."
    try:
        raw = np.asarray(V)
        ok = raw.dtype.kind in "iuf" or (raw.dtype.kind == "O" and all(_is_number(x) for x in raw.ravel()))
        if not ok:
            raise TypeError
        v = raw.astype(float)
    except (TypeError, ValueError):
        raise ValueError(f"V must be a number or an array of numbers, got {shown}") from None
    if v.size == 0:
        raise ValueError("V must hold at least one velocity, got an empty array")
    bad = ~(np.isfinite(v) & (v >= V_RANGE[0]) & (v <= V_RANGE[1]))
    if np.any(bad):
        raise ValueError(f"V must be finite and in [{V_RANGE[0]:g}, {V_RANGE[1]:g}], got {float(v[bad].ravel()[0])!r}")
    return v


# ------------------------------------------------------------------------------ quadrature in z
@dataclass(frozen=True)
class _Quadrature:
    z: np.ndarray  # pinning distances
    weight: np.ndarray  # probabilities, summing to 1


def _panels(lo_scale: float, zbar: float, z_top: float) -> np.ndarray:
    """Panel ends: doubling from ``lo_scale`` up to ``zbar`` (at small V the waiting time
    changes on the drive's loading distance), panels of zbar up to 4 zbar, then doubling
    up to ``z_top`` (the exponential tail: 12 Gauss nodes integrate e^-z over a panel of 16
    e-folds to ~1e-9 of its mass, itself below e^-16))."""
    ends = [0.0]
    b = lo_scale
    while b < zbar:
        ends.append(b)
        b *= 2.0
    ends += [zbar, 2.0 * zbar, 3.0 * zbar, 4.0 * zbar]
    b = 8.0 * zbar
    while b < z_top:
        ends.append(b)
        b *= 2.0
    ends = np.array(ends)
    return np.unique(np.concatenate([ends[ends < z_top], [z_top]]))


def _quadrature(model: Model, V: float, nodes: int = Z_NODES) -> _Quadrature:
    """Composite Gauss-Legendre for E_z over g (a density: exponential or tabulated),
    graded towards z = 0 on the scale ``alpha V / gamma`` where the waiting time changes
    fastest at small V."""
    jumps = model.jumps
    zbar = jumps.mean
    alpha, _ = _fractions(model)
    lo_scale = 0.25 * max(alpha * V / model.gamma, 1e-12 * zbar)
    if jumps.kind == KIND_EXPONENTIAL:
        z_top = min(jumps.cutoff, 40.0 * jumps.zbar)
        pdf = lambda z: np.exp(-z / jumps.zbar)  # noqa: E731 - normalised below
    else:
        z_top = jumps.z_max
        pdf = lambda z: np.asarray(jumps.pdf(z), dtype=float)  # noqa: E731
    ends = _panels(lo_scale, zbar, z_top)
    g, w = leggauss(nodes)
    mid, half = 0.5 * (ends[1:] + ends[:-1]), 0.5 * np.diff(ends)
    z = (mid[:, None] + half[:, None] * g[None, :]).ravel()
    weight = (half[:, None] * w[None, :]).ravel() * pdf(z)
    if not (np.all(np.isfinite(weight)) and np.all(weight >= 0.0) and weight.sum() > 0.0):
        raise ValueError("the jump distribution's pdf must be finite and >= 0 with positive mass")
    keep = weight > 0.0
    return _Quadrature(z[keep], weight[keep] / weight.sum())


# ------------------------------------------------------------------------------ the chain on a grid
@dataclass
class _Grid:
    """Chebyshev points in theta, mapped to the deficit x by ``x = c + w sinh(mu + nu theta)``."""

    theta: np.ndarray
    x: np.ndarray
    bw: np.ndarray
    c: float
    w: float
    mu: float
    nu: float

    @classmethod
    def build(cls, n: int, center: float, width: float) -> "_Grid":
        theta = -np.cos(np.pi * np.arange(n) / (n - 1))
        bw = (-1.0) ** np.arange(n)
        bw[0] *= 0.5
        bw[-1] *= 0.5
        if not (math.isfinite(width) and width < 0.2):
            return cls(theta, 0.5 * (theta + 1.0), bw, 0.5, math.inf, 0.0, 1.0)
        a0, a1 = math.asinh((0.0 - center) / width), math.asinh((1.0 - center) / width)
        mu, nu = 0.5 * (a1 + a0), 0.5 * (a1 - a0)
        x = np.clip(center + width * np.sinh(mu + nu * theta), 0.0, 1.0)
        x[0], x[-1] = 0.0, 1.0
        return cls(theta, x, bw, center, width, mu, nu)

    def dtheta_dx(self, x: np.ndarray) -> np.ndarray:
        if not math.isfinite(self.w):
            return np.full_like(x, 2.0)
        return 1.0 / (self.nu * np.sqrt(self.w**2 + (x - self.c) ** 2))

    def differentiation_matrix(self) -> np.ndarray:
        """d/dtheta on the Chebyshev points (Trefethen, Spectral Methods in MATLAB, cheb)."""
        n = self.theta.size
        c = np.ones(n)
        c[0] = c[-1] = 2.0
        c *= (-1.0) ** np.arange(n)
        dX = self.theta[:, None] - self.theta[None, :]
        Dm = np.outer(c, 1.0 / c) / (dX + np.eye(n))
        return Dm - np.diag(Dm.sum(axis=1))


#: Sweeps of iterative refinement of the stationary weights.
REFINE_SWEEPS = 2


def _stationary_weights(Q: np.ndarray) -> np.ndarray:
    """The weights w with w Q = 0 and sum(w) = 1 (Q = M - I), as the nonsingular system
    (1/n - Q)^T w = 1/n, refined against Q itself.

    Near the identity (large V, small k0 + k1) the entries of Q are ~ alpha zeta_bar, far
    below 1/n: forming 1/n - Q rounds them to a few digits (at k0 = 1e-4, (k1, k2) = (0, 1),
    V = 1e7 one solve missed E_pi[t] = zeta_bar by 5e-6 relative, and b by 5e-6), and the LU's
    backward error is amplified by 1 / (spectral gap) ~ 1 / (alpha zeta_bar).  Each sweep
    solves for the correction with the same matrix but takes the residual
    (1 - sum w)/n + Q^T w from Q's accurate entries; two sweeps bring E_pi[t] to zeta_bar
    within ~1e-15 (docs/validation/micro_renewal.md, section 5).
    """
    n = Q.shape[0]
    A_t = (1.0 / n - Q).T
    w = np.linalg.solve(A_t, np.full(n, 1.0 / n))
    for _ in range(REFINE_SWEEPS):
        residual = (1.0 - w.sum()) / n + Q.T @ w
        w = w + np.linalg.solve(A_t, residual)
    return w


@dataclass
class _Chain:
    """The renewal chain of one (model, V) on one grid, with its stationary weights."""

    model: Model
    V: float
    quad: _Quadrature
    grid: _Grid
    zeta: np.ndarray
    Q: np.ndarray
    Et: np.ndarray
    EI: np.ndarray
    weights: np.ndarray
    t: np.ndarray | None = None
    xp: np.ndarray | None = None
    L: np.ndarray | None = None

    @classmethod
    def solve(cls, model: Model, V: float, quad: _Quadrature, grid: _Grid, store: bool = False) -> "_Chain":
        alpha, beta = _fractions(model)
        zeta = model.gamma * quad.z / V
        Q, Et, EI, t, xp, L = RK.assemble(grid.x, grid.theta, grid.bw, zeta, quad.weight, alpha, beta,
                                          grid.c, grid.w, grid.mu, grid.nu, store)
        return cls(model, V, quad, grid, zeta, Q, Et, EI, _stationary_weights(Q),
                   t if store else None, xp if store else None, L if store else None)

    @property
    def zeta_bar(self) -> float:
        return float(self.quad.weight @ self.zeta)

    @property
    def mean_wait(self) -> float:
        """E_pi[t] from the computed weights (chain units; exactly zeta_bar for the exact pi)."""
        return float(self.weights @ self.Et)

    # sigma and b are renewal-reward ratios over the *computed* mean wait, not over its exact
    # value zeta_bar: an error in where the weights put the measure is shared by the mean wait
    # and cancels from the ratios up to O(zeta_bar) (docs/reference/micro_renewal.md, section
    # 3; without the refined solve it was 5e-6 of the mean wait at V = 1e7)
    @property
    def sigma(self) -> float:
        return _stress(self.model, self.V, float(self.weights @ self.EI), self.mean_wait)

    @property
    def branching_ratio(self) -> float:
        m = self.model
        crossings = float(self.weights @ (1.0 / (m.k0 + m.k1 + m.k2 * self.grid.x)))
        return (m.k1 + m.k2) * crossings * self.zeta_bar / self.mean_wait

    @property
    def wait_error(self) -> float:
        """E_pi[T] V / zbar - 1, which the exact stationary measure makes 0."""
        return self.mean_wait / self.zeta_bar - 1.0


#: Below this ratio (k0 + k1) / k2 the grid clusters at x = 0 on the scale (k0 + k1) / k2.
BOUNDARY_LAYER = 0.05


def _map_width(model: Model) -> float:
    """Width of the sinh map, clustered at x = 0: with a small k0 + k1, blocks that waited
    long (a large z) arrive with x near 0, where the waiting time and the density at the
    threshold vary on the scale (k0 + k1)/k2 (their singularity is at x = -(k0+k1)/k2).
    Otherwise the affine map (inf): Chebyshev collocation of the expectation operator
    acts as a moment method and needs no resolution of the (narrow) stationary measure."""
    ratio = (model.k0 + model.k1) / model.k2
    return ratio if ratio < BOUNDARY_LAYER else math.inf


def _solve_adaptive(model: Model, V: float, tol: float, n_max: int = N_MAX, store: bool = False):
    """Grow the grid by 3/2 until sigma and b move less than ``tol``; returns the finest
    chain, the error estimates (the last change) and whether ``tol`` was met."""
    quad = _quadrature(model, V)
    width = _map_width(model)
    prev = None
    n = N_START
    while True:
        chain = _Chain.solve(model, V, quad, _Grid.build(n, 0.0, width), store=store)
        if prev is not None:
            err_s = abs(chain.sigma - prev.sigma)
            err_b = abs(chain.branching_ratio - prev.branching_ratio)
            if (err_s <= tol and err_b <= tol) or n >= n_max:
                return chain, err_s, err_b, bool(err_s <= tol and err_b <= tol)
        prev = chain
        n = min(int(1.5 * n), n_max)


# ------------------------------------------------------------------------------ deterministic jumps
def _map_derivatives(x: float, zeta: float, alpha: float, beta: float) -> tuple[float, float, float, float]:
    """For the deterministic 1-D map x -> x'(x, zeta): (t, x', dt/dx, dx'/dx), by implicit
    differentiation of alpha t + beta D (1 - e^-t) = zeta."""
    D = x + zeta
    t = RK.waiting_time(zeta, D, alpha, beta)
    xp = D * math.exp(-t)
    t_x = -beta * (-math.expm1(-t)) / (alpha + beta * xp)
    return t, xp, t_x, math.exp(-t) * (1.0 - D * t_x)


def _deterministic(model: Model, V: float) -> tuple[float, float, float, float]:
    """Fixed point x* of the 1-D map x -> x'(x, zbar): (x*, t*, sigma, b).  Since
    x' - x = (alpha/beta)(t - zeta), x' = x forces t = zeta, and (R1) then gives
    x* = zeta / (e^zeta - 1) in closed form.  (A Newton iteration on the map, used before,
    leaves the round-off of x' - x over 1 - dx'/dx ~ alpha zeta: 1e-7 in b at k0 = 1e-3,
    (k1, k2) = (0, 1), V = 1e5.)"""
    alpha, beta = _fractions(model)
    zeta = model.gamma * model.jumps.mean / V
    x = zeta * math.exp(-zeta) / -math.expm1(-zeta)  # zeta / (e^zeta - 1), no overflow at large zeta
    t = zeta
    sigma = _stress(model, V, RK.margin_integral(zeta, x + zeta, t, alpha, beta), zeta)
    b = (model.k1 + model.k2) / (model.k0 + model.k1 + model.k2 * x)
    return x, t, sigma, b


# ------------------------------------------------------------------------------ linear stability
def _response_terms(chain_alpha, chain_beta, rho1, t, xp, D, lam):
    """e^{-lam t} times the shift of the next jump time (dT) and of the arrival deficit
    (dx) per unit relative perturbation of the slip velocity nu e^{lam t}, for blocks that
    jumped at time 0 (chain units)."""
    A = np.exp(-lam * t)
    em = -np.expm1(-t)
    one_minus_A_over_lam = -np.expm1(-lam * t) / lam
    k = chain_beta / (lam + 1.0)
    A_delta1 = -(rho1 - k) * one_minus_A_over_lam - k * em * A
    A_dT = A_delta1 / (chain_alpha + chain_beta * xp)
    A_dx = -(xp * A_dT + (-np.expm1(-(lam + 1.0) * t)) / (lam + 1.0))
    return A, A_dT, A_dx


def _gain(model: Model, V: float, tol: float):
    """G as a function of lam in chain units (lam / gamma), on one chain built once."""
    rho1 = (model.k1 + model.k2) / model.kappa
    alpha, beta = _fractions(model)
    if model.jumps.kind == KIND_DETERMINISTIC:
        x, _, _, _ = _deterministic(model, V)
        zeta = model.gamma * model.jumps.mean / V
        D = x + zeta
        t, _, t_x, x_x = _map_derivatives(x, zeta, alpha, beta)

        def gain_deterministic(lam: complex) -> complex:
            # on the fixed point: h = 1 / (1 - A), h' from differentiating h = 1 + A h(x'(x))
            A, A_dT, A_dx = _response_terms(alpha, beta, rho1, t, x, D, lam)
            h = 1.0 / (1.0 - A)
            h1 = -lam * t_x * A * h / (1.0 - A * x_x)
            return complex(-lam * A_dT * h + A_dx * h1)

        return gain_deterministic
    chain, _, _, _ = _solve_adaptive(model, V, tol, store=True)
    grid, n = chain.grid, chain.grid.x.size
    D = grid.x[:, None] + chain.zeta[None, :]
    Dtheta = grid.differentiation_matrix()
    dthdx = grid.dtheta_dx(chain.xp)
    wz = chain.quad.weight
    rate = chain.zeta_bar / chain.mean_wait

    def gain(lam: complex) -> complex:
        A, A_dT, A_dx = _response_terms(alpha, beta, rho1, chain.t, chain.xp, D, lam)
        M = np.einsum("iq,iqj->ij", A * wz[None, :], chain.L)
        h = np.linalg.solve(np.eye(n) - M, np.ones(n, dtype=complex))  # discounted future jumps
        H = chain.L @ h
        H1 = (chain.L @ (Dtheta @ h)) * dthdx
        # per jump, over the computed mean wait (r0 = 1 / E_pi[t]), as sigma and b are
        return complex(chain.weights @ np.sum(wz[None, :] * (-lam * A_dT * H + A_dx * H1), axis=1)) * rate

    return gain


@blas_single_threaded
def characteristic_function(model: Model, V: float, lam, *, tol: float = 1e-10) -> np.ndarray:
    r"""The open-loop gain :math:`G(\lambda)` of steady sliding at drive velocity V.

    A perturbation :math:`\nu e^{\lambda t}` of the mean slip velocity changes the jump
    rate by :math:`G(\lambda)\,\nu e^{\lambda t}/\bar z`; the closed loop has a mode
    :math:`e^{\lambda t}` where :math:`G(\lambda) = 1`.  ``lam`` is in units of 1/time
    (real or complex, an array or a number; ``Re lam > -gamma``, not 0).  Limits:
    :math:`G(0^+) = k_1/(k_0+k_1)`, :math:`G(+\infty) = b`, the branching ratio.

    Parameters
    ----------
    model : Model
        The model.
    V : float
        Drive velocity, in [1e-6, 1e7].
    lam : complex or array_like
        Where to evaluate G, in 1/time.
    tol : float
        Tolerance of the chain's adaptive grid (default 1e-10).

    Returns
    -------
    ndarray of complex
        :math:`G(\lambda)`, with the shape of ``lam``.

    Raises
    ------
    ValueError
        If ``model`` is not a :class:`Model`, ``V`` is out of range, or a ``lam`` is 0, not
        finite or has :math:`\operatorname{Re}\lambda \le -\gamma`.

    Examples
    --------
    >>> import micro
    >>> model = micro.Model(k0=0.1)
    >>> G = micro.characteristic_function(model, 2.0, [1e6])          # G(+inf) = b
    >>> round(float(G[0].real), 4), round(float(micro.steady_sliding(model, 2.0).branching_ratio), 4)
    (0.9423, 0.9423)
    """
    _check_model(model)
    V = float(_check_velocities(V))
    lam = np.asarray(lam, dtype=complex) / model.gamma
    if np.any(lam == 0.0) or np.any(~np.isfinite(lam)) or np.any(lam.real <= -1.0):
        raise ValueError(f"lam must be finite, nonzero and have Re lam > -gamma = {-model.gamma:g}")
    gain = _gain(model, V, tol)
    out = np.empty(lam.shape, dtype=complex)
    for k, l in np.ndenumerate(lam):
        out[k] = gain(l)
    return out


def _growth_rate(model: Model, V: float, b: float, tol: float) -> float:
    """The largest real root lam > 0 of G(lam) = 1 (in 1/time), NaN if b <= 1.  G(0+) =
    k1/(k0+k1) < 1 and G(+inf) = b > 1: scan down from large lam for the first sign
    change, then Brent's method on log lam."""
    if not b > 1.0:
        return math.nan
    gain = _gain(model, V, tol)
    f = lambda ll: gain(math.exp(ll)).real - 1.0  # noqa: E731 - chain units
    zeta_bar = model.gamma * model.zbar / V
    hi = math.log(1e3 / zeta_bar / max(b - 1.0, 1e-6))
    f_hi = f(hi)
    while f_hi <= 0.0 and hi < 700.0:
        hi += 4.0
        f_hi = f(hi)
    lo = hi
    while True:
        lo -= 2.0
        f_lo = f(lo)
        if f_lo <= 0.0:
            break
        if lo < -60.0:
            return math.nan
        hi, f_hi = lo, f_lo
    return model.gamma * math.exp(brentq(f, lo, hi, xtol=1e-12))


def growth_rate_near_vc(model: Model, b):
    r"""The growth rate of steady sliding's unstable mode close to V^c, from its branching
    ratio ``b`` > 1: :math:`\Lambda = \frac{k_2\gamma}{k_1 + k_2}\frac{b}{b - 1} - \gamma` (per unit
    time).

    The asymptote of the root of G(Lambda) = 1 as b -> 1+ (docs/reference/micro_transition.md
    §4.1): a fast slip perturbation Y shifts every margin by -(k1 + k2) Y at once, the dashpots
    give back k2 Y at the rate gamma, and the mode lives while that relief lags the excess
    b - 1.  Its relative error is about d = 1 - V/V^c (0.3 d to d at the paper's parameters);
    NaN where b <= 1.

    >>> import micro
    >>> m = micro.Model(k0=0.1)
    >>> st = micro.steady_sliding(m, 0.999 * micro.critical_velocity(m).Vc)
    >>> bool(abs(micro.growth_rate_near_vc(m, st.branching_ratio) / st.growth_rate - 1) < 1e-3)
    True
    """
    b = np.asarray(b, dtype=float)
    with np.errstate(divide="ignore", invalid="ignore"):
        lam = model.k2 * model.gamma * b / ((model.k1 + model.k2) * (b - 1.0)) - model.gamma
    return np.where(b > 1.0, lam, np.nan)[()]


@blas_single_threaded
def unstable_mode_count(model: Model, V: float, *, omega_max: float | None = None, n_omega: int = 4000,
                        tol: float = 1e-10) -> int:
    r"""The number of roots of :math:`G(\lambda) = 1` with :math:`\operatorname{Re}\lambda > 0`,
    by the argument principle along the imaginary axis (G is analytic in the right
    half-plane and tends to b on its large half-circle).  A check of the claim that b
    alone decides stability; it costs ``n_omega`` evaluations of G.  Where the phase has
    not settled (close to V^c, where G(iω) − 1 tends to b − 1 only beyond the frequencies
    the quadrature resolves) a warning is logged and the count is not conclusive.

    Parameters
    ----------
    model : Model
        The model.
    V : float
        Drive velocity, in [1e-6, 1e7].
    omega_max : float, optional
        The largest frequency on the axis, > 0 (default ``200 V / zbar``).
    n_omega : int
        Frequencies, geometric from ``1e-6 gamma`` to ``omega_max`` (an integer >= 10,
        default 4000).
    tol : float
        Tolerance of the chain's adaptive grid (default 1e-10).

    Returns
    -------
    int
        The number of unstable modes (0 where steady sliding is stable).

    Raises
    ------
    ValueError
        If ``model`` is not a :class:`Model`, ``V`` is out of range, ``n_omega`` is not an
        integer >= 10, or ``omega_max`` is not a finite number > 0.

    Examples
    --------
    >>> import micro
    >>> micro.unstable_mode_count(micro.Model(k0=0.3), 0.06)      # below V^c = 0.1947; seconds
    1
    """
    _check_model(model)
    V = float(_check_velocities(V))
    if int(n_omega) != n_omega or n_omega < 10:
        raise ValueError(f"n_omega must be an integer >= 10, got {n_omega!r}")
    if omega_max is not None and not (math.isfinite(omega_max) and omega_max > 0.0):
        raise ValueError(f"omega_max must be a finite number > 0, got {omega_max!r}")
    zeta_bar = model.gamma * model.zbar / V
    if omega_max is None:
        omega_max = 200.0 * model.gamma / zeta_bar
    omega = np.concatenate([[1e-9 * model.gamma], np.geomspace(1e-6 * model.gamma, omega_max, n_omega)])
    G = characteristic_function(model, V, 1j * omega, tol=tol) - 1.0
    phase = np.unwrap(np.angle(G))
    turns = (phase[-1] - phase[0]) / math.pi
    settled = abs(G[-1].imag) < 0.5 * abs(G[-1].real)  # the end of the axis must be near b - 1, real
    if not (abs(turns - round(turns)) < 0.05 and settled):
        log.warning("unstable_mode_count(V=%g): the phase has not settled (%.3f turns, G(i omega_max)-1 = %s)",
                    V, turns, G[-1])
    return int(round(-turns))


# ------------------------------------------------------------------------------ public results
@dataclass
class SteadySliding:
    """Steady sliding at each drive velocity, from the renewal chain.

    Arrays have the shape of the ``V`` given; ``to_frame()`` has one row per V.

    Attributes
    ----------
    model : Model
        The model.
    V : ndarray
        The drive velocities.
    sigma : ndarray
        The stationary stress.
    branching_ratio : ndarray
        b, the mean number of blocks a jump pushes over the threshold.
    stable : ndarray of bool
        Whether steady sliding is linearly stable (b < 1).
    growth_rate : ndarray
        The rate of the unstable mode (1/time; NaN where stable or not asked for).
    sigma_error, branching_error : ndarray
        The change of sigma and b from the previous grid, and at least their round-off
        (8 ulp of ``f_th + |sigma|`` and of b).
    wait_error : ndarray
        The relative error of the mean waiting time against zbar / V.
    n_nodes : ndarray of int
        The grid used (0 without dashpot, 1 for deterministic jumps: closed forms).
    converged : ndarray of bool
        Whether the grid met ``tol``.
    method : ndarray of str
        What answered each V: ``'chain'`` (the collocated renewal chain),
        ``'fixed point'`` (deterministic jumps: the chain's fixed point in closed form) or
        ``'no dashpot'`` (k2 = 0: a renewal process in closed form).
    message : str
        ``'converged'``, or the velocities where it did not.
    """

    model: Model
    V: np.ndarray
    sigma: np.ndarray
    branching_ratio: np.ndarray
    stable: np.ndarray
    growth_rate: np.ndarray
    sigma_error: np.ndarray
    branching_error: np.ndarray
    wait_error: np.ndarray
    n_nodes: np.ndarray
    converged: np.ndarray
    method: np.ndarray
    message: str = field(default="")

    def to_frame(self) -> pd.DataFrame:
        import pandas as pd

        m = self.model
        n = np.size(self.V)
        return pd.DataFrame({
            "k0": np.full(n, m.k0), "k1": np.full(n, m.k1), "k2": np.full(n, m.k2), "zbar": np.full(n, m.zbar),
            "V": np.ravel(self.V), "sigma": np.ravel(self.sigma), "branching_ratio": np.ravel(self.branching_ratio),
            "stable": np.ravel(self.stable), "growth_rate": np.ravel(self.growth_rate),
            "sigma_error": np.ravel(self.sigma_error), "converged": np.ravel(self.converged),
            "method": np.ravel(self.method),
        })


#: A dashpot whose stiffness is below this fraction of kappa is taken as absent: its effect
#: on sigma and b is of order k2 / kappa, and the chain's solve with it is singular
#: (k2 = 2e-211 at k0 = 1: numpy.linalg.LinAlgError, found by tests/micro/test_properties.py).
NO_DASHPOT = 1e-13


#: Relative round-off below which no error estimate of sigma or b goes: 8 ulp of
#: f_th + |sigma| and of b (where the grids agree to the last bit, the errors measured against
#: the large-V expansion are up to 2.2 ulp of f_th + |sigma| and 6.1 ulp of b;
#: docs/validation/micro_renewal.md, section 5).
ROUNDOFF = 8.0 * np.finfo(float).eps


#: Smallest relaxation per mean wait, gamma zbar / V, the chain resolves.
RELAX_MIN = 1e-16


def _no_dashpot(model: Model) -> bool:
    return model.k2 <= NO_DASHPOT * model.kappa


@blas_single_threaded
def steady_sliding(model: Model, V, *, tol: float = 1e-11, growth_rate: bool = True,
                   warn: bool = True) -> SteadySliding:
    """Steady sliding at drive velocity ``V`` (a number or an array), on either branch.

    The stationary measure of the jump-to-jump chain is solved on grids of 32, 48, 72, ...
    nodes until sigma and the branching ratio change by less than ``tol`` (up to 384
    nodes; ``converged`` says whether ``tol`` was met).  Cost: a few ms per V after
    compilation; with ``growth_rate`` (the default) each unstable V also costs a root
    search on G (about 0.03 s).  A grid that misses ``tol`` is logged as a warning unless
    ``warn`` is False; ``converged`` and ``message`` say it either way.

    Parameters
    ----------
    model : Model
        The model.
    V : float or array_like
        Drive velocities, each in [1e-6, 1e7] (and at most ``gamma zbar / 1e-16``).
    tol : float
        Change of sigma and b between grids at which to stop, > 0 (default 1e-11).
    growth_rate : bool
        Compute the growth rate of the unstable mode where b > 1 (default True).
    warn : bool
        Log a warning where the grid misses ``tol`` (default True).

    Returns
    -------
    SteadySliding
        sigma, the branching ratio, stability and growth rate at each V, with their
        errors.

    Raises
    ------
    ValueError
        If ``model`` is not a :class:`Model`, a velocity is not finite or out of range,
        or ``tol`` is not a finite number > 0.

    Examples
    --------
    >>> import micro
    >>> branch = micro.steady_sliding(micro.Model(k0=0.1), [0.5, 2.0])
    >>> branch.stable.tolist(), [round(float(s), 6) for s in branch.sigma]
    ([False, True], [0.902686, 0.893759])
    """
    _check_model(model)
    v = _check_velocities(V)
    if not (math.isfinite(tol) and tol > 0.0):
        raise ValueError(f"tol must be a finite number > 0, got {tol!r}")
    if not _no_dashpot(model) and model.gamma * model.jumps.mean / float(np.max(v)) < RELAX_MIN:
        # (the chain's solve is singular where exp(-gamma t) rounds to 1 over a wait: k2 = 1e-11, V = 1e6)
        raise ValueError(f"V must be at most gamma zbar / {RELAX_MIN:g} = {model.gamma * model.jumps.mean / RELAX_MIN:g} "
                         f"for this model: faster, the dashpots relax by less than round-off between a block's "
                         f"jumps and the renewal chain cannot resolve them, got {float(np.max(v)):g}")
    flat = v.ravel()
    out = {k: np.full(flat.size, math.nan) for k in ("sigma", "b", "lam", "err_s", "err_b", "wait", "n")}
    conv = np.ones(flat.size, dtype=bool)
    method = np.full(flat.size, "chain", dtype=object)
    for k, Vk in enumerate(flat):
        if _no_dashpot(model):
            method[k] = "no dashpot"
            # no relaxation: every margin renews with increments (k0 + k1) z at any V
            out["sigma"][k] = model.f_th - (model.k0 + model.k1) * model.jumps.mean_residual
            out["b"][k] = model.k1 / (model.k0 + model.k1)
            out["err_s"][k] = out["err_b"][k] = out["wait"][k] = 0.0
            out["n"][k] = 0
        elif model.jumps.kind == KIND_DETERMINISTIC:
            method[k] = "fixed point"
            _, t, out["sigma"][k], out["b"][k] = _deterministic(model, float(Vk))
            out["err_s"][k] = out["err_b"][k] = 0.0
            out["wait"][k] = t / (model.gamma * model.jumps.mean / Vk) - 1.0
            out["n"][k] = 1
        else:
            chain, err_s, err_b, ok = _solve_adaptive(model, float(Vk), tol)
            out["sigma"][k], out["b"][k] = chain.sigma, chain.branching_ratio
            out["err_s"][k], out["err_b"][k], out["wait"][k] = err_s, err_b, chain.wait_error
            out["n"][k] = chain.grid.x.size
            conv[k] = ok
        # no estimate below the round-off of the formulas themselves (the grids of a
        # near-identity chain can agree to the last bit)
        out["err_s"][k] = max(out["err_s"][k], ROUNDOFF * (abs(model.f_th) + abs(out["sigma"][k])))
        out["err_b"][k] = max(out["err_b"][k], ROUNDOFF * out["b"][k])
        if growth_rate and out["b"][k] > 1.0:
            out["lam"][k] = _growth_rate(model, float(Vk), out["b"][k], max(tol, 1e-10))
    shape = v.shape
    stable = out["b"] < 1.0
    message = "converged" if conv.all() else (
        f"the grid did not reach tol = {tol:g} at V = "
        + ", ".join(f"{x:g}" for x in flat[~conv]) + f" ({N_MAX} nodes); see sigma_error")
    if not conv.all() and warn:
        log.warning("micro.steady_sliding(k0=%g): %s", model.k0, message)
    r = lambda a: a.reshape(shape)  # noqa: E731
    return SteadySliding(model, v, r(out["sigma"]), r(out["b"]), r(stable), r(out["lam"]), r(out["err_s"]),
                         r(out["err_b"]), r(out["wait"]), r(out["n"].astype(int)), r(conv), r(method), message)


def vc_small_k0(model: Model) -> float:
    r"""The small-k0 asymptote of the critical velocity,
    :math:`V^c \simeq k_2 \gamma \langle z^2\rangle / (2 \bar z k_0)`: at large V the
    stationary spring stretch at a jump averages the mean residual
    :math:`\langle z^2\rangle/(2\bar z)`, and b = 1 where ``k2 E[1 - x] = k0``.

    Parameters
    ----------
    model : Model
        The model.

    Returns
    -------
    float
        The asymptote; the exact V^c (:func:`micro.critical_velocity`) approaches it as
        :math:`1 - O(k_0)`.

    Raises
    ------
    ValueError
        If ``model`` is not a :class:`Model`.

    Examples
    --------
    >>> import micro
    >>> round(micro.vc_small_k0(micro.Model(k0=0.01)), 6)      # 0.081 / k0
    8.1
    """
    _check_model(model)
    return model.k2 * model.gamma * model.jumps.mean_residual / model.k0


@lru_cache(maxsize=64)
def cached_vc(model: Model) -> float:
    """V^c from the renewal chain (:func:`critical_velocity_renewal`), cached per model: it
    serves every row of a sweep, and a command line's check of its arguments once more."""
    return float(critical_velocity_renewal(model)[0])


@blas_single_threaded
def critical_velocity_renewal(model: Model, *, V_min: float = 1e-4, V_max: float = 1e5, rtol: float = 1e-10,
                              tol: float = 1e-11):
    """V^c as the root of ``b(V) = 1``, the velocity where the branching ratio of steady
    sliding crosses 1 (Brent's method on log V).  ``k0 >= k2`` (or ``k2 = 0``): steady
    sliding is stable at every V (b < 1 already at V -> 0), Vc = 0 at once.
    :func:`micro.critical_velocity` calls it and wraps the result.

    Parameters
    ----------
    model : Model
        The model.
    V_min, V_max : float
        The range searched (default 1e-4 to 1e5), bracketing outward from
        :func:`vc_small_k0`.
    rtol : float
        Relative tolerance of the root (default 1e-10).
    tol : float
        Tolerance of each :func:`steady_sliding` (default 1e-11).

    Returns
    -------
    tuple
        ``(Vc, error, status, message, evaluations)``: status ``'converged'``, ``'no
        stick-slip'`` (k0 >= k2, Vc = 0), ``BELOW`` = ``'V^c below V_min'`` (Vc = 0) or
        ``ABOVE`` = ``'V^c above V_max'`` (Vc = inf); ``evaluations`` is a
        list of dicts ``V, branching_ratio, error``.

    Raises
    ------
    ValueError
        If ``model`` is not a :class:`Model`.
    """
    _check_model(model)
    evaluations: list[dict] = []
    if model.k2 == 0.0 or model.k0 >= model.k2:
        return 0.0, 0.0, "no stick-slip", (
            f"k0 = {model.k0:g} >= k2 = {model.k2:g}: the branching ratio of steady sliding is below 1 at every V "
            f"(its V -> 0 limit is (k1 + k2)/(k0 + k1)), no stick-slip"), evaluations

    def f(log_v: float) -> float:
        # exp(log(V_max)) may round above V_max (1e7 -> 10000000.000000006): clip to the range
        res = steady_sliding(model, min(max(math.exp(log_v), V_min), V_max), tol=tol, growth_rate=False, warn=False)
        evaluations.append({"V": math.exp(log_v), "branching_ratio": float(res.branching_ratio),
                            "error": float(res.branching_error)})
        return float(res.branching_ratio) - 1.0

    guess = min(max(vc_small_k0(model), V_min), V_max)
    lo = hi = math.log(guess)
    f_lo = f_hi = f(lo)
    lmin, lmax = math.log(V_min), math.log(V_max)
    while f_lo <= 0.0:  # still stable: go slower
        if lo <= lmin:
            return 0.0, 0.0, BELOW, (f"steady sliding stable already at V_min = {V_min:g}, while k0 = {model.k0:g} "
                                     f"< k2 = {model.k2:g} (stick-slip below V^c): V^c lies below V_min"), evaluations
        hi, f_hi = lo, f_lo
        lo = max(lo - 1.5, lmin)
        f_lo = f(lo)
    while f_hi > 0.0:  # still unstable: go faster
        if hi >= lmax:
            return math.inf, math.inf, ABOVE, (f"steady sliding unstable still at V_max = {V_max:g}: V^c lies above "
                                               f"V_max"), evaluations
        lo, f_lo = hi, f_hi
        hi = min(hi + 1.5, lmax)
        f_hi = f(hi)
    # no point in locating the root below the noise of b: where the chain cannot reach its
    # tolerance (k1 = 0 at small k0) Brent would bisect that noise for dozens of evaluations
    noise = max(e["error"] for e in evaluations)
    secant = abs(f_hi - f_lo) / (hi - lo)
    xtol = max(1e-14, 0.1 * noise / secant) if secant > 0 else 1e-14
    root = brentq(f, lo, hi, xtol=xtol, rtol=max(rtol, 1e-15))
    Vc = math.exp(root)
    # error: the root moves by (error of b) / |db/dlog V| plus the root finder's tolerance
    h = 1e-4
    slope = (f(root + h) - f(root - h)) / (2 * h)
    err_b = max(e["error"] for e in evaluations[-3:])
    error = Vc * (abs(err_b / slope) + rtol)
    return Vc, error, "converged", f"b(V) = 1 at V = {Vc:.12g} (relative error {error / Vc:.1e})", evaluations
