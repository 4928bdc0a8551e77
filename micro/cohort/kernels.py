"""Numba kernels of :mod:`micro.cohort` (the loading phase as cohorts of exponential margins).

Layout: cohort ``c`` has scalars (birth time ``t0``, mean slip ``X0`` and stress ``s0`` at
birth, the dashpot integral ``J``, and ``Ej = exp(-gamma a)`` with ``a`` how long before
``t0`` its members made their last jumps, on average), and ``nn[c]`` cells of width ``h`` in delta_R starting
at node ``j0[c]``, stored from ``off[c]``: cell ``k`` keeps the density ``q`` at both of its
ends (at ``2 (off + k)`` and ``2 (off + k) + 1``) and its floor ``m`` (in units of the margin
at birth), piecewise linear with at most one kink: at ``4 (off + k)`` the values at the
two ends, the kink's position (local coordinate; 1 when there is none) and the value
there.  ``co[c]`` holds the step's coefficients: beta (the margin's response to the margin
at birth, aged by ``a`` more than the rest), the threshold ``D``
at delta_R = 0, dD/d(delta_R), dD/d(dX), exp(-gamma age), and the smallest gap between
floor and threshold at dX = 0 (cohorts that cannot cross are skipped).

Threads: :func:`closure`, :func:`smallest_root` and :func:`commit` are called from Python;
each first sets numba's thread count to the cores free to this process
(:func:`micro._threads.use_free_cores`: serial beside other busy processes, where
numba's OpenMP threads spun at every join and made two runs at once on 2 cores 6 to 60
times slower each).  Jitted code calls the kernels ``_closure``, ``_smallest_root`` and
``_commit`` directly.  Where numba has one thread only for good (``NUMBA_NUM_THREADS=1``,
as in compare's pool workers) they run serial twins instead (:func:`_serial_twins`): the
same numbers, and less to compile.
"""
import functools
import math
import types

import numpy as np
from numba import njit, prange

from .._threads import one_numba_thread, use_free_cores

#: The cohorts are summed in this many interleaved chunks (the order of the sums does not
#: depend on the number of threads), in parallel from PARALLEL_COHORTS cohorts on.
CHUNKS = 8
PARALLEL_COHORTS = 64


@njit(cache=True)
def coefficients(t, dt, X, sigma, V, k0, k1, k2, f_th, gamma, t0, X0, s0, J, Ej, n, co, j0, nn, off, q, m, ylo, h):
    """Fill ``co`` for a step of length ``dt`` from time ``t`` (slip ``X``, stress ``sigma``):
    a member born with margin delta' crosses once delta' <= D0 + Dy delta_R + D1 dX, dX the
    step's slip (the step's drive, dashpot relaxation and redistribution in it).  Returns
    the weight of dX in the step's dashpot integral and exp(-gamma dt)."""
    kappa = k0 + k1 + k2
    r2 = k2 / kappa
    alpha = 1.0 - r2
    Edt = math.exp(-gamma * dt)
    phi = 1.0 - (1.0 - Edt) / (gamma * dt) if dt > 0 else 0.0
    b1 = k0 - kappa + k2 * phi
    for c in range(n):
        E = math.exp(-gamma * (t + dt - t0[c]))
        beta = 1.0 - r2 * (1.0 - E)
        # the margin's response to the members' own last jumps, made on average a time
        # -log(Ej) / gamma before t0 (the step they were born in)
        beta_j = 1.0 - r2 * (1.0 - E * Ej[c])
        dX0 = X - X0[c]
        b0 = (f_th - sigma - k0 * V * dt - beta * (f_th - s0[c]) - kappa * dX0 + k2 * (J[c] * Edt + dX0 * (1.0 - Edt)))
        co[c, 0] = beta_j
        co[c, 1] = -b0 / beta_j  # D at y = 0
        co[c, 2] = alpha * (1.0 - E) / beta_j  # dD/dy
        co[c, 3] = -b1 / beta_j  # dD/ddX
        co[c, 4] = E
        # the smallest gap between the floor and the threshold at dX = 0: no member of
        # the cohort crosses while co[c, 3] * dX stays below it
        gap = math.inf
        o = off[c]
        for k in range(nn[c]):
            if q[2 * (o + k)] == 0.0 and q[2 * (o + k) + 1] == 0.0:
                continue
            d0 = co[c, 1] + co[c, 2] * (ylo + (j0[c] + k) * h)
            i4 = 4 * (o + k)
            dh = co[c, 2] * h
            g = min(m[i4] - d0, m[i4 + 1] - d0 - dh, m[i4 + 3] - d0 - dh * m[i4 + 2])
            if g < gap:
                gap = g
        co[c, 5] = gap
    return phi, Edt


