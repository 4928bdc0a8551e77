"""An independent classical rate-and-state spring-slider for the tests: scipy's DOP853 at
rtol 1e-12 in (ln v, ln theta) and physical time.  It shares no code with :mod:`rsf`.

.. math::
    \\mu = \\mu_0 + a\\ln\\frac{v}{v_0} + b\\ln\\frac{v_0\\theta}{D_c},\\qquad
    k_0\\,(V(t) - v) = \\dot\\mu\\;\\Rightarrow\\;
    a\\,\\frac{\\mathrm{d}\\ln v}{\\mathrm{d}t} = k_0(V - v) - b\\,\\frac{\\mathrm{d}\\ln\\theta}{\\mathrm{d}t}.
"""
from __future__ import annotations

import numpy as np
from scipy.integrate import solve_ivp


def state_rate(law: str, v: float, theta: float, Dc: float) -> float:
    """d ln(theta)/dt of the named state evolution law (independent formulas)."""
    if law == "aging":          # Dieterich (1979)
        return 1.0 / theta - v / Dc
    if law == "slip":           # Ruina (1983)
        return -(v / Dc) * np.log(v * theta / Dc)
    if law == "prz":            # Perrin, Rice & Zheng (1995)
        return (1.0 - (v * theta / (2.0 * Dc)) ** 2) / theta
    raise ValueError(law)


def mu_at(law: str, *, a: float, b: float, Dc: float, k0: float, v0: float, mu0: float,
          velocities, times, t_eval: np.ndarray) -> np.ndarray:
    """Friction at ``t_eval`` for piecewise-constant driving (``velocities[i]`` from
    ``times[i]``), starting at steady state at ``velocities[0]``."""
    def rhs(t, y, V):
        lv, lth = y
        v = np.exp(lv)
        dlth = state_rate(law, v, np.exp(lth), Dc)
        return [(k0 * (V - v) - b * dlth) / a, dlth]

    y = np.array([np.log(velocities[0]), np.log(Dc / velocities[0])])
    edges = list(times) + [max(t_eval[-1], times[-1])]
    lv = np.full(t_eval.size, np.nan)
    lth = np.full(t_eval.size, np.nan)
    for i, V in enumerate(velocities):
        t0, t1 = edges[i], edges[i + 1]
        if t1 <= t0:
            continue
        inside = (t_eval >= t0) & (t_eval <= t1)
        sol = solve_ivp(rhs, (t0, t1), y, method="DOP853", rtol=1e-12, atol=1e-14,
                        dense_output=True, args=(V,))
        assert sol.success, sol.message
        if inside.any():
            yy = sol.sol(t_eval[inside])
            lv[inside], lth[inside] = yy
        y = sol.y[:, -1]
    return mu0 + a * (lv - np.log(v0)) + b * (lth + np.log(v0 / Dc))
