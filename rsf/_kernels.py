r"""Small, pure numba kernels: steady-state laws, the stick and slip roots, the phase
decision and the right-hand sides handed to CVODE.

Conventions (see ``docs/reference/rsf.md``):

* a steady-state law is evaluated by ``law_eval(v, p) -> (mu_ss(v) - mu_ref, W(v))``:
  ``p[0]`` is the law's integer code (``KIND_*``) and ``p[1:]`` its parameters;
  ``mu_ref`` is a constant kept outside the kernels (the large-velocity limit where there
  is one, so that frictions just above it keep full relative precision after long
  slips); :math:`W(v) = -v\,\mathrm{d}\mu_{ss}/\mathrm{d}v` is the velocity-weakening
  rate (positive for velocity weakening).  All frictions in the kernels are relative to
  ``mu_ref``;
* the friction of the paper's model is :math:`\phi(\theta) = \mu_{ss}(D_c/\theta)` (Eq. 11),
  and :math:`u = D_c/\theta` is the "state velocity", so that
  :math:`\mathrm{d}\phi/\mathrm{d}\ln\theta = W(u)`;
* with :math:`K = k_0 D_c` the slide velocity is :math:`v = N/D` with
  :math:`N = K V - u W(u)` and :math:`D = K - W(u)`.

The kernels take plain arrays and floats only (no function arguments), so that numba's
on-disk cache (``cache=True``) serves the command line.  :func:`kernel_namespace` builds
the same set around another ``law_eval`` (a user's law), compiled or as pure Python; the
pure-Python set is also the plain reference the compiled kernels are tested against.
"""
from __future__ import annotations

import math
import types

import numba
import numpy as np
from numba import njit

# Gauss-Legendre nodes and weights (8 points on [-1, 1]).
_GL_X = np.array([
    -0.9602898564975363, -0.7966664774136267, -0.5255324099163290, -0.1834346424956498,
    0.1834346424956498, 0.5255324099163290, 0.7966664774136267, 0.9602898564975363,
])
_GL_W = np.array([
    0.1012285362903763, 0.2223810344533745, 0.3137066458778873, 0.3626837833783620,
    0.3626837833783620, 0.3137066458778873, 0.2223810344533745, 0.1012285362903763,
])

# Law codes (p[0] of a law's parameter array).
KIND_HYPERBOLIC = 0
KIND_VISCOELASTIC = 1
KIND_LOG = 2
KIND_TABLE = 3
KIND_USER = 4

# Phase codes returned by :func:`decide`.
STICK = 0
SLIDE = 1
SLIP = 2

# Kinds of :func:`phase_fn` (and :func:`phase_dfn`, :func:`brentq`, :func:`first_root`):
# numpy integers, not Python ints, so that numba types them as int64.  A literal 0 or 1
# in a jitted call is typed as Literal[int], and each of the four kernels was compiled
# once per literal, twice in all (2.4 CPU seconds for the four with an empty numba cache
# in compare's rsf warm-up, 1.2 s as int64 only; mean of three runs).
STICK_FN = np.int64(0)
SLIP_FN = np.int64(1)

# Flags returned by the root kernels.
FOUND = 0
HORIZON = 1       # no root before the time horizon (stick) / runaway slip (slip)
FAILED = 2        # iteration limit
NO_SLIP = 3       # the slip has zero length (not over-stressed)
FLOOR = 4         # the slip ended below the resolved range of theta (theta_floor)


# --------------------------------------------------------------------------------------
# steady-state laws: (v, p) -> (mu_ss, W)
# --------------------------------------------------------------------------------------
@njit(cache=True, nogil=True)
def hyperbolic_law(v, p):
    r"""Eq. (10): :math:`\mu_{ss} - \mu_\infty = A/(v + B)`, ``p = [A, B]``."""
    d = v + p[1]
    return p[0] / d, p[0] * (v / d) / d


