"""Numba kernels of the Fokker-Planck (master-equation) solver.

The density P(delta_F, delta_R) is stored on cells of side ``eps`` indexed by

* ``d``: the bin of the distance to threshold ``delta = delta_F + delta_R`` (the paper's
  ``i + j``), so that the stability boundary ``delta = 0`` is a column, and
* ``j``: the bin of ``delta_R`` (a row); the delta_F bin of a cell is ``k = d - j``.

Each cell carries three mass-weighted numbers:

* ``M``, its mass;
* ``W = M * eta``: its delta_R position is ``(j + eta) * eps`` with ``eta`` in
  [-1/2, 1/2).  Relaxation moves mass along delta_R exactly, with no numerical
  diffusion; mass that lands in the same cell merges at its centre of mass.
* ``O = M * omega``: along delta_F its mass is spread uniformly over the upper fraction
  ``omega`` of its bin (``omega = 1`` except where mass has crossed the threshold).

Driving and stress redistribution shift every delta_F by the same amount: the shift is
a continuous offset ``phi`` (in bins, in [0, 1)) plus an integer column offset ``off``,
so the stress is not quantised to ``eps``.  The mass of cell ``(j, d)`` then covers

    delta in [(hi - omega) eps, hi eps),   hi = d + 1 - phi + eta.

The part below ``delta = 0`` is unstable: its mass jumps (``delta_F += kappa z``,
``delta_R`` unchanged: the dashpot is rigid during the jump) and lands with the exact
bin integrals of the distribution of ``kappa z``.  All moves conserve mass and the
first moments of delta_F and delta_R exactly.

Arrays of integers ``ist`` and floats ``fst`` carry the scalar state (``I_*`` and
``F_*`` indices); ``prm`` carries the model constants (``P_*``).
"""
from __future__ import annotations

import math

import numpy as np
from numba import njit

# --- float state -------------------------------------------------------------------
F_T = 0  # time
F_W = 1  # drive position w
F_HBAR = 2  # mean block position hbar
F_SIGMA = 3  # stress k0 (w - hbar)
F_PHI = 4  # continuous shift in bins, [0, 1)
F_MEANX = 5  # sum of M * delta_F
F_JUMPS = 6  # cumulative number of jumps per block
F_PENDING = 7  # time not relaxed yet (negative: relaxed ahead, see advance)
F_SLIP_RATE = 8  # d hbar / dt over the last step
F_DISP = 9  # mass-weighted mean |delta_R_inf - delta_R| (sets the relaxation step)
F_NEG = 10  # most negative cell mass seen (stays 0)
F_MASS = 11  # total mass (diagnostic)
F_WIN_START = 12  # time of the last record (start of the current window)
F_WIN_MIN = 13  # smallest stress in the window
F_WIN_MAX = 14  # largest stress in the window
F_WIN_INT = 15  # time integral of the stress over the window
F_WIN_LEN = 16  # time covered by F_WIN_INT
F_OWED = 17  # shift (bins) owed but not applied yet (|owed| <= OWED_TOL, or an iteration cap)
F_REC_SIGMA = 18  # stress at the last record
N_FSTATE = 19

# --- integer state -----------------------------------------------------------------
I_OFF = 0  # column of d = 0
I_JBASE = 1  # delta_R bin j of row 0
I_RLO = 2  # first occupied row
I_RHI = 3  # one past the last occupied row
I_STEPS = 4  # time steps taken
I_ITER = 5  # closure iterations taken
I_NREC = 6  # records written
I_NSHOCK = 7  # shocks written
I_CUR = 8  # which of the two buffers holds the density
N_ISTATE = 9

