"""Stick-slip cycles at small k0: the return-map fixed point (``method="cycle"``)
against the Fokker-Planck time-stepping (``method="fp"``), run time and values (issue 16).

Points: the Fig. 4 parameters at V = 0.3 V^c for k0 = 0.01, 1e-3, 1e-4 (V^c from the
renewal chain), bins eps = kappa zbar / {6, 8}.  Both methods solve the same
discretised equation, so at equal eps they must agree within their errors; the
exact sigma_min = ``micro.sigma_fast_limit`` (docs/reference/micro_model.md §5) checks
both.  The time-stepping is run only where it costs less than ``--fp-budget`` seconds
per point (its shocks are time-stepped: ~0.5 s per cycle at k0 = 1e-3, growing as 1/k0).

Writes benchmarks/results/micro_cycle_speed.csv.

    python benchmarks/micro_cycle_speed.py          # about 5 minutes
"""
from __future__ import annotations

import argparse
import time
from pathlib import Path

import pandas as pd

import micro

HERE = Path(__file__).resolve().parent


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--k0", default="0.01,0.001,0.0001")
    ap.add_argument("--frac", type=float, default=0.3, help="V / V^c")
    ap.add_argument("--divisors", default="6,8", help="eps = kappa zbar / divisor")
    ap.add_argument("--rtol", type=float, default=1e-3)
    ap.add_argument("--fp-k0-min", type=float, default=1e-3, help="time-step only at k0 >= this")
    args = ap.parse_args()
    rows = []
    # compile once, outside the timings
    micro.stationary(micro.Model(k0=0.01), 2.4, method="cycle", numerics=micro.Numerics(eps=0.025),
                     convergence=micro.Convergence(rtol=1e-2))
    for k0 in (float(x) for x in args.k0.split(",")):
        model = micro.Model(k0=k0)
        V = args.frac * float(micro.critical_velocity(model).Vc)
        exact = micro.sigma_fast_limit(model)
        for div in (float(x) for x in args.divisors.split(",")):
            eps = model.kappa * model.zbar / div
            methods = ["cycle"] + (["fp"] if k0 >= args.fp_k0_min else [])
            for method in methods:
                t = time.perf_counter()
                res = micro.stationary(model, V, method=method, numerics=micro.Numerics(eps=eps),
                                       convergence=micro.Convergence(rtol=args.rtol, n=3), warn=False)
                row = dict(method=method, k0=k0, V=V, eps=eps, sigma_max=res.sigma_max, sigma_min=res.sigma_min,
                           sigma_min_exact=exact, period=res.period, error=res.sigma_stderr, cycles=res.n_cycles,
                           converged=res.converged, wall_s=time.perf_counter() - t, message=res.message)
                rows.append(row)
                print({k: (f"{v:.7g}" if isinstance(v, float) else v) for k, v in row.items() if k != "message"},
                      flush=True)
                pd.DataFrame(rows).to_csv(HERE / "results" / "micro_cycle_speed.csv", index=False)


if __name__ == "__main__":
    main()
