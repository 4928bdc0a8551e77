r"""A reference for the :math:`a = 0` model that needs no ODE integrator.

Independent of the solver (no numba kernels, no CVODE): it uses only the laws' numpy
methods and scipy's ``brentq`` and ``quad``.

* stick: closed form, :math:`\theta = \theta_0 + t`, :math:`\sigma = \sigma_0 + k_0 V t`;
  its end is the root of :math:`h(t) = \sigma_0 + k_0 V t - \phi(\theta_0 + t)`;
* slip: :math:`g(s) = \sigma_0 - K s - \phi(\theta_0 e^{-s})`, first root after the
  over-stressed hump;
* slide: the constraint :math:`\sigma = \phi(\theta)` reduces Eqs. (8), (11), (12) to a
  one-dimensional quadrature.  With :math:`u = D_c/\theta` and
  :math:`\rho = \ln u`,

  .. math:: t = \int \frac{D_c\,D(e^\rho)}{K\,(V - e^\rho)}\,\mathrm{d}\rho,
            \qquad D(u) = K - W(u),

  and the slide ends where :math:`D = 0` (slip) or :math:`N = KV - uW = 0` (stick).

Threshold differences are computed as :math:`\phi(\theta_b) - \phi(\theta_a) =
\int W\,\mathrm{d}\ln\theta` by ``quad``, so that they keep full precision.  The root
brackets assume that :math:`W(v)` has a single maximum in :math:`\ln v` and that
:math:`\phi` is concave in :math:`\theta` (true for Eqs. 4 and 10; :func:`check_assumptions`
tests it), which makes each root unique in its bracket.

:func:`reference_cycle` finds the limit cycle as the fixed point of the map from one slip
landing to the next.
"""
from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np
from scipy.integrate import quad
from scipy.optimize import brentq

from .params import SpringSlider

__all__ = ["ReferenceCycle", "reference_cycle", "cycle_map", "check_assumptions"]

_RHO_MAX = 690.0      # ln u beyond which W is taken as 0 (u = e^690)
_QUAD = dict(epsabs=1e-16, epsrel=1e-13, limit=400)


def _u(rho: float) -> float:
    return math.exp(min(rho, _RHO_MAX))


class _Model:
    """Scalar helpers for one (model, V)."""

    def __init__(self, model: SpringSlider, V: float) -> None:
        self.law = model.law
        self.k0 = model.k0
        self.Dc = model.Dc
        self.K = model.K
        self.V = V

    def W(self, u: float) -> float:
        if u <= 0.0:
            return 0.0
        return float(self.law.weakening(np.array([u]))[0])

    def mu(self, u: float) -> float:
        return float(self.law.mu_ss(np.array([u]))[0])

    def phi(self, theta: float) -> float:
        return self.mu(self.Dc / theta)

    def dphi_rho(self, rho_a: float, rho_b: float) -> float:
        r""":math:`\phi` at :math:`u = e^{\rho_b}` minus :math:`\phi` at :math:`e^{\rho_a}`:
        :math:`-\int_{\rho_a}^{\rho_b} W(e^\rho)\,\mathrm{d}\rho` (since
        :math:`\mathrm{d}\mu_{ss}/\mathrm{d}\ln u = -W`)."""
        lo, hi = min(rho_a, _RHO_MAX), min(rho_b, _RHO_MAX)
        if lo == hi:
            return 0.0
        val, _ = quad(lambda r: self.W(math.exp(r)), lo, hi, **_QUAD)
        return -val

    def N(self, u: float) -> float:
        return self.K * self.V - u * self.W(u)

    def D(self, u: float) -> float:
        return self.K - self.W(u)


@dataclass
class _Segment:
    kind: str
    duration: float
    integral: float          # of sigma dt
    sigma_start: float
    sigma_end: float
    theta_end: float


def _stick(m: _Model, rho0: float, sigma0_minus_phi0: float, sigma0: float) -> _Segment:
    """Stick from u0 = e^rho0 (theta0 = Dc/u0) with gap sigma0 - phi(theta0) <= 0."""
    theta0 = m.Dc * math.exp(-rho0)
    k0V = m.k0 * m.V

    def h(log_ratio: float) -> float:
        # log_ratio = ln(theta/theta0) >= 0; phi(theta) - phi(theta0) = dphi in rho
        t = theta0 * math.expm1(log_ratio)
        return sigma0_minus_phi0 + k0V * t - m.dphi_rho(rho0, rho0 - log_ratio)

    # the threshold never exceeds mu_ss(0+): sigma passes it by t_up
    phi_sup = m.mu(0.0) if np.isfinite(m.mu(0.0)) else None
    lo = 1e-9
    while h(lo) >= 0.0 and lo < 1.0:
        lo *= 10.0
    if phi_sup is not None:
        t_up = (phi_sup - sigma0) / k0V
        hi = math.log1p(max(t_up, 0.0) / theta0) + 1e-3
    else:
        hi = 1.0
    while h(hi) < 0.0:
        hi = 2.0 * hi + 1.0
    r = brentq(h, lo, hi, xtol=1e-15, rtol=8.9e-16, maxiter=500)
    t = theta0 * math.expm1(r)
    sigma_end = sigma0 + k0V * t
    return _Segment("stick", t, 0.5 * (sigma0 + sigma_end) * t, sigma0, sigma_end, theta0 * math.exp(r))


