"""The cohort method's fixed point checked by plain cycles: a point is run as the default
path runs it (``micro.cohort.cycle_cohorts`` from rest, at ``--tol``), then ``--cycles``
plain cycles of the same map (the run's own step, ``state.dt``) continue from its state.
Where those cycles settle, they give the map's fixed point by the plainest iteration
there is, with no extrapolation and no error rule: what the run reported is checked
against it (its claimed error against its true distance).

Prints the run's result and every 50th cycle (sigma_max, sigma_min, amplitude, period,
the fraction the shock left unjumped, seconds); writes one row per point to
``benchmarks/results/micro_cohort_plain_check.csv`` (rows merge by k0, V / V^c, dt):
the run's values and error, and the mean of the last ``--tail`` cycles with their
largest distance from it and the drift over them.

    python -m studies micro_cohort_plain_check --k0 0.1 --fractions 0.95,0.98,0.99 --dt 0.02 --cycles 400
    python -m studies micro_cohort_plain_check --k0 0.01 --fractions 0.99 --dt 0.02 --cycles 1500

Recorded in docs/validation/micro_transition.md section 1 ("The k0 = 0.1 rows
recomputed").  Inside the method: the run's ``state`` and the hook for studies
``micro.study_hooks.one_cycle``.
"""
from __future__ import annotations

import argparse

import numpy as np

import micro
import micro.cohort as C
from micro import study_hooks as H  # the cycle map on the run's state

from benchmarks._harness import RESULTS, Stopwatch, write_csv


def check(k0: float, frac: float, dt: float, tol: float, cycles: int, tail: int) -> dict:
    model = micro.Model(k0=k0)
    Vc = micro.critical_velocity(model).Vc
    h = 5.0 * model.kappa * model.zbar * dt
    with Stopwatch() as sw:
        r = C.cycle_cohorts(model, frac * Vc, dt=dt, h=h, tol=tol, max_iter=200)
    print(f"k0 {k0:g}, V/Vc {frac:g}, dt {dt:g}: run {sw.seconds:.1f} s, sigma_max {r.sigma_max:.9f}, "
          f"sigma_min {r.sigma_min:.9f}, amplitude {r.sigma_max - r.sigma_min:.9f}, error {r.error:.3g}, "
          f"{r.iterations} cycles: {r.message}", flush=True)
    row = dict(k0=k0, V_over_Vc=frac, dt=dt, h=h, tol=tol, run_sigma_max=r.sigma_max, run_sigma_min=r.sigma_min,
               run_amplitude=r.sigma_max - r.sigma_min, run_error=r.error, run_cycles=r.iterations,
               run_converged=r.converged, run_s=sw.seconds)
    if r.state is None:
        return row
    st = r.state.copy()
    seq = []
    with Stopwatch() as sw:
        for i in range(cycles):
            o = H.one_cycle(st, st.dt)
            if not o["ok"]:
                print(f"  cycle {i}: {o['message']}", flush=True)
                break
            seq.append((o["sigma_max"], o["sigma_min"], o["period"], o["unjumped"]))
            if i % 50 == 0 or i == cycles - 1:
                print(f"  {i} {o['sigma_max']:.9f} {o['sigma_min']:.9f} {o['sigma_max'] - o['sigma_min']:.9f} "
                      f"{o['period']:.6f} {o['unjumped']:.4f} {sw.seconds:.1f}", flush=True)
    a = np.array(seq)
    if len(a) >= tail:
        last = a[-tail:]
        amp = last[:, 0] - last[:, 1]
        row.update(plain_cycles=len(a), plain_sigma_max=last[:, 0].mean(), plain_sigma_min=last[:, 1].mean(),
                   plain_amplitude=amp.mean(), plain_period=last[:, 2].mean(),
                   plain_spread=float(np.abs(last[:, :2] - last[:, :2].mean(axis=0)).max()),
                   plain_drift_sigma_max=float(last[-1, 0] - last[0, 0]),
                   plain_drift_sigma_min=float(last[-1, 1] - last[0, 1]), plain_s=sw.seconds,
                   run_true_error=float(max(abs(r.sigma_max - last[:, 0].mean()),
                                            abs(r.sigma_min - last[:, 1].mean()))))
    return row


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--k0", type=float, default=0.1)
    ap.add_argument("--fractions", default="0.95,0.98,0.99")
    ap.add_argument("--dt", type=float, default=0.02)
    ap.add_argument("--tol", type=float, default=2e-5)
    ap.add_argument("--cycles", type=int, default=400)
    ap.add_argument("--tail", type=int, default=50, help="the last cycles averaged")
    a = ap.parse_args()
    rows = [check(a.k0, float(f), a.dt, a.tol, a.cycles, a.tail) for f in a.fractions.split(",")]
    out = RESULTS / "micro_cohort_plain_check.csv"
    frame = write_csv(rows, out, keys=["k0", "V_over_Vc", "dt"])
    print(frame.to_string(index=False))


if __name__ == "__main__":
    main()
