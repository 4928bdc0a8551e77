"""The normal forms of RS's transition at V^c (rsf.normal_form; docs/reference/rsf.md §15):
the first Lyapunov coefficient against closed forms and against rsf's own limit cycles,
the a = 0 stick-slip reduction against rsf.limit_cycle, and the one test of the transition."""
from __future__ import annotations

import math

import numpy as np
import pandas as pd
import pytest

import rsf
from rsf import normal_form as nf
from rsf.analysis import steady_jacobian

B_LOG, DC_LOG, A_LOG = 0.01, 10.0, 0.005
KC_LOG = (B_LOG - A_LOG) / DC_LOG


def _log_model(state_law="aging", eta=1e-3, k_over_kc=0.8, **kw):
    return rsf.standard_rs(mu0=0.6, a=A_LOG, b=B_LOG, Dc=DC_LOG, k0=k_over_kc * KC_LOG, v0=1.0,
                           eta_rad=eta, state_law=state_law, **kw)


# ------------------------------------------------------------------ l1: the machinery
@pytest.mark.parametrize("s", [-1.0, 0.3])
def test_first_lyapunov_of_the_textbook_normal_form(s):
    """x' = -y + s x r^2, y' = x + s y r^2: z' = i z + 2 s z|z|^2 in Kuznetsov's
    normalisation (<q, q> = 1), so l1 = Re c1 / omega = 2 s."""
    def F(x):
        r2 = x[0] ** 2 + x[1] ** 2
        return np.array([-x[1] + s * x[0] * r2, x[0] + s * x[1] * r2])

    omega, l1, err, _, _ = nf._first_lyapunov(F, np.array([[0.0, -1.0], [1.0, 0.0]]))
    assert omega == pytest.approx(1.0, rel=1e-14)
    assert l1 == pytest.approx(2.0 * s, rel=1e-10)
    assert err < 1e-10


@pytest.mark.parametrize("model", [
    rsf.SpringSlider(k0=0.1, a=1e-3),
    rsf.SpringSlider(k0=0.1, a=1e-3, state_law="slip"),
    rsf.SpringSlider(k0=0.1, a=1e-3, state_law="prz"),
    rsf.SpringSlider(k0=0.1, a=1e-3, state_law=rsf.NagataLaw(c=0.5, b=0.01)),
    rsf.SpringSlider(k0=0.1, a=1e-3, eta_rad=1e-3),
    rsf.SpringSlider(k0=0.1, a=1e-3, state_law=lambda v, th: 1.0 - v * th / 0.06),
    _log_model("slip", eta=1e-4),
    _log_model("aging", eta=1e-4, second_state=rsf.SecondState(0.004, 50.0), k_over_kc=0.08),
], ids=["aging", "slip", "prz", "nagata", "damped", "user", "log-slip-damped", "two-state"])
def test_vector_field_linearises_to_the_steady_jacobian(model):
    """The field whose derivatives give l1 is the model's: its Jacobian at steady sliding
    (by differences) is rsf.analysis.steady_jacobian (closed form), at and off V^c."""
    Vc = rsf.critical_velocity(model).Vc
    for V in (Vc, 0.7 * Vc):
        F, _ = nf._vector_field(model, V)
        n = steady_jacobian(model, V).shape[0]
        assert np.max(np.abs(F(np.zeros(n)))) < 1e-13          # steady sliding is x = 0
        J = nf._jacobian_fd(F, n)
        np.testing.assert_allclose(J, steady_jacobian(model, V), rtol=1e-7, atol=1e-7 * np.max(np.abs(J)))


