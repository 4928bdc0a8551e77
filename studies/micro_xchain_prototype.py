"""Does the cycle as a periodic renewal chain in the mean slip X converge, and does Newton solve it (issue 52, items 1-2)?

A prototype of the cycle map that issue 52 asks for, with a fixed layout whether shocks are
total or partial: not a solver of the package.  Exponential jumps.

**The chain.**  Given the drive time t(X) over one period L of the mean slip, every block is
an independent renewal process.  Just before a jump its state is its stretch e = x - u (the
lag minus the dashpot's) and where the jump happens; the jump draws z ~ Exp(zbar), leaves
the margin kappa z and the stretch e - z; from then on (Eqs. 1-2, micro_model.md §1)

    margin = kappa beta(tau) (z - D),  kappa beta D = k0 V tau + k1 dX + k2 (I - e (1 - e^{-gamma tau})),

tau the drive time and dX the mean slip since the jump, I = int e^{-gamma (t - t')} dX(t'),
beta = 1 - (k2 / kappa)(1 - e^{-gamma tau}).  The block jumps again where D first exceeds
z, so P(still pinned) = exp(-max D / zbar) in closed form, and its stretch there is
(e - z) e^{-gamma tau} + I.  In a shock (no time) D = (k1 + k2) dX / kappa: the blocks jump
as many times as their margins say, in any order.  The period is cut into intervals (slip
hs_k, time theta_k, both linear inside); the chain's states are (interval, e on a uniform
grid of m nodes in [e_lo, e_hi], hat functions), a block born at its interval's midpoint.
Its stationary measure is one sparse solve, normalised to L / zbar jumps per block per
period; the stress at X = 0 is f_th minus the mean margin of the blocks there.

**The closure and Newton.**  The mean slip is zbar times the jumps, so the jumps in each
interval must be hs_k / zbar.  Layout: n_l loading intervals of equal arclength
ds = dX + V dt (a fraction w_k of it slip), then n_s shock intervals of equal slip and no
time.  Unknowns: the n_l fractions, ds and the shock's slip.  Equations: the closure on the
n_l loading intervals, the fold (the jump density, linearly extrapolated from the first two
shock intervals to the shock's start, is 1 / zbar: branching ratio 1) and V T = L.  The
closure over the shock then holds by the normalisation.  Newton with a forward-difference
Jacobian (a chord iteration from the coarser level's solution with its Jacobian on a finer
e grid; where the chord stalls, Newton from the cohort cycle), started
from the cohort method's cycle (``micro.stationary(method="cohort").cycle``, its ``trace``).

``--steady``: at V (stable steady sliding) the chain with t = X / V against the renewal
chain's stress (``micro.steady_sliding``, no code shared), over ``--levels`` n,m.
``--cycle``: at ``--fraction`` V^c, for each level n_l,n_s,m the Newton solution's
sigma_max, sigma_min, period against the cohort method's.

Each row: kind, k0, V, fraction, n_l, n_s, m, e_lo, e_hi, sigma_max, sigma_min, period,
ref_sigma_max, ref_sigma_min, ref_period, newton_iterations, residual, start_residual,
e_support_lo, e_support_hi (where the stationary measure's stretch marginal exceeds 1e-9 of
its peak), clipped (the fraction of the jumps that landed outside the e grid, put on its
end), wall_s.  Writes benchmarks/results/micro_xchain_prototype.csv (rows merge by kind, k0, V,
n_l, n_s, m, e_lo, e_hi).  Recorded in docs/validation/micro_transition.md, claim 24.

    NUMBA_NUM_THREADS=1 python -m studies micro_xchain_prototype --steady 1.0 --levels 20,20 40,20 80,20 160,20
    NUMBA_NUM_THREADS=1 python -m studies micro_xchain_prototype --cycle --k0 0.1 --fraction 0.5 \\
        --e-range -0.05,0.3 --levels 20,20,40 20,20,80 20,20,160 20,40,80 20,40,160 40,40,80 20,80,80
"""
from __future__ import annotations

import argparse
import time

import numba as nb
import numpy as np
import scipy.sparse as sp
import scipy.sparse.linalg as spla

import micro

from benchmarks._harness import RESULTS, write_csv

CSV = RESULTS / "micro_xchain_prototype.csv"
KEYS = ["kind", "k0", "V", "n_l", "n_s", "m", "e_lo", "e_hi"]


