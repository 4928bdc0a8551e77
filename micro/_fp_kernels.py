"""Numba kernels of the Fokker-Planck (master-equation) solver.

Cells
-----
The density P(delta_F, delta_R) is stored on cells of side ``eps`` indexed by

* ``d``: the bin of the distance to threshold ``delta = delta_F + delta_R`` (the paper's
  ``i + j``), so that the stability boundary ``delta = 0`` is a column, and
* ``j``: the bin of ``delta_R`` (a row); the delta_F bin of a cell is ``k = d - j``.

Each cell carries three mass-weighted numbers: its mass ``M``; ``W = M * eta``, where
its delta_R is ``(j + eta) * eps``; and ``O = M * omega``, its mass being spread
uniformly over the upper fraction ``omega`` of its delta_F bin (``omega = 1`` except
where mass has crossed the threshold).  Mass that lands in the same cell merges at its
centre of mass.  Driving and stress redistribution shift every delta_F by the same
amount: a continuous offset ``phi`` in [0, 1) bins plus an integer column offset
``off``.  Every move conserves mass and the first moment of delta_F exactly.

Lazy, exact relaxation
----------------------
Between two jumps of a block, Eq. (2) relaxes its delta_R towards
``Y(x) = (k2/kappa)(<delta_F> - delta_F)``; for mass that does not jump, ``<delta_F> -
delta_F`` changes only as the others jump, by ``kappa * d hbar``.  So over any
interval since a reference time ``t_a`` the exact delta_R of such mass is

    y(t) = lam * y_a + (1 - lam) * Ya(x) + B(t),    lam = exp(-gamma (t - t_a)),

with ``Ya(x) = Y(x) - k2 (hbar(t) - hbar(t_a))`` and ``B`` one drift accumulator common to
all cells.  The stored delta_R are those of time ``t_a`` ("stale"): the threshold logic
uses the true positions of the few cells near it, mass that jumps is stored
pre-compensated (so that the next synchronisation relaxes it only from its jump on),
and a synchronisation moves every cell to its true position and resets ``t_a``.  The
relaxation is therefore exact in time; synchronising only bounds how stale the stored
positions get.

Arrays of integers ``ist`` and floats ``fst`` carry the scalar state (``I_*``, ``F_*``);
``prm`` the constants (``P_*``).
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
F_SUMX = 5  # sum of M * delta_F
F_JUMPS = 6  # cumulative jumps per block
F_TREF = 7  # time t_a of the stored delta_R
F_HREF = 8  # hbar at t_a
F_LAM = 9  # exp(-gamma (t - t_a))
F_DRIFT = 10  # B(t)
F_LAM_SYNC = 11  # synchronise once F_LAM falls to this
F_SLIP_RATE = 12  # d hbar / dt: the last step's, or half the previous estimate if larger
F_NEG = 13  # most negative cell mass seen (stays 0)
F_MASS = 14  # total mass
F_WIN_START = 15  # time of the last record
F_WIN_MIN = 16
F_WIN_MAX = 17
F_WIN_INT = 18
F_WIN_LEN = 19
F_OWED = 20  # shift (bins) owed to the next step
F_REC_SIGMA = 21  # stress at the last record
F_YMEAN = 22  # exact mean delta_R = k2 <u>: it only relaxes, exp(-gamma t) (jumps keep u)
N_FSTATE = 23

# --- integer state -----------------------------------------------------------------
I_OFF = 0  # column of d = 0
I_JBASE = 1  # delta_R bin j of row 0
I_RLO = 2  # first occupied row
I_RHI = 3  # one past the last occupied row
I_STEPS = 4
I_ITER = 5
I_NREC = 6
I_NSHOCK = 7
I_CUR = 8  # which of the two buffers holds the density
I_SYNCS = 9  # synchronisations done
N_ISTATE = 10

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
P_THETA_R = 13  # largest relaxation of a near-threshold cell between synchronisations, in bins
P_DT_MAX = 14
P_SHOCK = 15  # a step whose cascade shifts more bins than this is a shock
P_REC_DSIGMA = 16  # record when the stress has moved this much
P_S_MAX = 17  # largest landing displacement kappa z kept
P_PULL_LAND = 18  # largest relaxation pull (bins) of mass landing between synchronisations
P_STOP_SHIFT = 19  # a cascade that has shifted this many bins stops the advance (STOP_EVENT), mid-cascade
N_PARAM = 20

# --- return codes ---------------------------------------------------------------------
DONE = 0
NEED_ROWS = 1
NEED_COLS = 2
RECORDS_FULL = 3
SHOCKS_FULL = 4
MAX_STEPS = 5
STOP_EVENT = 6
INTERNAL_ERROR = 7

#: Stored columns scanned on each side of the threshold.  Synchronisations keep every
#: cell's stored position within SCAN - 2 bins of its true one (the drift adds at most
#: one more bin), so every cell whose true position is near the threshold is scanned.
SCAN = 4
#: Cells lighter than this do not constrain the synchronisation schedule (if one is
#: missed at the threshold it jumps at the next synchronisation instead).
LIGHT = 1e-14
#: An injection stops once the mass left in its tail is below this; the rest goes into
#: its last cell (mass stays exact).
TAIL_FLOOR = 1e-16
#: Cell edges within this many bins of the threshold count as on it.
EDGE_TOL = 1e-9
#: The closure stops once it owes less than this fraction of the step's drive (and at
#: least OWED_FLOOR bins); the rest is carried exactly to the next step.  It must be
#: relative: for small k0 the drive is only a fraction 1 - c ~ k0/kappa of each step's
#: shift, and an absolute tolerance above it would skip cascades and make the step-size
#: control alternate stick and slip (a spurious cycle of stress drop theta_shift * eps).
OWED_REL = 0.1
OWED_FLOOR = 1e-12
#: Largest shift (bins) of one closure iteration: the scan covers SCAN bins of margin.
MAX_SHIFT = 2.0
#: Shortest step.  In a global shock the slip rate estimate of the step rule grows by the
#: shift of each step over theta_shift; a shock cut into hundreds of steps (each return
#: to grow or recentre the grid is a new step) overflowed it to inf, and dt to 0
#: (k0 = 1e-4, V = 35: a ZeroDivisionError).  No time scale of the model is this short.
DT_MIN = 1e-12


@njit(cache=True, nogil=True, inline="always")
def _clip01(v: float) -> float:
    if v <= 0.0:
        return 0.0
    if v >= 1.0:
        return 1.0
    return v


@njit(cache=True, nogil=True)
def landing_cdf(s: float, prm: np.ndarray, table: np.ndarray) -> float:
    """Cumulative distribution of the landing displacement ``s = kappa z``."""
    if s <= 0.0:
        return 0.0
    if s >= prm[P_S_MAX]:
        return 1.0
    kind = int(prm[P_KIND])
    if kind == 0:
        # exponential: D0 = kappa * scale, D2 = normalisation (the cutoff is in S_MAX)
        return -math.expm1(-s / prm[P_D0]) / prm[P_D2]
    if kind == 1:
        return 1.0 if s >= prm[P_D0] else 0.0  # deterministic: D0 = kappa * zbar
    u = s / prm[P_D0]  # tabulated on s = i * D0
    i = int(u)
    if i >= table.shape[0] - 1:
        return 1.0
    f = u - i
    return table[i] * (1.0 - f) + table[i + 1] * f


# ------------------------------------------------------------------------ relaxation
@njit(cache=True, nogil=True, inline="always")
def _target(fst, prm, x):
    """Ya(x): the relaxation target of delta_R at delta_F = x, in the frame of t_a."""
    return (prm[P_K2] / prm[P_KAPPA]) * (fst[F_SUMX] / fst[F_MASS] - x) - prm[P_K2] * (fst[F_HBAR] - fst[F_HREF])


@njit(cache=True, nogil=True, inline="always")
def _correction(fst, prm, y, x):
    """True minus stored delta_R of mass stored at ``y`` with delta_F ``x``."""
    return (1.0 - fst[F_LAM]) * (_target(fst, prm, x) - y) + fst[F_DRIFT]


@njit(cache=True, nogil=True, inline="always")
def _stored(fst, prm, y_true, x, p_lam):
    """Stored delta_R of mass that has true delta_R ``y_true`` now and jumped when the
    relaxation factor since t_a was ``p_lam``: the next synchronisation relaxes it by
    ``F_LAM / p_lam`` only."""
    ya = _target(fst, prm, x)
    return ya + (y_true - fst[F_DRIFT] - ya) / p_lam


# ------------------------------------------------------------------------ jumps
@njit(cache=True, nogil=True)
def inject(M, W, O, ist, fst, prm, table, chi, clo, mass, y_true, depth, p_lam):
    """Deposit ``mass`` that jumps from delta_R = ``y_true``, ``depth`` bins below threshold.

    The mass lands at ``delta = kappa z - depth * eps`` (delta_R unchanged), i.e. at
    delta_F = ``kappa z - depth * eps - y_true``; what would land below threshold jumps
    again at once (a geometric series, summed exactly).  Each landing delta_F bin gets
    the exact integral of the jump distribution and is stored pre-compensated for lazy
    relaxation.  Returns ``(number of jumps, change of sum(M * delta_F))``; a landing row
    (column) outside the arrays returns ``(-1, 0)`` (``(-2, 0)``) before anything is written.
    """
    eps = prm[P_EPS]
    phi = fst[F_PHI]
    off = ist[I_OFF]
    jb = ist[I_JBASE]
    nrow = M.shape[0]
    ncol = M.shape[1]
    s_cut = depth * eps
    f_cut = landing_cdf(s_cut, prm, table)
    if f_cut >= 1.0:
        f_cut = 1.0 - 1e-15
    scale = mass / (1.0 - f_cut)  # mass that jumps, counting repeated jumps
    x_exit = -(y_true + s_cut)  # delta_F of the jumping mass
    s_to_x = y_true + s_cut  # delta_F = s - s_to_x
    k_first = int(math.floor(-y_true / eps + phi))  # bin of the threshold, x = -y_true
    # --- landing rows and columns: y_stored is linear in x, so its ends bound it
    s_end = prm[P_S_MAX]
    for s_probe in (s_cut, s_end):
        x = s_probe - s_to_x
        ys = _stored(fst, prm, y_true, x, p_lam)
        jp = int(math.floor(ys / eps + 0.5))
        kp = int(math.floor(x / eps + phi))
        if jp - jb < 1 or jp - jb > nrow - 2:
            return -1.0, 0.0
        if off + kp + jp > ncol - 2 or off + kp + jp < 1:
            return -2.0, 0.0
    exponential = int(prm[P_KIND]) == 0
    moment = 0.0
    f_lo = f_cut
    k = k_first
    if exponential:
        b = prm[P_D0]
        norm = prm[P_D2]
        s_hi = (k + 1 - phi) * eps + s_to_x
        e_hi = math.exp(-s_hi / b)
        ratio = math.exp(-eps / b)
    # the stored delta_R is linear in the landing delta_F: step it bin by bin
    g_slope = (prm[P_K2] / prm[P_KAPPA]) * (1.0 / p_lam - 1.0)  # d y_stored / d x
    x_full = (k + 0.5 - phi) * eps  # centre of a full bin k
    u_full = _stored(fst, prm, y_true, x_full, p_lam) / eps
    du = g_slope  # per bin (x advances by eps, u by g_slope * eps / eps)
    r_min = nrow
    r_max = -1
    c_min = ncol
    c_max = -1
    while True:
        s_lo_bin = (k - phi) * eps + s_to_x
        s_hi = (k + 1 - phi) * eps + s_to_x
        if (1.0 - f_lo) * scale < TAIL_FLOOR or s_hi >= prm[P_S_MAX]:
            f_hi = 1.0  # fold the rest of the tail into this bin (mass stays exact)
        elif exponential:
            f_hi = (1.0 - e_hi) / norm
        else:
            f_hi = landing_cdf(s_hi, prm, table)
        if exponential:
            e_hi *= ratio
        dm = (f_hi - f_lo) * scale
        if dm > 0.0:
            part = (s_hi - max(s_lo_bin, s_cut)) / eps  # filled fraction of the delta_F bin
            if part >= 1.0:
                part = 1.0
                u = u_full
            else:
                u = u_full + du * 0.5 * (1.0 - part)  # centre of the filled part is higher
            x = (k + 1 - phi - 0.5 * part) * eps
            jp = int(math.floor(u + 0.5))
            r = jp - jb
            c = off + k + jp
            M[r, c] += dm
            W[r, c] += dm * (u - jp)
            O[r, c] += dm * part
            if r < r_min:
                r_min = r
            if r > r_max:
                r_max = r
            if c < c_min:
                c_min = c
            if c > c_max:
                c_max = c
            moment += dm * (x - x_exit)
        f_lo = f_hi
        if f_hi >= 1.0:
            break
        k += 1
        u_full += du
    # occupied extents (a landing run spans few rows: widen each touched row to the run)
    for r in range(r_min, r_max + 1):
        if c_min < clo[r]:
            clo[r] = c_min
        if c_max + 1 > chi[r]:
            chi[r] = c_max + 1
    if r_min < ist[I_RLO]:
        ist[I_RLO] = r_min
    if r_max + 1 > ist[I_RHI]:
        ist[I_RHI] = r_max + 1
    return scale, moment


# ------------------------------------------------------------------------ threshold
@njit(cache=True, nogil=True)
def crossing_candidates(M, W, O, ist, fst, prm, clo, cand):
    """Cells that a shift of up to MAX_SHIFT bins can carry across ``delta = 0``: fills
    rows of ``cand`` with (true lower edge in bins, filled fraction, mass) and returns
    how many."""
    eps = prm[P_EPS]
    phi = fst[F_PHI]
    off = ist[I_OFF]
    jb = ist[I_JBASE]
    n = 0
    for r in range(ist[I_RLO], ist[I_RHI]):
        if clo[r] > off + SCAN:
            continue
        j = r + jb
        for d in range(-SCAN, SCAN + 1):
            c = off + d
            m = M[r, c]
            if m <= 0.0:
                continue
            eta = W[r, c] / m
            omega = O[r, c] / m
            x = (d - j + 1 - phi - 0.5 * omega) * eps
            lo = d + 1 - phi + eta + _correction(fst, prm, (j + eta) * eps, x) / eps - omega
            if lo < MAX_SHIFT and n < cand.shape[0]:
                cand[n, 0] = lo
                cand[n, 1] = omega
                cand[n, 2] = m
                n += 1
    return n


@njit(cache=True, nogil=True, inline="always")
def _crossing(cand, n, shift):
    """Mass of the candidates below ``delta = 0`` after a shift of ``shift`` bins."""
    total = 0.0
    for i in range(n):
        lo = cand[i, 0]
        if lo >= shift:
            continue
        omega = cand[i, 1]
        if omega <= EDGE_TOL or shift - lo >= omega:
            total += cand[i, 2]
        else:
            total += cand[i, 2] * (shift - lo) / omega
    return total


@njit(cache=True, nogil=True)
def shift_and_jump(M, W, O, ist, fst, prm, table, chi, clo, shift, ex_m, ex_y, ex_d, p_lam):
    """Shift every delta_F down by ``shift`` bins and make the mass that crosses jump.

    Exits are pooled by true delta_R bin in ``ex_*`` (which must be zero or hold exits
    still waiting) and landed by :func:`inject_exits`.  Returns ``(jumped mass, change
    of sum(M * delta_F))``, or ``(-1 or -2, moment so far)`` if a landing fell outside
    the arrays (the shift is applied; the exits wait in ``ex_*``).
    """
    off = ist[I_OFF]
    phi = fst[F_PHI]
    eps = prm[P_EPS]
    jb = ist[I_JBASE]
    nrow = M.shape[0]
    phi_b = phi + shift
    any_exit = False
    for r in range(ist[I_RLO], ist[I_RHI]):
        if clo[r] > off + SCAN:
            continue
        j = r + jb
        for d in range(-SCAN, SCAN + 1):
            c = off + d
            m = M[r, c]
            if m <= 0.0:
                continue
            eta = W[r, c] / m
            omega = O[r, c] / m
            y = (j + eta) * eps
            x = (d - j + 1 - phi - 0.5 * omega) * eps  # before the shift
            corr = _correction(fst, prm, y, x)
            hi = d + 1 - phi_b + eta + corr / eps  # true upper edge after the shift
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
            # exits are pooled by their true delta_R bin: landing is linear in delta_R,
            # so one landing per pool keeps every first moment exact
            pool = int(math.floor((y + corr) / eps + 0.5)) - jb
            pool = min(max(pool, 0), nrow - 1)
            ex_m[pool] += out
            ex_y[pool] += out * (y + corr)
            ex_d[pool] += out * depth
            any_exit = True
    fst[F_SUMX] -= shift * eps * fst[F_MASS]
    whole = int(math.floor(phi_b + 1e-12))
    if whole > 0:
        phi_b = max(phi_b - whole, 0.0)
        ist[I_OFF] = off + whole
    fst[F_PHI] = phi_b
    if not any_exit:
        return 0.0, 0.0
    return inject_exits(M, W, O, ist, fst, prm, table, chi, clo, ex_m, ex_y, ex_d, p_lam)


@njit(cache=True, nogil=True)
def inject_exits(M, W, O, ist, fst, prm, table, chi, clo, ex_m, ex_y, ex_d, p_lam):
    """Land the exits collected per row in ``ex_*``; rows whose landing fits are cleared.
    Returns ``(jumped, moment)``, or ``(-1 or -2, moment so far)`` if some landing did
    not fit the rows (columns)."""
    jumped = 0.0
    moment = 0.0
    failed = 0.0
    for r in range(ex_m.shape[0]):
        em = ex_m[r]
        if em > 0.0:
            n, dmom = inject(M, W, O, ist, fst, prm, table, chi, clo, em, ex_y[r] / em, ex_d[r] / em, p_lam)
            if n < 0.0:
                failed = n
                continue
            ex_m[r] = 0.0
            ex_y[r] = 0.0
            ex_d[r] = 0.0
            jumped += n
            moment += dmom
    fst[F_SUMX] += moment
    if failed < 0.0:
        return failed, moment
    return jumped, moment


@njit(cache=True, nogil=True)
def _apply_jumps(fst, prm, jumped, moment):
    """Account for jumps that moved sum(M * delta_F) by ``moment``: hbar moves by
    ``moment / kappa``, the stress drops by ``k0`` times that and every delta_F owes a
    further shift of ``(k1 + k2)`` times that (the redistribution).  Returns the owed
    shift in bins."""
    dh = moment / prm[P_KAPPA]
    fst[F_HBAR] += dh
    fst[F_SIGMA] -= prm[P_K0] * dh
    fst[F_JUMPS] += jumped
    return (prm[P_K1] + prm[P_K2]) * dh / prm[P_EPS]


@njit(cache=True, nogil=True)
def close_step(M, W, O, ist, fst, prm, table, chi, clo, owed, tol, ex_m, ex_y, ex_d, p_lam, cand, max_iter):
    """Apply ``owed`` bins of shift and the stress redistribution it triggers.

    The shift that closes the cascade solves ``shift = owed + c * crossing(shift)``
    (``c`` the redistribution per unit of crossing mass); the exits of that shift are
    then computed exactly, and what the prediction missed (mass landing within the
    shift, the true mean jump) is owed again.
    An avalanche (``c >= 1``) applies what it owes, at most ``MAX_SHIFT`` bins at a
    time, and goes on.  The remainder (below ``OWED_TOL``, possibly negative) is
    carried in ``F_OWED``, so ``sum(M * delta_F) + sigma - owed * eps`` is exactly
    constant.  Returns ``(total shift, iterations, code)``: ``code`` is DONE, or
    NEED_ROWS / NEED_COLS when a landing did not fit the arrays (the exits wait in ``ex_*``),
    or STOP_EVENT when the cascade has shifted ``P_STOP_SHIFT`` bins and still goes on (the
    rest is owed in ``F_OWED``: the caller stops at the start of a global shock).
    """
    eps = prm[P_EPS]
    c_per_mass = (prm[P_K1] + prm[P_K2]) * prm[P_ZMEAN] / eps
    total = 0.0
    it = 0
    while owed > tol and it < max_iter:
        it += 1
        # solve shift = owed + c_per_mass * crossing_mass(shift) by fixed-point iteration
        # on the predicted exits (monotone from below); an avalanche hits MAX_SHIFT
        n_cand = crossing_candidates(M, W, O, ist, fst, prm, clo, cand)
        step = owed
        for _ in range(200):
            if step >= MAX_SHIFT:
                step = MAX_SHIFT
                break
            new_step = owed + c_per_mass * _crossing(cand, n_cand, step)
            if abs(new_step - step) <= 1e-3 * tol:
                step = new_step
                break
            step = new_step
        if step > MAX_SHIFT:
            step = MAX_SHIFT
        jumped, moment = shift_and_jump(M, W, O, ist, fst, prm, table, chi, clo, step, ex_m, ex_y, ex_d, p_lam)
        total += step
        owed -= step
        if jumped < 0.0:
            owed += _apply_jumps(fst, prm, 0.0, moment)
            fst[F_OWED] = owed
            return total, it, NEED_ROWS if jumped > -1.5 else NEED_COLS
        if jumped > 0.0:
            owed += _apply_jumps(fst, prm, jumped, moment)
        if total >= prm[P_STOP_SHIFT]:
            break
    fst[F_OWED] = owed
    if total >= prm[P_STOP_SHIFT] and owed > tol:
        return total, it, STOP_EVENT
    return total, it, DONE


# ------------------------------------------------------------------------ synchronisation
@njit(cache=True, nogil=True)
def synchronise(M, W, O, Mn, Wn, On, ist, fst, prm, table, chi, clo, chi_n, clo_n, ex_m, ex_y, ex_d):
    """Move every cell to its true delta_R (exact relaxation since t_a) and reset t_a.

    Reads and zeroes ``M, W, O``; writes ``Mn, Wn, On`` (zero on entry).  Mass found
    below threshold (only within rounding, since exits follow the true positions) jumps.
    Sets the relaxation factor at which to synchronise next: when a near-threshold cell
    may have moved ``P_THETA_R`` bins, or any cell ``SCAN - 2`` bins closer to the
    threshold than stored.  Returns ``(jumped, moment, code)``.
    """
    eps = prm[P_EPS]
    off = ist[I_OFF]
    phi = fst[F_PHI]
    jb = ist[I_JBASE]
    nrow = M.shape[0]
    new_rlo = nrow
    new_rhi = 0
    sum_x = 0.0
    sum_y = 0.0
    sum_m = 0.0
    neg = 0.0
    need = 0.5  # smallest safe 1 - lam until the next synchronisation
    for r in range(nrow):
        ex_m[r] = 0.0
        ex_y[r] = 0.0
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
            y = (j + eta) * eps + _correction(fst, prm, (j + eta) * eps, x)
            sum_x += m * x
            sum_y += m * y
            sum_m += m
            u = y / eps
            jp = int(math.floor(u + 0.5))
            etap = u - jp
            rp = jp - jb
            cp = off + k + jp
            if rp < 1 or rp > nrow - 2 or cp > Mn.shape[1] - 2:
                return -1.0, 0.0, INTERNAL_ERROR  # bounds() rules this out
            hi = k + jp + 1 - phi + etap
            if hi - omega < 0.0:
                if hi <= EDGE_TOL:
                    out = m
                    depth = 0.5 * omega - hi
                else:
                    out = m * (1.0 - hi / omega)
                    depth = 0.5 * (omega - hi)
                ex_m[rp] += out
                ex_y[rp] += out * y
                ex_d[rp] += out * depth
                m -= out
                omega = hi
            if rp < new_rlo:
                new_rlo = rp
            if rp + 1 > new_rhi:
                new_rhi = rp + 1
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
    fst[F_SUMX] = sum_x
    fst[F_MASS] = sum_m
    fst[F_TREF] = fst[F_T]
    fst[F_HREF] = fst[F_HBAR]
    fst[F_LAM] = 1.0
    # <delta_R> relaxes exactly as exp(-gamma t) (<u> does, and jumps keep u); the
    # binned landings of jumping mass miss that by O(eps^2) per jump, a bias that the
    # relaxation alone would only bound at (jump rate) * eps^2 / gamma, i.e. growing
    # with V.  Restore the invariant with a uniform offset carried by the drift term.
    fst[F_DRIFT] = fst[F_YMEAN] - sum_y / sum_m
    # --- schedule: the next synchronisation comes before any cell's correction
    # (1 - lam) * pull can exceed SCAN - 2 bins, or P_THETA_R bins for a cell at the
    # threshold; mass that lands meanwhile pulls at most P_PULL_LAND bins.
    mean_x = sum_x / sum_m
    g = prm[P_K2] / prm[P_KAPPA]
    pull_all = prm[P_PULL_LAND]
    pull_near = 0.0
    for r in range(new_rlo, new_rhi):
        j = r + jb
        for c in range(clo_n[r], chi_n[r]):
            m = Mn[r, c]
            if m <= LIGHT:
                continue
            eta = Wn[r, c] / m
            omega = On[r, c] / m
            x = (c - off - j + 1 - phi - 0.5 * omega) * eps
            pull = abs(g * (mean_x - x) - (j + eta) * eps) / eps  # full relaxation, in bins
            if pull > pull_all:
                pull_all = pull
            if c - off + 1 - phi + eta - omega < SCAN and pull > pull_near:
                pull_near = pull
    if pull_all > 0.0:
        need = min(need, (SCAN - 2) / pull_all)
    if pull_near > 0.0:
        need = min(need, prm[P_THETA_R] / pull_near)
    fst[F_LAM_SYNC] = 1.0 - need
    # jumps of mass found below threshold
    jumped, moment = inject_exits(Mn, Wn, On, ist, fst, prm, table, chi_n, clo_n, ex_m, ex_y, ex_d, 1.0)
    if jumped < 0.0:
        return -1.0, moment, NEED_ROWS if jumped > -1.5 else NEED_COLS
    return jumped, moment, DONE


@njit(cache=True, nogil=True)
def bounds(ist, fst, prm, clo, chi):
    """Rows and columns that the true positions, or a full relaxation from them, can
    reach: ``(rmin, rmax, cmax)``."""
    eps = prm[P_EPS]
    g = prm[P_K2] / prm[P_KAPPA]
    off = ist[I_OFF]
    phi = fst[F_PHI]
    jb = ist[I_JBASE]
    mean_x = fst[F_SUMX] / fst[F_MASS]
    rmin = 1 << 60
    rmax = -(1 << 60)
    cmax = -(1 << 60)
    for r in range(ist[I_RLO], ist[I_RHI]):
        if chi[r] <= clo[r]:
            continue
        j = r + jb
        for k in (clo[r] - off - j, chi[r] - 1 - off - j):
            for frac in (0.0, 1.0):
                x = (k + frac - phi) * eps
                for y in ((j - 0.5) * eps, (j + 0.5) * eps):
                    for yy in (y + _correction(fst, prm, y, x), g * (mean_x - x)):
                        jp = int(math.floor(yy / eps + 0.5))
                        rmin = min(rmin, jp - jb - 1)
                        rmax = max(rmax, jp - jb + 1)
                        cmax = max(cmax, off + k + jp + 1)
    return rmin, rmax, cmax


# ------------------------------------------------------------------------ records
@njit(cache=True, nogil=True)
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


# ------------------------------------------------------------------------ the loop
@njit(cache=True, nogil=True)
def advance(bufM, bufW, bufO, bufchi, bufclo, ist, fst, prm, table, ex_m, ex_y, ex_d, cand,
            velocity, t_stop, max_steps, cols_needed, rec, rec_dt, shocks, stop_shocks):
    """Advance the density from ``fst[F_T]`` to ``t_stop`` at drive velocity ``velocity``.

    One step advances the time by ``dt`` (the relaxation is carried by the lazy
    representation), drives by ``velocity * dt`` and closes the cascade of shifts,
    jumps and redistribution.  ``dt`` keeps the shift within ``P_THETA_S`` bins.  When
    the relaxation factor has fallen to ``F_LAM_SYNC`` every cell is synchronised.

    Records ``t, sigma, min, max, time mean`` (over the window since the previous
    record) whenever the stress has moved ``P_REC_DSIGMA`` since the last record, after
    at most ``rec_dt``, and on both sides of every shock (a step whose cascade shifts
    more than ``P_SHOCK`` bins; also listed as ``t, sigma before, sigma after, shift``).
    Returns a code telling why it stopped; on ``NEED_ROWS`` / ``NEED_COLS`` the caller
    grows the arrays and calls again (pending exits wait in ``ex_*``).
    """
    k0 = prm[P_K0]
    eps = prm[P_EPS]
    gamma = prm[P_GAMMA]
    ncol = bufM.shape[2]
    nrow = bufM.shape[1]
    steps = 0
    a = ist[I_CUR]
    # exits left pending by a previous NEED_* return
    for r in range(nrow):
        if ex_m[r] > 0.0:
            jumped, moment = inject_exits(bufM[a], bufW[a], bufO[a], ist, fst, prm, table, bufchi[a], bufclo[a],
                                          ex_m, ex_y, ex_d, max(fst[F_LAM], 1e-300))
            if jumped < 0.0:
                fst[F_OWED] += _apply_jumps(fst, prm, 0.0, moment)
                return NEED_ROWS if jumped > -1.5 else NEED_COLS
            fst[F_OWED] += _apply_jumps(fst, prm, jumped, moment)
            break
    while True:
        t = fst[F_T]
        if t_stop - t <= 1e-14 * max(1.0, abs(t_stop)):
            return DONE
        if steps >= max_steps:
            return MAX_STEPS
        off = ist[I_OFF]
        if off < SCAN + 3 or off + cols_needed + SCAN + 3 > ncol:
            return NEED_COLS
        a = ist[I_CUR]
        # --- synchronise when the stored positions are too stale
        # (the uniform part of every cell's correction, drift minus the relaxation of the
        # target's k2 * (hbar - hbar_a) term, is kept within one bin: at large V it grows
        # like k2 V gamma t^2 / 2 and would otherwise carry cells past the scan window)
        uniform = fst[F_DRIFT] - (1.0 - fst[F_LAM]) * prm[P_K2] * (fst[F_HBAR] - fst[F_HREF])
        if gamma > 0.0 and (fst[F_LAM] <= fst[F_LAM_SYNC] * (1.0 + 1e-12) or abs(uniform) > eps):
            rmin, rmax, cmax = bounds(ist, fst, prm, bufclo[a], bufchi[a])
            if rmin < 1 or rmax > nrow - 2:
                return NEED_ROWS
            if cmax > ncol - 2:
                return NEED_COLS
            b = 1 - a
            for r in range(nrow):
                bufchi[b, r] = 0
                bufclo[b, r] = ncol
            jumped, moment, code = synchronise(bufM[a], bufW[a], bufO[a], bufM[b], bufW[b], bufO[b], ist, fst, prm,
                                               table, bufchi[a], bufclo[a], bufchi[b], bufclo[b], ex_m, ex_y, ex_d)
            if code == INTERNAL_ERROR:
                return code
            ist[I_CUR] = b
            ist[I_SYNCS] += 1
            a = b
            fst[F_OWED] += _apply_jumps(fst, prm, max(jumped, 0.0), moment)
            if code != DONE:
                return code
        M = bufM[a]
        W = bufW[a]
        O = bufO[a]
        chi = bufchi[a]
        clo = bufclo[a]
        # --- step size: the shift, and the relaxation until the next synchronisation
        shift_rate = (k0 * velocity + (prm[P_K1] + prm[P_K2]) * fst[F_SLIP_RATE]) / eps
        dt = prm[P_DT_MAX]
        if shift_rate > 0.0:
            dt = min(dt, max(prm[P_THETA_S] / shift_rate, DT_MIN))
        if gamma > 0.0 and fst[F_LAM] > fst[F_LAM_SYNC]:
            dt = min(dt, math.log(fst[F_LAM] / fst[F_LAM_SYNC]) / gamma * (1.0 + 1e-9))
        dt = min(dt, t_stop - t)
        # --- time advance: relaxation factor and drift (hbar is constant within the step)
        lam_step = math.exp(-gamma * dt)
        fst[F_DRIFT] = lam_step * fst[F_DRIFT] + prm[P_K2] * (fst[F_HBAR] - fst[F_HREF]) * (1.0 - lam_step)
        fst[F_LAM] *= lam_step
        fst[F_YMEAN] *= lam_step
        # --- drive, then the cascade it triggers (the jumps happen at the end of the step)
        sigma_prev = fst[F_SIGMA]
        hbar_prev = fst[F_HBAR]
        fst[F_T] = t + dt
        fst[F_W] += velocity * dt
        fst[F_SIGMA] += k0 * velocity * dt
        drive = k0 * velocity * dt / eps
        owed = fst[F_OWED] + drive
        sigma_before = fst[F_SIGMA]
        tol = max(OWED_FLOOR, OWED_REL * drive)
        total, it, code = close_step(M, W, O, ist, fst, prm, table, chi, clo, owed, tol, ex_m, ex_y, ex_d,
                                     max(fst[F_LAM], 1e-300), cand, 100000000)
        ist[I_ITER] += it
        # a short step (cut by a synchronisation, a record or t_stop) may close no jump
        # although the blocks slide: remember the previous rate for a few steps, or the
        # next step would drive unchecked and release a spurious shock
        fst[F_SLIP_RATE] = max((fst[F_HBAR] - hbar_prev) / dt, 0.5 * fst[F_SLIP_RATE])
        steps += 1
        ist[I_STEPS] += 1
        sigma_after = fst[F_SIGMA]
        # --- records.  The state after the cascade is the accurate one (within a step the
        # drive is applied before the jumps it causes): averages and extrema use
        # post-cascade values; the value before the cascade counts only as a shock's peak.
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
        if code != DONE:
            return code
        if ist[I_NREC] + 2 >= rec.shape[0]:
            return RECORDS_FULL
        if ist[I_NSHOCK] >= shocks.shape[0]:
            return SHOCKS_FULL
        if stop_shocks > 0 and ist[I_NSHOCK] >= stop_shocks:
            return STOP_EVENT
