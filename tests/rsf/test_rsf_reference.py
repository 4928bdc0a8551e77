"""The event-driven solver (CVODE slides, root-found sticks and slips) against the
integrator-free reference (closed-form stick, quadrature slide, scipy roots)."""
from __future__ import annotations

import pytest

import rsf
from rsf.reference import check_assumptions, reference_cycle

TIGHT = rsf.SolverOptions(rtol=1e-12, atol=1e-14, cycle_rtol=1e-12)

CASES = [
    # k0, V, law, expected sequence (stick->slide cycles go through CVODE)
    (0.3, 0.1, None, ("stick->slip", "slip->stick")),
    (0.3, 0.05, None, ("stick->slide", "slide->slip", "slip->stick")),
    (0.3, 0.2026, None, ("stick->slip", "slip->stick")),               # 1e-3 below Vc
    (0.1, 0.02, None, ("stick->slide", "slide->slip", "slip->stick")),
    (0.01, 1.0, None, ("stick->slip", "slip->stick")),
    (0.01, 0.01, None, ("stick->slide", "slide->slip", "slip->stick")),
    (1e-4, 1000.0, None, ("stick->slip", "slip->stick")),
    (0.01, 0.5, "eq4", ("stick->slip", "slip->stick")),
    (0.01, 0.003, "eq4", ("stick->slide", "slide->slip", "slip->stick")),
]


@pytest.mark.parametrize("k0, V, law, sequence", CASES)
def test_limit_cycle_matches_quadrature_reference(k0, V, law, sequence):
    model = rsf.SpringSlider(rsf.ViscoelasticLaw() if law == "eq4" else rsf.HyperbolicLaw(), k0=k0)
    assert all(check_assumptions(model).values())
    ref = reference_cycle(model, V)
    got = rsf.limit_cycle(model, V, options=TIGHT)
    assert got.converged and got.regime == ref.regime == "stick-slip"
    assert got.sequence == ref.sequence == sequence
    assert abs(got.sigma_max - ref.sigma_max) < 1e-8
    assert abs(got.sigma_min - ref.sigma_min) < 1e-8
    assert abs(got.sigma_mean - ref.sigma_mean) < 1e-8
    assert got.period == pytest.approx(ref.period, rel=1e-8)
    assert got.sigma_min <= got.sigma_mean <= got.sigma_max


def test_plain_iteration_and_extrapolation_agree_with_reference():
    model = rsf.SpringSlider(k0=0.3)
    V = 0.2029043116776025 * (1 - 1e-4)
    ref = reference_cycle(model, V)
    fast = rsf.limit_cycle(model, V, options=rsf.SolverOptions(cycle_rtol=1e-12))
    slow = rsf.limit_cycle(model, V, options=rsf.SolverOptions(cycle_rtol=1e-12, accelerate=False,
                                                               max_cycles=100000))
    assert fast.converged and slow.converged
    assert fast.n_cycles < slow.n_cycles / 5
    for r in (fast, slow):
        # the cycle-to-cycle test bounds the distance to the fixed point only up to
        # 1/(1 - multiplier); the multiplier is ~0.998 here
        assert abs(r.sigma_max - ref.sigma_max) < 1e-8
        assert abs(r.sigma_min - ref.sigma_min) < 1e-8
