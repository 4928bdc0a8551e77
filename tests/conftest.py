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
