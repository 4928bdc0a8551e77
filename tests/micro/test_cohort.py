"""Stick-slip cycles by cohorts of exponential margins (``method="cohort"``).

Checks that share no code with the method: the exact stress after a total shock
(``micro.sigma_fast_limit``), the branching ratio of the state after a total shock
(1 - k0/kappa, by hand), the exact moments of a deposit, and the Fokker-Planck solvers'
sigma_max at the same point.
"""
from __future__ import annotations

import dataclasses
import math
from pathlib import Path

import numpy as np
import pytest

import micro
from micro.cohort import kernels as CK
from micro.cohort import cycle_cohorts
from micro.cohort.cycle import _one_cycle
from micro.cohort.solver import _NO_COARSE
from micro.cohort.state import _start


def test_state_after_a_total_shock_has_branching_ratio_one_minus_k0_over_kappa():
    """Exp(kappa zbar) margins: the density at the threshold is 1/(kappa zbar), so an
    avalanche's branching ratio is (k1 + k2)/kappa and dH/d(dX) = -k0/kappa at dX = 0,
    whatever the delta_R marginal (to the re-jumps' O(dX)); the stress is f_th - kappa zbar + <delta_R>."""
    model = micro.Model(k0=0.01)
    y = np.array([-0.05, 0.0, 0.02])
    st = _start(model, 1.0, model.kappa * model.zbar / 20, (y, np.array([0.2, 0.5, 0.3])))
    assert st.sigma == pytest.approx(micro.sigma_fast_limit(model) + 0.2 * -0.05 + 0.3 * 0.02, abs=1e-14)
    st.prepare(0.0)
    assert st.closure(0.0)[0] == pytest.approx(0.0, abs=1e-15)
    H, dH = st.closure(1e-9 * model.zbar)  # (the right derivative: the floors are at the threshold)
    assert dH == pytest.approx(-model.k0 / model.kappa, rel=1e-6)


# (26 s alone on 2 idle cores: slow, so that the default run stays within 5 minutes; the
# cohort rows' discretisation error in the default run is checked by tests/micro/test_api.py)
@pytest.mark.slow
def test_steady_sliding_stepped_by_cohorts_converges_in_dt_with_order_two_to_the_renewal_chain():
    """k0 = 0.3, V = 1 (about 5 V^c: steady sliding is stable), from the product state,
    stepped to t = 4 at dt = 0.04 and 0.02: the stress against the renewal chain's steady
    stress (micro.steady_sliding, which shares no code with the method).  Measured at
    t = 20: errors 3.05e-3, 8.1e-4, 2.1e-4 at dt = 0.04, 0.02, 0.01 (order 1.9-2.0); with
    the newborns' own relaxation starting at the step's end (``AGE = 0``) 1.67e-2, 8.3e-3,
    4.1e-3 (order 1.0)."""
    model = micro.Model(k0=0.3)
    exact = float(micro.steady_sliding(model, [1.0]).sigma[0])
    errors = []
    for dt in (0.04, 0.02):
        st = _start(model, 1.0, model.kappa * model.zbar / 20, None)
        for i in range(int(round(4.0 / dt))):
            phi, Edt = st.prepare(dt)
            x, status = st.root()
            assert status == 0
            st.commit(x, dt, phi, Edt)
            if i % 50 == 49:
                st.compact()
        errors.append(st.sigma - exact)
    assert 0.0 < errors[1] < 1.5e-3
    assert errors[0] / errors[1] > 3.0


def test_a_long_loading_phase_takes_longer_steps_in_its_middle(monkeypatch):
    # k0 = 0.01, 0.1 V^c: a loading phase of about 9 / gamma.  Steps dt within 1 / gamma of
    # either end, up to 4 dt between: from the same state, the graded loading phase takes
    # 149 closure set-ups where uniform steps take 260, and its extrema move by < 1e-6
    from micro.cohort import cycle, options, state
    gamma = 0.9
    assert cycle._step_length(0.0, 10.0, 0.01, gamma) == 0.01
    assert cycle._step_length(3.0, 10.0, 0.01, gamma) == pytest.approx(0.027)
    assert cycle._step_length(5.0, 10.0, 0.01, gamma) == 0.04
    assert cycle._step_length(9.5, 10.0, 0.01, gamma) == 0.01
    assert cycle._step_length(5.0, 0.0, 0.01, gamma) == 0.01  # no reference phase yet
    model = micro.Model(k0=0.01)
    V = 0.1 * micro.critical_velocity(model).Vc
    st = _start(model, V, model.kappa * model.zbar / 5.0, None)
    assert _one_cycle(st, 0.04)["ok"] and st.period_ref > 8.0 / model.gamma
    calls = []
    prepare = state._Cohorts.prepare
    monkeypatch.setattr(state._Cohorts, "prepare", lambda self, dt: calls.append(dt) or prepare(self, dt))
    graded = _one_cycle(st.copy(), 0.04)
    n_graded = len(calls)
    monkeypatch.setattr(options, "DEFAULT", dataclasses.replace(options.DEFAULT, GRADED_MAX=1.0))
    uniform = _one_cycle(st.copy(), 0.04)
    assert n_graded < 0.65 * (len(calls) - n_graded)
    for name in ("sigma_max", "sigma_min", "sigma_after"):
        assert graded[name] == pytest.approx(uniform[name], abs=2e-6)


def test_the_tuning_constants_are_one_frozen_options_object_that_checks_itself():
    """The cohort method's constants are the fields of one frozen CohortOptions; a value out
    of range fails naming the field; the runs read ``options.DEFAULT`` when they need one
    (so ``override`` changes the step rule inside its block, and restores it after)."""
    from micro.cohort import cycle, options
    with pytest.raises(dataclasses.FrozenInstanceError):
        options.DEFAULT.GRADED_MAX = 1.0
    for field, value, allowed in (("GRADED_MAX", 0.5, "a number >= 1"), ("MAX_CELLS", 1.5, "an integer >= 1"),
                                  ("AGE", 1.5, r"a number in \[0, 1\]"), ("CELL_FLOOR", 0.0, "a finite number > 0"),
                                  ("AITKEN_MAX_RATIO", 1.0, r"a number in \(0, 1\)"),
                                  ("ANDERSON_BACKTRACKS", -1, "an integer >= 0"), ("BAND_ABOVE", 16, "below")):
        with pytest.raises(ValueError, match=f"CohortOptions {field} must be {allowed}"):
            dataclasses.replace(options.DEFAULT, **{field: value})
    assert dataclasses.replace(options.DEFAULT, GRADED_MAX=math.inf, PEAK_CREEP=0.0).GRADED_MAX == math.inf
    default = options.DEFAULT
    assert cycle._phase_step(0.1, 0.01) == pytest.approx(0.01 * 0.1 / default.SHORT_PHASE)
    with options.override(SHORT_PHASE=0.25) as changed:
        assert options.DEFAULT is changed and changed.SHORT_PHASE == 0.25 and default.SHORT_PHASE == 0.5
        assert cycle._phase_step(0.1, 0.01) == pytest.approx(0.01 * 0.1 / 0.25)
    assert options.DEFAULT is default and cycle._phase_step(0.1, 0.01) == pytest.approx(0.01 * 0.1 / 0.5)


