"""Numba kernels of the event-driven N-block simulation (orchestrated by :mod:`micro.nblock`).

Nothing here validates its input: :mod:`micro.nblock` builds every array and checks every
parameter before calling :func:`run_events`.

Lazy representation (derived in ``docs/reference/micro_nblock.md``)
---------------------------------------------------------
With :math:`s_i = u_i + h_i` and the global exponentially weighted mean :math:`m(t)` of
:math:`\\bar h` (:math:`\\dot m = \\gamma(\\bar h - m)`, :math:`\\gamma = k_2/\\eta_u`), every block
obeys :math:`s_i(t) = m(t) + x(t) S_i` with :math:`x(t) = e^{-\\gamma (t - t_{ref})}` and a
constant :math:`S_i` between its own jumps. Eq. (B1) becomes

.. math:: \\delta_i(t) = \\underbrace{(k_0+k_1) h_i}_{a_i} + \\underbrace{k_2 S_i}_{b_i}\\, x(t) - \\Phi(t),
          \\qquad \\Phi = k_0 w + (k_1+k_2)\\bar h - k_2 m - f_{th}.

So the order of the blocks by :math:`\\delta_i` is the order of the lines
:math:`T_i(x) = a_i + b_i x`, and a kinetic tournament tree (each internal node keeps the
winner of its two children and the value of x at which they swap) gives the least stable
block at any time in O(1) and keeps itself valid in O(log N) per jump or swap.
"""
from __future__ import annotations

import math

import numpy as np
from numba import njit

# ---- slots of the float state vector ---------------------------------------------------
F_T = 0  # time
F_TREF = 1  # reference time of x = exp(-gamma (t - t_ref))
F_X = 2  # x(t)
F_W = 3  # drive position (relative to F_OFFSET)
F_HBAR = 4  # mean position (relative to F_OFFSET)
F_M = 5  # exponentially weighted mean of hbar (relative to F_OFFSET)
F_OFFSET = 6  # origin of positions
F_SUMS = 7  # sum of S_i (for the mean of u)
N_FSTATE = 8

# ---- slots of the integer counters --------------------------------------------------------
C_JUMPS = 0
C_AVALANCHES = 1
C_SWAPS = 2  # certificate failures processed by the kinetic tree
C_SHOCKS = 3  # global shocks recorded
C_REBASES = 4
C_BINS = 5  # bins filled
C_STATUS = 6  # 0 running/finished at t_max, 1 stopped after the requested shocks, 2 jump limit
C_SHOCKS_LOST = 7  # global shocks that did not fit in the output buffer
N_COUNTERS = 8

STATUS_COMPLETED = 0
STATUS_SHOCK_LIMIT = 1
STATUS_JUMP_LIMIT = 2

# ---- slots of the parameter vector -------------------------------------------------------
P_K0 = 0
P_K1 = 1
P_K2 = 2
P_GAMMA = 3
P_FTH = 4
P_INVN = 5
P_KIND = 6
P_ZBAR = 7
P_NORM = 8  # 1 - exp(-cutoff / zbar) of the exponential distribution
P_POSBOUND = 9  # shift the origin when |hbar| exceeds this
N_PARAMS = 10

KIND_EXPONENTIAL = 0
KIND_DETERMINISTIC = 1
KIND_TABLE = 2

REBASE_THETA = 20.0  # rebase x when gamma (t - t_ref) reaches this (x >= 2e-9)
SWAP_TIE = 1e-12  # relative tolerance under which two lines are considered equal now
NO_CERT = -1.0

# ---- columns of the tree array (one row per node, so that a node is one half cache line) --
T_A = 0  # a of the node's winner
T_B = 1  # b of the node's winner
T_XC = 2  # certificate: x at which the node's comparison flips (NO_CERT: never)
T_MXC = 3  # largest certificate in the node's subtree
N_TREE_COLS = 4

_M1 = np.uint64(0xBF58476D1CE4E5B9)
_M2 = np.uint64(0x94D049BB133111EB)
_GOLDEN = np.uint64(0x9E3779B97F4A7C15)
_ODD = np.uint64(0xD1B54A32D192ED03)
_S30 = np.uint64(30)
_S27 = np.uint64(27)
_S31 = np.uint64(31)
_S11 = np.uint64(11)
_TWO_M53 = 1.0 / 9007199254740992.0


