"""A wrong D_c is caught: the quick report's two critical slip distances, each 5 % off, make
the independent checks of test_compare_dc_independent.py (the very functions its tests run)
fail.  Each test passes when the fault is caught; with the fault removed it fails."""
from __future__ import annotations

import pytest

from test_compare_dc_independent import check_dc_a_minimum, check_dc_b_least_squares


@pytest.fixture
def rep(quick_report):
    return quick_report[0]   # tests/compare/conftest.py


def test_a_dc_a_off_by_5_percent_is_caught(rep, monkeypatch):
    # D_c (a), the extrema fit: the residual recomputed by the independent RS cycle is least
    # within 2e-3 of the reported D_c in ln D_c; from 5 % off, it is lower on one side
    monkeypatch.setitem(rep.values, "Dc", rep.values["Dc"] * 1.05)
    with pytest.raises(AssertionError, match=">"):
        check_dc_a_minimum(rep)


def test_a_dc_b_off_by_5_percent_is_caught(rep, monkeypatch):
    # D_c (b), one D_c for all k0 from micro's V^c: the root of the least squares' gradient,
    # recomputed here, to 1e-6
    monkeypatch.setitem(rep.values, "Dc_vc", rep.values["Dc_vc"] * 1.05)
    with pytest.raises(AssertionError, match="comparison failed"):
        check_dc_b_least_squares(rep)