def test_the_cycles_trace_is_its_steps_stresses():
    """``trace``: the last cycle's stress at each step's end, rebuilt from its steps' drive
    and slip (k0 (V l - x) a step).  It must reproduce that cycle's own row of the history
    to round-off: its period, sigma_before, sigma_after, sigma_min and trapezoid mean, start
    at the cycle before's sigma_after, and stay below its sigma_max (the peak, which the
    replay of the creep before the shock can put between step ends)."""
    model = micro.Model(k0=0.1)
    V = 0.3 * micro.critical_velocity(model).Vc
    res = cycle_cohorts(model, V, dt=0.04, h=model.kappa * model.zbar / 10, tol=1e-5, start=_NO_COARSE)
    t, sigma = res.trace
    row = dict(zip(("sigma_max", "sigma_min", "period", "sigma_mean", "sigma_before", "sigma_after"), res.history[-1]))
    tiny = 1e-12
    assert t[0] == 0.0 and t[-1] == pytest.approx(row["period"], abs=tiny)
    assert sigma[0] == pytest.approx(res.history[-2][5], abs=tiny)
    assert sigma[-2] == pytest.approx(row["sigma_before"], abs=tiny)
    assert sigma[-1] == pytest.approx(row["sigma_after"], abs=tiny)
    assert sigma.min() == pytest.approx(row["sigma_min"], abs=tiny) and sigma.max() <= row["sigma_max"] + tiny
    mean = np.sum(0.5 * (sigma[1:] + sigma[:-1]) * np.diff(t)) / t[-1]
    assert mean == pytest.approx(row["sigma_mean"], abs=tiny)


def test_step_roots_are_the_first_sign_change_of_the_closure_even_next_to_a_fold(monkeypatch):
    """Every step's slip against the closure H itself, evaluated apart: H > 0 on a grid
    below the returned root, and H changes sign within 1e-7 of the slip plus H's
    round-off over its slope (H's round-off measured at 1e-18 in units of slip; 1e-16
    allowed).  k0 = 1e-3 at 0.85 V^c, where each loading phase ends in a fold, so that
    some roots are nearly double: the root finder steps to a parabola's zero there (Newton
    from the left only halved the distance per evaluation) and stops at H's round-off (it
    had bisected noise)."""
    from micro.cohort import state
    model = micro.Model(k0=1e-3)
    V = 0.85 * micro.critical_velocity(model).Vc
    st = _start(model, V, model.kappa * model.zbar / 5.0, None)
    root = state._Cohorts.root
    slopes = []

    def checked_root(self, below=0.0):
        x, status = root(self, below)
        if status == 0 and x > 0.0:
            H, dH = self.closure(x)
            slack = 1e-7 * x + 1e-16 / abs(dH)
            assert self.closure(x - slack)[0] > 0.0
            assert self.closure(x + slack)[0] < 0.0
            assert all(self.closure(y)[0] > 0.0 for y in np.linspace(0.0, x - slack, 9)[1:])
            slopes.append(abs(dH))
        return x, status

    monkeypatch.setattr(state._Cohorts, "root", checked_root)
    for _ in range(2):
        assert _one_cycle(st, 0.004)["ok"]
    # many roots, some next to a fold (slope below a twentieth of k0 / kappa, the state after a shock)
    assert len(slopes) > 20 and min(slopes) < 0.05 * model.k0 / model.kappa


@pytest.mark.parametrize("k0, frac", [(0.01, 0.5), (1e-4, 0.95)])
def test_warm_started_roots_are_the_cold_started_ones(monkeypatch, k0, frac):
    """A step's Newton iteration starts from the slip rate of the steps before (the fold's
    bisection from the slip of its longest step that did not fold), the shock's root by
    Newton in a bracket a hundredth wide: the same slips and the same folds as Newton from
    0 and plain bisection (at k0 = 1e-4 the shock's closure is flat, dH = -1e-4, and
    lands on exactly 0: a first version returned a bisection point there, 1.3 off)."""
    from micro.cohort import state
    model = micro.Model(k0=k0)
    V = frac * micro.critical_velocity(model).Vc
    st = _start(model, V, model.kappa * model.zbar / 5.0, None)
    root, shock_root = state._Cohorts.root, state._Cohorts.shock_root
    seen = {"warm": 0, "shocks": 0}

    def checked_root(self, below=0.0):
        x, status = root(self, below)
        cold = CK.smallest_root(self.n, self.co, self.j0, self.nn, self.off, self.q, self.m, self.ylo, self.h,
                                self.lam, model.zbar, 1e-15 * model.zbar,
                                max(1e-9 * model.zbar, 0.25 * self.last), 0.0)
        assert status == cold[1]
        if status == 0:
            assert x == pytest.approx(cold[0], rel=1e-10)
            seen["warm"] += below > 0.0 or self.prev_rate > 0.0
        return x, status

    def checked_shock_root(self, x0):
        x = shock_root(self, x0)
        lo, hi = x0, max(2.0 * x0, model.zbar)
        while self.closure(hi)[0] > 0.0:
            lo, hi = hi, 2.0 * hi
        while hi - lo > 1e-14 * hi:
            mid = 0.5 * (lo + hi)
            lo, hi = (mid, hi) if self.closure(mid)[0] > 0.0 else (lo, mid)
        assert x == pytest.approx(hi, rel=1e-10)  # (the closure is flat: its round-off moves the root by ~1e-12)
        seen["shocks"] += 1
        return x

    monkeypatch.setattr(state._Cohorts, "root", checked_root)
    monkeypatch.setattr(state._Cohorts, "shock_root", checked_shock_root)
    for _ in range(2):
        assert _one_cycle(st, 0.04 if frac < 0.9 else 0.004)["ok"]
    assert seen["warm"] > 20 and seen["shocks"] == 2


def test_serial_twins_are_the_parallel_kernels_bit_for_bit(monkeypatch):
    """Where numba runs one thread only (compare's pool workers) the cohort kernels run as
    serial twins, which compile faster (no parfors): the same sums in the same order, so
    the same numbers to the last bit, also from PARALLEL_COHORTS cohorts on."""
    assert CK._closure.targetoptions["parallel"] and CK._commit.targetoptions["parallel"]
    for entry in (CK.closure, CK.smallest_root, CK.commit):
        assert not entry.serial.targetoptions.get("parallel")
        assert type(entry.serial._cache) is type(entry.__wrapped__._cache)  # on numba's disk cache as well
    model = micro.Model(k0=0.1)  # some 500 cohorts at V = 1 (a cycle takes 15 s: stopped once all were seen)
    st = _start(model, 1.0, model.kappa * model.zbar, None)
    seen = {"smallest_root": 0, "commit": 0}

    class Seen(Exception):
        pass

    def both(name):
        entry = getattr(CK, name)

        def call(*args):
            copies = [a.copy() if isinstance(a, np.ndarray) else a for a in args]
            out = entry.__wrapped__(*args)
            assert entry.serial(*copies) == out
            for a, b in zip(args, copies):
                if isinstance(a, np.ndarray):
                    assert np.array_equal(a, b, equal_nan=True)
            if name == "smallest_root":  # and the closure at the root (smallest_root's args less its last three)
                assert CK._closure(out[0], *args[:-3]) == CK.closure.serial(out[0], *args[:-3])
            seen[name] += args[1 if name == "commit" else 0] >= CK.PARALLEL_COHORTS
            if min(seen.values()) >= 20:
                raise Seen
            return out

        monkeypatch.setattr(CK, name, call)

    for name in seen:
        both(name)
    try:
        _one_cycle(st, 0.04)
    except Seen:
        pass
    assert min(seen.values()) >= 20, seen


