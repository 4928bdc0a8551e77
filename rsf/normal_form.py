r"""Normal forms of the loss of stability of steady sliding at :math:`V^c`
(``docs/reference/rsf.md`` §15 has the derivations).

* :math:`a > 0`: a Hopf bifurcation.  :func:`hopf_normal_form` computes its first Lyapunov
  coefficient :math:`l_1` (Kuznetsov, *Elements of Applied Bifurcation Theory*, §3.5,
  Eq. 3.20) from the second and third derivatives of the vector field at the steady state
  and the critical eigenvectors; its sign says super- or subcritical, and with the speed
  at which the pair crosses it gives the amplitude law
  :math:`\sigma_{max} - \sigma_{min} = c\,d^{1/2}` with :math:`d = (V^c - V)/V^c`.  In
  closed form for the aging, slip and PRZ laws (one state variable, no radiation
  damping); by finite differences with a convergence check for every other combination.
* :math:`a = 0`: no Hopf bifurcation (the pair has gone to infinity); the cycle near
  :math:`V^c` is a stick and an instantaneous slip, and its landing point is the fixed
  point of a return map that reduces exactly to two scalar equations.
  :func:`stick_slip_normal_form` solves them (:meth:`StickSlipNormalForm.cycle`) and
  expands them: :math:`\sigma_{max} - \sigma_{min} = c_0 d^{1/2}(1 + c_2 d + O(d^2))`.
* :func:`transition_spectrum` and :func:`classify_spectrum`: the growth rate of the
  unstable mode against d, and the test ``compare.fits.classify_transition`` applies to
  micro (diverging: a mode entering from infinity; vanishing at a finite frequency: Hopf).
* :func:`cycle_near_hopf`: the limit cycle next to a Hopf point, where
  :func:`rsf.limit_cycle` alone needs :math:`\sim 1/d` cycles (its section map has a
  multiplier :math:`1 - O(d)`): the fixed point of the section map by the secant method
  on :func:`rsf.simulate`, then :func:`rsf.limit_cycle` started on it.
"""
from __future__ import annotations

import math
from dataclasses import asdict, dataclass, field, replace
from typing import Callable, Sequence

import numpy as np
import pandas as pd
from scipy.optimize import brentq

from ._validation import positive
from .analysis import critical_velocity, stability_margin, steady_jacobian
from .laws import HyperbolicLaw, LogLaw
from .params import InitialState, SolverOptions, SpringSlider
from .solver import limit_cycle, simulate
from .state_laws import AGING, NAGATA, PRZ, SLIP, USER

__all__ = ["HopfNormalForm", "hopf_normal_form", "StickSlipNormalForm", "stick_slip_normal_form",
           "transition_spectrum", "classify_spectrum", "cycle_near_hopf"]


# ----------------------------------------------------------------------------- derivatives
def _stencil(m: int, orders: Sequence[int]) -> np.ndarray:
    """Central finite-difference weights on the offsets -m..m: row j gives
    ``h**orders[j] * f^(orders[j])(0)`` exactly for polynomials of degree 2m."""
    k = np.arange(-m, m + 1, dtype=float)
    n = k.size
    vander = np.array([k ** j / math.factorial(j) for j in range(n)])
    out = []
    for order in orders:
        rhs = np.zeros(n)
        rhs[order] = 1.0
        out.append(np.linalg.solve(vander, rhs))
    return np.array(out)


_M = 4
_W23 = _stencil(_M, (2, 3))            # 9 points: f'' to O(h^8), f''' to O(h^6)
_STEPS = tuple(0.4 * 2.0 ** -k for k in range(7))


def _taylor_scalar(f: Callable[[float], float], orders: Sequence[int], m: int = 5,
                   steps: Sequence[float] = _STEPS) -> tuple[np.ndarray, np.ndarray]:
    """Derivatives of a real scalar function at 0 by central differences on 2m + 1 points,
    at a ladder of steps; returns the value at the step where two successive steps agree
    best and that difference (the convergence check)."""
    w = _stencil(m, orders)
    est = []
    for h in steps:
        vals = np.array([f(j * h) for j in range(-m, m + 1)])
        est.append(np.array([w[i] @ vals / h ** o for i, o in enumerate(orders)]))
    est = np.array(est)
    diffs = np.abs(np.diff(est, axis=0))
    scale = np.maximum(np.abs(est[1:]), 1e-300)
    rel = np.max(diffs / scale, axis=1)
    i = int(np.argmin(rel))
    return est[i + 1], diffs[i]


def _omega_derivatives(law, V: float, n: int = 4) -> tuple[np.ndarray, str]:
    r""":math:`\Omega^{(k)}(0)`, k = 0..n, of :math:`\Omega(z) = W(V e^{-z})`.

    Exact for the laws given in closed form: the log law (W constant) and Eq. (10), whose
    :math:`\Omega` is analytic in a disc of radius :math:`\pi` (the pole
    :math:`u = -B`): Cauchy's integral on the circle :math:`|z| = 1` with 64 points
    (error :math:`\sim \pi^{-64}`).  Other laws: central differences of ``law.weakening``
    with a convergence check."""
    if isinstance(law, LogLaw):
        out = np.zeros(n + 1)
        out[0] = float(law.weakening(np.array([V]))[0])
        return out, "closed form"
    if isinstance(law, HyperbolicLaw):
        M, r = 64, 1.0
        z = r * np.exp(2j * np.pi * np.arange(M) / M)
        u = V * np.exp(-z)
        vals = law.A * u / (u + law.B) ** 2
        coef = np.fft.fft(vals) / M
        out = np.array([(coef[k] * math.factorial(k) / r ** k).real for k in range(n + 1)])
        return out, "closed form"

    def omega(z: float) -> float:
        return float(law.weakening(np.array([V * math.exp(-z)]))[0])

    ders, _ = _taylor_scalar(omega, tuple(range(1, n + 1)), m=6,
                             steps=tuple(0.2 * 2.0 ** -k for k in range(8)))
    return np.concatenate([[omega(0.0)], ders]), "finite differences"


