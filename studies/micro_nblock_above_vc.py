"""Does a stick-slip cycle coexist with stable steady sliding just above V^c?  An N-block probe.

The reset model's branch of total-shock cycles runs past V^c, to about V^c (1 + k0 / 2 k2)
(docs/reference/micro_transition.md section 4), so the onset could be hysteretic.  The
cohort method has not reached V^c (docs/validation/micro_transition.md section 5).  This
probe asks the N-block, which shares no code with either: at k0 = ``--k0`` (the model's
other parameters at their defaults, V^c exact from the renewal chain), N = ``--N`` blocks,

* **switched**: ``--periods-before`` cycles at ``--below`` V^c (stick-slip), then
  ``--periods-after`` cycle periods at ``--above`` V^c, in one run (the state carried
  across the switch);
* **direct**: the same time at ``--above`` V^c from the relaxed start.

A global shock is an avalanche of at least ``--shock-fraction`` N jumps.  If a cycle
coexists above V^c, the switched run keeps shocks of about the size it had below V^c;
if not, its drops fall to what the direct run shows (the finite-N fluctuations of
steady sliding, which at this N also make avalanches above the threshold).  Each row gives
the drops (sigma before minus after a shock) at the switch and over the last fifth of the
run, the number of shocks after the switch, and the stress range over the last tenth.

Writes benchmarks/results/micro_nblock_above_vc.csv (rows merge by k0, N, below, above,
seed, run).

    NUMBA_NUM_THREADS=1 python -m studies micro_nblock_above_vc --k0 0.1 --N 100000 --above 1.02   # about 2 min
"""
from __future__ import annotations

import argparse

import numpy as np

import micro
from benchmarks._harness import RESULTS, Stopwatch, warm_up, write_csv
from micro.nblock import simulate_nblock

CSV = RESULTS / "micro_nblock_above_vc.csv"


def _row(run, kind, t_switch, duration, period, args, Vc, cpu):
    sh = run.shocks
    late = sh[sh.t > t_switch]
    drops = (late.sigma_before - late.sigma_after).to_numpy()
    tail = late[late.t > t_switch + 0.8 * duration]
    ts = run.timeseries
    last = ts[ts.t > t_switch + 0.9 * duration]
    return dict(k0=args.k0, N=args.N, seed=args.seed, below=args.below, above=args.above, run=kind, Vc=Vc,
                period_below=period, duration=duration, shocks_after=len(late),
                first_drop=float(drops[0]) if len(drops) else np.nan,
                tail_drop_mean=float((tail.sigma_before - tail.sigma_after).mean()) if len(tail) else np.nan,
                tail_drop_max=float((tail.sigma_before - tail.sigma_after).max()) if len(tail) else np.nan,
                last_range=float(last.sigma_max.max() - last.sigma_min.min()),
                last_mean=float(last.sigma_mean.mean()), cpu_s=cpu)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--k0", type=float, default=0.1)
    ap.add_argument("--N", type=int, default=100_000)
    ap.add_argument("--below", type=float, default=0.95, help="V / V^c before the switch")
    ap.add_argument("--above", type=float, default=1.02, help="V / V^c after it")
    ap.add_argument("--periods-before", type=float, default=80.0)
    ap.add_argument("--periods-after", type=float, default=400.0)
    ap.add_argument("--shock-fraction", type=float, default=0.15)
    ap.add_argument("--seed", type=int, default=0)
    args = ap.parse_args()
    model = micro.Model(k0=args.k0)
    Vc = micro.critical_velocity(model).Vc
    warm_up(simulate_nblock, model, Vc, 1000, t_max=1.0)
    pre = simulate_nblock(model, args.below * Vc, args.N, t_max=60.0, seed=args.seed,
                          shock_fraction=args.shock_fraction)
    period = float(np.diff(pre.shocks.t.to_numpy()).mean())
    t1, t2 = args.periods_before * period, args.periods_after * period
    rows = []
    with Stopwatch(cpu=True) as sw:
        switched = simulate_nblock(model, [(t1, args.below * Vc), (t2, args.above * Vc)], args.N, seed=args.seed,
                                   shock_fraction=args.shock_fraction, record_every=period / 5)
    rows.append(_row(switched, "switched", t1, t2, period, args, Vc, sw.seconds))
    with Stopwatch(cpu=True) as sw:
        direct = simulate_nblock(model, args.above * Vc, args.N, t_max=t2, seed=args.seed,
                                 shock_fraction=args.shock_fraction, record_every=period / 5)
    rows.append(_row(direct, "direct", 0.0, t2, period, args, Vc, sw.seconds))
    for r in rows:
        print(f"k0 = {r['k0']:g}, N = {r['N']}, {r['run']} at {r['above']:g} V^c: {r['shocks_after']} shocks in "
              f"{args.periods_after:g} periods of {period:.4g}; first drop {r['first_drop']:.5f}, last fifth's "
              f"mean {r['tail_drop_mean']:.5f} (largest {r['tail_drop_max']:.5f}); last tenth's range "
              f"{r['last_range']:.5f}; {r['cpu_s']:.0f} s of CPU", flush=True)
    write_csv(rows, CSV, keys=["k0", "N", "below", "above", "seed", "run"])


if __name__ == "__main__":
    main()
