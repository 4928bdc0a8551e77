"""The cohort method's error rules replayed on long plain-cycle sequences: at every cycle,
what the run would have claimed, against the distance to the sequence's own limit.

For each point (k0 and V / V^c, Fig. 4 parameters) the fine map is started as
``micro.cohort.cycle_cohorts`` starts it cold (the coarse transient at twice ``--dt`` and
h, to tol = max(4 ``--tol``, 3e-4); its state, each cell split in two, at the coarse
cycle's step), and ``--cycles`` plain cycles of it are recorded: the judged stresses, the
state's move (the L1 change of the surviving blocks' delta_R marginal) and the number of
steps of each loading phase.  The limit is the last cycle plus its last step times
r / (1 - r), r the state's contraction over the last ten cycles (that tail is printed: it
is the limit's own uncertainty).  Then, for every prefix of the sequence, the error the
run would claim is computed twice, by the rules on each stress's own steps alone
(``micro.study_hooks.error_estimate``, the rule before) and with the bound of the state's move
(``micro.study_hooks.state_tail``, the rule now); where each rule would stop (two cycles in
a row within ``--tol``) and every cycle where a claim is below the true distance are
printed.

Writes benchmarks/results/micro_cohort_state_tail_check.csv (one row per cycle and
point; rows merge by k0, V / V^c, dt, cycle).

    NUMBA_NUM_THREADS=1 python -m studies micro_cohort_state_tail_check --k0 0.3 --fractions 0.98 --cycles 160
    NUMBA_NUM_THREADS=1 python -m studies micro_cohort_state_tail_check --k0 0.3 --fractions 0.99 --cycles 160
                                          # 7 and 17 minutes (2.6 and 6.5 s a cycle, one core, load 2-3)
    python -m studies micro_cohort_state_tail_check --replay        # the rules on the CSV's sequences

The rules and the cycle map are not public API; the study reaches them through the hooks
for studies (``micro.study_hooks``): ``error_estimate``, ``state_tail``,
``relaxation_multiplier``, ``continued``, ``phase_step``, ``step_off``, ``one_cycle``.
"""
from __future__ import annotations

import argparse

import numpy as np
import pandas as pd

import micro
from micro import cohort as C
from micro.cohort import options as cohort_options
from micro.cohort.estimate import COLUMNS, JUDGED, WINDOW
from micro import study_hooks as H

from benchmarks._harness import RESULTS, Stopwatch, warm_up, write_csv

OUT = RESULTS / "micro_cohort_state_tail_check.csv"


def record(k0: float, frac: float, dt: float, tol: float, cycles: int) -> pd.DataFrame:
    """``cycles`` plain cycles of the fine map from a cold run's start (module docstring)."""
    model = micro.Model(k0=k0)
    V = frac * micro.critical_velocity(model).Vc
    h = 5.0 * model.kappa * model.zbar * dt
    opt = cohort_options.DEFAULT
    coarse = C.cycle_cohorts(model, V, dt=2 * dt, h=2 * h, tol=max(opt.COARSE_TOL * tol, opt.COARSE_FLOOR),
                             max_iter=300, start=H.NO_COARSE)
    st = H.continued(coarse, model, V, h)
    step = H.phase_step(coarse.period, dt)
    previous, rows, sw = st.node_masses(), [], Stopwatch()
    while len(rows) < cycles:
        out = H.one_cycle(st, step)
        if H.step_off(out["period"], step, dt):  # (a new step: the sequence starts again, as in a run)
            step, rows = H.phase_step(out["period"], dt), []
            previous = out["marginal"]
            continue
        rows.append(dict(k0=k0, V_over_Vc=frac, dt=dt, h=h, cycle=len(rows), period=out["period"],
                         steps=len(out["steps"]), move=float(np.abs(out["marginal"] - previous).sum()),
                         unjumped=out["unjumped"], **{c: out[c] for c in COLUMNS if c != "period"}))
        previous = out["marginal"]
        if len(rows) % 20 == 0:
            print(f"  k0 = {k0:g}, {frac:g} V^c: cycle {len(rows)}, sigma_max {out['sigma_max']:.9f}, "
                  f"move {rows[-1]['move']:.2e}, {sw.seconds:.0f} s", flush=True)
    return pd.DataFrame(rows)


def replay(seq: pd.DataFrame, tol: float) -> None:
    """The two rules at every prefix of one point's sequence, against its limit."""
    seq = seq.sort_values("cycle")
    k0, frac = float(seq.k0.iloc[0]), float(seq.V_over_Vc.iloc[0])
    model = micro.Model(k0=k0)
    a = seq[list(COLUMNS)].to_numpy()
    moves = seq.move.to_numpy().copy()
    moves[0] = np.nan
    steps = seq.steps.to_numpy()
    kinks = np.flatnonzero(steps[1:] != steps[:-1]) + 1  # (printed only: _state_tail finds them itself)
    r = (moves[-1] / moves[-11]) ** 0.1
    last = a[-1] - a[-2]
    limit = a[-1] + last * r / (1.0 - r)
    judged = list(JUDGED)
    print(f"k0 = {k0:g}, {frac:g} V^c, dt = {seq.dt.iloc[0]:g}: {len(a)} cycles, state contraction {r:.4f}, "
          f"limit sigma_max {limit[0]:.8f} sigma_min {limit[1]:.8f} (its tail {np.abs(last * r / (1 - r))[judged].max():.1e}); "
          f"kinks at cycles {kinks.tolist()}")
    passed, stopped = {"before": 0, "now": 0}, set()
    for n in range(WINDOW, len(a) + 1):
        slowest = H.relaxation_multiplier(model, a[n - 1, 2])
        errors, how, best, _ = H.error_estimate(a[:n], tol, slowest)
        tail, m = H.state_tail(a[:n], moves[:n], steps[:n], slowest)
        true = float(np.abs(best - limit)[judged].max())
        for rule, claim in (("before", float(errors[judged].max())), ("now", max(float(errors[judged].max()), tail))):
            passed[rule] = passed[rule] + 1 if claim <= tol else 0
            if passed[rule] == 2 and rule not in stopped:
                stopped.add(rule)
                print(f"  {rule}: stops at cycle {n}, claims {claim:.2e}, true {true:.2e} ({how[0]}, {how[1]})")
            if claim < true and rule == "now":
                print(f"  now: cycle {n} claims {claim:.2e} < true {true:.2e} (the limit's own tail "
                      f"{np.abs(last * r / (1 - r))[judged].max():.1e})")


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--k0", type=float, default=0.3)
    ap.add_argument("--fractions", default="0.98,0.99", help="V / V^c, comma separated")
    ap.add_argument("--dt", type=float, default=0.01)
    ap.add_argument("--tol", type=float, default=2e-5)
    ap.add_argument("--cycles", type=int, default=160)
    ap.add_argument("--replay", action="store_true", help="only replay the rules on the CSV's sequences")
    ap.add_argument("--out", default=str(OUT))
    args = ap.parse_args()
    if not args.replay:
        warm_up(C.cycle_cohorts, micro.Model(k0=0.1), 0.3, tol=1e-3, max_iter=6)
        for frac in (float(f) for f in args.fractions.split(",")):
            write_csv(record(args.k0, frac, args.dt, args.tol, args.cycles), args.out,
                      keys=["k0", "V_over_Vc", "dt", "cycle"])
    table = pd.read_csv(args.out)
    for _, seq in table.groupby(["k0", "V_over_Vc", "dt"]):
        replay(seq, args.tol)


if __name__ == "__main__":
    main()