# ---- random pinning landscape ------------------------------------------------------------
@njit(cache=True, nogil=True, inline="always")
def mix64(z):
    """splitmix64 finaliser of an unsigned 64-bit integer."""
    z = (z ^ (z >> _S30)) * _M1
    z = (z ^ (z >> _S27)) * _M2
    return z ^ (z >> _S31)


@njit(cache=True, nogil=True, inline="always")
def hash_uniform(seed, block, count):
    """A uniform number in (0, 1) fixed by (seed, block, count): the ``count``-th well of ``block``.

    Each block owns a reproducible random landscape, so the outcome of an avalanche does
    not depend on the order in which its unstable blocks are processed.
    """
    k = mix64(np.uint64(seed) ^ (np.uint64(block) * _GOLDEN))
    k = mix64(k + np.uint64(count) * _ODD)
    return (float(k >> _S11) + 0.5) * _TWO_M53


@njit(cache=True, nogil=True, inline="always")
def draw_distance(par, qtab_u, qtab_z, seed, block, count):
    """The distance to the next pinning well of ``block`` at its ``count``-th jump."""
    u = hash_uniform(seed, block, count)
    kind = int(par[P_KIND])
    if kind == KIND_EXPONENTIAL:
        return -par[P_ZBAR] * math.log1p(-u * par[P_NORM])
    if kind == KIND_DETERMINISTIC:
        return par[P_ZBAR]
    return np.interp(u, qtab_u, qtab_z)


# ---- one block between events ----------------------------------------------------------
@njit(cache=True, nogil=True, inline="always")
def first_crossing(alpha, beta, gamma, drive, tau_max):
    """First root in [0, tau_max] of f(tau) = alpha + beta exp(-gamma tau) - drive tau.

    f is the stability margin delta of one block while hbar is constant (Eq. (B3) plus the
    drive). f is convex and decreasing for beta >= 0 and concave for beta < 0, so if
    f(0) > 0 it has a root in [0, tau_max] iff f(tau_max) <= 0, and that root is unique.
    Returns -1 if there is none, 0 if f(0) <= 0. Newton's method from the side where it
    converges monotonically (left for convex, right for concave), safeguarded by bisection.
    """
    f0 = alpha + beta
    if f0 <= 0.0:
        return 0.0
    fe = alpha + beta * math.exp(-gamma * tau_max) - drive * tau_max
    if fe > 0.0:
        return -1.0
    lo = 0.0
    hi = tau_max
    tau = lo if beta >= 0.0 else hi
    for _ in range(200):
        e = math.exp(-gamma * tau)
        f = alpha + beta * e - drive * tau
        if f > 0.0:
            lo = tau
        else:
            hi = tau
        fp = -gamma * beta * e - drive
        new = 0.5 * (lo + hi)
        if fp < 0.0:
            cand = tau - f / fp
            if lo <= cand <= hi:
                new = cand
        if f == 0.0 or abs(new - tau) <= 1e-15 * abs(new) or hi - lo <= 1e-15 * hi:
            return new
        tau = new
    return hi


# ---- kinetic tournament tree -------------------------------------------------------------
@njit(cache=True, nogil=True, inline="always")
def tree_recompute(v, win, tree, x):
    """Recompute internal node v from its two children at the current x.

    The winner is the line a + b x lower now; the certificate tree[v, T_XC] is the x (< now)
    at which the loser overtakes it, or NO_CERT if it never does (x only decreases). Lines
    within SWAP_TIE of each other are treated as equal now and the one lower in the
    future (larger b) wins, so that a swap is never scheduled at the present x.
    """
    left = 2 * v
    right = left + 1
    il = win[left]
    ir = win[right]
    if ir < 0 or il < 0:
        src = left if ir < 0 else right
        win[v] = win[src]
        tree[v, T_A] = tree[src, T_A]
        tree[v, T_B] = tree[src, T_B]
        tree[v, T_XC] = NO_CERT
    else:
        al = tree[left, T_A]
        bl = tree[left, T_B]
        ar = tree[right, T_A]
        br = tree[right, T_B]
        if al + bl * x <= ar + br * x:
            w, aw, bw, ao, bo = left, al, bl, ar, br
        else:
            w, aw, bw, ao, bo = right, ar, br, al, bl
        cert = NO_CERT
        if bw < bo:
            xs = (aw - ao) / (bo - bw)
            if xs >= x * (1.0 - SWAP_TIE):
                # equal now: take the one that stays lower
                w = right if w == left else left
                aw, bw = ao, bo
            else:
                cert = xs
        win[v] = win[w]
        tree[v, T_A] = aw
        tree[v, T_B] = bw
        tree[v, T_XC] = cert
    m = tree[v, T_XC]
    if tree[left, T_MXC] > m:
        m = tree[left, T_MXC]
    if tree[right, T_MXC] > m:
        m = tree[right, T_MXC]
    tree[v, T_MXC] = m


