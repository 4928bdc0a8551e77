"""Bifurcation-diagram benchmark: 5 k0 x 50 V limit cycles with extrema converged to 1e-6.

Times ``rsf.sweep`` (compiled kernels, CVODE slides, Aitken-accelerated cycles) after
compilation, the same without the cycle extrapolation, and the plain ``solve_ivp`` event
loop of ``rsf_baseline_solve_ivp.py`` on the same points, and prints run times, the
speed-up and the largest disagreement of the extrema.

    python benchmarks/rsf_bifurcation.py [--baseline-every N] [--repeat R]

(``--baseline-every 5`` runs the baseline on every 5th point only and extrapolates its
total, to save time.)
"""
from __future__ import annotations

import argparse
import os
import sys

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
sys.path.insert(0, os.path.dirname(os.path.dirname(os.path.abspath(__file__))))  # the repository

import rsf  # noqa: E402
from _harness import Stopwatch, timed, warm_up  # noqa: E402
from rsf_baseline_solve_ivp import Paper, cycle_stats  # noqa: E402

K0S = [0.3, 0.1, 0.01, 0.001, 0.0001]
N_V = 50
OPTIONS = rsf.SolverOptions(cycle_rtol=1e-6, rtol=1e-8, atol=1e-10)


def grid(k0: float) -> np.ndarray:
    Vc = rsf.critical_velocity(rsf.HyperbolicLaw(), k0=k0, Dc=rsf.PAPER_DC).Vc
    return np.geomspace(1e-3 * Vc, 3.0 * Vc, N_V)


def run_rsf(options: rsf.SolverOptions) -> tuple[float, dict]:
    out = {}
    sw = Stopwatch()
    for k0 in K0S:
        out[k0] = rsf.sweep(rsf.SpringSlider(k0=k0), grid(k0), options=options)
    return sw.seconds, out


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--baseline-every", type=int, default=1)
    parser.add_argument("--repeat", type=int, default=3)
    args = parser.parse_args()

    warm_up(lambda: [rsf.limit_cycle(rsf.SpringSlider(k0=k0), V, options=OPTIONS)   # every kernel once
                     for k0, V in ((0.3, 0.05), (0.3, 0.15), (0.3, 1.0), (1e-4, 100.0))],
            label="first calls (numba compilation or cache load, CVODE set-up)")

    times = []
    for _ in range(args.repeat):
        dt, res = run_rsf(OPTIONS)
        times.append(dt)
    plain_opts = rsf.SolverOptions(cycle_rtol=1e-6, rtol=1e-8, atol=1e-10, accelerate=False,
                                   max_cycles=200000)
    dt_plain, res_plain = run_rsf(plain_opts)
    n_points = len(K0S) * N_V
    bad = [r for k0 in K0S for r in res[k0] if not r.converged]
    print(f"rsf: {n_points} points, best of {args.repeat}: {min(times):.3f} s "
          f"({1e3 * min(times) / n_points:.2f} ms/point); runs {', '.join(f'{t:.3f}' for t in times)} s; "
          f"unconverged: {len(bad)}")
    print(f"rsf without cycle extrapolation: {dt_plain:.3f} s ({1e3 * dt_plain / n_points:.2f} ms/point)")

    print()
    print(f"{'k0':>8} {'rsf [s]':>9} {'baseline [s]':>13} {'points':>7} {'max cycles':>11} "
          f"{'max|dsig_max|':>14} {'max|dsig_min|':>14} {'regimes equal':>14}")
    total_base = 0.0
    total_rsf_sub = 0.0
    for k0 in K0S:
        V = grid(k0)
        idx = range(0, N_V, args.baseline_every)
        t_b = 0.0
        dmax = dmin = 0.0
        same = 0
        cycles = 0
        for i in idx:
            b, seconds = timed(cycle_stats, Paper(k0), float(V[i]), cycle_rtol=1e-6, rtol=1e-9)
            t_b += seconds
            r = res[k0][i]
            same += b["regime"] == r.regime
            cycles = max(cycles, b["cycles"])
            if b["regime"] == r.regime:
                dmax = max(dmax, abs(b["sigma_max"] - r.sigma_max))
                dmin = max(dmin, abs(b["sigma_min"] - r.sigma_min))
        t_r = sum(r.run_time for j, r in enumerate(res[k0]) if j in idx)
        total_base += t_b
        total_rsf_sub += t_r
        print(f"{k0:>8g} {t_r:>9.3f} {t_b:>13.2f} {len(idx):>7d} {cycles:>11d} {dmax:>14.2e} "
              f"{dmin:>14.2e} {same:>10d}/{len(idx)}")
    scale = N_V / len(range(0, N_V, args.baseline_every))
    base_all = total_base * scale
    print()
    print(f"baseline solve_ivp loop: {total_base:.2f} s on {n_points / scale:.0f} points "
          f"({total_base / (n_points / scale):.3f} s/point) -> {base_all:.1f} s for all {n_points}")
    print(f"speed-up of rsf (best run) over the baseline: {base_all / min(times):.0f}x; "
          f"without cycle extrapolation: {base_all / dt_plain:.0f}x")


if __name__ == "__main__":
    main()
