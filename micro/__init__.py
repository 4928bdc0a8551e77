r"""micro — the mean-field viscoelastic depinning model of Landes, Rosso & Jagla (2015).

Steady sliding and its stability are solved directly, as the jump-to-jump renewal chain
of one block (:mod:`micro.renewal`); transients, stick-slip cycles and slide-hold-slide
by a Fokker-Planck (master) equation for the joint density P(delta_F, delta_R) at finite
driving velocity (their Appendix B), with an independent N-block check.

The obvious entry points::

    import micro
    model = micro.Model(k0=0.01)                       # Fig. 4 parameters: k1=.1, k2=.9, zbar=.1
    run = micro.simulate(model, 5.0, duration=50.0)    # stress time series, w = V t
    steady = micro.steady_sliding(model, [1.0, 5.0])   # steady branch: sigma, branching ratio, stability
    vc = micro.critical_velocity(model)                # V^c where the branching ratio reaches 1
    state = micro.stationary(model, 5.0)               # steady stress, or sigma_max / sigma_min
    table = micro.sweep(model, [1.0, 5.0, 20.0])       # one row per V
    peaks = micro.slide_hold_slide(model, 1000.0, [0.1, 1.0, 10.0])
"""
from __future__ import annotations

from .grid import GridTooLarge
from .analytic import sigma_deterministic_steady, sigma_fast_limit, sigma_slow_limit
from .params import Deterministic, Exponential, JumpDistribution, Model, Tabulated
from .protocols import Drive
from .renewal import SteadySliding, characteristic_function, steady_sliding, unstable_mode_count, vc_small_k0
from .solver import (
    Convergence,
    Critical,
    Numerics,
    Run,
    Stationary,
    critical_velocity,
    default_eps,
    simulate,
    slide_hold_slide,
    stationary,
    sweep,
)

__all__ = [
    "Model",
    "JumpDistribution",
    "Exponential",
    "Deterministic",
    "Tabulated",
    "Drive",
    "Numerics",
    "Convergence",
    "Run",
    "Stationary",
    "Critical",
    "SteadySliding",
    "steady_sliding",
    "characteristic_function",
    "unstable_mode_count",
    "vc_small_k0",
    "GridTooLarge",
    "simulate",
    "stationary",
    "critical_velocity",
    "sweep",
    "slide_hold_slide",
    "default_eps",
    "sigma_deterministic_steady",
    "sigma_fast_limit",
    "sigma_slow_limit",
]
