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
