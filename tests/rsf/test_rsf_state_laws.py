"""State evolution laws (aging, slip, PRZ, Nagata, a user callable) and two state
variables, each against the independent scipy integrator of ``_independent_rs``
(DOP853, rtol 1e-12, no code shared with rsf): 1e-8 in mu at default options on
velocity steps, k0 = 20, 2, 1.2 k_c and a = 0.005, 0.008."""
from __future__ import annotations

import math
import sys
from pathlib import Path

import numpy as np
import pytest

import rsf

sys.path.insert(0, str(Path(__file__).parent))
from _independent_rs import mu_at  # noqa: E402

B, DC, V0, MU0 = 0.01, 10.0, 1.0, 0.6
TE = np.linspace(0.0, 100.0, 401)


def _user_slip(v: float, theta: float) -> float:
    x = v * theta / DC
    return -x * math.log(x)


# (name, rsf state law, reference law, reference extras, second state, step velocity)
LAWS = {
    "prz": ("prz", "prz", {}, None, 2.0),
    "nagata": (rsf.NagataLaw(c=2.0), "nagata", {"nagata_c": 2.0}, None, 10.0),
    "user": (_user_slip, "slip", {}, None, 2.0),
    "two-state aging": ("aging", "aging", {"b2": 0.004, "Dc2": 50.0}, (0.004, 50.0), 2.0),
    "two-state slip": ("slip", "slip", {"b2": 0.004, "Dc2": 50.0}, (0.004, 50.0), 1.5),
}


@pytest.mark.parametrize("k_over_kc", [20.0, 2.0, 1.2])
@pytest.mark.parametrize("a", [0.005, 0.008])
@pytest.mark.parametrize("name", list(LAWS))
def test_state_law_matches_independent_reference(name, a, k_over_kc):
    state_law, ref_law, extra, second, v_step = LAWS[name]
    k0 = k_over_kc * (B - a) / DC
    model = rsf.standard_rs(mu0=MU0, a=a, b=B, Dc=DC, k0=k0, v0=V0, state_law=state_law,
                            second_state=rsf.SecondState(*second) if second else None)
    vel = [1.0, v_step, 1.0]
    tr = rsf.simulate(model, protocol=rsf.Protocol.velocity_steps(vel, [10.0, 40.0]),
                      t_end=100.0, t_eval=TE)
    assert tr.success, tr.message
    mu = mu_at(ref_law, a=a, b=B, Dc=DC, k0=k0, v0=V0, mu0=MU0, velocities=vel,
               times=[0.0, 10.0, 50.0], t_eval=TE, **extra)
    assert np.max(np.abs(tr.sigma - mu)) < 1e-8


def test_nagata_with_c_zero_is_the_aging_law():
    te = np.linspace(0.0, 60.0, 61)
    runs = [rsf.simulate(rsf.standard_rs(a=0.005, b=B, Dc=DC, k0=0.001, v0=V0, state_law=law),
                         protocol=rsf.Protocol.velocity_steps([1.0, 10.0], [10.0]), t_end=60.0,
                         t_eval=te) for law in (rsf.NagataLaw(c=0.0), "aging")]
    assert np.max(np.abs(runs[0].sigma - runs[1].sigma)) < 1e-12
    nag = rsf.simulate(rsf.standard_rs(a=0.005, b=B, Dc=DC, k0=0.001, v0=V0,
                                       state_law=rsf.NagataLaw(c=2.0)),
                       protocol=rsf.Protocol.velocity_steps([1.0, 10.0], [10.0]), t_end=60.0,
                       t_eval=te)
    assert np.max(np.abs(nag.sigma - runs[1].sigma)) > 1e-4          # the term matters


def test_prz_reports_half_theta_prz():
    """rsf's theta for PRZ is theta_PRZ / 2: steady state Dc / V like the other laws."""
    model = rsf.standard_rs(a=0.005, b=B, Dc=DC, k0=0.01, v0=V0, state_law="prz")
    tr = rsf.simulate(model, protocol=rsf.Protocol.velocity_steps([1.0, 10.0], [10.0]),
                      t_end=200.0, t_eval=[0.0, 200.0])
    assert tr.theta[0] == pytest.approx(DC / 1.0, rel=1e-15)
    assert tr.theta[-1] == pytest.approx(DC / 10.0, rel=1e-7)
    assert tr.sigma[-1] == pytest.approx(MU0 + (0.005 - B) * math.log(10.0), abs=1e-9)


def test_docstrings_give_equation_and_reference():
    for cls in (rsf.AgingLaw, rsf.SlipLaw, rsf.PRZLaw, rsf.NagataLaw):
        doc = cls.__doc__
        assert ".. math::" in doc and any(str(y) in doc for y in (1979, 1983, 1995, 2012))


