"""The cohort method across parameters, against the N-block simulation (issue 37, item 3).

Every other cohort check uses the paper's Fig. 4 parameters.  Here each parameter is moved
on its own, (k1, k2) = (0, 1), (0.5, 0.5), (0.9, 0.1); eta_u = 0.5, 2; f_th = 2; zbar =
0.05 (the Fig. 4 set, "default", is the baseline), at V = V^c / 2 (d = 0.5, where the
cohort's discretisation error is known) and a k0 where shocks are total (the blocks a
shock leaves unjumped are at most 7e-4 of them) and the N-block is affordable: k0 = 0.05,
0.02 for (0.5, 0.5), 0.01 for (0.9, 0.1) (at k0 = 0.05 its shocks leave a quarter of the
blocks and one cohort point took 10 minutes).

``--solver nblock`` (the reference; shares no code with the cohort method): for each set
and each N, ``micro.nblock.stick_slip_extrema_nblock`` from the relaxed start, its seed
(``--seed`` plus the set's index: the sets related by the model's scaling, eta_u, f_th and
zbar, give the default set's numbers to the last digit with the same seed), the set's
transient shocks dropped (20: the sigma_B of a run at N = 1e5 settles by the 15th; 100 at
(k1, k2) = (0, 1)) and ``--cycles`` averaged, with the standard errors of the cycles
inflated by their lag-1 autocorrelation.
Three numbers per cycle: the largest stress of the cycle from the run's binned maxima
(bins of a 500th of the loading time kappa zbar / (k0 V), ``sigma_peak``: what the
cohort method calls sigma_max), the stress when the shock starts (``sigma_before``) and
right after it (``sigma_after``, sigma_min).  Two N a factor 4 apart give the finite-N
trend.  Writes benchmarks/results/micro_cohort_parameters_nblock.csv (rows merge by set,
N and seed); tests/micro/test_cohort_parameters.py reads it.

``--solver cohort`` (the record, not read by the tests): the cohort method at the test's
resolution (``dt`` per set, the default cell kappa zbar / 20, the default tol) and at
``--levels`` finer ones (dt and h halved together, tol 2e-6), and the effect of each
parameter: the Fig. 4 set at the same k0 and V (and at the same V / V^c), by
``micro.stationary`` (the renewal chain where it slides steadily).  Writes
benchmarks/results/micro_cohort_parameters_cohort.csv.

    python -m studies micro_cohort_parameters --solver nblock --N 250000,1000000   # about 2 h of CPU
    python -m studies micro_cohort_parameters --solver cohort                        # about 10 min of CPU
"""
from __future__ import annotations

import argparse
import math

import numpy as np
import pandas as pd

import micro
from micro import nblock as nb

from benchmarks._harness import RESULTS, Stopwatch, warm_up, write_csv

NBLOCK_CSV = RESULTS / "micro_cohort_parameters_nblock.csv"
COHORT_CSV = RESULTS / "micro_cohort_parameters_cohort.csv"

#: V / V^c of every point (d = 0.5).
FRACTION = 0.5
#: name: (k0, the parameters moved from the Fig. 4 set, the test's cohort time step, the
#: N-block's discarded shocks).  The step is 0.02 in units where the dashpots relax at
#: gamma = 0.9: dt gamma = 0.018 (0.01 at eta_u = 0.5, 0.04 at eta_u = 2; 0.1 at k2 = 0.1,
#: gamma = 0.1, where dt = 0.02 moves sigma_max by 2e-7 and costs 17 times as much).  At
#: (k1, k2) = (0, 1) the cycle map contracts by 0.92 a cycle (a single block's relaxation,
#: (1 - alpha (1 - exp(-gamma T)))^2 with alpha = (k0 + k1) / kappa = 0.048): the N-block
#: run still drifted by 5.7e-4 between the halves of 40 cycles after 20 discarded, so it
#: discards 100.
SETS: dict[str, tuple[float, dict, float, int]] = {
    "default": (0.05, {}, 0.02, 20),
    "k1=0/k2=1": (0.05, dict(k1=0.0, k2=1.0), 0.02, 100),
    "k1=0.5/k2=0.5": (0.02, dict(k1=0.5, k2=0.5), 0.02, 20),
    "k1=0.9/k2=0.1": (0.01, dict(k1=0.9, k2=0.1), 0.1, 20),
    "eta_u=0.5": (0.05, dict(eta_u=0.5), 0.01, 20),
    "eta_u=2": (0.05, dict(eta_u=2.0), 0.04, 20),
    "f_th=2": (0.05, dict(f_th=2.0), 0.02, 20),
    "zbar=0.05": (0.05, dict(zbar=0.05), 0.02, 20),
}