def test_one_numba_thread_runs_the_serial_twins(monkeypatch):
    """The entry points pick the serial twin exactly where numba has one thread for good."""
    from micro import _threads

    monkeypatch.setattr(_threads, "_numba_limit", lambda: 1)
    assert CK.one_numba_thread()
    monkeypatch.setattr(_threads, "_numba_limit", lambda: 2)
    assert not CK.one_numba_thread()
    calls = []
    monkeypatch.setattr(CK, "one_numba_thread", lambda: calls.append(1) or True)
    i64 = np.zeros(1, np.int64)
    args = (0.5, 0, np.zeros((1, 6)), i64, i64.copy(), i64.copy(), np.zeros(2), np.zeros(4), 0.0, 0.1, 0.1, 0.1)
    assert CK.closure(*args) == (-0.5, -1.0) and calls
    assert CK.closure.serial.signatures


@pytest.mark.parametrize("coarse", [True, pytest.param(False, marks=pytest.mark.slow)])  # (18 s: the default run
# keeps the start from a coarse run, the default path)
def test_a_short_loading_phase_gets_its_steps_from_the_cycle_not_from_the_transient(coarse):
    # k0 = 0.3, 0.95 V^c: the transient's loading phases are shorter (0.16) than the
    # cycle's (0.25).  The step must be the cycle's dt T / SHORT_PHASE, whatever phase the
    # transient cut it to: it used to stay at 0.65 of that, so the resolution depended on
    # the path to the cycle, not on dt.  With the coarse transient first, the fine run
    # takes the coarse cycle's phase; without it, the run lengthens the step it had cut
    from micro.cohort import options
    model = micro.Model(k0=0.3)
    dt = 0.02
    res = cycle_cohorts(model, 0.95 * micro.critical_velocity(model).Vc, dt=dt, h=model.kappa * model.zbar / 10,
                        tol=1e-3, start=None if coarse else _NO_COARSE)
    assert res.converged and res.period < options.DEFAULT.SHORT_PHASE
    assert res.state.dt == pytest.approx(dt * res.period / options.DEFAULT.SHORT_PHASE, rel=0.25)


def test_a_shock_keeps_the_mean_lag_at_zero():
    """The blocks' mean lag behind the mean slip is zero at all times (the mean slip is
    their mean displacement).  After a total shock every margin is Exp(kappa zbar), so
    that says sigma = f_th - kappa zbar + <delta_R>; the method does not impose it, so it
    holds only if the shock's slip counts every re-jump exactly.  At k0 = 1e-4 a block
    jumps some 7000 times in a shock; with the re-jumps by two Gauss points, the stress
    was 8.5e-4 off this after one cycle, and the offset grew cycle to cycle."""
    model = micro.Model(k0=1e-4)
    st = _start(model, 81.0, model.kappa * model.zbar / 5, None)
    for _ in range(3):
        out = _one_cycle(st, 0.04)
        assert out["ok"] and st.n == 1  # (a total shock: one cohort left)
        nodes, masses = st.marginal(0)
        lagged = model.f_th - st.lam + (masses @ nodes) / masses.sum()
        assert abs(st.sigma - lagged) < 1e-8


def test_a_run_close_to_vc_is_accelerated_and_bounds_its_error_by_the_slowest_mode():
    """Close to V^c the cycles contract by 0.9-0.98 a cycle, and five plain cycles can hide a
    mode slower than the one they show (at k0 = 1e-3, 0.95 V^c the Aitken estimate was
    measured 25 times too small: studies/micro_cohort_estimate_check.py).  Such a run is
    accelerated, and each error is at least the last step times m / (1 - m), m the slowest
    multiplier; a run far from V^c is not accelerated."""
    model = micro.Model(k0=0.001)
    Vc = micro.critical_velocity(model).Vc
    coarse = dict(dt=0.04, h=model.kappa * model.zbar / 5, tol=1e-4, start=_NO_COARSE)
    near = cycle_cohorts(model, 0.95 * Vc, **coarse)
    assert near.converged and "slowest multiplier" in near.message, near.message
    m = float(near.message.rsplit("m = ", 1)[1].split()[0])
    assert 0.97 < m < 0.995
    last = np.abs(np.diff(near.history[-2:, :2], axis=0)[0])
    assert near.error >= (last * m / (1.0 - m)).max() * (1 - 1e-12)
    far = cycle_cohorts(model, 0.3 * Vc, **coarse)
    assert far.converged and "Anderson" not in far.message and "slower mode" not in far.message, far.message


def test_anderson_leaves_the_plain_cycles_half_the_budget():
    """Below the map's roughness Anderson's residual creeps down without stalling: at
    k0 = 1e-3, 0.95 V^c and tol = 1e-6 it used to take every cycle left, and the run ended
    with no plain cycle, no value and an estimate of 6e-3.  It now gets at most half."""
    model = micro.Model(k0=0.001)
    V = 0.95 * micro.critical_velocity(model).Vc
    res = cycle_cohorts(model, V, dt=0.04, h=model.kappa * model.zbar / 5, tol=1e-9, max_iter=60,
                        start=_NO_COARSE)
    # (was: '"Anderson" in res.message or not res.converged', true either way.)  What happens:
    # Anderson runs (accelerated), takes at most half of the cycles left after the first
    # window, the plain cycles get the rest (27 measured after it, the history it leaves),
    # and 60 cycles do not reach 1e-9, which the run says
    assert res.accelerated and not res.converged
    assert res.message.startswith("no fixed point to 1e-09 in 60 cycles"), res.message
    assert res.iterations == 60 and len(res.history) >= 25
    assert math.isfinite(res.sigma_max) and res.sigma_max == pytest.approx(0.9068, abs=1e-3)


@pytest.mark.parametrize("W", [0.03, math.inf])
def test_deposit_keeps_mass_and_mean(W):
    """The hat-function deposit of Y = ytop - B Z, Z ~ Exp(lam) on [0, W], keeps the mass
    and the mean exactly (E[Z] of the truncated exponential, by hand)."""
    lam, B, ytop, h = 0.1, 0.8, 0.013, 0.005
    dep = np.zeros(1000)
    ylo = -4.0  # (the deposit covers 40 lam of Z)
    assert CK.deposit(dep, 0.7, ytop, B, W, lam, ylo, h) == 0.0
    EZ = lam if math.isinf(W) else lam - W * math.exp(-W / lam) / (1.0 - math.exp(-W / lam))
    y = ylo + h * np.arange(dep.size)
    assert dep.sum() == pytest.approx(0.7, rel=1e-10)
    assert (dep @ y) / dep.sum() == pytest.approx(ytop - B * EZ, abs=1e-10)
    assert dep.min() >= 0.0