@njit(cache=True, nogil=True)
def viscoelastic_law(v, p):
    r"""Eq. (4): :math:`\mu_{ss} - \mu_{ss}(\infty) = \bar z k_2\,(1/2 - h(y))` with
    :math:`y = \bar z k_2/(v\eta_u)` and :math:`h(y) = 1/y - 1/(e^y - 1)`;
    ``p = [zbar*k2, eta_u]``."""
    c = p[0]
    if v <= 0.0:
        return 0.5 * c, 0.0
    y = c / (v * p[1])
    if y < 0.05:
        y2 = y * y
        # excess = 1/2 - h(y)
        ex = y / 12.0 - y * y2 / 720.0 + y * y2 * y2 / 30240.0 - y * y2 * y2 * y2 / 1209600.0
        w = y / 12.0 - y * y2 / 240.0 + y * y2 * y2 / 6048.0 - y * y2 * y2 * y2 / 172800.0
    elif y > 700.0:
        ex = 0.5 - 1.0 / y
        w = 1.0 / y
    else:
        em = -math.expm1(-y)
        e = math.exp(-y)
        ex = 0.5 - 1.0 / y + e / em
        w = 1.0 / y - y * e / (em * em)
    return c * ex, c * w


@njit(cache=True, nogil=True)
def log_law(v, p):
    r"""Eq. (9): :math:`\mu_{ss} - \mu_0 = (a - b)\ln(v/v_0)`, ``p = [a - b, v0]``."""
    if v <= 0.0:
        v = 1e-300
    return p[0] * math.log(v / p[1]), -p[0]


@njit(cache=True, nogil=True)
def table_law(v, p):
    r"""Monotone cubic Hermite (PCHIP) interpolation of :math:`\mu_{ss}` in :math:`\ln v`,
    constant outside the data.  ``p = [n, x_0..x_{n-1}, y_0.., d_0..]`` with
    :math:`x = \ln v`, ``y`` the data minus the reference (the last value) and ``d`` the
    PCHIP node slopes :math:`\mathrm{d}y/\mathrm{d}x`."""
    n = int(p[0])
    if v <= 0.0:
        return p[1 + n], 0.0
    x = math.log(v)
    if x <= p[1]:
        return p[1 + n], 0.0
    if x >= p[n]:
        return p[2 * n], 0.0
    lo = 0
    hi = n - 1
    while hi - lo > 1:
        mid = (lo + hi) // 2
        if p[1 + mid] <= x:
            lo = mid
        else:
            hi = mid
    x0 = p[1 + lo]
    h = p[2 + lo] - x0
    t = (x - x0) / h
    y0 = p[1 + n + lo]
    y1 = p[2 + n + lo]
    d0 = p[1 + 2 * n + lo]
    d1 = p[2 + 2 * n + lo]
    t2 = t * t
    omt = 1.0 - t
    y = (1.0 + 2.0 * t) * omt * omt * y0 + t * omt * omt * h * d0 + t2 * (3.0 - 2.0 * t) * y1 \
        + t2 * (t - 1.0) * h * d1
    dydx = ((6.0 * t2 - 6.0 * t) * (y0 - y1)) / h + (3.0 * t2 - 4.0 * t + 1.0) * d0 \
        + (3.0 * t2 - 2.0 * t) * d1
    return y, -dydx


@njit(cache=True, nogil=True)
def law_eval(v, p):
    """Evaluate the law coded in ``p[0]`` with parameters ``p[1:]``: (mu_ss - mu_ref, W)."""
    kind = int(p[0])
    q = p[1:]
    if kind == KIND_HYPERBOLIC:
        return hyperbolic_law(v, q)
    if kind == KIND_VISCOELASTIC:
        return viscoelastic_law(v, q)
    if kind == KIND_LOG:
        return log_law(v, q)
    if kind == KIND_TABLE:
        return table_law(v, q)
    return math.nan, math.nan


# --------------------------------------------------------------------------------------
# the friction phi(theta) and accurate differences of it
# --------------------------------------------------------------------------------------
@njit(cache=True, nogil=True)
def phi_w(p, theta, Dc):
    r"""Return :math:`\phi(\theta) = \mu_{ss}(D_c/\theta)` (Eq. 11, relative to ``mu_ref``)
    and :math:`W(D_c/\theta)`."""
    return law_eval(Dc / theta, p)


@njit(cache=True, nogil=True)
def dphi(p, theta_a, log_ratio, Dc):
    r"""Return :math:`\phi(\theta_a e^{r}) - \phi(\theta_a)` for ``r = log_ratio``.

    For :math:`|r| \le 1/4` this is the 8-point Gauss-Legendre value of
    :math:`\int_0^r W(D_c e^{-\rho}/\theta_a)\,\mathrm{d}\rho`, which keeps full relative
    accuracy for small differences (no cancellation); otherwise the plain difference.
    """
    if abs(log_ratio) <= 0.25:
        half = 0.5 * log_ratio
        total = 0.0
        u_a = Dc / theta_a
        for i in range(8):
            rho = half * (1.0 + _GL_X[i])
            total += _GL_W[i] * law_eval(u_a * math.exp(-rho), p)[1]
        return half * total
    return law_eval(Dc / (theta_a * math.exp(log_ratio)), p)[0] - law_eval(Dc / theta_a, p)[0]


