"""How each method of :mod:`micro` is set: one small frozen, validated options object per
method, and the table that names them.

Each question of :mod:`micro.api` takes ``method=``, a name (the method with its
defaults) or one of these objects, in the spirit of ``scipy.integrate.solve_ivp``'s
per-method arguments and of diffrax's solver objects:

* :class:`Renewal`: steady sliding, its spectrum and V^c by the jump-to-jump renewal
  chain (:mod:`micro.renewal`); its tolerance.
* :class:`Cohort`: stick-slip cycles by cohorts of exponential margins
  (:mod:`micro.cohort`); its time step and delta_R cell.
* :class:`FP`: the Fokker-Planck equation (:mod:`micro.fp`); its bin (also
  ``numerics=``, its older name :class:`Numerics`).
* :class:`Auto` (``"auto"``, the default): the best method for each question, each
  with the options given here.

:class:`Convergence`, the stopping rule of the iterations, is shared.  A method that is
retired (``"cycle"``) or unknown fails here, in one line, before anything is computed.
"""
from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, ClassVar, Union

from .params import KIND_EXPONENTIAL, Model, _number

if TYPE_CHECKING:  # pragma: no cover  (micro.grid loads the Fokker-Planck kernels: imported where used)
    from .grid import GridSettings

__all__ = ["FP", "Numerics", "Cohort", "Renewal", "Auto", "Convergence", "METHODS", "resolve", "default_eps",
           "check_velocity"]


def _no_bool(obj, names, prefix: str = "") -> None:
    """Numbers only: a bool (``True`` is an int to Python) is refused, naming the field."""
    for name in names:
        if isinstance(getattr(obj, name), bool):
            raise ValueError(f"{prefix}{name} must be a number, got {getattr(obj, name)!r}")


def check_velocity(V: float, name: str = "V") -> float:
    """``V`` as a finite float > 0, or one ValueError naming it (not a bool or a string:
    the model's own number check)."""
    V = _number(name, V)
    if not (math.isfinite(V) and V > 0.0):
        raise ValueError(f"{name} must be a finite number > 0, got {V:g}")
    return V


#: Default bin: this fraction of a mean jump of delta, kappa * zbar.
EPS_FRACTION = 1.0 / 50.0


def default_eps(model: Model) -> float:
    """The default bin, ``kappa * zbar / 50`` (2e-3 for the paper's parameters).

    The Fokker-Planck method's ``eps`` when :class:`FP` is given none.

    Parameters
    ----------
    model : Model
        The model.

    Returns
    -------
    float
        ``model.kappa * model.zbar / 50``.

    Examples
    --------
    >>> import micro
    >>> round(micro.default_eps(micro.Model(k0=0.01)), 12)       # kappa = 1.01, zbar = 0.1
    0.00202
    """
    return model.kappa * model.zbar * EPS_FRACTION


@dataclass(frozen=True)
class FP:
    """The Fokker-Planck method's options (``method=micro.FP(...)`` or
    ``numerics=micro.FP(...)``; :class:`Numerics` is its older name).

    Parameters
    ----------
    eps : bin width of delta_F and delta_R; None: :func:`default_eps`, ``kappa zbar / 50``.
        Its refinement variable (second order).
    theta_shift, theta_relax : the step limits of the shift and the relaxation, in bins.
    max_memory_gib : the memory the grid may take; beyond it a run raises
        :class:`~micro.grid.GridTooLarge` instead of exhausting the machine.
    """

    name: ClassVar[str] = "fp"
    eps: float | None = None
    theta_shift: float = 0.5
    theta_relax: float = 0.5
    max_memory_gib: float = 4.0

    def __post_init__(self) -> None:
        _no_bool(self, ("eps", "theta_shift", "theta_relax", "max_memory_gib"))
        if not (math.isfinite(self.max_memory_gib) and self.max_memory_gib > 0.0):
            raise ValueError(f"max_memory_gib must be a finite number > 0, got {self.max_memory_gib!r}")
        if self.eps is not None and not (math.isfinite(self.eps) and self.eps > 0.0):
            raise ValueError(f"eps must be a finite number > 0 (or None for the default), got {self.eps!r}")
        if not (0.0 < self.theta_shift <= 1.0):
            raise ValueError(f"theta_shift must be in (0, 1], got {self.theta_shift!r}")
        if not (0.0 < self.theta_relax <= 2.0):
            raise ValueError(f"theta_relax must be in (0, 2], got {self.theta_relax!r}")

    def settings(self, model: Model) -> GridSettings:
        """The grid's settings for ``model`` (a ValueError naming eps if it is out of range)."""
        from .grid import GridSettings

        eps = default_eps(model) if self.eps is None else float(self.eps)
        settings = GridSettings(eps=eps, theta_shift=self.theta_shift, theta_relax=self.theta_relax, dt_max=math.inf,
                                max_bytes=self.max_memory_gib * 2**30)
        settings.check(model)
        return settings


