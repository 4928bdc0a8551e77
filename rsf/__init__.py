r"""rsf — rate-and-state friction for a spring-slider, after Landes, Rosso & Jagla (2015),
Sec. V: stick, slide and instantaneous slip located as events, the linear stability of
steady sliding, limit cycles and the standard rate-and-state laws.

The obvious entry point is :func:`simulate`::

    import rsf
    model = rsf.SpringSlider(k0=0.01)            # the paper's Eq. (10) law, Dc = 0.06
    run = rsf.simulate(model, V=1.0, t_end=50)   # time series + events
    cycle = rsf.limit_cycle(model, V=1.0)        # the attractor: regime, sigma_max, ...
    table = rsf.sweep(model, [0.1, 1, 10, 20]).to_frame()
    rsf.critical_velocity(model.law, k0=0.01, Dc=0.06).Vc
"""
from __future__ import annotations

from .laws import (
    PAPER_A,
    PAPER_B,
    PAPER_DC,
    CallableLaw,
    HyperbolicLaw,
    LogLaw,
    SteadyStateLaw,
    TabulatedLaw,
    ViscoelasticLaw,
    paper_mu_inf,
)
from .params import InitialState, Protocol, SolverOptions, SpringSlider, standard_rs
from .reference import reference_cycle
from .state_laws import (
    AgingLaw,
    CallableStateLaw,
    NagataLaw,
    PRZLaw,
    SecondState,
    SlipLaw,
    StateLaw,
)
from .results import STATUS_MESSAGES, CycleResult, Event, Status, SweepResult, Trajectory
from .solver import limit_cycle, simulate, sweep
from .normal_form import (HopfNormalForm, StickSlipNormalForm, classify_spectrum, cycle_near_hopf,
                          hopf_normal_form, stick_slip_normal_form, transition_spectrum)
from .stability import CriticalVelocity, critical_velocity
from .hopf import HopfFit, fit_power_law, hopf_scaling

__all__ = [
    "simulate",
    "limit_cycle",
    "sweep",
    "critical_velocity",
    "hopf_scaling",
    "fit_power_law",
    "hopf_normal_form",
    "stick_slip_normal_form",
    "transition_spectrum",
    "classify_spectrum",
    "cycle_near_hopf",
    "reference_cycle",
    "SpringSlider",
    "standard_rs",
    "Protocol",
    "InitialState",
    "SolverOptions",
    "SteadyStateLaw",
    "HyperbolicLaw",
    "ViscoelasticLaw",
    "LogLaw",
    "TabulatedLaw",
    "CallableLaw",
    "paper_mu_inf",
    "StateLaw",
    "AgingLaw",
    "SlipLaw",
    "PRZLaw",
    "NagataLaw",
    "CallableStateLaw",
    "SecondState",
    "PAPER_A",
    "PAPER_B",
    "PAPER_DC",
    "Trajectory",
    "CycleResult",
    "SweepResult",
    "CriticalVelocity",
    "HopfFit",
    "HopfNormalForm",
    "StickSlipNormalForm",
    "Event",
    "Status",
    "STATUS_MESSAGES",
]