# ----------------------------------------------------------------------------- vector field
def _vector_field(model: SpringSlider, V: float):
    r"""The spring-slider at constant driving ``V`` (:math:`a > 0`) as an autonomous ODE in
    :math:`x = (w, y[, y_2])`, :math:`w = \ln(v/V)`, :math:`y = \ln(V\theta/D_c)`,
    :math:`y_2 = \ln(V\theta_2/D_{c2})`, and the time :math:`\tau = Vt/D_c`; steady sliding
    is :math:`x = 0`.  Returns ``(F, L)``: ``F(x) -> dx/dtau`` and the gradient of the
    spring force :math:`k_0(X - x) = \mu + \eta v` at 0 (whose extrema the cycle's
    :math:`\sigma_{max}, \sigma_{min}` are)."""
    a, K, eta, Dc = model.a, model.K, model.eta_rad, model.Dc
    law, state, sec = model.law, model.state, model.second_state
    ev = eta * V
    code = state.code
    kappa = 0.0
    if code == NAGATA:
        b = state.b if state.b is not None else law.b
        kappa = state.c / b

    def W(y: float) -> float:
        return float(law.weakening(np.array([V * math.exp(-y)]))[0])

    def rate(w: float, y: float, which: int) -> float:
        """(D_c/V) d ln(theta)/dt of the state law (without Nagata's stress-rate term)."""
        if which == SLIP:
            return -math.exp(w) * (w + y)
        if which == PRZ:
            return 0.5 * math.exp(-y) * (1.0 - math.exp(2.0 * (w + y)))
        if which == USER:
            th = Dc * math.exp(y) / V
            return Dc / V * float(state.func(V * math.exp(w), th)) / th
        return math.exp(-y) - math.exp(w)           # aging (and Nagata's first part)

    rho = b2 = 0.0
    if sec is not None:
        rho, b2 = Dc / sec.Dc2, sec.b2

    def F(x: np.ndarray) -> np.ndarray:
        w, y = float(x[0]), float(x[1])
        ew = math.exp(w)
        spring_rate = K * (1.0 - ew)                 # (D_c/V) d(spring)/dt
        Wa = W(y) + a
        g = rate(w, y, code)
        y2_t = 0.0
        if sec is not None:
            y2_t = rho * rate(w, float(x[2]), code)
        # (a + eta v) w_t = spring_rate - Wa y_t - b2 y2_t, with (Nagata)
        # y_t = g - kappa (spring_rate - eta v w_t)
        rhs = spring_rate - Wa * (g - kappa * spring_rate) - b2 * y2_t
        w_t = rhs / (a + ev * ew + Wa * kappa * ev * ew)
        y_t = g - kappa * (spring_rate - ev * ew * w_t)
        out = [w_t, y_t] + ([y2_t] if sec is not None else [])
        return np.array(out)

    L = np.array([a + ev, W(0.0) + a] + ([b2] if sec is not None else []))
    return F, L


def _jacobian_fd(F, n: int, h: float = 1e-4) -> np.ndarray:
    J = np.empty((n, n))
    for j in range(n):
        e = np.zeros(n)
        e[j] = h
        J[:, j] = (8 * (F(e) - F(-e)) - (F(2 * e) - F(-2 * e))) / (12 * h)
    return J


# ----------------------------------------------------------------------------- Kuznetsov
def _critical_pair(A: np.ndarray) -> tuple[float, np.ndarray, np.ndarray]:
    r""":math:`\omega_0`, q and p at a Hopf point: :math:`Aq = i\omega_0 q`,
    :math:`A^Tp = -i\omega_0 p`, :math:`\langle q, q\rangle = \langle p, q\rangle = 1`
    (:math:`\langle p, q\rangle = \bar p^T q`)."""
    lam, vec = np.linalg.eig(A)
    i = int(np.argmax(lam.imag))
    omega = float(lam[i].imag)
    if not omega > 0.0:
        raise ValueError(f"no complex pair at the critical point: eigenvalues {lam.tolist()}")
    q = vec[:, i] / np.linalg.norm(vec[:, i])
    lam_t, vec_t = np.linalg.eig(A.T)
    j = int(np.argmin(np.abs(lam_t - np.conj(lam[i]))))
    p = vec_t[:, j]
    p = p / np.conj(np.vdot(p, q))
    return omega, q, p


