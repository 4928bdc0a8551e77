"""Time series: protocols (velocity steps, slide-hold-slide), the direct effect a > 0
against the a = 0 phase model, against scipy's solve_ivp, and the classic
rate-and-state responses."""
from __future__ import annotations

import math

import numpy as np
import pytest
from scipy.integrate import solve_ivp

import rsf


def test_a_to_zero_converges_to_the_phase_model():
    law = rsf.HyperbolicLaw(mu_inf=0.9)
    ref = rsf.limit_cycle(rsf.SpringSlider(law, k0=0.3), 0.1)
    errors = []
    for a in (1e-4, 1e-5, 1e-6):
        r = rsf.limit_cycle(rsf.SpringSlider(law, k0=0.3, a=a), 0.1)
        assert r.converged and r.regime == "stick-slip"
        errors.append(max(abs(r.sigma_max - ref.sigma_max), abs(r.sigma_min - ref.sigma_min)))
    # first order in a: each decade of a gains a decade of agreement
    assert errors[2] < 1e-5
    assert 5 < errors[0] / errors[1] < 20 and 5 < errors[1] / errors[2] < 20


def _scipy_rs(model, V1, V2, t_step, t_eval, y0):
    """Independent a > 0 integration in physical time (LSODA)."""
    law = model.law
    a, k0, Dc = model.a, model.k0, model.Dc

    def rhs(t, y):
        lv, lth = y
        v, th = math.exp(lv), math.exp(lth)
        u = Dc / th
        w = float(law.weakening(u))
        thdot = 1 - th * v / Dc if model.state_law == "aging" else -(th * v / Dc) * math.log(th * v / Dc)
        V = V1 if t < t_step else V2
        return [(k0 * (V - v) - (w + a) * thdot / th) / a, thdot / th]

    sol1 = solve_ivp(rhs, (0, t_step), y0, method="LSODA", rtol=1e-11, atol=1e-13, dense_output=True)
    sol2 = solve_ivp(rhs, (t_step, t_eval[-1]), sol1.y[:, -1], method="LSODA", rtol=1e-11,
                     atol=1e-13, dense_output=True)
    out = np.where(t_eval[None, :] < t_step, sol1.sol(np.minimum(t_eval, t_step)),
                   sol2.sol(np.maximum(t_eval, t_step)))
    lv, lth = out
    u = Dc / np.exp(lth)
    return law.mu_ss(u) + a * np.log(np.exp(lv) / u)


@pytest.mark.parametrize("state_law", ["aging", "slip"])
def test_velocity_step_against_scipy(state_law):
    model = rsf.standard_rs(k0=2e3, state_law=state_law)         # stable: k0 Dc > b - a
    proto = rsf.Protocol.velocity_steps([1e-6, 1e-5], [20.0])
    tr = rsf.simulate(model, protocol=proto, t_end=40.0,
                      initial=rsf.InitialState(perturbation=0.0),
                      options=rsf.SolverOptions(rtol=1e-11, atol=1e-13))
    assert tr.success
    t = tr.t[(tr.t > 0) & (np.abs(tr.t - 20.0) > 1e-9)][::5]
    sigma = np.interp(t, tr.t, tr.sigma)
    ref = _scipy_rs(model, 1e-6, 1e-5, 20.0, t, [math.log(1e-6), math.log(model.Dc / 1e-6)])
    np.testing.assert_allclose(sigma, ref, atol=2e-8)
    # the new steady state
    assert tr.sigma[-1] == pytest.approx(model.sigma_steady(1e-5), abs=1e-6)


def test_stiff_velocity_step_peak_is_the_direct_effect():
    a, b = 0.01, 0.015
    model = rsf.standard_rs(a=a, b=b, k0=1e8)                    # k0 Dc = 1e3 >> a, b
    proto = rsf.Protocol.velocity_steps([1e-6, 1e-5], [10.0])
    tr = rsf.simulate(model, protocol=proto, t_end=20.0, initial=rsf.InitialState(perturbation=0.0))
    before = model.sigma_steady(1e-6)
    assert tr.sigma.max() - before == pytest.approx(a * math.log(10.0), rel=1e-3)
    assert tr.sigma[-1] - before == pytest.approx((a - b) * math.log(10.0), abs=1e-5)


