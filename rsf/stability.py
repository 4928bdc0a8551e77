r"""Linear stability of steady sliding: the Jacobian, the stability margin and the critical
velocity (``docs/reference/rsf.md`` has the derivation).  Linearising the spring-slider about
steady sliding at :math:`V` (:math:`\theta = D_c/V`) gives, for the aging law (Eq. 8),
any direct effect :math:`a \ge 0` and the slip law alike, a trace proportional to
:math:`W(V) - k_0 D_c` with :math:`W(V) = -V\,\mathrm{d}\mu_{ss}/\mathrm{d}V`: steady sliding
is unstable where

.. math:: k_0 D_c < -V \frac{\mathrm{d}\mu_{ss}}{\mathrm{d}V}.

For Eq. (10), :math:`W(V) = AV/(V+B)^2` and the boundary :math:`k_0 D_c (V+B)^2 = AV` is the
quadratic :math:`K V^2 + (2KB - A)V + KB^2 = 0` (:math:`K = k_0 D_c`) with roots

.. math:: V_\pm = \frac{A - 2KB \pm \sqrt{A(A - 4KB)}}{2K}, \qquad V_+ V_- = B^2 .

Real roots need :math:`K \le A/(4B)`.  :math:`V_+ = V^c` is the critical velocity of the
paper: steady sliding is stable above it.  :math:`V_-` is the lower end of the unstable
band: below it steady sliding is linearly stable again.
"""
from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np
import pandas as pd
from scipy.optimize import brentq

from ._validation import positive
from .laws import HyperbolicLaw, LogLaw, SteadyStateLaw
from .params import SpringSlider
from .state_laws import NAGATA, USER

__all__ = ["CriticalVelocity", "critical_velocity", "steady_jacobian", "stability_margin"]


@dataclass(frozen=True)
class CriticalVelocity:
    """Result of :func:`critical_velocity`.

    Attributes
    ----------
    k0, Dc : float
        Driving stiffness and critical slip distance of the model.
    Vc : float
        The critical velocity: the largest V at which steady sliding turns unstable as V
        decreases (``inf`` if it is unstable at all large V, ``nan`` if it is stable at every
        V).
    V_lower : float
        Lower end of the unstable band containing Vc (0 if the band reaches V -> 0, nan if
        there is no band).
    roots : tuple of float
        Every V > 0 with k0 Dc = W(V), ascending.
    unstable : tuple of (float, float)
        The intervals of V where steady sliding is linearly unstable.
    method : str
        'quadratic' (closed form for Eq. 10), 'constant W' (the log law, whose weakening
        does not depend on V) or 'scan' (roots bracketed on a log grid).
    params : dict
        Unused by rsf itself (empty); not compared.
    """

    k0: float
    Dc: float
    Vc: float
    V_lower: float
    roots: tuple[float, ...] = ()
    unstable: tuple[tuple[float, float], ...] = ()
    method: str = "scan"
    params: dict = field(default_factory=dict, compare=False)

    @property
    def K(self) -> float:
        return self.k0 * self.Dc

    def is_stable(self, V: float) -> bool:
        """Whether steady sliding at V is linearly stable."""
        return not any(lo < V < hi for lo, hi in self.unstable)

    @property
    def status(self) -> str:
        """``'unstable band'``, ``'stable at every V'`` (Vc is nan: k0 Dc exceeds the largest
        -V dmu_ss/dV) or ``'unstable at large V'`` (Vc is inf)."""
        if math.isnan(self.Vc):
            return "stable at every V"
        return "unstable at large V" if math.isinf(self.Vc) else "unstable band"

    def to_frame(self) -> pd.DataFrame:
        """One row: k0, Dc, Vc, V_lower, method, status."""
        return pd.DataFrame([{"k0": self.k0, "Dc": self.Dc, "Vc": self.Vc,
                              "V_lower": self.V_lower, "method": self.method, "status": self.status}])