def test_cohort_cycle_matches_the_fokker_planck_solvers_and_the_exact_sigma_min():
    """k0 = 0.01, V = 0.3 V^c.  sigma_min is f_th - kappa zbar (0.899) to the method's
    O(dt) error; sigma_max lies within the spread of the Fokker-Planck results at this
    point (time-stepping 0.959337 and 0.959577, the shock-to-shock map 0.959632 and
    0.959419, at eps = 0.0168 and 0.0126: benchmarks/results/micro_cycle_speed.csv)."""
    model = micro.Model(k0=0.01)
    res = cycle_cohorts(model, 2.403, dt=0.02, h=0.01, tol=1e-4)
    assert res.converged and res.applicable, res.message
    assert abs(res.sigma_min - micro.sigma_fast_limit(model)) < 1e-4
    assert 0.95934 - 3e-4 < res.sigma_max < 0.95963 + 3e-4
    assert res.error <= 1e-4
    # started from the fixed point, the first cycle is on it (from the first shock's
    # image, without the coarser run, it is 1e-2 away)
    again = cycle_cohorts(model, 2.403, dt=0.02, h=0.01, tol=1e-4, start=res)
    assert abs(again.history[0, 0] - res.sigma_max) < 2e-4
    assert again.sigma_max == pytest.approx(res.sigma_max, abs=2e-4)
    cold = cycle_cohorts(model, 2.403, dt=0.02, h=0.01, tol=1e-4, max_iter=4, start=_NO_COARSE)
    assert abs(cold.history[0, 0] - res.sigma_max) > 5e-3


def test_cycle_sequence_is_smooth_at_small_k0():
    """At k0 = 1e-3 the cycle-to-cycle sequence of sigma_max converges monotonically with
    a steady contraction ratio (the shock-to-shock map on the grid jitters by ~k0 eps
    there): what makes the Aitken extrapolation valid."""
    model = micro.Model(k0=0.001)
    res = cycle_cohorts(model, 24.27, dt=0.02, h=0.01, tol=1e-9, max_iter=10, start=_NO_COARSE)
    d = np.diff(res.history[:, 0])
    assert np.all(d < 0.0), d
    rho = d[1:] / d[:-1]
    assert np.all((rho > 0.5) & (rho < 0.95)), rho


def test_shocks_that_are_not_total():
    """k0 = 0.1, V = V^c / 2: a shock leaves 7e-4 of the blocks unjumped, which stay in
    their cohorts.  Against the N-block simulation (shares no code; N = 4e5, 20 cycles:
    sigma_max 0.941931 +- 2.8e-5, sigma_min 0.889966 +- 3.6e-5)."""
    model = micro.Model(k0=0.1)
    res = cycle_cohorts(model, 0.36375217, dt=0.02, h=0.01, tol=2e-5)
    assert res.converged and 1e-4 < res.unjumped < 1e-2, res.message
    assert abs(res.sigma_max - 0.941931) < 2e-4
    assert abs(res.sigma_min - 0.889966) < 2e-4
    assert res.p is None  # (not a product state: no marginal to continue from)


def test_cohort_falls_back_without_exponential_jumps():
    model = micro.Model(k0=0.3, jumps=micro.Deterministic(0.1))
    res = micro.stationary(model, 0.1, method="cohort", numerics=micro.Numerics(eps=0.025),
                           convergence=micro.Convergence(rtol=5e-2, t_max=40.0), warn=False)
    assert res.method == "fp"
    assert res.message.startswith("the cohort method needs exponential jumps (a jumped block's margin is then "
                                  "Exp(kappa zbar)): Fokker-Planck time-stepping")


def test_cohort_rejects_bad_input():
    with pytest.raises(ValueError, match="exponential"):
        cycle_cohorts(micro.Model(k0=0.01, jumps=micro.Deterministic(0.1)), 1.0)
    for kwargs, name in (({"dt": 0.0}, "dt"), ({"h": -1.0}, "h"), ({"h": 1.0}, "h"), ({"tol": math.nan}, "tol")):
        with pytest.raises(ValueError, match=name):
            cycle_cohorts(micro.Model(k0=0.01), 1.0, **kwargs)
    with pytest.raises(ValueError, match="method"):
        micro.stationary(micro.Model(k0=0.01), 1.0, method="cohorts")


def test_cli_sweep_method_cohort(tmp_path, monkeypatch):
    """``micro sweep --method cohort`` writes the sweep's columns; ``--cohort-h`` is its cell
    and ``--cohort-dt`` its time step (both reach the method); ``--eps``, the
    Fokker-Planck bin, is refused there before anything is computed."""
    import pandas as pd

    from micro import api
    from micro.cli import main

    seen = []

    def spy(model, V, **kw):
        seen.append(kw)
        return cycle_cohorts(model, V, **kw)

    monkeypatch.setattr(api, "cycle_cohorts", spy)
    assert main(["sweep", "--k0", "0.001", "--V", "20", "--method", "cohort", "--eps", "0.01",
                 "--out", str(tmp_path / "no.csv")]) == 2
    assert not seen and not (tmp_path / "no.csv").exists()
    out = tmp_path / "cohort.csv"
    assert main(["sweep", "--k0", "0.001", "--V", "20", "--method", "cohort", "--cohort-h", "0.01",
                 "--cohort-dt", "0.02", "--out", str(out)]) == 0
    assert seen and seen[0]["dt"] == 0.02 and seen[0]["h"] == 0.01
    row = pd.read_csv(out).iloc[0]
    assert row.regime == "stick-slip" and bool(row.converged) and row.eps == 0.01 and row.method == "cohort"
    assert abs(row.sigma_min - micro.sigma_fast_limit(micro.Model(k0=0.001))) < 1e-4
    assert row.sigma_max > row.sigma_mean > row.sigma_min and row.period > 0


def test_each_quantity_is_judged_on_its_own():
    # column 0: two modes (ratios 0.97 and 0.6): the ratio still rises, and the error
    # bounds the true distance to the limit once the slow mode shows; column 1 alternates
    # below tol / STILL: noise, not a drift; column 2: one mode, extrapolated exactly; column 3
    # jumps (a change of the step count): not contracting, a large error
    from micro.cohort.estimate import _estimate
    n = np.arange(13)
    a = np.zeros((13, 4))
    a[:, 0] = 0.9 - 1e-4 * 0.97 ** n - 3e-4 * 0.6 ** n
    a[:, 1] = 0.899 + 1e-7 * (-1.0) ** n
    a[:, 2] = 0.95 + 2e-4 * 0.8 ** n
    a[:, 3] = 0.93 + 1e-5 * n
    a[10:, 3] += 4e-5
    errors, how, best, rho = _estimate(a, 1e-5)
    assert how == ["Aitken", "noise", "Aitken", "slow"]
    assert abs(best[0] - 0.9) <= errors[0] < 1e-3
    assert errors[1] <= 1e-6 + 1e-15 and best[1] == a[-1, 1]
    assert best[2] == pytest.approx(0.95, abs=1e-13) and errors[2] < 1e-12
    assert errors[3] > 1e-3
    assert rho[2] == pytest.approx(0.8, rel=1e-9)