# --- parameters ----------------------------------------------------------------------
P_K0 = 0
P_K1 = 1
P_K2 = 2
P_KAPPA = 3
P_GAMMA = 4
P_FTH = 5
P_EPS = 6
P_ZMEAN = 7
P_KIND = 8  # 0 exponential, 1 deterministic, 2 tabulated
P_D0 = 9  # distribution constants, in units of the landing displacement s = kappa z
P_D1 = 10
P_D2 = 11
P_THETA_S = 12  # largest shift per step, in bins
P_THETA_R = 13  # largest typical relaxation displacement per step, in bins
P_DT_MAX = 14  # largest time step
P_SHOCK = 15  # closure shift (bins) above which a step is recorded as a shock
P_REC_DSIGMA = 16  # record when the stress has moved this much since the last record
N_PARAM = 17

# --- return codes ---------------------------------------------------------------------
DONE = 0
NEED_ROWS = 1
NEED_COLS = 2
RECORDS_FULL = 3
SHOCKS_FULL = 4
MAX_STEPS = 5
STOP_EVENT = 6

#: An injection stops once the mass left in its tail is below this; the rest goes into
#: its last cell (mass stays exact, the tail beyond is not resolved).
TAIL_FLOOR = 1e-16
#: Cell edges within this many bins of the threshold count as on it.
EDGE_TOL = 1e-9
#: The closure stops once less than this many bins are owed; the remainder is carried
#: exactly to the next step.
OWED_TOL = 1e-2


@njit(cache=True, inline="always")
def _clip01(v: float) -> float:
    if v <= 0.0:
        return 0.0
    if v >= 1.0:
        return 1.0
    return v


@njit(cache=True)
def landing_cdf(s: float, prm: np.ndarray, table: np.ndarray) -> float:
    """Cumulative distribution of the landing displacement ``s = kappa z``."""
    if s <= 0.0:
        return 0.0
    kind = int(prm[P_KIND])
    if kind == 0:
        # exponential: D0 = kappa * scale, D1 = kappa * cutoff, D2 = normalisation
        if s >= prm[P_D1]:
            return 1.0
        return -math.expm1(-s / prm[P_D0]) / prm[P_D2]
    if kind == 1:
        # deterministic: D0 = kappa * zbar
        return 1.0 if s >= prm[P_D0] else 0.0
    # tabulated on s = i * D0, i = 0..n-1; D1 = s_max
    if s >= prm[P_D1]:
        return 1.0
    u = s / prm[P_D0]
    i = int(u)
    if i >= table.shape[0] - 1:
        return 1.0
    f = u - i
    return table[i] * (1.0 - f) + table[i + 1] * f


@njit(cache=True)
def inject_row(M, W, O, r, jbase, off, phi, eps, mass, eta, depth, prm, table, chi, clo):
    """Deposit ``mass`` that jumps from below the threshold of row ``r``.

    The mass has delta_R offset ``eta`` and sits on average ``depth`` bins below
    ``delta = 0`` (for mass that crossed during a shift of ``s`` bins, ``depth = s/2``):
    it lands at ``delta = kappa z - depth * eps``.  The part that would land below
    threshold jumps again at once (a geometric series, summed exactly).  Returns
    ``(number of jumps, change of sum(M * delta_F))``.
    """
    ncol = M.shape[1]
    theta = eta - phi + depth  # bin d receives kappa z / eps in [d + theta, d + 1 + theta)
    f_cut = landing_cdf(depth * eps, prm, table)
    if f_cut >= 1.0:
        f_cut = 1.0 - 1e-15
    scale = mass / (1.0 - f_cut)  # mass that jumps, counting repeated jumps
    j = r + jbase
    x_exit = -(j + eta + depth) * eps  # mean delta_F of the mass that jumps
    half_shift = depth
    d = int(math.floor(half_shift - theta))
    c = off + d
    first = c
    f_lo = f_cut
    moment = 0.0
    exponential = int(prm[P_KIND]) == 0
    if exponential:
        # F(s) = (1 - exp(-s/b)) / norm for s < s_max: one multiplication per bin
        b = prm[P_D0]
        s_max = prm[P_D1]
        norm = prm[P_D2]
        s_hi = (d + 1 + theta) * eps
        e_hi = math.exp(-s_hi / b)
        ratio = math.exp(-eps / b)
    while True:
        if c >= ncol - 1 or (1.0 - f_lo) * scale < TAIL_FLOOR:
            c = min(c, ncol - 1)  # fold the far tail into this column (conserves mass)
            f_hi = 1.0
        elif exponential:
            f_hi = (1.0 - e_hi) / norm if s_hi < s_max else 1.0
            e_hi *= ratio
            s_hi += eps
        else:
            f_hi = landing_cdf((d + 1 + theta) * eps, prm, table)
        dm = (f_hi - f_lo) * scale
        if dm > 0.0:
            part = (d + 1 + theta) - max(d + theta, half_shift)  # filled fraction of the bin
            M[r, c] += dm
            W[r, c] += dm * eta
            O[r, c] += dm * part
            moment += dm * ((d - j + 1 - phi - 0.5 * part) * eps - x_exit)
        f_lo = f_hi
        if f_hi >= 1.0 or c == ncol - 1:
            break
        d += 1
        c += 1
    if c + 1 > chi[r]:
        chi[r] = c + 1
    if first < clo[r]:
        clo[r] = first
    return scale, moment


