r"""
Steady sliding and the critical velocity (micro)
================================================

The stationary questions of the microscopic model have a direct answer: at every
driving velocity :math:`V` the stress of steady sliding, whether it is stable (the
branching ratio of the renewal chain below 1) and, where it is not, the growth rate
of the unstable mode.  The critical velocity :math:`V^c` is the root of
"branching ratio = 1".  Milliseconds per velocity, no time-stepping.
"""
import matplotlib.pyplot as plt
import numpy as np

import micro

# %%
# The paper's Fig. 4 parameters (k1 = 0.1, k2 = 0.9, exponential jumps of mean
# zbar = 0.1) at one driving stiffness k0.
model = micro.Model(k0=0.1)
V = np.geomspace(0.05, 50.0, 40)
branch = micro.steady_sliding(model, V, growth_rate=False)  # growth rates: below
vc = micro.critical_velocity(model)
print(vc.message)
table = branch.to_frame()
table[["V", "sigma", "branching_ratio", "stable", "sigma_error"]].iloc[::8]

# %%
# Below :math:`V^c` steady sliding exists but is unstable (dotted): the model
# stick-slips there (see the stick-slip example).  At large V the stress tends to the
# exact limit :math:`\sigma_\infty + k_2\gamma\,\mathrm{Var}(R)/V`
# (:func:`micro.sigma_fast_limit`, reference page "The micro model").
fig, (ax, bx) = plt.subplots(1, 2, figsize=(9, 3.6))
stable = table.stable.to_numpy()
ax.semilogx(table.V[stable], table.sigma[stable], "-", label="steady, stable")
ax.semilogx(table.V[~stable], table.sigma[~stable], ":", label="steady, unstable")
ax.semilogx(V, [micro.sigma_fast_limit(model, v) for v in V], "--", lw=0.8, label="large-V limit")
ax.axvline(vc.Vc, color="k", lw=0.6)
ax.set(xlabel="driving velocity V", ylabel="sigma", title=f"k0 = 0.1, Vc = {vc.Vc:.4f}")
ax.legend(fontsize=8)
bx.semilogx(table.V, table.branching_ratio, "-")
bx.axhline(1.0, color="k", lw=0.6)
bx.axvline(vc.Vc, color="k", lw=0.6)
bx.set(xlabel="driving velocity V", ylabel="branching ratio b(V)")
fig.tight_layout()

# %%
# Below :math:`V^c` a perturbation of steady sliding grows like :math:`e^{\lambda t}`;
# the growth rate :math:`\lambda` diverges as V approaches :math:`V^c` from below (the
# unstable mode enters from infinity: the transition is not a Hopf bifurcation, see the
# comparison's reference page).
unstable = micro.steady_sliding(model, [0.1, 0.2, 0.4, 0.6, 0.7])
unstable.to_frame()[["V", "branching_ratio", "growth_rate"]]

# %%
# :math:`V^c` at several stiffnesses, and its small-k0 asymptote
# (:func:`micro.vc_small_k0`).
for k0 in (0.3, 0.1, 0.01):
    m = micro.Model(k0=k0)
    print(f"k0 = {k0:<5g} Vc = {micro.critical_velocity(m).Vc:.6g}   small-k0 asymptote {micro.vc_small_k0(m):.6g}")