def test_an_extrapolation_that_runs_off_is_not_reported():
    """A period drifting by 2.5e-8 a cycle with two nearly equal steps (ratio 1 - 4e-8, all
    ratios in [0, 1)) sent Aitken's extrapolation to -0.43 from cycles at 0.2097, and the run
    reported it (micro_cohort_other_choices.py, SHORT_PHASE = 1).  A ratio above 0.999 is
    judged as a drift: the last cycle, with the error of a thousand such steps; a clean
    geometric tail is still extrapolated."""
    from micro.cohort.estimate import _estimate
    d = np.array([-2.51e-8, -2.50e-8, -2.49e-8, -2.49e-8 * (1 - 4e-8)])
    period = 0.2097144864 + np.concatenate([[0.0], np.cumsum(d)])
    errors, how, best, _ = _estimate(period[:, None], 1e-6)
    assert how == ["slow"] and best[0] == period[-1]
    assert errors[0] == pytest.approx(1e3 * 2.50e-8, rel=1e-6)  # (the largest of the last three steps)
    tail = 0.95 + 2e-4 * 0.8 ** np.arange(6)
    errors, how, best, _ = _estimate(tail[:, None], 1e-6)
    assert how == ["Aitken"] and best[0] == pytest.approx(0.95, abs=1e-13) and errors[0] < 1e-12


def test_tiny_steps_along_a_slow_mode_are_not_convergence():
    """At k0 = 1e-3, d = 0.005 the cycles moved by 8e-8 a cycle (below tol / 100) and the
    rule called them converged to 4e-7; 300 more cycles drifted by 3.1e-5
    (docs/validation/micro_cohort.md section 5).  With the model's slowest multiplier there
    (a lone block's relaxation over the period, 0.9992) the same steps leave m / (1 - m)
    times themselves: not within tol; a fast map keeps the old factor five."""
    from micro.cohort.estimate import _estimate, _relaxation_multiplier
    from micro.cohort.options import DEFAULT
    model = micro.Model(k0=0.001)
    m = _relaxation_multiplier(model, 0.0088)
    assert m == pytest.approx(0.9992, abs=1e-4)
    assert _relaxation_multiplier(model, 5.0) == pytest.approx(0.9, abs=2e-3)
    n = np.arange(8)
    a = np.tile((0.9006 - 1e-4 * m ** n)[:, None], (1, 4))  # (steps of 8e-8, 1e-4 to go)
    errors, how, _, _ = _estimate(a, 2e-5, m)
    assert how[0] == "last steps" and errors[0] > 2e-5 and errors[0] >= 0.9006 - a[-1, 0]
    errors, how, _, _ = _estimate(a, 2e-5)
    assert how[0] == "last steps" and errors[0] == pytest.approx(DEFAULT.STILL * 1e-4 * (1 - m) * m ** 5, rel=1e-6)


def test_an_extrapolation_does_not_claim_past_a_slow_mode_it_has_not_seen():
    """Two modes, 0.96 and the model's slowest, 0.982 (a lone block's relaxation at k0 = 0.1,
    0.98 V^c, where shocks leave 43 % of the blocks): five cycles show ratios of about 0.96,
    and Aitken's extrapolation on them claimed 8e-7 where 7e-6 remained (at that point the
    cohort method claimed 1.4e-5 where 3.9e-5 remained, docs/validation/micro_cohort.md
    section 5).  With the slowest multiplier known, the claim covers the distance."""
    from micro.cohort.estimate import _estimate
    n = np.arange(13)
    a = np.tile((0.9 - 1e-4 * 0.96 ** n - 3e-5 * 0.982 ** n)[:, None], (1, 4))
    errors, how, best, _ = _estimate(a, 2e-5)
    assert how[0] == "Aitken" and errors[0] < abs(best[0] - 0.9)  # (what the rule alone gives)
    errors, how, best, _ = _estimate(a, 2e-5, 0.982)
    assert how[0] == "Aitken" and errors[0] >= abs(best[0] - 0.9)


def test_a_stress_passing_through_zero_steps_is_bounded_by_the_state_s_move():
    """Two modes of the state (multipliers 0.97, the model's slowest, and 0.9) move
    sigma_max with opposite signs, so that its steps pass through zero: the rules on its
    own steps call it noise and claim a sixth of the distance (at k0 = 0.3, 0.99 V^c the
    cohort method claimed 1.1e-5 where 3.7e-5 remained, docs/validation/micro_cohort.md
    section 5).  The state's move, a norm, does not pass through zero, and the other
    stresses of the cycle (here sigma_min, on both modes with one sign) show how far the
    stresses move with it: the bound covers the distance.  A kink (a stress jumping where
    the loading phase changes its number of steps) does not set that response."""
    from micro.cohort.estimate import _estimate, _state_tail
    n = np.arange(24)
    u, v = 0.5 * 0.97 ** n, 0.15 * (0.97 / 0.9) ** 21.5 * 0.9 ** n  # (the modes, in mass)
    a = np.tile((0.9 + 1e-3 * (u - v))[:, None], (1, 6))
    a[:, 1] = 0.89 - 1e-3 * (u + 0.2 * v)
    moves = np.concatenate([[np.nan], np.abs(np.diff(u)) + np.abs(np.diff(v))])
    steps = np.full(n.size, 50)  # (every loading phase in 50 steps: no kink)
    errors, how, best, _ = _estimate(a, 2e-5, 0.97)
    distance = abs(best[0] - 0.9)
    assert how[0] == "noise" and errors[0] < distance / 3 and distance > 1.5e-4
    tail, m = _state_tail(a, moves, steps, 0.97)
    assert m == 0.97 and distance <= tail < 3 * distance
    a[18:, 4] += 1e-4  # (sigma_before jumps by 1e-4 at row 18)
    steps[18:] = 49  # (a kink: from row 18 on the loading phase takes a step less)
    assert _state_tail(a, moves, steps, 0.97)[0] == pytest.approx(tail, rel=1e-12)
    steps[18:] = 50
    assert _state_tail(a, moves, steps, 0.97)[0] > 4 * tail
    moves[-1] = 0.0  # (a state that did not move: nothing left)
    assert _state_tail(a, moves, steps, 0.97) == (0.0, 0.0)


