"""How far is the cohort stepper's own V^c from the exact one (issue 52, item 1)?

Just above V^c steady sliding is stable, so the cohort map's time stepping, started from
the state after a total shock (``micro.study_hooks.start_state``) and run with uniform
steps ``--steps`` and cells ``kappa zbar / --h-div`` at V = ``--fraction`` V^c, settles on
its own steady state.  Its branching ratio b_h, the slope of the avalanche closure at zero
slip with the drive frozen (``1 + dH/dX`` at dX -> 0, dt = 0), is compared with the
renewal chain's b (``micro.steady_sliding``, which shares no code with the cohorts), and so
is its stress.  Close to V^c, b - 1 is proportional to d, with the slope ``db/dd`` measured
here on the renewal chain (central differences, d = -fraction + 1 +- 1e-3); so the
stepper's own V^c lies ``(b_h - b) / (db/dd)`` from the exact one in d (positive: the
stepped model is less stable than the exact one).  A cycle at distance d from V^c is then
computed at an effective distance off by that much; the resolution near V^c has to keep it
well below d.

``--trial`` F: after the run, one trial step F times as long from the settled state: does
the closure's root search (``CohortState.root``) declare a fold (the start of a shock)?
If so, ``trial_ratio`` is H at the point where it found H rising over H at zero slip: a
fold where the closure's minimum touches zero has a ratio near 0, a wiggle of H far to the
left of its only root a ratio of order 1 (the shock criterion then fires in steady
sliding).

``--cycle-d`` D: the same question inside the cycle map.  At d = D below V^c the cold
cycles (``micro.study_hooks.one_cycle`` from the state after a total shock, steps
``hooks.phase_step`` of each cycle's period at ``--cycle-dt``, as a run takes them) for
``--cycles`` cycles, observing every fold the root search declares: at the start of each
shock (the shortest step at which the bisection of the shock's step still found a fold)
the ratio H / H(0) where the fold was found, by cycle.  Rows in
benchmarks/results/micro_cohort_fold_flips.csv (k0, d, dt, h_div, cycle, ratio, x,
step; merged by k0, d, dt, h_div).

Each row: k0, fraction, step, h_div, t (the time at which it was read, every ``--every``),
sigma_error, b, b_h, b_error, dbdd, vc_shift_d, shocks (folds met on the way, each
stepped through as a shock), trial, trial_fold, trial_ratio, wall_s.  Writes
benchmarks/results/micro_cohort_steady_near_vc.csv (rows merge by k0, fraction, step,
h_div, t).  Recorded in docs/validation/micro_transition.md, "Which resolution fails near
V^c".

    NUMBA_NUM_THREADS=1 python -m studies micro_cohort_steady_near_vc --k0 0.01 --fraction 1.1 \\
        --steps 0.002,0.001 --h-div 20 --duration 16 --every 2 --trial 1.5
    NUMBA_NUM_THREADS=1 python -m studies micro_cohort_steady_near_vc --k0 0.01 --cycle-d 0.02 \\
        --cycle-dt 0.02 --h-div 20 --cycles 40
"""
from __future__ import annotations

import argparse
import math
import time

import micro
from micro import study_hooks as hooks

from benchmarks._harness import RESULTS, write_csv

CSV = RESULTS / "micro_cohort_steady_near_vc.csv"
KEYS = ["k0", "fraction", "step", "h_div", "t"]
FLIPS_CSV = RESULTS / "micro_cohort_fold_flips.csv"
FLIPS_KEYS = ["k0", "d", "dt", "h_div"]


def _step(st, length: float) -> int:
    """One step of ``length``; a fold met in it is stepped through as the cycle map does
    (the step bisected to where the fold appears, then the shock).  Returns 1 for a fold."""
    phi, Edt = st.prepare(length)
    x, status = st.root()
    if status == 0:
        st.commit(x, length, phi, Edt)
        return 0
    if status == 2:
        raise RuntimeError(f"the closure did not converge at t = {st.t:.4g}")
    lo, x_lo = hooks.fold_start(st, length)
    if lo > 0.0:
        phi, Edt = st.prepare(lo)
        x, _ = st.root(below=x_lo)
        st.commit(x, lo, phi, Edt)
    st.shock()
    return 1


def branching(st) -> float:
    """The state's instantaneous branching ratio: 1 + dH/dX at dX -> 0 with dt = 0."""
    snap = st.copy()
    snap.prepare(0.0)
    return 1.0 + snap.closure(1e-9 * st.model.zbar)[1]


def trial_step(st, factor: float, step: float) -> tuple[bool, float]:
    """A trial step ``factor * step`` from a copy: (a fold declared, H where found / H(0))."""
    snap = st.copy()
    snap.prepare(factor * step)
    x, status = snap.root()
    if status != 1:
        return False, math.nan
    return True, snap.closure(x)[0] / snap.closure(0.0)[0]


