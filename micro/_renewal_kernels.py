"""Numba kernels of the jump-to-jump renewal chain (see :mod:`micro.renewal`).

Everything here is in the chain's own units: time in 1/gamma, lengths in V/gamma, the
margin delta in kappa*V/gamma.  A block that has just jumped by zeta, with deficit
``D = x + zeta`` of its k2-spring below V*tau, next reaches the threshold after the
time t that solves

    alpha * t + beta * D * (1 - exp(-t)) = zeta,        alpha = (k0+k1)/kappa, beta = k2/kappa,

and arrives there with deficit ``x' = D * exp(-t)``.  The assembly, and through it
every kernel here, has a plain-numpy twin in the tests (``tests/micro/test_renewal.py``).
"""
from __future__ import annotations

import math

import numpy as np
from numba import njit

#: Newton iterations of the waiting time before giving up (it takes a few).
MAX_NEWTON = 80


@njit(cache=True, nogil=True)
def waiting_time(zeta: float, D: float, alpha: float, beta: float) -> float:
    """Root t > 0 of ``alpha t + beta D (1 - e^-t) = zeta``: the time to the next jump.

    The left side F + zeta is increasing and concave in t, so Newton from a lower bound
    increases monotonically to the root.  Two lower bounds: ``zeta / (alpha + beta D)``
    (the tangent at 0) and, for a long wait, ``(zeta - beta D) / alpha`` (where F =
    -beta D e^-t < 0).  Once a step is below 1e-9 t the next iterate is exact to
    round-off (quadratic convergence): take it and stop.  The bracket guards round-off.
    """
    if zeta <= 0.0:
        return 0.0
    lo = zeta / (alpha + beta * D)
    hi = math.inf
    if alpha > 0.0:
        hi = zeta / alpha
        lo = max(lo, (zeta - beta * D) / alpha)
    if zeta < beta * D:
        hi = min(hi, -math.log1p(-zeta / (beta * D)))
    t = lo
    for _ in range(MAX_NEWTON):
        F = alpha * t - beta * D * math.expm1(-t) - zeta
        dF = alpha + beta * D * math.exp(-t)
        if F > 0.0:
            hi = min(hi, t)
        else:
            lo = max(lo, t)
        step = F / dF
        tn = t - step
        if not (lo <= tn <= hi):
            tn = 0.5 * (lo + hi) if math.isfinite(hi) else 2.0 * t
        if abs(tn - t) <= 1e-9 * tn:
            return tn
        t = tn
    return t


@njit(cache=True, nogil=True)
def phi2(t: float) -> float:
    """``(t - 1 + e^-t) / t^2`` without cancellation (a series below t = 0.1)."""
    if t < 0.1:
        term = 0.5
        total = 0.5
        k = 2.0
        for _ in range(10):
            k += 1.0
            term *= -t / k
            total += term
        return total
    return (t + math.expm1(-t)) / (t * t)


@njit(cache=True, nogil=True)
def margin_integral(zeta: float, D: float, t: float, alpha: float, beta: float) -> float:
    """Integral of the margin from a jump to the next, ``zeta t - alpha t^2/2 - beta D
    (t - 1 + e^-t)``: a positive integrand, written without cancellation."""
    return t * (zeta - 0.5 * alpha * t - beta * D * t * phi2(t))


@njit(cache=True, nogil=True)
def displacement(x: float, zeta: float, t: float, alpha: float) -> float:
    """``x' - x`` without cancellation.  From the waiting-time equation,
    ``x' - x = alpha (t - D (1 - e^-t)) = alpha (t (1 - D) + D (t - 1 + e^-t))``, whose terms
    are small where the chain is close to the identity (large V, small k0); for t > 1
    the direct difference is accurate."""
    D = x + zeta
    if t > 1.0:
        return D * math.exp(-t) - x
    return alpha * (t * ((1.0 - x) - zeta) + D * t * t * phi2(t))


