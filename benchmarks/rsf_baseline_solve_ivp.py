"""Baseline for the bifurcation benchmark: the a = 0 spring-slider (Eqs. 8, 11, 12 of Landes,
Rosso & Jagla 2015) with a plain ``scipy.integrate.solve_ivp`` event loop written in Python.

Every phase is integrated by ``solve_ivp`` (DOP853) with a terminal event: the stick
(theta' = 1, sigma' = k0 V, event sigma = phi(theta)), the slide (the reduced ODE, in the
same desingularised time as rsf so that D = 0 is a regular event) and the slip (in the
slip s = dx / Dc: ln theta' = -1, sigma' = -k0 Dc, event sigma = phi(theta)).  Cycles are
repeated one by one until sigma_max, sigma_min and the period change by less than
``cycle_rtol`` from one cycle to the next -- no extrapolation, no compiled code.  This is
what rsf is compared against; it is not part of the package.

Run ``python benchmarks/rsf_baseline_solve_ivp.py`` for a few points.
"""
from __future__ import annotations

import math

from scipy.integrate import solve_ivp

A, B, DC = 0.007, 0.078, 0.06


class Paper:
    """Eq. (10) with the paper's offset."""

    def __init__(self, k0: float, Dc: float = DC) -> None:
        self.k0, self.Dc, self.K = k0, Dc, k0 * Dc
        self.mu_inf = 1.0 - 0.05 * (k0 + 1.0)

    def phi(self, theta: float) -> float:          # mu_ss(Dc / theta) - mu_inf, Eq. (11)
        return A * theta / (self.Dc + B * theta)   # (relative: keeps precision near mu_inf)

    def W(self, u: float) -> float:                 # -u dmu_ss/du
        return A * (u / (u + B)) / (u + B)


def _event(fun, direction):
    fun.terminal = True
    fun.direction = direction
    return fun


def cycle_stats(model: Paper, V: float, cycle_rtol: float = 1e-6, rtol: float = 1e-9,
                max_cycles: int = 20000) -> dict:
    """Run from the perturbed steady state to a converged cycle or steady sliding."""
    k0, Dc, K = model.k0, model.Dc, model.K
    theta = Dc / V * 1.001
    sigma = model.phi(theta)
    t = 0.0
    landings = []       # (t, sigma_max of the cycle, sigma_min)
    sig_max = -math.inf
    phase = None

    def decide(theta: float) -> str:
        u = Dc / theta
        w = model.W(u)
        if K * V - u * w < 0:
            return "stick"
        return "slide" if K - w > 0 else "slip"

    phase = decide(theta)
    for _ in range(10 * max_cycles):
        if phase == "stick":
            ev = _event(lambda tt, y: y[1] - model.phi(y[0]), 1)
            sol = solve_ivp(lambda tt, y: [1.0, k0 * V], (0.0, 1e12), [theta, sigma], method="DOP853",
                            events=ev, rtol=rtol, atol=1e-14, first_step=1e-9 * theta)
            dt = sol.t_events[0][0]
            theta, sigma = sol.y_events[0][0]
            t += dt
            sig_max = max(sig_max, sigma)
            u = Dc / theta
            phase = "slide" if K - model.W(u) > 0 else "slip"
        elif phase == "slide":
            u0 = Dc / theta
            vs = max(V, u0)

            def rhs(tau, y):
                u = u0 * math.exp(-y[0])
                return [(u - V) / vs, Dc * (K - model.W(u)) / (K * vs)]

            e_slip = _event(lambda tau, y: K - model.W(u0 * math.exp(-y[0])), -1)
            e_stick = _event(lambda tau, y: K * V - u0 * math.exp(-y[0]) * model.W(u0 * math.exp(-y[0])), -1)
            e_steady = _event(lambda tau, y: abs(math.log(u0 * math.exp(-y[0]) / V)) - cycle_rtol, -1)
            stable = K - model.W(V) > 0
            events = [e_slip, e_stick] + ([e_steady] if stable else [])
            sol = solve_ivp(rhs, (0.0, 1e4), [0.0, 0.0], method="DOP853", events=events, rtol=rtol,
                            atol=1e-14)
            which = [i for i, te in enumerate(sol.t_events) if len(te)][0]
            z, dt = sol.y_events[which][0]
            theta *= math.exp(z)
            sigma = model.phi(theta)
            t += dt
            if which == 2:
                mu = model.mu_inf + model.phi(Dc / V)
                return {"regime": "steady", "sigma_max": mu, "sigma_min": mu, "period": math.nan,
                        "cycles": len(landings)}
            phase = "slip" if which == 0 else "stick"
        else:   # slip, in s = dx / Dc
            s0 = sigma
            lt0 = math.log(theta)
            ev = _event(lambda s, y: y[1] - model.phi(math.exp(y[0])), -1)
            sol = solve_ivp(lambda s, y: [-1.0, -K], (0.0, 1e5), [lt0, s0], method="DOP853",
                            events=ev, rtol=rtol, atol=1e-14, first_step=1e-6)
            lt, sigma = sol.y_events[0][0]
            theta = max(math.exp(lt), 1e-300)
            landings.append((t, model.mu_inf + sig_max, model.mu_inf + sigma))
            sig_max = -math.inf
            phase = decide(theta)
            if len(landings) >= 3:
                (t0, _, _), (t1, mx1, mn1), (t2, mx2, mn2) = landings[-3:]
                p1, p2 = t1 - t0, t2 - t1
                change = max(abs(mx2 - mx1) / abs(mx2), abs(mn2 - mn1) / abs(mn2), abs(p2 - p1) / p2)
                if change < cycle_rtol:
                    return {"regime": "stick-slip", "sigma_max": mx2, "sigma_min": mn2, "period": p2,
                            "cycles": len(landings)}
            if len(landings) > max_cycles:
                break
    return {"regime": "unknown", "sigma_max": math.nan, "sigma_min": math.nan, "period": math.nan,
            "cycles": len(landings)}


if __name__ == "__main__":
    from _harness import timed

    for k0, V in [(0.3, 0.05), (0.3, 0.15), (0.01, 1.0), (0.01, 20.0)]:
        out, seconds = timed(cycle_stats, Paper(k0), V)
        print(f"k0={k0:<7g} V={V:<7g} {seconds:7.3f} s  {out}")
