"""Shared test set-up: a non-interactive plotting backend, seeded generators and
strict floating-point errors inside the test functions themselves."""
from __future__ import annotations

import os

os.environ.setdefault("MPLBACKEND", "Agg")

import numpy as np
import pytest


@pytest.fixture(autouse=True)
def _strict_numpy():
    """Turn numpy floating-point warnings into errors for the duration of a test."""
    old = np.seterr(all="raise", under="ignore")
    try:
        yield
    finally:
        np.seterr(**old)


@pytest.fixture
def rng() -> np.random.Generator:
    """A seeded generator, so that every stochastic test is reproducible."""
    return np.random.default_rng(20151001)


EXAMPLES_DIR = os.path.join(os.path.dirname(os.path.dirname(os.path.abspath(__file__))), "docs", "examples")


@pytest.fixture
def run_example(tmp_path, monkeypatch):
    """Run a docs example (a sphinx-gallery script of ``docs/examples``) as a script, in an
    empty working directory, and return its namespace and the matplotlib figures it drew
    (what the gallery shows).  The figures are closed afterwards."""
    import runpy

    import matplotlib.pyplot as plt

    def run(path):
        monkeypatch.chdir(tmp_path)
        plt.close("all")
        namespace = runpy.run_path(str(path), run_name="__main__")
        figures = [plt.figure(n) for n in plt.get_fignums()]
        return namespace, figures

    yield run
    plt.close("all")