@njit(cache=True)
def _i1(A, B, c, e):
    """int_0^1 (A + B s) exp(-c - e s) ds: by its series for |e| < 0.5 (the closed form
    loses digits there: (1 - e^-e (1 + e)) / e^2 about 1e-16 / e^2 of them), summed until
    a term falls below 1e-17 (the sums are 1/2 to 1), else in closed form."""
    if abs(e) < 0.5:
        # sum_n (-e)^n / n! * (A / (n + 1) + B / (n + 2)); the 19th term is below 1e-21
        term = 1.0
        a_sum = 0.0
        b_sum = 0.0
        for n in range(19):
            a_sum += term / (n + 1)
            b_sum += term / (n + 2)
            term *= -e / (n + 1)
            if abs(term) < 1e-17:
                break
        return math.exp(-c) * (A * a_sum + B * b_sum)
    ee = math.exp(-e)
    return math.exp(-c) * (A * (1 - ee) / e + B * (1 - ee * (1 + e)) / (e * e))


@njit(cache=True)
def _i2(A, B, C, c, e):
    """int_0^1 (A + B s + C s^2) exp(-c - e s) ds, as :func:`_i1`."""
    if abs(e) < 0.5:
        term = 1.0
        a_sum = 0.0
        b_sum = 0.0
        c_sum = 0.0
        for n in range(19):
            a_sum += term / (n + 1)
            b_sum += term / (n + 2)
            c_sum += term / (n + 3)
            term *= -e / (n + 1)
            if abs(term) < 1e-17:
                break
        return math.exp(-c) * (A * a_sum + B * b_sum + C * c_sum)
    ee = math.exp(-e)
    e2 = e * e
    return math.exp(-c) * (A * (1 - ee) / e + B * (1 - ee * (1 + e)) / e2 + C * (2 - ee * (e2 + 2 * e + 2)) / (e2 * e))


@njit(cache=True)
def _isub(q0, q1, m0, m1, a, b, lam):
    """int_a^b q(s) exp(-m(s)/lam) ds, with q and m linear on [0, 1]."""
    L = b - a
    return L * _i1(q0 + (q1 - q0) * a, (q1 - q0) * L, (m0 + (m1 - m0) * a) / lam, (m1 - m0) * L / lam)


@njit(cache=True)
def _piece(m, i4, p):
    """Piece ``p`` (0: before the kink, 1: after it) of a cell's floor: its range [lo, hi]
    and the floor's line there, as its values at the cell's ends (0 and 1); lo == hi if
    the piece is empty."""
    m0 = m[i4]; m1 = m[i4 + 1]; sk = m[i4 + 2]; mk = m[i4 + 3]
    if p == 0:
        if sk <= 0.0:
            return 0.0, 0.0, m0, m0
        slope = (mk - m0) / sk
        return 0.0, sk, m0, m0 + slope
    if sk >= 1.0:
        return 1.0, 1.0, m1, m1
    slope = (m1 - mk) / (1.0 - sk)
    return sk, 1.0, m1 - slope, m1