def run(k0: float, fraction: float, step: float, h_div: float, duration: float, every: float,
        trial: float) -> list[dict]:
    """The rows of one (k0, fraction, step, h_div)."""
    model = micro.Model(k0=k0)
    vc = micro.critical_velocity(model).Vc
    V = fraction * vc
    exact = micro.steady_sliding(model, [V, vc * (fraction - 1e-3), vc * (fraction + 1e-3)])
    sigma, b = float(exact.sigma[0]), float(exact.branching_ratio[0])
    # d = 1 - V / V^c: the first V of the pair is at d + 1e-3
    dbdd = float(exact.branching_ratio[1] - exact.branching_ratio[2]) / 2e-3
    st = hooks.start_state(model, V, model.kappa * model.zbar / h_div)
    begin, rows, shocks = time.perf_counter(), [], 0
    per_read = int(round(every / step))
    for i in range(int(round(duration / step))):
        shocks += _step(st, step)
        if i % 50 == 49:
            st.compact()
        if (i + 1) % per_read == 0:
            b_h = branching(st)
            rows.append(dict(k0=k0, fraction=fraction, step=step, h_div=h_div, t=round(st.t, 9),
                             sigma_error=st.sigma - sigma, b=b, b_h=b_h, b_error=b_h - b, dbdd=dbdd,
                             vc_shift_d=(b_h - b) / dbdd, shocks=shocks, trial=math.nan, trial_fold=False,
                             trial_ratio=math.nan, wall_s=time.perf_counter() - begin))
            print(f"k0 {k0:g}, V = {fraction:g} V^c, step {step:g}, h = kappa zbar / {h_div:g}, t = {st.t:.1f}: "
                  f"sigma error {st.sigma - sigma:+.3e}, b_h - b {b_h - b:+.3e}, V^c shift in d "
                  f"{(b_h - b) / dbdd:+.2e}, folds {shocks}", flush=True)
    if trial > 0.0 and rows:
        fold, ratio = trial_step(st, trial, step)
        rows[-1].update(trial=trial, trial_fold=fold, trial_ratio=ratio)
        print(f"  trial step {trial:g} x {step:g}: fold declared {fold}, H there / H(0) = {ratio:.3g}", flush=True)
    return rows


class _Observed(hooks.CohortState):
    """The cohort state, recording every fold its root search declares in a loading step:
    (time of the step's start, step length, slip where found, H there / H(0))."""

    folds: list

    def root(self, below: float = 0.0):
        x, status = super().root(below)
        if status == 1 and self.pending > 0.0:
            self.folds.append((self.t, self.pending, x, self.closure(x)[0] / self.closure(0.0)[0]))
        return x, status


def fold_flips(k0: float, d: float, dt: float, h_div: float, cycles: int) -> list[dict]:
    """The folds at each shock's start over ``cycles`` cold cycles at ``d`` (module docstring)."""
    model = micro.Model(k0=k0)
    V = (1.0 - d) * micro.critical_velocity(model).Vc
    st = hooks.start_state(model, V, model.kappa * model.zbar / h_div)
    st.__class__ = _Observed  # (copies made inside a cycle are plain states: not observed)
    step, rows = dt, []
    for cycle in range(cycles):
        st.folds = []
        out = hooks.one_cycle(st, step)
        if not out["ok"]:
            raise RuntimeError(out["message"])
        if st.folds:
            # the bisection's last fold: the shortest step still found to fold, at this shock's start
            t0 = max(f[0] for f in st.folds)
            _, length, x, ratio = min((f for f in st.folds if f[0] == t0), key=lambda f: f[1])
            rows.append(dict(k0=k0, d=d, dt=dt, h_div=h_div, cycle=cycle, ratio=ratio, x=x, step=length))
        if hooks.step_off(out["period"], step, dt):
            step = hooks.phase_step(out["period"], dt)
    spurious = [r["cycle"] for r in rows if r["ratio"] > 1e-2]
    print(f"k0 {k0:g}, d = {d:g}, dt {dt:g}, h = kappa zbar / {h_div:g}: {len(rows)} shock starts in {cycles} cold "
          f"cycles; H / H(0) where the fold was found: median {sorted(r['ratio'] for r in rows)[len(rows) // 2]:.2g}; "
          f"above 1e-2 (a wiggle, not a fold) at cycles {spurious}", flush=True)
    return rows


def main(argv: list[str] | None = None) -> int:
    p = argparse.ArgumentParser(prog="python -m studies micro_cohort_steady_near_vc",
                                description=__doc__.split("\n\n")[0])
    p.add_argument("--k0", type=float, default=0.01)
    p.add_argument("--fraction", type=float, default=1.1, help="V / V^c, above 1 (default 1.1)")
    p.add_argument("--steps", default="0.002,0.001", help="uniform time steps, comma-separated")
    p.add_argument("--h-div", default="20", help="cells kappa zbar / H, comma-separated")
    p.add_argument("--duration", type=float, default=16.0)
    p.add_argument("--every", type=float, default=2.0)
    p.add_argument("--trial", type=float, default=1.5,
                   help="a trial step this many times the step at the end (0: none)")
    p.add_argument("--cycle-d", type=float, default=None,
                   help="instead: the folds at the shocks' starts of cold cycles at this d")
    p.add_argument("--cycle-dt", type=float, default=0.02)
    p.add_argument("--cycles", type=int, default=30)
    a = p.parse_args(argv)
    if a.cycle_d is not None:
        if not 0.0 < a.cycle_d < 1.0:
            p.error(f"--cycle-d must be in (0, 1), got {a.cycle_d:g}")
        for h_div in (float(h) for h in a.h_div.split(",")):
            write_csv(fold_flips(a.k0, a.cycle_d, a.cycle_dt, h_div, a.cycles), FLIPS_CSV, keys=FLIPS_KEYS)
        print(f"wrote {FLIPS_CSV}")
        return 0
    if not a.fraction > 1.0:
        p.error(f"--fraction must be above 1 (steady sliding stable), got {a.fraction:g}")
    if not 0.0 < a.every <= a.duration:
        p.error("--every must be in (0, --duration]")
    for step in (float(s) for s in a.steps.split(",")):
        for h_div in (float(h) for h in a.h_div.split(",")):
            rows = run(a.k0, a.fraction, step, h_div, a.duration, a.every, a.trial)
            write_csv(rows, CSV, keys=KEYS)
    print(f"wrote {CSV}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
