"""The quick report's scientific outputs against values computed independently of it:
closed forms, analytic limits, the N-block's bracket of V^c (docs/reference/micro_nblock.md)."""
from __future__ import annotations

import math

import numpy as np
import pandas as pd
import pytest

import compare
import micro
import rsf


@pytest.fixture(scope="module")
def rep(tmp_path_factory):
    tmp = tmp_path_factory.mktemp("quick")
    return compare.report(compare.Settings.quick(), out=tmp / "report", cache_dir=tmp / "cache", workers=1,
                          progress=False)


def test_critical_velocity_table_has_all_five_k0_and_the_kept_columns(rep):
    crit = pd.read_csv(rep.out / "critical_velocity.csv")
    assert {"k0", "Vc_micro", "Vc_rs"} <= set(crit.columns)
    assert sorted(crit.k0) == sorted(compare.PAPER_K0)
    # micro's V^c against its small-k0 asymptote k2 gamma <z^2>/(2 zbar k0) (derived, not solved):
    # 0.1 % at k0 = 1e-4, where the next order is ~k0; a wrong V^c solver misses it by far more
    small = crit.set_index("k0")
    assert small.Vc_micro[1e-4] == pytest.approx(small.Vc_micro_small_k0[1e-4], rel=1e-3)
    # ... and against the N-block's bracket at k0 = 0.1 (stick-slip at 0.70, steady at 0.75)
    assert 0.70 < small.Vc_micro[0.1] < 0.75


def test_rs_critical_velocity_is_the_closed_form_root(rep):
    """RS's V^c of the report against k0 D_c = A V/(V + B)^2 solved here by hand."""
    crit = rep["critical_velocity"]
    A, B, Dc = rep.values["A"], rep.values["B"], rep.values["Dc"]
    for _, r in crit[np.isfinite(crit.Vc_rs)].iterrows():
        c = r.k0 * Dc
        # c (V + B)^2 = A V  ->  the larger root
        a2, a1, a0 = c, 2 * c * B - A, c * B * B
        V_plus = (-a1 + math.sqrt(a1 * a1 - 4 * a2 * a0)) / (2 * a2)
        assert r.Vc_rs == pytest.approx(V_plus, rel=1e-9)


def test_eq10_fit_to_the_exact_branch(rep):
    """A and B near the paper's (0.007, 0.078), each offset within 2e-4 of micro's exact
    sigma(V -> inf) = f_th - kappa <z^2>/(2 zbar) (the fit does not know it), and the
    tail ratio A / C reported against C = k2 gamma Var(R) (analytic)."""
    assert rep.values["A"] == pytest.approx(rsf.PAPER_A, rel=0.15)
    assert rep.values["B"] == pytest.approx(rsf.PAPER_B, rel=0.15)
    chk = rep["steady_fit_checks"]
    assert np.all(np.abs(chk.offset_error) < 2e-4)
    model = micro.Model(k0=0.1)
    C = micro.sigma_fast_limit(model, 1.0) - micro.sigma_fast_limit(model)
    assert chk.tail_ratio.iloc[0] == pytest.approx(rep.values["A"] / C, rel=1e-12)
    assert rep.values["steady_max_residual"] < 2e-3


def test_dc_from_critical_velocity_reproduces_each_k0(rep):
    """Per k0 the V^c-matching D_c puts RS's V^c exactly on micro's."""
    per = rep["dc_critical"]
    for _, r in per.iterrows():
        cv = rsf.critical_velocity(rsf.HyperbolicLaw(A=rep.values["A"], B=rep.values["B"], mu_inf=0.0), r.k0,
                                   r.Dc_law)
        assert cv.Vc == pytest.approx(r.Vc_micro, rel=1e-8)
    # micro's own slope gives D_c -> zbar at small k0 (W(V) -> C/V with V^c -> C/(zbar k0))
    assert per.set_index("k0").Dc_exact_slope[1e-4] == pytest.approx(0.1, rel=2e-3)


def test_transition_evidence(rep):
    tr = rep.values["transition"]
    assert tr["growth_diverges"] and tr["hopf"] is False
    # the N-block amplitude vanishes like a square root (0.5-0.6 in docs; a frozen solver gives 0)
    assert 0.35 < tr["beta"] < 0.8
    assert "not a Hopf bifurcation" in rep.summary


def test_every_figure_and_the_summary_are_written(rep):
    for name in ("bifurcation", "steady_fit", "dc_profile", "critical_velocity", "hopf", "phase", "shs"):
        assert (rep.out / f"{name}.png").stat().st_size > 10_000, name
    text = (rep.out / "summary.md").read_text()
    for heading in ("Eq. (10)", "Critical velocity", "D_c two ways", "transition", "Phase", "Slide-hold-slide"):
        assert heading in text