@njit(cache=True, nogil=True)
def phase_fn(kind, p, x, c):
    r"""The scalar functions whose first root ends a stick (``kind = 0``) or a slip
    (``kind = 1``).

    stick, ``c = [h0, theta0, k0*V, Dc]``, ``x = t``:
    :math:`h(t) = h_0 + k_0 V t - [\phi(\theta_0 + t) - \phi(\theta_0)]`;

    slip, ``c = [g0, theta0, k0*Dc, Dc]``, ``x = s = \Delta x / D_c``:
    :math:`g(s) = g_0 - k_0 D_c\, s - [\phi(\theta_0 e^{-s}) - \phi(\theta_0)]`;

    with :math:`h_0 = g_0 = \sigma_0 - \phi(\theta_0)`.
    """
    if kind == 0:
        return c[0] + c[2] * x - dphi(p, c[1], math.log1p(x / c[1]), c[3])
    return c[0] - c[2] * x - dphi(p, c[1], -x, c[3])


@njit(cache=True, nogil=True)
def phase_dfn(kind, p, x, c):
    """Derivative of :func:`phase_fn` with respect to ``x``."""
    if kind == 0:
        theta = c[1] + x
        return c[2] - law_eval(c[3] / theta, p)[1] / theta
    return -c[2] + law_eval(c[3] * math.exp(x) / c[1], p)[1]


@njit(cache=True, nogil=True)
def brentq(kind, p, c, xa, xb, fa, fb):
    """Brent's method (the algorithm of scipy's ``brentq``) on :func:`phase_fn` over a
    bracket with ``fa * fb <= 0``; returns the root to about machine precision."""
    xtol = 1e-300
    rtol = 4.0 * 2.220446049250313e-16
    xpre = xa
    xcur = xb
    fpre = fa
    fcur = fb
    xblk = 0.0
    fblk = 0.0
    spre = 0.0
    scur = 0.0
    if fpre == 0.0:
        return xpre
    if fcur == 0.0:
        return xcur
    for _ in range(200):
        if fpre != 0.0 and fcur != 0.0 and ((fpre < 0.0) != (fcur < 0.0)):
            xblk = xpre
            fblk = fpre
            spre = xcur - xpre
            scur = spre
        if abs(fblk) < abs(fcur):
            xpre = xcur
            xcur = xblk
            xblk = xpre
            fpre = fcur
            fcur = fblk
            fblk = fpre
        delta = 0.5 * (xtol + rtol * abs(xcur))
        sbis = 0.5 * (xblk - xcur)
        if fcur == 0.0 or abs(sbis) < delta:
            return xcur
        if abs(spre) > delta and abs(fcur) < abs(fpre):
            if xpre == xblk:
                stry = -fcur * (xcur - xpre) / (fcur - fpre)
            else:
                dpre = (fpre - fcur) / (xpre - xcur)
                dblk = (fblk - fcur) / (xblk - xcur)
                stry = -fcur * (fblk * dblk - fpre * dpre) / (dblk * dpre * (fblk - fpre))
            if 2.0 * abs(stry) < min(abs(spre), 3.0 * abs(sbis) - delta):
                spre = scur
                scur = stry
            else:
                spre = sbis
                scur = sbis
        else:
            spre = sbis
            scur = sbis
        xpre = xcur
        fpre = fcur
        if abs(scur) > delta:
            xcur += scur
        elif sbis > 0.0:
            xcur += delta
        else:
            xcur -= delta
        fcur = phase_fn(kind, p, xcur, c)
    return xcur


