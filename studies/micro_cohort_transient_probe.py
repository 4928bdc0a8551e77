"""Can the cohort method carry a transient of steady sliding?  A probe of its cost and
error, against the renewal chain's exact steady stress (issue: transients by cohorts).

The report's slide-hold-slide point (k0 = 0.1, V = 10, the paper's other parameters)
starts from steady sliding.  This script time-steps the cohort method's state (one cohort
per step: the cohort method's state ``micro.study_hooks.CohortState``, ``prepare``/``root``/``commit``: the same steps
the cycle map takes in a loading phase) at constant V from the ``frozen`` start (every
dashpot relaxed, margins Exp(kappa zbar): one cohort), and records the stress, the
cohorts and cells alive and the CPU time at t = 0.25, 0.5, 0.75, 1 for two time steps.
The difference between the two runs at equal t is their discretisation error (the exact
transient is the same); the renewal chain's steady stress is printed beside it.

Why a hook for studies: the cohort method has no public transient entry point (this
probe is the measurement that says why not).

Run: ``python -m studies micro_cohort_transient_probe`` (about 1-2 minutes on 2
cores); writes benchmarks/results/micro_cohort_transient_probe.csv.  Recorded in
docs/validation/micro_defaults.md, "Transients by cohorts".
"""
from __future__ import annotations

import argparse

import numpy as np
import pandas as pd

import micro
from benchmarks._harness import RESULTS, Stopwatch, warm_up, write_csv
from micro import study_hooks as H  # CohortState, the method's state (see above)

K0, V, T = 0.1, 10.0, 1.0
STEPS = (0.004, 0.002)


def run(model: micro.Model, dt: float, exact: float) -> list[dict]:
    h = model.kappa * model.zbar / 20.0
    st = H.CohortState(model, V, h)
    dep = np.zeros(st.ny)
    dep[int(round(-st.ylo / h))] = 1.0  # every delta_R = 0 ...
    st.sigma = model.f_th - st.lam  # ... and margins Exp(kappa zbar): the frozen start
    st.add(dep)
    rows, n, marks = [], 0, [0.25, 0.5, 0.75, 1.0]
    with Stopwatch(cpu=True) as sw:
        while marks:
            phi, Edt = st.prepare(dt)
            x, status = st.root()
            if status != 0:
                raise RuntimeError(f"a shock started at t = {st.t:g}: not steady sliding")
            st.commit(x, dt, phi, Edt)
            n += 1
            if n % 200 == 0:
                st.compact()
            if st.t >= marks[0] - 1e-12:
                marks.pop(0)
                rows.append(dict(k0=model.k0, V=V, dt=dt, t=st.t, sigma=st.sigma, sigma_steady_exact=exact,
                                 cohorts=st.n, cells=st.pool, cpu_s=sw.seconds))
                print(rows[-1], flush=True)
    return rows


def main() -> None:
    argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter).parse_args()  # no options: --help only
    model = micro.Model(k0=K0)
    exact = float(micro.steady_sliding(model, [V]).to_frame().sigma.iloc[0])
    warm_up(lambda: run(micro.Model(k0=K0), 0.05, exact))
    rows = []
    for dt in STEPS:
        rows += run(model, dt, exact)
    frame = pd.DataFrame(rows)
    write_csv(frame, RESULTS / "micro_cohort_transient_probe.csv")
    a, b = (frame[frame.dt == dt].set_index("t").sigma for dt in STEPS)
    print("difference between the two time steps at equal t:\n", (a.values - b.values))


if __name__ == "__main__":
    main()
