"""Tests of the independent N-block simulation (micro.nblock).

Accuracy is checked against a brute-force reference implementation, against closed-form
results (Eq. (4) and its exact finite-N version, the large-V and small-V limits for any g),
and against exact invariants; never against saved output. Long runs are marked slow.
"""
from __future__ import annotations

import math
import re
import sys
from pathlib import Path

import numpy as np
import pytest
from scipy import stats
from scipy.optimize import brentq

import micro._nblock_kernels as K
from micro import nblock as nb
from micro.params import Deterministic, Exponential, Model, Tabulated

sys.path.insert(0, str(Path(__file__).parent))
from _nblock_reference import hash_uniform_numpy, reference_simulate  # noqa: E402


def gamma_pdf(z):
    """A Tabulated g with a vanishing density at z = 0 (shape 2, scale 0.05)."""
    return z * np.exp(-z / 0.05)


DISTRIBUTIONS = {
    "exponential": Exponential(0.1),
    "deterministic": Deterministic(0.1),
    "tabulated": Tabulated(pdf=gamma_pdf, support_max=1.5),
}


# ----------------------------------------------------------------------------------------
# kernels against plain references
# ----------------------------------------------------------------------------------------
def test_landscape_hash_kernel_matches_numpy_and_is_uniform():
    blocks = np.arange(20000) % 137
    counts = np.arange(20000) // 137
    numpy_u = hash_uniform_numpy(12345, blocks, counts)
    kernel_u = np.array([K.hash_uniform(np.uint64(12345), int(b), int(c)) for b, c in zip(blocks[:300], counts[:300])])
    np.testing.assert_array_equal(kernel_u, numpy_u[:300])
    assert np.all((numpy_u > 0.0) & (numpy_u < 1.0))
    assert stats.kstest(numpy_u, "uniform").pvalue > 1e-3
    # different seeds give independent landscapes
    other = hash_uniform_numpy(12346, blocks, counts)
    assert abs(np.corrcoef(numpy_u, other)[0, 1]) < 0.05


