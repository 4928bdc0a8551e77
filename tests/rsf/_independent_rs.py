"""An independent classical rate-and-state spring-slider for the tests: scipy's DOP853 at
rtol 1e-12 in (ln v, ln theta_1[, ln theta_2]) and physical time.  It shares no code with
:mod:`rsf`.

.. math::
    \\mu = \\mu_0 + a\\ln\\frac{v}{v_0} + \\sum_i b_i\\ln\\frac{v_0\\theta_i}{D_{ci}}
    \\quad(\\text{PRZ: } \\theta_i/(2D_{ci})),\\qquad
    k_0\\,(X(t) - x) = \\mu + \\eta v,

so that :math:`(a + \\eta v)\\,\\dot{(\\ln v)} = k_0(V - v) - \\sum_i b_i\\,\\dot{(\\ln\\theta_i)}`.
"""
from __future__ import annotations

from typing import Callable

import numpy as np
from scipy.integrate import solve_ivp


def _theta_ss(law: str, v: float, Dc: float) -> float:
    return 2.0 * Dc / v if law == "prz" else Dc / v


def _dln_theta(law: str, v: float, theta: float, Dc: float, user=None) -> float:
    """d ln(theta)/dt for the laws whose rate does not involve the stress rate."""
    if law == "aging":          # Dieterich (1979)
        return 1.0 / theta - v / Dc
    if law == "slip":           # Ruina (1983)
        return -(v / Dc) * np.log(v * theta / Dc)
    if law == "prz":            # Perrin, Rice & Zheng (1995), theta_PRZ
        return (1.0 - (v * theta / (2.0 * Dc)) ** 2) / theta
    if law == "user":
        return user(v, theta) / theta
    raise ValueError(law)


def state_rate(law: str, v: float, theta: float, Dc: float) -> float:
    """d ln(theta)/dt (aging, slip, prz)."""
    return _dln_theta(law, v, theta, Dc)


def make_rhs(law: str, *, a: float, b: float, Dc: float, k0: float, velocity, eta: float = 0.0,
             nagata_c: float = 0.0, b2: float = 0.0, Dc2: float = 1.0, user=None):
    """d/dt of (ln v, ln theta[, ln theta2]) at load-point velocity ``velocity(t)``."""
    two = b2 > 0.0
    base = "aging" if law == "nagata" else law

    def rhs(t, y):
        V = velocity(t)
        v = np.exp(y[0])
        spring_rate = k0 * (V - v)
        d1 = _dln_theta(base, v, np.exp(y[1]), Dc, user)
        d2 = _dln_theta(base, v, np.exp(y[2]), Dc2, user) if two else 0.0
        if law == "nagata":
            # d1 = aging - (c/b) mu_dot with mu_dot = spring_rate - eta v L: solve for L
            L = ((1.0 + nagata_c) * spring_rate - b * d1 - b2 * d2) / (
                a + eta * v + nagata_c * eta * v)
            d1 = d1 - (nagata_c / b) * (spring_rate - eta * v * L)
        else:
            L = (spring_rate - b * d1 - b2 * d2) / (a + eta * v)
        return [L, d1, d2] if two else [L, d1]

    return rhs


def reference(law: str, *, a: float, b: float, Dc: float, k0: float, v0: float, mu0: float,
              velocity: Callable[[float], float], breaks, t_eval: np.ndarray, eta: float = 0.0,
              nagata_c: float = 0.0, b2: float = 0.0, Dc2: float = 1.0,
              user=None) -> dict[str, np.ndarray]:
    """mu and v at ``t_eval`` for the load-point velocity ``velocity(t)`` (smooth inside
    each interval between the ``breaks``, where the integration restarts with the value
    just after the break), from steady state at ``velocity(0)``.

    ``law``: aging, slip, prz, nagata (aging with the stress-rate term, Nagata et al.
    2012) or user (``user(v, theta) -> dtheta/dt``)."""
    two = b2 > 0.0
    base = "aging" if law == "nagata" else law
    clamp = [0.0, 0.0]          # the interval's own V at its ends

    inner = make_rhs(law, a=a, b=b, Dc=Dc, k0=k0, eta=eta, nagata_c=nagata_c, b2=b2, Dc2=Dc2,
                     user=user, velocity=lambda t: velocity(min(max(t, clamp[0]), clamp[1])))

    def rhs(t, y, t_left, t_right):
        clamp[0], clamp[1] = t_left, t_right
        return inner(t, y)

    V0 = velocity(0.0)
    y = [np.log(V0), np.log(_theta_ss(base, V0, Dc))]
    if two:
        y.append(np.log(_theta_ss(base, V0, Dc2)))
    t_last = float(t_eval[-1])
    edges = sorted({0.0, t_last, *[float(t) for t in breaks if 0.0 < t < t_last]})
    Y = np.full((len(y), t_eval.size), np.nan)
    for t0, t1 in zip(edges[:-1], edges[1:]):
        eps = 1e-12 * (t1 - t0)
        sol = solve_ivp(rhs, (t0, t1), y, method="DOP853", rtol=1e-12, atol=1e-14,
                        dense_output=True, args=(t0 + eps, t1 - eps))
        assert sol.success, sol.message
        inside = (t_eval >= t0) & (t_eval <= t1)
        if inside.any():
            Y[:, inside] = sol.sol(t_eval[inside])
        y = sol.y[:, -1]
    norm = 2.0 if base == "prz" else 1.0
    mu = mu0 + a * (Y[0] - np.log(v0)) + b * (Y[1] + np.log(v0 / (norm * Dc)))
    if two:
        mu = mu + b2 * (Y[2] + np.log(v0 / (norm * Dc2)))
    return {"mu": mu, "v": np.exp(Y[0])}


def mu_at(law: str, *, velocities, times, t_eval: np.ndarray, **kw) -> np.ndarray:
    """Friction at ``t_eval`` for piecewise-constant driving (``velocities[i]`` from
    ``times[i]``), starting at steady state at ``velocities[0]``."""
    times = np.asarray(times, dtype=float)
    vel = np.asarray(velocities, dtype=float)

    def velocity(t):
        return vel[max(int(np.searchsorted(times, t, side="right")) - 1, 0)]

    return reference(law, velocity=velocity, breaks=times[1:], t_eval=t_eval, **kw)["mu"]
