"""Sphinx configuration of the frictionkit documentation.

Build (warnings are errors, as in CI)::

    pip install '.[docs]'
    python -m sphinx -W --keep-going -b html docs docs/_build/html

Markdown pages are read by myst-parser, the API reference is generated from the numpydoc
docstrings (autosummary + numpydoc) and ``docs/examples/plot_*.py`` are run and rendered by
sphinx-gallery into ``docs/auto_examples`` (generated, not in git).
"""
from __future__ import annotations

import os
import sys

import matplotlib

matplotlib.use("Agg")

# the packages are importable from the checkout without installing
sys.path.insert(0, os.path.abspath(".."))

project = "frictionkit"
author = "frictionkit authors"
copyright = "2026, frictionkit authors"
release = "0.1.0"

extensions = [
    "sphinx.ext.autodoc",
    "sphinx.ext.autosummary",
    "sphinx.ext.mathjax",
    "sphinx.ext.intersphinx",
    "numpydoc",
    "myst_parser",
    "sphinx_gallery.gen_gallery",
]

source_suffix = {".rst": "restructuredtext", ".md": "markdown"}
root_doc = "index"
exclude_patterns = ["_build", "auto_examples/*.ipynb", "auto_examples/*.py", "auto_examples/*.zip",
                    "auto_examples/*.md5", "auto_examples/*.json", "examples/*"]

# -- Markdown (myst) ---------------------------------------------------------------------
# $...$, $$...$$ and ```math blocks are the notation of the reference pages.
myst_enable_extensions = ["dollarmath", "amsmath"]
myst_fence_as_directive = ["math"]
myst_heading_anchors = 3

# -- API reference -----------------------------------------------------------------------
autosummary_generate = True
autodoc_default_options = {"members": True, "inherited-members": False}
autodoc_typehints = "none"  # numpydoc's Parameters sections carry the types
numpydoc_show_class_members = False
numpydoc_class_members_toctree = False
numpydoc_xref_param_type = False

intersphinx_mapping = {
    "python": ("https://docs.python.org/3", None),
    "numpy": ("https://numpy.org/doc/stable", None),
    "pandas": ("https://pandas.pydata.org/docs", None),
}
# the build must not depend on the network: no inventories are fetched unless asked for
if not os.environ.get("FRICTIONKIT_DOCS_INTERSPHINX"):
    intersphinx_mapping = {}

# autosummary's one-line summaries end at the first ". " that is not a known abbreviation:
# add the paper's ("Eqs. (1)-(2)", "Fig. 7", "Sec. V") so that the sentence is not cut there.
import sphinx.ext.autosummary as _autosummary  # noqa: E402

_autosummary.WELL_KNOWN_ABBREVIATIONS = (*_autosummary.WELL_KNOWN_ABBREVIATIONS, "Eq.", "Eqs.", "Fig.", "Figs.", "Sec.",
                                         " Eq.", " Eqs.", " Fig.", " Figs.", " Sec.", "(Eq.", "(Eqs.",
                                         "(Fig.", "(Sec.", " cf.", "(cf.", " vs.")

# -- Examples (sphinx-gallery) -----------------------------------------------------------
sphinx_gallery_conf = {
    "examples_dirs": "examples",
    "gallery_dirs": "auto_examples",
    "filename_pattern": r"/plot_",
    "within_subsection_order": "FileNameSortKey",
    "abort_on_example_error": True,
    "download_all_examples": False,
    "remove_config_comments": True,
    "min_reported_time": 1,
}

# -- HTML --------------------------------------------------------------------------------
html_theme = "alabaster"
html_static_path: list[str] = []
templates_path = ["_templates"]
html_title = "frictionkit"
