"""A wrong RS solver is caught: a small error put into rsf.limit_cycle's amplitude makes the
check against the independent Eq. (11) cycle (``check_limit_cycle`` of
test_rsf_eq11_independent.py, the same function that test runs) fail.  Each test passes
when the fault is caught, and fails if the check stops seeing it."""
from __future__ import annotations

import dataclasses
import sys
from pathlib import Path

import pytest

import rsf

sys.path.insert(0, str(Path(__file__).parent))
from test_rsf_eq11_independent import check_limit_cycle  # noqa: E402

#: The stick-slip case of the check (k0, V, Dc, A, B, mu_inf): amplitude 0.054
CASE = (0.3, 0.1, 0.06, 0.007, 0.078, 0.935)


def _amplitude_off_by(monkeypatch, rel: float) -> None:
    """rsf.limit_cycle's cycle widened by ``rel`` of its amplitude about its middle."""
    real = rsf.limit_cycle

    def faulty(*args, **kwargs):
        res = real(*args, **kwargs)
        half = 0.5 * rel * (res.sigma_max - res.sigma_min)
        return dataclasses.replace(res, sigma_max=res.sigma_max + half, sigma_min=res.sigma_min - half)
    monkeypatch.setattr(rsf, "limit_cycle", faulty)


def test_the_check_passes_without_the_fault(monkeypatch):
    _amplitude_off_by(monkeypatch, 0.0)  # (the wrapper itself changes nothing)
    check_limit_cycle(*CASE)


def test_an_amplitude_off_by_1e_9_of_itself_is_caught(monkeypatch):
    # 1e-9 of 0.054 is 5.4e-11 (2.7e-11 on each extremum): the check's 1e-11 sees it
    _amplitude_off_by(monkeypatch, 1e-9)
    with pytest.raises(AssertionError, match=r"± 1\.0e-11"):
        check_limit_cycle(*CASE)