def model_of(name: str) -> micro.Model:
    k0, moved = SETS[name][:2]
    moved = dict(moved)
    zbar = moved.pop("zbar", 0.1)
    return micro.Model(k0=k0, jumps=micro.Exponential(zbar=zbar), **moved)


def point(name: str) -> tuple[micro.Model, float, float]:
    """The set's model, its V^c (renewal chain) and the drive V = FRACTION V^c."""
    model = model_of(name)
    vc = float(micro.critical_velocity(model).Vc)
    return model, vc, FRACTION * vc


def _stderr(x: np.ndarray) -> float:
    """The standard error of the mean of ``x`` with its lag-1 autocorrelation r (clipped to
    [0, 0.9]) taken into account: sd / sqrt(n) * sqrt((1 + r) / (1 - r)), the N-block's own
    rule (``stick_slip_extrema_nblock``)."""
    d = x - x.mean()
    r = float(d[1:] @ d[:-1] / (d @ d)) if d @ d > 0 else 0.0
    r = min(max(r, 0.0), 0.9)
    return float(x.std(ddof=1) / math.sqrt(x.size) * math.sqrt((1.0 + r) / (1.0 - r)))


def _halves(x: np.ndarray) -> float:
    """The second half's mean less the first's (a drift left by the transient)."""
    h = x.size // 2
    return float(x[h:].mean() - x[:h].mean())


def run_nblock(name: str, n_blocks: int, cycles: int, seed: int) -> dict:
    model, vc, V = point(name)
    discard = SETS[name][3]
    loading = model.kappa * model.zbar / (model.k0 * V)  # longer than a loading phase
    t_max = (cycles + discard + 2) * 2.0 * loading
    cpu = Stopwatch(cpu=True)
    wall = Stopwatch()
    ext = nb.stick_slip_extrema_nblock(model, V, n_blocks, n_cycles=cycles, n_discard=discard, seed=seed,
                                       t_max=t_max, record_every=loading / 500.0)
    if ext.status not in ("ok", "transient"):
        raise RuntimeError(f"{name}, N = {n_blocks}: {ext.message}")
    ts = ext.result.timeseries
    t_end = ts["t"].to_numpy()
    t_start = np.concatenate([[0.0], t_end[:-1]])
    bin_max = ts["sigma_max"].to_numpy()
    shocks = ext.result.shocks["t"].to_numpy()
    peaks = []
    for j in range(discard, len(shocks)):
        prev = shocks[j - 1] if j > 0 else 0.0
        inside = (t_start >= prev) & (t_start < shocks[j])
        peaks.append(bin_max[inside].max())
    peaks = np.array(peaks)
    before = ext.shocks["sigma_before"].to_numpy()
    after = ext.shocks["sigma_after"].to_numpy()
    periods = np.diff(ext.shocks["t"].to_numpy())
    moved = SETS[name][1]
    return dict(
        set=name, k0=model.k0, k1=model.k1, k2=model.k2, eta_u=model.eta_u, f_th=model.f_th,
        zbar=moved.get("zbar", 0.1), Vc=vc, fraction=FRACTION, V=V, N=n_blocks, seed=seed,
        n_cycles=len(peaks), n_discard=discard,
        sigma_peak=float(peaks.mean()), sigma_peak_stderr=_stderr(peaks), sigma_peak_drift=_halves(peaks),
        sigma_before=float(before.mean()), sigma_before_stderr=_stderr(before), sigma_before_drift=_halves(before),
        sigma_after=float(after.mean()), sigma_after_stderr=_stderr(after), sigma_after_drift=_halves(after),
        period=float(periods.mean()), period_stderr=_stderr(periods),
        exact_sigma_min=micro.sigma_fast_limit(model), status=ext.status,
        n_jumps=int(ext.result.n_jumps), wall_time=round(wall.seconds, 1), cpu_time=round(cpu.seconds, 1),
    )