@njit(cache=True, nogil=True)
def asinh_difference(a: float, b: float, eps: float) -> float:
    """``asinh(a) - asinh(b)`` for ``a = b + eps`` with eps known accurately."""
    if b < 0.0:
        return -asinh_difference(-a, -b, -eps)
    sa, sb = math.sqrt(1.0 + a * a), math.sqrt(1.0 + b * b)
    return math.log1p(eps * (1.0 + (a + b) / (sa + sb)) / (b + sb))


@njit(cache=True, nogil=True)
def theta_offset(x: float, dx: float, c: float, w: float, mu: float, nu: float) -> float:
    """``theta(x + dx) - theta(x)`` with the relative accuracy of dx."""
    if not math.isfinite(w):
        return 2.0 * dx
    return asinh_difference((x + dx - c) / w, (x - c) / w, dx / w) / nu


@njit(cache=True, nogil=True)
def lagrange_row(i: int, offset: float, nodes: np.ndarray, bw: np.ndarray, out: np.ndarray) -> None:
    """``out[j] = l_j(nodes[i] + offset)``, the Lagrange basis on ``nodes`` (barycentric
    form), with the distances to the nodes taken as ``offset + (nodes[i] - nodes[k])`` so
    that a small offset keeps its relative accuracy."""
    n = nodes.shape[0]
    for k in range(n):
        d = offset + (nodes[i] - nodes[k])
        if abs(d) < 1e-300:
            for j in range(n):
                out[j] = 0.0
            out[k] = 1.0
            return
        out[k] = bw[k] / d
    total = 0.0
    for k in range(n):
        total += out[k]
    for k in range(n):
        out[k] /= total


@njit(cache=True, nogil=True)
def assemble(xn, thn, bw, zeta, wz, alpha, beta, c, w, mu, nu, store):
    """The chain on the collocation grid.

    Returns the generator ``Q = M - I`` of the expectation operator
    ``M[i, j] = E_z l_j(x'(x_i, z))``, with each diagonal entry set to minus the sum of its
    row's off-diagonal ones (the basis sums to 1): near the identity (large V, small k0)
    the off-diagonal entries keep their relative accuracy where ``M - I`` would lose it.
    Also returns the mean waiting time ``Et[i]`` and the mean integral of the margin over
    a waiting time ``EI[i]`` from each node; with ``store``, also the waiting times
    ``t[i, q]``, the arrival deficits ``xp[i, q]`` and the basis rows ``L[i, q, :]`` at
    the arrivals (for the linear stability); otherwise empty arrays.
    """
    n = xn.shape[0]
    nq = zeta.shape[0]
    M = np.zeros((n, n))
    Et = np.zeros(n)
    EI = np.zeros(n)
    if store:
        T = np.empty((n, nq))
        XP = np.empty((n, nq))
        L = np.empty((n, nq, n))
    else:
        T = np.empty((0, 0))
        XP = np.empty((0, 0))
        L = np.empty((0, 0, 0))
    row = np.empty(n)
    for i in range(n):
        x = xn[i]
        for q in range(nq):
            z = zeta[q]
            D = x + z
            t = waiting_time(z, D, alpha, beta)
            dx = displacement(x, z, t, alpha)
            xp = min(max(x + dx, 0.0), 1.0)
            dth = theta_offset(x, dx, c, w, mu, nu)
            dth = min(max(dth, -1.0 - thn[i]), 1.0 - thn[i])
            lagrange_row(i, dth, thn, bw, row)
            wq = wz[q]
            for j in range(n):
                if j != i:
                    M[i, j] += wq * row[j]
            Et[i] += wq * t
            EI[i] += wq * margin_integral(z, D, t, alpha, beta)
            if store:
                T[i, q] = t
                XP[i, q] = xp
                for j in range(n):
                    L[i, q, j] = row[j]
        off = 0.0
        for j in range(n):
            if j != i:
                off += M[i, j]
        M[i, i] = -off
    return M, Et, EI, T, XP, L
