"""Fokker-Planck against N-block at small k0: wall time at equal error (issue 2).

Point: k0 = 1e-3, V = 174.75 (Fig. 10's point, 1.5 times the RS V^c; Fig. 4 parameters),
steady sliding.  Reference: the large-V law ``micro.sigma_fast_limit`` (its neglected
O(V^-2) term is ~3e-8 here).  The Fokker-Planck rows are those of
benchmarks/results/micro_fp_eps_convergence.csv (run `python -m studies micro_fp_eps_convergence` for k0 = 0.001
first).  The N-block solver is run here for growing N; near V^c its finite-N system
slips in global shocks, so its error is a finite-size bias that falls slowly with N.
Its error and wall time are fitted as powers of N, and the wall time it would need to
match each Fokker-Planck error is extrapolated from them (said so in the output: such N
are far beyond what can be run).

Writes benchmarks/results/micro_fp_vs_nblock_small_k0.csv.

    python benchmarks/micro_fp_vs_nblock_small_k0.py            # about 5 minutes
"""
from __future__ import annotations

import argparse

import numpy as np
import pandas as pd

import micro
from micro import nblock

from _harness import RESULTS, timed, warm_up, write_csv

K0, V = 0.001, 174.75


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--N", type=str, default="1000,3000,10000,30000", help="comma-separated block numbers")
    args = ap.parse_args()
    model = micro.Model(k0=K0)
    ref = micro.sigma_fast_limit(model, V)
    warm_up(nblock.stationary_stress_nblock, model, V, 100, t_transient=0.5, batch_length=0.5, n_batches=2)
    rows = []
    for n in (int(x) for x in args.N.split(",")):
        # 3 time units of transient (the FP state settles in ~2), 5 batches of 2
        r, wall = timed(nblock.stationary_stress_nblock, model, V, n, t_transient=3.0, batch_length=2.0,
                        n_batches=5, seed=1)
        rows.append(dict(solver="N-block", N=n, value=r.sigma_mean, stderr=r.sigma_stderr, regime=r.regime,
                         error=r.sigma_mean - ref, wall_s=wall))
        print(rows[-1], flush=True)
    nb = pd.DataFrame(rows)
    a_err, c_err = np.polyfit(np.log(nb.N), np.log(np.abs(nb.error)), 1)
    a_t, c_t = np.polyfit(np.log(nb.N), np.log(nb.wall_s), 1)
    print(f"N-block: |error| ~ N^{a_err:.2f}, wall ~ N^{a_t:.2f}")
    fp = pd.read_csv(RESULTS / "micro_fp_eps_convergence.csv")
    fp = fp[(fp.k0 == K0) & fp.converged.astype(bool)].sort_values("eps", ascending=False)
    for _, row in fp.iterrows():
        err = abs(row.sigma - ref)
        n_need = float(np.exp((np.log(err) - c_err) / a_err))
        t_need = float(np.exp(c_t + a_t * np.log(n_need)))
        rows.append(dict(solver="FP", eps=row.eps, value=row.sigma, error=row.sigma - ref, wall_s=row.wall_s,
                         nblock_N_needed=n_need, nblock_wall_s_extrapolated=t_need, speedup=t_need / row.wall_s))
        print(f"FP eps = {row.eps:g}: error {row.sigma - ref:+.2e} in {row.wall_s:.0f} s; the N-block would need "
              f"N ~ {n_need:.2g} and ~{t_need:.2g} s (extrapolated): {t_need / row.wall_s:.2g}x", flush=True)
    table = write_csv(rows, RESULTS / "micro_fp_vs_nblock_small_k0.csv")
    print(table.to_string(index=False))


if __name__ == "__main__":
    main()
