"""Oscillation amplitude against V near V^c: Fokker-Planck at several bins against the N-block.

Both solvers start from their steady state at `--V-start` (default the larger of 2 and
1.5 times the largest V, above V^c) and are stepped down to each V.  The amplitude is the
median, over windows of `--window` time units after the first, of the peak-to-peak stress
in the window.  A physical cycle has the same
amplitude at every bin and N; an oscillation of the grid shrinks with eps (near V^c it
reaches ~2 eps), and the N-block's finite-N noise falls like N^-1/2.  This is the independent check of the
bisection's V^c (`micro.critical_velocity`).

Writes benchmarks/results/micro_fp_vs_nblock_hopf_amplitude.csv (rows merge by k0, k1, k2, resolution and V; a bin
eps < 1 never equals an N).  A run lasts at least 30 block cycles (30 zbar / V); one made longer
has its windows lengthened by the same factor.

    python -m studies micro_fp_vs_nblock_hopf_amplitude                              # k0 = 0.1
    python -m studies micro_fp_vs_nblock_hopf_amplitude --solver fp --eps 0.004 --V 0.8,0.9
    python -m studies micro_fp_vs_nblock_hopf_amplitude --solver nblock --N 1e6 --t-max 60
    python -m studies micro_fp_vs_nblock_hopf_amplitude --k0 0.3 --k1 0.5 --k2 0.5 --solver nblock --V 0.02,0.04,0.06
    python -m studies micro_fp_vs_nblock_hopf_amplitude --k0 0.01 --solver nblock --V 7,7.5,8,8.5,9.5 --t-max 80
"""
from __future__ import annotations

import argparse

import numpy as np
import pandas as pd

import micro
from benchmarks._harness import RESULTS, Stopwatch, write_csv
from micro.nblock import simulate_nblock



def amplitude(t: np.ndarray, smax: np.ndarray, smin: np.ndarray, window: float, t_max: float) -> tuple[float, float]:
    """Median and largest peak-to-peak stress over the windows after the first."""
    pp = []
    for a in np.arange(window, t_max - 0.5 * window, window):
        m = (t >= a) & (t < a + window)
        if m.any():
            pp.append(float(smax[m].max() - smin[m].min()))
    return float(np.median(pp)), float(np.max(pp))


def run_length(model: micro.Model, V: float, t_max: float, window: float) -> tuple[float, float]:
    """At least 30 block cycles (30 zbar / V); a run made longer has its windows
    lengthened by the same factor."""
    T = max(t_max, 30.0 * model.zbar / V)
    return T, window * T / t_max


def fp_rows(model: micro.Model, eps: float, Vs: list[float], t_max: float, window: float, V_start: float) -> list[dict]:
    num = micro.Numerics(eps=eps)
    # (the steady start compiles the kernels, or loads numba's cache, before any clock starts)
    base = micro.stationary(model, V_start, numerics=num, keep_grid=True, method="fp")
    rows = []
    for V in Vs:
        sw = Stopwatch()
        T, W = run_length(model, V, t_max, window)
        r = micro.simulate(model, V, duration=T, numerics=num, initial=base.grid,
                           record_dsigma=0.25 * model.k0 * eps, record_dt=W / 200.0).records
        med, top = amplitude(r.t.to_numpy(), r.sigma_max.to_numpy(), r.sigma_min.to_numpy(), W, T)
        rows.append(dict(solver="fp", resolution=eps, V=V, amplitude=med, amplitude_max=top,
                         in_k0_eps=med / (model.k0 * eps), t_max=T, wall_s=sw.seconds))
        print(rows[-1], flush=True)
    return rows


def nblock_rows(model: micro.Model, N: int, Vs: list[float], t_max: float, window: float, V_start: float) -> list[dict]:
    # (the steady start compiles the kernels, or loads numba's cache, before any clock starts)
    base = simulate_nblock(model, V_start, N, t_max=30.0, initial="frozen")
    rows = []
    for V in Vs:
        sw = Stopwatch()
        T, W = run_length(model, V, t_max, window)
        r = simulate_nblock(model, V, N, t_max=T, initial=base.final_state, record_every=W / 500.0).timeseries
        med, top = amplitude(r.t.to_numpy(), r.sigma_max.to_numpy(), r.sigma_min.to_numpy(), W, T)
        rows.append(dict(solver="nblock", resolution=float(N), V=V, amplitude=med, amplitude_max=top,
                         in_k0_eps=np.nan, t_max=T, wall_s=sw.seconds))
        print(rows[-1], flush=True)
    return rows


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--k0", type=float, default=0.1)
    ap.add_argument("--k1", type=float, default=0.1)
    ap.add_argument("--k2", type=float, default=0.9)
    ap.add_argument("--solver", choices=("fp", "nblock", "both"), default="both")
    ap.add_argument("--eps", type=str, default="0.016,0.008", help="comma-separated FP bins")
    ap.add_argument("--N", type=str, default="1e5", help="comma-separated N-block sizes")
    ap.add_argument("--V", type=str, default="0.6,0.7,0.8,0.9,1.0,1.2", help="comma-separated velocities")
    ap.add_argument("--t-max", type=float, default=120.0, help="simulated time per velocity")
    ap.add_argument("--window", type=float, default=10.0, help="amplitude window (time units)")
    ap.add_argument("--V-start", type=float, default=None,
                    help="steady start, above V^c (default max(2, 1.5 max V))")
    args = ap.parse_args()
    model = micro.Model(k0=args.k0, k1=args.k1, k2=args.k2)
    Vs = [float(v) for v in args.V.split(",")]
    V_start = args.V_start if args.V_start is not None else max(2.0, 1.5 * max(Vs))
    out = RESULTS / "micro_fp_vs_nblock_hopf_amplitude.csv"
    runs = []
    if args.solver in ("fp", "both"):
        runs += [("fp", float(e)) for e in args.eps.split(",")]
    if args.solver in ("nblock", "both"):
        runs += [("nblock", float(n)) for n in args.N.split(",")]
    for solver, res in runs:
        if solver == "fp":
            rows = fp_rows(model, res, Vs, args.t_max, args.window, V_start)
        else:
            rows = nblock_rows(model, int(res), Vs, args.t_max, args.window, V_start)
        new = pd.DataFrame(rows).assign(k0=args.k0, k1=args.k1, k2=args.k2)
        write_csv(new, out, keys=["k0", "k1", "k2", "resolution", "V"])
    table = pd.read_csv(out).sort_values(["k1", "k0", "V", "solver", "resolution"])
    print(table.pivot_table(index=["k1", "k2", "k0", "V"], columns=["solver", "resolution"], values="amplitude").to_string(
        float_format=lambda x: f"{x:.4f}"))


if __name__ == "__main__":
    main()