@njit(cache=True)
def _piece_range(d0, d1, f0, f1, lo, hi):
    """The part [a, b] of [lo, hi] where the threshold (d0 -> d1 over the cell) is above the
    floor's line (f0 -> f1); (-1, -1) if none."""
    if hi <= lo:
        return -1.0, -1.0
    gl = (d0 - f0) + ((d1 - f1) - (d0 - f0)) * lo
    gh = (d0 - f0) + ((d1 - f1) - (d0 - f0)) * hi
    if gl <= 0.0 and gh <= 0.0:
        return -1.0, -1.0
    if gl > 0.0 and gh > 0.0:
        return lo, hi
    sc = lo + (hi - lo) * gl / (gl - gh)
    if gl > 0.0:
        return lo, sc
    return sc, hi


@njit(cache=True)
def _floor_at(m, i4, s):
    """A cell's floor at local coordinate ``s``."""
    sk = m[i4 + 2]
    if s <= sk:
        return m[i4] + (m[i4 + 3] - m[i4]) * (s / sk) if sk > 0.0 else m[i4 + 3]
    return m[i4 + 3] + (m[i4 + 1] - m[i4 + 3]) * ((s - sk) / (1.0 - sk))


@njit(cache=True)
def _survivors_cell(q0, q1, m, i4, lam):
    S = 0.0
    for p in range(2):
        lo, hi, f0, f1 = _piece(m, i4, p)
        if hi > lo:
            S += _isub(q0, q1, f0, f1, lo, hi, lam)
    return S


@njit(cache=True)
def _cell(Da, Dy, ylo, j, h, index, q):
    """Cell ``index`` of the pool, at node ``j``: its left edge in delta_R, the threshold at
    its two ends, where its floor is stored, and its density at its two ends."""
    y0 = ylo + j * h
    d0 = Da + Dy * y0
    return y0, d0, d0 + Dy * h, 4 * index, q[2 * index], q[2 * index + 1]


@njit(cache=True)
def _closure_cohort(c, dX, co, j0, nn, off, q, m, ylo, h, lam):
    """Cohort ``c``'s jumps per block in the step if its slip is ``dX``, and their
    derivative in dX (:func:`closure`)."""
    N = 0.0
    dN = 0.0
    if co[c, 3] * dX <= co[c, 5]:
        return N, dN
    beta = co[c, 0]
    Da = co[c, 1] + co[c, 3] * dX
    Dy = co[c, 2]
    D1 = co[c, 3]
    o = off[c]
    for k in range(nn[c]):
        y0, d0, d1, i4, q0, q1 = _cell(Da, Dy, ylo, j0[c] + k, h, o + k, q)
        if q0 == 0.0 and q1 == 0.0:
            continue
        for p in range(2):
            lo, hi, ma, mb = _piece(m, i4, p)
            a, b = _piece_range(d0, d1, ma, mb, lo, hi)
            if a < 0.0:
                continue
            # first crossings, exact
            below = _isub(q0, q1, d0, d1, a, b, lam)
            cross = _isub(q0, q1, ma, mb, a, b, lam) - below
            dcross = below / lam
            # re-jumps, exact: beta / lam * int q (D - m) exp(-m / lam) - cross
            L = b - a
            qa = q0 + (q1 - q0) * a
            qd = (q1 - q0) * L
            ga = (d0 - ma) + ((d1 - d0) - (mb - ma)) * a
            gd = ((d1 - d0) - (mb - ma)) * L
            over = L * _i2(qa * ga, qa * gd + qd * ga, qd * gd, (ma + (mb - ma) * a) / lam, (mb - ma) * L / lam)
            rej = beta / lam * (over - lam * cross)
            drej = beta / lam * (cross)
            N += h * (cross + rej)
            dN += h * (dcross + drej) * D1
    return N, dN