@pytest.mark.parametrize("name", sorted(DISTRIBUTIONS))
def test_drawn_distances_follow_g(name):
    dist = DISTRIBUTIONS[name]
    kind, zbar, norm, qu, qz = nb._jump_tables(dist)
    par = np.zeros(K.N_PARAMS)
    par[K.P_KIND], par[K.P_ZBAR], par[K.P_NORM] = kind, zbar, norm
    n = 40000
    z = np.array([K.draw_distance(par, qu, qz, np.uint64(7), i % 200, i // 200) for i in range(n)])
    if name == "deterministic":
        assert np.all(z == dist.zbar)
        return
    assert stats.kstest(z, lambda x: dist.cdf(x)).pvalue > 1e-3
    assert abs(z.mean() - dist.mean) < 5.0 * z.std() / math.sqrt(n)
    # the kernel draws exactly the distribution's own quantile function
    u = np.array([K.hash_uniform(np.uint64(7), i % 200, i // 200) for i in range(2000)])
    np.testing.assert_allclose(z[:2000], dist.quantile(u), rtol=1e-12, atol=1e-14)


def test_first_crossing_matches_brentq(rng):
    gamma, checked = 0.9, 0
    for _ in range(3000):
        alpha, beta = rng.uniform(-0.05, 0.2), rng.uniform(-0.2, 0.2)
        drive, tau_max = rng.choice([0.0, rng.uniform(0.0, 2.0)]), rng.uniform(0.01, 20.0)
        f = lambda s: alpha + beta * np.exp(-gamma * s) - drive * s  # noqa: E731
        tau = K.first_crossing(alpha, beta, gamma, drive, tau_max)
        if f(0.0) <= 0.0:
            assert tau == 0.0
        elif f(tau_max) > 0.0:
            assert tau == -1.0
            # no crossing hidden inside the interval either (f is convex or concave)
            assert np.all(f(np.linspace(0.0, tau_max, 2001)) > 0.0)
        else:
            expected = brentq(f, 0.0, tau_max, xtol=1e-15, rtol=1e-15)
            assert abs(tau - expected) <= 1e-12 * (1.0 + expected)
            # and it is the first root: f > 0 before it
            grid = np.linspace(0.0, tau * (1.0 - 1e-9), 101)
            assert np.all(f(grid) > -1e-15)
            checked += 1
    assert checked > 500


def test_kinetic_tree_tracks_the_lowest_line(rng):
    """Root of the tournament tree = argmin of a_i + b_i x while x decreases, with updates."""
    n, n_leaves = 37, 64
    a = rng.uniform(0.0, 1.0, n)
    b = rng.uniform(-1.0, 1.0, n)
    win = np.empty(2 * n_leaves, dtype=np.int64)
    tree = np.empty((2 * n_leaves, K.N_TREE_COLS))
    par = np.zeros(K.N_PARAMS)
    par[K.P_K0], par[K.P_K1], par[K.P_K2] = 1.0, 0.0, 1.0  # so that a = h and b = S
    K.tree_build(a, b, par, n_leaves, win, tree, 1.0)
    swaps = 0
    for x in np.geomspace(1.0, 1e-3, 400)[1:]:
        swaps += K.tree_process_swaps(win, tree, x, n_leaves)
        values = a + b * x
        assert values[win[1]] == pytest.approx(values.min(), abs=1e-12)
        assert tree[1, K.T_MXC] < x
        if rng.random() < 0.3:  # a jump: one block gets a new line
            i = int(rng.integers(n))
            a[i] += rng.uniform(0.0, 0.5)
            b[i] += rng.uniform(-0.5, 0.5) / x
            K.tree_set_leaf(i, a[i], b[i], n_leaves, win, tree, x)
            assert (a + b * x)[win[1]] == pytest.approx((a + b * x).min(), abs=1e-12)
    assert swaps > 20


CASES = [
    # (k0, velocity or schedule, t_max)
    (1.0, 1.0, 3.0),  # steady sliding
    (0.1, 0.2, 3.0),  # stick-slip: global shocks
    (0.1, [(1.0, 0.3), (0.5, 0.0), (1.0, 2.0)], None),  # slide-hold-slide
]


@pytest.mark.parametrize("name", sorted(DISTRIBUTIONS))
@pytest.mark.parametrize("k0,velocity,t_max", CASES)
def test_event_driven_kernel_matches_bruteforce_reference(name, k0, velocity, t_max):
    model = Model(k0=k0, k1=0.1, k2=0.9, jumps=DISTRIBUTIONS[name])
    n = 24
    ref = reference_simulate(model, velocity, n, t_max=t_max, seed=3)
    res = nb.simulate_nblock(model, velocity, n, t_max=t_max, seed=3, record_every=0.01)
    assert res.status == "completed"
    assert res.n_jumps == ref["n_jumps"] > 50
    assert res.n_avalanches == ref["n_avalanches"]
    np.testing.assert_allclose(res.final_state.h, ref["state"].h, atol=1e-11)
    np.testing.assert_allclose(res.final_state.u, ref["state"].u, atol=1e-11)
    assert res.final_state.w == pytest.approx(ref["state"].w, abs=1e-11)
    assert res.sigma_integral == pytest.approx(ref["sigma_integral"], abs=1e-10)


def test_kernel_matches_reference_through_swaps_and_rebases():
    """Fast relaxation (eta_u = 0.05, gamma = 18) forces many tree swaps and x-rebases."""
    model = Model(k0=0.5, k1=0.1, k2=0.9, eta_u=0.05, jumps=Exponential(0.1))
    velocity, n, t_max = 0.4, 40, 4.0
    ref = reference_simulate(model, velocity, n, t_max=t_max, seed=11, phases="random")
    res = nb.simulate_nblock(model, velocity, n, t_max=t_max, seed=11, phases="random", record_every=0.5)
    assert res.n_rebases >= 3 and res.n_swaps >= 50
    assert res.n_jumps == ref["n_jumps"]
    np.testing.assert_allclose(res.final_state.h, ref["state"].h, atol=1e-10)
    np.testing.assert_allclose(res.final_state.u, ref["state"].u, atol=1e-10)
    assert res.sigma_integral == pytest.approx(ref["sigma_integral"], abs=1e-9)


@pytest.mark.parametrize("k1,k2", [(0.1, 0.0), (0.0, 0.9)])
@pytest.mark.parametrize("velocity", [1.0, 0.0, [(1.0, 0.5), (2.0, 0.0)]])
def test_kernel_matches_reference_at_k1_or_k2_zero_and_holds(k1, k2, velocity):
    model = Model(k0=0.3, k1=k1, k2=k2, jumps=Exponential(0.1))
    ref = reference_simulate(model, velocity, 30, t_max=3.0, seed=2, phases="random")
    res = nb.simulate_nblock(model, velocity, 30, t_max=3.0, seed=2, phases="random")
    assert res.n_jumps == ref["n_jumps"]
    np.testing.assert_allclose(res.final_state.h, ref["state"].h, atol=1e-11)
    np.testing.assert_allclose(res.final_state.u, ref["state"].u, atol=1e-11)


# ----------------------------------------------------------------------------------------
# invariants
# ----------------------------------------------------------------------------------------
def test_mean_dashpot_elongation_relaxes_exactly():
    r"""Jumps leave u unchanged and Eq. (2) averages to d<u>/dt = -gamma <u>: <u>(t) = <u>(0) e^{-gamma t}."""
    model = Model(k0=0.3, k1=0.1, k2=0.9, jumps=Exponential(0.1))
    n = 500
    st = nb.initial_state(model, n)
    for offset in (0.0, 0.05):
        start = nb.NBlockState(h=st.h, u=st.u + offset, w=st.w)
        res = nb.simulate_nblock(model, 0.7, n, t_max=30.0, record_every=1.0, initial=start, seed=2)
        assert res.n_jumps > 10 * n
        expected = offset * np.exp(-model.gamma * res.timeseries["t"].to_numpy())
        np.testing.assert_allclose(res.timeseries["mean_u"], expected, atol=1e-11)
        assert np.mean(res.final_state.u) == pytest.approx(expected[-1], abs=1e-11)


def test_stress_identity_and_shock_drops():
    """sigma = k0 (w - hbar) at the end; a global shock drops sigma by exactly k0 * delta_hbar."""
    model = Model(k0=0.1, k1=0.1, k2=0.9, jumps=Exponential(0.1))
    res = nb.simulate_nblock(model, 0.05, 2000, t_max=60.0, record_every=0.5, seed=4)
    fs = res.final_state
    assert res.timeseries["sigma"].iloc[-1] == pytest.approx(model.k0 * (fs.w - np.mean(fs.h)), abs=1e-10)
    assert res.timeseries["w"].iloc[-1] == pytest.approx(fs.w, abs=1e-10)
    assert len(res.shocks) >= 2
    drops = res.shocks["sigma_before"] - res.shocks["sigma_after"]
    np.testing.assert_allclose(drops, model.k0 * res.shocks["delta_hbar"], atol=1e-10)
    # every block is stable at the end
    assert np.all(fs.delta(model) > 0.0)
    # w advanced by V t
    st = nb.initial_state(model, 2000)
    assert fs.w == pytest.approx(st.w + 0.05 * 60.0, abs=1e-9)


def test_hold_keeps_drive_fixed_and_schedule_semantics():
    model = Model(k0=0.3, k1=0.1, k2=0.9, jumps=Exponential(0.1))
    schedule = [(5.0, 1.0), (5.0, 0.0), (2.0, 1.0)]
    res = nb.simulate_nblock(model, schedule, 300, record_every=0.5, seed=1)
    ts = res.timeseries
    assert ts["t"].iloc[-1] == pytest.approx(12.0)
    hold = ts[(ts["t"] > 5.0 + 1e-9) & (ts["t"] <= 10.0 + 1e-9)]
    assert np.ptp(hold["w"]) == 0.0
    w0 = nb.initial_state(model, 300).w
    assert ts["w"].iloc[-1] == pytest.approx(w0 + 7.0, abs=1e-9)
    # a longer t_max holds the last velocity, a shorter one cuts the schedule
    longer = nb.simulate_nblock(model, schedule, 300, t_max=14.0, record_every=0.5, seed=1)
    assert longer.final_state.w == pytest.approx(w0 + 9.0, abs=1e-9)
    shorter = nb.simulate_nblock(model, schedule, 300, t_max=7.0, record_every=0.5, seed=1)
    assert shorter.final_state.w == pytest.approx(w0 + 5.0, abs=1e-9)


def test_stop_conditions_are_reported():
    model = Model(k0=0.1, k1=0.1, k2=0.9, jumps=Exponential(0.1))
    capped = nb.simulate_nblock(model, 1.0, 500, t_max=100.0, max_jumps=1000)
    assert capped.status == "jump_limit" and not capped.success
    assert capped.n_jumps == 1000 and capped.final_state.t < 100.0
    shocks = nb.simulate_nblock(model, 0.05, 500, t_max=1000.0, stop_after_shocks=3)
    assert shocks.status == "shock_limit" and shocks.success and len(shocks.shocks) == 3
    assert shocks.final_state.t == pytest.approx(shocks.shocks["t"].iloc[-1])


# ----------------------------------------------------------------------------------------
# analytic results
# ----------------------------------------------------------------------------------------
def test_finite_n_formula_tends_to_eq4():
    model = Model(k0=1.0, k1=0.1, k2=0.9, jumps=Deterministic(0.1))
    for v in (0.5, 1.0, 5.0):
        eq4 = nb.sigma_deterministic_steady(model, v)
        gaps = [nb.sigma_deterministic_steady_finite_n(model, v, n) - eq4 for n in (10**3, 10**4, 10**5)]
        assert gaps[0] > 0.0 and gaps[1] == pytest.approx(gaps[0] / 10.0, rel=0.02)
        assert abs(gaps[2]) < 1e-6


@pytest.mark.parametrize("velocity,n", [(0.5, 100), (1.0, 100), (5.0, 100), (0.5, 1000), (1.0, 1000)])
def test_deterministic_jumps_reach_eq4_exactly_at_finite_n(velocity, n):
    """Evenly spaced phases: after the transient sigma equals the exact N-block steady state."""
    model = Model(k0=1.0, k1=0.1, k2=0.9, jumps=Deterministic(0.1))
    res = nb.simulate_nblock(model, velocity, n, t_max=80.0, record_every=20.0, initial="frozen")
    late = res.timeseries["sigma_mean"].iloc[-1]  # exact time average over t in [60, 80]
    exact = nb.sigma_deterministic_steady_finite_n(model, velocity, n)
    assert late == pytest.approx(exact, abs=2e-8)
    assert abs(late - nb.sigma_deterministic_steady(model, velocity)) < 0.1 / n
    assert res.n_avalanches == res.n_jumps  # blocks jump one at a time, in turn


def test_stationary_stress_deterministic_matches_eq4_within_error():
    model = Model(k0=1.0, k1=0.1, k2=0.9, jumps=Deterministic(0.1))
    out = nb.stationary_stress_nblock(model, 1.0, 5000, t_transient=10.0, batch_length=2.0, n_batches=10,
                                      initial="frozen")
    assert out.regime == "steady" and out.n_global_shocks == 0
    eq4 = nb.sigma_deterministic_steady(model, 1.0)
    finite_n = 0.1 / out.n_blocks  # bound on the O(1/N) gap (measured 0.045/N)
    assert abs(out.sigma_mean - eq4) <= 4.0 * out.sigma_stderr + finite_n + 1e-9


def test_random_phases_with_deterministic_jumps_synchronise():
    """Independent random phases: blocks that jump in one avalanche keep equal increments
    and stay together for ever (pulse-coupled synchronisation), so clusters are frozen and
    sigma is biased above the evenly spaced value."""
    model = Model(k0=1.0, k1=0.1, k2=0.9, jumps=Deterministic(0.1))
    n = 2000
    res = nb.simulate_nblock(model, 1.0, n, t_max=150.0, record_every=25.0, phases="random", seed=5,
                             initial="frozen")
    ts = res.timeseries
    periods_per_bin = 25.0 / (model.jumps.mean / 1.0)
    clusters = ts["n_avalanches"].to_numpy() / periods_per_bin
    assert clusters[-1] == clusters[-2] < n / 5  # every cluster fires once per period, in mean groups > 5
    assert ts["max_avalanche"].iloc[-1] == ts["max_avalanche"].iloc[-2] > 50  # the same largest cluster
    assert ts["sigma_mean"].iloc[-1] > nb.sigma_deterministic_steady_finite_n(model, 1.0, n) + 1e-4


def test_fast_limit_for_exponential_g():
    model = Model(k0=1.0, k1=0.1, k2=0.9, jumps=Exponential(0.1))
    v = 1000.0
    out = nb.stationary_stress_nblock(model, v, 10000, t_transient=0.004, batch_length=0.004, n_batches=16,
                                      initial="relaxed")
    limit = nb.sigma_fast_limit(model, v)
    finite_n = 0.5 / out.n_blocks
    assert abs(out.sigma_mean - limit) <= 4.0 * out.sigma_stderr + finite_n
    # the limit is kappa times the mean residual: far from the (k0 + k1) or Eq. (6) values
    assert abs(out.sigma_mean - (1.0 - (model.k0 + model.k1) * model.jumps.mean_residual)) > 50 * out.sigma_stderr


def test_slow_limit_for_exponential_g():
    model = Model(k0=1.0, k1=0.1, k2=0.9, jumps=Exponential(0.1))
    v = 0.002
    out = nb.stationary_stress_nblock(model, v, 100000, t_transient=50.0, batch_length=50.0, n_batches=16, seed=1)
    assert out.regime == "steady"
    limit = nb.sigma_slow_limit(model, v)
    # next order: incomplete relaxation of blocks with z < V / gamma, measured +7e-5 here
    higher_order = 2e-4
    assert abs(out.sigma_mean - limit) <= 4.0 * out.sigma_stderr + higher_order
    assert abs(out.sigma_mean - nb.sigma_fast_limit(model)) > 0.05


def test_k0_above_k2_has_no_global_shocks_but_k0_below_has():
    fast = Model(k0=1.0, k1=0.1, k2=0.9, jumps=Exponential(0.1))
    res = nb.simulate_nblock(fast, 0.01, 20000, t_max=200.0, record_every=10.0, seed=3)
    assert len(res.shocks) == 0 and res.timeseries["max_avalanche"].max() < 0.25 * 20000
    soft = Model(k0=0.1, k1=0.1, k2=0.9, jumps=Exponential(0.1))
    out = nb.stick_slip_extrema_nblock(soft, 0.05, 5000, n_cycles=5, n_discard=3)
    assert out.regime == "stick-slip" and out.n_cycles == 5
    assert out.sigma_max - out.sigma_min > 10 * (out.sigma_max_stderr + out.sigma_min_stderr)


# ----------------------------------------------------------------------------------------
# input validation
# ----------------------------------------------------------------------------------------
MODEL = Model(k0=0.3)


@pytest.mark.parametrize(
    "kwargs,match",
    [
        (dict(n_blocks=1), "n_blocks"),
        (dict(n_blocks=2.5), "n_blocks"),
        (dict(n_blocks=True), "n_blocks"),
        (dict(n_blocks="100"), "n_blocks"),
        (dict(velocity=-1.0), "velocity"),
        (dict(velocity=float("nan")), "velocity"),
        (dict(velocity=float("inf")), "velocity"),
        (dict(velocity="fast"), "velocity"),
        (dict(velocity=[]), "schedule"),
        (dict(velocity=[(1.0,)]), "schedule entry 0"),
        (dict(velocity=[(1.0, 1.0), (-1.0, 1.0)]), "entry 1 duration"),
        (dict(velocity=[(1.0, -2.0)]), "entry 0 velocity"),
        (dict(t_max=0.0), "t_max"),
        (dict(t_max=-1.0), "t_max"),
        (dict(t_max=float("nan")), "t_max"),
        (dict(t_max=None), "t_max"),
        (dict(record_every=0.0), "record_every"),
        (dict(record_every=1e-12), "record_every"),
        (dict(seed=-1), "seed"),
        (dict(shock_fraction=0.0), "shock_fraction"),
        (dict(initial="hot"), "initial"),
        (dict(phases="chaotic"), "phases"),
        (dict(stop_after_shocks=0), "stop_after_shocks"),
        (dict(max_jumps=0), "max_jumps"),
        (dict(model="model"), "model"),
    ],
)
def test_simulate_rejects_bad_input(kwargs, match):
    args = dict(model=MODEL, velocity=1.0, n_blocks=100, t_max=1.0)
    args.update(kwargs)
    with pytest.raises(ValueError, match=match):
        nb.simulate_nblock(**args)


def test_bad_initial_state_and_helper_arguments_are_rejected():
    st = nb.initial_state(MODEL, 10)
    with pytest.raises(ValueError, match="shape"):
        nb.simulate_nblock(MODEL, 1.0, 11, t_max=1.0, initial=st)
    bad = nb.NBlockState(h=st.h, u=st.u * np.nan, w=st.w)
    with pytest.raises(ValueError, match="finite"):
        nb.simulate_nblock(MODEL, 1.0, 10, t_max=1.0, initial=bad)
    with pytest.raises(ValueError, match="velocity"):
        nb.stationary_stress_nblock(MODEL, 0.0, 100)
    with pytest.raises(ValueError, match="n_batches"):
        nb.stationary_stress_nblock(MODEL, 1.0, 100, n_batches=1)
    with pytest.raises(ValueError, match="batch_length"):
        nb.stationary_stress_nblock(MODEL, 1.0, 100, batch_length=-1.0)
    with pytest.raises(ValueError, match="n_cycles"):
        nb.stick_slip_extrema_nblock(MODEL, 1.0, 100, n_cycles=1)
    with pytest.raises(ValueError, match="velocity"):
        nb.sigma_deterministic_steady(MODEL, -1.0)


# ----------------------------------------------------------------------------------------
# long runs
# ----------------------------------------------------------------------------------------
@pytest.mark.slow
@pytest.mark.parametrize("velocity", [0.5, 1.0, 5.0])
def test_slow_deterministic_eq4_large_n(velocity):
    model = Model(k0=1.0, k1=0.1, k2=0.9, jumps=Deterministic(0.1))
    n = 10000
    res = nb.simulate_nblock(model, velocity, n, t_max=80.0, record_every=20.0, initial="frozen")
    late = res.timeseries["sigma_mean"].iloc[-1]
    assert late == pytest.approx(nb.sigma_deterministic_steady_finite_n(model, velocity, n), abs=2e-8)
    assert abs(late - nb.sigma_deterministic_steady(model, velocity)) < 0.1 / n


@pytest.mark.slow
@pytest.mark.parametrize("velocity", [50.0, 200.0])
def test_slow_fast_limit_first_correction(velocity):
    model = Model(k0=1.0, k1=0.1, k2=0.9, jumps=Exponential(0.1))
    out = nb.stationary_stress_nblock(model, velocity, 20000, t_transient=2.0, batch_length=0.2, n_batches=20,
                                      initial="frozen")
    assert abs(out.sigma_mean - nb.sigma_fast_limit(model, velocity)) <= 4.0 * out.sigma_stderr + 0.5 / 20000


@pytest.mark.slow
def test_slow_stick_slip_extrema_converge_in_n():
    model = Model(k0=0.1, k1=0.1, k2=0.9, jumps=Exponential(0.1))
    small = nb.stick_slip_extrema_nblock(model, 0.05, 10000, n_cycles=20)
    large = nb.stick_slip_extrema_nblock(model, 0.05, 100000, n_cycles=20)
    for attr in ("sigma_max", "sigma_min"):
        err = getattr(small, attr + "_stderr") + getattr(large, attr + "_stderr")
        assert abs(getattr(small, attr) - getattr(large, attr)) < 5.0 * err + 2e-3


def test_docs_example_runs():
    """The example at the top of docs/reference/micro_nblock.md runs as written."""
    text = (Path(__file__).resolve().parents[2] / "docs" / "reference" / "micro_nblock.md").read_text()
    blocks = re.findall(r"```python\n(.*?)```", text, flags=re.S)
    assert blocks
    for code in blocks:
        namespace: dict = {}
        exec(compile(code, "docs/reference/micro_nblock.md", "exec"), namespace)
    assert namespace["cycle"].regime == "stick-slip"
    assert namespace["steady"].sigma_stderr > 0.0


def test_stick_slip_extrema_flag_a_transient():
    # k0 = 0.01, V = 1 (0.125 V^c): from the relaxed start sigma_max falls from 0.989 towards
    # 0.9622 over some 30 cycles, so with no discarded shock the sequence drifts and says so
    model = nb.Model(k0=0.01)
    out = nb.stick_slip_extrema_nblock(model, 1.0, 5000, n_cycles=10, n_discard=0)
    assert out.status == "transient"
    assert "raise n_discard" in out.message
    seq = out.shocks["sigma_before"].to_numpy()
    assert seq[0] - seq[-1] > 0.01
    # the standard error is not the naive one of a strongly correlated sequence
    assert out.sigma_max_stderr > seq.std(ddof=1) / np.sqrt(seq.size)


@pytest.mark.slow
def test_the_default_discard_runs_until_the_cycles_stop_drifting():
    # k0 = 0.01, V = 1 (0.125 V^c), N = 2e4: from the relaxed start ten discarded shocks
    # leave sigma_max drifting (0.96328 over the first four cycles, 0.96230 over the next
    # four), which the status says; the default discard goes on until the last sixteen
    # cycles pass the drift test
    model = nb.Model(k0=0.01)
    fixed = nb.stick_slip_extrema_nblock(model, 1.0, 20000, n_cycles=8, n_discard=10)
    assert fixed.status == "transient"
    auto = nb.stick_slip_extrema_nblock(model, 1.0, 20000, n_cycles=8)
    assert auto.status == "ok", auto.message
    discarded = int(auto.message.split(" after ")[1].split()[0])
    assert discarded > 10
    assert len(auto.shocks) == 8
    # the continuations' shock times follow on from the run before
    assert auto.shocks["t"].is_monotonic_increasing
    assert auto.period == pytest.approx(float(np.diff(auto.shocks["t"]).mean()))
    assert abs(auto.period - fixed.period) < 5.0 * math.hypot(auto.period_stderr, fixed.period_stderr)


def test_n_discard_auto_is_checked():
    with pytest.raises(ValueError, match="n_discard must be an integer in \\[0, 1000000\\] or 'auto'"):
        nb.stick_slip_extrema_nblock(MODEL, 1.0, 100, n_discard="many")
    with pytest.raises(ValueError, match="max_discard"):
        nb.stick_slip_extrema_nblock(MODEL, 1.0, 100, max_discard=3)
