"""Bifurcation diagram of the rate-and-state spring-slider (cf. Fig. 8 of Landes, Rosso &
Jagla 2015): sigma_max and sigma_min of the attractor against the driving velocity V, for
k0 = 0.3, 0.1, 0.01, 0.001, 1e-4 with the paper's Eq. (10) and Dc = 0.06.

    python docs/examples/rsf_bifurcation.py [OUT.png] [--points N]
"""
from __future__ import annotations

import argparse
import os
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", ".."))

import rsf  # noqa: E402


def main(argv: list[str] | None = None) -> str:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("out", nargs="?", default=os.path.join(
        os.path.dirname(os.path.abspath(__file__)), "..", "figures", "rsf_bifurcation.png"))
    parser.add_argument("--points", type=int, default=60, help="velocities per k0")
    args = parser.parse_args(argv)

    V = np.geomspace(1e-4, 1e4, args.points)
    fig, ax = plt.subplots(figsize=(6.5, 4.5))
    for k0 in (0.3, 0.1, 0.01, 0.001, 0.0001):
        model = rsf.SpringSlider(k0=k0)
        sweep = rsf.sweep(model, V, options=rsf.SolverOptions(cycle_rtol=1e-8))
        frame = sweep.to_frame()
        if not sweep.all_converged:
            raise RuntimeError(sweep.message)
        line, = ax.semilogx(frame.V, frame.sigma_max, "-", lw=1.2, label=f"k0 = {k0:g}")
        ax.semilogx(frame.V, frame.sigma_min, "-", lw=1.2, color=line.get_color())
        cv = rsf.critical_velocity(model)
        ax.axvline(cv.Vc, color=line.get_color(), lw=0.6, ls=":")
    ax.set_xlabel("driving velocity V")
    ax.set_ylabel("sigma_max, sigma_min")
    ax.set_title("RS spring-slider, Eq. (10), Dc = 0.06 (dotted: Vc)")
    ax.legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(args.out, dpi=120)
    plt.close(fig)
    print(f"wrote {args.out}")
    return args.out


if __name__ == "__main__":
    main()