@njit(cache=True, parallel=True)
def _closure(dX, n, co, j0, nn, off, q, m, ylo, h, lam, zbar):
    """H(dX) = zbar * (jumps per block in the step if the slip is dX) - dX, and dH/d(dX).
    First crossings are integrated exactly over each cell's crossed part; a block that
    crossed jumps again as a Poisson process of rate 1/lam in its margin's overshoot
    (exponential jumps), also integrated exactly.  (By two Gauss-Legendre points, as
    before, the re-jumps of a shock at small k0, some 7000 per block at k0 = 1e-4, were
    off by about 1e-6 of the slip: every block's lag then moved from the mean slip,
    which nothing in the dynamics restores, and at k0 = 1e-4 the cycle's stress kept
    an offset of up to 1e-4 that depended on the start.)
    The cohorts are summed in CHUNKS interleaved chunks, in parallel when there are at
    least PARALLEL_COHORTS of them (the same sums in the same order either way)."""
    parts = np.zeros((CHUNKS, 2))
    if n >= PARALLEL_COHORTS:
        for k in prange(CHUNKS):
            for c in range(k, n, CHUNKS):
                Nc, dNc = _closure_cohort(c, dX, co, j0, nn, off, q, m, ylo, h, lam)
                parts[k, 0] += Nc
                parts[k, 1] += dNc
    else:
        for k in range(CHUNKS):
            for c in range(k, n, CHUNKS):
                Nc, dNc = _closure_cohort(c, dX, co, j0, nn, off, q, m, ylo, h, lam)
                parts[k, 0] += Nc
                parts[k, 1] += dNc
    N = 0.0
    dN = 0.0
    for k in range(CHUNKS):
        N += parts[k, 0]
        dN += parts[k, 1]
    return zbar * N - dX, zbar * dN - 1.0


# the round-off of H relative to the slip, from H evaluated about converged roots (a few
# 1e-16 to 1.5e-15 of slips of 4e-4 to 9e-4): a root is known no better than ROUND x / |H'|.
# (At a slip of 1e-6 the round-off was 1e-18, 1e-12 of it: there the stop below is not met
# by the round-off term, and the iteration ends in its bracket at that round-off instead,
# tests/micro/test_cohort.py::test_step_roots_are_the_first_sign_change_of_the_closure_even_next_to_a_fold.)
ROUND = 2e-15


@njit(cache=True)
def _quadratic_step(H, dH, c):
    """The step to the first zero of H + dH u + c u^2 (Newton's step when c = 0, and when
    the parabola has no zero)."""
    disc = dH * dH - 4.0 * c * H
    if disc < 0.0:
        return -H / dH
    return 2.0 * H / (-dH + math.sqrt(disc))


@njit(cache=True)
def _converged(step, x, tol, dH):
    """A Newton step this small is below what the root is known to: ``1e-13 x + tol``, or
    the round-off of H over its slope (which dominates close to a fold, where H' -> 0)."""
    return step <= 1e-13 * (x + step) + tol + ROUND * x / abs(dH)