@njit(cache=True, nogil=True, inline="always")
def tree_set_leaf(i, a_i, b_i, n_leaves, win, tree, x):
    """Give block i the line a_i + b_i x and repair the path to the root."""
    v = n_leaves + i
    tree[v, T_A] = a_i
    tree[v, T_B] = b_i
    v >>= 1
    while v >= 1:
        tree_recompute(v, win, tree, x)
        v >>= 1


@njit(cache=True, nogil=True)
def tree_build(h, s_coef, par, n_leaves, win, tree, x):
    """Fill the leaves with the blocks' lines and build every internal node at x."""
    n = h.shape[0]
    k01 = par[P_K0] + par[P_K1]
    k2 = par[P_K2]
    for v in range(n_leaves, 2 * n_leaves):
        i = v - n_leaves
        tree[v, T_XC] = NO_CERT
        tree[v, T_MXC] = NO_CERT
        if i < n:
            win[v] = i
            tree[v, T_A] = k01 * h[i]
            tree[v, T_B] = k2 * s_coef[i]
        else:
            win[v] = -1
            tree[v, T_A] = np.inf
            tree[v, T_B] = 0.0
    for v in range(n_leaves - 1, 0, -1):
        tree_recompute(v, win, tree, x)


@njit(cache=True, nogil=True)
def tree_process_swaps(win, tree, x, n_leaves):
    """Repair every node whose certificate has failed (certificate >= x), deepest first."""
    count = 0
    while tree[1, T_MXC] >= x:
        v = 1
        while v < n_leaves:
            if tree[2 * v, T_MXC] >= x:
                v = 2 * v
            elif tree[2 * v + 1, T_MXC] >= x:
                v = 2 * v + 1
            else:
                break
        while v >= 1:
            tree_recompute(v, win, tree, x)
            v >>= 1
        count += 1
    return count


# ---- global bookkeeping ------------------------------------------------------------------
@njit(cache=True, nogil=True, inline="always")
def phi(fs, par):
    """The common part of delta: Phi = k0 w + (k1 + k2) hbar - k2 m - f_th."""
    return (
        par[P_K0] * fs[F_W]
        + (par[P_K1] + par[P_K2]) * fs[F_HBAR]
        - par[P_K2] * fs[F_M]
        - par[P_FTH]
    )


@njit(cache=True, nogil=True, inline="always")
def advance(fs, par, velocity, t_new):
    """Drive and relax from fs[F_T] to t_new with hbar fixed; return the integral of sigma."""
    dt = t_new - fs[F_T]
    k0 = par[P_K0]
    gamma = par[P_GAMMA]
    integral = k0 * (fs[F_W] - fs[F_HBAR]) * dt + 0.5 * k0 * velocity * dt * dt
    fs[F_W] += velocity * dt
    if gamma > 0.0:
        decay = math.exp(-gamma * dt)
        fs[F_M] = fs[F_HBAR] + (fs[F_M] - fs[F_HBAR]) * decay
        fs[F_X] *= decay  # reset to exactly 1 at every rebase
    fs[F_T] = t_new
    return integral


@njit(cache=True, nogil=True)
def rebase(fs, par, h, s_coef, n_leaves, win, tree):
    """Reset x to 1 and move the origin of positions to hbar (O(N), rare).

    S_i -> S_i x keeps every s_i; shifting h, w, hbar and m together keeps every delta.
    The tree is rebuilt from the leaves, which also removes accumulated round-off.
    """
    n = h.shape[0]
    xr = fs[F_X]
    shift = fs[F_HBAR]
    total_h = 0.0
    total_s = 0.0
    for i in range(n):
        s_coef[i] *= xr
        h[i] -= shift
        total_h += h[i]
        total_s += s_coef[i]
    fs[F_W] -= shift
    fs[F_M] -= shift
    fs[F_OFFSET] += shift
    fs[F_HBAR] = total_h / n
    fs[F_SUMS] = total_s
    fs[F_TREF] = fs[F_T]
    fs[F_X] = 1.0
    tree_build(h, s_coef, par, n_leaves, win, tree, 1.0)


