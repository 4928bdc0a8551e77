"""Which of the cohort method's two resolutions, the time step ``dt`` or the delta_R cell
``h``, fails to converge close to V^c (issue 52: at d = 0.01 the finer levels, dt and h
halved together, moved without order)?

At k0 = ``--k0`` and each d = (V^c - V) / V^c of ``--d`` (exact V^c), the cycle
``micro.cohort.cycle_cohorts(model, V, dt=dt, h=kappa zbar / h_div, tol=--tol)`` on a
small table of (dt, h_div), ``--runs``, in that order.  A run ``dt:h_div`` is cold
(micro's own path: its coarse run at 2 dt, 2 h first), a process of its own stopped after
``--max-seconds`` of wall time (then a row with status ``timeout``, no numbers); a run
``dt:h_div@k`` continues the result of the k-th run of the list (``start`` in the CSV:
the path of ``studies/micro_transition_error_check.py``, whose finer levels each continue
the one before), and then the whole list is one chain in one process, stopped after
``--max-seconds`` in all.  Each row keeps the extrema, the period, the fixed point's
error and how it was certified (``path``: plain cycles, Anderson, Newton-Krylov, or not
certified), the shocks' unjumped fraction (Anderson's acceleration needs it below
``ANDERSON_UNJUMPED`` of ``micro.cohort.options``), the loading phase's step (``phase_step``: close to
V^c it is ``dt T / SHORT_PHASE`` for the T at which it was last set, kept while within a
quarter of that; ``nominal_step`` is the one for the cycle's own T) and its number of
steps in the last cycle (``n_steps``, the integer count: a candidate cause of a
sawtooth), and the run's wall time (one thread; the machine was shared, load 3-4).
``--summary`` prints, from the CSV alone, the changes along dt at fixed h and along h at
fixed dt, with the observed order where three levels exist.

Writes benchmarks/results/micro_near_vc_resolution.csv (rows merge by k0, d, dt, h_div,
tol, start; runs already there are skipped unless ``--redo``).  Recorded in
docs/validation/micro_transition.md, "Which resolution fails near V^c".

    NUMBA_NUM_THREADS=1 python -m studies micro_near_vc_resolution --k0 0.01 --d 0.01 --tol 1e-5 \
        --runs 0.01:20,0.005:20,0.01:40                       # cold: 422 s, then two timeouts at 480 s
    NUMBA_NUM_THREADS=1 python -m studies micro_near_vc_resolution --k0 0.01 --d 0.01 --tol 1e-5 \
        --max-seconds 2700 --runs 0.02:20,0.01:40@0,0.005:40@1,0.01:80@1   # one chain: 27 min
    python -m studies micro_near_vc_resolution --summary
"""
from __future__ import annotations

import argparse
import math
import multiprocessing as mp
import queue as queue_module
import time

import numpy as np
import pandas as pd

import micro
from micro.cohort import cycle_cohorts, options as cohort_options

from benchmarks._harness import RESULTS, write_csv

CSV = RESULTS / "micro_near_vc_resolution.csv"
KEYS = ["k0", "d", "dt", "h_div", "tol", "start"]
#: (dt, kappa zbar / h) in the order run: the default, the two axes and the diagonal, then
#: the quarter steps.
RUNS = "0.01:20,0.005:20,0.01:40,0.005:40,0.0025:20,0.01:80,0.0025:40,0.005:80,0.0025:80"
QUANTITIES = ("sigma_max", "sigma_min", "amplitude", "period")


def path_of(res) -> str:
    """How the fixed point was certified, from the result's message."""
    m = res.message
    if not res.converged:
        return "not converged"
    if not math.isfinite(res.error):
        return "not certified"
    if "by Newton-Krylov on the cycle map" in m:
        return "Newton-Krylov"
    if "after Anderson's" in m:
        return "Anderson"
    return "plain (Aitken)" if "(Aitken)" in m else "plain"