def steady_jacobian(model: SpringSlider, V: float) -> np.ndarray:
    r"""Jacobian of the spring-slider linearised about steady sliding at ``V``, for
    :math:`a > 0`, in the relative perturbations :math:`\xi = \delta v/V`,
    :math:`\psi = \delta\theta/\theta` and the time :math:`\tau = Vt/D_c`
    (``docs/reference/rsf.md``, "Radiation damping"):

    .. math::
        \frac{\mathrm{d}}{\mathrm{d}\tau}\begin{pmatrix}\xi\\ \psi\end{pmatrix}
        = \frac{1}{a + \eta V}\begin{pmatrix} W + a - K & W + a\\
          -(a + \eta V) & -(a + \eta V)\end{pmatrix}
          \begin{pmatrix}\xi\\ \psi\end{pmatrix}

    (with a second state variable a 3 x 3 matrix, :func:`_two_state_jacobian`)
    for the aging, slip and PRZ laws (they share the linearisation
    :math:`\psi_\tau = -(\xi + \psi)`), with :math:`K = k_0 D_c`,
    :math:`W = W(V)` and :math:`\eta = \eta_{rad}`: trace
    :math:`(W - K - \eta V)/(a + \eta V)`, determinant :math:`K/(a + \eta V) > 0`.  The
    Nagata law adds :math:`(c/b)(K\xi + \eta V\xi_\tau)` to :math:`\psi_\tau`.  For a
    user law :math:`\psi_\tau = p\,\xi + q\,\psi` with :math:`p, q` the logarithmic
    derivatives of :math:`(D_c/V)\,\dot\theta/\theta` (central differences of the
    user's function), and the first row becomes
    :math:`(-K - (W + a)p,\; -(W + a)q)/(a + \eta V)`.
    """
    V = positive("V", V)
    if model.a == 0.0:
        raise ValueError("steady_jacobian needs a direct effect a > 0")
    if model.second_state is not None:
        return _two_state_jacobian(model, V)
    if model.state.code == USER:
        return _user_jacobian(model, V)
    K = model.K
    a = model.a
    W = float(model.law.weakening(np.array([V]))[0])
    damp = model.eta_rad * V
    Wa = W + a
    kappa = 0.0
    if model.state.code == NAGATA:
        b = model.state.b if model.state.b is not None else model.law.b
        kappa = model.state.c / b
    D = a + damp * (1.0 + Wa * kappa)
    j11 = (Wa - K * (1.0 + Wa * kappa)) / D
    j12 = Wa / D
    j21 = -1.0 + kappa * K + kappa * damp * j11
    j22 = -1.0 + kappa * damp * j12
    return np.array([[j11, j12], [j21, j22]])


def _two_state_jacobian(model: SpringSlider, V: float) -> np.ndarray:
    r"""3 x 3 Jacobian in :math:`(\xi, \psi_1, \psi_2)` for a second state variable:
    :math:`\psi_{2,\tau} = -\rho(\xi + \psi_2)` with :math:`\rho = D_c/D_{c2}`, and
    :math:`(a + \eta V)\xi_\tau = -K\xi + (W + a)(\xi + \psi_1) + b_2\rho(\xi + \psi_2)`."""
    rho = model.Dc / model.second_state.Dc2
    b2 = model.second_state.b2
    W = float(model.law.weakening(np.array([V]))[0])
    Wa = W + model.a
    D = model.a + model.eta_rad * V
    return np.array([[(-model.K + Wa + b2 * rho) / D, Wa / D, b2 * rho / D],
                     [-1.0, -1.0, 0.0],
                     [-rho, 0.0, -rho]])


def _user_jacobian(model: SpringSlider, V: float) -> np.ndarray:
    Dc = model.Dc
    theta = Dc / V
    func = model.state.func

    def g(lv: float, lth: float) -> float:       # (Dc / V) d ln(theta)/dt
        th = math.exp(lth)
        return Dc / V * float(func(math.exp(lv), th)) / th

    h = 1e-6
    lv, lth = math.log(V), math.log(theta)
    p = (g(lv + h, lth) - g(lv - h, lth)) / (2 * h)
    q = (g(lv, lth + h) - g(lv, lth - h)) / (2 * h)
    W = float(model.law.weakening(np.array([V]))[0])
    D = model.a + model.eta_rad * V
    Wa = W + model.a
    return np.array([[(-model.K - Wa * p) / D, -Wa * q / D], [p, q]])