@njit(cache=True)
def threshold_rate(M, W, O, off, phi, rlo, rhi):
    """Mass that crosses ``delta = 0`` per bin of shift, from the cells touching it.

    A cell whose mass sits in ``[lo, hi)`` (in bins) with ``lo`` within ``EDGE_TOL`` of
    the threshold loses ``M / omega`` per bin; mass already below the threshold (left by
    a merge) counts as crossing at once.
    """
    rate = 0.0
    for r in range(rlo, rhi):
        for d in range(-1, 2):
            c = off + d
            m = M[r, c]
            if m <= 0.0:
                continue
            omega = O[r, c] / m
            lo = d + 1 - phi + W[r, c] / m - omega
            if lo <= EDGE_TOL and omega > EDGE_TOL:
                rate += m / omega
    return rate


@njit(cache=True)
def shift_and_jump(M, W, O, ist, fst, prm, table, chi, clo, shift, ex_m, ex_w, ex_d):
    """Shift every delta_F down by ``shift`` bins and make the mass that crosses jump.

    Returns ``(jumped mass, change of sum(M * delta_F) by the jumps)``.
    """
    off = ist[I_OFF]
    phi = fst[F_PHI]
    eps = prm[P_EPS]
    rlo = ist[I_RLO]
    rhi = ist[I_RHI]
    phi_b = phi + shift
    any_exit = False
    for r in range(rlo, rhi):
        em = 0.0
        ew = 0.0
        ed = 0.0
        for d in range(-1, 2):
            c = off + d
            m = M[r, c]
            if m <= 0.0:
                continue
            eta = W[r, c] / m
            omega = O[r, c] / m
            hi = d + 1 - phi_b + eta  # upper edge after the shift
            if hi - omega >= 0.0 and omega > EDGE_TOL:
                continue
            if hi <= EDGE_TOL or omega <= EDGE_TOL:
                out = m
                depth = 0.5 * omega - hi
                M[r, c] = 0.0
                W[r, c] = 0.0
                O[r, c] = 0.0
            else:
                out = m * (1.0 - hi / omega)
                depth = 0.5 * (omega - hi)
                keep = m - out
                M[r, c] = keep
                W[r, c] = keep * eta
                O[r, c] = keep * hi
            em += out
            ew += out * eta
            ed += out * depth
        ex_m[r] = em
        ex_w[r] = ew
        ex_d[r] = ed
        if em > 0.0:
            any_exit = True
    fst[F_MEANX] -= shift * eps * fst[F_MASS]
    if phi_b >= 1.0 - 1e-12:
        phi_b -= 1.0
        if phi_b < 0.0:
            phi_b = 0.0
        off += 1
        ist[I_OFF] = off
    fst[F_PHI] = phi_b
    jumped = 0.0
    moment = 0.0
    if any_exit:
        jb = ist[I_JBASE]
        for r in range(rlo, rhi):
            em = ex_m[r]
            if em > 0.0:
                n, dmom = inject_row(M, W, O, r, jb, off, phi_b, eps, em, ex_w[r] / em, ex_d[r] / em, prm, table, chi, clo)
                jumped += n
                moment += dmom
        fst[F_MEANX] += moment
    return jumped, moment