def _row(k0, d, V, vc, dt, h_div, h, tol, start, res, wall) -> dict:
    """A run's row."""
    state = getattr(res, "state", None)
    step = float(getattr(state, "dt", math.nan)) if state is not None else math.nan
    trace = getattr(res, "trace", None)
    lengths = np.diff(trace[0])[:-1] if trace is not None else np.array([])  # (the loading phase's steps, shock left out)
    return dict(
        k0=k0, d=d, V=V, Vc=vc, dt=dt, h_div=h_div, h=h, tol=tol, start=start, status="done", sigma_max=res.sigma_max,
        sigma_min=res.sigma_min, amplitude=res.sigma_max - res.sigma_min, sigma_before=res.sigma_before,
        sigma_after=res.sigma_after, period=res.period, error=res.error, converged=bool(res.converged),
        certified=bool(res.converged and math.isfinite(res.error)), path=path_of(res), iterations=res.iterations,
        accelerated=bool(res.accelerated), unjumped=res.unjumped, phase_step=step,
        nominal_step=dt * min(1.0, res.period / cohort_options.DEFAULT.SHORT_PHASE), n_steps=int(lengths.size),
        last_step_fraction=float(lengths[-1] / lengths[:-1].max()) if lengths.size > 1 else math.nan,
        coarse_period=res.coarse.period if res.coarse is not None else math.nan,
        drift_20=drift(res.history), wall_s=round(wall, 1), message=res.message[:240])


def drift(history: np.ndarray, cycles: int = 20) -> float:
    """The amplitude's change over the last ``cycles`` cycles of a run's history (since its
    last restart; nan if shorter): how far a sequence still moves where it stops."""
    if history is None or len(history) <= cycles:
        return math.nan
    a = history[:, 0] - history[:, 1]
    return float(a[-1] - a[-1 - cycles])


def _solve(k0: float, d: float, chain: list, tol: float, queue) -> None:
    """The runs of ``chain`` (in a child process), each ``(dt, h_div, start)``: ``start``
    None (cold: micro's own path, its coarse run included) or the index in ``chain`` of the
    run whose result it continues; each row on ``queue`` as it is done."""
    cycle_cohorts(micro.Model(k0=0.05), 0.77, dt=0.04, tol=1e-3)  # (numba's cache, kept out of the wall time)
    model = micro.Model(k0=k0)
    vc = float(micro.critical_velocity(model).Vc)
    V = (1.0 - d) * vc
    results = []
    for dt, h_div, start in chain:
        h = model.kappa * model.zbar / h_div
        begin = time.perf_counter()
        res = cycle_cohorts(model, V, dt=dt, h=h, tol=tol, start=None if start is None else results[start])
        label = "cold" if start is None else f"{chain[start][0]:g}:{chain[start][1]:g}"
        queue.put(_row(k0, d, V, vc, dt, h_div, h, tol, label, res, time.perf_counter() - begin))
        results.append(res)


def run(k0: float, d: float, chain: list, tol: float, max_seconds: float):
    """The runs of ``chain`` in a child process, stopped after ``max_seconds`` in all (the
    run under way then gets a row with status ``timeout``)."""
    ctx = mp.get_context("spawn")  # (numba's OpenMP layer refuses fork)
    queue = ctx.Queue()
    child = ctx.Process(target=_solve, args=(k0, d, chain, tol, queue), daemon=True)
    begin = time.perf_counter()
    child.start()
    rows, since = [], begin
    while len(rows) < len(chain) and time.perf_counter() - begin < max_seconds:
        try:
            rows.append(queue.get(timeout=1.0))
            since = time.perf_counter()
            yield rows[-1]
        except queue_module.Empty:
            if not child.is_alive() and queue.empty():
                break  # (it failed: its traceback is on stderr)
    late = len(rows) < len(chain) and child.is_alive()
    child.join(timeout=5.0)
    if child.is_alive():
        child.terminate()
        child.join()
    if len(rows) < len(chain):
        dt, h_div, start = chain[len(rows)]
        label = "cold" if start is None else f"{chain[start][0]:g}:{chain[start][1]:g}"
        yield dict(k0=k0, d=d, dt=dt, h_div=h_div, tol=tol, start=label,
                   status=f"timeout after {max_seconds:g} s" if late else f"failed (exit {child.exitcode})",
                   wall_s=round(time.perf_counter() - since, 1))


def _order(q: np.ndarray) -> float:
    """The observed order of three levels halved in turn (nan unless both changes have one sign)."""
    d1, d2 = q[0] - q[1], q[1] - q[2]
    return math.log2(d1 / d2) if d1 * d2 > 0 else math.nan