def stability_margin(model: SpringSlider, V: float) -> float:
    r"""Positive where steady sliding at ``V`` is linearly unstable, negative where it is
    stable, zero at the Hopf bifurcation: :math:`W(V) - k_0 D_c - \eta_{rad}V` (the
    trace of :func:`steady_jacobian` times :math:`a + \eta V`) for the aging, slip and
    PRZ laws and for :math:`a = 0`; the trace of the Jacobian for the Nagata and user laws
    when its determinant is positive (a saddle, determinant < 0, counts as unstable); the
    largest real part of the eigenvalues with a second state variable."""
    if model.second_state is not None:
        return float(np.max(np.linalg.eigvals(steady_jacobian(model, V)).real))
    if model.state.code in (NAGATA, USER) and model.a > 0.0:
        J = steady_jacobian(model, V)
        det = float(np.linalg.det(J))
        return float(np.trace(J)) if det > 0.0 else abs(det) + 1e-300   # a saddle: unstable
    W = float(model.law.weakening(np.array([V]))[0])
    return W - model.K - model.eta_rad * V


def critical_velocity(law: SteadyStateLaw | None = None, k0: float = 0.01, Dc: float = 0.06, *,
                      v_min: float = 1e-12, v_max: float = 1e12) -> CriticalVelocity:
    r"""Where steady sliding loses stability: the roots of :math:`k_0 D_c = W(V)`, or with
    radiation damping :math:`\eta_{rad}` (a :class:`~rsf.params.SpringSlider` given) of
    :math:`k_0 D_c + \eta_{rad} V = W(V)`; for the Nagata law the zeros of the trace of
    :func:`steady_jacobian`.

    Parameters
    ----------
    law : SteadyStateLaw, optional
        Default: the paper's Eq. (10).  (Also accepts a :class:`~rsf.params.SpringSlider`
        as first argument, whose law, k0, Dc, state law and eta_rad are then used.)
    k0, Dc : float
        Driving stiffness and critical slip distance, > 0.
    v_min, v_max : float
        Range scanned for roots of a general law (ignored for the closed forms), > 0 with
        ``v_max > v_min``.

    Returns
    -------
    CriticalVelocity
        ``Vc`` (nan if steady sliding is stable at every V, inf if unstable at all large
        V), the lower end of its unstable band, every root and the unstable intervals.

    Raises
    ------
    ValueError
        If ``law`` is neither a steady-state law nor a spring-slider, ``k0``, ``Dc``,
        ``v_min`` or ``v_max`` is not a finite number > 0, ``v_max <= v_min``, or the
        default ``mu_inf`` of Eq. (10) is negative at ``k0`` (k0 >= 19).

    Examples
    --------
    >>> import rsf
    >>> cv = rsf.critical_velocity(k0=0.1, Dc=0.06)
    >>> round(cv.Vc, 4), round(cv.V_lower, 4)
    (1.0046, 0.0061)
    """
    if isinstance(law, SpringSlider):
        model = law
        if (model.eta_rad > 0.0 or model.second_state is not None
                or (model.state.code in (NAGATA, USER) and model.a > 0.0)):
            return _critical_velocity_scan(model, v_min, v_max)
        law, k0, Dc = model.law, model.k0, model.Dc
    if law is None:
        law = HyperbolicLaw()
    if not isinstance(law, SteadyStateLaw):
        raise ValueError(f"law must be a SteadyStateLaw, got {law!r}")
    k0 = positive("k0", k0)
    Dc = positive("Dc", Dc)
    v_min = positive("v_min", v_min)
    v_max = positive("v_max", v_max)
    if v_max <= v_min:
        raise ValueError(f"v_max must be > v_min = {v_min!r}, got {v_max!r}")
    law = law.bind(k0)
    K = k0 * Dc
    if isinstance(law, HyperbolicLaw):
        A, B = law.A, law.B
        disc = A * (A - 4.0 * K * B)
        if disc < 0.0 or A == 0.0:
            return CriticalVelocity(k0, Dc, math.nan, math.nan, (), (), "quadratic")
        v_plus = (A - 2.0 * K * B + math.sqrt(disc)) / (2.0 * K)
        v_minus = B * B / v_plus
        roots = (v_minus, v_plus) if v_minus < v_plus else (v_plus,)
        unstable = ((v_minus, v_plus),) if v_minus < v_plus else ()
        return CriticalVelocity(k0, Dc, v_plus, v_minus, roots, unstable, "quadratic")
    if isinstance(law, LogLaw):
        w = law.b - law.a
        if w > K:
            return CriticalVelocity(k0, Dc, math.inf, 0.0, (), ((0.0, math.inf),), "constant W")
        return CriticalVelocity(k0, Dc, math.nan, math.nan, (), (), "constant W")
    v = np.geomspace(v_min, v_max, 2401)
    f = law.weakening(v) - K
    roots = []
    for i in np.flatnonzero(np.sign(f[:-1]) * np.sign(f[1:]) < 0):
        roots.append(brentq(lambda x: float(law.weakening(np.array([math.exp(x)]))[0]) - K,
                            math.log(v[i]), math.log(v[i + 1]), xtol=1e-14))
    roots = [math.exp(r) for r in roots]
    unstable = _unstable_intervals(roots, lambda v: float(law.weakening(np.array([v]))[0]) > K)
    if not unstable:
        return CriticalVelocity(k0, Dc, math.nan, math.nan, tuple(roots), (), "scan")
    lo, hi = unstable[-1]
    return CriticalVelocity(k0, Dc, hi, lo, tuple(roots), tuple(unstable), "scan")


