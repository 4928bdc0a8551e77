"""The stick-slip amplitude against V^c - V by the cohort method (``micro.cohort``).

Fig. 4 parameters, k0 = 0.1 and 0.01, V / V^c from 0.5 to 0.999 with the exact V^c of
the renewal chain; each V starts from the previous V's cycle (when that is a product
state), converged to tol = 1e-6 at (dt, h) = (0.01, kappa zbar / 20), and again at
(0.005, kappa zbar / 40) to measure the discretisation error of each amplitude.  The
law amplitude = A (1 - V/V^c)^nu is fitted over the points closest to V^c, with the
exponent's standard error from the fit.

Writes benchmarks/results/micro_cohort_amplitude.csv, a row at a time (rows merge by k0,
V / V^c, dt and h: ``--k0 0.01`` alone adds its rows).

    python benchmarks/micro_cohort_amplitude.py        # about 20 minutes on 1 core
"""
from __future__ import annotations

import argparse
import time
from pathlib import Path

import numpy as np
import pandas as pd

import micro
from micro.cohort import cycle_cohorts

HERE = Path(__file__).resolve().parent
FRACTIONS = (0.5, 0.7, 0.8, 0.9, 0.95, 0.97, 0.98, 0.99, 0.995, 0.998, 0.999)


def fit_law(frac: np.ndarray, amp: np.ndarray) -> tuple[float, float, float]:
    """Least squares of log amplitude against log(1 - V/V^c): exponent, its standard
    error, prefactor."""
    x, y = np.log(1.0 - frac), np.log(amp)
    A = np.vstack([x, np.ones_like(x)]).T
    coef, res, *_ = np.linalg.lstsq(A, y, rcond=None)
    dof = max(len(x) - 2, 1)
    s2 = float(np.sum((y - A @ coef) ** 2)) / dof
    cov = s2 * np.linalg.inv(A.T @ A)
    return float(coef[0]), float(np.sqrt(cov[0, 0])), float(np.exp(coef[1]))


KEY = ["k0", "V_over_Vc", "dt", "h"]


def save(rows: list[dict], out: Path) -> pd.DataFrame:
    """Merge ``rows`` into the CSV at ``out`` (a row replaces the one with its k0, V / V^c,
    dt and h), so that an interrupted run keeps its rows and runs at other k0 add theirs."""
    frame = pd.DataFrame(rows)
    if out.exists():
        old = pd.read_csv(out)
        old = old[~old.set_index(KEY).index.isin(frame.set_index(KEY).index)]
        frame = pd.concat([old, frame], ignore_index=True)
    frame = frame.sort_values(["k0", "V_over_Vc", "dt"], ascending=[False, True, False]).reset_index(drop=True)
    out.parent.mkdir(parents=True, exist_ok=True)
    frame.to_csv(out, index=False)
    return frame


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--k0", default="0.1,0.01")
    ap.add_argument("--fractions", default=",".join(str(f) for f in FRACTIONS))
    ap.add_argument("--max-iter", type=int, default=400, help="cycles (and accelerated cycles) per point")
    ap.add_argument("--out", default=str(HERE / "results" / "micro_cohort_amplitude.csv"))
    args = ap.parse_args()
    out = Path(args.out)
    rows = []
    for k0 in (float(v) for v in args.k0.split(",")):
        model = micro.Model(k0=k0)
        Vc = micro.critical_velocity(model).Vc
        lam = model.kappa * model.zbar
        starts = {}
        for frac in (float(f) for f in args.fractions.split(",")):
            V = frac * Vc
            for dt, h in ((0.01, lam / 20.0), (0.005, lam / 40.0)):
                t = time.perf_counter()
                res = cycle_cohorts(model, V, dt=dt, h=h, tol=1e-6, start=starts.get(h), max_iter=args.max_iter)
                if res.p is not None:
                    starts[h] = res
                rows.append(dict(k0=k0, Vc=Vc, V_over_Vc=frac, V=V, dt=dt, h=h, sigma_max=res.sigma_max,
                                 sigma_min=res.sigma_min, amplitude=res.sigma_max - res.sigma_min,
                                 period=res.period, unjumped=res.unjumped, error=res.error, cycles=res.iterations,
                                 converged=res.converged, applicable=res.applicable,
                                 wall_s=time.perf_counter() - t, message=res.message))
                print({k: v for k, v in rows[-1].items() if k != "message"}, flush=True)
                frame = save(rows, out)
    fine = frame[(frame.dt == 0.005) & frame.converged]
    for k0, grp in fine.groupby("k0", sort=False):
        near = grp[grp.V_over_Vc >= 0.98]
        if len(near) >= 3:
            nu, se, A = fit_law(near.V_over_Vc.to_numpy(), near.amplitude.to_numpy())
            print(f"k0 = {k0:g}: amplitude = {A:.4g} (1 - V/Vc)^({nu:.3f} +- {se:.3f}) over V/Vc >= 0.98")


if __name__ == "__main__":
    main()
