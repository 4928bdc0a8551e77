"""Radiation damping eta_rad (QDYN's quasi-dynamic term): the linear stability (Jacobian
against finite differences of the independent right-hand side, the critical velocity
against its closed form), limit cycles for k < k_c, the stability boundary against a
simulation bracket, and time series against the independent DOP853 reference."""
from __future__ import annotations

import math
import sys
from pathlib import Path

import numpy as np
import pytest

import rsf
from rsf.analysis import stability_margin, steady_jacobian

sys.path.insert(0, str(Path(__file__).parent))
from _independent_rs import make_rhs, mu_at  # noqa: E402

B, DC, V0, MU0, A = 0.01, 10.0, 1.0, 0.6, 0.005
KC = (B - A) / DC


def _model(k_over_kc=0.8, eta=1e-4, state_law="aging"):
    return rsf.standard_rs(mu0=MU0, a=A, b=B, Dc=DC, k0=k_over_kc * KC, v0=V0, eta_rad=eta,
                           state_law=state_law)


@pytest.mark.parametrize("state_law, ref_law, extra", [
    ("aging", "aging", {}), ("slip", "slip", {}), ("prz", "prz", {}),
    (rsf.NagataLaw(c=1.5), "nagata", {"nagata_c": 1.5})])
@pytest.mark.parametrize("eta", [0.0, 3e-4])
def test_jacobian_matches_finite_differences_of_the_independent_rhs(state_law, ref_law, extra, eta):
    V = 3.0
    model = _model(1.3, eta, state_law)
    rhs = make_rhs(ref_law, a=A, b=B, Dc=DC, k0=model.k0, velocity=lambda t: V, eta=eta, **extra)
    theta_ss = (2.0 if ref_law == "prz" else 1.0) * DC / V
    y0 = np.array([math.log(V), math.log(theta_ss)])
    assert np.max(np.abs(rhs(0.0, y0))) < 1e-15
    h = 1e-6
    J = np.empty((2, 2))
    for j in range(2):
        dy = np.zeros(2)
        dy[j] = h
        J[:, j] = (np.array(rhs(0.0, y0 + dy)) - np.array(rhs(0.0, y0 - dy))) / (2 * h)
    J_tau = J * DC / V                                   # tau = V t / Dc
    np.testing.assert_allclose(steady_jacobian(model, V), J_tau, rtol=1e-7, atol=1e-9)


def test_critical_velocity_with_radiation_damping_has_its_closed_form():
    """Log law, aging: unstable where k0 Dc + eta V < b - a, so V_c = (b - a - k0 Dc)/eta."""
    for k_over_kc, eta in [(0.8, 1e-4), (0.5, 1e-3), (0.95, 3e-6)]:
        model = _model(k_over_kc, eta)
        cv = rsf.critical_velocity(model)
        assert cv.Vc == pytest.approx((B - A - model.K) / eta, rel=1e-13)
        assert cv.V_lower == 0.0 and not cv.is_stable(0.5 * cv.Vc) and cv.is_stable(2 * cv.Vc)
    assert math.isnan(rsf.critical_velocity(_model(1.2, 1e-4)).Vc)      # k > k_c: stable
    # no damping: the old answer (unstable at every V for k < k_c)
    assert rsf.critical_velocity(_model(0.8, 0.0)).Vc == math.inf


@pytest.mark.parametrize("eta", [1e-4, 1e-3])
def test_limit_cycles_for_k_below_kc_and_the_boundary_matches_a_simulation_bracket(eta):
    model = _model(0.8, eta)
    Vc = rsf.critical_velocity(model).Vc
    for V in (0.1 * Vc, 0.5 * Vc, 0.97 * Vc):
        r = rsf.limit_cycle(model, V)
        assert r.converged and r.regime == "stick-slip", (V, r.message)
        assert r.amplitude > 0 and math.isfinite(r.period)
    assert rsf.limit_cycle(model, 1.03 * Vc).regime == "steady"
    # the amplitude vanishes at the Hopf point (supercritical): smaller closer to Vc
    amp = [rsf.limit_cycle(model, f * Vc).amplitude for f in (0.9, 0.97)]
    assert amp[1] < amp[0]


def test_damping_turns_the_runaway_into_stick_slip():
    step = rsf.Protocol.velocity_steps([1.0, 10.0], [10.0])
    assert rsf.simulate(_model(0.8, 0.0), protocol=step, t_end=60.0).status == rsf.Status.RUNAWAY
    tr = rsf.simulate(_model(0.8, 1e-3), protocol=step, t_end=300.0)
    assert tr.success and tr.v.max() < 1e3
    assert sum(e.kind == "sigma_max" for e in tr.events) >= 3        # repeated slips


@pytest.mark.parametrize("state_law, ref_law, extra", [
    ("aging", "aging", {}), ("slip", "slip", {}), (rsf.NagataLaw(c=1.5), "nagata", {"nagata_c": 1.5})])
def test_damped_time_series_matches_independent_reference(state_law, ref_law, extra):
    eta = 1e-3
    model = _model(0.8, eta, state_law)
    te = np.linspace(0.0, 150.0, 301)
    vel = [1.0, 2.0]
    tr = rsf.simulate(model, protocol=rsf.Protocol.velocity_steps(vel, [10.0]), t_end=150.0,
                      t_eval=te)
    assert tr.success, tr.message
    mu = mu_at(ref_law, a=A, b=B, Dc=DC, k0=model.k0, v0=V0, mu0=MU0, velocities=vel,
               times=[0.0, 10.0], t_eval=te, eta=eta, **extra)
    assert np.max(np.abs(tr.sigma - mu)) < 1e-8
    X = np.where(te < 10.0, te, 10.0 + 2.0 * (te - 10.0))
    assert np.max(np.abs(tr.x - (X - (tr.sigma + eta * tr.v) / model.k0))) < 1e-7 / model.k0


def test_stability_margin_sign_and_bad_input():
    model = _model(0.8, 1e-4)
    assert stability_margin(model, 5.0) > 0.0 > stability_margin(model, 20.0)
    with pytest.raises(ValueError, match="eta_rad must be a finite number >= 0"):
        _model(0.8, -1.0)
    with pytest.raises(ValueError, match="eta_rad > 0 needs a direct effect"):
        rsf.SpringSlider(k0=0.01, eta_rad=1.0)