def _unstable_intervals(roots: list[float], unstable_at) -> list[tuple[float, float]]:
    """The intervals of (0, inf) between consecutive sorted ``roots`` where steady sliding is
    unstable, each judged at one probe velocity inside it by ``unstable_at(V)``."""
    edges = [0.0] + list(roots) + [math.inf]
    unstable = []
    for lo, hi in zip(edges[:-1], edges[1:]):
        if lo == 0.0 and hi == math.inf:
            probe = 1.0
        elif lo == 0.0:
            probe = hi / 10.0
        elif hi == math.inf:
            probe = lo * 10.0
        else:
            probe = math.sqrt(lo * hi)
        if unstable_at(probe):
            unstable.append((lo, hi))
    return unstable


def _critical_velocity_scan(model: SpringSlider, v_min: float, v_max: float) -> CriticalVelocity:
    """The roots of :func:`stability_margin` in V, bracketed on a log grid and refined by
    brentq to machine precision."""
    v_min = positive("v_min", v_min)
    v_max = positive("v_max", v_max)
    if v_max <= v_min:
        raise ValueError(f"v_max must be > v_min = {v_min!r}, got {v_max!r}")

    def margin_log(x: float) -> float:
        return stability_margin(model, math.exp(x))

    v = np.geomspace(v_min, v_max, 2401)
    f = np.array([stability_margin(model, float(x)) for x in v])
    sign = np.sign(f)
    roots = [float(v[i]) for i in np.flatnonzero(sign == 0.0)
             if 0 < i < v.size - 1 and sign[i - 1] * sign[i + 1] < 0]   # a root on the grid
    roots += [math.exp(brentq(margin_log, math.log(v[i]), math.log(v[i + 1]), xtol=1e-15,
                              rtol=4 * np.finfo(float).eps))
              for i in np.flatnonzero(sign[:-1] * sign[1:] < 0)]
    roots.sort()
    unstable = _unstable_intervals(roots, lambda v: stability_margin(model, v) > 0.0)
    k0, Dc = model.k0, model.Dc
    if not unstable:
        return CriticalVelocity(k0, Dc, math.nan, math.nan, tuple(roots), (), "scan")
    lo, hi = unstable[-1]
    return CriticalVelocity(k0, Dc, hi, lo, tuple(roots), tuple(unstable), "scan")
