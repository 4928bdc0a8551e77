"""An independent check of the stick-slip cycle close to V^c by micro's N-block simulation.

At k0 = ``--k0`` (the model's other parameters at their defaults) and each
d = (V^c - V) / V^c of ``--d`` (V^c exact, from the renewal chain), for each N of ``--N``:
``micro.nblock.stick_slip_extrema_nblock`` from the relaxed state, ``--n-discard`` global
shocks discarded as the transient (near V^c the cycle map contracts by only about
0.9-0.96 per cycle at k0 = 0.1), the next ``--n-cycles`` averaged.  A global shock is an
avalanche of at least ``--shock-fraction`` * N jumps: close to V^c a shock leaves most
blocks unjumped (about 61 % at k0 = 0.1, d = 0.01 by the cohort method), so the default
0.15 is below the function's 0.25.  Each row records the means and standard errors
(lag-1 corrected) of sigma_max and sigma_min, the amplitude sigma_max - sigma_min with
the hypot of the two errors, the period, the function's status ('transient' if the
cycles still drift, 'fewer_cycles' if t_max cut the run short) and the run's own status
('shock_limit' when it stopped at the requested shock count, i.e. t_max was not
reached), and the checks that the shocks are global: the smallest and mean shock size
over N (jumps over N: a block may jump more than once), the largest avalanche below the
threshold after the transient (``largest_subthreshold``, over N; ``bins_near_miss`` counts
time bins holding one of at least 0.02 N) and the longest period over the mean (about 2
if a shock was missed).  CPU
seconds per run exclude the compilation (``warm_up``).

Writes benchmarks/results/micro_transition_nblock_check.csv (rows merge by k0, d, N,
seed, n_discard, cycles_requested, shock_fraction).

The runs in the CSV (one numba thread, CPU times at a load of 2-3.6 on 2 cores; the cost
grows a little faster than N, about 3.6 times per factor 3):

    NUMBA_NUM_THREADS=1 python benchmarks/micro_transition_nblock_check.py --d 0.2,0.01 --N 100000   # 52 s of CPU
    NUMBA_NUM_THREADS=1 python benchmarks/micro_transition_nblock_check.py     # the grid: 37 min of CPU
    NUMBA_NUM_THREADS=1 python benchmarks/micro_transition_nblock_check.py --d 0.01,0.02,0.05 --N 3000000   # 33 min
    NUMBA_NUM_THREADS=1 python benchmarks/micro_transition_nblock_check.py --d 0.01 --N 100000,300000,1000000 --shock-fraction 0.3
    NUMBA_NUM_THREADS=1 python benchmarks/micro_transition_nblock_check.py --d 0.01 --N 100000,300000,1000000 --shock-fraction 0.05
    NUMBA_NUM_THREADS=1 python benchmarks/micro_transition_nblock_check.py --k0 0.01 --d 0.1,0.05,0.02 --N 100000,300000
        # k0 = 0.01: 2-3 times the cost at k0 = 0.1 (each block jumps 7-13 times in a total shock)
"""
from __future__ import annotations

import argparse
import math

import numpy as np
import pandas as pd

import micro
from _harness import RESULTS, Stopwatch, warm_up, write_csv
from micro import nblock

