"""Limit-cycle detection: stopping rules, honest statuses, cycle bookkeeping, sweeps and
the Hopf scaling next to the bifurcation."""
from __future__ import annotations

import logging
import math

import numpy as np
import pytest

import rsf

ALLOWED = {("stick->slip", "slip->stick"), ("stick->slide", "slide->slip", "slip->stick")}


def test_unconverged_run_says_so(caplog):
    model = rsf.SpringSlider(k0=0.3)
    V = rsf.critical_velocity(model).Vc * (1 - 1e-5)
    with caplog.at_level(logging.WARNING, logger="rsf"):
        r = rsf.limit_cycle(model, V, options=rsf.SolverOptions(max_cycles=5, accelerate=False))
    assert not r.converged
    assert r.status == rsf.Status.MAX_CYCLES and not r.success
    assert r.regime == "unknown"
    assert "not converged" in r.message
    assert r.relative_change > 1e-8
    assert any("not converged" in rec.message for rec in caplog.records)
    assert r.to_frame().loc[0, "converged"] == False  # noqa: E712 (numpy bool)


def test_steady_run_stops_as_soon_as_steady():
    model = rsf.SpringSlider(k0=0.01)
    r = rsf.limit_cycle(model, 20.0)
    assert r.status == rsf.Status.STEADY and r.converged and r.regime == "steady"
    assert r.n_cycles == 0 and math.isnan(r.period)
    assert r.sigma_max == r.sigma_min == r.sigma_mean == pytest.approx(model.sigma_steady(20.0))
    stop = r.events[-1]
    assert stop.kind == "steady"
    # the run stopped where the outcome is certain: integrating on from that state gives a
    # single slide with no switch, converging to steady sliding
    tr = rsf.simulate(model, 20.0, t_end=stop.t + 50.0 * model.Dc / 20.0 * 100,
                      initial=rsf.InitialState(theta=stop.theta, sigma=stop.sigma))
    assert [e.kind for e in tr.events] == ["start", "end"]
    assert tr.sigma[-1] == pytest.approx(model.sigma_steady(20.0), abs=1e-12)
    # and without the certificate (a switch close by) CVODE's steady event ends the run
    # within cycle_rtol of the steady state
    tr2 = rsf.simulate(model, 20.0, t_end=1e3, stop_at_steady=True)
    assert tr2.status == rsf.Status.STEADY
    assert abs(math.log(model.Dc / tr2.events[-1].theta / 20.0)) <= 1e-8 * (1 + 1e-6)


@pytest.mark.parametrize("k0, V", [(0.3, 0.04), (0.3, 0.15), (0.01, 0.001), (0.01, 5.0)])
def test_cycle_sequences_and_mean(k0, V):
    r = rsf.limit_cycle(rsf.SpringSlider(k0=k0), V)
    assert r.converged and r.regime == "stick-slip"
    assert r.sequence in ALLOWED
    assert [e.kind for e in r.events] == list(r.sequence)
    assert r.sigma_min < r.sigma_mean < r.sigma_max
    assert r.events[0].sigma == pytest.approx(r.sigma_max, abs=1e-15)     # stick end
    assert r.events[-1].sigma == pytest.approx(r.sigma_min, abs=1e-15)    # slip landing


def test_mean_and_period_against_the_time_series():
    # stick-slip cycles without slides: the sampled time series is exact (linear sticks)
    model = rsf.SpringSlider(k0=0.3)
    r = rsf.limit_cycle(model, 0.1, options=rsf.SolverOptions(cycle_rtol=1e-13))
    tr = rsf.simulate(model, 0.1, t_end=80.0)
    lands = [e.t for e in tr.events if e.kind == "slip->stick"]
    t0, t1 = lands[-3], lands[-1]
    assert (t1 - t0) / 2 == pytest.approx(r.period, rel=1e-9)
    sel = (tr.t >= t0) & (tr.t <= t1)
    mean = np.trapezoid(tr.sigma[sel], tr.t[sel]) / (t1 - t0)
    assert mean == pytest.approx(r.sigma_mean, abs=1e-10)


def test_sweep_frame_has_the_required_columns():
    model = rsf.SpringSlider(k0=0.01)
    res = rsf.sweep(model, [0.1, 1.0, 20.0])
    df = res.to_frame()
    for col in ("k0", "Dc", "V", "regime", "sigma_max", "sigma_min", "sigma_mean", "period"):
        assert col in df.columns
    assert list(df.regime) == ["stick-slip", "stick-slip", "steady"]
    assert res.all_converged and res.status >= 0
    assert df.k0.eq(0.01).all() and df.Dc.eq(0.06).all()


def test_runaway_slip_is_reported():
    # log law without direct effect and b - a > k0 Dc: the first slip never arrests
    model = rsf.SpringSlider(rsf.LogLaw(mu0=0.6, a=0.0, b=0.02, v0=1.0), k0=0.1, Dc=0.06, a=0.0)
    r = rsf.limit_cycle(model, 1.0)
    assert not r.converged and r.status == rsf.Status.RUNAWAY
    assert "runaway" in r.message


def test_hopf_exponent_is_one_half_next_to_vc():
    fit = rsf.hopf_scaling(rsf.SpringSlider(k0=0.3), epsilon=[1e-7, 1e-6, 1e-5, 1e-4],
                           fit_max=1e-4)
    assert fit.converged
    assert fit.exponent == pytest.approx(0.5, abs=1e-3)
    assert fit.exponent_stderr < 1e-3
    # the amplitude vanishes continuously at Vc
    assert np.all(np.diff(fit.amplitude) > 0) and fit.amplitude.min() < 1e-4


def test_small_k0_amplitude_is_linear_away_from_vc_and_sigma_min_const():
    model = rsf.SpringSlider(k0=1e-4)
    fit = rsf.hopf_scaling(model, epsilon=[1e-3, 1e-2, 1e-1], fit_max=1.0)
    assert fit.exponent == pytest.approx(1.0, abs=0.05)
    np.testing.assert_allclose(fit.sigma_min, model.law.mu_inf, atol=1e-8)
