"""Runaway as a status, the step budget, output at chosen times (t_eval), and the
classical rate-and-state laws against an independent scipy integrator
(``_independent_rs``, DOP853 at rtol 1e-12, sharing no code with rsf)."""
from __future__ import annotations

import math
import sys
from pathlib import Path

import numpy as np
import pytest
from scipy.integrate import solve_ivp

import rsf

sys.path.insert(0, str(Path(__file__).parent))
from _independent_rs import mu_at, state_rate  # noqa: E402

B, DC, V0, MU0 = 0.01, 10.0, 1.0, 0.6


def _model(law: str, a: float, k_over_kc: float) -> rsf.SpringSlider:
    kc = (B - a) / DC
    return rsf.standard_rs(mu0=MU0, a=a, b=B, Dc=DC, k0=k_over_kc * kc, v0=V0, state_law=law)


def _blowup_time(law: str, a: float, k0: float, v_bound: float) -> float:
    """Independent: the time at which v reaches v_bound after the step 1 -> 10 at t = 10
    (steady state at V = 1 before the step)."""
    def rhs(t, y):
        v, th = math.exp(y[0]), math.exp(y[1])
        dl = state_rate(law, v, th, DC)
        return [(k0 * (10.0 - v) - B * dl) / a, dl]

    def hit(t, y):
        return y[0] - math.log(v_bound)
    hit.terminal = True
    sol = solve_ivp(rhs, (10.0, 60.0), [0.0, math.log(DC)], method="DOP853", rtol=1e-12,
                    atol=1e-14, events=hit)
    assert sol.t_events[0].size == 1
    return float(sol.t_events[0][0])


STEP = rsf.Protocol.velocity_steps([1.0, 10.0], [10.0])


@pytest.fixture
def cvode_calls(monkeypatch):
    """A spy on rsf's CVODE drivers: (driver, right-hand-side evaluations, status) per call."""
    import rsf._sundials

    calls = []
    for name in ("integrate", "integrate_outputs"):
        original = getattr(rsf._sundials, name)

        def spy(*args, _original=original, _name=name, **kwargs):
            sol = _original(*args, **kwargs)
            calls.append((_name, int(sol.nfev), int(sol.status)))
            return sol
        monkeypatch.setattr(rsf._sundials, name, spy)
    return calls


@pytest.mark.parametrize("law, k_over_kc", [("aging", 0.8), ("slip", 2.0)])
def test_runaway_is_a_status_with_its_time_and_trajectory(law, k_over_kc, cvode_calls):
    model = _model(law, 0.005, k_over_kc)
    tr = rsf.simulate(model, protocol=STEP, t_end=60.0)
    # the run stops where v passes the bound, nothing is integrated beyond it (was: under 1 s
    # of wall clock): 307 and 274 evaluations in two CVODE calls (before and after the step)
    assert len(cvode_calls) == 2 and sum(c[1] for c in cvode_calls) <= 600, cvode_calls
    assert tr.status == rsf.Status.RUNAWAY and not tr.success
    t_ref = _blowup_time(law, 0.005, model.k0, 1e4)           # default bound: 1e3 * max V
    assert tr.t[-1] == pytest.approx(t_ref, abs=1e-7)
    assert tr.v[-1] == pytest.approx(1e4, rel=1e-6)
    assert f"t = {tr.t[-1]:.10g}" in tr.message
    assert tr.events[-1].kind == "runaway"
    assert tr.t.size > 50 and np.all(np.diff(tr.t) >= 0) and tr.t[0] == 0.0
    assert np.all(np.isfinite(tr.sigma))


def test_runaway_bound_is_an_option():
    model = _model("aging", 0.005, 0.8)
    tr = rsf.simulate(model, protocol=STEP, t_end=60.0, options=rsf.SolverOptions(v_max=1e7))
    assert tr.status == rsf.Status.RUNAWAY
    assert tr.t[-1] == pytest.approx(_blowup_time("aging", 0.005, model.k0, 1e7), abs=1e-7)