@pytest.mark.parametrize("law", [rsf.HyperbolicLaw(), rsf.ViscoelasticLaw()])
@pytest.mark.parametrize("state_law", ["aging", "slip", "prz"])
@pytest.mark.parametrize("a", [1e-2, 1e-4])
def test_closed_form_equals_finite_differences(law, state_law, a):
    model = rsf.SpringSlider(law=law, k0=0.1, a=a, state_law=state_law)
    closed = rsf.hopf_normal_form(model)
    fd = rsf.hopf_normal_form(model, method="finite differences")
    assert closed.method.startswith("closed form") and fd.method == "finite differences"
    assert fd.l1 == pytest.approx(closed.l1, rel=1e-7)
    assert fd.l1_error < 1e-7 * abs(fd.l1)
    assert fd.prefactor == pytest.approx(closed.prefactor, rel=1e-7)
    assert fd.kind == closed.kind
    assert closed.omega == pytest.approx(math.sqrt(model.K / a) * closed.Vc / model.Dc, rel=1e-12)


def test_omega_derivatives_of_eq10_in_closed_form_and_by_differences():
    """Omega(z) = W(V e^-z) for Eq. 10: Omega_1 = W (u - B)/(u + B),
    Omega_2 = W ((u - B)^2 - 2uB)/(u + B)^2 (u = V); the Cauchy integral and the finite
    differences of a CallableLaw copy of the law agree with them."""
    A, B, V = rsf.PAPER_A, rsf.PAPER_B, 1.3
    law = rsf.HyperbolicLaw(mu_inf=0.9)
    W = A * V / (V + B) ** 2
    exact = [W, W * (V - B) / (V + B), W * ((V - B) ** 2 - 2 * V * B) / (V + B) ** 2]
    om, how = nf._omega_derivatives(law, V, 4)
    assert how == "closed form"
    np.testing.assert_allclose(om[:3], exact, rtol=1e-13)
    copy = rsf.CallableLaw(lambda v: 0.9 + A / (v + B), lambda v: -A / (v + B) ** 2)
    om_fd, how_fd = nf._omega_derivatives(copy, V, 4)
    assert how_fd == "finite differences"
    np.testing.assert_allclose(om_fd, om, rtol=1e-6, atol=1e-9 * W)


# ------------------------------------------------------------------ l1: the verdicts
@pytest.mark.parametrize("state_law", ["aging", "slip"])
def test_classical_log_law_without_damping_is_degenerate(state_law):
    """With W constant the undamped log law has l1 = 0 for the aging and the slip law (the
    slip law reduces to a Lienard equation x'' + f(x) x' + g(x) = 0 with
    f'' - f' g''/g' = 0): neither sub- nor supercritical at first order, in closed form
    and by differences (the stiffness is the parameter: V only sets the time unit)."""
    model = _log_model(state_law, eta=0.0)
    closed = rsf.hopf_normal_form(model, parameter="k0", V=1.0)
    fd = rsf.hopf_normal_form(model, parameter="k0", V=1.0, method="finite differences")
    assert closed.k0c == pytest.approx(KC_LOG, rel=1e-12)
    assert closed.kind == fd.kind == "degenerate"
    assert closed.l1 == 0.0
    assert abs(fd.l1) < 1e-8
    assert math.isnan(closed.prefactor)


def test_kinds_of_the_laws():
    """Eq. (10), a = 1e-3, k0 = 0.1: aging and slip supercritical, PRZ subcritical; the damped
    log law (the reference page once called its slip law subcritical): supercritical for
    both, l1 independent of eta (V eta is what enters)."""
    kinds = {sl: rsf.hopf_normal_form(rsf.SpringSlider(k0=0.1, a=1e-3, state_law=sl)).kind
             for sl in ("aging", "slip", "prz")}
    assert kinds == {"aging": "supercritical", "slip": "supercritical", "prz": "subcritical"}
    for sl in ("aging", "slip"):
        f1, f2 = (rsf.hopf_normal_form(_log_model(sl, eta=eta)) for eta in (1e-3, 1e-4))
        assert f1.kind == f2.kind == "supercritical"
        assert f1.l1 == pytest.approx(f2.l1, rel=1e-6)
        assert f1.Vc == pytest.approx(1.0, rel=1e-12) and f2.Vc == pytest.approx(10.0, rel=1e-12)
    sub = rsf.hopf_normal_form(rsf.SpringSlider(k0=0.1, a=1e-3, state_law="prz"))
    assert sub.side == "d < 0" and np.isnan(sub.amplitude(1e-4)) and sub.amplitude(-1e-4) > 0