@njit(cache=True)
def _apply_jumps(fst, prm, jumped, moment):
    """Account for jumps that moved sum(M * delta_F) by ``moment``.

    The mean block position moves by ``moment / kappa``, the stress drops by ``k0``
    times that, and every delta_F owes a further shift of ``(k1 + k2)`` times that
    (the stress redistribution).  Returns the owed shift in bins.
    """
    dh = moment / prm[P_KAPPA]
    fst[F_HBAR] += dh
    fst[F_SIGMA] -= prm[P_K0] * dh
    fst[F_JUMPS] += jumped
    return (prm[P_K1] + prm[P_K2]) * dh / prm[P_EPS]


@njit(cache=True)
def close_step(M, W, O, ist, fst, prm, table, chi, clo, owed, ex_m, ex_w, ex_d, max_iter):
    """Apply ``owed`` bins of shift and the stress redistribution it triggers.

    With ``c`` the redistribution (in bins) per bin of shift from the cells touching the
    threshold, the closure ``shift = owed + c * shift`` gives ``shift = owed / (1 - c)``;
    the exits of that shift are then computed exactly cell by cell, and what the linear
    prediction missed (cells that start or stop crossing within the shift) is owed
    again.  An avalanche (``c >= 1``) applies what it owes, at most up to the next column
    boundary, and goes on.  A small negative remainder (the prediction overshot) is
    carried to the next step rather than dropped, so that
    ``sum(M * delta_F) + sigma - owed * eps`` stays exactly constant.  Returns the total
    shift in bins and the number of iterations.
    """
    eps = prm[P_EPS]
    c_per_mass = (prm[P_K1] + prm[P_K2]) * prm[P_ZMEAN] / eps
    total = 0.0
    it = 0
    while owed > OWED_TOL and it < max_iter:
        it += 1
        c = c_per_mass * threshold_rate(M, W, O, ist[I_OFF], fst[F_PHI], ist[I_RLO], ist[I_RHI])
        step = owed / (1.0 - c) if c < 1.0 else owed
        room = 1.0 - fst[F_PHI]
        if step > room:
            step = room
        jumped, moment = shift_and_jump(M, W, O, ist, fst, prm, table, chi, clo, step, ex_m, ex_w, ex_d)
        total += step
        owed -= step
        if jumped > 0.0:
            owed += _apply_jumps(fst, prm, jumped, moment)
    fst[F_OWED] = owed
    return total, it


@njit(cache=True)
def bounds_after_relax(ist, fst, prm, lam, clo, chi):
    """Rows and columns that a relaxation by factor ``lam`` can reach: ``(rmin, rmax, cmax)``."""
    eps = prm[P_EPS]
    g = prm[P_K2] / prm[P_KAPPA]
    off = ist[I_OFF]
    phi = fst[F_PHI]
    jb = ist[I_JBASE]
    mean_x = fst[F_MEANX] / fst[F_MASS]
    rmin = 1 << 60
    rmax = -(1 << 60)
    cmax = -(1 << 60)
    for r in range(ist[I_RLO], ist[I_RHI]):
        if chi[r] <= clo[r]:
            continue
        j = r + jb
        for k in (clo[r] - off - j, chi[r] - 1 - off - j):
            x = (k + 0.5 - phi) * eps
            yinf = g * (mean_x - x)
            for y in ((j - 0.5) * eps, (j + 0.5) * eps):
                jp = int(math.floor((yinf + lam * (y - yinf)) / eps + 0.5))
                rmin = min(rmin, jp - jb - 1)
                rmax = max(rmax, jp - jb + 1)
                cmax = max(cmax, off + k + jp + 1)
    return rmin, rmax, cmax