# --------------------------------------------------------------------------------------
# the stick and slip roots
# --------------------------------------------------------------------------------------
@njit(cache=True, nogil=True)
def first_root(kind, p, c, x, x_max, k0V, w_neg, lipschitz):
    r"""March from ``x`` (where the phase function has not yet crossed) to its first
    crossing, and refine it with :func:`brentq`.

    In the sign convention ``F = h`` (stick, ``kind = 0``) or ``F = -g`` (slip,
    ``kind = 1``), ``F(x) < 0`` before the root.  Each iteration first tries a Newton step:
    if it lands on ``F >= 0`` it brackets the root; if it lands short (``F < 0``, the
    function is locally concave, so the tangent lies above it) no root was stepped over and
    the Newton point is accepted.  Otherwise the march advances by the larger of a
    certified step (``F`` cannot reach 0 within it: ``-F/(k0 V)`` for the stick when the
    threshold cannot decrease, ``-F/L`` for the slip with ``L >= sup|g'|``) and a geometric
    step (half the distance travelled, at most 0.05 (stick) or 0.1 (slip) in
    :math:`\ln	heta`).  Only a pair of crossings closer than such a geometric step can be
    missed (a tangency of the trajectory with the threshold).

    Returns ``(x, flag)``: FOUND, HORIZON (no crossing up to ``x_max``) or FAILED.
    """
    sgn = 1.0 if kind == 0 else -1.0
    f = sgn * phase_fn(kind, p, x, c)
    x_start = x
    for _ in range(100000):
        fp = sgn * phase_dfn(kind, p, x, c)
        if fp > 0.0:
            xn = x - f / fp
            if xn > x_max:
                xn = x_max
            if xn > x:
                fn = sgn * phase_fn(kind, p, xn, c)
                if fn >= 0.0:
                    return brentq(kind, p, c, x, xn, sgn * f, sgn * fn), FOUND
                if xn == x_max:
                    return x_max, HORIZON
                if xn > x + 1e-3 * (x - x_start):
                    x = xn
                    f = fn
                    continue
        # certified step
        if kind == 0:
            theta = c[1] + x
            step = math.inf
            if k0V > 0.0:
                step = -f / k0V if w_neg == 0.0 else -0.5 * f / k0V
            if w_neg > 0.0:
                step = min(step, theta * math.expm1(-0.5 * f / w_neg))
            geo = min(0.5 * (x - x_start) + 1e-7 * c[1], theta * 0.05127109637602412)
        else:
            step = -f / lipschitz
            geo = min(0.5 * (x - x_start) + 1e-8, 0.1)
        if geo > step:
            step = geo
        if not (step < math.inf):
            return x_max, HORIZON
        x_new = x + step
        if x_new >= x_max:
            x_new = x_max
        f_new = sgn * phase_fn(kind, p, x_new, c)
        if f_new >= 0.0:
            return brentq(kind, p, c, x, x_new, sgn * f, sgn * f_new), FOUND
        if x_new == x_max:
            return x_max, HORIZON
        if x_new == x:
            return x, FAILED
        x = x_new
        f = f_new
    return x, FAILED


@njit(cache=True, nogil=True)
def stick_end(p, h0, theta0, k0V, Dc, t_max, w_neg, concave_sup):
    r"""First time :math:`t \in (0, t_{max}]` at which a stick started at
    :math:`(\sigma_0, \theta_0)` reaches the threshold, :math:`\sigma_0 + k_0 V t = \phi(\theta_0 + t)`
    (closed-form stick: :math:`\theta = \theta_0 + t`, :math:`\sigma = \sigma_0 + k_0 V t`).

    ``h0 = sigma0 - phi(theta0) <= 0``; ``h0 = 0`` means a start on the threshold (after a
    slip, or where a slide stops), in which case the stick first steps off by
    1e-7 theta0.  ``w_neg`` bounds :math:`\max(0, -W)` (0 for velocity-weakening laws).

    ``concave_sup`` is NaN unless :math:`\phi` is concave in :math:`\theta` (the law says
    so), in which case it is :math:`\sup\phi` (relative, inf if unbounded): then
    :math:`h(t)` is convex, a negative value anywhere certifies that no root lies before
    it, and the root is bracketed directly (between the first negative point and the time
    at which :math:`\sigma` passes :math:`\sup\phi`, or by tenfold steps) instead of
    marched to.

    Returns ``(t, flag)`` with ``flag`` one of FOUND, HORIZON (no end before ``t_max``),
    FAILED.
    """
    c = np.empty(4)
    c[0] = h0
    c[1] = theta0
    c[2] = k0V
    c[3] = Dc
    t = 0.0
    h = h0
    if h0 >= 0.0:
        t = min(1e-7 * theta0, t_max)
        h = phase_fn(STICK_FN, p, t, c)
        if h >= 0.0:
            return 0.0, FOUND
    if concave_sup == concave_sup and k0V > 0.0:
        # h convex: every negative point is certified root-free before it
        phi0 = law_eval(Dc / theta0, p)[0]
        if concave_sup < math.inf:
            t_hi = (concave_sup - (h0 + phi0)) / k0V
            t_hi = max(t_hi * (1.0 + 1e-12), t * 2.0)
        else:
            t_hi = max(10.0 * t, theta0)
        for _ in range(2000):
            if t_hi >= t_max:
                t_hi = t_max
            h_hi = phase_fn(STICK_FN, p, t_hi, c)
            if h_hi >= 0.0:
                return brentq(STICK_FN, p, c, t, t_hi, h, h_hi), FOUND
            if t_hi == t_max:
                return t_max, HORIZON
            t = t_hi
            h = h_hi
            t_hi = 10.0 * t_hi + theta0
        return t, FAILED
    return first_root(STICK_FN, p, c, t, t_max, k0V, w_neg, 1.0)


