r"""micro — the mean-field viscoelastic depinning model of Landes, Rosso & Jagla (2015).

One call per question (:mod:`micro.api`), each answered by default by the best method
for it: steady sliding, its stability and V^c by the jump-to-jump renewal chain of one
block (:mod:`micro.renewal`, exact in milliseconds); stick-slip cycles by the cohort
method (:mod:`micro.cohort`, fixed points of the cycle map, seconds at every k0);
transients and slide-hold-slide by the Fokker-Planck equation for P(delta_F, delta_R)
(:mod:`micro.fp`, the paper's Appendix B), also the fallback where nothing better
applies; an independent event-driven N-block simulation (:mod:`micro.nblock`) checks
them.  ``method=`` takes a name or an options object (:mod:`micro.methods`), and every
result says which method produced it.

The obvious entry points::

    import micro
    model = micro.Model(k0=0.01)                       # Fig. 4 parameters: k1=.1, k2=.9, zbar=.1
    run = micro.simulate(model, 5.0, duration=50.0)    # stress time series, w = V t
    steady = micro.steady_sliding(model, [1.0, 5.0])   # steady branch: sigma, branching ratio, stability
    vc = micro.critical_velocity(model)                # V^c where the branching ratio reaches 1
    state = micro.stationary(model, 5.0)               # steady stress, or sigma_max / sigma_min
    fine = micro.stationary(model, 5.0, method=micro.Cohort(dt=0.005))  # a method's own options
    table = micro.sweep(model, [1.0, 5.0, 20.0])       # one row per V
    branch = micro.cycle_branch(model, d_min=0.02)     # stick-slip branch towards V^c, with errors
    peaks = micro.slide_hold_slide(model, 1000.0, [0.1, 1.0, 10.0])
"""
from __future__ import annotations

from importlib import import_module as _import_module
from typing import TYPE_CHECKING

if TYPE_CHECKING:  # pragma: no cover  (for type checkers and IDEs: the names are loaded on first use)
    from .grid import GridTooLarge
    from .analytic import sigma_deterministic_steady, sigma_fast_limit, sigma_slow_limit
    from .params import Deterministic, Exponential, JumpDistribution, Model, Tabulated
    from .protocols import Drive
    from .renewal import (SteadySliding, characteristic_function, growth_rate_near_vc, steady_sliding,
                          unstable_mode_count, vc_small_k0)
    from .methods import FP, Auto, Cohort, Convergence, Numerics, Renewal, default_eps
    from .results import Critical, CycleFixedPoint, Run, Stationary
    from .api import critical_velocity, simulate, slide_hold_slide, stationary, sweep
    from .branch import Branch, cycle_branch

__all__ = [
    "Model",
    "JumpDistribution",
    "Exponential",
    "Deterministic",
    "Tabulated",
    "Drive",
    "Auto",
    "Renewal",
    "Cohort",
    "FP",
    "Numerics",
    "Convergence",
    "Run",
    "Stationary",
    "Critical",
    "CycleFixedPoint",
    "SteadySliding",
    "steady_sliding",
    "characteristic_function",
    "growth_rate_near_vc",
    "unstable_mode_count",
    "vc_small_k0",
    "GridTooLarge",
    "simulate",
    "stationary",
    "critical_velocity",
    "sweep",
    "cycle_branch",
    "Branch",
    "slide_hold_slide",
    "default_eps",
    "sigma_deterministic_steady",
    "sigma_fast_limit",
    "sigma_slow_limit",
]

#: The submodule of each public name: ``import micro`` loads none of them (numba, scipy and
#: pandas take most of a second, which a command line's bad-input error should not wait
#: for); each is imported on first use of one of its names (PEP 562).
_SOURCES = {
    "grid": ("GridTooLarge",),
    "analytic": ("sigma_deterministic_steady", "sigma_fast_limit", "sigma_slow_limit"),
    "params": ("Deterministic", "Exponential", "JumpDistribution", "Model", "Tabulated"),
    "protocols": ("Drive",),
    "renewal": ("SteadySliding", "characteristic_function", "growth_rate_near_vc", "steady_sliding",
                "unstable_mode_count", "vc_small_k0"),
    "methods": ("FP", "Auto", "Cohort", "Convergence", "Numerics", "Renewal", "default_eps"),
    "results": ("Critical", "CycleFixedPoint", "Run", "Stationary"),
    "api": ("critical_velocity", "simulate", "slide_hold_slide", "stationary", "sweep"),
    "branch": ("Branch", "cycle_branch"),
}
_MODULE_OF = {name: module for module, names in _SOURCES.items() for name in names}


def __getattr__(name: str):
    """A public name from its submodule (imported now, kept), or a submodule (``micro.cohort``)."""
    module = _MODULE_OF.get(name)
    if module is not None:
        value = getattr(_import_module(f".{module}", __name__), name)
        globals()[name] = value
        return value
    if not name.startswith("__"):
        try:
            return _import_module(f".{name}", __name__)
        except ModuleNotFoundError as exc:
            if exc.name != f"{__name__}.{name}":   # (a submodule that exists but fails to import says so)
                raise
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")


def __dir__() -> list[str]:
    return sorted(set(globals()) | set(_MODULE_OF))