@njit(cache=True)
def _smallest_root(n, co, j0, nn, off, q, m, ylo, h, lam, zbar, tol, xmin, xguess):
    """The smallest root of H (status 0), or status 1 if H has a positive local minimum
    before it: the slip jumps, a fold (the start of a shock).  Status 2: no convergence.

    From the left (H > 0), with steps capped at doubling (from ``xmin``) so that a minimum
    is not jumped over: each step goes to the first zero of the parabola through H, H' and
    the curvature from the last two slopes (Newton's step at first).  Near a fold the root
    is close to a double one, where Newton from the left only halves the distance a step;
    the parabola takes it in one.  Once a point past the root is known (H <= 0), the same
    step from the left end, with the curvature from both ends, safeguarded by bisection.
    Converged when a Newton step is below ``1e-13 x + tol`` (``tol``: the round-off of H
    in units of slip away from folds) or below the round-off of H over its slope
    (:func:`_converged`).

    ``xguess`` > 0 (a point close to the root, from the step before): where H is positive
    and falling there, the iteration starts there instead of from 0 (it would have passed
    there: the capped steps from 0 jump over as much, so a minimum before it is missed no
    more than by them); where H is below zero there, it bounds the root from above and the
    iteration starts from 0 in that bracket; where H is zero to round-off, it is the root."""
    x = 0.0
    H, dH = -1.0, 0.0
    b, Hb = -1.0, 0.0
    if xguess > 0.0:
        Hg, dHg = _closure(xguess, n, co, j0, nn, off, q, m, ylo, h, lam, zbar)
        if Hg > 0.0 and dHg < 0.0:
            x, H, dH = xguess, Hg, dHg
        elif dHg < 0.0 and abs(Hg) <= ROUND * xguess:
            return xguess, 0
        elif Hg <= 0.0:
            b, Hb = xguess, Hg
    if x == 0.0:
        H, dH = _closure(x, n, co, j0, nn, off, q, m, ylo, h, lam, zbar)
        if H <= 0.0:
            return 0.0, 0
    if b < 0.0:
        # from the left, no bound yet
        xp, dHp = -1.0, 0.0
        for it in range(400):
            if dH >= 0.0:
                return x, 1
            newton = -H / dH
            if _converged(newton, x, tol, dH):
                return x + newton, 0
            xn = x + newton
            if xp >= 0.0 and x > xp:
                xn = x + _quadratic_step(H, dH, 0.5 * (dH - dHp) / (x - xp))
            cap = 2.0 * x + xmin
            if xn > cap:
                xn = cap
            Hn, dHn = _closure(xn, n, co, j0, nn, off, q, m, ylo, h, lam, zbar)
            if Hn > 0.0:
                xp, dHp = x, dH
                x, H, dH = xn, Hn, dHn
                continue
            b, Hb = xn, Hn
            break
        if b < 0.0:
            return x, 2
    # in the bracket [a, b], H(a) > 0 >= H(b)
    a, Ha, dHa = x, H, dH
    for k in range(300):
        if dHa >= 0.0:
            return a, 1
        newton = -Ha / dHa
        if _converged(newton, a, tol, dHa):
            return a + newton, 0
        L = b - a
        xt = a + _quadratic_step(Ha, dHa, (Hb - Ha - dHa * L) / (L * L))
        if not (a < xt < b):
            xt = 0.5 * (a + b)
        Ht, dHt = _closure(xt, n, co, j0, nn, off, q, m, ylo, h, lam, zbar)
        if Ht > 0.0:
            a, Ha, dHa = xt, Ht, dHt
        else:
            b, Hb = xt, Ht
            if -Ht <= ROUND * xt:
                return xt, 0
        if b - a <= 1e-13 * b + tol:
            return b, 0
    return b, 0


@njit(cache=True)
def _psi(cp, B, W, lam):
    """E[(cp + B Z)_+] for Z ~ Exp(lam) truncated to [0, W] (W may be inf)."""
    tail = math.exp(-W / lam) if W < 1e300 else 0.0
    norm = 1.0 - tail
    if cp >= 0.0:
        # E[Z] of the truncated exponential
        if W < 1e300:
            EZ = (lam - (W + lam) * tail) / norm
        else:
            EZ = lam
        return cp + B * EZ
    z0 = -cp / B
    if z0 >= W:
        return 0.0
    if W < 1e300:
        return B * (lam * math.exp(-z0 / lam) - (W - z0 + lam) * tail) / norm
    return B * lam * math.exp(-z0 / lam)


@njit(cache=True)
def deposit(dep, mass, ytop, B, W, lam, ylo, h):
    """Deposit ``mass`` of Y = ytop - B Z (Z ~ Exp(lam) on [0, W]) on the hat functions of
    the nodes ``ylo + j h`` exactly (second differences of E[(c - Y)_+]); a point when the
    spread is below 1e-6 h.  Returns the mass that fell outside the nodes."""
    ny = dep.size
    span = B * min(W, 40.0 * lam)
    if span < 1e-6 * h:
        if W < 1e300:
            tail = math.exp(-W / lam)
            EZ = (lam - (W + lam) * tail) / (1.0 - tail) if W > 1e-12 * lam else 0.5 * W
        else:
            EZ = lam
        u = (ytop - B * EZ - ylo) / h
        jj = int(math.floor(u)); f = u - jj
        if jj < 0 or jj + 1 >= ny:
            return mass
        dep[jj] += mass * (1.0 - f); dep[jj + 1] += mass * f
        return 0.0
    jlo = int(math.floor((ytop - span - ylo) / h)) - 1
    jhi = int(math.ceil((ytop - ylo) / h)) + 1
    out = 0.0
    if jlo < 0 or jhi >= ny:
        out = mass  # (only the part outside is lost; counted below)
        jlo = max(jlo, 0); jhi = min(jhi, ny - 1)
    tot = 0.0
    # psi at the nodes j - 1, j, j + 1, each evaluated once
    yj = ylo + jlo * h
    p_lo = _psi(yj - h - ytop, B, W, lam)
    p_mid = _psi(yj - ytop, B, W, lam)
    for j in range(jlo, jhi + 1):
        yj = ylo + j * h
        p_hi = _psi(yj + h - ytop, B, W, lam)
        w = (p_hi - 2.0 * p_mid + p_lo) / h
        if w > 0.0:
            dep[j] += mass * w
            tot += w
        p_lo, p_mid = p_mid, p_hi
    if out > 0.0:
        return mass * (1.0 - tot)
    return 0.0


