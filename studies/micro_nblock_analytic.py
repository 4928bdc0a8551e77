"""N-block simulation against the closed-form results, with statistical errors.

* deterministic jumps, evenly spaced phases: Eq. (4) and its exact finite-N version
  (k0 = 1, k1 = 0.1, k2 = 0.9, zbar = 0.1; V = 0.5, 1, 5);
* deterministic jumps, random phases: the frozen synchronised clusters and their bias;
* exponential g (zbar = 0.1, cutoff 10), k0 = 1: the large-V limit with its 1/V term and the
  small-V limit with its -eta_u V term.

Writes ``benchmarks/results/micro_nblock_analytic.csv`` and prints the table.

Usage::

    python -m studies micro_nblock_analytic [--out benchmarks/results]
"""
from __future__ import annotations

import argparse
import logging
import sys
from pathlib import Path

import pandas as pd

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

from micro import Deterministic, Exponential, Model  # noqa: E402
from micro import nblock as nb  # noqa: E402

from benchmarks._harness import RESULTS, warm_up, write_csv  # noqa: E402


def deterministic_rows() -> list[dict]:
    model = Model(k0=1.0, k1=0.1, k2=0.9, jumps=Deterministic(0.1))
    rows = []
    for v in (0.5, 1.0, 5.0):
        for n in (1_000, 10_000, 100_000):
            if n == 100_000 and v == 5.0:
                continue
            res = nb.simulate_nblock(model, v, n, t_max=80.0, record_every=20.0, initial="frozen")
            late = float(res.timeseries["sigma_mean"].iloc[-1])  # exact average over t in [60, 80]
            rows.append(dict(case="deterministic, evenly spaced", V=v, N=n, sigma=late, stderr=0.0,
                             reference="Eq. (4)", reference_value=nb.sigma_deterministic_steady(model, v),
                             finite_n_value=nb.sigma_deterministic_steady_finite_n(model, v, n),
                             wall_s=res.wall_time))
    for v in (1.0,):
        for n in (2_000, 20_000):
            res = nb.simulate_nblock(model, v, n, t_max=200.0, record_every=50.0, initial="frozen",
                                     phases="random", seed=5)
            late = float(res.timeseries["sigma_mean"].iloc[-1])
            rows.append(dict(case="deterministic, random phases", V=v, N=n, sigma=late, stderr=0.0,
                             reference="Eq. (4)", reference_value=nb.sigma_deterministic_steady(model, v),
                             finite_n_value=nb.sigma_deterministic_steady_finite_n(model, v, n),
                             wall_s=res.wall_time,
                             note=f"{res.n_jumps / res.n_avalanches:.1f} blocks per cluster, largest "
                                  f"{int(res.timeseries['max_avalanche'].iloc[-1])}"))
    return rows


def exponential_rows() -> list[dict]:
    model = Model(k0=1.0, k1=0.1, k2=0.9, jumps=Exponential(0.1))
    rows = []
    for v, n, tt, bl in ((1000.0, 20_000, 0.02, 0.01), (200.0, 20_000, 1.0, 0.1), (50.0, 20_000, 3.0, 0.3)):
        out = nb.stationary_stress_nblock(model, v, n, t_transient=tt, batch_length=bl, n_batches=20,
                                          initial="frozen")
        rows.append(dict(case="exponential, large V", V=v, N=n, sigma=out.sigma_mean, stderr=out.sigma_stderr,
                         reference="f_th - kappa <z^2>/(2<z>) + k2 gamma Var(R)/V",
                         reference_value=nb.sigma_fast_limit(model, v), finite_n_value=float("nan"),
                         wall_s=out.wall_time, note=f"V->inf limit {nb.sigma_fast_limit(model):.6f}"))
    for v in (0.001, 0.002, 0.005, 0.01):
        out = nb.stationary_stress_nblock(model, v, 100_000, t_transient=50.0, batch_length=50.0, n_batches=20,
                                          seed=1)
        rows.append(dict(case="exponential, small V", V=v, N=100_000, sigma=out.sigma_mean,
                         stderr=out.sigma_stderr,
                         reference="f_th - (k0+k1) <z^2>/(2<z>) - eta_u V",
                         reference_value=nb.sigma_slow_limit(model, v), finite_n_value=float("nan"),
                         wall_s=out.wall_time, note=f"lag1 {out.lag1_autocorrelation:.2f}"))
    return rows


def main(argv: list[str] | None = None) -> pd.DataFrame:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--out", type=Path, default=RESULTS)
    args = parser.parse_args(argv)
    logging.basicConfig(level=logging.WARNING)
    # (the rows' wall_s are the runs' own wall_time, which would hold the compilation)
    warm_up(nb.simulate_nblock, Model(k0=0.3), 1.0, 50, t_max=1.0)
    table = pd.DataFrame(deterministic_rows() + exponential_rows())
    table["difference"] = table["sigma"] - table["reference_value"]
    table["difference_finite_n"] = table["sigma"] - table["finite_n_value"]
    write_csv(table, args.out / "micro_nblock_analytic.csv")
    with pd.option_context("display.width", 250, "display.max_columns", 30, "display.max_colwidth", 60):
        print(table[["case", "V", "N", "sigma", "stderr", "reference_value", "difference",
                     "difference_finite_n", "wall_s", "note"]].to_string(index=False))
    return table


if __name__ == "__main__":
    main()
