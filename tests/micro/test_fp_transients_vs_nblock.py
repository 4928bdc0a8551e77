"""The Fokker-Planck transients against the independent N-block (issue 53, item 4).

micro's default for a transient is the Fokker-Planck equation (FP); these tests hold two of
them against the N-block, which shares nothing with it but the parameters:

* the slide-hold-slide peak against hold time (k0 = 0.3, V = 1, about 5 V^c; holds 1, 3, 10);
* the paper's Fig. 3 slow trace from a start (k0 = 0.01, V = 0.001), at a handful of times.

The N-block reference is precomputed (one row per seed and N) by
studies/micro_fp_transients_nblock_reference.py into tests/data/micro_fp_transients_nblock.csv,
whose first line gives the command, date and commit.  Each comparison allows

    K * (the N-block's standard error over independent seeds + the FP's bin error) + bias,

where the FP's bin error is measured in the test: the change of the result from eps to eps / 2
(taken as the error of the eps / 2 value; K covers how far that has been measured to
underestimate it, see ``K``), and ``bias`` is the N-block's finite-N bias, bounded by the
change of its mean from N / 10 to N (a bound for any bias falling like N^-p with p >= 0.3).
A check also fails if its tolerance is not small against what it checks, and the
fault-injection tests show that the checks fail when the FP solves a model whose mean jump is
off by 5 % (Fig. 3) or 10 % (slide-hold-slide).
"""
from __future__ import annotations

from pathlib import Path

import numpy as np
import pandas as pd
import pytest

import micro

CSV = Path(__file__).resolve().parents[1] / "data" / "micro_fp_transients_nblock.csv"
#: the multiple of (standard error + bin error) allowed.  The FP's peak does not converge
#: monotonically in eps: over the pairs (eps, eps / 2) from 0.032 to 0.004 the change
#: underestimated the error of the eps / 2 value (against the N-block at N = 1e5) by up to
#: 2.94 times (at eps = 0.02, hold 1), and by 2.15 at this test's eps = 0.016
#: (docs/validation/micro_numerics.md §6)
K = 3.0

SHS_MODEL, SHS_V, SHS_RESUME = micro.Model(k0=0.3), 1.0, 1.0
FIG3_MODEL, FIG3_V, FIG3_HALF_WINDOW = micro.Model(k0=0.01), 0.001, 25.0


def _reference(kind: str, key: str, at: str) -> pd.DataFrame:
    """Mean over seeds at the largest N, its standard error, and the bias bound
    |mean(N) - mean(N / 10)| (or the largest change to a smaller N if N / 10 is absent)."""
    ref = pd.read_csv(CSV, comment="#")
    ref = ref[ref.kind == kind]
    stats = ref.groupby(["N", at])[key].agg(["mean", "std", "count"]).reset_index()
    n_max = stats.N.max()
    big = stats[stats.N == n_max].set_index(at)
    small = stats[stats.N < n_max]
    small = small[small.N == small.N.max()].set_index(at)
    out = pd.DataFrame({"mean": big["mean"], "stderr": big["std"] / np.sqrt(big["count"]),
                        "bias": (big["mean"] - small["mean"]).abs(), "N": n_max})
    return out


def _check(fine: pd.Series, coarse: pd.Series, ref: pd.DataFrame, scale, share: float) -> pd.DataFrame:
    """Compare ``fine`` (the FP at eps / 2) with the reference.  A row passes (``ok``) if the
    FP is within the tolerance and the tolerance is below ``share * scale`` (a check whose
    tolerance outgrew what it checks confirms nothing)."""
    table = ref.assign(fp=fine, fp_coarse=coarse)
    table["bin_error"] = (table.fp - table.fp_coarse).abs()
    table["tol"] = K * (table.stderr + table.bin_error) + table.bias
    table["diff"] = table.fp - table["mean"]
    table["tight"] = table.tol < share * scale
    table["ok"] = (table["diff"].abs() <= table.tol) & table.tight
    return table


# --------------------------------------------------------------------------- slide-hold-slide
def _fp_shs(model: micro.Model, eps: float, holds) -> pd.Series:
    res = micro.slide_hold_slide(model, SHS_V, list(holds), numerics=micro.FP(eps=eps), resume=SHS_RESUME)
    return pd.Series(res.delta_sigma_max.to_numpy(), index=pd.Index(res.hold_time.to_numpy(), name="hold"))