@njit(cache=True)
def _commit_cohort(c, dX, co, j0, nn, off, q, m, J, X0, s0, X, Edt, phi, ylo, h, lam, r2, k2, f_th, gx, gw, dep):
    """:func:`commit` for cohort ``c``; returns the mass that fell outside the nodes."""
    bad = 0.0
    beta = co[c, 0]; E = co[c, 4]
    Da = co[c, 1] + co[c, 3] * dX
    Dy = co[c, 2]
    o = off[c]
    Jn = J[c] * Edt + (X - X0[c]) * (1.0 - Edt) + phi * dX
    J[c] = Jn
    if co[c, 3] * dX <= co[c, 5]:
        return bad
    for k in range(nn[c]):
        y0, d0, d1, i4, q0, q1 = _cell(Da, Dy, ylo, j0[c] + k, h, o + k, q)
        if q0 == 0.0 and q1 == 0.0:
            continue
        crossed = False
        cross_total = 0.0
        for p in range(2):
            lo, hi, ma, mb = _piece(m, i4, p)
            a, b = _piece_range(d0, d1, ma, mb, lo, hi)
            if a < 0.0:
                continue
            crossed = True
            cross = _isub(q0, q1, ma, mb, a, b, lam) - _isub(q0, q1, d0, d1, a, b, lam)
            if cross <= 0.0:
                continue
            cross_total += cross
            # newborns at the Gauss points, scaled to the exact crossed mass
            L = b - a
            tot = 0.0
            for i in range(gx.size):
                s = a + L * gx[i]
                qv = q0 + (q1 - q0) * s
                mv = ma + (mb - ma) * s
                Dv = d0 + (d1 - d0) * s
                tot += gw[i] * qv * (math.exp(-mv / lam) - math.exp(-Dv / lam))
            for i in range(gx.size):
                s = a + L * gx[i]
                qv = q0 + (q1 - q0) * s
                mv = ma + (mb - ma) * s
                Dv = d0 + (d1 - d0) * s
                mass = gw[i] * qv * (math.exp(-mv / lam) - math.exp(-Dv / lam))
                if mass <= 0.0 or tot <= 0.0:
                    continue
                mass *= h * cross / tot
                if mass < 1e-18:
                    continue
                yv = y0 + s * h
                Btil = 1.0 - beta  # (r2 (1 - E Ej): delta_R's response to the margin at birth)
                Atil = yv * E + r2 * (1.0 - E) * (f_th - s0[c] + yv) + k2 * Jn
                bad += deposit(dep, mass, Atil - Btil * mv, Btil, Dv - mv, lam, ylo, h)
        if crossed:
            _new_floor(m, i4, d0, d1, q0, q1, cross_total, lam)
    return bad


