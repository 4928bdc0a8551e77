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

import math
from typing import Callable

import numpy as np
from scipy.integrate import solve_ivp
from scipy.optimize import brentq


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


# ------------------------------------------------------------------------------------------------
# a = 0 with the paper's Eq. (10): the stick-slip cycle of Eq. (11), phase by phase
# ------------------------------------------------------------------------------------------------
def eq11_cycle(*, A: float, B: float, mu_inf: float, k0: float, Dc: float, V: float,
               rtol: float = 1e-13, max_cycles: int = 100000) -> dict:
    """The attractor of the a = 0 spring-slider with Eq. (10), mu_ss = mu_inf + A/(v + B), and the
    aging law, reached from steady sliding at V with theta x 1.001 (as rsf.limit_cycle starts).

    With a = 0 the friction is phi(theta) = mu_ss(Dc/theta) = mu_inf + A theta/(Dc + B theta), and
    with u = Dc/theta, K = k0 Dc, W(u) = A u/(u + B)^2, N = K V - u W(u), D = K - W(u) the motion
    on the threshold sigma = phi(theta) is, here solved phase by phase with no ODE integrator:

    * N < 0, stick (v = 0, theta = theta0 + t, sigma = phi(theta0) + k0 V t): phi is concave, so
      sigma - phi vanishes once more, at t = (A Dc/(k0 V (Dc + B theta0)) - Dc - B theta0)/B;
    * N > 0, D < 0, instantaneous slip (theta = theta0 e^-s, sigma = phi(theta0) - K s): it lands
      at the root of g(s) = phi(theta0) - phi(theta0 e^-s) - K s beyond the top of its hump,
      s1 = ln(u+/u0) with u+ the upper root of W(u) = K (scipy's brentq);
    * N > 0, D > 0, slide along the threshold: u moves monotonically to V, and the slide ends at
      the first root of N (a stick) or D (a slip) between u and V, or settles on V (steady).

    sigma moves monotonically in each phase, so its extrema are at the phase ends.  The cycle
    (slip landing to slip landing) is iterated to the fixed point of the landing theta (relative
    change < ``rtol``).  Returns ``regime`` ('steady' or 'stick-slip'), ``sigma_max``,
    ``sigma_min``, ``n_cycles`` and ``sequence`` (the phases of the last cycle)."""
    K = k0 * Dc

    def rel(theta):                      # phi(theta) - mu_inf
        return A * theta / (Dc + B * theta)

    def drop(t1, t2):                    # phi(t1) - phi(t2), without cancellation
        return A * Dc * (t1 - t2) / ((Dc + B * t1) * (Dc + B * t2))

    def W(theta):                        # W(u) at u = Dc/theta (theta may underflow to 0)
        return A * Dc * theta / (Dc + B * theta) ** 2

    def uW(theta):
        return A * Dc * Dc / (Dc + B * theta) ** 2

    disc = (A - 2 * K * B) ** 2 - 4 * K * K * B * B
    roots_D = []                         # W(u) = K: K u^2 + (2 K B - A) u + K B^2 = 0
    if disc > 0 and A > 2 * K * B:
        roots_D = [((A - 2 * K * B) - math.sqrt(disc)) / (2 * K), ((A - 2 * K * B) + math.sqrt(disc)) / (2 * K)]
    r = math.sqrt(K * V / A)             # N = 0: u / (u + B) = r
    root_N = B * r / (1.0 - r) if r < 1.0 else math.inf

    def stick(theta):
        return theta + (A * Dc / (k0 * V * (Dc + B * theta)) - Dc - B * theta) / B

    def slip(theta):
        s1 = math.log(roots_D[1] * theta / Dc)
        if not s1 > 0.0:
            raise RuntimeError(f"slip with no hump at u = {Dc / theta!r} (u+ = {roots_D[1]!r})")
        g = lambda s: drop(theta, theta * math.exp(-s)) - K * s  # noqa: E731
        s_hi = s1 + rel(theta) / K + 1.0
        s = brentq(g, s1, s_hi, xtol=1e-300, rtol=4 * np.finfo(float).eps, maxiter=500)
        return theta * math.exp(-s)

    def slide_end(theta):                # theta moves monotonically to Dc/V
        lo, hi = sorted((theta, Dc / V))
        inside = [(abs(x - theta), x, kind) for x, kind in
                  [(Dc / root_N, "stick")] + [(Dc / x, "slip") for x in roots_D] if lo < x < hi]
        if not inside:
            return None, "steady"
        _, x, kind = min(inside)
        return x, kind

    theta = 1.001 * Dc / V
    phases: list[str] = []
    visited: list[float] = []            # theta at the phase ends of the current cycle
    landing = math.nan
    for n_cycles in range(max_cycles + 1):
        for _ in range(64):              # at most a few phases per cycle
            N, D = K * V - uW(theta), K - W(theta)
            if N < 0.0:
                theta, kind = stick(theta), "stick"
            elif D < 0.0:
                theta, kind = slip(theta), "slip"
            else:
                end, then = slide_end(theta)
                if end is None:
                    s = mu_inf + A / (V + B)
                    return {"regime": "steady", "sigma_max": s, "sigma_min": s, "n_cycles": n_cycles,
                            "sequence": tuple(phases + ["slide"])}
                phases.append("slide")
                visited.append(end)
                # the slide ends exactly on a root of N or D: that phase follows (the sign of
                # N or D there is round-off)
                theta, kind = (stick(end), "stick") if then == "stick" else (slip(end), "slip")
            phases.append(kind)
            visited.append(theta)
            if kind == "slip":
                break
        else:
            raise RuntimeError("no slip in 64 phases")
        if abs(theta - landing) <= rtol * theta:     # (never true while landing is NaN)
            return {"regime": "stick-slip", "sigma_max": mu_inf + rel(max(visited)),
                    "sigma_min": mu_inf + rel(min(visited)), "n_cycles": n_cycles, "sequence": tuple(phases)}
        landing = theta
        phases, visited = [], [theta]
    raise RuntimeError(f"no fixed point of the landing map in {max_cycles} cycles")
