"""Steady-state laws: numpy methods against the compiled kernels, derivatives against finite
differences, the limits of Eq. (4), the table interpolant, and input validation."""
from __future__ import annotations

import math

import numpy as np
import pytest
from scipy.interpolate import PchipInterpolator

import rsf
from rsf import _kernels

V_GRID = np.geomspace(1e-6, 1e6, 61)


def _kernel_values(law, v):
    p = law.kernel_params
    out = np.array([_kernels.law_eval(float(x), p) for x in v])
    return out[:, 0] + law.mu_ref, out[:, 1]


LAWS = [
    rsf.HyperbolicLaw().bind(0.01),
    rsf.HyperbolicLaw(A=0.02, B=0.5, mu_inf=0.3),
    rsf.ViscoelasticLaw(k0=0.01),
    rsf.ViscoelasticLaw(f_th=2.0, zbar=0.2, k1=0.3, k2=0.5, eta_u=3.0, k0=0.1),
    rsf.LogLaw(mu0=0.6, a=0.01, b=0.015, v0=1e-6),
    rsf.TabulatedLaw(np.geomspace(1e-3, 1e3, 13), 1.0 - 0.05 * np.tanh(np.linspace(-2, 3, 13))),
]


@pytest.mark.parametrize("law", LAWS, ids=lambda law: law.name)
def test_kernel_matches_numpy(law):
    mu_k, w_k = _kernel_values(law, V_GRID)
    mu_n = law.mu_ss(V_GRID)
    w_n = law.weakening(V_GRID)
    np.testing.assert_allclose(mu_k, mu_n, rtol=1e-13, atol=1e-15)
    np.testing.assert_allclose(w_k, w_n, rtol=1e-9, atol=1e-15 * max(1.0, np.abs(w_n).max()))


@pytest.mark.parametrize("law", LAWS, ids=lambda law: law.name)
def test_derivative_matches_finite_differences(law):
    v = np.geomspace(1.3e-4, 0.77e4, 41)    # off the table's knots (kinks of W at its ends)
    h = 1e-6 * v
    fd = (law.mu_ss(v + h) - law.mu_ss(v - h)) / (2 * h)
    scale = np.abs(fd).max()
    np.testing.assert_allclose(law.dmu_ss(v), fd, rtol=1e-5, atol=1e-7 * scale)


def test_hyperbolic_is_eq10_with_paper_offset():
    law = rsf.HyperbolicLaw().bind(0.3)
    assert law.mu_inf == pytest.approx(1.0 - 0.1 * (0.3 + 0.1 + 0.9) / 2, abs=1e-15)
    v = np.array([0.0, 0.078, 1.0])
    np.testing.assert_allclose(law.mu_ss(v), law.mu_inf + 0.007 / (v + 0.078), rtol=1e-15)
    # W(v) = A v / (v + B)^2 peaks at v = B with A / (4 B)
    assert law.weakening(0.078) == pytest.approx(0.007 / (4 * 0.078), rel=1e-14)
    assert law.weakening_bounds() == (0.0, pytest.approx(0.007 / (4 * 0.078)))


def test_viscoelastic_limits_are_eq5_and_eq6():
    law = rsf.ViscoelasticLaw(k0=0.01)
    eq5 = 1.0 - 0.1 / 2 * (0.01 + 0.1)
    eq6 = 1.0 - 0.1 / 2 * (0.01 + 0.1 + 0.9)
    assert law.mu_ss(1e-9) == pytest.approx(eq5 - 1e-9, abs=1e-15)   # mu ~ Eq.(5) - V eta_u
    assert law.mu_ss(1e9) == pytest.approx(eq6, abs=1e-9)
    assert law.mu_ref == pytest.approx(eq6, abs=1e-15)
    # direct evaluation of Eq. (4) at moderate V
    v = np.array([0.05, 0.3, 2.0])
    y = 0.1 * 0.9 / v
    eq4 = 1.0 - (v - 0.1 * 0.9 / np.expm1(y)) - 0.1 / 2 * (0.01 + 0.1)
    np.testing.assert_allclose(law.mu_ss(v), eq4, rtol=1e-14)
    # velocity weakening with the characteristic 1/V tail: W ~ zbar k2 y / 12 for large V
    assert law.weakening(1e4) == pytest.approx(0.09 * (0.09 / 1e4) / 12, rel=1e-6)