def _lyapunov_terms(F, A: np.ndarray, omega: float, q: np.ndarray, p: np.ndarray,
                    h: float) -> tuple[complex, complex, complex]:
    r"""The three terms of Kuznetsov's Eq. (3.20),
    :math:`\langle p, C(q,q,\bar q)\rangle`, :math:`\langle p, B(q, A^{-1}B(q,\bar q))\rangle`
    and :math:`\langle p, B(\bar q, (2i\omega_0 - A)^{-1}B(q,q))\rangle`, with the
    multilinear forms from second and third directional derivatives of the real field F
    (9-point central differences at step h along unit directions), by polarisation."""
    n = A.shape[0]
    zero = np.zeros(n)

    def d23(u: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        s = float(np.linalg.norm(u))
        if s == 0.0:
            return zero, zero
        e = u / s
        vals = np.array([F(j * h * e) for j in range(-_M, _M + 1)])
        d2 = _W23[0] @ vals / h ** 2
        d3 = _W23[1] @ vals / h ** 3
        return d2 * s ** 2, d3 * s ** 3

    cache: dict[bytes, tuple[np.ndarray, np.ndarray]] = {}

    def D(u: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        key = np.asarray(u, dtype=float).tobytes()
        if key not in cache:
            cache[key] = d23(u)
        return cache[key]

    def B(u: np.ndarray, v: np.ndarray) -> np.ndarray:        # real, symmetric
        return (D(u + v)[0] - D(u - v)[0]) / 4.0

    def Bc(u: np.ndarray, v: np.ndarray) -> np.ndarray:       # complex arguments
        ur, ui, vr, vi = u.real, u.imag, v.real, v.imag
        return (B(ur, vr) - B(ui, vi)) + 1j * (B(ur, vi) + B(ui, vr))

    ar, ai = q.real, q.imag
    d3a, d3b = D(ar)[1], D(ai)[1]
    d3p, d3m = D(ar + ai)[1], D(ar - ai)[1]
    c_abb = (d3p + d3m - 2.0 * d3a) / 6.0
    c_aab = (d3p - d3m - 2.0 * d3b) / 6.0
    C_qqqb = (d3a + c_abb) + 1j * (c_aab + d3b)
    B_qqb = D(ar)[0] + D(ai)[0]
    B_qq = D(ar)[0] - D(ai)[0] + 2j * B(ar, ai)
    s = np.linalg.solve(A, B_qqb)
    t = np.linalg.solve(2j * omega * np.eye(n) - A, B_qq)
    t1 = np.vdot(p, C_qqqb)
    t2 = np.vdot(p, Bc(q, s.astype(complex)))
    t3 = np.vdot(p, Bc(np.conj(q), t))
    return t1, t2, t3


def _first_lyapunov(F, A: np.ndarray, steps: Sequence[float] = (0.2, 0.1, 0.05, 0.025, 0.0125)
                    ) -> tuple[float, float, float, np.ndarray, float]:
    r"""Kuznetsov's first Lyapunov coefficient
    :math:`l_1 = \frac{1}{2\omega_0}\operatorname{Re}[\langle p,C(q,q,\bar q)\rangle
    - 2\langle p,B(q,A^{-1}B(q,\bar q))\rangle
    + \langle p,B(\bar q,(2i\omega_0-A)^{-1}B(q,q))\rangle]` of ``F`` at 0 (a Hopf point,
    Jacobian ``A``), at a ladder of steps: returns ``(omega0, l1, error, q, scale)`` with
    l1 from the step where two successive steps agree best, that difference as its error,
    and the size of the largest term (to judge a vanishing l1)."""
    omega, q, p = _critical_pair(A)
    vals, scales = [], []
    for h in steps:
        t1, t2, t3 = _lyapunov_terms(F, A, omega, q, p, h)
        vals.append((t1 - 2.0 * t2 + t3).real / (2.0 * omega))
        scales.append(max(abs(t1), 2.0 * abs(t2), abs(t3)) / (2.0 * omega))
    vals = np.array(vals)
    diffs = np.abs(np.diff(vals))
    i = int(np.argmin(diffs))
    return omega, float(vals[i + 1]), float(diffs[i]), q, float(scales[i + 1])


# ----------------------------------------------------------------------------- a > 0
@dataclass(frozen=True)
class HopfNormalForm:
    r"""The Hopf normal form of steady sliding at its critical point (:math:`a > 0`).

    Coordinates :math:`x = (\ln(v/V), \ln(V\theta/D_c)[, \ln(V\theta_2/D_{c2})])`, physical
    time t; q is normalised as in Kuznetsov (:math:`\langle q,q\rangle = \langle p,q\rangle
    = 1`).  On the centre manifold :math:`\dot z = (\beta + i\omega)z + c_1 z|z|^2`, with
    :math:`\beta = \operatorname{Re}\lambda \simeq g\,d` and
    :math:`l_1 = \operatorname{Re}c_1/\omega_0` (Kuznetsov's Eq. 3.20).  The cycle has
    :math:`|z|^2 = -\beta/\operatorname{Re}c_1`, and
    :math:`\sigma_{max} - \sigma_{min} = 4|Lq|\,|z| = c\,|d|^{1/2}` to leading order, with
    L the gradient of the spring force.

    Attributes
    ----------
    Vc : float
        The critical driving velocity (with ``parameter='k0'``: the V given).
    k0c : float
        The critical stiffness (with ``parameter='V'``: the model's k0).
    a, Dc : float
        The model's direct effect and critical slip distance.
    parameter : str
        ``'V'``: :math:`d = (V^c - V)/V^c`; ``'k0'``: :math:`d = (k_0^c - k_0)/k_0^c`.
    omega : float
        :math:`\omega_0`, the angular frequency of the critical pair (per unit time);
        ``period`` is :math:`2\pi/\omega_0`.
    l1 : float
        Kuznetsov's first Lyapunov coefficient :math:`\operatorname{Re}c_1/\omega_0`
        (dimensionless: the same in any time unit); ``l1_error`` its convergence estimate
        (0 for the closed forms).
    re_c1 : float
        :math:`\operatorname{Re}c_1 = \omega_0 l_1`.
    growth_slope : float
        :math:`g = \mathrm{d}\operatorname{Re}\lambda/\mathrm{d}d` at d = 0 (per unit time).
    radius_prefactor : float
        :math:`\sqrt{|g/\operatorname{Re}c_1|}`: the cycle's :math:`|z| = ` this
        :math:`\times|d|^{1/2}`.
    sigma_gain : float
        :math:`|Lq|`.
    prefactor : float
        c: :math:`\sigma_{max} - \sigma_{min} \simeq c\,|d|^{1/2}` on the side where the
        cycle exists (nan if degenerate).
    kind : str
        ``'supercritical'`` (a stable cycle where steady sliding is unstable),
        ``'subcritical'`` (an unstable cycle where it is stable) or ``'degenerate'``
        (:math:`l_1` is zero within its error: the next coefficient decides).
    side : str
        Where the cycle exists: ``'d > 0'`` or ``'d < 0'`` ('' if degenerate).
    method : str
        ``'closed form'`` (with ``(W' and W'' by differences)`` for a law other than the
        log law and Eq. 10) or ``'finite differences'``.
    law, state_law : str
        The names of the model's steady-state and state laws.
    eta_rad : float
        The model's radiation damping.
    """

    Vc: float
    k0c: float
    parameter: str
    a: float
    Dc: float
    omega: float
    l1: float
    l1_error: float
    re_c1: float
    growth_slope: float
    radius_prefactor: float
    sigma_gain: float
    prefactor: float
    kind: str
    side: str
    method: str
    law: str = ""
    state_law: str = ""
    eta_rad: float = 0.0

    @property
    def period(self) -> float:
        return 2.0 * math.pi / self.omega

    def amplitude(self, d) -> np.ndarray:
        r""":math:`c|d|^{1/2}` where the cycle exists, nan on the other side."""
        d = np.asarray(d, dtype=float)
        ok = d > 0 if self.side == "d > 0" else (d < 0 if self.side == "d < 0" else np.zeros_like(d, bool))
        return np.where(ok, self.prefactor * np.sqrt(np.abs(d)), np.nan)

    def to_dict(self) -> dict:
        out = asdict(self)
        out["period"] = self.period
        return out


def _closed_form_l1(K: float, a: float, om1: float, om2: float, code: int) -> tuple[float, float]:
    r"""l1 in :math:`\tau = Vt/D_c` for the aging, slip and PRZ laws without damping, for
    :math:`q = ((K+a)/a,\ i\sqrt{K/a} - 1)` (not normalised); from the symbolic evaluation
    of Eq. (3.20) (``docs/reference/rsf.md`` §15).  Returns (l1, |q|^2)."""
    base = -(K + a) / (4.0 * math.sqrt(K) * a ** 2.5)
    if code == AGING:
        l1 = base * a * (om1 - om2)
    elif code == SLIP:
        l1 = base * ((K + a) * om1 - a * om2)
    else:                                    # PRZ
        l1 = base * ((K + a) * om1 - a * om2 - K * K)
    return l1, (K + a) * (K + 2.0 * a) / a ** 2


def _critical_k0(model: SpringSlider, V: float) -> float:
    """The largest k0 at which steady sliding at V is unstable (a root of the margin)."""
    def margin(lk: float) -> float:
        return stability_margin(replace(model, k0=math.exp(lk)), V)

    grid = np.linspace(math.log(1e-12), math.log(1e6), 361)
    vals = np.array([margin(x) for x in grid])
    idx = np.flatnonzero((vals[:-1] > 0.0) & (vals[1:] <= 0.0))
    if not idx.size:
        raise ValueError(f"steady sliding at V = {V:g} changes stability at no k0 in [1e-12, 1e6]")
    i = int(idx[-1])
    return math.exp(brentq(margin, grid[i], grid[i + 1], xtol=1e-15, rtol=1e-15))


def _leading_growth(model: SpringSlider, V: float) -> float:
    lam = np.linalg.eigvals(steady_jacobian(model, V)) * V / model.Dc
    return float(np.max(lam.real))


def hopf_normal_form(model: SpringSlider, *, parameter: str = "V", V: float | None = None,
                     method: str = "auto") -> HopfNormalForm:
    r"""The first Lyapunov coefficient of the Hopf bifurcation of steady sliding
    (:math:`a > 0`), its kind and the amplitude prefactor.

    Parameters
    ----------
    model : SpringSlider
        Any law and state law with a direct effect a > 0 (also radiation damping and a
        second state variable).
    parameter : {'V', 'k0'}
        The bifurcation parameter: the driving velocity (at the model's critical velocity,
        :func:`rsf.critical_velocity`), or the stiffness at the driving velocity ``V`` (for
        the log law without damping, whose steady state does not depend on V).
    V : float
        The driving velocity, with ``parameter='k0'`` only.
    method : {'auto', 'closed form', 'finite differences'}
        ``'auto'``: the closed form for the aging, slip and PRZ laws with one state variable
        and no damping, finite differences otherwise.

    Returns
    -------
    HopfNormalForm
        The frequency, the first Lyapunov coefficient and its error, the kind
        (super-, subcritical or degenerate), the side of the critical point where the
        cycle exists and the amplitude prefactor :math:`c` of :math:`c\,|d|^{1/2}`.

    Raises
    ------
    ValueError
        If ``model`` is not a :class:`~rsf.params.SpringSlider`, :math:`a = 0`,
        ``parameter`` or ``method`` is not one of its choices, ``V`` is given with
        ``parameter='V'`` or missing with ``'k0'``, the model has no finite critical
        velocity (``parameter='V'``) or no critical stiffness in [1e-12, 1e6]
        (``parameter='k0'``), the critical eigenvalues are not a pair on the imaginary
        axis, or ``method='closed form'`` is asked for a model it does not cover.

    Examples
    --------
    >>> import rsf
    >>> nf = rsf.hopf_normal_form(rsf.SpringSlider(k0=0.1, a=1e-3))
    >>> nf.kind, nf.side
    ('supercritical', 'd > 0')
    """
    if not isinstance(model, SpringSlider):
        raise ValueError(f"model must be an rsf.SpringSlider, got {model!r}")
    if model.a == 0.0:
        raise ValueError("hopf_normal_form needs a direct effect a > 0; with a = 0 steady sliding "
                         "loses stability without a Hopf pair (see stick_slip_normal_form)")
    if parameter not in ("V", "k0"):
        raise ValueError(f"parameter must be 'V' or 'k0', got {parameter!r}")
    if method not in ("auto", "closed form", "finite differences"):
        raise ValueError(f"method must be 'auto', 'closed form' or 'finite differences', got {method!r}")
    if parameter == "V":
        if V is not None:
            raise ValueError("V is the bifurcation parameter with parameter='V'; give it only "
                             "with parameter='k0'")
        Vc = critical_velocity(model).Vc
        if not (math.isfinite(Vc) and Vc > 0.0):
            raise ValueError(f"the model has no finite critical velocity (Vc = {Vc}); for the log "
                             f"law without damping use parameter='k0' with a V")
        k0c = model.k0
        crit = model
    else:
        if V is None:
            raise ValueError("parameter='k0' needs the driving velocity V")
        Vc = positive("V", V)
        k0c = _critical_k0(model, Vc)
        crit = replace(model, k0=k0c)
    Dc, a, K = crit.Dc, crit.a, crit.K
    unit = Vc / Dc                              # tau -> t
    A = steady_jacobian(crit, Vc)
    lam = np.linalg.eigvals(A)
    lead = lam[int(np.argmax(lam.real))]
    if not (abs(lead.imag) > 0.0 and abs(lead.real) <= 1e-7 * abs(lead)):
        raise ValueError(f"no Hopf pair at the critical point: the leading eigenvalues of the "
                         f"Jacobian are {lam.tolist()}, not a pair on the imaginary axis")
    F, L = _vector_field(crit, Vc)
    code = crit.state.code
    simple = crit.eta_rad == 0.0 and crit.second_state is None and code in (AGING, SLIP, PRZ)
    if method == "closed form" and not simple:
        raise ValueError("the closed form covers the aging, slip and PRZ laws with one state "
                         "variable and no radiation damping; use method='finite differences'")
    if method == "closed form" or (method == "auto" and simple):
        om, om_how = _omega_derivatives(crit.law, Vc, 2)
        l1_raw, qq = _closed_form_l1(K, a, om[1], om[2], code)
        omega_tau = math.sqrt(K / a)
        q = np.array([(K + a) / a, 1j * omega_tau - 1.0]) / math.sqrt(qq)
        l1_tau, err_tau, scale_tau = l1_raw / qq + 0.0, 0.0, abs(l1_raw / qq)
        how = "closed form" if om_how == "closed form" else "closed form (W' and W'' by differences)"
    else:
        omega_tau, l1_tau, err_tau, q, scale_tau = _first_lyapunov(F, A)
        how = "finite differences"
    omega = omega_tau * unit
    l1, err = l1_tau, err_tau                   # Re(c1)/omega0: the same in any time unit
    re_c1 = omega * l1
    # the crossing speed g = d Re(lambda)/d d, in 1/time
    if parameter == "V":
        def growth(d: float) -> float:
            return _leading_growth(crit, Vc * (1.0 - d))
    else:
        def growth(d: float) -> float:
            return _leading_growth(replace(crit, k0=k0c * (1.0 - d)), Vc)
    h = 1e-4
    d1 = (growth(h) - growth(-h)) / (2 * h)
    d2 = (growth(h / 2) - growth(-h / 2)) / h
    g = (4.0 * d2 - d1) / 3.0
    gain = float(abs(np.dot(L, q)))
    degenerate = abs(l1_tau) <= max(10.0 * err_tau, 1e-9 * scale_tau) or l1_tau == 0.0
    if degenerate:
        kind, side, radius, c = "degenerate", "", math.nan, math.nan
    else:
        kind = "supercritical" if l1 < 0.0 else "subcritical"
        radius = math.sqrt(abs(g / re_c1))
        c = 4.0 * gain * radius
        side = "d > 0" if (g > 0) == (l1 < 0) else "d < 0"
    return HopfNormalForm(Vc=Vc, k0c=k0c, parameter=parameter, a=a, Dc=Dc, omega=omega, l1=l1,
                          l1_error=err, re_c1=re_c1, growth_slope=g, radius_prefactor=radius,
                          sigma_gain=gain, prefactor=c, kind=kind, side=side, method=how,
                          law=crit.law.name, state_law=crit.state.name, eta_rad=crit.eta_rad)


# ----------------------------------------------------------------------------- a = 0
def _h(y: float) -> float:
    """e^y - 1 - y without cancellation."""
    if abs(y) < 0.1:
        term, total, k = y * y / 2.0, 0.0, 2
        while abs(term) > 1e-18 * abs(total) or total == 0.0:
            total += term
            k += 1
            term *= y / k
            if k > 40:
                break
        return total
    return math.expm1(y) - y


def _partner(eta: float) -> float:
    r"""The :math:`\zeta < 0` with :math:`e^\zeta - \zeta = e^\eta - \eta` (:math:`\eta > 0`)."""
    target = _h(eta)
    guess = -eta - eta * eta / 3.0 - eta ** 3 / 9.0
    lo, hi = 1.5 * guess - 1e-300, 0.5 * guess
    while _h(lo) < target:
        lo *= 2.0
    while _h(hi) > target:
        hi *= 0.5
    return brentq(lambda z: _h(z) - target, lo, hi, xtol=1e-300, rtol=1e-15, maxiter=200)


_GL_X, _GL_W = np.polynomial.legendre.leggauss(48)


@dataclass(frozen=True)
class StickSlipNormalForm:
    r"""The stick-slip cycle born at :math:`V^c` when :math:`a = 0` (``docs/reference/rsf.md``
    §15).

    The cycle is a stick from the landing :math:`y_1` to :math:`y_2` and an instantaneous
    slip back (:math:`y = \ln(V\theta/D_c)`); it is the fixed point of the landing-to-landing
    map, which reduces exactly to

    .. math:: e^{y_2} - y_2 = e^{y_1} - y_1, \qquad
              \int_{y_1}^{y_2} \big[W(Ve^{-y}) - k_0D_c\big]\,\mathrm{d}y = 0,

    :math:`\sigma_{max} - \sigma_{min} = K(y_2 - y_1)`, period :math:`= (\sigma_{max} -
    \sigma_{min})/(k_0V)`.  Expanded in :math:`d = (V^c - V)/V^c`:
    :math:`\sigma_{max} - \sigma_{min} = c_0 d^{1/2}(1 + c_2 d + O(d^2))`,
    :math:`c_0 = 2\sqrt6\,K\sqrt{\Omega_1/(\Omega_1 - \Omega_2)}`, with
    :math:`\Omega(z) = W(V^c e^{-z})` and its derivatives :math:`\Omega_k` at 0.

    Attributes
    ----------
    Vc, k0, Dc, K : float
        The critical velocity, the stiffness, the critical slip distance and
        :math:`K = k_0 D_c`.
    omegas : tuple of float
        :math:`\Omega_1 \dots \Omega_4`.
    omega_method : str
        How they were computed: 'closed form' or 'finite differences'.
    prefactor : float
        :math:`c_0` (nan unless :math:`\Omega_1 > \Omega_2 > -\infty` and
        :math:`\Omega_1 > 0`).
    correction : float
        :math:`c_2`.
    period_prefactor : float
        :math:`c_0/(k_0 V^c)`: the period is this :math:`\times d^{1/2}` (it vanishes at
        :math:`V^c`).
    kind : str
        ``'supercritical'`` (:math:`\Omega_1 > \Omega_2`: a small cycle below V^c) or
        ``'no small cycle'``.
    model : SpringSlider
        The model, for :meth:`cycle`.
    """

    Vc: float
    k0: float
    Dc: float
    K: float
    omegas: tuple
    prefactor: float
    correction: float
    period_prefactor: float
    kind: str
    omega_method: str
    model: SpringSlider = field(repr=False, compare=False, default=None)

    def amplitude(self, d, order: int = 2) -> np.ndarray:
        r""":math:`c_0 d^{1/2}` (``order=0``) or :math:`c_0 d^{1/2}(1 + c_2 d)` (``order=2``)."""
        d = np.asarray(d, dtype=float)
        corr = 1.0 + (self.correction * d if order >= 2 else 0.0)
        return np.where(d > 0, self.prefactor * np.sqrt(np.abs(d)) * corr, np.nan)

    def cycle(self, V: float, check: bool = True) -> dict:
        r"""The exact stick-slip cycle at ``V`` (< V^c) from the two equations above, without
        an integrator (Gauss-Legendre quadrature of W, brentq).  Returns a dict with V, d,
        y_land (:math:`y_1`), y_top (:math:`y_2`), sigma_max, sigma_min, amplitude, period.
        ``check``: verify on a grid that the stick meets the threshold first at y_top and
        the slip first at y_land (true near V^c; raises if not)."""
        model = self.model
        V = positive("V", V)
        if not V < self.Vc:
            raise ValueError(f"V must be below Vc = {self.Vc!r}, got {V!r}")
        if self.kind != "supercritical":
            raise ValueError("no small stick-slip cycle below Vc for this law (Omega1 <= Omega2)")
        K, law = self.K, model.law

        def W(y: np.ndarray) -> np.ndarray:
            return law.weakening(V * np.exp(np.minimum(-np.asarray(y, dtype=float), 700.0)))

        def F(eta: float) -> float:
            zeta = _partner(eta)
            mid, half = 0.5 * (eta + zeta), 0.5 * (eta - zeta)
            return float(half * (_GL_W @ (W(mid + half * _GL_X) - K)))

        d = (self.Vc - V) / self.Vc
        guess = max(math.sqrt(6.0 * d * self.omegas[0] / (self.omegas[0] - self.omegas[1])), 1e-300)
        lo, hi = guess, guess
        while F(lo) <= 0.0:
            lo *= 0.5
            if lo < 1e-300:
                raise RuntimeError("no stick-slip fixed point found")
        while F(hi) > 0.0:
            hi *= 1.5
            if hi > 50.0:
                raise RuntimeError("no stick-slip fixed point found")
        eta = brentq(F, lo, hi, xtol=1e-300, rtol=1e-15, maxiter=300)
        zeta = _partner(eta)
        if check:
            self._check_first_crossings(V, zeta, eta)
        amp = K * (eta - zeta)
        return {"V": V, "d": d, "y_land": zeta, "y_top": eta,
                "sigma_max": float(law.mu_ss(np.array([V * math.exp(-eta)]))[0]),
                "sigma_min": float(law.mu_ss(np.array([V * math.exp(-zeta)]))[0]),
                "amplitude": amp, "period": amp / (self.k0 * V)}

    def _check_first_crossings(self, V: float, y1: float, y2: float) -> None:
        law, K = self.model.law, self.K
        y = np.linspace(y1, y2, 401)[1:-1]
        # differences of phi by quadrature of W from y1: phi(y) - phi(y1) = int_{y1}^{y} W dy
        def dphi(b: float) -> float:
            mid, half = 0.5 * (b + y1), 0.5 * (b - y1)
            z = np.minimum(-(mid + half * _GL_X), 700.0)
            return float(half * (_GL_W @ law.weakening(V * np.exp(z))))
        dp = np.array([dphi(float(b)) for b in y])
        stick_gap = K * (np.exp(y1) * np.expm1(y - y1)) - dp     # sigma - phi on the stick, < 0
        slip_gap = K * (y - y1) - dp                              # (sigma - phi) on the slip, > 0
        tol = 1e-12 * K * (y2 - y1)
        if np.any(stick_gap > tol) or np.any(slip_gap < -tol):
            raise RuntimeError(f"at V = {V:g} the cycle is not a single stick and slip between "
                               f"y = {y1:.6g} and {y2:.6g}: too far from Vc for the reduction")

    def to_dict(self) -> dict:
        out = {k: v for k, v in asdict(self).items() if k != "model"}
        out["omegas"] = list(self.omegas)
        return out


def stick_slip_normal_form(model: SpringSlider) -> StickSlipNormalForm:
    r"""The nonsmooth normal form of the :math:`a = 0` transition at :math:`V^c`: the
    prefactor :math:`c_0` and correction :math:`c_2` of
    :math:`\sigma_{max} - \sigma_{min} = c_0 d^{1/2}(1 + c_2 d)`, and the exact cycle
    (:meth:`StickSlipNormalForm.cycle`).  (For a > 0 the same formulas give the
    :math:`a \to 0` limit taken before :math:`d \to 0`.)

    Parameters
    ----------
    model : SpringSlider
        The slider; only its steady-state law, ``k0`` and ``Dc`` enter.

    Returns
    -------
    StickSlipNormalForm
        :math:`V^c`, :math:`\Omega_1 \dots \Omega_4`, :math:`c_0`, :math:`c_2`, the
        period's prefactor and the kind (prefactors nan where there is no small cycle).

    Raises
    ------
    ValueError
        If ``model`` is not a :class:`~rsf.params.SpringSlider` or has no finite critical
        velocity.

    Examples
    --------
    >>> import rsf
    >>> nf = rsf.stick_slip_normal_form(rsf.SpringSlider(k0=0.1))
    >>> nf.kind, round(nf.Vc, 4)
    ('supercritical', 1.0046)
    """
    if not isinstance(model, SpringSlider):
        raise ValueError(f"model must be an rsf.SpringSlider, got {model!r}")
    Vc = critical_velocity(model.law, k0=model.k0, Dc=model.Dc).Vc
    if not (math.isfinite(Vc) and Vc > 0.0):
        raise ValueError(f"the model has no finite critical velocity (Vc = {Vc})")
    om, how = _omega_derivatives(model.law, Vc, 4)
    o1, o2, o3, o4 = (float(x) for x in om[1:5])
    K = model.K
    if o1 > 0.0 and o1 > o2:
        c0 = 2.0 * math.sqrt(6.0) * K * math.sqrt(o1 / (o1 - o2))
        c2 = ((7 * o1 ** 3 - 10 * o1 ** 2 * o2 + 3 * o1 ** 2 * o4 + 5 * o1 * o2 ** 2
               - 10 * o1 * o2 * o3 + 5 * o2 ** 3) / (20.0 * o1 * (o1 - o2) ** 2))
        kind = "supercritical"
    else:
        c0 = c2 = math.nan
        kind = "no small cycle"
    return StickSlipNormalForm(Vc=Vc, k0=model.k0, Dc=model.Dc, K=K, omegas=(o1, o2, o3, o4),
                               prefactor=c0, correction=c2, period_prefactor=c0 / (model.k0 * Vc),
                               kind=kind, omega_method=how, model=model)


# ----------------------------------------------------------------------------- one test
def transition_spectrum(model: SpringSlider, d: Sequence[float]) -> pd.DataFrame:
    r"""The unstable mode of steady sliding at :math:`V = V^c(1 - d)`.

    For :math:`a > 0`: the eigenvalues of :func:`rsf.analysis.steady_jacobian` (per unit
    time), the leading one's real part (``growth_rate``) and imaginary part
    (``frequency``), and the other one's real part (``other_rate``).  For :math:`a = 0`:
    the direct-effect limit :math:`a \to 0` has one eigenvalue at :math:`+\infty` for every
    d > 0 (``fast_rate``; the instantaneous slip) and one finite real one, the linearised
    slide :math:`\dot\delta = \alpha K\delta/(W - K)`, :math:`\alpha = V/D_c`, which is
    ``growth_rate`` (it diverges as :math:`1/d`).  Columns: d, V, growth_rate, frequency,
    other_rate, fast_rate, and the same rates in units of :math:`V/D_c` (suffix ``_tau``).

    Parameters
    ----------
    model : SpringSlider
        The slider (any direct effect :math:`a \ge 0`).
    d : sequence of float
        Relative distances below the critical velocity, :math:`d = (V^c - V)/V^c`.

    Returns
    -------
    pandas.DataFrame
        One row per d: k0, a, d, V, the rates per unit time and per :math:`V/D_c`.

    Raises
    ------
    ValueError
        If the model has no finite critical velocity.

    Examples
    --------
    >>> import rsf
    >>> sp = rsf.transition_spectrum(rsf.SpringSlider(k0=0.1), [0.01, 0.1])
    >>> bool(sp.growth_rate.iloc[0] > sp.growth_rate.iloc[1])     # diverges as 1/d for a = 0
    True
    """
    d = np.atleast_1d(np.asarray(d, dtype=float))
    cv = critical_velocity(model) if model.a > 0.0 else critical_velocity(model.law, k0=model.k0, Dc=model.Dc)
    Vc = cv.Vc
    if not (math.isfinite(Vc) and Vc > 0.0):
        raise ValueError(f"the model has no finite critical velocity (Vc = {Vc})")
    rows = []
    for di in d:
        V = Vc * (1.0 - float(di))
        unit = V / model.Dc
        if model.a > 0.0:
            lam = np.linalg.eigvals(steady_jacobian(model, V))
            lam = lam[np.argsort(-lam.real)]
            lead, other = lam[0], lam[-1]
            rows.append({"d": float(di), "V": V, "growth_rate_tau": float(lead.real),
                         "frequency_tau": float(abs(lead.imag)), "other_rate_tau": float(other.real),
                         "fast_rate_tau": math.nan})
        else:
            W = float(model.law.weakening(np.array([V]))[0])
            slow = model.K / (W - model.K) if W != model.K else math.inf
            rows.append({"d": float(di), "V": V, "growth_rate_tau": slow, "frequency_tau": 0.0,
                         "other_rate_tau": math.nan,
                         "fast_rate_tau": math.inf if W > model.K else -math.inf})
        for key in ("growth_rate", "frequency", "other_rate", "fast_rate"):
            rows[-1][key] = rows[-1][key + "_tau"] * unit
    out = pd.DataFrame(rows)
    out.insert(0, "a", model.a)
    out.insert(0, "k0", model.k0)
    return out


def classify_spectrum(spectrum: pd.DataFrame, periods: pd.DataFrame | None = None) -> dict:
    r"""The test of ``compare.fits.classify_transition``, for any model's spectrum.

    ``spectrum``: columns d and growth_rate (the unstable mode, as from
    :func:`transition_spectrum`).  The mode's growth rate at the smallest d (``near``) and
    at the d closest to 0.5 (``far``): it *diverges* if near > 10 far (an eigenvalue
    entering from infinity), else it vanishes as at a local bifurcation.  ``periods``
    (optional): columns d and period of the born cycle; the slope of ln period against ln d
    is ``period_exponent``.  Hopf: not diverging and :math:`|` period_exponent :math:`| <
    0.25` (a finite frequency).

    Parameters
    ----------
    spectrum : pandas.DataFrame
        Columns ``d`` and ``growth_rate`` (and ``frequency``, optional).
    periods : pandas.DataFrame, optional
        Columns ``d`` and ``period``; the period exponent needs at least 3 finite periods > 0.

    Returns
    -------
    dict
        ``d_near``, ``growth_near``, ``d_far``, ``growth_far`` (``frequency_near``),
        ``growth_diverges``, with periods ``period_exponent`` and ``d_period`` (its range
        of d), ``hopf`` (bool) and ``text``, a sentence with the verdict.

    Raises
    ------
    ValueError
        If the spectrum has fewer than two finite growth rates.

    Examples
    --------
    >>> import rsf
    >>> out = rsf.classify_spectrum(rsf.transition_spectrum(rsf.SpringSlider(k0=0.1), [1e-3, 0.5]))
    >>> out["growth_diverges"], out["hopf"]
    (True, False)
    """
    out: dict = {}
    sp = spectrum[np.isfinite(spectrum.growth_rate)].sort_values("d")
    if len(sp) < 2:
        raise ValueError("the spectrum needs at least two finite growth rates")
    near, far = sp.iloc[0], sp.iloc[int(np.argmin(np.abs(sp.d.to_numpy() - 0.5)))]
    out.update(d_near=float(near.d), growth_near=float(near.growth_rate), d_far=float(far.d),
               growth_far=float(far.growth_rate))
    if "frequency" in sp:
        out["frequency_near"] = float(near.frequency)
    out["growth_diverges"] = bool(near.growth_rate > 10 * far.growth_rate)
    if periods is not None:
        per = periods[np.isfinite(periods.period) & (periods.period > 0)]
        if len(per) >= 3:
            out["period_exponent"] = float(np.polyfit(np.log(per.d.to_numpy(float)),
                                                      np.log(per.period.to_numpy(float)), 1)[0])
            out["d_period"] = (float(per.d.min()), float(per.d.max()))
    out["hopf"] = (not out["growth_diverges"]) and abs(out.get("period_exponent", 0.0)) < 0.25
    verdict = "consistent with a Hopf bifurcation" if out["hopf"] else "not a Hopf bifurcation"
    growth = (f"the growth rate of the unstable mode {'rises' if out['growth_diverges'] else 'falls'} "
              f"from {out['growth_far']:.3g} at d = {out['d_far']:.2g} to {out['growth_near']:.3g} "
              f"at d = {out['d_near']:.2g}")
    if "period_exponent" in out:
        growth += f"; the period scales as d^{out['period_exponent']:.2f}"
    out["text"] = f"{verdict}: {growth}"
    return out


# ----------------------------------------------------------------------------- cycles
def cycle_near_hopf(model: SpringSlider, V: float, *, guess: float | None = None,
                    options: SolverOptions | None = None, tol: float = 1e-13,
                    max_iter: int = 40, max_cycles: int = 200):
    r"""The limit cycle at ``V`` next to a Hopf point (:math:`a > 0`, one state variable).

    :func:`rsf.limit_cycle` iterates the section map, whose multiplier is
    :math:`1 - O(d)` there, so that it needs :math:`\sim 1/d` cycles.  Here the section
    :math:`v = V` (falling: the σ minimum) is parametrised by
    :math:`y = \ln(V\theta/D_c)`; the map :math:`y \mapsto P(y)` is one
    :func:`rsf.simulate` run from :math:`(v = V, \theta)` to its next ``'sigma_min'``
    event, and :math:`P(y) = y` is solved by the secant method (``tol`` absolute in y).
    The result is :func:`rsf.limit_cycle` started on that fixed point (converged in a
    few cycles), a :class:`~rsf.CycleResult`.

    Parameters
    ----------
    model : SpringSlider
        With a direct effect :math:`a > 0` and one state variable.
    V : float
        Driving velocity, > 0, on the side of the Hopf point where the cycle exists.
    guess : float, optional
        A first y at the section (default: from :func:`hopf_normal_form`).
    options : SolverOptions, optional
        Default: cycle_rtol = 1e-11, rtol = 1e-12, atol = 1e-14.
    tol : float
        Absolute tolerance of the secant iteration in y (default 1e-13).
    max_iter : int
        Secant steps at most (default 40).
    max_cycles : int
        Cycles at most of the final :func:`rsf.limit_cycle` (default 200).

    Returns
    -------
    CycleResult
        The limit cycle at ``V``, from :func:`rsf.limit_cycle` started on the fixed point.

    Raises
    ------
    ValueError
        If :math:`a = 0`, the model has a second state variable, ``V`` is not a finite
        number > 0, or (without ``guess``) :func:`hopf_normal_form` refuses the model.
    RuntimeError
        If a run from the section finds no minimum of :math:`\sigma`.
    """
    if model.a == 0.0 or model.second_state is not None:
        raise ValueError("cycle_near_hopf needs a > 0 and one state variable")
    V = positive("V", V)
    options = options or SolverOptions(cycle_rtol=1e-11, rtol=1e-12, atol=1e-14)
    Dc = model.Dc
    if guess is None:
        nf = hopf_normal_form(model)
        d = (nf.Vc - V) / nf.Vc
        r = nf.radius_prefactor * math.sqrt(abs(d))
        _, L = _vector_field(model, V)
        _, q, _ = _critical_pair(steady_jacobian(model, nf.Vc))
        # on the cycle x = 2 Re(z q); at the sigma minimum the spring rate w vanishes:
        # choose the phase where Re(z q_w) = 0 and sigma is lowest
        phase = math.atan2(q[0].real, q[0].imag) if q[0] != 0 else 0.0
        cands = [2.0 * (r * np.exp(1j * (phase + s)) * q).real for s in (0.0, math.pi)]
        x = min(cands, key=lambda c: float(L @ c))
        guess = float(x[1])
    lam = np.linalg.eigvals(steady_jacobian(model, V))
    period_guess = 2.0 * math.pi / max(float(np.max(np.abs(lam.imag))), 1e-3) * Dc / V

    def section_map(y: float) -> tuple[float, float]:
        nonlocal period_guess
        theta = Dc * math.exp(y) / V
        t_end = 2.5 * period_guess
        for _ in range(6):
            tr = simulate(model, V, t_end=t_end, initial=InitialState(theta=theta, perturbation=0.0),
                          options=options)
            mins = [e for e in tr.events if e.kind == "sigma_min" and e.t > 0.2 * period_guess]
            if mins:
                period_guess = mins[0].t
                return math.log(V * mins[0].theta / Dc), mins[0].t
            t_end *= 4.0
        raise RuntimeError(f"no sigma minimum after starting at y = {y:g} (V = {V:g})")

    y0 = guess
    f0 = section_map(y0)[0] - y0
    y1 = y0 * (1.0 + 1e-3) if y0 != 0.0 else 1e-8
    f1 = section_map(y1)[0] - y1
    for _ in range(max_iter):
        if f1 == f0:
            break
        y2 = y1 - f1 * (y1 - y0) / (f1 - f0)
        y0, f0 = y1, f1
        y1 = y2
        f1 = section_map(y1)[0] - y1
        if abs(y1 - y0) <= tol:
            break
    theta = Dc * math.exp(y1) / V
    # From the fixed point, limit_cycle confirms the cycle without Aitken jumps (next to the
    # fixed point they would amplify the map's round-off by 1/(1 - multiplier)).  The
    # amplitude's cycle-to-cycle change cannot fall below the integrator's noise in sigma
    # (about 1e-14) over the amplitude: the test is not asked to be tighter than that.
    tr = simulate(model, V, t_end=1.5 * period_guess,
                  initial=InitialState(theta=theta, perturbation=0.0), options=options)
    amp = float(np.max(tr.sigma) - np.min(tr.sigma)) if tr.sigma.size else 0.0
    rtol = options.cycle_rtol if not amp > 0.0 else min(max(options.cycle_rtol, 1e-13 / amp), 1e-6)
    return limit_cycle(model, V, initial=InitialState(theta=theta, perturbation=0.0),
                       options=replace(options, accelerate=False, cycle_rtol=rtol,
                                       max_cycles=min(options.max_cycles, max_cycles)))