@pytest.mark.parametrize("law", [rsf.HyperbolicLaw(), rsf.ViscoelasticLaw()])
def test_hopf_prefactor_tends_to_two_over_root_three_of_the_stick_slip_one(law):
    """Aging law: c^2 = 32 (K + a) K Omega_1/(Omega_1 - Omega_2) and
    c0^2 = 24 K^2 Omega_1/(Omega_1 - Omega_2), so c/c0 = (2/sqrt 3)(1 + a/K)^(1/2) for every
    law: the limits a -> 0 and d -> 0 do not commute."""
    for a in (1e-2, 1e-4, 1e-6):
        model = rsf.SpringSlider(law=law, k0=0.1, a=a)
        c = rsf.hopf_normal_form(model).prefactor
        c0 = rsf.stick_slip_normal_form(model).prefactor
        assert c / c0 == pytest.approx(2 / math.sqrt(3) * math.sqrt(1 + a / model.K), rel=1e-9)


def test_hopf_amplitude_against_the_simulated_cycle():
    """l1 against an independent check: rsf's own limit cycle at d = 1e-4 and 1e-5 (Eq. 10,
    aging, a = 1e-3, k0 = 0.1).  The amplitude over c d^(1/2) is 1 + 0.29 d (measured
    1.000029, 1.0000017); a wrong l1 would move it by its own relative error over two.
    The period is 2 pi/omega to O(d) (measured 1 + 7.9 d)."""
    model = rsf.SpringSlider(k0=0.1, a=1e-3)
    h = rsf.hopf_normal_form(model)
    opts = rsf.SolverOptions(cycle_rtol=1e-11, rtol=1e-12, atol=1e-14)
    for d, tol in ((1e-4, 1e-4), (1e-5, 2e-5)):
        r = rsf.cycle_near_hopf(model, h.Vc * (1 - d), options=opts)
        assert r.converged and r.regime == "stick-slip"
        assert (r.sigma_max - r.sigma_min) / (h.prefactor * math.sqrt(d)) == pytest.approx(1.0, abs=tol)
        assert r.period == pytest.approx(h.period, rel=10 * d)   # measured 7.9 d


@pytest.mark.slow
@pytest.mark.parametrize("case", ["aging", "slip", "log-aging", "log-slip"])
def test_hopf_amplitude_ratio_tends_to_one_over_three_decades(case):
    """The benchmark's check (studies/rsf_normal_form.py): amplitude / (c d^(1/2)) within
    1e-3 of 1 at d = 1e-4, 1e-5, 1e-6, 1e-7, and closer at smaller d."""
    model = {"aging": rsf.SpringSlider(k0=0.1, a=1e-3),
             "slip": rsf.SpringSlider(k0=0.1, a=1e-3, state_law="slip"),
             "log-aging": _log_model("aging"), "log-slip": _log_model("slip")}[case]
    h = rsf.hopf_normal_form(model)
    opts = rsf.SolverOptions(cycle_rtol=1e-11, rtol=1e-14, atol=1e-16)
    dev = []
    for d in (1e-4, 1e-5, 1e-6, 1e-7):
        r = rsf.cycle_near_hopf(model, h.Vc * (1 - d), options=opts)
        assert r.converged
        dev.append(abs((r.sigma_max - r.sigma_min) / (h.prefactor * math.sqrt(d)) - 1.0))
    assert max(dev) < 1e-3
    assert dev[2] < 1e-4


def test_damped_slip_law_has_no_cycle_just_above_vc():
    """Supercritical also globally near V^c: at 1.01 V^c every start ends steady (no
    coexisting cycle), from small and large perturbations of theta."""
    model = _log_model("slip")
    for pert in (1e-3, 3.0, 30.0):
        r = rsf.limit_cycle(model, 1.01, initial=rsf.InitialState(perturbation=pert))
        assert r.regime == "steady", r.message