@njit(cache=True, nogil=True, inline="always")
def avalanche(
    trigger, fs, par, h, s_coef, n_jumps, seed, qtab_u, qtab_z, n_leaves, win, tree, max_jumps, counters
):
    """Instantaneous avalanche at the current time, started by block ``trigger``.

    A jump h_i -> h_i + z leaves u_i unchanged (rigid dashpot), so s_i -> s_i + z,
    S_i -> S_i + z / x, and delta_i rises by (k0 + k1 + k2) z; hbar rises by z / N, which
    lowers every delta by (k1 + k2) z / N. The least stable block jumps next while its
    delta is <= 0 (blocks may jump several times). Returns (number of jumps, total z).
    """
    k01 = par[P_K0] + par[P_K1]
    k2 = par[P_K2]
    inv_n = par[P_INVN]
    x = fs[F_X]
    i = trigger
    size = 0
    total_z = 0.0
    while True:
        z = draw_distance(par, qtab_u, qtab_z, seed, i, n_jumps[i])
        n_jumps[i] += 1
        h[i] += z
        dz = z / x
        s_coef[i] += dz
        fs[F_SUMS] += dz
        fs[F_HBAR] += z * inv_n
        tree_set_leaf(i, k01 * h[i], k2 * s_coef[i], n_leaves, win, tree, x)
        size += 1
        total_z += z
        counters[C_JUMPS] += 1
        if counters[C_JUMPS] >= max_jumps:
            break
        i = win[1]
        if tree[1, T_A] + tree[1, T_B] * x - phi(fs, par) > 0.0:
            break
    return size, total_z


