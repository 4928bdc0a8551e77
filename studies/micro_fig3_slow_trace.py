"""The paper's Fig. 3 at its slow drive (k0 = 0.01, V = 0.001): the first slow cycle from a
start, by the Fokker-Planck equation refined in its bin and by the N-block as N grows.

Both runs start at rest and shock at once (t of about 0.007); the first slow shock comes
some 8000 time units later.  Each row gives its time and the stress peak before it (the
largest stress after t = 100), and the run's wall time; the two methods share no code, so
where the FP's values move with eps towards the N-block's, which move little with N, the
report's trace (`compare --paper`, Fig. 3: the N-block at N = 1e5) is the better one.

Writes benchmarks/results/micro_fig3_slow_trace.csv (rows merge by method and resolution).

    python -m studies micro_fig3_slow_trace --eps 0.016,0.008 --N 30000,100000   # about 3 minutes
    python -m studies micro_fig3_slow_trace --eps 0.004 --N ""                    # about 7 minutes
"""
from __future__ import annotations

import argparse

import numpy as np

import micro
from benchmarks._harness import RESULTS, timed, warm_up, write_csv
from micro.nblock import simulate_nblock

CSV = RESULTS / "micro_fig3_slow_trace.csv"
K0, V = 0.01, 0.001


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--eps", default="0.016,0.008", help="FP bins (comma-separated; empty for none)")
    ap.add_argument("--N", default="30000,100000", help="N-block sizes (comma-separated; empty for none)")
    ap.add_argument("--t-end", type=float, default=9000.0)
    args = ap.parse_args()
    model = micro.Model(k0=K0)
    rows = []
    if args.eps:
        warm_up(micro.simulate, model, micro.Drive(((1.0, V),)), numerics=micro.Numerics(eps=0.02))
    for eps in (float(e) for e in args.eps.split(",") if e):
        run, wall = timed(micro.simulate, model, micro.Drive(((args.t_end, V),)), numerics=micro.Numerics(eps=eps),
                          record_dt=args.t_end / 4000)
        t, sigma = np.asarray(run.records.t), np.asarray(run.records.sigma)
        falls = np.flatnonzero((np.diff(sigma) < -0.01) & (t[:-1] > 100.0))  # (the first: the shock's start)
        t1 = float(t[falls[0]]) if len(falls) else np.nan
        peak = float(sigma[(t > 100.0) & (t <= t1)].max()) if len(falls) else np.nan
        rows.append(dict(method="fp", resolution=eps, t_shock=t1, peak=peak, wall_s=wall))
    if args.N:
        warm_up(simulate_nblock, model, V, 1000, t_max=10.0)
    for N in (int(n) for n in args.N.split(",") if n):
        run, wall = timed(simulate_nblock, model, V, N, t_max=args.t_end, record_every=args.t_end / 4000)
        sh = run.shocks[run.shocks.t > 100.0]
        t1 = float(sh.t.iloc[0]) if len(sh) else np.nan
        peak = float(sh.sigma_before.iloc[0]) if len(sh) else np.nan
        rows.append(dict(method="nblock", resolution=N, t_shock=t1, peak=peak, wall_s=wall))
    for r in rows:
        what = f"eps = {r['resolution']:g}" if r["method"] == "fp" else f"N = {r['resolution']:g}"
        print(f"{r['method']:6s} {what:12s} first slow shock at t = {r['t_shock']:.1f}, peak {r['peak']:.5f}, "
              f"{r['wall_s']:.1f} s", flush=True)
    write_csv(rows, CSV, keys=["method", "resolution"])


if __name__ == "__main__":
    main()
