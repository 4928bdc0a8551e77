r"""
Bifurcation diagram of the rate-and-state slider (rsf)
======================================================

The rate-and-state counterpart of the paper's Fig. 8: :math:`\sigma_{max}` and
:math:`\sigma_{min}` of the attractor against the driving velocity, for the paper's
five stiffnesses, with its steady-state law Eq. (10) and :math:`D_c = 0.06`.
:func:`rsf.sweep` finds the limit cycle (or steady sliding) at each velocity,
about a millisecond each; :func:`rsf.critical_velocity` gives :math:`V^c` (dotted)
in closed form.
"""
import matplotlib.pyplot as plt
import numpy as np

import rsf

V = np.geomspace(1e-4, 1e4, 25)
fig, ax = plt.subplots(figsize=(6.5, 4.5))
for k0 in (0.3, 0.1, 0.01, 0.001, 0.0001):
    model = rsf.SpringSlider(k0=k0)
    sweep = rsf.sweep(model, V, options=rsf.SolverOptions(cycle_rtol=1e-8))
    if not sweep.all_converged:
        raise RuntimeError(sweep.message)
    frame = sweep.to_frame()
    (line,) = ax.semilogx(frame.V, frame.sigma_max, "-", lw=1.2, label=f"k0 = {k0:g}")
    ax.semilogx(frame.V, frame.sigma_min, "-", lw=1.2, color=line.get_color())
    ax.axvline(rsf.critical_velocity(model).Vc, color=line.get_color(), lw=0.6, ls=":")
ax.set(xlabel="driving velocity V", ylabel="sigma_max, sigma_min",
       title="RS spring-slider, Eq. (10), Dc = 0.06 (dotted: Vc)")
ax.legend(fontsize=8)
fig.tight_layout()

# %%
# The table of one sweep: one row per velocity, with the regime, the extrema, the mean,
# the period and the convergence status of each point.
rsf.sweep(rsf.SpringSlider(k0=0.1), [0.003, 0.01, 0.1, 0.5, 2.0]).to_frame()[
    ["V", "regime", "sigma_max", "sigma_min", "sigma_mean", "period", "converged", "sequence"]]
