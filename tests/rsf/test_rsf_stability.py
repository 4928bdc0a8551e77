"""Linear stability of steady sliding against the integrated dynamics, and the
invariance under (k0, Dc) -> (k0 lambda, Dc / lambda)."""
from __future__ import annotations

import math

import numpy as np
import pytest

import rsf

K0S = [0.3, 0.1, 0.01, 0.001, 0.0001]


@pytest.mark.parametrize("k0", K0S)
def test_quadratic_roots(k0):
    cv = rsf.critical_velocity(rsf.HyperbolicLaw(), k0=k0, Dc=0.06)
    K, A, B = k0 * 0.06, 0.007, 0.078
    for V in (cv.Vc, cv.V_lower):
        assert K * (V + B) ** 2 == pytest.approx(A * V, rel=1e-12)
    assert cv.Vc * cv.V_lower == pytest.approx(B * B, rel=1e-12)
    # the same roots from the generic scan of W(V) = K (a callable law)
    law = rsf.CallableLaw(lambda v: 0.007 / (v + 0.078), lambda v: -0.007 / (v + 0.078) ** 2)
    scan = rsf.critical_velocity(law, k0=k0, Dc=0.06)
    assert scan.method == "scan"
    assert scan.Vc == pytest.approx(cv.Vc, rel=1e-10)
    assert scan.V_lower == pytest.approx(cv.V_lower, rel=1e-10)


@pytest.mark.parametrize("k0", K0S)
def test_regime_changes_at_the_critical_velocity(k0):
    model = rsf.SpringSlider(k0=k0)
    cv = rsf.critical_velocity(model)
    below = rsf.limit_cycle(model, cv.Vc * (1 - 1e-3))
    above = rsf.limit_cycle(model, cv.Vc * (1 + 1e-3))
    assert below.converged and below.regime == "stick-slip"
    assert above.converged and above.regime == "steady"
    assert above.sigma_mean == pytest.approx(model.sigma_steady(cv.Vc * (1 + 1e-3)), abs=1e-14)


@pytest.mark.parametrize("k0", [0.3, 0.1, 0.01])
def test_lower_root_bounds_stick_slip_from_below(k0):
    # from the (perturbed) steady state, stick-slip exists only inside (V_lower, Vc)
    model = rsf.SpringSlider(k0=k0)
    cv = rsf.critical_velocity(model)
    inside = rsf.limit_cycle(model, cv.V_lower * 1.01)
    below = rsf.limit_cycle(model, cv.V_lower * 0.99)
    assert inside.regime == "stick-slip" and below.regime == "steady"


def test_no_instability_above_the_stiffness_bound():
    k0 = 0.007 / (4 * 0.078) / 0.06 * 1.01          # K just above A / (4B)
    model = rsf.SpringSlider(k0=k0)
    cv = rsf.critical_velocity(model)
    assert math.isnan(cv.Vc) and cv.unstable == ()
    for V in (1e-3, 0.078, 10.0):
        assert rsf.limit_cycle(model, V).regime == "steady"


def test_direct_effect_does_not_move_the_critical_velocity():
    model = rsf.SpringSlider(rsf.HyperbolicLaw(mu_inf=0.9), k0=0.3, a=1e-3)
    Vc = rsf.critical_velocity(model).Vc
    assert rsf.limit_cycle(model, Vc * 0.98).regime == "stick-slip"
    assert rsf.limit_cycle(model, Vc * 1.02).regime == "steady"


def test_eq4_law_critical_velocity_matches_dynamics():
    model = rsf.SpringSlider(rsf.ViscoelasticLaw(), k0=0.01)
    cv = rsf.critical_velocity(model)
    assert cv.method == "scan"
    assert float(model.law.weakening(cv.Vc)) == pytest.approx(model.K, rel=1e-10)
    assert rsf.limit_cycle(model, cv.Vc * (1 - 1e-3)).regime == "stick-slip"
    assert rsf.limit_cycle(model, cv.Vc * (1 + 1e-3)).regime == "steady"


@pytest.mark.parametrize("scale", [10.0, 0.1, 1e-3])
@pytest.mark.parametrize("k0, V", [(0.3, 0.1), (0.3, 0.05), (0.01, 0.01), (0.01, 5.0)])
def test_Dc_enters_only_through_k0_Dc(k0, V, scale):
    law = rsf.HyperbolicLaw(mu_inf=0.9)          # explicit: the paper's offset depends on k0
    opts = rsf.SolverOptions(rtol=1e-12, atol=1e-14, cycle_rtol=1e-12)
    base = rsf.limit_cycle(rsf.SpringSlider(law, k0=k0, Dc=0.06), V, options=opts)
    scaled = rsf.limit_cycle(rsf.SpringSlider(law, k0=k0 * scale, Dc=0.06 / scale), V, options=opts)
    assert base.sequence == scaled.sequence
    assert scaled.sigma_max == pytest.approx(base.sigma_max, abs=1e-11)
    assert scaled.sigma_min == pytest.approx(base.sigma_min, abs=1e-11)
    assert scaled.sigma_mean == pytest.approx(base.sigma_mean, abs=1e-10)
    assert scaled.period == pytest.approx(base.period / scale, rel=1e-9)   # t' = t / scale
    assert (rsf.critical_velocity(law, k0=k0 * scale, Dc=0.06 / scale).Vc
            == pytest.approx(rsf.critical_velocity(law, k0=k0, Dc=0.06).Vc, rel=1e-12))


def test_time_series_invariance():
    law = rsf.HyperbolicLaw(mu_inf=0.9)
    a = rsf.simulate(rsf.SpringSlider(law, k0=0.3, Dc=0.06), V=0.05, t_end=20.0)
    b = rsf.simulate(rsf.SpringSlider(law, k0=3.0, Dc=0.006), V=0.05, t_end=2.0)
    ea, eb = a.events_frame(), b.events_frame()
    assert list(ea.kind) == list(eb.kind)
    np.testing.assert_allclose(eb.t * 10.0, ea.t, rtol=1e-9, atol=1e-12)
    np.testing.assert_allclose(eb.sigma, ea.sigma, atol=1e-10)
    np.testing.assert_allclose(eb.theta * 10.0, ea.theta, rtol=1e-8)


@pytest.mark.parametrize("k0", [0.3, 0.01])
def test_below_the_lower_root_every_start_ends_steady(k0):
    # no coexisting stick-slip cycle below V_lower: stuck, over-stressed and on-threshold
    # starts over twelve decades of theta all end in steady sliding
    model = rsf.SpringSlider(k0=k0)
    V = rsf.critical_velocity(model).V_lower * 0.9
    for theta in np.geomspace(1e-6, 1e6, 13) * model.Dc / V:
        phi = float(model.law.mu_ss(model.Dc / theta))
        for offset in (-0.05, 0.0, 0.01):
            r = rsf.limit_cycle(model, V, initial=rsf.InitialState(theta=theta, sigma=phi + offset))
            assert r.regime == "steady" and r.converged, (theta, offset, r.message)
