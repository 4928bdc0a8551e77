r"""
Phase diagram in the (k0, V) plane (compare)
============================================

The paper's Fig. 5: micro's exact V^c against k0 for a (k1, k2) set, with its
small-k0 asymptote and the limit k0 = k2 above which steady sliding is stable at every
V, and the RS V^c(k0) with both fitted D_c.  The quick settings draw one set; the
default report draws the paper's four.

This runs :func:`compare.report` for the ``phase`` scenario with
:meth:`compare.Settings.quick` (few points, a coarse bin: its numbers only show that the
pipeline works) and shows the figure it writes.  The full figure is
``python -m compare --scenario phase`` (the default settings, under a minute).
"""
import tempfile

import matplotlib.pyplot as plt

import compare

# %%
# Micro's results are cached on disk (``$COMPARE_CACHE_DIR`` or
# ``~/.cache/frictionkit-compare``), so a second run computes nothing.  The report
# folder here is temporary: pass a folder of your own to keep the CSV tables, the
# figures and ``summary.md``.
folder = tempfile.mkdtemp(prefix="compare-phase-")
rep = compare.report(compare.Settings.quick(), scenarios=["phase"], out=folder, progress=False, workers=1)
print(sorted(rep.tables))

# %%
# The figure, as written into the report folder.
fig, ax = plt.subplots(figsize=(10, 6))
ax.imshow(plt.imread(rep.figures["phase"]))
ax.set_axis_off()
fig.tight_layout()
