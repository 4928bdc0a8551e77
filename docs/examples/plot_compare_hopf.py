r"""
The transition near V^c: is it Hopf? (compare)
==============================================

Micro's growth rate of the unstable mode below V^c, and both models' cycle amplitude
against the distance d = (V^c - V)/V^c from each model's own exact V^c: Fokker-Planck
at two bins, N-block at two sizes, and RS, each with a fitted power law.  RS has a Hopf
bifurcation (exponent 1/2); micro's unstable mode is real and its growth rate diverges
at V^c.

This runs :func:`compare.report` for the ``hopf`` scenario with
:meth:`compare.Settings.quick` (few points, a coarse bin: its numbers only show that the
pipeline works) and shows the figure it writes.  The full figure is
``python -m compare --scenario hopf`` (the default settings, under a minute).
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

# %%
# The figure, as written into the report folder.
fig, ax = plt.subplots(figsize=(10, 6))
ax.imshow(plt.imread(rep.figures["hopf"]))
ax.set_axis_off()
fig.tight_layout()