# ------------------------------------------------------------------ a = 0
def test_stick_slip_reduction_is_the_limit_cycle():
    """The two equations of the return map give rsf.limit_cycle's cycle (σ extrema and
    period) to its tolerance, for Eq. (10) at k0 = 0.1 and 0.01 and d from 1e-1 to 1e-6."""
    opts = rsf.SolverOptions(cycle_rtol=1e-12, rtol=1e-12, atol=1e-14)
    for k0 in (0.1, 0.01):
        model = rsf.SpringSlider(k0=k0)
        s = rsf.stick_slip_normal_form(model)
        for d in (1e-1, 1e-3, 1e-6):
            V = s.Vc * (1 - d)
            r = rsf.limit_cycle(model, V, options=opts)
            ex = s.cycle(V)
            assert r.sequence == ("stick->slip", "slip->stick")
            assert ex["sigma_max"] == pytest.approx(r.sigma_max, abs=1e-13)
            assert ex["sigma_min"] == pytest.approx(r.sigma_min, abs=1e-13)
            assert ex["amplitude"] == pytest.approx(r.sigma_max - r.sigma_min, rel=1e-8)
            assert ex["period"] == pytest.approx(r.period, rel=1e-8)


def test_stick_slip_prefactor_and_exponent_against_the_simulation():
    """c0 d^(1/2) (1 + c2 d) against rsf.limit_cycle over d = 1e-2 ... 1e-7 (k0 = 0.3 and 0.1):
    within 1e-6 where c2 d^2 is below it; the exponent between d = 1e-7 and 1e-4 is 1/2 plus
    the derived correction (1.5e-6 at k0 = 0.3)."""
    opts = rsf.SolverOptions(cycle_rtol=1e-12, rtol=1e-12, atol=1e-14)
    for k0 in (0.3, 0.1):
        model = rsf.SpringSlider(k0=k0)
        s = rsf.stick_slip_normal_form(model)
        amps = {}
        for d in (1e-2, 1e-4, 1e-7):
            r = rsf.limit_cycle(model, s.Vc * (1 - d), options=opts)
            amps[d] = r.sigma_max - r.sigma_min
            tol = 1e-6 if d < 1e-2 else 3e-5
            assert amps[d] / float(s.amplitude(d)) == pytest.approx(1.0, abs=tol)
        slope = math.log(amps[1e-4] / amps[1e-7]) / math.log(1e3)
        derived = 0.5 + math.log((1 + s.correction * 1e-4) / (1 + s.correction * 1e-7)) / math.log(1e3)
        assert slope == pytest.approx(derived, abs=1e-8)
        assert slope == pytest.approx(0.5, abs=1e-5)


def test_stick_slip_prefactor_in_closed_form_for_eq10():
    """c0 = 2 sqrt(6) K sqrt(Omega_1/(Omega_1 - Omega_2)) with Eq. (10)'s
    Omega_1/(Omega_1 - Omega_2) = (u - B)(u + B)/(2B(2u - B)) at u = V^c."""
    for k0 in (0.3, 0.1, 0.01, 1e-3):
        model = rsf.SpringSlider(k0=k0)
        s = rsf.stick_slip_normal_form(model)
        u, B = s.Vc, rsf.PAPER_B
        ratio = (u - B) * (u + B) / (2 * B * (2 * u - B))
        assert s.prefactor == pytest.approx(2 * math.sqrt(6) * model.K * math.sqrt(ratio), rel=1e-12)
        assert s.period_prefactor == pytest.approx(s.prefactor / (k0 * s.Vc), rel=1e-14)


