"""N-block simulation: wall time and statistical error against N, at one steady and one stick-slip point.

Points (k1 = 0.1, k2 = 0.9, exponential g with zbar = 0.1 and cutoff 10, eta_u = 1, f_th = 1):

* steady:     k0 = 0.1, V = 2.0  -> stationary stress by batch means
* stick-slip: k0 = 0.1, V = 0.05 -> sigma_max, sigma_min over global shocks

For every N the same simulated time (steady) or number of cycles (stick-slip) is used, so
the error shrinks with N at a cost proportional to N. The regime is checked by how the
largest avalanche and the stress fluctuations scale with N.

Compile time is measured separately: a tiny run in a subprocess with an empty numba cache
(cold compile) and one with the project's cache (cache load); all other wall times are
run time only (the kernels are compiled before the clock starts).

Usage::

    python benchmarks/micro_nblock_convergence.py [--max-n 1000000] [--out benchmarks/results]
"""
from __future__ import annotations

import argparse
import logging
import os
import subprocess
import sys
import tempfile
from pathlib import Path

import numpy as np
import pandas as pd

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

from micro import Exponential, Model  # noqa: E402
from micro import nblock as nb  # noqa: E402

from _harness import RESULTS, timed, warm_up, write_csv  # noqa: E402

logger = logging.getLogger("micro_nblock_convergence")

STEADY = dict(k0=0.1, velocity=2.0, t_transient=10.0, batch_length=2.0, n_batches=10)
STICK_SLIP = dict(k0=0.1, velocity=0.05, n_discard=10, n_cycles=20)

# (the tiny run times itself from before its imports, in a fresh interpreter)
TINY = (
    "import time; t = time.perf_counter();"
    "from micro import Model, nblock as nb;"
    "nb.simulate_nblock(Model(k0=0.3), 1.0, 50, t_max=1.0);"
    "print(time.perf_counter() - t)"
)


def first_call_seconds(cache_dir: str | None) -> float:
    """Time of a tiny first run in a fresh interpreter (with ``cache_dir`` as numba cache)."""
    env = dict(os.environ, PYTHONPATH=str(ROOT))
    if cache_dir is not None:
        env["NUMBA_CACHE_DIR"] = cache_dir
    out = subprocess.run([sys.executable, "-c", TINY], env=env, capture_output=True, text=True, check=True)
    return float(out.stdout.strip().splitlines()[-1])


def model(k0: float) -> Model:
    return Model(k0=k0, k1=0.1, k2=0.9, eta_u=1.0, f_th=1.0, jumps=Exponential(0.1, 10.0))


def steady_row(n: int) -> dict:
    p = STEADY
    m = model(p["k0"])
    out, wall = timed(
        nb.stationary_stress_nblock, m, p["velocity"], n, t_transient=p["t_transient"],
        batch_length=p["batch_length"], n_batches=p["n_batches"], initial="frozen",
    )
    res = out.result
    ts = res.timeseries.iloc[-p["n_batches"]:]
    return dict(
        point="steady", k0=p["k0"], V=p["velocity"], N=n, wall_s=wall, n_jumps=res.n_jumps,
        ns_per_jump=1e9 * res.wall_time / max(res.n_jumps, 1),
        simulated_time=float(res.timeseries["t"].iloc[-1]),
        sigma_mean=out.sigma_mean, sigma_stderr=out.sigma_stderr, sigma_stderr_naive=out.sigma_stderr_naive,
        lag1=out.lag1_autocorrelation,
        sigma_max=np.nan, sigma_max_stderr=np.nan, sigma_min=np.nan, sigma_min_stderr=np.nan,
        n_cycles=0, period=np.nan,
        max_avalanche_fraction=float(ts["max_avalanche"].max() / n),
        sigma_range_in_batch=float((ts["sigma_max"] - ts["sigma_min"]).mean()),
        n_shocks_over_quarter_n=out.n_global_shocks,
        regime_by_shocks=out.regime,
    )


def stick_slip_row(n: int) -> dict:
    p = STICK_SLIP
    m = model(p["k0"])
    out, wall = timed(nb.stick_slip_extrema_nblock, m, p["velocity"], n, n_cycles=p["n_cycles"],
                      n_discard=p["n_discard"])
    res = out.result
    return dict(
        point="stick-slip", k0=p["k0"], V=p["velocity"], N=n, wall_s=wall, n_jumps=res.n_jumps,
        ns_per_jump=1e9 * res.wall_time / max(res.n_jumps, 1),
        simulated_time=res.final_state.t,
        sigma_mean=np.nan, sigma_stderr=np.nan, sigma_stderr_naive=np.nan, lag1=np.nan,
        sigma_max=out.sigma_max, sigma_max_stderr=out.sigma_max_stderr,
        sigma_min=out.sigma_min, sigma_min_stderr=out.sigma_min_stderr,
        n_cycles=out.n_cycles, period=out.period,
        max_avalanche_fraction=float(out.shocks["size"].mean() / n) if out.n_cycles else np.nan,
        sigma_range_in_batch=out.sigma_max - out.sigma_min,
        n_shocks_over_quarter_n=len(res.shocks),
        regime_by_shocks=out.regime,
    )


def main(argv: list[str] | None = None) -> pd.DataFrame:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--max-n", type=int, default=1_000_000, help="largest N (powers of ten from 1e3)")
    parser.add_argument("--out", type=Path, default=RESULTS, help="directory of the CSV files")
    args = parser.parse_args(argv)
    logging.basicConfig(level=logging.INFO, format="%(asctime)s %(name)s: %(message)s")

    with tempfile.TemporaryDirectory() as empty:
        cold = first_call_seconds(empty)
    warm = first_call_seconds(None)
    # compile (or load) the kernels in this process before any clock starts
    warm_up(nb.simulate_nblock, model(0.3), 1.0, 50, t_max=1.0)
    compile_table = write_csv([dict(what="first tiny run, empty numba cache (JIT compile)", seconds=cold),
                               dict(what="first tiny run, numba cache present (cache load)", seconds=warm)],
                              args.out / "micro_nblock_compile.csv")
    print(compile_table.to_string(index=False))

    sizes = [n for n in (1_000, 10_000, 100_000, 1_000_000) if n <= args.max_n]
    rows = []
    for n in sizes:
        for make in (steady_row, stick_slip_row):
            row = make(n)
            logger.info("%s N=%d done in %.1f s", row["point"], n, row["wall_s"])
            rows.append(row)
            write_csv(rows, args.out / "micro_nblock_convergence.csv")
    table = pd.DataFrame(rows)
    with pd.option_context("display.width", 200, "display.max_columns", 30):
        print("\nsteady point (k0 = 0.1, V = 2): stationary stress")
        print(table[table.point == "steady"][
            ["N", "wall_s", "n_jumps", "ns_per_jump", "sigma_mean", "sigma_stderr", "lag1",
             "max_avalanche_fraction", "sigma_range_in_batch", "n_shocks_over_quarter_n"]].to_string(index=False))
        print("\nstick-slip point (k0 = 0.1, V = 0.05): extrema over global shocks")
        print(table[table.point == "stick-slip"][
            ["N", "wall_s", "n_jumps", "ns_per_jump", "sigma_max", "sigma_max_stderr", "sigma_min",
             "sigma_min_stderr", "n_cycles", "period", "max_avalanche_fraction"]].to_string(index=False))
    return table


if __name__ == "__main__":
    main()