@pytest.mark.parametrize("law, k_over_kc", [("aging", 0.8), ("slip", 2.0)])
def test_solver_failure_reports_where_it_failed(law, k_over_kc, cvode_calls):
    """Without the bound the blow-up ends in a solver failure at the blow-up time (not at
    the start of the segment), after bounded work, with the trajectory up to there."""
    model = _model(law, 0.005, k_over_kc)
    tr = rsf.simulate(model, protocol=STEP, t_end=60.0,
                      options=rsf.SolverOptions(v_max=math.inf))
    # bounded work (was: under 5 s of wall clock): the stepping stops when its step falls
    # below the round-off of t (status -3), not at CVODE's step limit (-1); 755 and 738
    # evaluations measured
    assert cvode_calls[-1][2] == -3 and "round-off" in tr.message
    assert sum(c[1] for c in cvode_calls) <= 2500, cvode_calls
    assert tr.status == rsf.Status.SOLVER_FAILED
    t_ref = _blowup_time(law, 0.005, model.k0, 1e12)
    t_fail = float(tr.message.split("at t = ")[1].split(" ")[0])
    assert t_fail == pytest.approx(t_ref, abs=1e-3)
    assert tr.t[-1] == pytest.approx(t_fail, rel=1e-9)
    assert tr.v[-1] > 1e12


def test_step_budget_stops_a_run():
    model = _model("aging", 0.005, 20.0)
    tr = rsf.simulate(model, protocol=STEP, t_end=60.0,
                      options=rsf.SolverOptions(max_rhs_evals=50))
    assert tr.status == rsf.Status.STEP_BUDGET and "max_rhs_evals" in tr.message
    # a = 0: stick and slip are closed form, the cycle needs no right-hand-side evaluation, so
    # a budget of 1 does not stop it and changes nothing; with a direct effect (a > 0) the
    # cycle is integrated and the budget stops it
    model = rsf.SpringSlider(k0=0.01)
    r = rsf.limit_cycle(model, 1.0, options=rsf.SolverOptions(max_rhs_evals=1))
    free = rsf.limit_cycle(model, 1.0)
    assert r.status == rsf.Status.CONVERGED and (r.sigma_max, r.sigma_min) == (free.sigma_max, free.sigma_min)
    r = rsf.limit_cycle(rsf.SpringSlider(k0=0.01, a=0.002), 0.1, options=rsf.SolverOptions(max_rhs_evals=1))
    assert r.status == rsf.Status.STEP_BUDGET and "max_rhs_evals" in r.message


def test_no_sundials_warning_on_a_velocity_step(capfd):
    for law in ("aging", "slip"):
        tr = rsf.simulate(_model(law, 0.005, 20.0), protocol=STEP, t_end=60.0)
        assert tr.success
    err = capfd.readouterr().err
    assert "identically 0" not in err and "WARNING" not in err, err


def test_no_round_off_extrema_in_the_overdamped_tail():
    """Every sigma extremum reported is a real one: the independent solution has an
    extremum of the same kind within 1e-3 of its time, farther than 1e-9 from steady."""
    model = _model("aging", 0.005, 20.0)
    tr = rsf.simulate(model, protocol=rsf.Protocol.velocity_steps([1.0, 10.0, 1.0], [10, 40]),
                      t_end=200.0)
    kinds = [e.kind for e in tr.events if e.kind.startswith("sigma_")]
    assert 1 <= len(kinds) <= 4, kinds
    te = np.linspace(10, 200, 190001)
    mu = mu_at("aging", a=0.005, b=B, Dc=DC, k0=model.k0, v0=V0, mu0=MU0,
               velocities=[1.0, 10.0, 1.0], times=[0, 10, 50], t_eval=te)
    dmu = np.diff(mu)
    big = np.abs(dmu) > 1e-13
    flips = np.flatnonzero(big[1:] & big[:-1] & (np.sign(dmu[1:]) != np.sign(dmu[:-1])))
    t_ref = te[flips + 1]
    for e in tr.events:
        if e.kind.startswith("sigma_"):
            assert np.min(np.abs(t_ref - e.t)) < 1e-3, (e, t_ref)


# ---------------------------------------------------------------------------------------
# output at chosen times
# ---------------------------------------------------------------------------------------
CASES = [(law, a, k) for law in ("aging", "slip") for a in (0.005, 0.008) for k in (20.0, 2.0, 1.2)]