@nb.njit(cache=True)
def _transitions(theta, hs, V, k0, k1, k2, gamma, zbar, egrid, s_min, kmax, cap):
    """The chain's transitions (rows, cols, masses) from each state (interval i, stretch node
    j), the probability each leaves unjumped after kmax intervals, the mean margin each
    leaves at X = 0 (the end of the last interval), and the mass it puts outside the e grid
    (``clipped[0] = -1``: ``cap`` too small)."""
    n = theta.size
    m = egrid.size
    kappa = k0 + k1 + k2
    de = egrid[1] - egrid[0]
    rows = np.empty(cap, np.int64)
    cols = np.empty(cap, np.int64)
    vals = np.empty(cap)
    nnz = 0
    lost = np.zeros(n * m)
    delta0 = np.zeros(n * m)
    clipped = np.zeros(n * m)
    for i in range(n):
        for j in range(m):
            src = i * m + j
            e1 = egrid[j]
            tau = 0.0
            I = 0.0
            M = 0.0
            S = 1.0
            Dp = 0.0
            exp_p = 1.0
            Ip = 0.0
            Xk = 0.0
            for k in range(0, kmax + 1):
                iv = (i + k) % n
                frac = 0.5 if k == 0 else 1.0  # (born at the midpoint of interval i)
                th = frac * theta[iv]
                h = frac * hs[iv]
                Xk += h
                g = gamma * th
                phi = (1.0 - np.exp(-g)) / g if g > 1e-8 else 1.0 - 0.5 * g
                I = I * np.exp(-g) + h * phi  # (X linear in t inside an interval)
                tau += th
                ex = np.exp(-gamma * tau)
                kb = kappa - k2 * (1.0 - ex)
                D = (k0 * V * tau + k1 * Xk + k2 * (I - e1 * (1.0 - ex))) / kb
                if D > M:
                    Snew = np.exp(-D / zbar)
                    mass = S - Snew
                    zm = zbar + (M * S - D * Snew) / mass if mass > 1e-300 else 0.5 * (M + D)
                    sb = min(max((zm - Dp) / (D - Dp), 0.0), 1.0)  # where in the interval, D linear
                    ec = (e1 - zm) * (exp_p + sb * (ex - exp_p)) + Ip + sb * (I - Ip)
                    u = (ec - egrid[0]) / de
                    if u < 0.0 or u > m - 1:
                        clipped[src] += mass
                        u = min(max(u, 0.0), m - 1.0)
                    q = min(int(u), m - 2)
                    w = u - q
                    if nnz + 2 > cap:
                        clipped[0] = -1.0
                        return rows[:0], cols[:0], vals[:0], lost, delta0, clipped
                    rows[nnz] = src
                    cols[nnz] = iv * m + q
                    vals[nnz] = mass * (1 - w)
                    rows[nnz + 1] = src
                    cols[nnz + 1] = iv * m + q + 1
                    vals[nnz + 1] = mass * w
                    nnz += 2
                    M = D
                    S = Snew
                if iv == n - 1:  # at X = 0: E[margin; z > M] = kappa beta S (zbar + M - D)
                    delta0[src] += kb * S * (zbar + M - D)
                if S < s_min:
                    break
                Dp = D
                exp_p = ex
                Ip = I
            lost[src] = S
    return rows[:nnz], cols[:nnz], vals[:nnz], lost, delta0, clipped


class PeriodicChain:
    """The chain for one model, V and grid; :meth:`evaluate` for one t(X)."""

    def __init__(self, model: micro.Model, V: float, n: int, m: int, e_lo: float, e_hi: float,
                 s_min: float = 1e-12, periods: int = 40):
        self.model, self.V, self.n, self.m = model, V, n, m
        self.egrid = np.linspace(e_lo, e_hi, m)
        self.s_min, self.periods = s_min, periods

    def evaluate(self, theta: np.ndarray, hs: np.ndarray) -> dict:
        mo, n, m = self.model, self.n, self.m
        hs = np.asarray(hs, float)
        L, z = hs.sum(), mo.jumps.zbar
        cap = n * m * 200
        while True:
            rows, cols, vals, lost, delta0, clipped = _transitions(
                np.asarray(theta, float), hs, self.V, mo.k0, mo.k1, mo.k2, mo.k2 / mo.eta_u, z,
                self.egrid, self.s_min, n * self.periods, cap)
            if clipped[0] >= 0:
                break
            cap *= 4
        P = sp.csr_matrix((vals, (rows, cols)), shape=(n * m, n * m))
        A = (P.T - sp.eye(n * m)).tolil()
        A[0, :] = 1.0  # (pi P = pi with sum pi = 1)
        b = np.zeros(n * m)
        b[0] = 1.0
        pi = spla.spsolve(A.tocsc(), b) * (L / z)  # jumps per block per period
        by_state = pi.reshape(n, m)
        jumps = by_state.sum(axis=1)
        pe = by_state.sum(axis=0)
        held = np.nonzero(pe > 1e-9 * pe.max())[0]
        return dict(jumps=jumps, slip_error=jumps * z - hs, sigma0=mo.f_th - float(pi @ delta0),
                    e_support=(self.egrid[held[0]], self.egrid[held[-1]]), lost=float(lost.max()),
                    clipped=float(pi @ clipped) * z / L)


