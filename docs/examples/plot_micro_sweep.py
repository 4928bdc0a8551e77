r"""
A velocity sweep (micro)
========================

:func:`micro.sweep` gives one row per driving velocity, each from the best method for
it: where steady sliding is stable the renewal chain (exact, milliseconds), elsewhere
the stick-slip cycle by the cohort method (the fixed point of the cycle map, seconds).
The ``method`` column says which; ``discretisation_error`` what the discretisation may
have moved (NaN where it is not known, close to V^c).  The same table is what
``python -m micro sweep`` writes.
"""
import matplotlib.pyplot as plt
import numpy as np

import micro

model = micro.Model(k0=0.1)
V = [0.1, 0.2, 0.35, 1.0, 2.0, 5.0]
table = micro.sweep(model, V)
table[["V", "method", "regime", "sigma_max", "sigma_min", "discretisation_error", "converged"]]

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
ax.set(xlabel="driving velocity V", ylabel="sigma", title="micro sweep, k0 = 0.1 (renewal chain and cohort method)")
ax.legend(fontsize=8)
fig.tight_layout()