@njit(cache=True, nogil=True)
def slip_end(p, g0, theta0, K, Dc, lipschitz, theta_floor):
    r"""First root :math:`s > 0` of the slip function :math:`g(s)` of :func:`phase_fn`:
    the instantaneous slip :math:`\Delta x = D_c s` with :math:`\theta = \theta_0 e^{-s}` and
    :math:`\sigma = \sigma_0 - k_0 \Delta x` stops when :math:`\sigma = \phi(\theta)` again
    (paper, Sec. V.B).  ``lipschitz`` :math:`\ge \sup|g'| = K + \sup|W|`.

    Below ``theta_floor`` the state is not resolved: if the slip reaches it still
    over-stressed and :math:`D = K - W > 0` there (the threshold has levelled off, as for
    laws with a finite large-velocity limit), the rest of the slip is the linear
    continuation :math:`\Delta s = g/D`, and the flag is FLOOR (landing at ``theta_floor``).

    Returns ``(s, flag)`` with ``flag`` one of FOUND, FLOOR, HORIZON (runaway: no arrest),
    FAILED, NO_SLIP.
    """
    c = np.empty(4)
    c[0] = g0
    c[1] = theta0
    c[2] = K
    c[3] = Dc
    s_max = math.log(theta0 / theta_floor)
    if s_max <= 0.0:
        s_max = 1e-300
    s = 0.0
    if g0 <= 0.0:
        # on the threshold: the slip exists only if g rises just after s = 0
        found = False
        for trial in (1e-8, 1e-6, 1e-4):
            if trial < s_max and phase_fn(SLIP_FN, p, trial, c) > 0.0:
                s = trial
                found = True
                break
        if not found:
            return 0.0, NO_SLIP
    s, flag = first_root(SLIP_FN, p, c, s, s_max, 0.0, 0.0, lipschitz)
    if flag == HORIZON:
        g = phase_fn(SLIP_FN, p, s_max, c)
        d = K - law_eval(Dc / theta_floor, p)[1]
        if d > 0.0:
            return s_max + max(g, 0.0) / d, FLOOR
    return s, flag


@njit(cache=True, nogil=True)
def decide(p, theta, K, V, Dc):
    r"""The phase that follows a point on the threshold :math:`\sigma = \phi(\theta)`.

    With :math:`N = KV - uW` and :math:`D = K - W`: stick if :math:`N < 0` (the stick flow
    stays below the threshold); otherwise slide if :math:`D > 0` (then
    :math:`v = N/D \ge 0` is finite) and slip if :math:`D < 0`.  Tangent cases
    (:math:`N \approx 0` or :math:`D \approx 0`, relative 1e-12) are settled by probing
    the stick and slip functions a small step ahead.
    """
    u = Dc / theta
    w = law_eval(u, p)[1]
    N = K * V - u * w
    D = K - w
    scale_n = K * V + u * abs(w) + 1e-300
    scale_d = K + abs(w)
    c = np.empty(4)
    if N < -1e-12 * scale_n:
        return STICK
    if N <= 1e-12 * scale_n:
        c[0] = 0.0
        c[1] = theta
        c[2] = K * V / Dc
        c[3] = Dc
        if phase_fn(STICK_FN, p, 1e-5 * theta, c) < 0.0:
            return STICK
    if D > 1e-12 * scale_d:
        return SLIDE
    if D < -1e-12 * scale_d:
        return SLIP
    c[0] = 0.0
    c[1] = theta
    c[2] = K
    c[3] = Dc
    if phase_fn(SLIP_FN, p, 1e-5, c) > 0.0:
        return SLIP
    return SLIDE


