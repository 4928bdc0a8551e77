"""Run time against error across CVODE's rtol, against the integrator-free reference.

For limit cycles whose slide phases go through CVODE (stick -> slide -> slip) and one
without slides, prints for each rtol the largest errors of sigma_max, sigma_min,
sigma_mean and the period (relative) against ``rsf.reference_cycle``
(closed-form stick, quadrature slide, scipy roots), the number of right-hand-side
evaluations per slide and the run time per limit cycle (median of repeats, after
compilation).

    python benchmarks/rsf_accuracy.py
"""
from __future__ import annotations

import os
import statistics
import sys

sys.path.insert(0, os.path.dirname(os.path.dirname(os.path.abspath(__file__))))  # the repository

import rsf  # noqa: E402

from _harness import timed, warm_up  # noqa: E402

CASES = [
    ("Eq.10 k0=0.3  V=0.05", rsf.SpringSlider(k0=0.3), 0.05),
    ("Eq.10 k0=0.1  V=0.02", rsf.SpringSlider(k0=0.1), 0.02),
    ("Eq.10 k0=0.01 V=0.01", rsf.SpringSlider(k0=0.01), 0.01),
    ("Eq.4  k0=0.01 V=0.003", rsf.SpringSlider(rsf.ViscoelasticLaw(), k0=0.01), 0.003),
    ("Eq.10 k0=0.3  V=0.15 (no slide)", rsf.SpringSlider(k0=0.3), 0.15),
]
RTOLS = [1e-4, 1e-6, 1e-8, 1e-10, 1e-12]
REPEAT = 7


def main() -> None:
    refs = {name: rsf.reference_cycle(model, V) for name, model, V in CASES}
    warm_up(lambda: [rsf.limit_cycle(model, V) for _, model, V in CASES],
            label="compilation (or numba's cache) and a first limit cycle of each case")
    print(f"{'case':<34} {'rtol':>7} {'|d sigma_max|':>14} {'|d sigma_min|':>14} "
          f"{'|d sigma_mean|':>15} {'|dT|/T':>9} {'time/cycle-search':>18}")
    for name, model, V in CASES:
        ref = refs[name]
        for rtol in RTOLS:
            opts = rsf.SolverOptions(rtol=rtol, atol=rtol * 1e-2, cycle_rtol=1e-13)
            times = []
            for _ in range(REPEAT):
                r, seconds = timed(rsf.limit_cycle, model, V, options=opts)
                times.append(seconds)
            assert r.converged and r.sequence == ref.sequence, (name, rtol, r.message)
            print(f"{name:<34} {rtol:>7.0e} {abs(r.sigma_max - ref.sigma_max):>14.2e} "
                  f"{abs(r.sigma_min - ref.sigma_min):>14.2e} {abs(r.sigma_mean - ref.sigma_mean):>15.2e} "
                  f"{abs(r.period - ref.period) / ref.period:>9.2e} "
                  f"{1e3 * statistics.median(times):>15.2f} ms")
        print()
    print("reference sequences: " + "; ".join(f"{n}: {' '.join(refs[n].sequence)}" for n, _, _ in CASES))


if __name__ == "__main__":
    main()