def test_a_run_on_plain_cycles_takes_the_state_s_move_as_a_bound():
    """Where shocks leave many blocks (k0 = 0.3, 0.9 V^c: 44 %) the run iterates plain
    cycles, and the bound of the state's move is what it reports (its message names it)."""
    model = micro.Model(k0=0.3)
    res = cycle_cohorts(model, 0.9 * micro.critical_velocity(model).Vc, dt=0.02, tol=1e-4)
    assert res.converged and not res.accelerated and res.error <= 1e-4, res.message
    assert "(state's move)" in res.message, res.message


def test_anderson_beats_the_plain_cycles_close_to_vc():
    # k0 = 0.01, 0.9 V^c: the cycle map contracts by about 0.96 per cycle; fifteen cycles'
    # worth of Anderson's acceleration leaves a smaller residual than fifteen plain cycles
    from micro.cohort.cycle import _one_cycle
    from micro.cohort.solver import _anderson
    model = micro.Model(k0=0.01)
    V = 0.9 * micro.critical_velocity(model).Vc
    h, dt = model.kappa * model.zbar / 10.0, 0.004
    st = _start(model, V, h, None)
    for _ in range(3):
        _one_cycle(st, dt)
    x0 = st.dense(st.n - 1)

    def residual(x):
        s = _start(model, V, h, None, dep=x)
        assert _one_cycle(s, dt)["ok"]
        g = s.dense(s.n - 1)
        return np.abs(g / g.sum() - x / x.sum()).sum()

    state, used, _, _ = _anderson(model, V, h, dt, 0.01, st.copy(), st.period_ref, 1e-12, 15)
    assert state is not None and used == 15
    fast = state.dense(state.n - 1)
    st = _start(model, V, h, None, dep=x0)
    for _ in range(15):
        _one_cycle(st, dt)
    plain = st.dense(st.n - 1)
    assert residual(fast) < 0.3 * residual(plain)


def test_sigma_max_is_the_peak_before_the_shock():
    # k0 = 0.3, 0.5 V^c: the creep before a shock outruns the drive, so the stress peaks
    # about 1e-3 above its value when the shock starts (refined: 0.927168 against
    # sigma_before 0.926157 at the finest level; the Fokker-Planck time-stepping's largest
    # stress is 0.927261 at eps = 0.008); at k0 = 0.01 the two coincide
    model = micro.Model(k0=0.3)
    V = 0.5 * micro.critical_velocity(model).Vc
    res = cycle_cohorts(model, V, dt=0.04, h=model.kappa * model.zbar / 5.0, tol=1e-4)
    assert res.converged
    assert 7e-4 < res.sigma_max - res.sigma_before < 1.4e-3
    # (each is extrapolated on its own: sigma_min <= sigma_after holds to the error)
    assert res.sigma_max > res.sigma_mean > res.sigma_min and res.sigma_min <= res.sigma_after + res.error
    small = micro.Model(k0=0.01)
    res = cycle_cohorts(small, 0.5 * micro.critical_velocity(small).Vc, dt=0.04, h=small.kappa * small.zbar / 5.0,
                        tol=1e-4)
    assert res.converged and abs(res.sigma_max - res.sigma_before) < 1e-9


def _near_vc_state():
    """k0 = 1e-3, 0.95 V^c at twice the default steps and cells: the state three cycles
    from the first shock's image (just after a shock), with its model, V, h and step."""
    model = micro.Model(k0=0.001)
    V = 0.95 * micro.critical_velocity(model).Vc
    h, step = model.kappa * model.zbar / 10, 0.0032616871833801
    st = _start(model, V, h, None)
    for _ in range(3):
        _one_cycle(st, step)
    return model, V, h, step, st


def _near_vc_product_cycle():
    """The product state of :func:`_near_vc_state`'s marginal, and its cycle."""
    from micro.cohort.cycle import _product_cycle
    model, V, h, step, st = _near_vc_state()
    x = st.dense(st.n - 1)
    x /= x.sum()
    _, out, g = _product_cycle(model, V, h, step, st.period_ref, x)
    return model, V, h, x, out, g, step, st.period_ref


def test_a_cycle_at_frozen_slips_repeats_the_cycle_and_is_linear_in_the_marginal():
    """With the slips of a cycle imposed, the cycle from its own start repeats it, and a
    sum of starting masses goes to the sum of their images (the floors and the crossings
    do not depend on the density): what the band preconditioner rests on."""
    from micro.cohort.cycle import _frozen_cycle
    model, V, h, x, out, g, _, _ = _near_vc_product_cycle()
    again = _frozen_cycle(model, V, h, out["start"], out["steps"], x)
    assert np.abs(again / again.sum() - g).sum() < 1e-10
    i, j = int(np.argmax(x)), int(np.argmax(x)) - 30
    e1, e2 = np.zeros_like(x), np.zeros_like(x)
    e1[i], e2[j] = 1.0, 0.5
    images = [_frozen_cycle(model, V, h, out["start"], out["steps"], e) for e in (e1, e2, e1 + e2)]
    assert np.abs(images[2] - images[0] - images[1]).sum() < 1e-12
    assert images[0].sum() == pytest.approx(1.0, abs=1e-9)  # (a total shock: every block jumps)


def test_the_slow_modes_are_the_single_blocks_relaxing():
    """Between total shocks a block's delta_R relaxes alone, by
    a = 1 - alpha (1 - exp(-gamma T)) a cycle (alpha = (k0 + k1) / kappa; by hand from the
    solution of docs/reference/micro_cohort.md section 1), so the marginal's second moment
    relaxes by a^2: the slowest multiplier of the map at frozen slips (with the full map's
    response to a shift of the marginal, which moves the stress).  Newton's check with the whole Jacobian gives 0.9830
    here (benchmarks/results/micro_cohort_newton_check.csv)."""
    from micro.cohort.cycle import _product_cycle
    from micro.cohort.solver import _band_preconditioner
    model, V, h, x, out, g, step, ref = _near_vc_product_cycle()
    _, slowest = _band_preconditioner(model, V, h, lambda v: _product_cycle(model, V, h, step, ref, v), x, out, g)
    alpha = (model.k0 + model.k1) / model.kappa
    a = 1.0 - alpha * (1.0 - math.exp(-model.gamma * out["period"]))
    assert slowest[0] == pytest.approx(a * a, abs=5e-3)  # (0.9825 against 0.9858: blocks also jump between shocks)
    assert slowest[0] == pytest.approx(0.9830, abs=2e-3)


#: The N-block near V^c (micro.nblock, no code shared with the cohort method):
#: benchmarks/results/micro_transition_nblock_check.csv, written by
#: studies/micro_transition_nblock_check.py (its docstring has the commands; 100 shocks
#: discarded, 200-1500 cycles averaged, N = 1e4 to 1e6, several seeds).
NBLOCK_NEAR_VC = Path(__file__).resolve().parents[2] / "benchmarks" / "results" / "micro_transition_nblock_check.csv"