@njit(cache=True)
def relax(M, W, O, Mn, Wn, On, ist, fst, prm, table, chi, clo, chi_n, clo_n, dt, ex_m, ex_w, ex_d):
    """Relax every delta_R for a time ``dt`` (Eq. B3) and make the mass it carries across threshold jump.

    .. math:: \\delta_R \\to \\delta_R^\\infty + (\\delta_R - \\delta_R^\\infty) e^{-k_2 dt/\\eta_u},
              \\qquad \\delta_R^\\infty = \\frac{k_2}{\\kappa}(\\langle\\delta_F\\rangle - \\delta_F)

    Reads ``M, W, O`` (and zeroes them), writes ``Mn, Wn, On`` (which must be zero).
    Recomputes the sums of mass and delta_F and the mean relaxation displacement.
    Returns ``(jumped mass, change of sum(M * delta_F) by the jumps)``.
    """
    eps = prm[P_EPS]
    g = prm[P_K2] / prm[P_KAPPA]
    lam = math.exp(-prm[P_GAMMA] * dt)
    off = ist[I_OFF]
    phi = fst[F_PHI]
    jb = ist[I_JBASE]
    mean_x = fst[F_MEANX] / fst[F_MASS]
    nrow = M.shape[0]
    new_rlo = nrow
    new_rhi = 0
    sum_x = 0.0
    sum_m = 0.0
    sum_disp = 0.0
    neg = 0.0
    for r in range(nrow):
        ex_m[r] = 0.0
        ex_w[r] = 0.0
        ex_d[r] = 0.0
    for r in range(ist[I_RLO], ist[I_RHI]):
        j = r + jb
        for c in range(clo[r], chi[r]):
            m = M[r, c]
            if m == 0.0:
                continue
            eta = W[r, c] / m
            omega = O[r, c] / m
            M[r, c] = 0.0
            W[r, c] = 0.0
            O[r, c] = 0.0
            if m < 0.0:
                neg = min(neg, m)
                continue
            k = c - off - j
            x = (k + 1 - phi - 0.5 * omega) * eps
            sum_x += m * x
            sum_m += m
            y = (j + eta) * eps
            yinf = g * (mean_x - x)
            sum_disp += m * abs(yinf - y)
            u = (yinf + lam * (y - yinf)) / eps
            jp = int(math.floor(u + 0.5))
            etap = u - jp
            rp = jp - jb
            cp = off + k + jp
            if rp < new_rlo:
                new_rlo = rp
            if rp + 1 > new_rhi:
                new_rhi = rp + 1
            hi = k + jp + 1 - phi + etap
            if hi - omega < 0.0:
                # relaxation carried part of the cell below threshold: that part jumps
                if hi <= EDGE_TOL:
                    out = m
                    depth = 0.5 * omega - hi
                else:
                    out = m * (1.0 - hi / omega)
                    depth = 0.5 * (omega - hi)
                ex_m[rp] += out
                ex_w[rp] += out * etap
                ex_d[rp] += out * depth
                m -= out
                omega = hi
            if m > 0.0:
                Mn[rp, cp] += m
                Wn[rp, cp] += m * etap
                On[rp, cp] += m * omega
                if cp < clo_n[rp]:
                    clo_n[rp] = cp
                if cp + 1 > chi_n[rp]:
                    chi_n[rp] = cp + 1
        clo[r] = M.shape[1]
        chi[r] = 0
    if neg < fst[F_NEG]:
        fst[F_NEG] = neg
    ist[I_RLO] = new_rlo
    ist[I_RHI] = new_rhi
    fst[F_MEANX] = sum_x
    fst[F_MASS] = sum_m
    fst[F_DISP] = sum_disp / sum_m if sum_m > 0.0 else 0.0
    jumped = 0.0
    moment = 0.0
    for r in range(new_rlo, new_rhi):
        em = ex_m[r]
        if em > 0.0:
            n, dmom = inject_row(Mn, Wn, On, r, jb, off, phi, eps, em, ex_w[r] / em, ex_d[r] / em, prm, table, chi_n, clo_n)
            jumped += n
            moment += dmom
    fst[F_MEANX] += moment
    return jumped, moment


