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
the hypot of the two errors.  (The N-block's sigma_max and sigma_min are the stress just
before and just after its shocks, the paper's sigma_B and sigma_A: compare them with the
cohort's ``sigma_before`` and ``sigma_after``.  Those equal the cohort's cycle extremes
exactly at k0 <= 0.01 and to 1e-5 at k0 = 0.1, d <= 0.1 (2e-5 at d = 0.2), but at
k0 = 0.3 the creep before a shock outruns the drive and the stress peaks 2-3e-4 above
sigma_B at d = 0.05-0.1.)  Also the period, the function's status ('transient' if the
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

    NUMBA_NUM_THREADS=1 python -m studies micro_transition_nblock_check --d 0.2,0.01 --N 100000   # 52 s of CPU
    NUMBA_NUM_THREADS=1 python -m studies micro_transition_nblock_check     # the grid: 37 min of CPU
    NUMBA_NUM_THREADS=1 python -m studies micro_transition_nblock_check --d 0.01,0.02,0.05 --N 3000000   # 33 min
    NUMBA_NUM_THREADS=1 python -m studies micro_transition_nblock_check --d 0.01 --N 100000,300000,1000000 --shock-fraction 0.3
    NUMBA_NUM_THREADS=1 python -m studies micro_transition_nblock_check --d 0.01 --N 100000,300000,1000000 --shock-fraction 0.05
    NUMBA_NUM_THREADS=1 python -m studies micro_transition_nblock_check --k0 0.01 --d 0.1,0.05,0.02 --N 100000,300000
        # k0 = 0.01: 2-3 times the cost at k0 = 0.1 (each block jumps 7-13 times in a total shock)
    NUMBA_NUM_THREADS=1 python -m studies micro_transition_nblock_check --k0 0.01 --d 0.1 --N 1000000 --seed 1
    NUMBA_NUM_THREADS=1 python -m studies micro_transition_nblock_check --k0 0.01 --d 0.1 --N 10000,30000 --n-cycles 1500
    NUMBA_NUM_THREADS=1 python -m studies micro_transition_nblock_check --k0 0.01 --d 0.1 --N 30000 --n-cycles 1500 --seed 1
    NUMBA_NUM_THREADS=1 python -m studies micro_transition_nblock_check --k0 0.01 --d 0.1 --N 100000 --n-cycles 800 --seed 3
    NUMBA_NUM_THREADS=1 python -m studies micro_transition_nblock_check --k0 0.01 --d 0.1 --N 300000 --n-cycles 500 --seed 2
    NUMBA_NUM_THREADS=1 python -m studies micro_transition_nblock_check --k0 0.01 --d 0.05 --N 1000000 --seed 1
    NUMBA_NUM_THREADS=1 python -m studies micro_transition_nblock_check --k0 0.01 --d 0.05 --N 30000,100000 --n-cycles 1000 --seed 2
    NUMBA_NUM_THREADS=1 python -m studies micro_transition_nblock_check --k0 0.01 --d 0.05 --N 300000 --n-cycles 600 --seed 2
    NUMBA_NUM_THREADS=1 python -m studies micro_transition_nblock_check --k0 0.01 --d 0.01 --N 100000,300000,1000000 --record-every 0.002
    NUMBA_NUM_THREADS=1 python -m studies micro_transition_nblock_check --k0 0.01 --d 0.01 --N 3000000 --record-every 0.002
    NUMBA_NUM_THREADS=1 python -m studies micro_transition_nblock_check --k0 0.3 --d 0.1 --N 100000,300000,1000000,3000000 --shock-fraction 0.15 --record-every 0.002
    NUMBA_NUM_THREADS=1 python -m studies micro_transition_nblock_check --k0 0.3 --d 0.05 --N 100000,300000,1000000,3000000 --shock-fraction 0.1 --record-every 0.002
    NUMBA_NUM_THREADS=1 python -m studies micro_transition_nblock_check --k0 0.3 --d 0.02 --N 100000,300000,1000000,3000000 --shock-fraction 0.05 --record-every 0.002
    NUMBA_NUM_THREADS=1 python -m studies micro_transition_nblock_check --k0 0.3 --d 0.01 --N 100000,300000,1000000,3000000 --shock-fraction 0.025 --record-every 0.001
    NUMBA_NUM_THREADS=1 python -m studies micro_transition_nblock_check --k0 0.3 --d 0.05 --N 10000000 --shock-fraction 0.1 --record-every 0.002
        # k0 = 0.3: the threshold below the fraction a shock moves (56, 35, 16, 8 %); 4-1443 CPU s a run
    python -m studies micro_transition_nblock_check --k0 0.01 --d 0.1,0.05 --trend   # the finite-N fits
    python -m studies micro_transition_nblock_check --k0 0.3 --d 0.1,0.05 --trend
