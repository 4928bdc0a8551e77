"""Fokker-Planck against N-block at a stick-slip point of small k0: wall time at equal error.

Point: k0 = 0.01, V = 1 (about V^c / 8; Fig. 4 parameters), a stick-slip cycle of drop
~0.063 and period ~6.3.  Measured: sigma_max and sigma_min of the cycle, by the same
estimator for both solvers: from the solver's initial state, 30 cycles discarded and the
next 20 averaged (`micro.nblock.stick_slip_extrema_nblock`; for the
Fokker-Planck solver, `micro.simulate` and `micro.analysis.find_cycles`), the
Fokker-Planck solver at shrinking bins (solver ``fp``) and the N-block solver at growing
N (``nblock``).  Rows ``fp_stationary`` are `micro.stationary` with its own stopping rule
(the last 3 cycles agree within rtol = 1e-3 of the drop plus k0 eps), which stops while
the cycle's maximum still drifts slowly: they measure that rule's error; rows
``fp_stationary_n6`` the same with 6 cycles.

The error of a row is the larger of its errors in sigma_max and sigma_min, against two
references: ``fp`` at the finest bin, and the N-block at the largest N (whose own
statistical error, a few 1e-5, bounds what it can resolve).  For each ``fp`` row the
N-block wall time at the same error is interpolated log-log between the two N-block rows
that bracket the error.  An error below the largest N's is out of the N-block's measured
range; for it the script gives a lower bound: the wall time the largest N needs for its
statistical error alone (standard error over the cycles, falling like cycles^-1/2) to
reach that error.  Compilation is excluded.

Writes benchmarks/results/micro_fp_vs_nblock_stickslip.csv (rows merge by solver and
resolution, so a run with `--N 1e6` alone adds that row).

    python benchmarks/micro_fp_vs_nblock_stickslip.py                  # about 15 minutes
    python benchmarks/micro_fp_vs_nblock_stickslip.py --solver nblock --N 1e6   # about 45 minutes
"""
from __future__ import annotations

import argparse

import numpy as np
import pandas as pd

import micro
from _harness import RESULTS, merged, timed, warm_up, write_csv
from micro import nblock
from micro.analysis import Records, find_cycles

K0, V = 0.01, 1.0
#: both solvers: cycles discarded as transient, cycles averaged.  The Fokker-Planck
#: solver's cycle maximum relaxes over 20-30 cycles here (eps = 0.012: means over cycles
#: 0-9, 10-19, 20-29 and 30-107 of 0.96946, 0.96255, 0.96221, 0.96216), so the N-block's
#: default of 10 would leave a transient bias of ~4e-4.
N_DISCARD, N_CYCLES = 30, 20


def _drift(values: np.ndarray) -> float:
    """Mean of the second half of the averaged cycles minus that of the first (a check
    that the transient is over)."""
    half = values.size // 2
    return float(values[half:].mean() - values[:half].mean())


def fp_cycles(model: micro.Model, eps: float) -> dict:
    """The N-block's estimator on the Fokker-Planck solver: from the solver's initial
    state, N_DISCARD cycles discarded and the next N_CYCLES averaged."""
    num = micro.Numerics(eps=eps)
    hysteresis = 2.0 * model.k0 * eps  # as micro.stationary
    parts, grid, chunk = [], "auto", 50.0
    while True:
        run = micro.simulate(model, V, duration=chunk, numerics=num, initial=grid,
                             record_dsigma=0.25 * model.k0 * eps)
        part = run.records[["t", "sigma", "sigma_min", "sigma_max", "sigma_mean"]].to_numpy(copy=True)
        part[:, 0] += chunk * len(parts)  # each run's clock starts at 0
        parts.append(part)
        grid = run.grid
        cycles = find_cycles(Records.from_array(np.concatenate(parts)), hysteresis)
        if len(cycles) >= N_DISCARD + N_CYCLES:
            break
    used = cycles.iloc[N_DISCARD:N_DISCARD + N_CYCLES]
    root = np.sqrt(N_CYCLES)
    return dict(regime="stick-slip", converged=True, sigma_max_drift=_drift(used.sigma_max.to_numpy()),
                sigma_max=float(used.sigma_max.mean()),
                sigma_min=float(used.sigma_min.mean()), period=float(used.period.mean()),
                sigma_max_stderr=float(used.sigma_max.std(ddof=1) / root),
                sigma_min_stderr=float(used.sigma_min.std(ddof=1) / root))


def fp_stationary(model: micro.Model, eps: float, n: int = 3) -> dict:
    """micro.stationary with its own stopping rule (the last ``n`` cycles agree within
    rtol = 1e-3 of the drop plus k0 eps)."""
    r = micro.stationary(model, V, numerics=micro.Numerics(eps=eps), convergence=micro.Convergence(rtol=1e-3, n=n), method="fp")
    return dict(regime=r.regime, converged=r.converged, sigma_max_drift=np.nan, sigma_max=r.sigma_max,
                sigma_min=r.sigma_min, period=r.period, sigma_max_stderr=np.nan, sigma_min_stderr=np.nan)


