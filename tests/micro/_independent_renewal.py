r"""An independent reference for steady sliding: sigma(V), the branching ratio b(V) and V^c.

It shares no code with ``micro.renewal`` / ``micro._renewal_kernels``: from ``micro`` it
takes only the parameters (``micro.Model`` and the jump distributions' parameters or,
for ``micro.Tabulated``, the user's ``pdf`` callable).  The equations are derived here
from the model (Landes, Rosso & Jagla 2015, Eqs. 1-3), and discretised differently.

The chain
---------
In steady sliding (mean position moving at V) a block's force is
``F = sigma + a x + k2 e`` (a = k0 + k1; x its lag behind the mean, which grows at rate V;
e = x - u the stretch of its k2 spring, de/dt = V - gamma e, gamma = k2 / eta_u).  It
jumps by z ~ g when its margin ``f_th - F`` reaches 0; a jump lowers x and e by z.
In units where times are scaled by gamma and lengths by V / gamma (zeta = gamma z / V,
t = gamma T) the state just before a jump is the scaled spring deficit
``x = gamma (V/gamma - e) / V`` in [0, 1].  Parametrised by the (scaled) *waiting
time* t to the next jump rather than by the jump zeta, the chain is explicit
(alpha = a / kappa, beta = k2 / kappa, kappa = k0 + k1 + k2):

    D     = (x + alpha t) / (alpha + beta e^{-t})          deficit just after the jump
    zeta  = D - x = [alpha t + beta x (1 - e^{-t})] / (alpha + beta e^{-t})
    x'    = D e^{-t}                                        the next pre-jump state
    dzeta/dt = (alpha + beta x') / (alpha + beta e^{-t})   (> 0: t <-> zeta one to one)

(margin after the jump kappa (V/gamma) zeta, falling as kappa (V/gamma)[alpha t +
beta D (1 - e^{-t})], so the jump zeta that gives the waiting time t solves linearly
for zeta).  So the transition operator is, with g_zeta the density of zeta,

    P f(x) = int_0^inf g_zeta(zeta(x, t)) dzeta/dt(x, t) f(x'(x, t)) dt ,

and the stationary measure pi solves pi P = pi.  Observables (renewal-reward, block
averages = time averages over a cycle):

* stress: sigma = f_th - <margin>_time, <margin> = kappa (V/gamma) E[I] / E[t], with
  I(x, t) = int_0^t margin ds / (kappa V/gamma) = alpha t^2/2 + beta D (1 - (1 + t) e^{-t})
  (all terms positive; <x> = 0 and <u> = 0 in steady sliding);
* branching ratio: blocks reach the threshold at the jump rate V / zbar with margin
  speed V (a + k2 x'), so the density of margins at 0 is E_pi[1/(a + k2 x)] / zbar and
  b = (k1 + k2) zbar p0 = (k1 + k2) E_pi[1/(a + k2 x)];
* a check: stationarity of x forces E_pi[t] = gamma zbar / V exactly (``wait_error``).

Discretisation
--------------
Like micro.renewal this collocates the expectation operator P on one global interpolant
in x and takes the stationary weights as a left null vector (a moment method: only the
smooth functions P f need resolving, not the stationary measure, which is ~zeta_bar wide
at large V).  Everything else differs: micro.renewal uses Chebyshev-Lobatto points on an
affine or sinh map, a composite Gauss rule in z with a Newton solve of the waiting time at
every (node, z), and the system (1/n - Q)^T w = 1/n.  Here:

* x: Gauss-Legendre points in s on a logistic map x(s) clustered exponentially at x = 0
  on the scale alpha/beta (the pole of 1/(a + k2 x) at x = -alpha/beta) and at x = 1 on
  the scale zeta_bar (where the measure sits at large V); barycentric interpolation.
  (Gauss-Legendre *panels* with panel-local interpolation were tried first and fail: for a
  near-identity chain x' stays in its node's panel, the panels decouple and the discrete
  chain has nearly independent stationary states (b 1.7e-6 off at k0 = 0.01, V = 8, and
  erratic under refinement).)
* t: the waiting time is the integration variable (explicit kernel, no root solve at
  the nodes): composite Gauss-Legendre panels per row whose ends are the images of fixed
  z break points (the scale of g and the ends of its support; by bisection on the
  explicit zeta(x, t)) merged with fixed t break points (the relaxation scale 1, unit
  panels up to where x' decays for small alpha).  Rows are normalised to probability 1.
* pi: the left null vector of A = P - I, from the bordered system
  [[A^T, 1], [1^T, 0]] [w; s] = [0; 1], solved by LU with iterative refinement (residuals
  in long double).  Near-identity chains (large V, small alpha) lose everything to
  round-off if P is assembled and I subtracted, so the off-diagonal entries are computed
  from the displacement x' - x = alpha [(1 - x)(1 - e^{-t}) - (1 - (1 + t) e^{-t})] /
  (alpha + beta e^{-t}) (1 - x kept separately at the nodes, a series for small t) and
  the diagonal is minus the off-diagonal row sum.
* b - 1 = E[(k2 (1 - x) - k0)/(a + k2 x)], computed as such: V^c is its root, and
  |db/dlog V| ~ k0/kappa is small at small k0.

Deterministic jumps have no density: the fixed point of the map is closed-form,
x* = zeta/(e^zeta - 1) with t = zeta (from x' = x in the formulas above).

Refinement (``Resolution``): x nodes, t nodes per panel, and a subdivision of every t panel.
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numpy.polynomial.legendre import leggauss
from scipy import integrate, optimize

import micro

__all__ = ["Resolution", "JumpLaw", "jump_law", "steady", "branching_ratio", "branching_excess", "critical_velocity",
           "FastExpansion", "fast_expansion",
           "deterministic_steady", "deterministic_critical_velocity"]


# ------------------------------------------------------------------------------ the jump law
@dataclass(frozen=True)
class JumpLaw:
    """A density of pinning distances on [0, top], normalised, with break points (where it
    or its derivatives may jump) and its mean and second moment (scipy quad)."""

    pdf: object
    top: float
    breaks: tuple
    mean: float
    second: float


def _quad(fun, lo, hi, points):
    inner = [p for p in points if lo < p < hi]
    total = 0.0
    edges = [lo, *inner, hi]
    for a, b in zip(edges[:-1], edges[1:]):
        val, _ = integrate.quad(fun, a, b, epsabs=0.0, epsrel=2e-14, limit=400)
        total += val
    return total


def jump_law(jumps) -> JumpLaw:
    """The continuous density behind a micro jump distribution.

    Exponential: e^{-z/zbar} on [0, cutoff], truncated at 50 zbar (the mass beyond is
    e^-50 = 2e-22).  Tabulated: the user's pdf on [0, support_max] (the density itself,
    not Tabulated's trapezoidal table, whose mean differs at O(h^2)).
    """
    if isinstance(jumps, micro.Exponential):
        zb = float(jumps.zbar)
        top = min(float(jumps.cutoff), 50.0 * zb)

        def raw(z):
            return np.exp(-np.asarray(z, dtype=float) / zb)
        breaks = (0.0, top)
    elif isinstance(jumps, micro.Tabulated):
        top = float(jumps.support_max)
        user = jumps.pdf

        def raw(z):
            z = np.asarray(z, dtype=float)
            return np.asarray(user(z), dtype=float) * ((z >= 0.0) & (z <= top))
        breaks = (0.0, top)
    else:
        raise TypeError(f"no density for {type(jumps).__name__} (deterministic jumps: deterministic_steady)")
    scalar = lambda z: float(raw(np.array([z]))[0])  # noqa: E731
    norm = _quad(scalar, 0.0, top, breaks)
    pdf = lambda z: raw(z) / norm  # noqa: E731
    mean = _quad(lambda z: z * scalar(z) / norm, 0.0, top, breaks)
    second = _quad(lambda z: z * z * scalar(z) / norm, 0.0, top, breaks)
    return JumpLaw(pdf, top, breaks, mean, second)


# ------------------------------------------------------------------------------ small-t series
def _one_minus_one_plus_t_exp(t):
    """q(t) = 1 - (1 + t) e^{-t} = sum_{n>=2} (-1)^n (n - 1) t^n / n!, without cancellation."""
    t = np.asarray(t, dtype=float)
    out = np.empty_like(t)
    small = t < 0.25
    ts = t[small]
    term = ts * ts / 2.0  # n = 2: (n-1) t^n / n! = t^2 / 2
    acc = term.copy()
    power = ts * ts / 2.0  # t^n / n!
    for n in range(3, 24):
        power = power * ts / n
        acc += (-1) ** n * (n - 1) * power
    out[small] = acc
    tl = t[~small]
    out[~small] = -np.expm1(-tl) - tl * np.exp(-tl)
    return out


# ------------------------------------------------------------------------------ the explicit chain
def _zeta(x, t, al, be):
    e = np.exp(-t)
    return (al * t + be * x * (-np.expm1(-t))) / (al + be * e)


def _t_of_zeta(x, target, al, be):
    """Waiting time t with zeta(x, t) = target, elementwise: bisection on the increasing,
    explicit zeta(x, .) in the bracket [0, target/alpha] (zeta >= alpha t), 200 halvings
    (the bracket ends up far below the rounding of t)."""
    x, target = np.broadcast_arrays(np.asarray(x, float), np.asarray(target, float))
    lo = np.zeros(x.shape)
    hi = target / al
    for _ in range(200):
        mid = 0.5 * (lo + hi)
        above = _zeta(x, mid, al, be) >= target
        hi = np.where(above, mid, hi)
        lo = np.where(above, lo, mid)
    return hi


# ------------------------------------------------------------------------------ discretisation
@dataclass(frozen=True)
class Resolution:
    """x: ``nx`` Gauss-Legendre nodes (one global interpolant) per 10 units of the logistic
    map's span u1 - u0 (at least ``nx``: its poles at Im s = pi/(u1 - u0) set the rate);
    t: ``nt`` Gauss nodes per panel, every t panel split in ``split`` equal parts."""

    nx: int = 80
    nt: int = 16
    split: int = 1

    def refined(self) -> "Resolution":
        return Resolution(self.nx + 24, self.nt + 8, 2 * self.split)


def _expit(u):
    return 1.0 / (1.0 + np.exp(-u))


class _XMap:
    """x = (expit(u) - expit(u0)) / (expit(u1) - expit(u0)), u = u0 + (u1 - u0) s, s in [0, 1]:
    a logistic map clustered exponentially at x = 0 on the scale ``left`` (= alpha/beta: the
    pole of 1/(a + k2 x) at x = -alpha/beta, where blocks that waited long arrive) and at
    x = 1 on the scale ``right`` (= zeta_bar: at large V the stationary measure sits within
    a few zeta_bar of x = 1), each only when the scale is below 1/4.  Its own poles are at
    Im u = pi, i.e. Im s = pi / (u1 - u0)."""

    def __init__(self, left: float, right: float):
        self.u0 = math.log(left) if left < 0.25 else -1.0
        self.u1 = -math.log(right) if right < 0.25 else 1.0
        self.p0 = float(_expit(self.u0))
        self.q1 = float(_expit(-self.u1))  # 1 - expit(u1)
        self.span = float(_expit(self.u1)) - self.p0

    def _u(self, s):
        return self.u0 + (self.u1 - self.u0) * s

    def x(self, s):
        return (_expit(self._u(s)) - self.p0) / self.span

    def one_minus_x(self, s):
        return (_expit(-self._u(s)) - self.q1) / self.span

    def ds(self, x, y, dx):
        """s(x + dx) - s(x) accurately for small dx (x and y = 1 - x given)."""
        p = self.p0 + x * self.span  # expit(u)
        q = self.q1 + y * self.span  # 1 - expit(u)
        dp = dx * self.span
        return (np.log1p(dp / p) - np.log1p(-dp / q)) / (self.u1 - self.u0)


def _t_panels(x, law: JumpLaw, V, gamma, al, be, split):
    """Per row (x_i), panel ends in t: images of z break points (scale zbar and the
    support's ends) merged with fixed t break points (scale 1), clipped at t_top(x_i)."""
    zb = law.mean
    rel = np.array([0.125, 0.25, 0.5, 1.0, 1.5, 2.0, 3.0, 4.0, 6.0, 8.0, 12.0, 16.0, 24.0, 32.0, 40.0])
    zb_ends = np.unique(np.concatenate([rel * zb, np.asarray(law.breaks, float)]))
    zb_ends = zb_ends[(zb_ends > 0.0) & (zb_ends <= law.top)]
    zeta_ends = gamma * zb_ends / V
    t_z = _t_of_zeta(np.repeat(x[:, None], zeta_ends.size, 1), np.broadcast_to(zeta_ends, (x.size, zeta_ends.size)),
                     al, be)
    t_top = t_z[:, -1]  # image of the support's end (the largest break point)
    t1 = math.ceil(math.log(max(be / al, 1.0))) + 8
    fixed = np.concatenate([2.0 ** np.arange(-6, 0), np.arange(1.0, t1 + 1.0), t1 * 2.0 ** np.arange(1, 40)])
    ends = np.concatenate([np.zeros((x.size, 1)), t_z, np.broadcast_to(fixed, (x.size, fixed.size))], axis=1)
    ends = np.sort(np.minimum(ends, t_top[:, None]), axis=1)
    keep = int(np.max(np.sum(ends < t_top[:, None], axis=1))) + 1  # the rest are t_top repeated
    ends = ends[:, :keep]
    if split > 1:
        frac = np.arange(split) / split
        a, b = ends[:, :-1], ends[:, 1:]
        ends = np.concatenate([(a[:, :, None] + (b - a)[:, :, None] * frac).reshape(x.size, -1), ends[:, -1:]], 1)
    return ends


@dataclass
class _Solution:
    sigma: float
    b: float
    b_minus_1: float
    wait_error: float
    n_x: int
    n_t: int


def _solve_refined(M, rhs, sweeps: int = 3):
    """LU solve with iterative refinement, residuals in extended precision (x87 long
    double): near-identity chains make M ill-conditioned (||A|| / spectral gap ~ 1e3-1e6)
    and a plain solve leaves ~1e-12 noise in b (1e-8 in V^c at k0 = 1e-4); the entries
    themselves are accurate elementwise, so refining against them removes it."""
    x = np.linalg.solve(M, rhs)
    Ml, rl = M.astype(np.longdouble), rhs.astype(np.longdouble)
    for _ in range(sweeps):
        r = rl - Ml @ x.astype(np.longdouble)
        x = x + np.linalg.solve(M, r.astype(float))
    return x


def _solve(model: micro.Model, V: float, law: JumpLaw, res: Resolution) -> _Solution:
    k0, k1, k2 = model.k0, model.k1, model.k2
    kappa = k0 + k1 + k2
    al, be = (k0 + k1) / kappa, k2 / kappa
    gamma = k2 / model.eta_u
    zeta_bar = gamma * law.mean / V

    # x: Gauss-Legendre nodes in s (s = (1 + xi)/2), barycentric weights of Gauss points
    xmap = _XMap(al / be, zeta_bar)
    nx = math.ceil(res.nx * max(1.0, (xmap.u1 - xmap.u0) / 10.0))
    xi, gwx = leggauss(nx)
    lam = (-1.0) ** np.arange(nx) * np.sqrt((1.0 - xi * xi) * gwx)
    s_nodes = 0.5 * (1.0 + xi)
    x = xmap.x(s_nodes)
    y = xmap.one_minus_x(s_nodes)
    n = x.size

    # quadrature in t, row by row
    tends = _t_panels(x, law, V, gamma, al, be, res.split)
    g, gw = leggauss(res.nt)
    a, b = tends[:, :-1], tends[:, 1:]
    tm, th = 0.5 * (a + b), 0.5 * (b - a)
    t = (tm[:, :, None] + th[:, :, None] * g).reshape(n, -1)
    wq = (th[:, :, None] * gw).reshape(n, -1)
    X, Y = x[:, None], y[:, None]
    e = np.exp(-t)
    den = al + be * e
    zeta = (al * t + be * X * (-np.expm1(-t))) / den
    D = X + zeta
    xp = D * e
    dz = (al + be * xp) / den
    W = wq * (V / gamma) * law.pdf(V * zeta / gamma) * dz
    W = W / W.sum(axis=1, keepdims=True)

    q = _one_minus_one_plus_t_exp(t)
    delta = al * (Y * (-np.expm1(-t)) - q) / den  # x' - x, accurately
    Et = (W * t).sum(axis=1)
    EI = (W * (0.5 * al * t * t + be * D * q)).sum(axis=1)

    # global interpolation at x' = x + delta (barycentric, second form): with
    # xi' - xi_m = (xi_i - xi_m) + 2 (s' - s_i), the off-diagonal weights are accurate
    # however small delta is; the diagonal is minus their row sum (rows of P sum to 1)
    dxi = 2.0 * xmap.ds(X, Y, delta)
    diffs = (xi[:, None, None] - xi[None, None, :]) + dxi[:, :, None]  # (row, q, m)
    diffs[diffs == 0.0] = 1e-150  # x' on a node (never seen): its weight -> 1, the others -> 0
    terms = lam / diffs
    A = np.einsum("iq,iqj->ij", W / terms.sum(axis=2), terms)
    own = np.arange(n)
    A[own, own] = 0.0
    A[own, own] = -A.sum(axis=1)

    M = np.zeros((n + 1, n + 1))
    M[:n, :n] = A.T
    M[:n, n] = 1.0
    M[n, :n] = 1.0
    rhs = np.zeros(n + 1)
    rhs[n] = 1.0
    w = _solve_refined(M, rhs)[:n]

    mean_t = float(w @ Et)
    sigma = model.f_th - kappa * (V / gamma) * float(w @ EI) / mean_t
    # b - 1 = E[(k1 + k2)/(a + k2 x)] - 1 = E[(k2 (1 - x) - k0)/(a + k2 x)]: near V^c at small k0
    # both terms of the numerator are ~k0 and b - 1 is resolved to ~1e-16 k0 instead of 1e-16
    b_minus_1 = float(w @ ((k2 * y - k0) / (k0 + k1 + k2 * x)))
    return _Solution(sigma, 1.0 + b_minus_1, b_minus_1, mean_t / zeta_bar - 1.0, n, t.shape[1])


def _no_dashpot(model):
    return model.k2 == 0.0


def steady(model: micro.Model, V: float, res: Resolution = Resolution(), law: JumpLaw | None = None) -> _Solution:
    """sigma, b and the waiting-time check of steady sliding at V (one model, one V)."""
    if isinstance(model.jumps, micro.Deterministic):
        sigma, b = deterministic_steady(model, V)
        return _Solution(sigma, b, b - 1.0, 0.0, 1, 1)
    law = law if law is not None else jump_law(model.jumps)
    if _no_dashpot(model):
        resid = law.second / (2.0 * law.mean)
        b = model.k1 / (model.k0 + model.k1)
        return _Solution(model.f_th - (model.k0 + model.k1) * resid, b, b - 1.0, 0.0, 0, 0)
    return _solve(model, float(V), law, res)


def branching_ratio(model: micro.Model, V: float, res: Resolution = Resolution(), law: JumpLaw | None = None) -> float:
    return steady(model, V, res, law).b


def branching_excess(model: micro.Model, V: float, res: Resolution = Resolution(), law: JumpLaw | None = None) -> float:
    """b(V) - 1, computed as such (see _solve)."""
    return steady(model, V, res, law).b_minus_1


def critical_velocity(model: micro.Model, res: Resolution = Resolution(), *, rtol: float = 1e-14) -> float:
    """V^c, the root of b(V) = 1 (b decreases in V), on log V: secant steps from the
    large-V estimate k2 gamma <z^2> / (2 zbar k0) until b - 1 changes sign, then Brent's
    method in that bracket; 0 when k0 >= k2 (b(V -> 0) = (k1 + k2)/(k0 + k1) <= 1: no
    stick-slip).  b - 1 itself is resolved to ~1e-16 k0 (see _solve)."""
    if isinstance(model.jumps, micro.Deterministic):
        return deterministic_critical_velocity(model)
    if model.k2 == 0.0 or model.k0 >= model.k2:
        return 0.0
    law = jump_law(model.jumps)
    gamma = model.k2 / model.eta_u
    guess = model.k2 * gamma * law.second / (2.0 * law.mean * model.k0)  # b = 1 at large V (own estimate)
    seen: dict[float, float] = {}

    def f(lv: float) -> float:
        if lv not in seen:
            seen[lv] = branching_excess(model, math.exp(lv), res, law)
        return seen[lv]

    x0, x1 = math.log(guess), math.log(guess) - 0.05
    for _ in range(60):
        f0, f1 = f(x0), f(x1)
        if f0 == 0.0 or f1 == 0.0:
            return math.exp(x0 if f0 == 0.0 else x1)
        if (f0 > 0.0) != (f1 > 0.0):
            lv = optimize.brentq(f, min(x0, x1), max(x0, x1), xtol=1e-300, rtol=rtol)
            return math.exp(lv)
        x2 = x1 - f1 * (x1 - x0) / (f1 - f0) if f1 != f0 else x1 + (x1 - x0)
        x2 = min(max(x2, x1 - 1.0), x1 + 1.0)  # at most a factor e per step
        # overshoot a little, towards where b - 1 changes sign (b falls as V rises), so that the
        # next pair brackets the root: by at least 1e-10 in log V, because the secant can also
        # converge onto the root from one side (k0 = 0.4375, k1 = 0, k2 = 0.5, zbar = 0.25: b - 1
        # = -4e-17, -8e-18, then no step at all and "no sign change" after 60 iterations)
        x2 += (1.0 if f1 > 0.0 else -1.0) * max(1e-9 * abs(x2 - x1), 1e-10)
        x0, x1 = x1, x2
    raise RuntimeError("critical_velocity: no sign change of b - 1 found")  # pragma: no cover


# ------------------------------------------------------------------------------ deterministic jumps
def deterministic_steady(model: micro.Model, V: float) -> tuple[float, float]:
    """Closed form for g = delta(z - zbar): the map's fixed point has t = zeta,
    x* = zeta / (e^zeta - 1); returns (sigma, b)."""
    k0, k1, k2 = model.k0, model.k1, model.k2
    kappa = k0 + k1 + k2
    al, be = (k0 + k1) / kappa, k2 / kappa
    gamma = k2 / model.eta_u
    zeta = gamma * model.jumps.zbar / V
    xs = zeta * math.exp(-zeta) / -math.expm1(-zeta)  # zeta / (e^zeta - 1), no overflow at large zeta
    D = xs + zeta
    q = float(_one_minus_one_plus_t_exp(np.array([zeta]))[0])
    integral = 0.5 * al * zeta * zeta + be * D * q
    sigma = model.f_th - kappa * (V / gamma) * integral / zeta
    return sigma, (k1 + k2) / (k0 + k1 + k2 * xs)


def deterministic_critical_velocity(model: micro.Model) -> float:
    """b = 1 where k0 + k1 + k2 x* = k1 + k2, i.e. x* = zeta / (e^zeta - 1) = 1 - k0/k2:
    V^c = gamma zbar / zeta."""
    if model.k2 == 0.0 or model.k0 >= model.k2:
        return 0.0
    r = 1.0 - model.k0 / model.k2
    # s / (e^s - 1) = s e^-s / (1 - e^-s), decreasing from 1 (s -> 0) to 0
    zeta = optimize.brentq(lambda s: s * math.exp(-s) / -math.expm1(-s) - r, 1e-300, 1e3, xtol=1e-300, rtol=1e-15)
    return (model.k2 / model.eta_u) * model.jumps.zbar / zeta


# ------------------------------------------------------------------------------ the large-V expansion
@dataclass(frozen=True)
class FastExpansion:
    """sigma and b to O(V^-2): ``sigma_terms`` and ``b_terms`` are the V^0, V^-1 and V^-2
    terms (their sums are ``sigma`` and ``b``); the remainder is O(V^-3)."""

    sigma: float
    b: float
    sigma_terms: tuple
    b_terms: tuple


def fast_expansion(model: micro.Model, V: float) -> FastExpansion:
    r"""Steady sliding at large V from the model's equations, not from any chain
    (derivation: docs/reference/micro_renewal.md, section 6).

    With eps = gamma / V (gamma = k2 / eta_u), R the equilibrium residual of g (density
    (1 - G(r)) / zbar: <R^k> = <z^(k+1)> / ((k + 1) zbar)), Var(R) and mu3(R) its variance and
    third central moment, and S = Var(z^2/2 - <R> z):

        sigma = f_th - kappa <R> + k2 eps Var(R) + k2 eps^2 [alpha S / (2 zbar) - mu3(R)] + O(eps^3)
        b     = b0 [1 + beta eps <R> + beta eps^2 (beta <R>^2 - Var(R))] + O(eps^3),  b0 = (k1 + k2)/kappa

    (alpha = (k0 + k1)/kappa, beta = k2/kappa).  The moments of g come from quad on its
    density (deterministic jumps: zbar^k).
    """
    if isinstance(model.jumps, micro.Deterministic):
        zb = float(model.jumps.zbar)
        m1, m2, m3, m4 = zb, zb**2, zb**3, zb**4
    else:
        law = jump_law(model.jumps)
        scalar = lambda z: float(law.pdf(np.array([z]))[0])  # noqa: E731
        m1, m2 = law.mean, law.second
        m3 = _quad(lambda z: z**3 * scalar(z), 0.0, law.top, law.breaks)
        m4 = _quad(lambda z: z**4 * scalar(z), 0.0, law.top, law.breaks)
    k0, k1, k2 = model.k0, model.k1, model.k2
    kappa = k0 + k1 + k2
    alpha, beta = (k0 + k1) / kappa, k2 / kappa
    eps = (k2 / model.eta_u) / float(V)
    r1, r2, r3 = m2 / (2.0 * m1), m3 / (3.0 * m1), m4 / (4.0 * m1)  # <R>, <R^2>, <R^3>
    var = r2 - r1 * r1
    mu3 = r3 - 3.0 * r1 * r2 + 2.0 * r1**3
    S = m4 / 4.0 - r1 * m3 + r1 * r1 * m2
    sigma_terms = (model.f_th - kappa * r1, k2 * eps * var, k2 * eps**2 * (alpha * S / (2.0 * m1) - mu3))
    b0 = (k1 + k2) / kappa
    b_terms = (b0, b0 * beta * eps * r1, b0 * beta * eps**2 * (beta * r1 * r1 - var))
    return FastExpansion(sum(sigma_terms), sum(b_terms), sigma_terms, b_terms)