def test_table_is_pchip_in_log_velocity_and_monotone():
    V = np.array([0.01, 0.1, 0.3, 1.0, 5.0, 20.0])
    mu = np.array([1.03, 1.02, 1.0, 0.97, 0.955, 0.951])
    law = rsf.TabulatedLaw(V[::-1], mu[::-1])           # unsorted input is sorted
    ref = PchipInterpolator(np.log(V), mu)
    v = np.geomspace(0.011, 19.0, 200)
    np.testing.assert_allclose(law.mu_ss(v), ref(np.log(v)), rtol=1e-14)
    mu_k, w_k = _kernel_values(law, v)
    np.testing.assert_allclose(mu_k, ref(np.log(v)), rtol=1e-13)
    np.testing.assert_allclose(w_k, -ref.derivative()(np.log(v)), rtol=1e-9, atol=1e-14)
    assert np.all(np.diff(law.mu_ss(v)) <= 0.0)          # monotone data stay monotone
    assert np.all(law.weakening(v) >= -1e-15)
    # flat outside the data
    assert law.mu_ss(1e-6) == pytest.approx(1.03) and law.mu_ss(1e6) == pytest.approx(0.951)
    assert law.weakening(1e-6) == 0.0 and law.weakening(1e6) == 0.0


def test_table_from_csv(tmp_path):
    import pandas as pd

    path = tmp_path / "micro.csv"
    pd.DataFrame({"V": [0.1, 1.0, 10.0, 0.05], "sigma": [1.0, 0.98, 0.96, 1.01],
                  "regime": ["steady", "steady", "steady", "stick-slip"]}).to_csv(path, index=False)
    law = rsf.TabulatedLaw.from_csv(path, where="regime == 'steady'")
    np.testing.assert_array_equal(law.V, [0.1, 1.0, 10.0])
    with pytest.raises(ValueError, match="column 'mu' not in"):
        rsf.TabulatedLaw.from_csv(path, mu_column="mu")


def _hyp_mu(v):
    return 0.95 + 0.007 / (v + 0.078)


def _hyp_dmu(v):
    return -0.007 / (v + 0.078) ** 2


@pytest.mark.slow  # (5-8 s: the default tier keeps under 5 minutes; CI runs the slow tier)
def test_callable_law_jitted_and_pure_python_give_the_paper_cycle():
    law = rsf.CallableLaw(_hyp_mu, _hyp_dmu)
    assert law.jitted
    ref = rsf.limit_cycle(rsf.SpringSlider(rsf.HyperbolicLaw(mu_inf=0.95), k0=0.3), 0.05)

    class Opaque:  # a callable numba cannot compile
        def __call__(self, v):
            return _hyp_mu(v)

    slow = rsf.CallableLaw(Opaque(), _hyp_dmu)
    assert not slow.jitted
    for candidate in (law, slow):
        r = rsf.limit_cycle(rsf.SpringSlider(candidate, k0=0.3), 0.05)
        assert r.converged
        assert r.sequence == ref.sequence
        assert r.sigma_max == pytest.approx(ref.sigma_max, abs=1e-12)
        assert r.sigma_min == pytest.approx(ref.sigma_min, abs=1e-12)
        assert r.period == pytest.approx(ref.period, rel=1e-8)