@dataclass(frozen=True)
class Convergence:
    """When a stationary run stops.

    Parameters
    ----------
    rtol : stick-slip: the last ``n`` cycles' sigma_max and sigma_min agree within
        ``rtol`` times the stress drop and their periods within ``rtol`` (the paper:
        1 % over three consecutive global shocks).  Steady: the last ``n`` stress means
        agree within ``rtol`` times the velocity weakening ``|sigma - sigma_inf|``
        (the paper: 1 % over three values) plus the grid's jitter ``k0 * eps``, plus
        ``atol``.
    atol : absolute stress tolerance added to both tests.
    n : how many consecutive values or cycles must agree.
    t_max : longest simulated time (None: 400 relaxation times, or 60 times the
        time the drive needs to load one mean jump, whichever is longer).
    """

    rtol: float = 1e-2
    atol: float = 1e-9
    n: int = 3
    t_max: float | None = None

    def __post_init__(self) -> None:
        _no_bool(self, ("rtol", "atol", "n", "t_max"))
        if not (math.isfinite(self.rtol) and self.rtol > 0.0):
            raise ValueError(f"rtol must be a finite number > 0, got {self.rtol!r}")
        if not (math.isfinite(self.atol) and self.atol >= 0.0):
            raise ValueError(f"atol must be a finite number >= 0, got {self.atol!r}")
        if int(self.n) != self.n or self.n < 2:
            raise ValueError(f"n must be an integer >= 2, got {self.n!r}")
        if self.t_max is not None and not (math.isfinite(self.t_max) and self.t_max > 0.0):
            raise ValueError(f"t_max must be a finite number > 0 (or None), got {self.t_max!r}")


#: The older name of :class:`FP` (its options were the only numerics once).
Numerics = FP


#: Default time step of the cohort method (its error is second order in it).
COHORT_DT = 0.01
#: Default delta_R cell of the cohort method, in units of a mean jump kappa * zbar.
COHORT_CELL = 1.0 / 20.0


#: The most delta_R cells the cohort method's grid may have (each a few doubles in several
#: arrays; the default cell, kappa zbar / 20, gives about 160).
COHORT_CELLS_MAX = 1e7

#: The most time steps one loading phase of the cohort method may take (at about a
#: microsecond each, a quarter of an hour per cycle, and 10-20 cycles are needed): beyond,
#: :func:`micro.stationary` refuses before computing.
COHORT_STEPS_MAX = 1e9


@dataclass(frozen=True)
class Cohort:
    """The cohort method's options (``method=micro.Cohort(...)``).

    Parameters
    ----------
    dt : time step of the loading phase, in (0, 0.1] (default 0.01; the error is second
        order in it).
    h : delta_R cell, in [90 k2 zbar / 1e7, kappa zbar / 2]; None: ``kappa zbar / 20``.
    tol : the fixed point's tolerance on sigma_max, sigma_min, sigma_before and
        sigma_after, in units of stress, in [1e-9, 1e-2] (default 2e-5).
    max_iter : most cycles the fixed-point iteration may take, >= 4.
    """

    name: ClassVar[str] = "cohort"
    dt: float = COHORT_DT
    h: float | None = None
    tol: float = 2e-5
    max_iter: int = 200

    def __post_init__(self) -> None:
        _no_bool(self, ("dt", "h", "tol", "max_iter"), "Cohort ")
        if not (isinstance(self.tol, (int, float)) and math.isfinite(self.tol) and 1e-9 <= self.tol <= 1e-2):
            raise ValueError(f"Cohort tol must be in [1e-9, 1e-2], got {self.tol!r}")
        if not (isinstance(self.dt, (int, float)) and math.isfinite(self.dt) and 0.0 < self.dt <= 0.1):
            raise ValueError(f"Cohort dt must be a finite number in (0, 0.1], got {self.dt!r}")
        if self.h is not None and not (isinstance(self.h, (int, float)) and math.isfinite(self.h) and self.h > 0.0):
            raise ValueError(f"Cohort h must be a finite number > 0 (or None for kappa zbar / 20), got {self.h!r}")
        if not (isinstance(self.max_iter, int) and self.max_iter >= 4):
            raise ValueError(f"Cohort max_iter must be an integer >= 4, got {self.max_iter!r}")

    def cell(self, model: Model) -> float:
        """The delta_R cell for ``model``, or one ValueError naming h and its range: at most
        ``kappa zbar / 2``, and at least ``90 k2 zbar / COHORT_CELLS_MAX`` (the cohort's
        delta_R grid spans ``(k2 / kappa) 45 kappa zbar`` on each side of 0, so that many
        cells; a finer one asked for more memory than any machine has)."""
        top = 0.5 * model.kappa * model.zbar
        low = 90.0 * model.k2 * model.zbar / COHORT_CELLS_MAX
        h = model.kappa * model.zbar * COHORT_CELL if self.h is None else float(self.h)
        if not low <= h <= top:
            raise ValueError(f"Cohort h must be in [{low:.3g}, {top:g}] (at most kappa zbar / 2; at least 90 k2 "
                             f"zbar / {COHORT_CELLS_MAX:.0e}, the delta_R grid's span over its largest cell count), "
                             f"got {h:g}")
        return h


