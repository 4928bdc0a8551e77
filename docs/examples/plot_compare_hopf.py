r"""
The transition near V^c, on both sides (compare)
================================================

Left, the one test of how steady sliding loses stability, for both models: the growth
rate of the unstable mode against d = (V^c - V)/V^c.  Micro's and RS's (at a = 0) both
diverge at V^c: a real eigenvalue enters from infinity, and neither transition is a Hopf
bifurcation.  Right, both models' cycle amplitude against d on log-log axes, each from its
own exact V^c: micro's default (the cohort method, with a bar bounding its error where that
is known), the N-block at two sizes (standard errors) and RS, each with its fitted power
law and 95 % interval over the d it rests on; RS's asymptote c0 d^(1/2) (1 + c2 d) derived
from its stick-slip map; micro's reset-model total-shock law, derived where shocks are total
(d >~ k0/k2), and its measured linear law, labelled so (``rep["hopf_micro_laws"]``).
``rep["hopf_fit"]`` is the table,
``rep.values["transition_verdict"]`` the verdict.

This runs :func:`compare.report` for the ``hopf`` scenario with
:meth:`compare.Settings.quick` (few points, a coarse bin: its numbers only show that the
pipeline works) and shows the figure it writes.  The full figure is
``python -m compare --scenario hopf`` (the default settings, one to two minutes on 2 cores).
"""
import tempfile

import matplotlib.pyplot as plt

import compare

# %%
# Micro's results are cached on disk (``$COMPARE_CACHE_DIR`` or
# ``~/.cache/frictionkit-compare``), so a second run computes nothing.  The report
# folder here is temporary: pass a folder of your own to keep the CSV tables, the
# figures and ``summary.md``.
folder = tempfile.mkdtemp(prefix="compare-hopf-")
rep = compare.report(compare.Settings.quick(), scenarios=["hopf"], out=folder, progress=False, workers=1)
print(sorted(rep.tables))
print(rep["hopf_fit"][["model", "method", "resolution", "beta", "beta_low", "beta_high", "d_min", "d_max",
                       "n_points"]].to_string(index=False))
print(rep.values["transition_verdict"])

# %%
# The figure, as written into the report folder.
fig, ax = plt.subplots(figsize=(12, 5))
ax.imshow(plt.imread(rep.figures["hopf"]))
ax.set_axis_off()
fig.tight_layout()
