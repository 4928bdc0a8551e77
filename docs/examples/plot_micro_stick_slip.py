r"""
A stick-slip cycle (micro)
==========================

Below :math:`V^c` steady sliding is unstable and the model stick-slips: slow loading,
then a global avalanche.  :func:`micro.simulate` time-steps the Fokker-Planck
equation for the density of the blocks' margins (the paper's Appendix B) and returns
the stress time series; its bin ``eps`` sets accuracy and cost (second order in eps;
the default bin gives about 1e-4 and takes minutes; this example uses the coarse bin
0.016: seconds).  :func:`micro.stationary` solves the cycle directly, by default with
the cohort method: the fixed point of the cycle map, seconds at any k0.
"""
import matplotlib.pyplot as plt

import micro

model = micro.Model(k0=0.1)  # Vc = 0.7275
numerics = micro.Numerics(eps=0.016)

# %%
# The time series at V = 0.3 from the default initial state: each drop of the stress
# is a global shock (``run.shocks`` lists them).
run = micro.simulate(model, 0.3, duration=30.0, numerics=numerics)
print(run.shocks.head())
fig, ax = plt.subplots(figsize=(7, 3.2))
ax.plot(run.records.t, run.records.sigma)
ax.set(xlabel="time t", ylabel="sigma", title="micro, k0 = 0.1, V = 0.3, eps = 0.016")
fig.tight_layout()

# %%
# The limit cycle: ``method``, ``regime``, ``sigma_max``, ``sigma_min``, ``period``, a
# ``converged`` flag with a message, and the errors (``discretisation_error``, the
# change from twice the step and cell; ``sigma_stderr``, the fixed point's).
cycle = micro.stationary(model, 0.3)
print(cycle.method, cycle.regime, cycle.converged, cycle.message)
print(f"discretisation error {cycle.discretisation_error:.1e}, fixed-point error {cycle.sigma_stderr:.1e}")
print(f"sigma_max = {cycle.sigma_max:.4f}, sigma_min = {cycle.sigma_min:.4f}, period = {cycle.period:.3f}")