@njit(cache=True)
def _record(rec, ist, fst, t, sigma):
    """Write one record (the window since the previous record) and open a new window."""
    n = ist[I_NREC]
    rec[n, 0] = t
    rec[n, 1] = sigma
    rec[n, 2] = min(fst[F_WIN_MIN], sigma)
    rec[n, 3] = max(fst[F_WIN_MAX], sigma)
    rec[n, 4] = fst[F_WIN_INT] / fst[F_WIN_LEN] if fst[F_WIN_LEN] > 0.0 else sigma
    ist[I_NREC] = n + 1
    fst[F_WIN_START] = t
    fst[F_REC_SIGMA] = sigma
    fst[F_WIN_MIN] = sigma
    fst[F_WIN_MAX] = sigma
    fst[F_WIN_INT] = 0.0
    fst[F_WIN_LEN] = 0.0


@njit(cache=True)
def advance(bufM, bufW, bufO, bufchi, bufclo, ist, fst, prm, table, ex_m, ex_w, ex_d,
            velocity, t_stop, max_steps, cols_needed, rec, rec_dt, shocks, stop_shocks):
    """Advance the density from ``fst[F_T]`` to ``t_stop`` at drive velocity ``velocity``.

    One step: drive by ``velocity * dt`` and close the cascade of shifts, jumps and
    stress redistribution it triggers; relax the dashpots (Eq. B3) for the time elapsed
    since the last relaxation whenever the typical displacement that has accumulated
    reaches ``P_THETA_R`` bins (a lazy Lie splitting: relaxation is exact in time, so
    applying it less often only delays it).  The step keeps the shift within
    ``P_THETA_S`` bins and does not pass ``t_stop``.

    Records ``t, sigma, min sigma, max sigma, time-mean sigma`` (over the window since
    the previous record) whenever the stress has moved by ``P_REC_DSIGMA`` since the last
    record, ``rec_dt`` has passed, or a shock happens (then one record just before it and
    one just after).  A step whose cascade shifts more than ``P_SHOCK`` bins is a shock,
    also listed as ``t, sigma before, sigma after, shift in bins``.  Returns a code
    telling why it stopped; on ``NEED_ROWS`` and ``NEED_COLS`` the state is untouched.
    """
    k0 = prm[P_K0]
    eps = prm[P_EPS]
    gamma = prm[P_GAMMA]
    ncol = bufM.shape[2]
    nrow = bufM.shape[1]
    steps = 0
    while True:
        t = fst[F_T]
        if t_stop - t <= 1e-14 * max(1.0, abs(t_stop)):
            return DONE
        if steps >= max_steps:
            return MAX_STEPS
        off = ist[I_OFF]
        if off < 3 or off + cols_needed + 3 > ncol:
            return NEED_COLS
        # --- step size
        shift_rate = (k0 * velocity + (prm[P_K1] + prm[P_K2]) * fst[F_SLIP_RATE]) / eps
        dt = prm[P_DT_MAX]
        if shift_rate > 0.0:
            dt = min(dt, prm[P_THETA_S] / shift_rate)
        relax_rate = gamma * fst[F_DISP] / eps
        if relax_rate > 0.0 and 0.5 * prm[P_THETA_R] / relax_rate > fst[F_PENDING]:
            dt = min(dt, 0.5 * prm[P_THETA_R] / relax_rate - fst[F_PENDING])
        dt = min(dt, t_stop - t)
        # --- relaxation, lazily and centred in time: an event relaxes for the time since
        # the previous event's midpoint plus half the interval to the next one (the same
        # as this one), so that the relaxation events sit at the centres of the intervals
        # they stand for (second-order splitting).  An interval is as long as it takes the
        # typical displacement to reach P_THETA_R bins.
        a = ist[I_CUR]
        owed = fst[F_OWED]
        tau = fst[F_PENDING] + dt
        relax_rate = gamma * fst[F_DISP] / eps
        interval = prm[P_THETA_R] / relax_rate if relax_rate > 0.0 else 0.0
        end = t + dt >= t_stop * (1.0 - 1e-15)
        if gamma > 0.0 and (tau >= 0.5 * interval * (1.0 - 1e-12) or end):
            ahead = 0.0 if end else 0.5 * interval
            lam = math.exp(-gamma * (tau + ahead))
            rmin, rmax, cmax = bounds_after_relax(ist, fst, prm, lam, bufclo[a], bufchi[a])
            if rmin < 1 or rmax > nrow - 2:
                return NEED_ROWS
            if cmax > ncol - 2:
                return NEED_COLS
            b = 1 - a
            for r in range(nrow):
                bufchi[b, r] = 0
                bufclo[b, r] = ncol
            jumped, moment = relax(bufM[a], bufW[a], bufO[a], bufM[b], bufW[b], bufO[b], ist, fst, prm, table,
                                   bufchi[a], bufclo[a], bufchi[b], bufclo[b], tau + ahead, ex_m, ex_w, ex_d)
            ist[I_CUR] = b
            a = b
            fst[F_PENDING] = -ahead
            if jumped > 0.0:
                owed += _apply_jumps(fst, prm, jumped, moment)
        else:
            fst[F_PENDING] = tau
        M = bufM[a]
        W = bufW[a]
        O = bufO[a]
        chi = bufchi[a]
        clo = bufclo[a]
        # --- drive, then the cascade it triggers
        sigma_prev = fst[F_SIGMA]
        hbar_prev = fst[F_HBAR]
        fst[F_T] = t + dt
        fst[F_W] += velocity * dt
        fst[F_SIGMA] += k0 * velocity * dt
        owed += k0 * velocity * dt / eps
        sigma_before = fst[F_SIGMA]
        total, it = close_step(M, W, O, ist, fst, prm, table, chi, clo, owed, ex_m, ex_w, ex_d, 100000000)
        ist[I_ITER] += it
        fst[F_SLIP_RATE] = (fst[F_HBAR] - hbar_prev) / dt
        steps += 1
        ist[I_STEPS] += 1
        sigma_after = fst[F_SIGMA]
        # --- records.  The state after the cascade is the accurate one (within a step the
        # drive is applied before the jumps it causes, a splitting sawtooth): averages and
        # extrema use post-cascade values; the value before the cascade counts only as the
        # peak before a shock.
        shock = total > prm[P_SHOCK]
        if shock:
            fst[F_WIN_MAX] = max(fst[F_WIN_MAX], sigma_before)
            _record(rec, ist, fst, fst[F_T], sigma_before)
            n = ist[I_NSHOCK]
            if n < shocks.shape[0]:
                shocks[n, 0] = fst[F_T]
                shocks[n, 1] = sigma_before
                shocks[n, 2] = sigma_after
                shocks[n, 3] = total
            ist[I_NSHOCK] = n + 1
        else:
            fst[F_WIN_INT] += 0.5 * (sigma_prev + sigma_after) * dt
            fst[F_WIN_LEN] += dt
        fst[F_WIN_MIN] = min(fst[F_WIN_MIN], sigma_after)
        fst[F_WIN_MAX] = max(fst[F_WIN_MAX], sigma_after)
        if (shock or abs(sigma_after - fst[F_REC_SIGMA]) >= prm[P_REC_DSIGMA]
                or fst[F_T] - fst[F_WIN_START] >= rec_dt or fst[F_T] >= t_stop * (1.0 - 1e-15)):
            _record(rec, ist, fst, fst[F_T], sigma_after)
        if ist[I_NREC] + 2 >= rec.shape[0]:
            return RECORDS_FULL
        if ist[I_NSHOCK] >= shocks.shape[0]:
            return SHOCKS_FULL
        if stop_shocks > 0 and ist[I_NSHOCK] >= stop_shocks:
            return STOP_EVENT
