"""The cost of one cycle of the cohort method on 1 and 2 threads (numba's parallel kernels).

k0 = 0.1, 0.95 V^c (shocks leave a fifth of the blocks unjumped, so cohorts pile up):
from the same cold start, the first ``--cycles`` cycles at dt = 0.004 and the default
cell, timed one by one, with numba's thread count set to 1 and then 2.  The cycles are
the same on both (the kernels sum the cohorts in fixed chunks), so the stress after
each is printed to show it.  Compilation is done first and not counted.

    python benchmarks/micro_cohort_cycle_cost.py        # about 20 s
"""
from __future__ import annotations

import argparse

import numba

import micro
# the public cycle_cohorts runs a whole fixed-point iteration; timing one cycle at a time
# needs the cycle state (start_state) and the single cycle (one_cycle): hooks for studies
from micro.cohort import cycle_cohorts
from micro.study_hooks import one_cycle, start_state

from _harness import Stopwatch, warm_up


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--k0", type=float, default=0.1)
    ap.add_argument("--fraction", type=float, default=0.95, help="V / V^c")
    ap.add_argument("--cycles", type=int, default=8)
    args = ap.parse_args()
    model = micro.Model(k0=args.k0)
    V = args.fraction * micro.critical_velocity(model).Vc
    warm_up(cycle_cohorts, model, V, tol=1e-2, max_iter=4)
    for threads in (1, min(2, numba.config.NUMBA_NUM_THREADS)):
        numba.set_num_threads(threads)
        st = start_state(model, V, model.kappa * model.zbar / 20.0, None)
        total = 0.0
        for i in range(args.cycles):
            with Stopwatch() as sw:
                out = one_cycle(st, 0.004)
            total += sw.seconds
        print(f"{threads} thread(s): {args.cycles} cycles in {total:.2f} s, the last with {st.pool} cells "
              f"and {st.n} cohorts; sigma_max of the last {out['sigma_max']:.10f}", flush=True)


if __name__ == "__main__":
    main()
