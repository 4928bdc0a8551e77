"""Stress test of the Fokker-Planck solver (issue 2): V from 1e-4 to 1e3, k0 from 1e-4
to 1 (k0 = 1 >= k2 = 0.9: no stick-slip expected), bins at the coarse end of their range
and fine, a long run, and bins outside the range.

Every run is capped in simulated time so that it fits a wall-time budget (a short
calibration run measures the cost per unit time first).  Checked per run: the stress is
finite, total probability is 1 to round-off, no cell mass is negative, and a run that
missed its stopping test says so (converged = False with a message).  A run that breaks
one of these prints FAIL; the script exits non-zero if any does.  A run whose grid
outgrows the memory limit ends with micro.GridTooLarge, a clear refusal (regime
"refused"), which is not a failure.

Writes benchmarks/results/micro_fp_stress.csv.

    python -m studies micro_fp_stress              # about 20 minutes on one core
    python -m studies micro_fp_stress --budget 5   # quicker, more runs end unconverged
"""
from __future__ import annotations

import argparse
import math
import sys

import micro
from benchmarks._harness import RESULTS, Stopwatch, capped_t_max, warm_up, write_csv

OUT = RESULTS / "micro_fp_stress.csv"
K0 = (1e-4, 1e-3, 1e-2, 0.1, 1.0)
V = (1e-4, 1e-2, 1.0, 1e2, 1e3)
#: largest simulated time of a run (the calibration underestimates the cost of slow
#: drives, whose shocks come after the calibration run)
T_CAP = 5e3


def check(model: micro.Model, V: float, eps: float, budget: float, t_max: float | None = None) -> dict:
    sw = Stopwatch()
    try:
        t_max = min(capped_t_max(model, V, eps, budget), T_CAP) if t_max is None else t_max
        r = micro.stationary(model, V, numerics=micro.Numerics(eps=eps), convergence=micro.Convergence(t_max=t_max), method="fp")
    except micro.GridTooLarge as exc:  # a clear refusal, not a failure
        return dict(k0=model.k0, V=V, eps=eps, t_max=t_max, wall_s=sw.seconds, regime="refused",
                    converged=False, sigma_max=math.nan, sigma_min=math.nan, sigma_mean=math.nan,
                    message=str(exc), problems="", t_end=math.nan, mass_error=math.nan, min_mass=math.nan)
    row = dict(k0=model.k0, V=V, eps=eps, t_max=t_max, t_end=r.t_end, wall_s=sw.seconds,
               regime=r.regime, converged=r.converged, sigma_max=r.sigma_max, sigma_min=r.sigma_min,
               sigma_mean=r.sigma_mean, mass_error=r.mass_error, min_mass=r.min_mass, message=r.message)
    problems = []
    if not all(math.isfinite(row[k]) for k in ("sigma_max", "sigma_min", "sigma_mean")):
        problems.append("non-finite stress")
    if not row["mass_error"] <= 1e-9:
        problems.append(f"mass error {row['mass_error']:.2g}")
    if not row["min_mass"] >= -1e-12:
        problems.append(f"negative mass {row['min_mass']:.2g}")
    if not r.converged and "not converged" not in r.message and "stopped early" not in r.message:
        problems.append("unconverged without saying so")
    if model.k0 >= model.k2 and r.regime == "stick-slip":
        problems.append("stick-slip at k0 >= k2")
    row["problems"] = "; ".join(problems)
    return row


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--budget", type=float, default=20.0, help="wall-time budget per run, seconds (default 20)")
    ap.add_argument("--k0", default=",".join(map(str, K0)), help="comma-separated k0 values of the (k0, V) grid")
    args = ap.parse_args()
    warm_up(micro.stationary, micro.Model(k0=0.1), 2.0, numerics=micro.Numerics(eps=0.024), method="fp")
    rows = []

    def report(row):
        rows.append(row)
        write_csv(rows, OUT)  # keep what is done
        flag = "FAIL " + row["problems"] if row["problems"] else "ok"
        print(f"k0={row['k0']:<7g} V={row['V']:<7g} eps={row['eps']:<7.4g} {row['regime']:>10} "
              f"converged={row['converged']!s:5} sigma={row['sigma_mean']:.6f} "
              f"t_end={row['t_end']:.3g} wall={row['wall_s']:.1f}s {flag}", flush=True)

    for k0 in [float(k) for k in args.k0.split(",")]:
        model = micro.Model(k0=k0)
        coarse = model.kappa * model.zbar / 4.0  # the coarsest bin allowed
        for v in V:
            report(check(model, v, coarse, args.budget))
            report(check(model, v, 0.008, args.budget))
    # the finest bin allowed, at a cheap point
    model = micro.Model(k0=1.0)
    report(check(model, 10.0, model.kappa * model.zbar / 1000.0, 5.0 * args.budget))
    # a long run: 2000 time units (1800 relaxation times, 40000 jumps per block) of
    # steady sliding, the stress averaged over its first and last tenths
    sw = Stopwatch()
    run = micro.simulate(micro.Model(k0=0.1), 2.0, duration=2000.0, numerics=micro.Numerics(eps=0.024))
    rec = run.records
    early = rec[(rec.t > 100) & (rec.t < 300)].sigma_mean.mean()
    late = rec[rec.t > 1800].sigma_mean.mean()
    problems = []
    if not (run.mass_error <= 1e-9 and run.min_mass >= -1e-12 and rec.sigma.notna().all()):
        problems.append(f"density check: mass error {run.mass_error:.2g}, min mass {run.min_mass:.2g}")
    if abs(late - early) > 2e-5:
        problems.append(f"drift {late - early:.2g} between the first and last tenth")
    rows.append(dict(k0=0.1, V=2.0, eps=0.024, t_end=2000.0, wall_s=sw.seconds, regime="long run",
                     converged=True, sigma_mean=late, mass_error=run.mass_error, min_mass=run.min_mass,
                     message=f"mean stress {early:.7f} (t 100-300) and {late:.7f} (t 1800-2000)",
                     problems="; ".join(problems)))
    print(f"long run: {rows[-1]['message']}; mass error {run.mass_error:.2g}, min mass {run.min_mass:.2g}, "
          f"{rows[-1]['wall_s']:.0f} s {'FAIL ' + rows[-1]['problems'] if problems else 'ok'}", flush=True)
    # bins outside the range are refused with a message naming eps and the range
    for eps in (micro.Model(k0=0.1).kappa * 0.1 / 2000.0, 0.5):
        try:
            micro.stationary(micro.Model(k0=0.1), 2.0, numerics=micro.Numerics(eps=eps), method="fp")
            print(f"FAIL eps={eps:g} was accepted")
            rows.append(dict(k0=0.1, V=2.0, eps=eps, problems="out-of-range eps accepted"))
        except ValueError as exc:
            print(f"eps={eps:g} refused: {exc}")
    table = write_csv(rows, OUT)
    failed = table.problems.fillna("").astype(bool)
    refused = table.regime == "refused"
    unconverged = ~table.converged.fillna(False).astype(bool) & ~refused
    print(f"{len(table)} runs, {int(failed.sum())} failed, {int(unconverged.sum())} ended unconverged (and said so), "
          f"{int(refused.sum())} refused with GridTooLarge")
    sys.exit(1 if failed.any() else 0)


if __name__ == "__main__":
    main()
