"""Hopf scaling: sigma_max - sigma_min against Vc - V for k0 in {0.3, 0.1, 0.01, 0.001, 1e-4}.

For each k0 the limit cycle is computed at V = Vc (1 - eps) for eps from 1e-8 to 1e-1
(cycle_rtol 1e-11), and power laws amplitude ~ (Vc - V)^beta are fitted (least squares in
log-log, standard error of the slope) next to the bifurcation (eps <= 1e-5) and far from
it (1e-3 <= eps <= 1e-1).  Also printed: the spread of sigma_min over the far range
(relative to the amplitude), the local exponents, and the amplitude just above the lower
end of the unstable band, V_lower, where the transition is not continuous.

    python -m studies rsf_hopf [--plot docs/figures/rsf_hopf.png]
"""
from __future__ import annotations

import argparse
import os
import sys

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.dirname(os.path.abspath(__file__))))  # the repository

import rsf  # noqa: E402
from benchmarks._harness import Stopwatch, pyplot, save_figure  # noqa: E402

K0S = [0.3, 0.1, 0.01, 0.001, 0.0001]
EPS = np.geomspace(1e-8, 1e-1, 15)
OPTIONS = rsf.SolverOptions(cycle_rtol=1e-11, rtol=1e-12, atol=1e-14)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--plot", default=None, help="write a log-log figure to this PNG")
    args = parser.parse_args()
    sw = Stopwatch()
    fits = {}
    print(f"{'k0':>7} {'Vc':>10} {'beta (eps<=1e-5)':>20} {'beta (1e-3..1e-1)':>20} "
          f"{'spread sigma_min/amp (far)':>27} {'converged':>10}")
    for k0 in K0S:
        model = rsf.SpringSlider(k0=k0)
        fit = rsf.hopf_scaling(model, EPS, fit_max=1e-5, options=OPTIONS)
        x = fit.epsilon * fit.Vc
        far = (fit.epsilon >= 1e-3)
        b_far, db_far, _, _ = rsf.fit_power_law(x[far], fit.amplitude[far])
        spread = np.ptp(fit.sigma_min[far]) / fit.amplitude[far].max()
        fits[k0] = fit
        print(f"{k0:>7g} {fit.Vc:>10.5g} {fit.exponent:>11.5f} +- {fit.exponent_stderr:.1e} "
              f"{b_far:>11.4f} +- {db_far:.1e} {spread:>27.2e} {str(fit.converged):>10}")
    print()
    print("local exponents d ln(amplitude) / d ln(Vc - V), from eps = 1e-8 upwards:")
    for k0, fit in fits.items():
        print(f"  k0={k0:<7g} " + " ".join(f"{b:.3f}" for b in fit.local_exponents))
    print()
    print("sigma_min / sigma_max (eps = 1e-1, 1e-3, 1e-5): amplitude split around the steady branch")
    for k0, fit in fits.items():
        mu = [rsf.SpringSlider(k0=k0).sigma_steady(fit.Vc * (1 - e)) for e in fit.epsilon]
        rows = []
        for e in (1e-1, 1e-3, 1e-5):
            i = int(np.argmin(np.abs(np.log(fit.epsilon / e))))
            rows.append(f"eps={e:g}: (mu_ss - sigma_min)/amp = {(mu[i] - fit.sigma_min[i]) / fit.amplitude[i]:.3f}")
        print(f"  k0={k0:<7g} " + "; ".join(rows))
    print()
    print("amplitude just above V_lower (lower end of the unstable band):")
    for k0 in K0S:
        model = rsf.SpringSlider(k0=k0)
        cv = rsf.critical_velocity(model)
        amps = []
        for e in (1e-2, 1e-4, 1e-6):
            r = rsf.limit_cycle(model, cv.V_lower * (1 + e), options=OPTIONS)
            amps.append(f"{r.amplitude:.4g} ({r.regime})")
        below = rsf.limit_cycle(model, cv.V_lower * (1 - 1e-6), options=OPTIONS)
        print(f"  k0={k0:<7g} V_lower={cv.V_lower:.5g}: eps=1e-2,1e-4,1e-6 -> {', '.join(amps)}; "
              f"just below: {below.regime}")
    print(f"\ntotal {sw.seconds:.1f} s")
    if args.plot:
        fig, ax = pyplot().subplots(figsize=(5.5, 4.2))
        for k0, fit in fits.items():
            ax.loglog(fit.epsilon, fit.amplitude, "o-", ms=3, label=f"k0 = {k0:g}")
        ax.loglog(EPS[:8], 0.1 * EPS[:8] ** 0.5, "k--", lw=0.8, label="slope 1/2")
        ax.loglog(EPS[8:], 0.08 * EPS[8:], "k:", lw=0.8, label="slope 1")
        ax.set_xlabel("(Vc - V) / Vc")
        ax.set_ylabel("sigma_max - sigma_min")
        ax.legend(fontsize=7)
        fig.tight_layout()
        save_figure(fig, args.plot)


if __name__ == "__main__":
    main()
