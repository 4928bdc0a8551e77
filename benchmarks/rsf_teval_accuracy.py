"""Run time against error across CVODE's rtol for output at chosen times (``t_eval``),
against the independent reference of the tests (scipy DOP853 at rtol 1e-12,
``tests/rsf/_independent_rs.py``, no code shared with rsf).

Velocity steps 1 -> V1 -> 1 (at t = 10 and 50, to t = 100, 401 output times) on the
classical log law (a = 0.005, b = 0.01, Dc = 10, v0 = 1) with each state law.  For each
rtol (atol = rtol / 100) the table gives the largest |mu - mu_ref| at the output times with
``t_eval`` (CVODE's own output), the same from linear interpolation of the step output
onto the grid (what a user had to do before), and the run time (median of repeats, after
compilation).  Also the wall time of the runaway case of issue 17 (aging law,
k0 = 0.8 k_c, step 1 -> 10).

    python benchmarks/rsf_teval_accuracy.py          # writes benchmarks/results/rsf_teval_accuracy.csv
"""
from __future__ import annotations

import os
import statistics
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))                         # the repository
sys.path.insert(0, str(ROOT / "tests" / "rsf"))       # the independent reference

import numpy as np  # noqa: E402

import rsf  # noqa: E402
# the tests' independent reference (scipy, no code shared with rsf), not a name of rsf
from _independent_rs import mu_at  # noqa: E402

from _harness import RESULTS, timed, warm_up, write_csv  # noqa: E402

A, B, DC, V0, MU0 = 0.005, 0.01, 10.0, 1.0, 0.6
KC = (B - A) / DC
TE = np.linspace(0.0, 100.0, 401)
# name, state law for rsf, reference law, reference extras, k0 / k_c, step velocity, eta_rad
CASES = [
    ("aging 20kc", "aging", "aging", {}, 20.0, 10.0, 0.0),
    ("aging 1.2kc", "aging", "aging", {}, 1.2, 10.0, 0.0),
    ("slip 2kc", "slip", "slip", {}, 2.0, 2.0, 0.0),
    ("prz 2kc", "prz", "prz", {}, 2.0, 2.0, 0.0),
    ("nagata c=2 2kc", rsf.NagataLaw(c=2.0), "nagata", {"nagata_c": 2.0}, 2.0, 10.0, 0.0),
    ("aging 0.8kc eta=1e-3", "aging", "aging", {"eta": 1e-3}, 0.8, 2.0, 1e-3),
]
RTOLS = [1e-6, 1e-8, 1e-10, 1e-12]
REPEAT = 3


def main() -> None:
    rows = []
    print(f"{'case':<22} {'rtol':>7} {'t_eval err':>11} {'interp err':>11} {'t_eval ms':>10} "
          f"{'steps ms':>9}")
    for name, state_law, ref_law, extra, k_over_kc, v1, eta in CASES:
        k0 = k_over_kc * KC
        model = rsf.standard_rs(mu0=MU0, a=A, b=B, Dc=DC, k0=k0, v0=V0, state_law=state_law,
                                eta_rad=eta)
        vel = [1.0, v1, 1.0]
        proto = rsf.Protocol.velocity_steps(vel, [10.0, 40.0])
        mu_ref = mu_at(ref_law, a=A, b=B, Dc=DC, k0=k0, v0=V0, mu0=MU0, velocities=vel,
                       times=[0.0, 10.0, 50.0], t_eval=TE, **extra)
        warm_up(rsf.simulate, model, protocol=proto, t_end=100.0, t_eval=TE, label=f"{name}: first call")
        for rtol in RTOLS:
            opts = rsf.SolverOptions(rtol=rtol, atol=rtol * 1e-2)
            t_out, t_steps = [], []
            for _ in range(REPEAT):
                tr, seconds = timed(rsf.simulate, model, protocol=proto, t_end=100.0, t_eval=TE, options=opts)
                t_out.append(seconds)
                full, seconds = timed(rsf.simulate, model, protocol=proto, t_end=100.0, options=opts)
                t_steps.append(seconds)
            assert tr.success and full.success, (name, tr.message, full.message)
            err = float(np.max(np.abs(tr.sigma - mu_ref)))
            err_interp = float(np.max(np.abs(np.interp(TE, full.t, full.sigma) - mu_ref)))
            row = dict(case=name, rtol=rtol, err_t_eval=err, err_interpolated=err_interp,
                       ms_t_eval=1e3 * statistics.median(t_out),
                       ms_steps=1e3 * statistics.median(t_steps), n_steps=full.t.size)
            rows.append(row)
            print(f"{name:<22} {rtol:>7.0e} {err:>11.2e} {err_interp:>11.2e} "
                  f"{row['ms_t_eval']:>10.1f} {row['ms_steps']:>9.1f}")
        print()
    runaway = rsf.standard_rs(mu0=MU0, a=A, b=B, Dc=DC, k0=0.8 * KC, v0=V0)
    step = rsf.Protocol.velocity_steps([1.0, 10.0], [10.0])
    walls = []
    for _ in range(REPEAT):
        tr, seconds = timed(rsf.simulate, runaway, protocol=step, t_end=60.0)
        walls.append(seconds)
    print(f"runaway (aging, k0 = 0.8 k_c, step 1 -> 10): status {tr.status}, "
          f"{1e3 * statistics.median(walls):.1f} ms; {tr.message}")
    out = RESULTS / "rsf_teval_accuracy.csv"
    write_csv(rows, out)
    print(f"wrote {out.relative_to(ROOT)}")


if __name__ == "__main__":
    os.environ.setdefault("PYTHONWARNINGS", "ignore")
    main()