@njit(cache=True, nogil=True)
def slide_converges(p, u_s, V, K):
    r"""Whether a slide started at state velocity ``u_s`` certainly converges to steady
    sliding at ``V`` without an event.

    In a slide :math:`u` moves monotonically from :math:`u_s` towards :math:`V` (the reduced
    ODE is one-dimensional), so it converges iff neither :math:`D = K - W` nor
    :math:`N = KV - uW` vanishes on the way.  Both are sampled on a grid in :math:`\ln u`
    (spacing at most 0.01); the answer is True only if every sample is positive with a
    margin of four times the largest change between neighbouring samples, so that no root
    can hide between them.  False means "integrate and see".
    """
    span = math.log(V / u_s)
    n = int(abs(span) / 0.01) + 8
    if n > 4000:
        return False
    d_min = math.inf
    n_min = math.inf
    dd = 0.0
    dn = 0.0
    d_prev = 0.0
    n_prev = 0.0
    for i in range(n + 1):
        u = u_s * math.exp(span * i / n)
        w = law_eval(u, p)[1]
        d = K - w
        nn = K * V - u * w
        if d <= 0.0 or nn <= 0.0:
            return False
        if i > 0:
            dd = max(dd, abs(d - d_prev))
            dn = max(dn, abs(nn - n_prev))
        d_min = min(d_min, d)
        n_min = min(n_min, nn)
        d_prev = d
        n_prev = nn
    return d_min > 4.0 * dd and n_min > 4.0 * dn


# --------------------------------------------------------------------------------------
# the slide: CVODE right-hand side and events in the desingularised time tau
# --------------------------------------------------------------------------------------
@njit(cache=True, nogil=True)
def slide_rhs(y, yp, p, c):
    r"""Reduced slide ODE in the time :math:`\tau` with :math:`\mathrm{d}t = D_c D/(K v_s)\,\mathrm{d}\tau`.

    ``y = [z, t, I]`` with :math:`\theta = \theta_s e^{z}`, local time ``t`` and
    :math:`I = \int\sigma\,\mathrm{d}t`; ``c = [K, V, Dc, v_s, u_s, ...]`` where
    :math:`u_s = D_c/\theta_s` (the fields of :class:`rsf.engines.phase.SlideConstants`).  From Eqs. (8), (11), (12):
    :math:`\mathrm{d}z/\mathrm{d}\tau = (u - V)/v_s`.
    """
    K = c[0]
    u = c[4] * math.exp(-y[0])
    mu, w = law_eval(u, p)
    dt = c[2] * (K - w) / (K * c[3])
    yp[0] = (u - c[1]) / c[3]
    yp[1] = dt
    yp[2] = mu * dt


@njit(cache=True, nogil=True)
def slide_events(y, e, p, c):
    """Slide events: ``e[0]`` D (slide -> slip), ``e[1]`` N (v -> 0, slide -> stick),
    ``e[2]`` |ln(u/V)| - s_tol (steady), ``e[3]`` W (interior extremum of sigma),
    ``e[4]`` t - t_stop (the indices of :class:`rsf.engines.phase.SlideEvent`).
    ``c[5:10] = [s_tol, t_stop, ln V, steady_on, extrema_on]`` (``extrema_on`` only for laws
    whose W changes sign)."""
    K = c[0]
    V = c[1]
    u = c[4] * math.exp(-y[0])
    w = law_eval(u, p)[1]
    scale_d = K + abs(w)
    e[0] = (K - w) / scale_d
    scale_n = K * V + u * abs(w)
    if scale_n > 0.0:
        e[1] = (K * V - u * w) / scale_n
    else:
        e[1] = 1.0
    if c[8] > 0.0:
        e[2] = abs(math.log(u) - c[7]) - c[5]
    else:
        e[2] = 1.0
    if c[9] > 0.0:
        e[3] = w / scale_d
    else:
        e[3] = 1.0
    e[4] = (y[1] - c[6]) / (abs(c[6]) + c[2] / c[3])