def summary(frame: pd.DataFrame) -> str:
    """Along dt at fixed h_div and along h_div at fixed dt: each quantity's change from one
    level to the next (and over the amplitude), the two runs' fixed-point errors summed,
    and the order where three levels exist."""
    lines = []
    f = frame[(frame.status == "done")]
    for (k0, d, tol), g in f.groupby(["k0", "d", "tol"]):
        lines.append(f"k0 = {k0:g}, d = {d:g}, tol = {tol:g}")
        for axis, fixed in (("dt", "h_div"), ("h_div", "dt")):
            for value, s in g.groupby(fixed):
                s = s.sort_values(axis, ascending=(axis == "h_div"))
                if len(s) < 2:
                    continue
                s = s.reset_index(drop=True)
                for i in range(1, len(s)):
                    a, b = s.iloc[i - 1], s.iloc[i]
                    ch = {q: b[q] - a[q] for q in QUANTITIES}
                    lines.append(f"  along {axis:5s} at {fixed} = {value:g}: {a[axis]:g} -> {b[axis]:g} "
                                 f"(start {a.start} -> {b.start}): "
                                 + ", ".join(f"d{q} {ch[q]:+.2e}" for q in QUANTITIES)
                                 + f" (d amp / amp {ch['amplitude'] / b['amplitude']:+.1%}); errors {a.error:.1e} + "
                                 f"{b.error:.1e}; steps {a.n_steps} -> {b.n_steps}, step / nominal "
                                 f"{a.phase_step / a.nominal_step:.3f} -> {b.phase_step / b.nominal_step:.3f}; "
                                 f"{a.path} -> {b.path}")
                if len(s) >= 3:
                    orders = {q: _order(s[q].to_numpy()[-3:]) for q in ("sigma_max", "sigma_min", "amplitude")}
                    lines.append("    order (last three): " + ", ".join(f"{q} {p:.2f}" for q, p in orders.items()))
    return "\n".join(lines)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--k0", type=float, default=0.01)
    ap.add_argument("--d", default="0.02,0.01")
    ap.add_argument("--runs", default=RUNS, help="dt:h_div pairs, comma separated, in the order run; dt:h_div@k "
                    "continues the k-th (from 0) of the list (then the list is one chain in one process)")
    ap.add_argument("--tol", type=float, default=1e-6, help="the fixed points' tolerance")
    ap.add_argument("--max-seconds", type=float, default=480.0, help="the wall-time limit of a run, or of a chain of continued runs")
    ap.add_argument("--redo", action="store_true", help="run again the runs already in the CSV")
    ap.add_argument("--summary", action="store_true", help="only print the changes and orders from the CSV")
    args = ap.parse_args()
    if args.summary:
        print(summary(pd.read_csv(CSV)))
        return
    runs = []
    for item in args.runs.split(","):
        pair, _, start = item.partition("@")
        dt, h_div = (float(x) for x in pair.split(":"))
        runs.append((dt, h_div, int(start) if start else None))
    # (cold runs each in a process of their own; a list with continued runs is one chain)
    chains = [runs] if any(r[2] is not None for r in runs) else [[r] for r in runs]
    for d in [float(v) for v in args.d.split(",")]:
        for chain in chains:
            done = pd.read_csv(CSV) if CSV.exists() else pd.DataFrame(columns=KEYS)
            labels = ["cold" if s is None else f"{chain[s][0]:g}:{chain[s][1]:g}" for _, _, s in chain]
            have = [bool(np.any(np.isclose(done.k0, args.k0) & np.isclose(done.d, d) & np.isclose(done.dt, dt)
                                & np.isclose(done.h_div, h_div) & np.isclose(done.tol, args.tol)
                                & (done.start.astype(str) == label)))
                    for (dt, h_div, _), label in zip(chain, labels)]
            if all(have) and not args.redo:
                print(f"k0 = {args.k0:g}, d = {d:g}, {args.runs}: in the CSV, skipped", flush=True)
                continue
            for row in run(args.k0, d, chain, args.tol, args.max_seconds):
                print({k: row.get(k) for k in ("k0", "d", "dt", "h_div", "start", "status", "sigma_max", "sigma_min",
                                               "period", "error", "path", "iterations", "n_steps", "phase_step",
                                               "wall_s")}, flush=True)
                write_csv(pd.DataFrame([row]), CSV, keys=KEYS)


if __name__ == "__main__":
    main()