#: The cohort method takes an Exponential whose cutoff removes at most this fraction of the
#: jumps (exp(-cutoff / zbar) <= 1e-13, cutoff >= 30 zbar): a jumped block's margin is
#: then Exp(kappa zbar) to double precision.  A closer cutoff changes the margins at order
#: exp(-cutoff / zbar) (cutoff = 3 zbar: sigma_min 1.3e-2 off, tests/micro/test_cohort_parameters.py).
CUTOFF_TAIL = 1e-13


def cohort_not_applicable(model: Model) -> str:
    """Why the cohort method does not apply to ``model``'s jumps ("" if it does); here, not
    in :mod:`micro.cohort` (also ``micro.cohort.not_applicable``), so that a command line
    refuses such a model before it loads the cohort's kernels."""
    jumps = model.jumps
    if jumps.kind != KIND_EXPONENTIAL:
        return "the cohort method needs exponential jumps (a jumped block's margin is then Exp(kappa zbar))"
    if math.exp(-jumps.cutoff / jumps.zbar) > CUTOFF_TAIL:
        return (f"the cohort method needs exponential jumps whose cutoff removes a negligible tail "
                f"(cutoff >= 30 zbar = {30 * jumps.zbar:g}, got {jumps.cutoff:g})")
    return ""


@dataclass(frozen=True)
class Renewal:
    """The renewal chain's options (steady sliding, its spectrum and V^c).

    Parameters
    ----------
    tol : the chain's grid is refined until sigma and the branching ratio change by
        less than this; in [1e-13, 1e-3] (default 1e-11).
    """

    name: ClassVar[str] = "renewal"
    tol: float = 1e-11

    def __post_init__(self) -> None:
        _no_bool(self, ("tol",), "Renewal ")
        if not (isinstance(self.tol, (int, float)) and math.isfinite(self.tol) and 1e-13 <= self.tol <= 1e-3):
            raise ValueError(f"Renewal tol must be in [1e-13, 1e-3], got {self.tol!r}")


@dataclass(frozen=True)
class Auto:
    """The default: the best method for each question.

    Steady sliding (where it is stable) and V^c come from the renewal chain, stick-slip
    cycles from the cohort method where it applies (exponential jumps), and the
    Fokker-Planck equation answers only where nothing better applies or its state is
    asked for (a transient, a slide-hold-slide, ``keep_grid``).

    Parameters
    ----------
    renewal, cohort : the options of the methods it dispatches to; the Fokker-Planck
        fallback takes the ``numerics`` argument.
    """

    name: ClassVar[str] = "auto"
    renewal: Renewal = field(default_factory=Renewal)
    cohort: Cohort = field(default_factory=Cohort)

    def __post_init__(self) -> None:
        if not isinstance(self.renewal, Renewal):
            raise ValueError(f"Auto renewal must be a micro.Renewal, got {type(self.renewal).__name__}")
        if not isinstance(self.cohort, Cohort):
            raise ValueError(f"Auto cohort must be a micro.Cohort, got {type(self.cohort).__name__}")


Method = Union[str, FP, Cohort, Renewal, Auto]

#: The methods by name: each name gives its options object with the defaults.
METHODS: dict[str, type] = {"auto": Auto, "renewal": Renewal, "cohort": Cohort, "fp": FP}
#: Retired names, and what to use instead.
RETIRED = {"cycle": "method='cycle' was retired (its cycles are wrong close to V^c): use method='cohort', or "
                    "'auto' (the default), which solves the same stick-slip cycles at every k0"}


def resolve(method: Method, allowed: tuple[str, ...], question: str):
    """The options object for ``method`` (a name or an object), if ``question`` has that
    method among ``allowed``; else one ValueError naming the choices."""
    if isinstance(method, str):
        if method in RETIRED:
            raise ValueError(RETIRED[method])
        if method not in allowed:
            raise ValueError(f"{question}: method must be one of {', '.join(repr(m) for m in allowed)} "
                             f"(or its options object), got {method!r}")
        return METHODS[method]()
    name = getattr(type(method), "name", None)
    if not isinstance(name, str) or METHODS.get(name) is not type(method):
        raise ValueError(f"{question}: method must be a name ({', '.join(repr(m) for m in allowed)}) or an options "
                         f"object (micro.Auto, micro.Cohort, micro.Renewal, micro.FP), got {type(method).__name__}")
    if name not in allowed:
        raise ValueError(f"{question}: method must be one of {', '.join(repr(m) for m in allowed)}, got {name!r}")
    return method