# --------------------------------------------------------------------------------------
# a > 0: the regular rate-and-state ODE
# --------------------------------------------------------------------------------------
@njit(cache=True, nogil=True)
def rs_rhs(y, yp, p, c):
    r"""Spring-slider with a direct effect :math:`a > 0`:
    :math:`\mu = \mu_{ss}(u) + a\ln(v/u)` with :math:`u = D_c/\theta`
    (:func:`rs_rhs_dr` with the built-in state laws)."""
    rs_rhs_dr(y, yp, p, c, 0.0)


@njit(cache=True, nogil=True, inline="always")
def _state_rate(code, w, r, f, g):
    r"""d ln(theta)/ds of a built-in state law (``code`` 0 aging, 1 slip, 2 PRZ; 3, Nagata,
    gives its aging part) at :math:`w = \ln(v/v_s)`, :math:`r = \ln(v_s\theta/D_c)`, with
    :math:`f = v_s/(v_s + v)`, :math:`g = 1 - f`."""
    if code == 1.0:
        return -g * (w + r)
    if code == 2.0:
        return 0.5 * (math.exp(-r) * f - g * math.exp(min(w + r, 700.0)))
    return math.exp(-r) * f - g


@njit(cache=True, nogil=True)
def rs_rhs_dr(y, yp, p, c, dr_user):
    r"""Spring-slider with a direct effect :math:`a > 0`, optional radiation damping
    :math:`\eta` and an optional second state variable.

    Force balance :math:`k_0(X(t) - x) = \mu + \eta v` with
    :math:`\mu = \mu_{ss}(u) + a\ln(v/u) + b_2\ln(v_0\theta_2/D_{c2})`,
    :math:`u = D_c/\theta`.  Differentiating it gives

    .. math::
        (a + \eta v)\,\frac{\mathrm{d}\ln v}{\mathrm{d}t} = k_0(V - v)
        - (W + a)\,\frac{\mathrm{d}\ln\theta}{\mathrm{d}t}
        - b_2\,\frac{\mathrm{d}\ln\theta_2}{\mathrm{d}t},

    with :math:`\mathrm{d}\ln\theta/\mathrm{d}t` from the state law (code ``c[4]``:
    0 aging :math:`(u - v)/D_c`, 1 slip :math:`-(v/D_c)\ln(v/u)`, 2 PRZ
    :math:`(u/2D_c)(1 - (v/u)^2)`, 3 Nagata: aging :math:`- (c/b)\,\dot\mu`, solved
    together with the equation above since :math:`\dot\mu` holds :math:`\eta\dot v`;
    4 ``dr_user``, computed outside).  The independent variable is the dimensionless
    :math:`s` with :math:`\mathrm{d}s = (v_s + v)\,\mathrm{d}t/D_c`, which follows time
    in slow phases and slip in fast ones, so that the nearly instantaneous slips of small
    :math:`a` stay resolvable; with :math:`f = v_s/(v_s + v)` (computed from
    :math:`\ln v` without overflow) every rate below is bounded.

    ``y = [w, r, x, I, t(, q2)]`` with :math:`w = \ln(v/v_s)`, :math:`r = \ln(v_s/u)`,
    :math:`q_2 = \ln(v_s\theta_2/D_{c2})` (all 0 in steady sliding at :math:`V = v_s`,
    so that event functions near it are not differences of large numbers) and
    :math:`I = \int (\mu - \mu_{ref})\,\mathrm{d}t`;
    ``c = [K, V, Dc, a, state_law, v_s, ...events..., eta, c/b, b2, Dc/Dc2, ln(v0/v_s),
    dV/dt, t_0]`` (indices 12 to 18; with a ramp :math:`V(t) = V + \dot V (t - t_0)`): the
    fields of :class:`rsf.engines.smooth.RsConstants`, in order.
    """
    K = c[0]
    V = c[1]
    if c[17] != 0.0:                 # a sampled history: V ramps linearly in t
        V = max(V + c[17] * (y[4] - c[18]), 0.0)
    Dc = c[2]
    a = c[3]
    code = c[4]
    vs = c[5]
    eta = c[12]
    cb = c[13]
    b2 = c[14]
    w = y[0]
    r = y[1]
    if w > 0.0:
        ew = math.exp(-w)
        f = ew / (1.0 + ew)
    else:
        f = 1.0 / (1.0 + math.exp(w))
    g = 1.0 - f                      # v / (vs + v)
    er = math.exp(-r)                # u / vs
    mu, wk = law_eval(vs * er, p)
    dr0 = dr_user if code == 4.0 else _state_rate(code, w, r, f, g)
    dq2 = 0.0
    mu2 = 0.0
    if b2 > 0.0:
        q2 = y[5]
        dq2 = c[15] * _state_rate(code, w, q2, f, g)   # the same law, in units of Dc2
        mu2 = b2 * (q2 + c[16])
    stress = K * ((V / vs) * f - g)  # d(spring force)/ds
    damp = eta * vs * math.exp(min(w, 700.0)) if eta > 0.0 else 0.0   # eta v
    wa = wk + a
    if code == 3.0:
        dw = (stress - wa * (dr0 - cb * stress) - b2 * dq2) / (a + damp + wa * cb * damp)
        dr = dr0 - cb * (stress - damp * dw)
    else:
        dr = dr0
        dw = (stress - wa * dr - b2 * dq2) / (a + damp)
    dt = Dc / vs * f
    yp[0] = dw
    yp[1] = dr
    yp[2] = Dc * g
    yp[3] = (mu + a * (w + r) + mu2) * dt
    yp[4] = dt
    if b2 > 0.0:
        yp[5] = dq2