@njit(cache=True, parallel=True)
def _commit(dX, n, co, j0, nn, off, q, m, J, X0, s0, X, Edt, phi, ylo, h, lam, k2, kappa, f_th, gx, gw, dep):
    """Apply a step of slip ``dX``: the crossed members' delta_R (a linear function of
    their margin at birth, so an exponential on a segment) is deposited exactly on the
    hat functions of the nodes ``ylo + j h`` (``dep``: the newborn cohort, margins
    Exp(lam) after their re-jumps); a crossed cell gets the new floor, the larger of
    the old floor and the threshold (:func:`_new_floor`).  Returns the mass that fell
    outside the nodes.  Chunks of cohorts as in :func:`closure`, each depositing into
    its own row."""
    r2 = k2 / kappa
    deps = np.zeros((CHUNKS, dep.size))
    bads = np.zeros(CHUNKS)
    if n >= PARALLEL_COHORTS:
        for k in prange(CHUNKS):
            for c in range(k, n, CHUNKS):
                bads[k] += _commit_cohort(c, dX, co, j0, nn, off, q, m, J, X0, s0, X, Edt, phi, ylo, h, lam, r2,
                                          k2, f_th, gx, gw, deps[k])
    else:
        for k in range(CHUNKS):
            for c in range(k, n, CHUNKS):
                bads[k] += _commit_cohort(c, dX, co, j0, nn, off, q, m, J, X0, s0, X, Edt, phi, ylo, h, lam, r2,
                                          k2, f_th, gx, gw, deps[k])
    bad = 0.0
    for k in range(CHUNKS):
        bad += bads[k]
        dep += deps[k]
    return bad


@njit(cache=True)
def _new_floor(m, i4, d0, d1, q0, q1, crossed, lam):
    """Replace a cell's floor by max(floor, threshold).  That is piecewise linear; where it
    has at most one kink (the threshold overtaking a floor, the usual case) it is stored
    exactly; otherwise the kink farthest from the chord is kept and the floor shifted so
    that the surviving mass is exact."""
    S_exact = _survivors_cell(q0, q1, m, i4, lam) - crossed
    pts = np.empty(6)
    npt = 0
    pts[npt] = 0.0; npt += 1
    sk = m[i4 + 2]
    if 0.0 < sk < 1.0:
        pts[npt] = sk; npt += 1
    for p in range(2):
        # where the threshold crosses this piece of the floor (an end of the part above it)
        lo, hi, f0, f1 = _piece(m, i4, p)
        a, b = _piece_range(d0, d1, f0, f1, lo, hi)
        sc = b if a == lo else a
        if a >= 0.0 and lo < sc < hi:
            pts[npt] = sc; npt += 1
    pts[npt] = 1.0; npt += 1
    x = np.sort(pts[:npt])
    v = np.empty(npt)
    for i in range(npt):
        v[i] = max(_floor_at(m, i4, x[i]), d0 + (d1 - d0) * x[i])
    # drop interior points on the line of their neighbours, and points too close to an end
    keep = np.ones(npt, dtype=np.bool_)
    prev = 0
    for i in range(1, npt - 1):
        nxt = i + 1
        w = (x[i] - x[prev]) / (x[nxt] - x[prev]) if x[nxt] > x[prev] else 0.0
        line = v[prev] + (v[nxt] - v[prev]) * w
        if abs(v[i] - line) <= 1e-13 * (1.0 + abs(v[i])) or x[i] < 1e-9 or x[i] > 1.0 - 1e-9:
            keep[i] = False
        else:
            prev = i
    xi = x[keep]
    vi = v[keep]
    m[i4] = vi[0]
    m[i4 + 1] = vi[-1]
    if xi.size == 2:
        m[i4 + 2] = 1.0
        m[i4 + 3] = vi[-1]
        return
    # the interior point farthest from the chord is the kink
    best, dev = 1, -1.0
    for i in range(1, xi.size - 1):
        d = abs(vi[i] - (vi[0] + (vi[-1] - vi[0]) * xi[i]))
        if d > dev:
            best, dev = i, d
    m[i4 + 2] = xi[best]
    m[i4 + 3] = vi[best]
    if xi.size > 3:
        S = _survivors_cell(q0, q1, m, i4, lam)
        if S > 0.0 and S_exact > 0.0:
            shift = -lam * math.log(S_exact / S)
            m[i4] += shift; m[i4 + 1] += shift; m[i4 + 3] += shift