def run_cohort(name: str, levels: int) -> list[dict]:
    model, vc, V = point(name)
    dt = SETS[name][2]
    rows = []
    configs = [(dt, None, 2e-5)] + [(dt / 2**k, model.kappa * model.zbar / (20 * 2**k), 2e-6) for k in range(levels + 1)]
    for step, h, tol in configs:
        cpu = Stopwatch(cpu=True)
        res = micro.stationary(model, V, method=micro.Cohort(dt=step, h=h, tol=tol))
        rows.append(dict(set=name, what="cohort", k0=model.k0, V=V, Vc=vc, dt=step, h=res.eps, tol=tol,
                         sigma_max=res.sigma_max, sigma_before=res.sigma_before, sigma_min=res.sigma_min,
                         period=res.period, error=res.sigma_stderr, discretisation_error=res.discretisation_error,
                         unjumped=res.cycle.unjumped, converged=res.converged, method=res.method,
                         cpu_time=round(cpu.seconds, 2)))
        print(rows[-1], flush=True)
    # the effect: what the Fig. 4 set gives at the same k0, at the same V and at the same V / V^c
    base = micro.Model(k0=model.k0)
    vc_base = float(micro.critical_velocity(base).Vc)
    for label, v in (("default at the same V", V), ("default at the same V/Vc", FRACTION * vc_base)):
        if name == "default" or (label.endswith("V/Vc") and SETS[name][0] == SETS["default"][0]):
            continue
        cpu = Stopwatch(cpu=True)
        res = micro.stationary(base, v, method=micro.Auto(cohort=micro.Cohort(dt=0.02)))
        rows.append(dict(set=name, what=label, k0=base.k0, V=v, Vc=vc_base, dt=0.02, h=res.eps, tol=2e-5,
                         sigma_max=res.sigma_max, sigma_before=res.sigma_before, sigma_min=res.sigma_min,
                         period=res.period, error=res.sigma_stderr, discretisation_error=res.discretisation_error,
                         unjumped=res.cycle.unjumped if res.cycle is not None else math.nan, converged=res.converged,
                         method=res.method, cpu_time=round(cpu.seconds, 2)))
        print(rows[-1], flush=True)
    return rows


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--solver", choices=("nblock", "cohort"), required=True)
    ap.add_argument("--sets", default=",".join(SETS), help="comma-separated names of SETS")
    ap.add_argument("--N", default="250000,1000000", help="nblock: block counts")
    ap.add_argument("--cycles", type=int, default=40, help="nblock: shocks averaged")
    ap.add_argument("--seed", type=int, default=1, help="nblock: the seed of the first set (the k-th set's is seed + k)")
    ap.add_argument("--levels", type=int, default=1, help="cohort: finer levels (dt, h halved) after the test's")
    args = ap.parse_args()
    names = args.sets.split(",")
    for name in names:
        if name not in SETS:
            raise SystemExit(f"unknown set {name!r}; one of {', '.join(SETS)}")
    if args.solver == "nblock":
        warm_up(nb.stick_slip_extrema_nblock, micro.Model(k0=0.1), 0.3, 1000, n_cycles=2, n_discard=1)
        for N in [int(float(x)) for x in args.N.split(",")]:
            for name in names:
                row = run_nblock(name, N, args.cycles, args.seed + list(SETS).index(name))
                print(row, flush=True)
                write_csv(pd.DataFrame([row]), NBLOCK_CSV, keys=["set", "N", "seed"])
    else:
        warm_up(micro.stationary, micro.Model(k0=0.05), 0.77, method=micro.Cohort(dt=0.04))
        for name in names:
            rows = run_cohort(name, args.levels)
            write_csv(pd.DataFrame(rows), COHORT_CSV, keys=["set", "what", "dt", "h", "tol"])


if __name__ == "__main__":
    main()