def _nblock_near_vc(k0: float, d: float, column: str) -> tuple[float, float]:
    """(value, tolerance) of the N-block's ``column`` at k0 and d = 1 - V/V^c: the runs at the
    largest N pooled by inverse variance; the tolerance is three of its standard errors plus
    1.25 times its change from the next smaller N (for a finite-N bias falling like N^(-1/2) or
    faster, what is left at N_max is at most change / (sqrt(N_max / N_prev) - 1), 1.21 times
    the change for N_prev = N_max / 3.3).  At k0 = 0.01, d = 0.1: sigma_max 0.914169 +- 1.0e-5,
    0.914219 at N = 3e5, tolerance 9.3e-5 (the N^(-a) fits put the limit at 0.914083-0.914170).
    The N-block's sigma_max and sigma_min are the stress just before and just after its shocks,
    the cohort's cycle extremes exactly at k0 <= 0.01 (the benchmark's docstring)."""
    import pandas as pd
    rows = pd.read_csv(NBLOCK_NEAR_VC)
    rows = rows[np.isclose(rows.k0, k0) & np.isclose(rows.d, d) & (rows.status == "ok")]
    pooled = {}
    for n, g in rows.groupby("N"):
        w = 1.0 / g[f"{column}_stderr"] ** 2
        pooled[n] = (float((w * g[column]).sum() / w.sum()), float(w.sum() ** -0.5))
    sizes = sorted(pooled)
    assert len(sizes) >= 2 and sizes[-1] >= 1e6 and sizes[-1] <= 4 * sizes[-2], sizes
    (value, stderr), (previous, _) = pooled[sizes[-1]], pooled[sizes[-2]]
    return value, 3.0 * stderr + 1.25 * abs(previous - value)


def _assert_plain_cycles_stay(res, n: int) -> None:
    """Plain cycles (the map itself, no acceleration) from the state a run returns stay within
    its claimed fixed-point error of its sigma_max: the reported cycle is a cycle of the map."""
    st = res.state.copy()
    for _ in range(n):
        row = _one_cycle(st, res.state.dt)
        assert abs(row["sigma_max"] - res.sigma_max) <= res.error + 1e-9, (row["sigma_max"], res.sigma_max, res.error)


def test_close_to_vc_the_run_finds_newtons_fixed_point():
    """k0 = 1e-3, 0.95 V^c at twice the default steps and cells: Newton's method with the
    map's whole Jacobian (studies/micro_cohort_newton_check.py, 242 cycles for the
    Jacobian; from the first shock's image, as here) has its fixed point at sigma_max
    0.9071577854, sigma_min 0.8999000063.  The
    preconditioned Anderson iteration gets there (the plain cycles' Aitken rule stopped
    2.2e-5 short, claiming 8.5e-7), and its claimed error covers the distance."""
    model = micro.Model(k0=0.001)
    V = 0.95 * micro.critical_velocity(model).Vc
    res = cycle_cohorts(model, V, dt=0.02, h=model.kappa * model.zbar / 10, tol=5e-5, start=_NO_COARSE)
    assert res.converged
    err_max, err_min = abs(res.sigma_max - 0.9071577853553041), abs(res.sigma_min - 0.8999000063149599)
    assert max(err_max, err_min) < 1e-6
    assert max(err_max, err_min) < 3.0 * res.error + 1e-8, (err_max, err_min, res.error)
    # independent of the method: shocks are total here, so sigma_min is f_th - kappa zbar exactly
    # (docs/reference/micro_model.md, section 5; Newton's 6.3e-9 above it)
    assert abs(res.sigma_min - (model.f_th - model.kappa * model.zbar)) < 1e-7
    # and the cycle reported is a cycle: plain cycles from its state stay within its error
    _assert_plain_cycles_stay(res, 5)


def test_the_carried_cycle_from_a_state_is_its_own_cycle():
    """The map Anderson's iteration runs on: the state just after a shock with its newborns'
    marginal put back as it was is the same state, so its cycle is the plain one, and so is
    the count of blocks its shock left unjumped (it used to count the newborns too when
    storing them compacted the copy's cohorts: 0.99999 instead of 3e-34)."""
    from micro.cohort.cycle import _carried_cycle
    _, _, _, step, st = _near_vc_state()
    plain = st.copy()
    row = _one_cycle(plain, step)
    state, carried, g = _carried_cycle(st, step, st.period_ref, st.dense(st.n - 1))
    assert carried["unjumped"] == pytest.approx(row["unjumped"], abs=1e-12) and row["unjumped"] < 1e-9
    for name in ("sigma_max", "sigma_min", "period"):
        assert carried[name] == pytest.approx(row[name], abs=1e-9)
    assert np.abs(g - plain.dense(plain.n - 1) / plain.dense(plain.n - 1).sum()).sum() < 1e-7


def test_anderson_halves_a_step_the_map_does_not_apply_to(monkeypatch):
    """A step far from the fixed point can land on a state whose cycle the map does not
    apply to (here: the second evaluation's cycle reports too many blocks unjumped); the
    iteration halves it towards the last evaluated marginal and goes on, instead of
    ending there (as it did at k0 = 1e-3, 0.9 V^c in a sweep: 200 plain cycles after it,
    not converged)."""
    from micro.cohort import solver
    model, V, h, x, out, g, step, ref = _near_vc_product_cycle()
    st = _start(model, V, h, None, dep=x)
    st.period_ref = ref
    real, tried = solver._carried_cycle, []

    def flaky(base, step_, ref_, v):
        tried.append(v.copy())
        state, row, image = real(base, step_, ref_, v)
        if len(tried) == 3:  # (the second call is the preconditioner's shift)
            row = dict(row, unjumped=0.5)
        return state, row, image
    monkeypatch.setattr(solver, "_carried_cycle", flaky)
    best, used, slow, _ = solver._anderson(model, V, h, step, 0.02, st, ref, 1e-12, 6)
    assert best is not None and used == 6 and 0.97 < slow < 1.0
    # the next evaluation is the midpoint of the first and the refused second
    assert np.abs(tried[3] - 0.5 * (tried[0] / tried[0].sum() + tried[2])).sum() < 1e-12


def test_anderson_stops_at_once_where_the_frozen_map_grows(monkeypatch):
    """Where the preconditioner's frozen map has a multiplier >= 1 the preconditioned
    iteration does not contract (at k0 = 1e-3, 0.85 V^c its 35 evaluations wandered and
    were thrown away): Anderson returns after its first evaluation with that multiplier,
    and the caller solves by Newton-Krylov (docs/validation/micro_cohort.md section 5)."""
    from micro.cohort import solver
    model, V, h, x, out, g, step, ref = _near_vc_product_cycle()
    st = _start(model, V, h, None, dep=x)
    st.period_ref = ref
    real = solver._band_preconditioner

    def growing(*args, **kwargs):
        M, slowest = real(*args, **kwargs)
        return M, np.concatenate([[1.05], slowest[1:]])
    monkeypatch.setattr(solver, "_band_preconditioner", growing)
    best, used, slow, residual = solver._anderson(model, V, h, step, 0.02, st, ref, 1e-12, 20)
    assert used == 1 and slow == 1.05 and best is not None and 0.0 < residual < 1.0
    monkeypatch.setattr(solver, "_band_preconditioner", real)
    _, used, slow, _ = solver._anderson(model, V, h, step, 0.02, st, ref, 1e-12, 3)
    assert used == 3 and slow < 1.0