@pytest.mark.parametrize("law, a, k_over_kc", CASES)
def test_t_eval_matches_independent_reference(law, a, k_over_kc):
    """1e-8 in mu at default options (steps 1 -> 10 -> 1 for the aging law, 1 -> 2 -> 1
    for the slip law, which runs away on the larger step at k0 <= 2 k_c)."""
    model = _model(law, a, k_over_kc)
    vel = [1.0, 10.0, 1.0] if law == "aging" else [1.0, 2.0, 1.0]
    te = np.linspace(0.0, 100.0, 401)
    tr = rsf.simulate(model, protocol=rsf.Protocol.velocity_steps(vel, [10.0, 40.0]),
                      t_end=100.0, t_eval=te)
    assert tr.success, tr.message
    assert np.array_equal(tr.t, te)
    mu = mu_at(law, a=a, b=B, Dc=DC, k0=model.k0, v0=V0, mu0=MU0, velocities=vel,
               times=[0.0, 10.0, 50.0], t_eval=te)
    assert np.max(np.abs(tr.sigma - mu)) < 1e-8
    X = np.interp(te, [0, 10, 50, 100], [0, 10, 10 + 40 * vel[1], 60 + 40 * vel[1]])
    assert np.max(np.abs(tr.x - (X - tr.sigma / model.k0))) < 1e-8 / model.k0
    kinds = [e.kind for e in tr.events]
    assert kinds[0] == "start" and kinds[-1] == "end" and kinds.count("drive") == 2


def test_t_eval_reproduces_the_step_output_at_the_step_times():
    """a = 0 (stick, slide, slip): t_eval at the integrator's own step times gives back
    its samples."""
    model = rsf.SpringSlider(rsf.HyperbolicLaw(mu_inf=0.9), k0=0.3)
    cv = rsf.critical_velocity(model)
    for V in (0.5 * cv.Vc, 2.0 * cv.Vc):
        full = rsf.simulate(model, V=V, t_end=100.0)
        keep = np.concatenate([[True], np.diff(full.t) > 1e-9])
        keep &= np.concatenate([np.diff(full.t) > 1e-9, [True]])       # not at a slip
        te = full.t[keep]
        tr = rsf.simulate(model, V=V, t_end=100.0, t_eval=te)
        assert tr.success and np.array_equal(tr.t, te)
        assert np.max(np.abs(tr.sigma - full.sigma[keep])) < 1e-9
        assert np.max(np.abs(tr.theta - full.theta[keep]) / full.theta[keep]) < 1e-8


@pytest.mark.parametrize("t_eval, match", [
    ([], "at least one"), ([1.0, 1.0], "strictly increasing"), ([0.0, 200.0], "t_eval must lie"),
    ([-1.0, 2.0], "t_eval must lie"), ([0.0, np.nan], "finite"),
])
def test_bad_t_eval(t_eval, match):
    with pytest.raises(ValueError, match=match):
        rsf.simulate(_model("aging", 0.005, 2.0), V=1.0, t_end=100.0, t_eval=t_eval)


def test_bad_runaway_options():
    with pytest.raises(ValueError, match="v_max must be a number > 0"):
        rsf.SolverOptions(v_max=0.0)
    with pytest.raises(ValueError, match="max_rhs_evals must be an integer >= 1"):
        rsf.SolverOptions(max_rhs_evals=0)


def test_velocity_steps_start_at_exact_steady_state():
    model = _model("aging", 0.005, 2.0)
    tr = rsf.simulate(model, protocol=STEP, t_end=9.0)
    assert np.all(tr.v == 1.0) and np.all(tr.sigma == tr.sigma[0])
    assert tr.sigma[0] == pytest.approx(MU0, abs=1e-15)
    shs = rsf.simulate(model, protocol=rsf.Protocol.slide_hold_slide(1.0, 5.0, 10.0), t_end=5.0)
    assert np.all(shs.v == 1.0)
    const = rsf.simulate(model, V=1.0, t_end=5.0)            # constant driving: perturbed
    assert const.v[-1] != 1.0


def test_t_eval_keeps_the_samples_before_a_runaway():
    model = _model("aging", 0.005, 0.8)
    te = np.linspace(0.0, 60.0, 61)
    tr = rsf.simulate(model, protocol=STEP, t_end=60.0, t_eval=te)
    assert tr.status == rsf.Status.RUNAWAY
    assert np.array_equal(tr.t, te[:14])                    # 0, 1, ..., 13 < 13.1178
    mu = mu_at("aging", a=0.005, b=B, Dc=DC, k0=model.k0, v0=V0, mu0=MU0,
               velocities=[1.0, 10.0], times=[0.0, 10.0], t_eval=te[:14])
    assert np.max(np.abs(tr.sigma - mu)) < 1e-8
    assert tr.events[-1].kind == "runaway" and tr.events[-1].t == pytest.approx(13.11778153, abs=1e-7)