"""
from __future__ import annotations

import argparse
import math

import numpy as np
import pandas as pd

import micro
from benchmarks._harness import RESULTS, Stopwatch, warm_up, write_csv
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
    ap.add_argument("--trend", action="store_true",
                    help="instead: fit the CSV's amplitudes at --k0 and each --d against N (see trend())")
    args = ap.parse_args()
    if args.trend:
        for d in (float(x) for x in args.d.split(",")):
            trend(args.k0, d)
        return
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


def separated(rows: pd.DataFrame) -> pd.Series:
    """Whether each row is a check: its shocks stand apart from the other avalanches (the
    smallest shock at least twice the threshold, the largest other avalanche below half of it)."""
    return (rows.shock_size_min >= 2.0 * rows.shock_fraction) & (rows.largest_subthreshold <= 0.5 * rows.shock_fraction)


def pooled(rows: pd.DataFrame, col: str, by: str) -> pd.DataFrame:
    """``col`` of the rows pooled by inverse variance within each value of ``by`` (seeds and
    run lengths at one N, or one d): columns ``value``, ``stderr``, ``runs``, ``cycles``."""
    w = 1.0 / rows[f"{col}_stderr"] ** 2
    g = (rows.assign(w=w, wa=w * rows[col]).groupby(by)
         .agg(w=("w", "sum"), wa=("wa", "sum"), runs=("seed", "size"), cycles=("n_cycles", "sum")))
    return pd.DataFrame({"value": g.wa / g.w, "stderr": 1.0 / np.sqrt(g.w), "runs": g.runs, "cycles": g.cycles})


def trend(k0: float, d: float) -> None:
    """The N-block's finite-N trend at (k0, d), from the CSV: for the amplitude, sigma_max
    and sigma_min, the rows at one N (seeds, run lengths) pooled by inverse variance, then
    value(N) = limit + c N^(-a) fitted by weighted least squares with a free and with
    a = 1/2 and 1 fixed; each limit with its standard error and the fit's chi^2 per
    degree of freedom.  Rows whose shocks are not
    separated from the other avalanches are left out (and printed)."""
    rows = pd.read_csv(CSV)
    rows = rows[np.isclose(rows.k0, k0) & np.isclose(rows.d, d) & (rows.status == "ok")]
    clean = separated(rows)
    for r in rows[~clean].itertuples():
        print(f"k0 = {k0:g}, d = {d:g}, N = {r.N:.0f}, seed {r.seed}: left out, its shocks are not separated "
              f"(smallest {r.shock_size_min:.3g} N, largest other avalanche {r.largest_subthreshold:.3g} N, "
              f"threshold {r.shock_fraction:g} N); amplitude {r.amplitude:.6f} +- {r.amplitude_stderr:.1e}")
    rows = rows[clean]
    if rows.empty:
        print(f"k0 = {k0:g}, d = {d:g}: no rows")
        return
    for col in ("amplitude", "sigma_max", "sigma_min"):
        _trend_of(rows, col, k0, d)


def _trend_of(rows: pd.DataFrame, col: str, k0: float, d: float) -> None:
    from scipy.optimize import curve_fit

    by_n = pooled(rows, col, "N")
    N = by_n.index.to_numpy(float)
    val, err = by_n.value.to_numpy(), by_n.stderr.to_numpy()
    print(f"k0 = {k0:g}, d = {d:g}: {col} by N (seeds and runs pooled)")
    for n, a, e, r, c in zip(N, val, err, by_n.runs, by_n.cycles):
        print(f"  N = {n:9.0f}: {a:.6f} +- {e:.1e}  ({r} runs, {c} shocks)")

    def law(n, v_inf, c, a):
        return v_inf + c * n ** (-a)

    fits = []
    if len(N) >= 4:
        try:
            p, cov = curve_fit(law, N, val, p0=(val[-1], (val[0] - val[-1]) * N[0] ** 0.5, 0.5), sigma=err,
                               absolute_sigma=True, maxfev=20000)
            fits.append(("a free", p, np.sqrt(np.diag(cov)), len(N) - 3))
        except RuntimeError as exc:
            print(f"  a free  : no fit ({exc})")
    for a_fixed in (0.5, 1.0):
        p, cov = curve_fit(lambda n, v_inf, c: law(n, v_inf, c, a_fixed), N, val, p0=(val[-1], 0.0), sigma=err,
                           absolute_sigma=True)
        fits.append((f"a = {a_fixed:g}", np.append(p, a_fixed), np.append(np.sqrt(np.diag(cov)), 0.0), len(N) - 2))
    for name, p, e, dof in fits:
        chi2 = float(np.sum(((law(N, *p) - val) / err) ** 2))
        print(f"  {name:8s}: limit = {p[0]:.6f} +- {e[0]:.1e}, c = {p[1]:.3g}, a = {p[2]:.2f} +- {e[2]:.2f}; "
              f"chi2/dof = {chi2:.2f}/{dof}")


if __name__ == "__main__":
    main()
