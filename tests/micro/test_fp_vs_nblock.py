"""The Fokker-Planck solver against the independent N-block simulation (issue 2, item 5).

The two share nothing but the parameters.  Each comparison allows for (i) the N-block
statistical error (4 standard errors), (ii) its finite-N bias, measured to scale like
1/N with a coefficient below 2 (benchmarks/results/micro_nblock_convergence.csv:
steady k0 = 0.1, V = 2 moves by 1.5e-3, 2.2e-4, 1.7e-5 at N = 1e3, 1e4, 1e5 against
N = 1e6), and (iii) the Fokker-Planck bin error, estimated as |sigma(eps) - sigma(r eps)| with r = 2 or
1.5 (3 or 1.25 times the error of a second-order scheme).  The fast
tests use small N; the slow ones N >= 1e5, where the tolerance is a few 1e-5.
"""
from __future__ import annotations


import pytest

import micro
from micro import nblock

MODEL = micro.Model(k0=0.1)  # the paper's Fig. 4 parameters


def _fp_steady(model, V, eps):
    res = micro.stationary(model, V, numerics=micro.Numerics(eps=eps), method="fp")
    assert res.converged and res.regime == "steady", res.message
    return res.sigma_mean


def _fp_cycle(V, eps, rtol=1e-3):
    res = micro.stationary(MODEL, V, numerics=micro.Numerics(eps=eps), convergence=micro.Convergence(rtol=rtol), method="fp")
    assert res.converged and res.regime == "stick-slip", res.message
    return res


def _check_steady(model, V, eps, n_blocks, share):
    """FP and N-block against each other and each against the exact steady stress (the
    direct method); the N-block tolerance must be below ``share`` of the velocity
    weakening sigma(V) - sigma(V -> inf) that the comparison is about."""
    exact = float(micro.steady_sliding(model, V, growth_rate=False).sigma)
    weakening = exact - micro.sigma_fast_limit(model)
    fine, coarse = _fp_steady(model, V, eps), _fp_steady(model, V, 2.0 * eps)
    ref = nblock.stationary_stress_nblock(model, V, n_blocks, seed=1)
    # (below N ~ 1e5 the N-block system shows near-global avalanches at k0 = 0.1, V = 2)
    assert ref.regime == "steady" or n_blocks < 100_000
    tol_n = 4.0 * ref.sigma_stderr + 2.0 / n_blocks
    assert tol_n < share * weakening, (tol_n, weakening)
    assert abs(ref.sigma_mean - exact) <= tol_n, (ref.sigma_mean, exact, tol_n)
    # the FP's own error at k0 = 0.3, V = 0.4: 2.1e-5 at eps = 0.016, 3.8e-5 at 0.008 (not yet
    # monotone in eps)
    assert abs(fine - exact) <= 4e-3 * weakening, (fine, exact)
    tol = tol_n + abs(fine - coarse)
    assert abs(fine - ref.sigma_mean) <= tol, (fine, ref.sigma_mean, tol)
    return fine, ref


def _check_cycle(eps, n_blocks, coarse_ratio=2.0, share=1.0):
    fine, coarse = _fp_cycle(0.05, eps), _fp_cycle(0.05, coarse_ratio * eps, rtol=1e-2)
    ref = nblock.stick_slip_extrema_nblock(MODEL, 0.05, n_blocks, seed=1)
    assert ref.regime == "stick-slip"
    amplitude = ref.sigma_max - ref.sigma_min
    # finite-N bias of the extrema: measured 1.5e-3 (max) at N = 1e4, 5.9e-4 at 3e4
    bias = 18.0 / n_blocks
    for key, err in (("sigma_max", ref.sigma_max_stderr), ("sigma_min", ref.sigma_min_stderr)):
        a, b, r = getattr(fine, key), getattr(coarse, key), getattr(ref, key)
        tol = 4.0 * err + bias + abs(a - b)
        assert tol < share * amplitude, (key, tol, amplitude)
        assert abs(a - r) <= tol, (key, a, r, tol)
    assert fine.period == pytest.approx(ref.period, abs=4.0 * ref.period_stderr + 0.02 * ref.period)


@pytest.mark.slow  # (12 s under load; steady sliding is the renewal chain's by default, checked by default against an independent reference and a Monte Carlo)
def test_steady_sliding_agrees_with_nblock():
    # k0 = 0.3, V = 0.4 (about 2 V^c): velocity weakening 0.0154; at N = 2e4 the N-block's
    # tolerance is 2.6e-4 (1.7 %; its error 2.4e-5 measured)
    _check_steady(micro.Model(k0=0.3), 0.4, eps=0.016, n_blocks=20_000, share=0.02)


@pytest.mark.slow  # (10 s or so: the default tier keeps under 5 minutes; CI runs the slow tier)
def test_stick_slip_extrema_agree_with_nblock():
    # k0 = 0.1, V = 0.05: cycle amplitude 0.063; the bin error is estimated from eps and
    # 1.5 eps (0.8 |a - b| for order 2); tolerances 1.7e-3 and 2.5e-3, below 4 % of the cycle
    # (it was 5 % at N = 1e4; the FP's bin error, 1.2e-3 between the two bins, dominates now)
    _check_cycle(eps=0.016, n_blocks=30_000, coarse_ratio=1.5, share=0.04)


@pytest.mark.slow
def test_slow_steady_sliding_agrees_with_large_nblock():
    fine, ref = _check_steady(MODEL, 2.0, eps=0.004, n_blocks=100_000, share=0.05)
    assert abs(fine - ref.sigma_mean) < 1.5e-4


@pytest.mark.slow
def test_slow_stick_slip_agrees_with_large_nblock():
    _check_cycle(eps=0.008, n_blocks=200_000)