def _slip(m: _Model, rho0: float, sigma0: float, gap0: float) -> tuple[float, float]:
    """Slip from u0 = e^rho0 with gap sigma0 - phi >= 0; returns (rho_end, sigma_end)."""

    def g(s: float) -> float:
        return gap0 - m.K * s - m.dphi_rho(rho0, rho0 + s)

    # g rises while W > K (u inside the unstable band), then falls: bracket after the hump
    s_peak = 0.0
    r = rho0 + 1e-7
    if m.W(_u(r)) > m.K:
        hi = r + 0.5
        while m.W(_u(hi)) > m.K:
            r = hi
            hi += 0.5
        s_peak = brentq(lambda x: m.W(_u(x)) - m.K, r, hi, xtol=1e-15) - rho0
    lo = max(s_peak, 1e-9)
    if g(lo) <= 0.0:
        raise RuntimeError("reference slip: not over-stressed after the hump")
    hi = lo + 1.0
    while g(hi) > 0.0:
        hi = lo + 2.0 * (hi - lo)
    s = brentq(g, lo, hi, xtol=1e-15, rtol=8.9e-16, maxiter=500)
    return rho0 + s, sigma0 - m.K * s


def _slide(m: _Model, rho0: float) -> tuple[_Segment | None, float, str]:
    """Slide from u0 = e^rho0 (on the threshold).  Returns (segment, rho_end, next) with
    next 'slip', 'stick' or 'steady' (segment None for steady)."""
    rhoV = math.log(m.V)
    if rho0 == rhoV:
        return None, rho0, "steady"
    grid = np.linspace(rho0, rhoV, 4001)[1:]
    end = None
    nxt = "steady"
    prev = rho0
    for r in grid:
        u = math.exp(r)
        if m.D(u) <= 0.0:
            end = brentq(lambda x: m.D(math.exp(x)), prev, r, xtol=1e-15, rtol=8.9e-16)
            nxt = "slip"
            break
        if m.N(u) <= 0.0:
            end = brentq(lambda x: m.N(math.exp(x)), prev, r, xtol=1e-15, rtol=8.9e-16)
            nxt = "stick"
            break
        prev = r
    if end is None:
        return None, rhoV, "steady"

    def dt(r: float) -> float:
        u = math.exp(r)
        return m.Dc * m.D(u) / (m.K * (m.V - u))

    duration, _ = quad(dt, rho0, end, **_QUAD)
    integral, _ = quad(lambda r: dt(r) * m.mu(math.exp(r)), rho0, end, **_QUAD)
    theta_end = m.Dc * math.exp(-end)
    seg = _Segment("slide", abs(duration), abs(integral), m.phi(m.Dc * math.exp(-rho0)),
                   m.phi(theta_end), theta_end)
    return seg, end, nxt


@dataclass
class ReferenceCycle:
    r"""One cycle from a slip landing to the next, or steady sliding.

    Attributes
    ----------
    regime : str
        ``'stick-slip'`` or ``'steady'``.
    sigma_max, sigma_min, sigma_mean : float
        Extrema and time average of the friction over the cycle.
    period : float
        Its duration.
    sequence : tuple of str
        Its phase switches, as :attr:`rsf.CycleResult.sequence`.
    theta_landing, theta_next : float
        The state at the landing it starts from and at the next landing.
    fixed_point_residual : float
        :math:`\ln\theta_{next} - \ln\theta_{landing}` at the end of
        :func:`reference_cycle`'s iteration (nan for one map step).
    extras : dict
        Unused by rsf itself (empty).
    """

    regime: str
    sigma_max: float
    sigma_min: float
    sigma_mean: float
    period: float
    sequence: tuple[str, ...]
    theta_landing: float
    theta_next: float = math.nan
    fixed_point_residual: float = math.nan
    extras: dict = field(default_factory=dict)


