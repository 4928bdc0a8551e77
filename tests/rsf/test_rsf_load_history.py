"""Sampled load-point histories V(t) (Protocol.sampled, linear between samples) against
the independent scipy integrator of ``_independent_rs``."""
from __future__ import annotations

import sys
from pathlib import Path

import numpy as np
import pytest

import rsf

sys.path.insert(0, str(Path(__file__).parent))
from _independent_rs import reference  # noqa: E402

B, DC, V0, MU0 = 0.01, 10.0, 1.0, 0.6


def test_load_point_of_a_sampled_history_is_exact():
    proto = rsf.Protocol.sampled([0.0, 2.0, 5.0], [1.0, 3.0, 0.0])
    # X = t + t^2/2 on [0, 2]; then 4 + 3 (t - 2) - (t - 2)^2 / 2 on [2, 5]; then 8.5
    for t, want in [(1.0, 1.5), (2.0, 4.0), (3.0, 6.5), (5.0, 8.5), (9.0, 8.5)]:
        assert proto.load_point(t) == pytest.approx(want, rel=1e-15)
    assert proto.velocity_at(3.5) == pytest.approx(1.5)
    assert proto.slope_at(3.5) == pytest.approx(-1.0)
    assert proto.velocity_at(7.0) == 0.0 and proto.slope_at(7.0) == 0.0
    # a float whatever the time's type (numpy scalars in, Python floats out)
    for p in (proto, rsf.Protocol.sampled([0.0], [2.0])):
        assert type(p.load_point(np.float64(3.0))) is float


@pytest.mark.parametrize("law", ["aging", "slip"])
@pytest.mark.parametrize("k_over_kc", [20.0, 2.0])
def test_sampled_history_matches_independent_reference(law, k_over_kc):
    a = 0.005
    k0 = k_over_kc * (B - a) / DC
    ts = np.linspace(0.0, 60.0, 121)
    vs = 1.0 + 0.6 * np.sin(0.3 * ts) ** 2                 # a smooth V(t), sampled
    proto = rsf.Protocol.sampled(ts, vs)
    model = rsf.standard_rs(mu0=MU0, a=a, b=B, Dc=DC, k0=k0, v0=V0, state_law=law)
    te = np.linspace(0.0, 80.0, 321)
    tr = rsf.simulate(model, protocol=proto, t_end=80.0, t_eval=te)
    assert tr.success, tr.message
    ref = reference(law, a=a, b=B, Dc=DC, k0=k0, v0=V0, mu0=MU0,
                    velocity=lambda t: float(np.interp(t, ts, vs)), breaks=ts, t_eval=te)
    assert np.max(np.abs(tr.sigma - ref["mu"])) < 1e-8
    assert np.max(np.abs(tr.v / ref["v"] - 1.0)) < 1e-6
    X = np.array([proto.load_point(t) for t in te])
    assert np.max(np.abs(tr.x - (X - tr.sigma / k0))) < 1e-8 / k0   # the spring holds mu


def test_sampled_steps_equal_velocity_steps():
    """A sampled history with a very steep ramp is close to the step; exact equality for
    a flat history."""
    model = rsf.standard_rs(mu0=MU0, a=0.005, b=B, Dc=DC, k0=0.001, v0=V0)
    te = np.linspace(0.0, 50.0, 51)
    flat = rsf.simulate(model, protocol=rsf.Protocol.sampled([0.0, 20.0], [2.0, 2.0]),
                        t_end=50.0, t_eval=te)
    const = rsf.simulate(model, V=2.0, t_end=50.0, t_eval=te,
                         initial=rsf.InitialState(perturbation=0.0))
    assert np.max(np.abs(flat.sigma - const.sigma)) < 1e-14


def test_sampled_history_needs_a_direct_effect():
    with pytest.raises(ValueError, match="sampled .* needs a direct effect"):
        rsf.simulate(rsf.SpringSlider(k0=0.01), protocol=rsf.Protocol.sampled([0, 1], [1, 2]),
                     t_end=2.0)
    with pytest.raises(ValueError, match="interpolation must be one of"):
        rsf.Protocol([0.0, 1.0], [1.0, 2.0], interpolation="cubic")
