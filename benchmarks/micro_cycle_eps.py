"""Refinement study of the shock-to-shock map at small k0: sigma_max, sigma_min against
the bin eps, the measured order and the extrapolated limit (issue 16, the cycle side of
the paper's Fig. 10 at the k0 it could not converge).

Points: Fig. 4 parameters, V = 0.3 V^c, k0 = 1e-3 and 1e-4; eps = kappa zbar / 4 ... / 12.
Each bin starts from the previous bin's fixed point (fewer transient cycles).  The order
p and the limit come from the three finest bins (sigma(eps) = sigma_0 + C eps^p); the
error of the limit is the change of the extrapolation when the coarsest of the three
is dropped (a Richardson step with the measured p on the two finest).  sigma_min has
an exact limit, f_th - kappa zbar: the check of the procedure.

Writes benchmarks/results/micro_cycle_eps.csv.

    python benchmarks/micro_cycle_eps.py        # about 10 minutes
"""
from __future__ import annotations

import argparse
import math
from pathlib import Path

import numpy as np
import pandas as pd
from scipy.optimize import brentq

import micro
from micro.cycle import cycle_fixed_point

HERE = Path(__file__).resolve().parent


def order_and_limit(eps: np.ndarray, s: np.ndarray) -> tuple[float, float, float]:
    """From three bins e1 > e2 > e3 (ratios need not be equal): the order p solving
    (s1 - s2)/(s2 - s3) = (e1^p - e2^p)/(e2^p - e3^p), the limit s3 - (s2 - s3) e3^p/(e2^p - e3^p),
    and the limit's change against a p = 2 Richardson step on the two finest."""
    e1, e2, e3 = eps
    s1, s2, s3 = s
    r = (s1 - s2) / (s2 - s3)
    f = lambda p: (e1**p - e2**p) / (e2**p - e3**p) - r  # noqa: E731
    try:
        p = brentq(f, 0.2, 8.0)
    except ValueError:
        return math.nan, math.nan, math.nan
    limit = s3 - (s2 - s3) * e3**p / (e2**p - e3**p)
    second = s3 - (s2 - s3) * e3**2 / (e2**2 - e3**2)
    return p, limit, abs(limit - second)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--k0", default="0.001,0.0001")
    ap.add_argument("--frac", type=float, default=0.3, help="V / V^c")
    ap.add_argument("--divisors", default="4,6,8,10,12", help="eps = kappa zbar / divisor")
    ap.add_argument("--tol", type=float, default=2e-5)
    args = ap.parse_args()
    rows = []
    for k0 in (float(x) for x in args.k0.split(",")):
        model = micro.Model(k0=k0)
        V = args.frac * float(micro.critical_velocity(model).Vc)
        prev = None
        for div in (float(x) for x in args.divisors.split(",")):
            eps = model.kappa * model.zbar / div
            res = cycle_fixed_point(model, V, eps, tol=args.tol, start=prev)
            prev = res
            rows.append(dict(k0=k0, V=V, eps=eps, sigma_max=res.sigma_max, sigma_min=res.sigma_min,
                             sigma_min_exact=micro.sigma_fast_limit(model), period=res.period, error=res.error,
                             cycles=res.iterations, converged=res.converged, wall_s=res.wall_time))
            print({k: (f"{v:.7g}" if isinstance(v, float) else v) for k, v in rows[-1].items()}, flush=True)
            pd.DataFrame(rows).to_csv(HERE / "results" / "micro_cycle_eps.csv", index=False)
        d = pd.DataFrame([r for r in rows if r["k0"] == k0]).sort_values("eps", ascending=False).tail(3)
        for col in ("sigma_max", "sigma_min"):
            p, limit, err = order_and_limit(d.eps.to_numpy(), d[col].to_numpy())
            print(f"k0 = {k0:g}: {col} -> {limit:.6f} +- {err:.1e} (order {p:.2f} from eps = "
                  f"{', '.join(f'{e:.4f}' for e in d.eps)})", flush=True)


if __name__ == "__main__":
    main()