CSV = RESULTS / "micro_transition_nblock_check.csv"
KEYS = ["k0", "d", "N", "seed", "n_discard", "cycles_requested", "shock_fraction"]


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--k0", type=float, default=0.1)
    ap.add_argument("--d", default="0.01,0.02,0.05,0.1,0.2")
    ap.add_argument("--N", default="100000,300000,1000000", help="block counts, run in this order for each d")
    ap.add_argument("--n-cycles", type=int, default=200, help="shocks averaged over")
    ap.add_argument("--n-discard", type=int, default=100, help="shocks discarded first (the transient)")
    ap.add_argument("--shock-fraction", type=float, default=0.15,
                    help="an avalanche of at least this times N jumps is a global shock")
    ap.add_argument("--t-max-factor", type=float, default=0.1,
                    help="t_max = factor * (n_discard + n_cycles + 1) * 2 f_th / (k0 V) (the function's default at 1; "
                         "0.1 still leaves about 6 times the period at k0 = 0.1, d = 0.2 and keeps the bins few)")
    ap.add_argument("--record-every", type=float, default=0.005,
                    help="bin of the time series, fine enough (1/20 of the shortest period) for the largest avalanche "
                         "below the threshold to be seen between the shocks")
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument("--order", choices=("d", "N"), default="d",
                    help="outer loop over d (all N at one d first) or over N (all d at one N first)")
    args = ap.parse_args()
    model = micro.Model(k0=args.k0)
    vc = float(micro.critical_velocity(model).Vc)
    ds = [float(x) for x in args.d.split(",")]
    ns = [int(float(x)) for x in args.N.split(",")]
    points = [(d, n) for d in ds for n in ns] if args.order == "d" else [(d, n) for n in ns for d in ds]
    warm_up(nblock.stick_slip_extrema_nblock, model, 0.9 * vc, 2000, n_cycles=2, n_discard=1)
    total = args.n_discard + args.n_cycles
    for d, n in points:
        V = (1.0 - d) * vc
        t_max = args.t_max_factor * (total + 1) * 2.0 * model.f_th / (model.k0 * V)
        cpu = Stopwatch(cpu=True)
        res = nblock.stick_slip_extrema_nblock(model, V, n, n_cycles=args.n_cycles, n_discard=args.n_discard,
                                               t_max=t_max, seed=args.seed, shock_fraction=args.shock_fraction,
                                               record_every=args.record_every)
        seconds = cpu.seconds
        sizes = res.shocks["size"].to_numpy(float) / n if len(res.shocks) else np.array([np.nan])
        # the largest avalanche below the threshold after the transient, and the bins
        # holding one of at least 0.02 N: how clear the gap between shocks and the rest is
        ts = res.result.timeseries
        floor = res.result.shock_min_size
        first = res.shocks["t"].iloc[0] if len(res.shocks) else np.inf
        after = ts["max_avalanche"].to_numpy()[ts["t"].to_numpy() > first]
        below = after[after < floor]
        periods = np.diff(res.shocks["t"].to_numpy()) if len(res.shocks) > 1 else np.array([np.nan])
        row = dict(
            k0=args.k0, d=d, V=V, Vc=vc, N=n, seed=args.seed, n_discard=args.n_discard,
            cycles_requested=args.n_cycles, shock_fraction=args.shock_fraction,
            sigma_max=res.sigma_max, sigma_max_stderr=res.sigma_max_stderr,
            sigma_min=res.sigma_min, sigma_min_stderr=res.sigma_min_stderr,
            amplitude=res.sigma_max - res.sigma_min,
            amplitude_stderr=math.hypot(res.sigma_max_stderr, res.sigma_min_stderr),
            period=res.period, period_stderr=res.period_stderr, n_cycles=res.n_cycles,
            regime=res.regime, status=res.status, message=res.message,
            run_status=res.result.status, record_every=args.record_every, t_max=t_max,
            t_end=res.result.final_state.t,
            shock_size_min=float(np.min(sizes)), shock_size_mean=float(np.mean(sizes)),
            largest_subthreshold=float(below.max() / n) if below.size else 0.0,
            bins_near_miss=int(np.count_nonzero(below >= 0.02 * n)),
            period_max_over_mean=float(np.max(periods) / np.mean(periods)),
            cpu_s=round(seconds, 1),
        )
        shown = ("d", "N", "amplitude", "amplitude_stderr", "sigma_max", "sigma_min", "period", "n_cycles", "status",
                 "run_status", "shock_size_min", "largest_subthreshold", "cpu_s")
        print({k: row[k] for k in shown}, flush=True)
        write_csv(pd.DataFrame([row]), CSV, keys=KEYS)


if __name__ == "__main__":
    main()
