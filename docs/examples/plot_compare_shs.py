r"""
Slide-hold-slide in both models (compare)
=========================================

The paper's Fig. 7: the stress peak on reloading against the hold time, for micro
(exponential saturation), RS with Eq. (11) and the classical RS law Eq. (7), each with
its fitted growth law; and micro's stress around the reload.

This runs :func:`compare.report` for the ``shs`` scenario with
:meth:`compare.Settings.quick` (few points, a coarse bin: its numbers only show that the
pipeline works) and shows the figure it writes.  The full figure is
``python -m compare --scenario shs`` (the default settings, under a minute).
"""
import tempfile

import matplotlib.pyplot as plt

import compare

# %%
# Micro's results are cached on disk (``$COMPARE_CACHE_DIR`` or
# ``~/.cache/frictionkit-compare``), so a second run computes nothing.  The report
# folder here is temporary: pass a folder of your own to keep the CSV tables, the
# figures and ``summary.md``.
folder = tempfile.mkdtemp(prefix="compare-shs-")
rep = compare.report(compare.Settings.quick(), scenarios=["shs"], out=folder, progress=False, workers=1)
print(sorted(rep.tables))

# %%
# The figure, as written into the report folder.
fig, ax = plt.subplots(figsize=(10, 6))
ax.imshow(plt.imread(rep.figures["shs"]))
ax.set_axis_off()
fig.tight_layout()