def fp_rows(model: micro.Model, eps_list: list[float]) -> list[dict]:
    warm_up(micro.stationary, micro.Model(k0=0.1), 2.0, numerics=micro.Numerics(eps=0.024), method="fp")
    rows = []
    for eps in eps_list:
        for solver, measure in (("fp", fp_cycles), ("fp_stationary", fp_stationary),
                                ("fp_stationary_n6", lambda m, e: fp_stationary(m, e, n=6))):
            found, wall = timed(measure, model, eps)
            rows.append(dict(solver=solver, resolution=eps, **found, wall_s=wall))
            print(rows[-1], flush=True)
    return rows


def nblock_rows(model: micro.Model, N_list: list[int]) -> list[dict]:
    warm_up(nblock.stick_slip_extrema_nblock, model, V, 100, n_cycles=3, n_discard=1)
    rows = []
    for N in N_list:
        r = nblock.stick_slip_extrema_nblock(model, V, N, n_cycles=N_CYCLES, n_discard=N_DISCARD, seed=0)
        rows.append(dict(solver="nblock", resolution=float(N), regime=r.regime, converged=r.status == "ok",
                         sigma_max_drift=_drift(r.shocks.sigma_before.to_numpy()),
                         sigma_max=r.sigma_max, sigma_min=r.sigma_min, period=r.period,
                         sigma_max_stderr=r.sigma_max_stderr, sigma_min_stderr=r.sigma_min_stderr,
                         wall_s=r.wall_time))
        print(rows[-1], flush=True)
    return rows


def errors(table: pd.DataFrame) -> pd.DataFrame:
    """Errors against the finest bin and the largest N, and the N-block's wall time at
    each Fokker-Planck row's error (log-log interpolation between measured rows, or a
    lower bound below the largest N's error)."""
    fp = table[table.solver == "fp"].sort_values("resolution", ascending=False)
    nb = table[table.solver == "nblock"].sort_values("resolution")
    out = table.copy()
    for name, ref in (("fp", fp.iloc[-1] if len(fp) else None), ("nblock", nb.iloc[-1] if len(nb) else None)):
        if ref is None:
            continue
        out[f"error_vs_{name}"] = np.maximum(abs(out.sigma_max - ref.sigma_max), abs(out.sigma_min - ref.sigma_min))
    for column in ("nblock_wall_s_at_equal_error", "speedup", "nblock_wall_s_bound"):
        out[column] = np.nan
    if len(fp) >= 2 and len(nb) >= 2:
        nb_err = out.loc[nb.index, "error_vs_fp"].to_numpy()
        nb_wall = nb.wall_s.to_numpy()
        big = nb.iloc[-1]
        for i in fp.index[:-1]:
            err = out.loc[i, "error_vs_fp"]
            # the first N whose error is at or below err, and the one before it
            k = int(np.argmax(nb_err <= err)) if np.any(nb_err <= err) else -1
            if k > 0:
                a = np.log(err / nb_err[k - 1]) / np.log(nb_err[k] / nb_err[k - 1])
                wall = np.exp(np.log(nb_wall[k - 1]) + a * np.log(nb_wall[k] / nb_wall[k - 1]))
                out.loc[i, "nblock_wall_s_at_equal_error"] = wall
            elif k == 0:
                out.loc[i, "nblock_wall_s_at_equal_error"] = nb_wall[0]  # the smallest N is already as good
            else:
                # below the largest N's error: the largest N run long enough for its
                # statistical error alone to reach err (smaller N are biased by more)
                stderr = max(big.sigma_max_stderr, big.sigma_min_stderr)
                out.loc[i, "nblock_wall_s_bound"] = big.wall_s * max(1.0, (stderr / err) ** 2)
    out["speedup"] = out.nblock_wall_s_at_equal_error / out.wall_s
    out["speedup_bound"] = out.nblock_wall_s_bound / out.wall_s
    order = {"fp": 0, "fp_stationary": 1, "fp_stationary_n6": 2, "nblock": 3}
    key = out.solver.map(order) * 1e9 + np.where(out.solver == "nblock", out.resolution, -out.resolution)
    return out.iloc[np.argsort(key.to_numpy(), kind="stable")].reset_index(drop=True)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--solver", choices=("fp", "nblock", "both"), default="both")
    ap.add_argument("--eps", type=str, default="0.024,0.016,0.012,0.008,0.006", help="comma-separated FP bins")
    ap.add_argument("--N", type=str, default="1e3,1e4,1e5", help="comma-separated N-block sizes")
    args = ap.parse_args()
    model = micro.Model(k0=K0)
    rows = []
    if args.solver in ("fp", "both"):
        rows += fp_rows(model, [float(e) for e in args.eps.split(",")])
    if args.solver in ("nblock", "both"):
        rows += nblock_rows(model, [int(float(n)) for n in args.N.split(",")])
    out = RESULTS / "micro_fp_vs_nblock_stickslip.csv"
    keep = ["solver", "resolution", "regime", "converged", "sigma_max", "sigma_min", "period", "sigma_max_stderr",
            "sigma_min_stderr", "sigma_max_drift", "wall_s"]
    table = errors(merged(out, pd.DataFrame(rows), ["solver", "resolution"])[keep].reset_index(drop=True))
    write_csv(table, out)
    print(table.to_string(index=False, float_format=lambda x: f"{x:.6g}"))


if __name__ == "__main__":
    main()
