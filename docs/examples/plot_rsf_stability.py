r"""
Steady sliding, its stability and V^c (rsf)
===========================================

Steady sliding at velocity :math:`V` has the stress :math:`\mu_{ss}(V)` of the
steady-state law.  It is linearly unstable where the law weakens faster than the
spring can follow,

.. math:: k_0 D_c < W(V) = -V\,\frac{\mathrm d\mu_{ss}}{\mathrm dV},

so the critical velocity :math:`V^c` and the lower end :math:`V_-` of the unstable
band are the roots of :math:`W(V) = k_0 D_c` (closed form for the paper's Eq. 10).
"""
import matplotlib.pyplot as plt
import numpy as np

import rsf

law = rsf.HyperbolicLaw()  # Eq. (10): mu_inf + A / (V + B), A = 0.007, B = 0.078
V = np.geomspace(1e-4, 1e4, 200)

fig, ax = plt.subplots(figsize=(6, 3.6))
ax.loglog(V, law.weakening(V), "k-", label="W(V) = -V dmu_ss/dV")
for k0 in (0.3, 0.1, 0.01, 0.001):
    cv = rsf.critical_velocity(law, k0=k0, Dc=rsf.PAPER_DC)
    (line,) = ax.loglog(V, np.full_like(V, k0 * rsf.PAPER_DC), "--", lw=0.8, label=f"k0 Dc, k0 = {k0:g}")
    ax.plot([cv.V_lower, cv.Vc], [k0 * rsf.PAPER_DC] * 2, "o", color=line.get_color())
ax.set(xlabel="V", ylabel="W(V)", ylim=(1e-6, 1e-1), title="unstable where W(V) > k0 Dc (dots: V_-, Vc)")
ax.legend(fontsize=7)
fig.tight_layout()

# %%
# The same numbers as ``python -m rsf critical`` writes them.
for k0 in (0.3, 0.1, 0.01, 0.001, 0.0001):
    cv = rsf.critical_velocity(rsf.SpringSlider(k0=k0))
    print(f"k0 = {k0:<7g} Vc = {cv.Vc:<10.6g} V_lower = {cv.V_lower:<10.5g} method = {cv.method}")

# %%
# Stiffer springs never stick-slip: with Eq. (10) the band closes at
# :math:`k_0 D_c = A/(4B)` (k0 = 0.374 at D_c = 0.06), and ``Vc`` is NaN.
print(rsf.critical_velocity(rsf.SpringSlider(k0=1.0)))
