"""Stress tests over V from 1e-4 Vc to 1e3 Vc, k0 from 1e-4 to 1, Dc over four decades and
direct effects from tiny to large: every run converges or says why, no NaN, the regime
agrees with the stability analysis, and a time series started on the converged cycle shows
exactly the cycle's sequence of events, with every event on the threshold."""
from __future__ import annotations

import math

import numpy as np
import pytest

import rsf

ALLOWED_A0 = {("stick->slip", "slip->stick"), ("stick->slide", "slide->slip", "slip->stick")}
REL = [1e-4, 1e-3, 1e-2, 0.1, 0.3, 0.7, 0.99, 0.999, 1.001, 1.01, 2.0, 10.0, 1e2, 1e3]


def _velocities(cv, rel):
    if math.isfinite(cv.Vc):
        return [cv.Vc * r for r in rel]
    return list(np.geomspace(1e-4, 1e3, len(rel)))        # no instability: any V


def _expected_regime(cv, V):
    return "stick-slip" if cv.unstable and cv.V_lower < V < cv.Vc else "steady"


def _audit_cycle(model, V, r):
    """Re-run three periods from the converged cycle and check every event."""
    land = r.events[-1]
    tr = rsf.simulate(model, V, t_end=3.0 * r.period * (1 + 1e-9),
                      initial=rsf.InitialState(theta=land.theta, sigma=land.sigma))
    assert tr.success, tr.message
    kinds = [e.kind for e in tr.events if "->" in e.kind]
    n = len(r.sequence)
    assert kinds[: 3 * n] == list(r.sequence) * 3, kinds[: 3 * n + 2]
    law, K = model.law, model.K
    for e in tr.events:
        if "->" not in e.kind:
            continue
        u = model.Dc / e.theta
        phi = float(law.mu_ss(u)) if e.theta > 1e-240 * model.Dc else law.mu_ref
        assert e.sigma == pytest.approx(phi, abs=1e-11), e        # every switch on the threshold
        if e.kind == "slide->slip":
            assert abs(K - float(law.weakening(u))) < 1e-6 * K        # D = 0
    phi = law.mu_ss(np.maximum(model.Dc / tr.theta, 0.0))
    assert np.all(tr.sigma <= phi + 1e-11)
    assert np.all(tr.v >= 0.0)
    assert not np.any(np.isnan(tr.sigma)) and not np.any(np.isnan(tr.theta))


def _check(model, rel=REL, audit=True):
    cv = rsf.critical_velocity(model)
    for V in _velocities(cv, rel):
        r = rsf.limit_cycle(model, V)
        assert r.converged and r.status >= 0, (V, r.message)
        assert not any(math.isnan(x) for x in (r.sigma_max, r.sigma_min, r.sigma_mean)), V
        assert r.regime == _expected_regime(cv, V), (V, cv)
        if r.regime == "stick-slip":
            assert math.isfinite(r.period) and r.period > 0
            assert r.sigma_min <= r.sigma_mean <= r.sigma_max
            if model.a == 0.0:
                assert r.sequence in ALLOWED_A0, (V, r.sequence)
                if audit:
                    _audit_cycle(model, V, r)
            else:
                assert r.sequence == ("sigma_max", "sigma_min"), (V, r.sequence)


@pytest.mark.parametrize("k0", [1e-4, 1e-2, 0.3, 1.0])
def test_paper_model_over_velocities(k0):
    _check(rsf.SpringSlider(k0=k0))


@pytest.mark.parametrize("a", [1e-6, 0.1])
def test_direct_effect_tiny_and_large(a):
    model = rsf.SpringSlider(rsf.HyperbolicLaw(mu_inf=0.9), k0=0.3, a=a)
    _check(model, rel=[0.3, 0.9, 1.1, 10.0])


@pytest.mark.slow
@pytest.mark.parametrize("Dc", [6e-4, 6e-3, 6e-2, 6e-1, 6.0])
@pytest.mark.parametrize("k0", [1e-4, 1e-3, 1e-2, 0.1, 0.3, 1.0])
def test_grid_k0_Dc_V(k0, Dc):
    _check(rsf.SpringSlider(k0=k0, Dc=Dc))


@pytest.mark.slow
@pytest.mark.parametrize("law", [rsf.ViscoelasticLaw(), None])
@pytest.mark.parametrize("a", [1e-7, 1e-5, 1e-3, 1e-2, 0.1])
def test_grid_direct_effect(a, law):
    for k0 in (0.01, 0.3):
        model = rsf.SpringSlider(law or rsf.HyperbolicLaw(mu_inf=0.9), k0=k0, a=a)
        _check(model, rel=[1e-3, 0.1, 0.5, 0.9, 0.99, 1.01, 2.0, 1e3])


@pytest.mark.slow
@pytest.mark.parametrize("k0", [1e-3, 1e-2, 0.1])
def test_grid_eq4_law(k0):
    _check(rsf.SpringSlider(rsf.ViscoelasticLaw(), k0=k0))


# ---------------------------------------------------------------------------------------
# the options of issue 17: radiation damping, state laws, runaway, t_eval, load histories
# ---------------------------------------------------------------------------------------
REL_DAMPED = [1e-3, 0.1, 0.5, 0.9, 1.1, 10.0, 1e3]


