r"""
Bifurcation diagrams side by side (compare)
===========================================

The paper's Figs. 4 and 8 on shared axes: micro's exact steady branch (dotted where
unstable) with its V^c and its Fokker-Planck stick-slip extrema, and the rate-and-state
diagram with Eq. (10) fitted to micro's branch and D_c fitted to micro's extrema.  The
report also draws the fit of Eq. (10), the D_c profile and V^c(k0).

This runs :func:`compare.report` for the ``bifurcation`` scenario with
:meth:`compare.Settings.quick` (few points, a coarse bin: its numbers only show that the
pipeline works) and shows the figure it writes.  The full figure is
``python -m compare --scenario bifurcation`` (the default settings, under a minute).
"""
import tempfile

import matplotlib.pyplot as plt

import compare

# %%
# Micro's results are cached on disk (``$COMPARE_CACHE_DIR`` or
# ``~/.cache/frictionkit-compare``), so a second run computes nothing.  The report
# folder here is temporary: pass a folder of your own to keep the CSV tables, the
# figures and ``summary.md``.
folder = tempfile.mkdtemp(prefix="compare-bifurcation-")
rep = compare.report(compare.Settings.quick(), scenarios=["bifurcation"], out=folder, progress=False, workers=1)
print(sorted(rep.tables))

# %%
# The figure, as written into the report folder.
fig, ax = plt.subplots(figsize=(10, 6))
ax.imshow(plt.imread(rep.figures["bifurcation"]))
ax.set_axis_off()
fig.tight_layout()
