"""rsf's a = 0 limit cycles with Eq. (10) against ``_independent_rs.eq11_cycle``: the same
cycle solved phase by phase in closed form (stick and slide ends) and one scipy root per slip,
sharing no code with rsf (rsf.reference, its own integrator-free reference, is rsf code)."""
from __future__ import annotations

import sys
from pathlib import Path

import pytest

import rsf

sys.path.insert(0, str(Path(__file__).parent))
from _independent_rs import eq11_cycle  # noqa: E402

TIGHT = rsf.SolverOptions(rtol=1e-12, atol=1e-14, cycle_rtol=1e-12)
SEQUENCE = {("stick", "slip"): ("stick->slip", "slip->stick"),
            ("stick", "slide", "slip"): ("stick->slide", "slide->slip", "slip->stick")}


@pytest.mark.parametrize("k0, V, Dc, A, B, mu_inf", [
    (0.3, 0.1, 0.06, 0.007, 0.078, 0.935),          # stick-slip
    (0.3, 0.05, 0.06, 0.007, 0.078, 0.935),         # stick, slide, slip
    (0.3, 0.2026, 0.06, 0.007, 0.078, 0.935),       # 1e-3 below V^c: the landing map's multiplier near 1
    (0.1, 0.02, 0.06, 0.007, 0.078, 0.945),
    (0.01, 1.0, 0.06, 0.007, 0.078, 0.9495),
    (1e-4, 1000.0, 0.06, 0.007, 0.078, 0.95),       # a slip down to theta ~ 0
    (0.1, 0.3, 0.09, 0.0075, 0.07, 0.89),           # the quick report's neighbourhood
    (0.1, 1.1, 0.09, 0.0075, 0.07, 0.89),           # steady
])
def test_limit_cycle_against_the_independent_eq11_cycle(k0, V, Dc, A, B, mu_inf):
    check_limit_cycle(k0, V, Dc, A, B, mu_inf)


def check_limit_cycle(k0, V, Dc, A, B, mu_inf):
    """rsf.limit_cycle at TIGHT against eq11_cycle: the regime, the phase sequence, the
    extrema and the amplitude to 1e-11 (also the check of tests/rsf/test_rsf_fault_injection.py)."""
    model = rsf.SpringSlider(rsf.HyperbolicLaw(A=A, B=B, mu_inf=mu_inf), k0=k0, Dc=Dc)
    ref = eq11_cycle(A=A, B=B, mu_inf=mu_inf, k0=k0, Dc=Dc, V=V)
    got = rsf.limit_cycle(model, V, options=TIGHT)
    assert got.converged and got.regime == ref["regime"]
    if ref["regime"] == "stick-slip":
        assert got.sequence == SEQUENCE[ref["sequence"]]
    assert got.sigma_max == pytest.approx(ref["sigma_max"], abs=1e-11)
    assert got.sigma_min == pytest.approx(ref["sigma_min"], abs=1e-11)
    assert got.amplitude == pytest.approx(ref["sigma_max"] - ref["sigma_min"], abs=2e-11)
