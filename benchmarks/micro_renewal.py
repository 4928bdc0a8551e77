"""Run time against error of the direct steady-sliding solver (micro.renewal), V^c per k0,
and the Fokker-Planck's stored steady stresses scored against the exact stress.

1. ``grid``: for the paper's parameters (k1 = 0.1, k2 = 0.9, zbar = 0.1, exponential g)
   and the (k1, k2) = (0, 1) set at small k0, the error of sigma and of the branching ratio
   b on a fixed grid of n nodes against the finest grid (n = 160), with the run time of
   one solve (median of repeats, after compilation).
2. ``default``: micro.steady_sliding at its default tolerance, time per V and error.
3. ``vc``: micro.critical_velocity (method "renewal") for the paper's five k0 and the four
   (k1, k2) sets of Fig. 5: time, its error estimate, and the change against a run at
   tolerance 1e-13.
4. ``stress``: the supported range, k0 in {1e-4, ..., 1}, 22 V from 1e-3 to 1e4, the four
   (k1, k2) sets, exponential, deterministic and tabulated g: finiteness, sigma and b
   decreasing in V, points that miss tol, worst errors, and the time of the growth rate.
5. ``waiting``: the Newton waiting time against a 40-digit root (needs ``pip install
   mpmath``, not a dependency of the project; skipped without it).
6. ``fp``: the rows of results/micro_fp_eps_convergence.csv (Fokker-Planck steady stress
   against the bin eps) with their true error against the exact stress, and the measured
   order of the FP in eps (least squares of log error on log eps).

Compile time is reported apart (the first call in a fresh process).  Writes
benchmarks/results/micro_renewal_{grid,default,vc,stress,fp}.csv.

    python benchmarks/micro_renewal.py          # about two minutes
"""
from __future__ import annotations

import numpy as np
import pandas as pd

import micro
# the grid table solves the chain on a fixed grid of n nodes (the hooks for studies
# chain_grid, chain_on_grid, with quadrature and map_width), which steady_sliding chooses
# itself; critical_velocity_renewal (micro.renewal's __all__) takes a tolerance that
# critical_velocity does not pass on
from micro import renewal as R
from micro import study_hooks as H

from _harness import K0, RESULTS, median_time, timed, warm_up, write_csv

SETS = ((0.1, 0.9), (0.0, 1.0), (0.5, 0.5), (0.9, 0.1))


def grid_table() -> pd.DataFrame:
    rows = []
    cases = [(0.1, 0.1, 0.9, V) for V in (0.05, 0.9, 20.0, 1e4)] + [(1e-3, 0.0, 1.0, 100.0), (1e-4, 0.0, 1.0, 10.0)]
    for k0, k1, k2, V in cases:
        model = micro.Model(k0=k0, k1=k1, k2=k2)
        quad = H.quadrature(model, V)
        width = H.map_width(model)
        ref = H.chain_on_grid(model, V, quad, H.chain_grid(160, width))
        for n in (8, 12, 16, 24, 32, 48, 64, 96):
            grid = H.chain_grid(n, width)
            chain = H.chain_on_grid(model, V, quad, grid)
            wall = median_time(lambda: H.chain_on_grid(model, V, quad, grid))
            rows.append(dict(k0=k0, k1=k1, k2=k2, V=V, n=n, n_z=quad.z.size, wall_ms=1e3 * wall,
                             sigma_error=abs(chain.sigma - ref.sigma),
                             b_error=abs(chain.branching_ratio - ref.branching_ratio),
                             wait_error=abs(chain.wait_error)))
    return pd.DataFrame(rows)


def default_table() -> pd.DataFrame:
    rows = []
    for k0 in K0:
        model = micro.Model(k0=k0)
        Vc = micro.critical_velocity(model).Vc
        for V in (0.5 * Vc, 1.5 * Vc, 10 * Vc, 1e4):
            res = micro.steady_sliding(model, V, growth_rate=False)
            quad = H.quadrature(model, V)
            ref = H.chain_on_grid(model, V, quad, H.chain_grid(160, H.map_width(model)))
            wall = median_time(lambda: micro.steady_sliding(model, V, growth_rate=False))
            rows.append(dict(k0=k0, V=V, n=int(res.n_nodes), wall_ms=1e3 * wall, sigma=float(res.sigma),
                             sigma_error=abs(float(res.sigma) - ref.sigma), estimate=float(res.sigma_error),
                             b_error=abs(float(res.branching_ratio) - ref.branching_ratio)))
    return pd.DataFrame(rows)


def vc_table() -> pd.DataFrame:
    rows = []
    for k1, k2 in SETS:
        for k0 in K0:
            model = micro.Model(k0=k0, k1=k1, k2=k2)
            crit, wall = timed(micro.critical_velocity, model)
            tight, _, _, _, _ = R.critical_velocity_renewal(model, V_max=1e7, tol=1e-13)
            rows.append(dict(k1=k1, k2=k2, k0=k0, Vc=crit.Vc, status=crit.status, wall_s=wall,
                             error_estimate=(crit.V_high - crit.Vc) if crit.Vc > 0 else 0.0,
                             change_at_tol_1e13=abs(tight - crit.Vc),
                             k0_Vc_over_asymptote=crit.Vc / micro.vc_small_k0(model), evaluations=len(crit.evaluations)))
    return pd.DataFrame(rows)