@pytest.mark.parametrize("state_law", ["aging", "slip", "prz", rsf.NagataLaw(c=1.0)])
def test_radiation_damping_over_velocities(state_law):
    """Log law below its critical stiffness: with damping every run converges, to cycles
    below Vc and to steady sliding above it, as the stability analysis says."""
    model = rsf.standard_rs(mu0=0.6, a=0.005, b=0.01, Dc=10.0, k0=0.0004, v0=1.0,
                            eta_rad=1e-4, state_law=state_law)
    _check(model, rel=REL_DAMPED)


def test_radiation_damping_on_the_paper_law():
    model = rsf.SpringSlider(rsf.HyperbolicLaw(mu_inf=0.9), k0=0.3, a=1e-3, eta_rad=1e-2)
    _check(model, rel=[0.3, 0.9, 1.1, 10.0])


@pytest.mark.parametrize("state_law", ["aging", "slip", "prz", rsf.NagataLaw(c=2.0)])
def test_velocity_steps_never_hang(state_law):
    """Below, near and above k_c, steps up by 1e1 .. 1e3: each run ends (reached the end or
    ran away) within a step budget of 20 000 right-hand-side evaluations (at most 3561
    measured; a hang would end with STEP_BUDGET -- this was a 5 s wall-clock limit), with
    a finite trajectory and the runaway time in its message."""
    budget = rsf.SolverOptions(max_rhs_evals=20_000)
    for k_over_kc in (0.5, 0.9, 1.1, 3.0):
        for v1 in (10.0, 1e3):
            model = rsf.standard_rs(mu0=0.6, a=0.005, b=0.01, Dc=10.0, k0=k_over_kc * 5e-4,
                                    v0=1.0, state_law=state_law)
            tr = rsf.simulate(model, protocol=rsf.Protocol.velocity_steps([1.0, v1, 1.0], [10, 20]),
                              t_end=100.0, options=budget)
            assert tr.status in (rsf.Status.TIME_LIMIT, rsf.Status.RUNAWAY), tr.message
            assert np.all(np.isfinite(tr.sigma)) and np.all(np.isfinite(tr.v))
            if tr.status == rsf.Status.RUNAWAY:
                assert f"t = {tr.t[-1]:.10g}" in tr.message and tr.v[-1] >= 1e3 * v1 * (1 - 1e-9)


def test_t_eval_on_random_grids(rng):
    """Random output grids (including 0, segment boundaries and t_end): every requested
    time comes back exactly, once, with finite values; the events are those of the run
    without t_eval."""
    model = rsf.standard_rs(mu0=0.6, a=0.005, b=0.01, Dc=10.0, k0=0.002, v0=1.0, state_law="slip")
    proto = rsf.Protocol.velocity_steps([1.0, 3.0, 0.0, 1.0], [10.0, 20.0, 15.0])
    full = rsf.simulate(model, protocol=proto, t_end=80.0)
    for n in (1, 7, 500):
        te = np.unique(np.concatenate([rng.uniform(0.0, 80.0, n), [0.0, 10.0, 30.0, 45.0, 80.0]]))
        tr = rsf.simulate(model, protocol=proto, t_end=80.0, t_eval=te)
        assert tr.success and np.array_equal(tr.t, te)
        assert np.all(np.isfinite(tr.sigma)) and np.all(np.isfinite(tr.theta))
        assert [e.kind for e in tr.events] == [e.kind for e in full.events]
        assert np.allclose([e.t for e in tr.events], [e.t for e in full.events], rtol=0, atol=1e-9)
        # the samples at the changes of driving are the states of the 'drive' events
        for e in tr.events:
            if e.kind == "drive":
                i = int(np.searchsorted(te, e.t))
                assert te[i] == e.t and abs(tr.sigma[i] - e.sigma) < 1e-12


def test_sampled_histories_stay_finite(rng):
    model = rsf.standard_rs(mu0=0.6, a=0.005, b=0.01, Dc=10.0, k0=0.002, v0=1.0)
    for _ in range(3):
        ts = np.concatenate([[0.0], np.cumsum(rng.uniform(0.5, 5.0, 20))])
        vs = np.exp(rng.uniform(-2.0, 2.0, ts.size))
        tr = rsf.simulate(model, protocol=rsf.Protocol.sampled(ts, vs), t_end=float(ts[-1]) + 5.0)
        assert tr.success, tr.message
        assert np.all(np.isfinite(tr.sigma)) and np.all(tr.v > 0)


@pytest.mark.slow
@pytest.mark.parametrize("eta", [1e-6, 1e-4, 1e-2])
@pytest.mark.parametrize("k_over_kc", [0.2, 0.8, 0.95])
@pytest.mark.parametrize("state_law", ["aging", "slip"])
def test_grid_radiation_damping(eta, k_over_kc, state_law):
    model = rsf.standard_rs(mu0=0.6, a=0.005, b=0.01, Dc=10.0, k0=k_over_kc * 5e-4, v0=1.0,
                            eta_rad=eta, state_law=state_law)
    _check(model, rel=REL_DAMPED)
