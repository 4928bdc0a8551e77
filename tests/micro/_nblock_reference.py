"""A plain-numpy brute-force reference of the N-block simulation, for the tests only.

O(N) per event with explicit u_i, for small N: :func:`reference_simulate` and the numpy
twin of the kernels' pinning-landscape hash.  It shares the input checks and the
segment table of :mod:`micro.nblock` (so both read a drive the same way), nothing of
its event loop.
"""
from __future__ import annotations

import math

import numpy as np
from scipy.optimize import brentq

from micro.nblock import NBlockState, Velocity, _check_int, _check_model, _segments, initial_state
from micro.params import Model

# ---------------------------------------------------------------------------------------
# a plain-numpy brute-force reference (O(N) per event, explicit u_i), for small N only
# ---------------------------------------------------------------------------------------
_U64 = np.uint64


def _mix64_numpy(z: np.ndarray) -> np.ndarray:
    z = (z ^ (z >> _U64(30))) * _U64(0xBF58476D1CE4E5B9)
    z = (z ^ (z >> _U64(27))) * _U64(0x94D049BB133111EB)
    return z ^ (z >> _U64(31))


def hash_uniform_numpy(seed: int, block: np.ndarray, count: np.ndarray) -> np.ndarray:
    """numpy twin of :func:`micro._nblock_kernels.hash_uniform` (the pinning landscape)."""
    block = np.atleast_1d(np.asarray(block)).astype(np.uint64)
    count = np.atleast_1d(np.asarray(count)).astype(np.uint64)
    with np.errstate(over="ignore"):
        k = _mix64_numpy(np.full(block.shape, seed, dtype=np.uint64) ^ (block * _U64(0x9E3779B97F4A7C15)))
        k = _mix64_numpy(k + count * _U64(0xD1B54A32D192ED03))
    return ((k >> _U64(11)).astype(float) + 0.5) / 9007199254740992.0


def reference_simulate(
    model: Model,
    velocity: Velocity,
    n_blocks: int,
    t_max: float | None = None,
    seed: int = 0,
    initial: str | NBlockState = "relaxed",
    phases: str = "stratified",
) -> dict:
    r"""Brute-force reference of :func:`simulate_nblock` for small N (tests only).

    It keeps :math:`h_i` and :math:`u_i` explicitly, relaxes every :math:`u_i` by Eq. (B3)
    between events, evaluates Eq. (B1) for every block, finds each block's crossing with
    :func:`scipy.optimize.brentq`, and topples all unstable blocks of an avalanche together
    in sweeps. Distances come from ``model.jumps.quantile`` of the same landscape hash.
    Costs O(N) per event.

    Returns a dict with ``state`` (final :class:`NBlockState`), ``n_jumps``, ``n_avalanches``,
    ``sigma_integral`` (integral of sigma over [0, t_max]) and ``avalanches``
    (list of (t, size)).
    """

    _check_model(model)
    n = _check_int("n_blocks", n_blocks, 2, 4096)
    seg_end, seg_vel, t_max = _segments(velocity, t_max)
    if isinstance(initial, NBlockState):
        h, u, w = np.array(initial.h, dtype=float), np.array(initial.u, dtype=float), float(initial.w)
    else:
        st = initial_state(model, n, kind=initial, phases=phases, seed=seed % (2**63))
        h, u, w = st.h.copy(), st.u.copy(), st.w
    k0, k1, k2, f_th, gamma = model.k0, model.k1, model.k2, model.f_th, model.gamma
    count = np.zeros(n, dtype=np.int64)
    t = 0.0
    integral = 0.0
    n_jumps = 0
    avalanches: list[tuple[float, int]] = []

    def distances(blocks: np.ndarray) -> np.ndarray:
        uu = hash_uniform_numpy(seed, blocks, count[blocks])
        return np.asarray(model.jumps.quantile(uu), dtype=float)

    def margins() -> np.ndarray:
        hbar = h.mean()
        return f_th - k0 * (w - h) - (k1 + k2) * (hbar - h) + k2 * u

    seg = 0
    while True:
        v = seg_vel[seg]
        tau_max = seg_end[seg] - t
        hbar = h.mean()
        alpha = f_th - k0 * w - k1 * hbar + (k0 + k1) * h  # relaxed margin
        beta = k2 * (u - (hbar - h))
        f_end = alpha + beta * math.exp(-gamma * tau_max) - k0 * v * tau_max
        best_tau, best_i = math.inf, -1
        for i in np.flatnonzero(f_end <= 0.0):
            a_i, b_i = alpha[i], beta[i]
            if a_i + b_i <= 0.0:
                tau = 0.0
            else:
                tau = brentq(lambda s: a_i + b_i * math.exp(-gamma * s) - k0 * v * s, 0.0, tau_max,
                             xtol=1e-15, rtol=8.9e-16)
            if tau < best_tau:
                best_tau, best_i = tau, i
        tau = min(best_tau, tau_max)
        # advance: drive and relax (Eq. (B3)) with hbar fixed
        integral += k0 * (w - hbar) * tau + 0.5 * k0 * v * tau * tau
        u = (hbar - h) + (u - (hbar - h)) * math.exp(-gamma * tau)
        w += v * tau
        t += tau
        if best_i >= 0 and best_tau <= tau_max:
            unstable = np.array([best_i])
            size = 0
            while unstable.size:
                h[unstable] += distances(unstable)
                count[unstable] += 1
                size += unstable.size
                unstable = np.flatnonzero(margins() <= 0.0)
            n_jumps += size
            avalanches.append((t, size))
        else:
            t = float(seg_end[seg])
            if seg == len(seg_end) - 1:
                break
            seg += 1
    state = NBlockState(h=h, u=u, w=w, t=t)
    return {
        "state": state,
        "n_jumps": n_jumps,
        "n_avalanches": len(avalanches),
        "sigma_integral": integral,
        "avalanches": avalanches,
    }