@pytest.mark.parametrize("make, match", [
    (lambda: rsf.SpringSlider(k0=0.01, state_law="prz"), "needs a direct effect a > 0"),
    (lambda: rsf.SpringSlider(k0=0.01, state_law="bogus"), "state_law must be one of"),
    (lambda: rsf.SpringSlider(k0=0.01, a=0.01, state_law=rsf.NagataLaw(2.0)), "NagataLaw"),
    (lambda: rsf.NagataLaw(c=-1.0), "c must be a finite number >= 0"),
    (lambda: rsf.CallableStateLaw(func=lambda v, th: math.nan), "finite"),
    (lambda: rsf.CallableStateLaw(func=3), "callable"),
    (lambda: rsf.SecondState(b2=0.0, Dc2=1.0), "b2 must be a finite number > 0"),
    (lambda: rsf.SpringSlider(k0=0.01, a=0.01, second_state=rsf.SecondState(0.01, 1.0)),
     "second_state needs the log law"),
    (lambda: rsf.standard_rs(state_law=rsf.NagataLaw(1.0), second_state=rsf.SecondState(0.01, 1.0)),
     "second_state works with"),
])
def test_bad_state_law_input(make, match):
    with pytest.raises(ValueError, match=match):
        make()


def test_user_law_stability_and_limit_cycle_match_the_built_in_law():
    """A user callable equal to the aging law: same Jacobian (finite differences of the
    user's function), same Vc with radiation damping, same limit cycle."""
    from rsf.analysis import steady_jacobian

    def aging(v: float, theta: float) -> float:
        return 1.0 - v * theta / DC

    kw = dict(mu0=MU0, a=0.005, b=B, Dc=DC, k0=0.0004, v0=V0, eta_rad=1e-4)
    user, built_in = rsf.standard_rs(state_law=aging, **kw), rsf.standard_rs(**kw)
    np.testing.assert_allclose(steady_jacobian(user, 3.0), steady_jacobian(built_in, 3.0),
                               rtol=1e-8)
    assert rsf.critical_velocity(user).Vc == pytest.approx(10.0, rel=1e-8)
    r_user, r_built = rsf.limit_cycle(user, 5.0), rsf.limit_cycle(built_in, 5.0)
    assert r_user.converged and r_user.regime == "stick-slip"
    assert r_user.sigma_max == pytest.approx(r_built.sigma_max, abs=1e-7)
    assert r_user.period == pytest.approx(r_built.period, rel=1e-6)


def test_user_law_must_have_the_standard_steady_state():
    with pytest.raises(ValueError, match="steady state at theta = Dc/v"):
        rsf.standard_rs(Dc=DC, state_law=lambda v, th: 1.0 - v * th / (2 * DC))


@pytest.mark.parametrize("law", ["aging", "slip", "prz"])
def test_two_state_jacobian_matches_finite_differences_of_the_independent_rhs(law):
    from rsf.analysis import steady_jacobian
    from _independent_rs import make_rhs

    V, b2, Dc2, eta = 3.0, 0.004, 50.0, 1e-4
    model = rsf.standard_rs(mu0=MU0, a=0.005, b=B, Dc=DC, k0=0.0004, v0=V0, state_law=law,
                            second_state=rsf.SecondState(b2, Dc2), eta_rad=eta)
    rhs = make_rhs(law, a=0.005, b=B, Dc=DC, k0=0.0004, velocity=lambda t: V, eta=eta, b2=b2,
                   Dc2=Dc2)
    norm = 2.0 if law == "prz" else 1.0
    y0 = np.log([V, norm * DC / V, norm * Dc2 / V])
    h = 1e-6
    J = np.column_stack([(np.array(rhs(0.0, y0 + h * e)) - np.array(rhs(0.0, y0 - h * e))) / (2 * h)
                         for e in np.eye(3)])
    np.testing.assert_allclose(steady_jacobian(model, V), J * DC / V, rtol=1e-7, atol=1e-9)


def test_two_state_limit_cycles_and_stability_boundary():
    """Two state variables with radiation damping: cycles below the Vc of the 3 x 3
    linearisation (a Hopf point: a complex pair crosses), steady sliding above."""
    from rsf.analysis import steady_jacobian

    model = rsf.standard_rs(mu0=MU0, a=0.005, b=B, Dc=DC, k0=0.0004, v0=V0,
                            second_state=rsf.SecondState(0.004, 50.0), eta_rad=1e-4)
    cv = rsf.critical_velocity(model)
    assert math.isfinite(cv.Vc) and cv.V_lower == 0.0
    eig = np.linalg.eigvals(steady_jacobian(model, cv.Vc))
    lead = eig[np.argmax(eig.real)]
    assert abs(lead.real) < 1e-10 and abs(lead.imag) > 1e-3
    for f, regime in ((0.3, "stick-slip"), (0.97, "stick-slip"), (1.03, "steady"), (3.0, "steady")):
        r = rsf.limit_cycle(model, f * cv.Vc)
        assert r.converged and r.regime == regime, (f, r.message)