@pytest.mark.parametrize("make, match", [
    (lambda: rsf.HyperbolicLaw(B=0.0), "B must be a finite number > 0"),
    (lambda: rsf.HyperbolicLaw(A=-1.0), "A must be a finite number >= 0"),
    (lambda: rsf.HyperbolicLaw(mu_inf=float("nan")), "mu_inf must be a finite number"),
    (lambda: rsf.ViscoelasticLaw(k2=0.0), "k2 must be a finite number > 0"),
    (lambda: rsf.ViscoelasticLaw(eta_u=-1.0), "eta_u must be a finite number > 0"),
    (lambda: rsf.LogLaw(v0=0.0), "v0 must be a finite number > 0"),
    (lambda: rsf.LogLaw(b=-0.1), "b must be a finite number >= 0"),
    (lambda: rsf.TabulatedLaw([1.0], [1.0]), "at least 2"),
    (lambda: rsf.TabulatedLaw([1.0, 1.0], [1.0, 2.0]), "duplicate"),
    (lambda: rsf.TabulatedLaw([-1.0, 1.0], [1.0, 2.0]), "V must hold finite velocities > 0"),
    (lambda: rsf.TabulatedLaw([1.0, 2.0], [1.0]), "same length"),
    (lambda: rsf.CallableLaw(_hyp_mu, lambda v: 0.0), "does not match the derivative"),
    (lambda: rsf.CallableLaw(3.0, _hyp_dmu), "mu_ss_fn must be callable"),
])
def test_bad_law_parameters_raise_naming_the_parameter(make, match):
    with pytest.raises(ValueError, match=match):
        make()


def test_callable_law_accepts_a_correct_derivative_where_mu_dwarfs_v_times_its_slope():
    # mu = 0.6 - 0.005 v / (1 + v): at v = 1e-6 the central difference's round-off (a few
    # ulps of mu over 2h = 2e-11, about 1e-5) is far above a relative 1e-4 of the slope
    # (5e-7); the check must allow for it, and still refuse a wrong derivative there
    law = rsf.CallableLaw(lambda v: 0.6 - 0.005 * v / (1.0 + v), lambda v: -0.005 / (1.0 + v) ** 2)
    assert law.mu_ss(1e-6) == pytest.approx(0.6, abs=1e-8)
    with pytest.raises(ValueError, match="does not match the derivative"):
        rsf.CallableLaw(lambda v: 0.6 - 0.005 * v / (1.0 + v), lambda v: -0.0051 / (1.0 + v) ** 2)


def test_unbound_law_asks_for_k0():
    with pytest.raises(ValueError, match="bind"):
        rsf.HyperbolicLaw().mu_ss(1.0)
    assert rsf.SpringSlider(k0=0.2).law.mu_inf == pytest.approx(rsf.paper_mu_inf(0.2))
    assert math.isclose(rsf.paper_mu_inf(0.0), 0.95)


@pytest.mark.parametrize("law", LAWS + [rsf.LogLaw(mu0=0.6, a=0.015, b=0.01, v0=1e-6)], ids=lambda law: law.name)
def test_concavity_flag_is_true(law):
    # concave_sup claims phi(theta) concave, i.e. v W(v) non-decreasing, and is the sup of the
    # excess mu_ss - mu_ref (inf if unbounded); NaN claims nothing, and here is given exactly
    # where v W decreases somewhere (the table; a log law with b < a)
    v = np.geomspace(1e-10, 1e10, 20001)
    vw = v * law.weakening(v)
    non_decreasing = bool(np.all(np.diff(vw) >= -1e-12 * np.abs(vw).max()))
    sup = law.concave_sup
    assert non_decreasing == (not math.isnan(sup))
    excess = law.mu_ss(v) - law.mu_ref
    if math.isinf(sup):
        # the log law with b > a: unbounded, the excess grows as (b - a) ln(1/v) at small v
        slope = (excess[0] - excess[5000]) / math.log(v[5000] / v[0])
        assert sup > 0 and slope == pytest.approx(law.b - law.a, rel=1e-9) and slope > 0
    elif not math.isnan(sup):
        # a finite sup, approached as v -> 0 (measured within 6e-9 of it at v = 1e-10)
        assert excess.max() <= sup + 1e-15 and excess.max() >= (1.0 - 1e-7) * sup