@pytest.mark.slow
def test_a_sweep_reaches_the_fixed_point_close_to_vc():
    """The Fig. 10 sweep at k0 = 1e-3: 0.5, 0.7, then 0.9 V^c, each row from the one
    before.  The first preconditioned step from the 0.7 V^c state overshot into a cycle
    with a cut time step; the iteration then ended, and 200 plain cycles did not converge
    (here 60; with the step halved: 24 cycles)."""
    model = micro.Model(k0=0.001)
    Vc = micro.critical_velocity(model).Vc
    prev = None
    for f in (0.5, 0.7):
        prev = cycle_cohorts(model, f * Vc, tol=1e-5, start=prev)
    res = cycle_cohorts(model, 0.9 * Vc, tol=1e-5, start=prev, max_iter=60)
    assert res.converged and res.error < 1e-6, res.message
    assert res.sigma_max == pytest.approx(0.9138256, abs=1e-6)


def _run_with_a_growing_frozen_map(monkeypatch):
    """k0 = 0.01, 0.9 V^c at dt = 0.04, cell kappa zbar / 10, from a cold start, with
    Anderson's frozen-slip map reported as growing (slowest multiplier 1.03); asserts that
    the run was accelerated, so that the caller exercises that path."""
    from micro.cohort import solver
    real = solver._anderson
    seen = []

    def growing(*args, **kwargs):
        best, used, slow, step = real(*args, **kwargs)
        seen.append(slow)
        return best, used, 1.03, step

    monkeypatch.setattr(solver, "_anderson", growing)
    model = micro.Model(k0=0.01)
    V = 0.9 * micro.critical_velocity(model).Vc
    res = cycle_cohorts(model, V, dt=0.04, h=model.kappa * model.zbar / 10.0, start=_NO_COARSE)
    assert seen, "the run was not accelerated: the test no longer exercises the acceleration"
    return res


def test_a_frozen_map_that_grows_leaves_the_fixed_point_uncertified(monkeypatch):
    # k0 = 0.01, 0.9 V^c is accelerated; where the frozen-slip map (Anderson's
    # preconditioner) has a multiplier >= 1 nothing bounds a slower mode, and a pass of the
    # plain cycles' test was measured 3e-5 short of the fixed point (cell kappa zbar / 40,
    # docs/validation/micro_cohort.md section 5): the run must not claim to be converged.
    from micro.cohort import newton, solver
    # (such a run is then solved by Newton-Krylov on the whole map, which certifies it:
    # here it finds no fixed point, as where its budget runs out)
    monkeypatch.setattr(solver, "_newton", lambda *a, **k: newton.NewtonKrylov(message="none"))
    res = _run_with_a_growing_frozen_map(monkeypatch)
    # the stopping test is met (so the row stands), but the error is not known
    assert res.converged and math.isnan(res.error)
    assert "no certified fixed point" in res.message and "1.0300 >= 1" in res.message


def test_a_frozen_map_that_grows_is_solved_by_newton_krylov(monkeypatch):
    """Where the frozen-slip map (Anderson's preconditioner) grows, the fixed point is solved
    by Newton-Krylov on the whole cycle map, and the run's error is its residual's (the last
    Newton step) and the plain cycles' distance from it: finite, and it covers the distance
    to the fixed point that 500 plain cycles reach (no acceleration, cells dropped only
    below 1e-30: at the default CELL_FLOOR the plain cycles lose 5e-12 of the mass a cycle
    and drift, by 1.4e-7 in 700 cycles here; docs/validation/micro_cohort.md section 5).
    Before, such a run reported error NaN.  (At the real grow, kappa zbar / 40 at dt =
    0.02: the slow test below.)"""
    res = _run_with_a_growing_frozen_map(monkeypatch)
    assert res.converged and math.isfinite(res.error) and res.error < 1e-6, res.message
    assert "Newton-Krylov" in res.message and "1.0300 >= 1" in res.message
    # 500 plain cycles at CELL_FLOOR = 1e-30 (their last steps below 2e-11) at this run's step:
    # 0.9139688352273659
    assert abs(res.sigma_max - 0.9139688352273659) <= res.error + 1e-10, (res.sigma_max, res.error)
    # against the N-block, which shares no code with the method: its sigma_max at N -> inf within
    # _nblock_near_vc's tolerance plus this coarse run's discretisation error, which is below 2.5e-4 (twice its
    # measured change, 1.4e-4, to dt = 0.02, h = kappa zbar / 40 in the slow test below)
    model = micro.Model(k0=0.01)
    value, tol = _nblock_near_vc(0.01, 0.1, "sigma_max")
    assert abs(res.sigma_max - value) <= tol + 2.5e-4, (res.sigma_max, value, tol)
    assert abs(res.sigma_min - (model.f_th - model.kappa * model.zbar)) < 1e-5  # (shocks total)


@pytest.mark.slow
def test_close_to_vc_the_fine_cell_is_certified_by_newton_krylov():
    """k0 = 0.01, 0.9 V^c, cell kappa zbar / 40, dt = 0.02: the frozen-slip map grows
    (multiplier 1.028), Anderson's iteration stalls, and the run used to report error NaN
    (its plain cycles passed the stopping test 2e-6 to 3e-5 from where others stopped).
    Newton-Krylov certifies the fixed point, and plain cycles from it stay within its
    error.  At the step this path takes, studies/micro_cohort_newton_krylov.py
    (``--points 40:0.02 --no-consistent``) solved the same map to its round-off: sigma_max
    0.9141064424 (2.3e-9; the run: 0.9141064447, error 5.7e-8).  (The step moved from
    0.0083801882 and the reference from 0.9141064382 when the coarse run's error rule took
    the model's slowest multiplier into its extrapolations: the coarse period, which sets
    the step, moved by 5e-6 of itself.)  (About 20 s.)"""
    model = micro.Model(k0=0.01)
    V = 0.9 * micro.critical_velocity(model).Vc
    res = cycle_cohorts(model, V, dt=0.02, h=model.kappa * model.zbar / 40.0, tol=2e-5)
    assert res.converged and res.accelerated and math.isfinite(res.error) and res.error < 2e-6, res.message
    assert "Newton-Krylov" in res.message
    assert abs(res.sigma_max - 0.9141064424) <= res.error + 2.3e-9
    _assert_plain_cycles_stay(res, 10)
    # against the N-block (no code shared): within its tolerance plus the run's own bound on its
    # discretisation error (the change from twice the step and cell, plus both fixed points' errors)
    assert math.isfinite(res.discretisation_bound) and res.discretisation_bound < 2e-4  # (measured 1.34e-4)
    value, tol = _nblock_near_vc(0.01, 0.1, "sigma_max")
    assert abs(res.sigma_max - value) <= tol + res.discretisation_bound + res.error, (res.sigma_max, value, tol)
    value, tol = _nblock_near_vc(0.01, 0.1, "sigma_min")
    assert abs(res.sigma_min - value) <= tol + res.discretisation_bound + res.error, (res.sigma_min, value, tol)