@njit(cache=True)
def cell_survivors(pool, q, m, h, lam, out):
    """The mass of every cell of the pool (the first ``pool``) that has not crossed yet."""
    for i in range(pool):
        out[i] = _survivors_cell(q[2 * i], q[2 * i + 1], m, 4 * i, lam) * h


@njit(cache=True)
def compact(n, j0, nn, off, q, m, cell, floor, keep, q_out, m_out):
    """Pack the cells whose mass ``cell`` exceeds ``floor``, in place of the layout
    (``j0``, ``nn``, ``off``): each cohort trimmed to its first and last such cell, the
    cells between them that do not exceed it zeroed, cohorts with none dropped.  The new
    layout is written over the first entries of ``j0``, ``nn``, ``off``, with ``keep`` the
    old index of each kept cohort, the cells to ``q_out``, ``m_out``.  Returns the number
    of cohorts kept, of cells kept and the mass dropped."""
    p = 0
    i = 0
    dropped = 0.0
    for c in range(n):
        k, o = nn[c], off[c]
        a = -1
        b = -1
        total = 0.0
        for s in range(k):
            total += cell[o + s]
            if cell[o + s] > floor:
                if a < 0:
                    a = s
                b = s + 1
        if a < 0:
            dropped += total
            continue
        for s in range(a, b):
            src = o + s
            dst = p + s - a
            if cell[src] > floor:
                q_out[2 * dst] = q[2 * src]
                q_out[2 * dst + 1] = q[2 * src + 1]
                total -= cell[src]
            else:
                q_out[2 * dst] = 0.0
                q_out[2 * dst + 1] = 0.0
            for r in range(4):
                m_out[4 * dst + r] = m[4 * src + r]
        dropped += total
        keep[i] = c
        j0[i] = j0[c] + a
        nn[i] = b - a
        off[i] = p
        p += b - a
        i += 1
    return i, p, dropped


# ------------------------------------------------------------------------------ serial twins
def _serial_twins(names):
    """Copies of the jitted kernels ``names`` compiled without ``parallel``, calling each
    other (``_smallest_root``'s twin calls ``_closure``'s twin); the rest is shared.

    For processes where numba runs one thread only (``NUMBA_NUM_THREADS=1``: compare's
    pool workers, or a single core), where the parallel kernels cannot run in parallel but
    cost more to compile: with an empty numba cache, compare's cohort warm-up compiled the
    three in 5.1 CPU seconds (parfors), their twins in 1.9 s, and the whole warm-up took
    16.6 CPU s, now 11.9 s (medians of 3 runs on a shared machine).  The sums
    are the same in the same order (chunks as in :func:`_closure`), so the results are
    identical.  Each twin has a name of its own, and so its own entry in numba's disk
    cache (numba's cache key does not include ``parallel``)."""
    namespace = dict(globals())
    twins = {}
    for name in names:
        kernel = globals()[name]
        options = {key: value for key, value in kernel.targetoptions.items() if key not in ("parallel", "nopython")}
        func = kernel.py_func
        twin = types.FunctionType(func.__code__, namespace, name + "_serial", func.__defaults__, func.__closure__)
        twin.__qualname__ = name + "_serial"
        twin.__doc__ = func.__doc__
        twins[name] = njit(cache=True, **options)(twin)  # (caching is not among the targetoptions)
    namespace.update(twins)
    return twins


_SERIAL = _serial_twins(("_closure", "_smallest_root", "_commit"))


# ------------------------------------------------------------------------------ entry points from Python
def _on_free_cores(kernel):
    """``kernel`` (jitted) run with the calling thread's numba thread count set to the
    cores free now (:func:`micro._threads.use_free_cores`); its serial twin
    (:func:`_serial_twins`) where numba has one thread only (``NUMBA_NUM_THREADS=1``)."""
    serial = _SERIAL[kernel.__name__]

    @functools.wraps(kernel, updated=())
    def call(*args):
        if one_numba_thread():
            return serial(*args)
        use_free_cores()
        return kernel(*args)

    call.serial = serial
    return call


closure = _on_free_cores(_closure)
smallest_root = _on_free_cores(_smallest_root)
commit = _on_free_cores(_commit)