def layout(u: np.ndarray, n_l: int, n_s: int, V: float) -> tuple[np.ndarray, np.ndarray]:
    w, ds, xs = np.clip(u[:n_l], 0.0, 1.0), np.exp(u[n_l]), np.exp(u[n_l + 1])
    hs = np.concatenate((w * ds, np.full(n_s, xs / n_s)))
    theta = np.concatenate(((1.0 - w) * ds / V, np.zeros(n_s)))
    return hs, theta


def residual(u, chain: PeriodicChain, n_l: int, n_s: int):
    V, zbar = chain.V, chain.model.jumps.zbar
    hs, theta = layout(u, n_l, n_s, V)
    out = chain.evaluate(theta, hs)
    dens = out["jumps"][n_l:n_l + 2] * zbar / hs[n_l:n_l + 2]
    fold = (1.5 * dens[0] - 0.5 * dens[1] - 1.0) * hs[n_l]
    L = hs.sum()
    F = np.concatenate((out["slip_error"][:n_l], [fold, (V * theta.sum() - L) / L]))
    return F, out, hs, theta


def newton(u, chain, n_l, n_s, *, J=None, tol=1e-10, max_it=30, fd=1e-7):
    """Newton (or, with ``J`` given, the chord iteration) with a backtracking line search.
    Returns u, F, iterations, J."""
    F = residual(u, chain, n_l, n_s)[0]
    chord = J is not None
    for it in range(max_it):
        nF = np.linalg.norm(F)
        if nF < tol:
            return u, F, it, J
        if not chord:
            J = np.empty((F.size, u.size))
            for j in range(u.size):
                du = np.zeros_like(u)
                du[j] = fd if j >= n_l or u[j] < 0.5 else -fd
                J[:, j] = (residual(u + du, chain, n_l, n_s)[0] - F) / du[j]
        step = np.linalg.lstsq(J, -F, rcond=1e-9)[0]
        lam = 1.0
        while True:
            un = u + lam * step
            un[:n_l] = np.clip(un[:n_l], 0.0, 1.0)
            Fn = residual(un, chain, n_l, n_s)[0]
            if np.linalg.norm(Fn) < (1 - 0.25 * lam) * nF:
                break
            lam *= 0.5
            if lam < 1e-4:
                raise RuntimeError(f"no descent from |F| = {nF:.3g} after {it} iterations")
        u, F = un, Fn
    raise RuntimeError(f"|F| = {np.linalg.norm(F):.3g} after {max_it} iterations")


def start_from_cohorts(res, V: float, k0: float, n_l: int) -> np.ndarray:
    """The unknowns on the layout from a cohort cycle's trace (its last step is the shock)."""
    t, s = res.trace
    X = V * t - (s - s[0]) / k0
    S = X[:-1] + V * t[:-1]
    ds = S[-1] / n_l
    Xg = np.interp(np.linspace(0.0, S[-1], n_l + 1), S, X[:-1])
    w = np.clip(np.diff(Xg) / ds, 0.0, 1.0)
    return np.concatenate((w, [np.log(ds), np.log(X[-1] - X[-2])]))


def cycle_numbers(out, hs, theta, V, k0) -> dict:
    t = np.concatenate(([0.0], np.cumsum(theta)))
    X = np.concatenate(([0.0], np.cumsum(hs)))
    sigma = out["sigma0"] + k0 * (V * t - X)
    return dict(sigma_max=float(sigma.max()), sigma_min=float(sigma.min()), period=float(t[-1]))


