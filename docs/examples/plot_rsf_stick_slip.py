r"""
A stick-slip cycle and its limit cycle (rsf)
============================================

Without a direct effect the rate-and-state slider moves by stick, slide and
instantaneous slip; :func:`rsf.simulate` integrates a run and lists its phase switches
as events, :func:`rsf.limit_cycle` runs until the cycle has converged and describes
the attractor.
"""
import matplotlib.pyplot as plt

import rsf

model = rsf.SpringSlider(k0=0.1)  # Vc = 1.0046 with Eq. (10) and Dc = 0.06
run = rsf.simulate(model, V=0.5, t_end=3.0)
print(run.message)
run.events_frame().head(8)

# %%
# The stress time series (a slip is a vertical drop: two samples at one instant).
fig, ax = plt.subplots(figsize=(7, 3.2))
ax.plot(run.t, run.sigma)
ax.set(xlabel="time t", ylabel="sigma", title="RS, k0 = 0.1, V = 0.5")
fig.tight_layout()

# %%
# The converged cycle, with its status: a run that does not converge says so
# (``converged``, ``status``, ``message``) instead of returning a number silently.
cycle = rsf.limit_cycle(model, V=0.5)
print(cycle.regime, cycle.converged, cycle.message)
print(f"sigma_max = {cycle.sigma_max:.5f}, sigma_min = {cycle.sigma_min:.5f}, period = {cycle.period:.4f}")
print("sequence:", " ".join(cycle.sequence))

# %%
# Near :math:`V^c` the amplitude vanishes as :math:`(V^c - V)^{1/2}`: a Hopf
# bifurcation (:func:`rsf.hopf_scaling`).
fit = rsf.hopf_scaling(rsf.SpringSlider(k0=0.3), [1e-7, 1e-6, 1e-5])
print(f"exponent {fit.exponent:.4f} +- {fit.exponent_stderr:.1e}")