@pytest.mark.parametrize("a", [0.0, 2e-3])
def test_slide_hold_slide_peak_grows_with_hold(a):
    model = rsf.SpringSlider(rsf.HyperbolicLaw(mu_inf=0.9), k0=0.3, a=a)
    steady = model.sigma_steady(1.0)
    peaks = []
    for hold in (0.3, 3.0, 30.0):
        tr = rsf.simulate(model, protocol=rsf.Protocol.slide_hold_slide(1.0, 20.0, hold),
                          t_end=40.0 + hold)
        assert tr.success
        held = (tr.t > 20.0 + 1e-9) & (tr.t < 20.0 + hold - 1e-9)
        if a == 0.0:        # no creep without direct effect: the force stays put in the hold
            assert np.ptp(tr.sigma[held]) < 1e-12
        peaks.append(tr.sigma[tr.t > 20.0 + hold].max() - steady)
    assert 0 < peaks[0] < peaks[1] < peaks[2]


def test_phase_model_velocity_step_reaches_new_steady_state():
    model = rsf.SpringSlider(k0=0.3)
    proto = rsf.Protocol.velocity_steps([1.0, 3.0], [20.0])
    tr = rsf.simulate(model, protocol=proto, t_end=60.0)
    assert tr.success
    assert tr.sigma[-1] == pytest.approx(model.sigma_steady(3.0), abs=1e-9)
    # x follows the spring: sigma = k0 (X(t) - x)
    X = np.array([proto.load_point(t) for t in tr.t])
    np.testing.assert_allclose(model.k0 * (X - tr.x), tr.sigma, atol=1e-9)


def test_time_series_respects_the_threshold_and_signs():
    model = rsf.SpringSlider(k0=0.3)
    tr = rsf.simulate(model, 0.04, t_end=60.0)
    phi = model.law.mu_ss(model.Dc / tr.theta)
    assert np.all(tr.sigma <= phi + 1e-12)                # never above the threshold
    assert np.all(tr.v >= 0)
    # v is finite except where a slide ends in a slip (D -> 0, v -> inf)
    slide_ends = [e.t for e in tr.events if e.kind == "slide->slip"]
    assert set(tr.t[~np.isfinite(tr.v)]) <= set(slide_ends)
    X = 0.04 * tr.t
    np.testing.assert_allclose(model.k0 * (X - tr.x), tr.sigma, atol=1e-10)
    kinds = [e.kind for e in tr.events if "->" in e.kind]
    body = kinds[kinds.index("slip->stick") + 1:]
    assert body[: 3 * (len(body) // 3)] == ["stick->slide", "slide->slip", "slip->stick"] * (len(body) // 3)


@pytest.mark.parametrize("make, match", [
    (lambda: rsf.SpringSlider(k0=0.0), "k0 must be a finite number > 0"),
    (lambda: rsf.SpringSlider(Dc=-1.0), "Dc must be a finite number > 0"),
    (lambda: rsf.SpringSlider(a=-0.1), "a must be a finite number >= 0"),
    (lambda: rsf.SpringSlider(state_law="slip"), "needs a direct effect a > 0"),
    (lambda: rsf.SpringSlider(state_law="ruina"), "state_law must be one of"),
    (lambda: rsf.SpringSlider(law="paper"), "law must be a SteadyStateLaw"),
    (lambda: rsf.SolverOptions(rtol=1.0), r"rtol must lie in \[1e-14, 0.01\]"),
    (lambda: rsf.SolverOptions(cycle_rtol=0.0), "cycle_rtol must lie in"),
    (lambda: rsf.SolverOptions(max_cycles=0), "max_cycles must be an integer >= 1"),
    (lambda: rsf.SolverOptions(method="RK45"), "method must be one of"),
    (lambda: rsf.Protocol([0.0, 1.0], [1.0, -1.0]), "velocities must be finite and >= 0"),
    (lambda: rsf.Protocol([1.0], [1.0]), "times\\[0\\] must be 0"),
    (lambda: rsf.Protocol.slide_hold_slide(1.0, 1.0, 0.0), "hold_time must be a finite number > 0"),
    (lambda: rsf.InitialState(theta=0.0), "theta must be a finite number > 0"),
    (lambda: rsf.simulate(rsf.SpringSlider(), V=-1.0, t_end=1.0), "V must be a finite number > 0"),
    (lambda: rsf.simulate(rsf.SpringSlider(), V=1.0, t_end=0.0), "t_end must be a finite number > 0"),
    (lambda: rsf.limit_cycle(rsf.SpringSlider(), float("inf")), "V must be a finite number > 0"),
    (lambda: rsf.sweep(rsf.SpringSlider(), []), "at least one velocity"),
    (lambda: rsf.critical_velocity(rsf.HyperbolicLaw(), k0=0.01, Dc=0.0), "Dc must be a finite number > 0"),
])
def test_bad_input_raises_naming_the_parameter(make, match):
    with pytest.raises(ValueError, match=match):
        make()
