"""The question-level API: which method answers each question by default, what each row
says about its method and its error, and what happens before anything is computed."""
from __future__ import annotations

import logging
import math

import pandas as pd
import pytest

import micro
from micro import api
from micro.cohort import cycle_cohorts

SMALL = micro.Model(k0=1e-3)
#: the cohort method at twice its default step and cell: a cycle at small k0 in seconds
COARSE = micro.Cohort(dt=0.02, h=0.01, tol=1e-4)


@pytest.fixture
def cohort_calls(monkeypatch):
    """Every call of the cohort method through the API (the real method runs)."""
    calls = []

    def spy(model, V, **kw):
        calls.append((model, V, kw))
        return cycle_cohorts(model, V, **kw)

    monkeypatch.setattr(api, "cycle_cohorts", spy)
    return calls


def test_stable_steady_sliding_comes_from_the_renewal_chain(cohort_calls):
    model = micro.Model(k0=0.1)
    res = micro.stationary(model, 5.0)
    exact = micro.steady_sliding(model, 5.0, growth_rate=False)
    assert res.method == "renewal" and res.regime == "steady" and not cohort_calls
    assert res.sigma_mean == float(exact.sigma)
    assert res.discretisation_error == pytest.approx(float(exact.sigma_error)) and res.discretisation_error < 1e-9
    assert res.to_dict()["method"] == "renewal"


def test_a_stick_slip_cycle_comes_from_the_cohort_method_with_its_discretisation_error(cohort_calls):
    vc = micro.critical_velocity(SMALL).Vc
    res = micro.stationary(SMALL, 0.3 * vc, method=micro.Auto(cohort=COARSE))
    assert res.method == "cohort" and res.regime == "stick-slip" and len(cohort_calls) == 1
    assert cohort_calls[0][2]["dt"] == 0.02 and cohort_calls[0][2]["h"] == 0.01
    # the error bound: the change from the transient at twice dt and h, plus both fixed points' errors
    coarse = res.cycle.coarse
    change = max(abs(res.sigma_max - coarse.sigma_max), abs(res.sigma_min - coarse.sigma_min))
    assert res.discretisation_error == pytest.approx(change + coarse.error + res.sigma_stderr, rel=1e-12)
    assert 0.0 < res.discretisation_error < 2e-3
    # where shocks are total sigma_min is exactly f_th - kappa zbar (docs/reference/micro_model.md)
    exact_min = SMALL.f_th - SMALL.kappa * SMALL.zbar
    assert abs(res.sigma_min - exact_min) <= res.discretisation_error
    assert "discretisation error at most" in res.message


def test_close_to_vc_the_discretisation_error_is_not_known(cohort_calls, monkeypatch):
    # (the rule at a threshold moved out to d = 0.2: at the real one, d = 0.02, a cycle at
    # half of it costs minutes)
    monkeypatch.setattr(api, "NEAR_VC", 0.2)
    vc = micro.critical_velocity(SMALL).Vc
    res = micro.stationary(SMALL, (1.0 - 0.5 * api.NEAR_VC) * vc, method=micro.Auto(cohort=COARSE))
    assert res.method == "cohort"
    assert math.isnan(res.discretisation_error)
    assert "discretisation error not known" in res.message and "covers the iteration only" in res.message


@pytest.mark.slow
@pytest.mark.parametrize("k0, d", [(0.1, 0.1), (0.01, 0.05)])
def test_close_to_vc_the_bound_covers_the_next_finer_level(k0, d):
    """Between d = 0.2 and micro.api.NEAR_VC the reported bound covers the row's distance
    from a finer level's Richardson limit (dt and cell halved, first order: the most
    cautious; studies/micro_transition_error_check.py has two finer levels)."""
    assert d >= api.NEAR_VC
    model = micro.Model(k0=k0)
    V = (1.0 - d) * micro.critical_velocity(model).Vc
    row = micro.stationary(model, V, method=micro.Cohort(dt=0.02, tol=1e-4), warn=False)
    assert math.isfinite(row.discretisation_error) and "discretisation error at most" in row.message
    fine = cycle_cohorts(model, V, dt=0.01, h=row.eps / 2, tol=1e-4, start=row.cycle)
    assert fine.converged and math.isfinite(fine.error)
    for name in ("sigma_max", "sigma_min"):
        off = 2.0 * abs(getattr(row, name) - getattr(fine, name)) + fine.error
        assert off <= row.discretisation_error, (name, off, row.discretisation_error)
    # and the bound is not vacuous: below a fiftieth of the amplitude
    assert row.discretisation_error < 0.02 * (row.sigma_max - row.sigma_min)


def test_fokker_planck_only_where_the_cohort_method_does_not_apply_or_its_state_is_asked_for(cohort_calls):
    det = micro.Model(k0=0.3, jumps=micro.Deterministic(0.1))
    res = micro.stationary(det, 0.1, numerics=micro.FP(eps=0.025), convergence=micro.Convergence(rtol=5e-2, t_max=20.0),
                           warn=False)
    assert res.method == "fp" and "needs exponential jumps" in res.message
    kept = micro.stationary(micro.Model(k0=0.3), 0.1, numerics=micro.FP(eps=0.025), keep_grid=True,
                            convergence=micro.Convergence(rtol=5e-2, t_max=5.0), warn=False)
    assert kept.method == "fp" and kept.grid is not None
    assert not cohort_calls


