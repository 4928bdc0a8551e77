"""The analysis of the spring-slider, under the names it has always had here: the linear
stability of steady sliding and the critical velocity (:mod:`rsf.stability`), and the
amplitude scaling near the Hopf bifurcation (:mod:`rsf.hopf`).

This module only gathers them: the integrators import :mod:`rsf.stability`, and
:mod:`rsf.hopf` imports the integrators, so that no two modules import each other.
"""
from __future__ import annotations

from .hopf import HopfFit, fit_power_law, hopf_scaling
from .stability import CriticalVelocity, critical_velocity, stability_margin, steady_jacobian

__all__ = ["CriticalVelocity", "critical_velocity", "HopfFit", "hopf_scaling", "fit_power_law",
           "steady_jacobian", "stability_margin"]