def cycle_map(model: SpringSlider, V: float, theta_landing: float) -> ReferenceCycle:
    """Follow the motion from a point on the threshold (a slip landing at
    ``theta_landing``) to the next slip landing."""
    m = _Model(model, V)
    rho = math.log(m.Dc / theta_landing)
    sigma = m.phi(theta_landing)
    sigmas = [sigma]
    period = 0.0
    integral = 0.0
    seq: list[str] = []
    state = "threshold"
    for _ in range(20):
        u = _u(rho)
        if state == "threshold":
            n, d = m.N(u), m.D(u)
            state = "stick" if n < 0.0 else ("slide" if d > 0.0 else "slip")
            continue
        if state == "stick":
            seg = _stick(m, rho, 0.0, sigma)
            period += seg.duration
            integral += seg.integral
            sigma = seg.sigma_end
            sigmas.append(sigma)
            rho = math.log(m.Dc / seg.theta_end)
            u = _u(rho)
            nxt = "slide" if m.D(u) > 0.0 else "slip"
            seq.append(f"stick->{nxt}")
            state = nxt
        elif state == "slide":
            seg, rho, nxt = _slide(m, rho)
            if seg is None:
                mu = m.mu(V)
                return ReferenceCycle("steady", mu, mu, mu, math.nan, tuple(seq), theta_landing)
            period += seg.duration
            integral += seg.integral
            sigma = seg.sigma_end
            sigmas.append(sigma)
            seq.append(f"slide->{nxt}")
            state = nxt
        else:  # slip
            gap = sigma - m.mu(_u(rho))
            rho, sigma = _slip(m, rho, sigma, max(gap, 0.0))
            sigmas.append(sigma)
            n = m.N(_u(rho))
            nxt = "stick" if n < 0.0 else "slide"
            seq.append(f"slip->{nxt}")
            theta_next = m.Dc * math.exp(-rho) if rho < _RHO_MAX else 0.0
            mean = integral / period if period > 0.0 else math.nan
            return ReferenceCycle("stick-slip", max(sigmas), min(sigmas), mean, period,
                                  tuple(seq), theta_landing, theta_next)
    raise RuntimeError("reference: no slip within 20 phases")


def reference_cycle(model: SpringSlider, V: float, theta_landing: float | None = None,
                    tol: float = 1e-14, max_iter: int = 200) -> ReferenceCycle:
    r"""The limit cycle at velocity ``V`` as the fixed point of :func:`cycle_map`
    (the landing state :math:`\ln\theta_L` maps to the next landing).

    Starts from ``theta_landing`` (default: the landing after the first slip from 5 %
    above the steady state), iterates the map, then solves :math:`P(x) = x` by the secant
    method until the residual is below ``tol``.

    Parameters
    ----------
    model : SpringSlider
        A model without direct effect (:math:`a = 0`) whose law meets the shape
        assumptions of the module docstring (:func:`check_assumptions`).
    V : float
        Driving velocity, > 0.
    theta_landing : float, optional
        The state at a slip landing to start from.
    tol : float
        Residual of the fixed point in :math:`\ln\theta`, relative to
        :math:`\max(1, |\ln\theta|)` (default 1e-14).
    max_iter : int
        Secant steps at most (default 200); the last residual is returned either way.

    Returns
    -------
    ReferenceCycle
        The cycle (or ``regime='steady'`` if the motion settles into steady sliding), with
        its ``fixed_point_residual``.

    Raises
    ------
    ValueError
        If the model has a direct effect :math:`a > 0`.

    Examples
    --------
    >>> import rsf
    >>> ref = rsf.reference_cycle(rsf.SpringSlider(k0=0.1), 0.05)
    >>> ref.regime, round(ref.sigma_max, 6), round(ref.period, 4)
    ('stick-slip', 1.030897, 17.3286)
    """
    if model.a != 0.0:
        raise ValueError("the reference covers the a = 0 model only")
    m = _Model(model, V)
    if theta_landing is None:
        # first slip landing from 5 % above the steady state
        theta0 = m.Dc / V * 1.05
        first = cycle_map(model, V, theta0)
        if first.regime == "steady":
            return first
        theta_landing = first.theta_next
    floor = 1e-250 * m.Dc

    def P(x: float) -> tuple[float, ReferenceCycle]:
        theta = max(math.exp(x), floor)
        cyc = cycle_map(model, V, theta)
        if cyc.regime == "steady":
            return math.nan, cyc
        return math.log(max(cyc.theta_next, floor)), cyc

    x0 = math.log(max(theta_landing, floor))
    x1, cyc = P(x0)
    if math.isnan(x1):
        return cyc
    for _ in range(3):
        x0, (x1, cyc) = x1, P(x1)
        if math.isnan(x1):
            return cyc
    f0 = x1 - x0
    xa, fa = x0, f0
    xb = x1
    for _ in range(max_iter):
        xn, cyc = P(xb)
        fb = xn - xb
        if abs(fb) <= tol * max(1.0, abs(xb)):
            cyc.fixed_point_residual = fb
            return cyc
        if fb == fa:
            xa, fa, xb = xb, fb, xn
            continue
        xa, fa, xb = xb, fb, xb - fb * (xb - xa) / (fb - fa)
    cyc.fixed_point_residual = fb
    return cyc


def check_assumptions(model: SpringSlider, v_min: float = 1e-12, v_max: float = 1e12) -> dict[str, bool]:
    """Check the two shape assumptions of the reference on a grid: W(v) has a single
    maximum in ln v, and phi(theta) = mu_ss(Dc/theta) is concave in theta, which holds iff
    v W(v) is non-decreasing (phi'(theta) = u W(u)/Dc with u = Dc/theta)."""
    v = np.geomspace(v_min, v_max, 4001)
    w = model.law.weakening(v)
    dw = np.diff(w)
    big = np.abs(dw) > 1e-12 * np.max(np.abs(w))
    sign_changes = int(np.sum(np.diff(np.sign(dw[big])) != 0))
    vw = v * w
    return {"unimodal_W": sign_changes <= 1,
            "concave_phi": bool(np.all(np.diff(vw) >= -1e-12 * np.max(np.abs(vw))))}
