"""Property-based tests (hypothesis) of rsf's public constructors and of compare's
Settings: any bad value is one ValueError, on one line, that names the parameter; any
good spring-slider gives a critical velocity that is finite and positive or NaN with its
status, and a steady friction that the law gives.

A few dozen examples each in the default run; ``-m slow`` runs more."""
from __future__ import annotations

import math

import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

import compare
import rsf

QUICK = settings(max_examples=30, deadline=None, suppress_health_check=[HealthCheck.too_slow])
MORE = settings(max_examples=300, deadline=None, suppress_health_check=[HealthCheck.too_slow])

#: values no numeric parameter accepts: non-finite, non-numbers, bools
NOT_A_NUMBER = st.one_of(st.just(math.nan), st.just(math.inf), st.just(-math.inf), st.booleans(),
                         st.text(max_size=3), st.lists(st.floats(), max_size=2))
NEGATIVE = st.floats(max_value=-1e-300, allow_nan=False, allow_infinity=False)

#: (constructor, parameter): each refuses every negative value and every non-number
CASES = [(rsf.SpringSlider, p, dict(k0=0.1)) for p in ("k0", "Dc", "a", "eta_rad")] + \
        [(rsf.HyperbolicLaw, p, {}) for p in ("A", "B")] + \
        [(rsf.LogLaw, p, {}) for p in ("a", "b", "v0")] + \
        [(rsf.ViscoelasticLaw, p, {}) for p in ("f_th", "zbar", "k1", "k2", "eta_u")] + \
        [(rsf.SolverOptions, p, {}) for p in ("rtol", "atol", "cycle_rtol", "max_cycles", "max_rhs_evals")] + \
        [(rsf.SecondState, p, dict(b2=0.01, Dc2=1.0)) for p in ("b2", "Dc2")] + \
        [(compare.Settings, p, {}) for p in ("zbar", "eps", "rtol", "cycle_rtol", "cycle_dt", "dc_grid",
                                             "bootstrap", "branch_points")]


def _check(make, name, value, base):
    with pytest.raises(ValueError) as info:
        make(**dict(base, **{name: value}))
    message = str(info.value)
    assert name in message.split(" ")[0] or message.startswith(name), message
    assert "\n" not in message and "np.float64" not in message


@QUICK
@given(case=st.sampled_from(CASES), value=st.one_of(NOT_A_NUMBER, NEGATIVE))
def test_a_bad_parameter_is_one_error_naming_it(case, value):
    make, name, base = case
    _check(make, name, value, base)


@pytest.mark.slow
@MORE
@given(case=st.sampled_from(CASES), value=st.one_of(NOT_A_NUMBER, NEGATIVE))
def test_a_bad_parameter_is_one_error_naming_it_more_examples(case, value):
    make, name, base = case
    _check(make, name, value, base)


@QUICK
@given(k0=st.floats(1e-3, 18.0), Dc=st.floats(1e-3, 1.0), V=st.floats(1e-3, 1e3))
def test_a_good_spring_slider_has_a_critical_velocity_or_none_and_the_law_s_steady_friction(k0, Dc, V):
    model = rsf.SpringSlider(k0=k0, Dc=Dc)
    cv = rsf.critical_velocity(model)
    assert (math.isfinite(cv.Vc) and cv.Vc > 0) or (math.isnan(cv.Vc) and cv.status == "stable at every V")
    law = model.law
    # Eq. (10): mu_ss = mu_inf + A / (V + B), decreasing in V, above mu_inf
    assert law.mu_ss(V) > law.mu_ss(2 * V) > law.mu_inf
    assert law.mu_ss(V) == pytest.approx(law.mu_inf + law.A / (V + law.B), rel=1e-14)