def stress_table() -> pd.DataFrame:
    rows = []
    V = np.geomspace(1e-3, 1e4, 22)
    dists = {"exponential": micro.Exponential(0.1, 10.0), "deterministic": micro.Deterministic(0.1),
             "tabulated": micro.Tabulated(pdf=lambda z: z * np.exp(-z / 0.05), support_max=2.0)}
    for name, jumps in dists.items():
        for k1, k2 in SETS:
            for k0 in (1e-4, 1e-3, 1e-2, 0.1, 0.5, 1.0):
                model = micro.Model(k0=k0, k1=k1, k2=k2, jumps=jumps)
                res, wall = timed(micro.steady_sliding, model, V, growth_rate=False, warn=False)
                rows.append(dict(jumps=name, k1=k1, k2=k2, k0=k0, n_V=V.size, wall_s=wall,
                                 finite=bool(np.all(np.isfinite(res.sigma)) and np.all(np.isfinite(res.branching_ratio))),
                                 sigma_decreasing=bool(np.all(np.diff(res.sigma) < 1e-12)),
                                 b_decreasing=bool(np.all(np.diff(res.branching_ratio) < 1e-9)),
                                 missed_tol=int(np.count_nonzero(~res.converged)),
                                 worst_sigma_error=float(np.max(res.sigma_error)),
                                 worst_wait_error=float(np.max(np.abs(res.wait_error)))))
    return pd.DataFrame(rows)


def growth_rate_time() -> float:
    model = micro.Model(k0=0.1)
    V = [0.3, 0.6, 0.72]
    micro.steady_sliding(model, V)
    return median_time(lambda: micro.steady_sliding(model, V), repeats=3) / len(V)


def waiting_time_accuracy() -> float | None:
    try:
        import mpmath
    except ImportError:
        return None
    mpmath.mp.dps = 40
    rng = np.random.default_rng(0)
    worst = 0.0
    for _ in range(3000):
        a = 10 ** rng.uniform(-5, 0)
        D, z = 10 ** rng.uniform(-6, 1), 10 ** rng.uniform(-8, 3)
        t = H.waiting_time(z, D, a, 1 - a)
        ref = mpmath.findroot(lambda s: a * s + (1 - a) * D * (1 - mpmath.exp(-s)) - z, t)
        worst = max(worst, abs(t - float(ref)) / float(ref))
    return worst


def fp_table() -> tuple[pd.DataFrame, pd.DataFrame]:
    fp = pd.read_csv(RESULTS / "micro_fp_eps_convergence.csv")
    fp = fp[(fp.regime == "steady") & fp.converged.astype(bool)].copy()
    fp["sigma_exact"] = [float(micro.steady_sliding(micro.Model(k0=k0), V, growth_rate=False).sigma)
                         for k0, V in zip(fp.k0, fp.V)]
    fp["true_error"] = fp.sigma - fp.sigma_exact
    orders = []
    for (k0, V), g in fp.groupby(["k0", "V"]):
        if len(g) >= 2:
            p = np.polyfit(np.log(g.eps), np.log(np.abs(g.true_error)), 1)[0]
            orders.append(dict(k0=k0, V=V, n_eps=len(g), order=p, largest_error=g.true_error.abs().max(),
                               smallest_error=g.true_error.abs().min()))
    return fp[["k0", "V", "eps", "sigma", "sigma_exact", "true_error", "extrapolation", "wall_s"]], pd.DataFrame(orders)


def main() -> None:
    warm_up(micro.steady_sliding, micro.Model(k0=0.1), 2.0, label="compile (first call, numba cache cold or warm)")
    for name, frame in (("grid", grid_table()), ("default", default_table()), ("vc", vc_table()),
                        ("stress", stress_table())):
        write_csv(frame, RESULTS / f"micro_renewal_{name}.csv")
        print(f"\n## {name}\n" + frame.to_string(index=False, float_format=lambda x: f"{x:.4g}"))
    print(f"\ngrowth rate: {1e3 * growth_rate_time():.0f} ms per unstable V (k0 = 0.1, V = 0.3, 0.6, 0.72)")
    worst = waiting_time_accuracy()
    print("waiting time against a 40-digit root, 3000 random (alpha, D, zeta): " +
          ("skipped (pip install mpmath)" if worst is None else f"worst relative error {worst:.1e}"))
    fp, orders = fp_table()
    write_csv(fp, RESULTS / "micro_renewal_fp.csv")
    print("\n## fp\n" + fp.to_string(index=False, float_format=lambda x: f"{x:.6g}"))
    print("\n## fp order in eps\n" + orders.to_string(index=False, float_format=lambda x: f"{x:.3g}"))


if __name__ == "__main__":
    main()