def _shs_table(model: micro.Model, eps: float) -> pd.DataFrame:
    ref = _reference("shs", "delta_sigma_max", "hold")
    fine, coarse = _fp_shs(model, eps / 2.0, ref.index), _fp_shs(model, eps, ref.index)
    # the tolerance below a tenth of each hold's peak increase
    return _check(fine, coarse, ref, scale=ref["mean"], share=0.1)


# --------------------------------------------------------------------------- Fig. 3
def _fp_fig3(model: micro.Model, eps: float, times) -> pd.Series:
    t_end = max(times) + FIG3_HALF_WINDOW
    rec = micro.simulate(model, FIG3_V, duration=t_end, numerics=micro.FP(eps=eps),
                         record_dt=1.0, record_dsigma=1.0).records
    t, sigma_mean = rec.t.to_numpy(), rec.sigma_mean.to_numpy()
    dt = np.diff(np.concatenate([[0.0], t]))  # sigma_mean: the mean over the window since the last record
    out = []
    for tc in times:
        sel = (t > tc - FIG3_HALF_WINDOW) & (t <= tc + FIG3_HALF_WINDOW)
        out.append(float(np.sum(sigma_mean[sel] * dt[sel]) / np.sum(dt[sel])))
    return pd.Series(out, index=pd.Index(list(times), name="t"))


def _fig3_table(model: micro.Model, eps: float, t_max: float) -> pd.DataFrame:
    ref = _reference("fig3", "sigma", "t")
    ref = ref[ref.index <= t_max]
    fine, coarse = _fp_fig3(model, eps / 2.0, ref.index), _fp_fig3(model, eps, ref.index)
    # the tolerance below 2 % of the first shock's stress drop, kappa * zbar (the stress then
    # rises by k0 V per time unit, without creep to t = 7000 in both solvers)
    return _check(fine, coarse, ref, scale=FIG3_MODEL.kappa * FIG3_MODEL.zbar, share=0.02)


# --------------------------------------------------------------------------- the tests
@pytest.mark.slow  # (10 s or so: the default tier keeps under 5 minutes; CI runs the slow tier)
def test_slide_hold_slide_peak_agrees_with_nblock():
    # eps = 0.016 and 0.008 (about 15 CPU s); the FP at 0.008 is 1.7-1.8e-3 above the N-block
    # (its error measured 2.6-3.6e-3 at eps = 0.016, 0.6-0.9e-3 at 0.004: first order)
    table = _shs_table(SHS_MODEL, eps=0.016)
    assert table.ok.all(), table.to_string()


def test_fig3_trace_agrees_with_nblock():
    # the first 500 time units of the slow trace: eps = 0.02 and 0.01 (about 3 CPU s)
    table = _fig3_table(FIG3_MODEL, eps=0.02, t_max=500.0)
    assert table.ok.all(), table.to_string()


def test_fig3_check_catches_a_wrong_jump_size():
    # fault injection: the FP solves a model whose mean jump is 5 % too large (as a D_c 5 % off)
    faulty = micro.Model(k0=FIG3_MODEL.k0, jumps=micro.Exponential(zbar=0.105))
    table = _fig3_table(faulty, eps=0.02, t_max=250.0)
    assert not table.ok.any(), table.to_string()


@pytest.mark.slow
def test_slow_slide_hold_slide_check_catches_a_wrong_jump_size():
    # fault injection: a mean jump 10 % too large (+5.5-7.5e-3 on the peaks at eps = 0.008;
    # fails all three holds).  5 % is caught at one hold or none depending on where the bins
    # fall (zbar = 0.1049, 0.105, 0.1051): the FP's peak at a fixed eps moves by up to 2e-3
    # with the bin placement (0.105 against 1.05 * 0.1 at eps = 0.016), which the tolerance
    # must carry
    faulty = micro.Model(k0=SHS_MODEL.k0, jumps=micro.Exponential(zbar=0.11))
    table = _shs_table(faulty, eps=0.016)
    assert not table.ok.all(), table.to_string()


@pytest.mark.slow
def test_slow_fig3_trace_agrees_with_nblock_to_the_first_slow_shock():
    # to t = 7000 (the first slow shock comes near 8100): about 40 CPU s
    table = _fig3_table(FIG3_MODEL, eps=0.02, t_max=7000.0)
    assert table.ok.all(), table.to_string()