# ---- the event loop ------------------------------------------------------------------------
@njit(cache=True, nogil=True)
def run_events(
    par,
    fs,
    counters,
    h,
    s_coef,
    n_jumps,
    seed,
    qtab_u,
    qtab_z,
    n_leaves,
    win,
    tree,
    seg_end,
    seg_velocity,
    bin_width,
    n_bins,
    t_max,
    out_t,
    out_w,
    out_sigma,
    out_sigma_mean,
    out_sigma_max,
    out_sigma_min,
    out_jumps,
    out_avalanches,
    out_max_avalanche,
    out_mean_u,
    shock_min_size,
    stop_after_shocks,
    shock_t,
    shock_sigma_before,
    shock_sigma_after,
    shock_size,
    shock_dhbar,
    size_hist,
    max_jumps,
):
    """Run the event-driven dynamics from fs[F_T] to t_max (or an earlier stop).

    Events are, in time order: an instability of the least stable block (the root of the
    tree), found exactly by :func:`first_crossing`, which starts an avalanche; a failed
    certificate of the tree; the end of an output bin; the end of a drive segment; a rebase.
    Between events hbar is constant and every block evolves in closed form, so the dynamics
    is exact up to round-off. Output bins hold the exact time average of sigma.
    """
    k0 = par[P_K0]
    k1 = par[P_K1]
    k2 = par[P_K2]
    gamma = par[P_GAMMA]
    f_th = par[P_FTH]
    inv_n = par[P_INVN]
    n_seg = seg_end.shape[0]
    seg = 0
    while seg < n_seg - 1 and seg_end[seg] <= fs[F_T]:
        seg += 1
    k = int(fs[F_T] / bin_width)
    if k > n_bins - 1:
        k = n_bins - 1
    bin_start = fs[F_T]
    integral = 0.0
    sigma = k0 * (fs[F_W] - fs[F_HBAR])
    sig_max = sigma
    sig_min = sigma
    jumps_bin = 0
    avalanches_bin = 0
    max_aval_bin = 0
    n_shock_slots = shock_t.shape[0]
    stop = False
    while True:
        velocity = seg_velocity[seg]
        t = fs[F_T]
        t_bin = (k + 1) * bin_width
        if t_bin > t_max or k == n_bins - 1:
            t_bin = t_max
        t_seg = seg_end[seg]
        if abs(fs[F_HBAR]) > par[P_POSBOUND]:
            rebase(fs, par, h, s_coef, n_leaves, win, tree)
            counters[C_REBASES] += 1
        t_rebase = np.inf
        t_cert = np.inf
        if gamma > 0.0:
            t_rebase = fs[F_TREF] + REBASE_THETA / gamma
            if tree[1, T_MXC] > 0.0:
                t_cert = fs[F_TREF] - math.log(tree[1, T_MXC]) / gamma
                if t_cert < t:
                    t_cert = t
        t_lim = min(t_bin, t_seg, t_rebase, t_cert)
        x = fs[F_X]
        alpha = tree[1, T_A] - k0 * fs[F_W] - k1 * fs[F_HBAR] + f_th
        beta = tree[1, T_B] * x + k2 * (fs[F_M] - fs[F_HBAR])
        tau = first_crossing(alpha, beta, gamma, k0 * velocity, t_lim - t)
        if tau >= 0.0:
            t_new = t + tau
            if t_new > t_lim:
                t_new = t_lim
            integral += advance(fs, par, velocity, t_new)
            sigma_before = k0 * (fs[F_W] - fs[F_HBAR])
            if sigma_before > sig_max:
                sig_max = sigma_before
            size, total_z = avalanche(
                win[1], fs, par, h, s_coef, n_jumps, seed, qtab_u, qtab_z,
                n_leaves, win, tree, max_jumps, counters,
            )
            sigma_after = k0 * (fs[F_W] - fs[F_HBAR])
            if sigma_after < sig_min:
                sig_min = sigma_after
            counters[C_AVALANCHES] += 1
            jumps_bin += size
            avalanches_bin += 1
            if size > max_aval_bin:
                max_aval_bin = size
            b = 0
            s = size
            while s > 1:
                s >>= 1
                b += 1
            size_hist[b] += 1
            if size >= shock_min_size:
                j = counters[C_SHOCKS]
                if j < n_shock_slots:
                    shock_t[j] = fs[F_T]
                    shock_sigma_before[j] = sigma_before
                    shock_sigma_after[j] = sigma_after
                    shock_size[j] = size
                    shock_dhbar[j] = total_z * inv_n
                    counters[C_SHOCKS] += 1
                else:
                    counters[C_SHOCKS_LOST] += 1
                if counters[C_SHOCKS] >= stop_after_shocks:
                    counters[C_STATUS] = STATUS_SHOCK_LIMIT
                    stop = True
            if counters[C_JUMPS] >= max_jumps:
                counters[C_STATUS] = STATUS_JUMP_LIMIT
                stop = True
        else:
            integral += advance(fs, par, velocity, t_lim)
            if t_lim == t_cert:
                if fs[F_X] > tree[1, T_MXC]:
                    fs[F_X] = tree[1, T_MXC]
                counters[C_SWAPS] += tree_process_swaps(win, tree, fs[F_X], n_leaves)
            if t_lim == t_rebase:
                rebase(fs, par, h, s_coef, n_leaves, win, tree)
                counters[C_REBASES] += 1
            if t_lim == t_seg and seg < n_seg - 1:
                seg += 1
        t = fs[F_T]
        if stop or t >= t_bin:
            sigma = k0 * (fs[F_W] - fs[F_HBAR])
            if sigma > sig_max:
                sig_max = sigma
            if sigma < sig_min:
                sig_min = sigma
            out_t[k] = t
            out_w[k] = fs[F_W] + fs[F_OFFSET]
            out_sigma[k] = sigma
            out_sigma_mean[k] = integral / (t - bin_start) if t > bin_start else sigma
            out_sigma_max[k] = sig_max
            out_sigma_min[k] = sig_min
            out_jumps[k] = jumps_bin
            out_avalanches[k] = avalanches_bin
            out_max_avalanche[k] = max_aval_bin
            out_mean_u[k] = fs[F_M] + fs[F_X] * fs[F_SUMS] * inv_n - fs[F_HBAR]
            counters[C_BINS] = k + 1
            if stop or k == n_bins - 1:
                break
            k += 1
            bin_start = t
            integral = 0.0
            sig_max = sigma
            sig_min = sigma
            jumps_bin = 0
            avalanches_bin = 0
            max_aval_bin = 0