@njit(cache=True, nogil=True)
def rs_events(y, e, p, c):
    """Events of the a > 0 ODE: ``e[0]`` and ``e[1]`` ln(v/V) (sigma maximum when rising,
    minimum when falling), ``e[2]`` distance to the steady state minus s_tol, ``e[3]``
    t - t_stop, ``e[4]`` ln(v/v_max) (runaway); with a ramp ``c[17] != 0`` the extrema are
    at v = V(t) and there is no steady state (the indices of
    :class:`rsf.engines.smooth.RsEvent`).
    ``c[6:12] = [ln(V/v_s), ln(v_s/V), s_tol, steady_on, t_stop, ln(v_max/v_s)]``."""
    if c[17] != 0.0:                 # a ramp: extrema of the spring force at v = V(t)
        V = c[1] + c[17] * (y[4] - c[18])
        e[0] = y[0] - math.log(V / c[5]) if V > 0.0 else 1.0
        e[1] = e[0]
        e[2] = 1.0
    elif c[1] > 0.0:
        e[0] = y[0] - c[6]
        e[1] = e[0]
        if c[9] > 0.0:
            e[2] = abs(y[0] - c[6]) + abs(y[1] - c[7]) - c[8]
            if c[14] > 0.0:
                e[2] += abs(y[5] - c[7])
        else:
            e[2] = 1.0
    else:
        e[0] = 1.0
        e[1] = 1.0
        e[2] = 1.0
    e[3] = y[4] - c[10]
    e[4] = y[0] - c[11]


# --------------------------------------------------------------------------------------
# the same kernels around another law
# --------------------------------------------------------------------------------------
KERNEL_NAMES = ("law_eval", "phi_w", "dphi", "phase_fn", "phase_dfn", "brentq", "first_root",
                "stick_end", "slip_end", "decide", "slide_converges", "slide_rhs",
                "slide_events", "rs_rhs_dr", "rs_rhs", "rs_events")


def kernel_namespace(law_eval_func=None, jit: bool = False) -> dict:
    """A fresh set of the kernels of this module in which ``law_eval`` is replaced by
    ``law_eval_func`` (default: keep the built-in dispatch).

    With ``jit=False`` every kernel is plain Python (its source, calling the other
    plain-Python kernels); with ``jit=True`` they are compiled with numba for this law
    (not cached on disk: a user's law is a new function in every process).
    """
    namespace: dict = dict(globals())
    plain: dict = {}
    for name in KERNEL_NAMES:
        func = globals()[name].py_func
        plain[name] = types.FunctionType(func.__code__, namespace, name, func.__defaults__,
                                         func.__closure__)
    if law_eval_func is not None:
        plain["law_eval"] = law_eval_func
    else:
        for name in ("hyperbolic_law", "viscoelastic_law", "log_law", "table_law"):
            func = globals()[name].py_func
            plain[name] = types.FunctionType(func.__code__, namespace, name)
    namespace.update(plain)
    if jit:
        compiled = {name: (f if isinstance(f, numba.core.registry.CPUDispatcher) else njit(f))
                    for name, f in plain.items()}
        namespace.update(compiled)
        return {name: namespace[name] for name in KERNEL_NAMES}
    return {name: namespace[name] for name in KERNEL_NAMES}
