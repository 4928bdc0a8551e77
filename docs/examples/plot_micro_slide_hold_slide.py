r"""
Slide-hold-slide (micro)
========================

Drive, stop for a hold time, drive again: the stress overshoots its steady value on
reloading, more after a longer hold (aging; the paper's Fig. 7).  A protocol is a
:class:`micro.Drive` of ``(duration, velocity)`` segments; :func:`micro.slide_hold_slide`
measures the peak for many hold times from one stationary state.
"""
import matplotlib.pyplot as plt

import micro

model = micro.Model(k0=0.3)  # k0 = 0.3 slides steadily at V = 3 (Vc = 0.19)
numerics = micro.Numerics(eps=0.016)

# %%
# One protocol: slide at V = 3 for 10 time units, hold for 5, slide again for 3.
drive = micro.Drive.slide_hold_slide(3.0, slide=10.0, hold=5.0, resume=3.0)
run = micro.simulate(model, drive, numerics=numerics)
fig, ax = plt.subplots(figsize=(7, 3.2))
ax.plot(run.records.t, run.records.sigma)
ax.set(xlabel="time t", ylabel="sigma", title="micro, k0 = 0.3: slide 10, hold 5, slide")
fig.tight_layout()

# %%
# The peak against the hold time.  It saturates exponentially, on the dashpot
# relaxation time :math:`\eta_u/k_2` (reference page "The micro model", inconsistency 9).
peaks = micro.slide_hold_slide(model, 3.0, [0.3, 1.0, 3.0, 10.0], numerics=numerics)
print(peaks)
fig, ax = plt.subplots(figsize=(5, 3.2))
ax.semilogx(peaks.hold_time, peaks.delta_sigma_max, "o-")
ax.set(xlabel="hold time", ylabel="peak - steady stress")
fig.tight_layout()