# ------------------------------------------------------------------ the one test
def test_one_test_classifies_a_positive_as_hopf_and_a_zero_as_not():
    d = np.geomspace(1e-6, 0.5, 12)
    for a in (1e-2, 1e-3, 1e-4, 1e-5):
        model = rsf.SpringSlider(k0=0.1, a=a)
        sp = rsf.transition_spectrum(model, d)
        near = sp.iloc[0]
        # the pair crosses at a finite frequency sqrt(K/a) (tau units); its growth rate
        # vanishes like Omega_1 d/(2a)
        assert near.frequency_tau == pytest.approx(math.sqrt(model.K / a), rel=1e-3)
        om1 = nf._omega_derivatives(model.law, sp.V.iloc[0] / (1 - near.d), 1)[0][1]
        assert near.growth_rate_tau == pytest.approx(om1 * near.d / (2 * a), rel=1e-3)
        verdict = rsf.classify_spectrum(sp)
        assert verdict["hopf"] and not verdict["growth_diverges"]
    sp0 = rsf.transition_spectrum(rsf.SpringSlider(k0=0.1), d)
    assert np.all(np.isinf(sp0.fast_rate)) and np.all(sp0.frequency == 0)
    # the finite mode K/(W - K) diverges like 1/d: d * rate -> K / Omega_1 (tau units)
    s = rsf.stick_slip_normal_form(rsf.SpringSlider(k0=0.1))
    assert sp0.growth_rate_tau.iloc[0] * sp0.d.iloc[0] == pytest.approx(s.K / s.omegas[0], rel=1e-4)
    verdict = rsf.classify_spectrum(sp0)
    assert verdict["growth_diverges"] and not verdict["hopf"]
    assert "not a Hopf bifurcation" in verdict["text"]


def test_period_exponent_enters_the_verdict():
    sp = rsf.transition_spectrum(rsf.SpringSlider(k0=0.1), [1e-5, 0.5])
    s = rsf.stick_slip_normal_form(rsf.SpringSlider(k0=0.1))
    for ds, expected in (([0.02, 0.1, 0.3], 0.68), ([1e-5, 1e-4, 1e-3], 0.5)):
        per = pd.DataFrame({"d": ds})
        per["period"] = [s.cycle(s.Vc * (1 - d))["period"] for d in per.d]
        v = rsf.classify_spectrum(sp, per)
        assert v["period_exponent"] == pytest.approx(expected, abs=0.01) and not v["hopf"]
    # a Hopf spectrum with a finite period is Hopf, with a vanishing one it is not
    sp1 = rsf.transition_spectrum(rsf.SpringSlider(k0=0.1, a=1e-3), [1e-5, 0.5])
    flat = pd.DataFrame({"d": [1e-5, 1e-4, 1e-3], "period": [0.1532, 0.1533, 0.1544]})
    assert rsf.classify_spectrum(sp1, flat)["hopf"]
    assert not rsf.classify_spectrum(sp1, per)["hopf"]


# ------------------------------------------------------------------ input
def test_bad_input():
    with pytest.raises(ValueError, match="needs a direct effect a > 0"):
        rsf.hopf_normal_form(rsf.SpringSlider(k0=0.1))
    with pytest.raises(ValueError, match="parameter must be"):
        rsf.hopf_normal_form(rsf.SpringSlider(k0=0.1, a=1e-3), parameter="Dc")
    with pytest.raises(ValueError, match="no finite critical velocity"):
        rsf.hopf_normal_form(_log_model(eta=0.0))
    with pytest.raises(ValueError, match="needs the driving velocity"):
        rsf.hopf_normal_form(_log_model(eta=0.0), parameter="k0")
    with pytest.raises(ValueError, match="closed form covers"):
        rsf.hopf_normal_form(_log_model(eta=1e-3), method="closed form")
    s = rsf.stick_slip_normal_form(rsf.SpringSlider(k0=0.1))
    with pytest.raises(ValueError, match="below Vc"):
        s.cycle(2 * s.Vc)
    h = rsf.hopf_normal_form(rsf.SpringSlider(k0=0.1, a=1e-3))
    assert set(h.to_dict()) >= {"Vc", "omega", "l1", "prefactor", "kind", "period"}
    assert set(s.to_dict()) >= {"Vc", "prefactor", "correction", "kind"}
