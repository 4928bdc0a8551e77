"""Fit a Fokker-Planck run into a wall-time budget (shared by the benchmark scripts)."""
from __future__ import annotations

import micro


def capped_t_max(model: micro.Model, V: float, eps: float, budget: float) -> float:
    """Simulated time that fits ``budget`` seconds at drive velocity ``V``.

    The cost per unit time is measured on a second short run that continues the first
    (the first loads the springs from rest, which is cheaper than sliding and made a
    one-run calibration underestimate the cost four-fold at k0 = 1e-3, V = 175).
    """
    # a twentieth of a loading time, but at most 2 time units (at small V the cost is
    # the synchronisations, ~140 per unit time, not the drive)
    probe = min(0.05 * max(model.kappa * model.zbar / (model.k0 * V), 1.0), 2.0)
    numerics = micro.Numerics(eps=eps)
    first = micro.simulate(model, V, duration=probe, numerics=numerics)
    second = micro.simulate(model, V, duration=probe, numerics=numerics, initial=first.grid)
    rate = max(second.wall_time, 1e-4) / probe
    return budget / rate
