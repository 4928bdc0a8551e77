"""The N-block started from the cohort method's limit cycle: does it stay there?

An independent check of ``micro.cohort`` with no transient to wait out (close to V^c the
cycle map contracts by about 0.96 per cycle, so a cold N-block run needs hundreds of
cycles).  The cohorts' cycle is solved at (k0, V / V^c); N blocks get stratified margins
Exp(kappa zbar) and delta_R drawn from the cohorts' delta_R marginal after a shock (a
product state after a total shock), u = delta_R / k2, and positions and drive from their
margins with mean position 0; then ``micro.nblock.simulate_nblock`` runs ``--shocks``
global shocks.  Prints the cohorts' sigma_max, sigma_min and period and the N-block's means
with correlation-aware standard errors and whether they drift.

    python -m studies micro_nblock_from_cohorts --k0 0.01 --fraction 0.9 --N 1600000 --shocks 30
    python -m studies micro_nblock_from_cohorts --k0 0.001 --fraction 0.3 --N 80000 --shocks 6
"""
from __future__ import annotations

import argparse

import numpy as np

import micro
from micro.cohort import cycle_cohorts
from micro.nblock import NBlockState, simulate_nblock
# the N-block's own estimators of a correlated series (the standard error that
# stick_slip_extrema_nblock reports, and its drift test), applied here to shocks that
# simulate_nblock records: hooks for studies (the public API applies them only inside
# its own cycle runs)
from micro.study_hooks import correlated_stderr, drifts

from benchmarks._harness import Stopwatch, warm_up


def start_state(model: micro.Model, p: tuple[np.ndarray, np.ndarray], n: int, seed: int) -> NBlockState:
    """N blocks sampled from the product state: Exp(kappa zbar) margins (stratified) times
    the delta_R marginal ``p`` (masses on nodes, a piecewise-linear density)."""
    nodes, masses = p
    h = float(np.min(np.diff(nodes)))
    rng = np.random.default_rng(1000 + seed)
    q = (np.arange(n) + 0.5) / n
    delta = -model.kappa * model.zbar * np.log1p(-q)
    cdf = np.cumsum(masses) / masses.sum()
    k = np.minimum(np.searchsorted(cdf, rng.permutation(q)), nodes.size - 1)
    dR = nodes[k] + h * (rng.random(n) - rng.random(n))  # a hat function of half-width h
    dF = delta - dR
    sigma = model.f_th - dF.mean()
    x = (dF - (model.f_th - sigma)) / model.kappa
    return NBlockState(h=x - x.mean(), u=dR / model.k2, w=sigma / model.k0)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--k0", type=float, default=0.01)
    ap.add_argument("--fraction", type=float, default=0.9, help="V / V^c")
    ap.add_argument("--N", type=int, default=100_000)
    ap.add_argument("--shocks", type=int, default=10)
    ap.add_argument("--seed", type=int, default=0)
    args = ap.parse_args()
    model = micro.Model(k0=args.k0)
    V = args.fraction * micro.critical_velocity(model).Vc
    warm_up(cycle_cohorts, micro.Model(k0=0.1), 0.3, tol=1e-3, max_iter=6)
    warm_up(simulate_nblock, model, V, 50, t_max=1.0, label="the N-block's compilation (or numba's cache)")
    sw = Stopwatch()
    res = cycle_cohorts(model, V, tol=1e-6)
    if res.p is None:
        raise SystemExit("the cohorts' shocks are not total here: no product state to start from")
    print(f"cohorts: sigma_max {res.sigma_max:.6f}, sigma_min {res.sigma_min:.6f}, period {res.period:.4f} "
          f"(error {res.error:.1e}, {sw.seconds:.0f} s)", flush=True)
    sw.restart()
    run = simulate_nblock(model, V, args.N, t_max=3.0 * args.shocks * res.period, seed=args.seed,
                          initial=start_state(model, res.p, args.N, args.seed), stop_after_shocks=args.shocks,
                          record_every=res.period / 50)
    sb, sa = run.shocks.sigma_before.to_numpy(), run.shocks.sigma_after.to_numpy()
    period = np.diff(np.r_[0.0, run.shocks.t.to_numpy()])
    print(f"N-block, N = {args.N}, seed {args.seed}: {sb.size} shocks in {sw.seconds:.0f} s")
    print(f"  sigma_max {sb.mean():.6f} +- {correlated_stderr(sb):.1e} (drifts: {drifts(sb)}), "
          f"sigma_min {sa.mean():.6f} +- {correlated_stderr(sa):.1e}, "
          f"period {period.mean():.4f} +- {correlated_stderr(period):.1e}")


if __name__ == "__main__":
    main()
