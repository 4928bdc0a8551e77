r"""
Velocity steps and slide-hold-slide (rsf)
=========================================

A :class:`rsf.Protocol` is a piecewise-constant load-point velocity.  Here the classical
rate-and-state law (Eq. 7 with the aging law, :func:`rsf.standard_rs`, laboratory-like
units) under velocity steps, and the paper's model under slide-hold-slide.
"""
import matplotlib.pyplot as plt

import rsf

# %%
# Velocity steps 1 -> 10 -> 1 um/s on the classical law (a = 0.01, b = 0.015):
# the direct effect jumps the friction, the state evolves over D_c.
model = rsf.standard_rs()
steps = rsf.Protocol.velocity_steps([1e-6, 1e-5, 1e-6], [20.0, 10.0])
run = rsf.simulate(model, protocol=steps, t_end=60.0)
fig, ax = plt.subplots(figsize=(7, 3.2))
ax.plot(run.t, run.sigma)
ax.set(xlabel="time [s]", ylabel="friction mu", title="classical RS: velocity steps 1, 10, 1 um/s")
fig.tight_layout()

# %%
# Slide-hold-slide on the paper's model (Eq. 10 with the aging law, k0 = 0.3 slides
# steadily at V = 3): the peak on reloading grows with the hold time.
model = rsf.SpringSlider(k0=0.3)
fig, ax = plt.subplots(figsize=(7, 3.2))
for hold in (1.0, 3.0, 10.0):
    shs = rsf.Protocol.slide_hold_slide(3.0, slide_time=5.0, hold_time=hold)
    run = rsf.simulate(model, protocol=shs, t_end=5.0 + hold + 2.0)
    frame = run.to_frame()
    after = frame[frame.t > 5.0 + hold]
    print(f"hold {hold:>4g}: peak - steady = {after.sigma.max() - frame.sigma.iloc[0]:.5f}")
    ax.plot(frame.t - 5.0 - hold, frame.sigma, label=f"hold {hold:g}")
ax.set(xlabel="time since reloading", ylabel="sigma", xlim=(-3, 2), title="RS, Eq. (10), k0 = 0.3, V = 3")
ax.legend(fontsize=8)
fig.tight_layout()