def steady_rows(V: float, levels) -> list[dict]:
    model = micro.Model(k0=0.1)
    ref = float(micro.steady_sliding(model, V).sigma)
    gamma = model.k2 / model.eta_u
    e_lo, e_hi = -0.05 * V / gamma, 1.05 * V / gamma
    rows = []
    for n, m in levels:
        start = time.perf_counter()
        chain = PeriodicChain(model, V, n, m, e_lo, e_hi)
        out = chain.evaluate(np.full(n, 1.0 / n / V), np.full(n, 1.0 / n))
        rows.append(dict(kind="steady", k0=model.k0, V=V, fraction=np.nan, n_l=n, n_s=0, m=m, e_lo=e_lo, e_hi=e_hi,
                         sigma_max=out["sigma0"], sigma_min=out["sigma0"], period=np.nan, ref_sigma_max=ref,
                         ref_sigma_min=ref, ref_period=np.nan, newton_iterations=0,
                         residual=float(np.abs(out["slip_error"]).max()), start_residual=np.nan,
                         wall_s=time.perf_counter() - start))
        print(f"steady n {n} m {m}: sigma {out['sigma0']:.9f} - renewal chain {out['sigma0'] - ref:+.3e}", flush=True)
    return rows


def cycle_rows(k0: float, fraction: float, e_range, levels) -> list[dict]:
    model = micro.Model(k0=k0)
    V = fraction * micro.critical_velocity(model).Vc
    ref = micro.stationary(model, V, method="cohort").cycle  # (its trace: the cycle's stress at each step)
    rows, last = [], {}
    for n_l, n_s, m in levels:
        start = time.perf_counter()
        chain = PeriodicChain(model, V, n_l + n_s, m, *e_range)
        cold = start_from_cohorts(ref, V, k0, n_l)
        u, J = last.get((n_l, n_s), (cold, None))
        F0 = residual(u, chain, n_l, n_s)[0]
        try:
            u, F, its, J = newton(u, chain, n_l, n_s, J=J)
        except RuntimeError:
            if J is None:
                raise
            # the chord stalled (at 0.94 V^c, from m = 40 to 80, and so did Newton from the
            # coarser solution): Newton from the cohort method's cycle
            F0 = residual(cold, chain, n_l, n_s)[0]
            u, F, its, J = newton(cold, chain, n_l, n_s)
        last[(n_l, n_s)] = (u, J)
        F, out, hs, theta = residual(u, chain, n_l, n_s)
        c = cycle_numbers(out, hs, theta, V, k0)
        rows.append(dict(kind="cycle", k0=k0, V=V, fraction=fraction, n_l=n_l, n_s=n_s, m=m, e_lo=e_range[0],
                         e_hi=e_range[1], **c, ref_sigma_max=float(ref.sigma_max), ref_sigma_min=float(ref.sigma_min),
                         ref_period=float(ref.period), newton_iterations=its, residual=float(np.abs(F).max()),
                         start_residual=float(np.abs(F0).max()), e_support_lo=out["e_support"][0],
                         e_support_hi=out["e_support"][1], clipped=out["clipped"], wall_s=time.perf_counter() - start))
        write_csv(rows[-1:], CSV, keys=KEYS)  # (each level as it is done)
        print(f"cycle n_l {n_l} n_s {n_s} m {m}: sigma_max {c['sigma_max']:.6f} sigma_min {c['sigma_min']:.6f} "
              f"period {c['period']:.5f} ({its} iterations, |F| {np.abs(F).max():.1e}; e held in "
              f"[{out['e_support'][0]:.3f}, {out['e_support'][1]:.3f}]) | cohorts "
              f"{float(ref.sigma_max):.6f} {float(ref.sigma_min):.6f} {float(ref.period):.5f}", flush=True)
    return rows


def main(argv: list[str] | None = None) -> int:
    p = argparse.ArgumentParser(prog="python -m studies micro_xchain_prototype",
                                description=__doc__.split("\n\n")[0])
    p.add_argument("--steady", type=float, default=None, help="V for the steady check (k0 = 0.1)")
    p.add_argument("--cycle", action="store_true", help="the cycle at --fraction V^c")
    p.add_argument("--k0", type=float, default=0.1)
    p.add_argument("--fraction", type=float, default=0.5)
    p.add_argument("--e-range", default="-0.05,0.3", help="e_lo,e_hi of the stretch grid (cycle)")
    p.add_argument("--levels", nargs="+", required=True,
                   help="n,m (steady) or n_l,n_s,m (cycle); a level on the same n_l,n_s as the one before "
                        "starts from its solution with its Jacobian (chord)")
    a = p.parse_args(argv)
    levels = [tuple(int(x) for x in lv.split(",")) for lv in a.levels]
    if a.steady is not None:
        write_csv(steady_rows(a.steady, levels), CSV, keys=KEYS)
    if a.cycle:
        e_range = tuple(float(x) for x in a.e_range.split(","))
        cycle_rows(a.k0, a.fraction, e_range, levels)
    return 0