def test_transients_run_on_the_fokker_planck_equation():
    run = micro.simulate(micro.Model(k0=0.3), 1.0, duration=0.5, numerics=micro.FP(eps=0.025))
    assert run.method == "fp"
    table = micro.slide_hold_slide(micro.Model(k0=0.3), 5.0, [0.5, 1.0], numerics=micro.FP(eps=0.025),
                                   convergence=micro.Convergence(rtol=5e-2))
    assert list(table.method) == ["fp", "fp"]


def test_critical_velocity_default_is_the_renewal_chain():
    model = micro.Model(k0=0.1)
    auto = micro.critical_velocity(model)
    assert auto.method == "renewal" and auto.to_dict()["method"] == "renewal"
    assert micro.critical_velocity(model, method=micro.Renewal(tol=1e-11)).Vc == auto.Vc


def test_a_slow_drive_is_announced_before_the_first_cycle(monkeypatch, caplog):
    def refuse(*args, **kw):
        raise RuntimeError("no cycle was to be computed in this test")

    monkeypatch.setattr(api, "cycle_cohorts", refuse)
    model = micro.Model(k0=1e-4)
    assert api.cohort_steps_per_cycle(model, 0.01, 0.01) > api.SLOW_CYCLE_STEPS
    with caplog.at_level(logging.WARNING, logger="micro.api"), pytest.raises(RuntimeError, match="no cycle"):
        micro.stationary(model, 0.01)
    assert "a slow drive for the cohort method" in caplog.text


@pytest.mark.parametrize("bad, match", [
    (dict(method="cycle"), "retired"),
    (dict(method="renewal"), "stationary: method must be one of"),
    (dict(method=micro.Cohort(), keep_grid=True), "belong to method='fp'"),
    (dict(method=micro.Cohort(h=0.5)), "Cohort h must be in"),
    (dict(method=micro.FP(eps=0.02), numerics=micro.FP(eps=0.03)), "once"),
    (dict(numerics=micro.Cohort()), "numerics must be a micro.FP"),
    (dict(method=object()), "options object"),
])
def test_bad_method_fails_before_anything_is_computed(cohort_calls, bad, match):
    with pytest.raises(ValueError, match=match):
        micro.stationary(SMALL, 20.0, **bad)
    assert not cohort_calls


def test_a_sweep_hands_over_each_row_as_it_is_done(cohort_calls):
    seen = []
    frame = micro.sweep(micro.Model(k0=0.1), [5.0, 10.0], on_row=lambda f: seen.append(len(f)))
    assert seen == [1, 2] and list(frame.method) == ["renewal", "renewal"]


def test_cli_sweep_keeps_the_rows_before_a_failing_row(tmp_path, monkeypatch):
    from micro.cli import main

    real = api.stationary

    def fail_second(model, V, **kw):
        if V == 10.0:
            raise ValueError("the second row fails")
        return real(model, V, **kw)

    monkeypatch.setattr(api, "stationary", fail_second)
    out = tmp_path / "sweep.csv"
    assert main(["sweep", "--k0", "0.1", "--V", "5,10", "--out", str(out)]) == 2
    kept = pd.read_csv(out)
    assert list(kept.V) == [5.0] and kept.method.iloc[0] == "renewal"


@pytest.mark.parametrize("argv, flag", [
    (["sweep", "--k0", "0.01", "--V", "4", "--method", "cycle"], "--method cycle was retired"),
    (["sweep", "--k0", "0.01", "--V", "4", "--eps", "0.01"], "--eps sets the Fokker-Planck method"),
    (["sweep", "--k0", "0.01", "--V", "4", "--method", "fp", "--cohort-dt", "0.02"], "--cohort-dt sets the cohort"),
    (["steady", "--k0", "0.1", "--V", "1", "--cohort-h", "0.01"], "--cohort-h sets the cohort"),
    (["critical", "--k0", "0.1", "--rtol", "0.1"], "--rtol sets the Fokker-Planck"),
    (["run", "--k0", "0.1", "--V", "1", "--duration", "1", "--cohort-tol", "1e-5"], "--cohort-tol sets the cohort"),
    (["sweep", "--k0", "0.01", "--V", "4", "--cohort-h", "1"], "--cohort-h must be in"),
    (["sweep", "--k0", "0.01", "--V", "4", "--cohort-dt", "0.5"], "--cohort-dt must be a finite number in"),
    # issue 39 row 11: the flag as typed, not the parameter (these said "eps must be ...")
    (["sweep", "--k0", "0.1", "--V", "1", "--method", "fp", "--eps", "0"],
     "error: --eps must be a finite number > 0, got 0.0"),
    (["sweep", "--k0", "0.1", "--V", "1", "--method", "fp", "--eps", "0.1"],
     "error: --eps must be in [kappa*zbar/1000, kappa*zbar/4] = [0.00011, 0.0275]"),
])
def test_cli_refuses_a_flag_of_a_method_it_does_not_use(tmp_path, capsys, cohort_calls, argv, flag):
    from micro.cli import main

    out = tmp_path / "x.csv"
    assert main(argv + ["--out", str(out)]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and flag in err[0]
    assert not out.exists() and not cohort_calls
