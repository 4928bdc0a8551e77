r"""
A velocity sweep (micro)
========================

:func:`micro.sweep` gives one row per driving velocity: where steady sliding is
stable the row comes from the direct solver (exact, milliseconds), elsewhere the
Fokker-Planck equation is time-stepped until the stick-slip cycle converges.  The
same table is what ``python -m micro sweep`` writes.
"""
import matplotlib.pyplot as plt
import numpy as np

import micro

model = micro.Model(k0=0.1)
V = [0.1, 0.2, 0.35, 1.0, 2.0, 5.0]
table = micro.sweep(model, V, numerics=micro.Numerics(eps=0.016))
table[["V", "regime", "sigma_max", "sigma_min", "sigma_mean", "converged"]]

# %%
# The extrema against V over the exact steady branch (dotted where unstable): the
# micro half of the paper's Fig. 4 at one k0.
grid = np.geomspace(0.05, 5.0, 60)
branch = micro.steady_sliding(model, grid, growth_rate=False).to_frame()
fig, ax = plt.subplots(figsize=(6, 3.6))
ax.semilogx(branch.V.where(branch.stable), branch.sigma.where(branch.stable), "k-", lw=0.8, label="steady (exact)")
ax.semilogx(branch.V.where(~branch.stable), branch.sigma.where(~branch.stable), "k:", lw=0.8)
ax.semilogx(table.V, table.sigma_max, "o-", label="sigma_max")
ax.semilogx(table.V, table.sigma_min, "s-", label="sigma_min")
ax.axvline(micro.critical_velocity(model).Vc, color="grey", lw=0.6)
ax.set(xlabel="driving velocity V", ylabel="sigma", title="micro sweep, k0 = 0.1, eps = 0.016")
ax.legend(fontsize=8)
fig.tight_layout()
