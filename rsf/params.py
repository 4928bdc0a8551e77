r"""What the user sets: the spring-slider, the driving protocol, the initial state and the
solver options.  All are small frozen dataclasses that validate themselves on
construction, so that a bad parameter fails at once and names itself.

The model (paper, Sec. V.B; :math:`F_N = 1`, no inertia):

.. math::
    \sigma = k_0\,(X(t) - x) \quad \text{(Eq. 12, } X = Vt \text{ for constant driving)},\qquad
    \dot\theta = 1 - \frac{\theta v}{D_c} \quad \text{(Eq. 8)},

    \mu(v, \theta) = \mu_{ss}(D_c/\theta) + a \ln\frac{v\,\theta}{D_c}
    \quad \text{(Eq. 11 for } a = 0\text{; Eq. 7 for the log law)}.
"""
from __future__ import annotations

import math
import sys
from dataclasses import dataclass, field
from typing import Sequence

import numpy as np

from ._validation import choice, nonnegative, positive, positive_int, real, shown
from .laws import PAPER_DC, HyperbolicLaw, LogLaw, SteadyStateLaw, TabulatedLaw
from .state_laws import (
    AgingLaw,
    CallableStateLaw,
    NagataLaw,
    PRZLaw,
    SecondState,
    SlipLaw,
    state_law_from,
)

__all__ = ["SpringSlider", "Protocol", "InitialState", "SolverOptions", "standard_rs", "T_END_MAX",
           "DC_MIN", "THETA_FLOOR"]

#: The longest run :func:`rsf.simulate` and ``rsf run --t-end`` accept (one bound for both).
#: A steady slide is followed to it in a few CVODE runs; a run of stick-slip cycles that long
#: ends at ``SolverOptions.max_events`` or ``max_rhs_evals`` with its status.
T_END_MAX = 1e8

#: The smallest state the a = 0 engine resolves, in units of Dc: a slip of a law with a
#: finite large-velocity limit lands there (the state below it is not resolved).
THETA_FLOOR = 1e-250

#: The smallest Dc: the a = 0 engine's floor of the state, ``THETA_FLOOR * Dc``, must be a
#: normal double (>= 2.2e-308), else a slip's length ln(theta / floor) divides by zero.
DC_MIN = sys.float_info.min / THETA_FLOOR

#: A slip's onset is resolved when the threshold lies at least this far (relative) below
#: its plateau (see :meth:`SpringSlider.check_resolved`): two units of roundoff.
ONSET_RESOLUTION = 2.0 * sys.float_info.epsilon


@dataclass(frozen=True)
class SpringSlider:
    r"""A block pulled through a spring of stiffness :math:`k_0` on a rate-and-state
    interface.

    Parameters
    ----------
    law : SteadyStateLaw
        The steady-state friction :math:`\mu_{ss}(v)`; default the paper's Eq. (10),
        :class:`~rsf.laws.HyperbolicLaw` with :math:`\mu_\infty` resolved for ``k0``.
    k0 : float
        Driving stiffness, > 0.
    Dc : float
        Critical slip distance, finite and >= ``DC_MIN`` (2.2e-58: the a = 0 engine
        resolves the state down to ``THETA_FLOOR * Dc``, which must be a normal double;
        paper: 0.06).  How small a ``Dc`` still resolves a slip depends on the driving
        velocity too: :meth:`check_resolved`.
    a : float or None
        Direct effect :math:`a \ge 0`.  ``None``: the law's ``a`` for a
        :class:`~rsf.laws.LogLaw` (Eq. 7), otherwise 0 (the paper's model, Eq. 11).
        With :math:`a = 0` the motion splits into stick, slide and instantaneous slip; with
        :math:`a > 0` it is a regular ODE.
    state_law : {'aging', 'slip', 'prz', 'nagata'}, StateLaw or callable
        The state evolution (:mod:`rsf.state_laws`): Eq. (8) (Dieterich aging), the Ruina
        slip law :math:`\dot\theta = -(\theta v/D_c)\ln(\theta v/D_c)`,
        Perrin-Rice-Zheng, Nagata, or a callable ``f(v, theta) -> dtheta/dt``.  All but
        the aging law need :math:`a > 0` (with :math:`a = 0` the instantaneous slip is
        defined for the aging law only).  ``model.state`` is the resolved
        :class:`~rsf.state_laws.StateLaw`.
    second_state : SecondState or None
        A second state variable :math:`b_2\ln(v_0\theta_2/D_{c2})` (log law, a > 0; the
        aging, slip or PRZ law).
    eta_rad : float
        Radiation damping :math:`\eta_{rad} \ge 0` (QDYN's quasi-dynamic term; needs
        :math:`a > 0`): the force balance reads
        :math:`k_0(X(t) - x) = \mu(v, \theta) + \eta_{rad}\,v` (with :math:`F_N = 1`).
        Default 0, the paper's model.

    Raises
    ------
    ValueError
        If ``law`` is not a steady-state law, ``k0`` or ``Dc`` is not a finite number > 0,
        ``a`` or ``eta_rad`` is negative, the state law is unknown, or the parts do not fit
        together: a state law other than aging, ``eta_rad > 0`` or a second state with
        :math:`a = 0`; a user state law whose steady state is not :math:`\theta = D_c/v`;
        ``NagataLaw(b=None)`` or a second state without a :class:`~rsf.laws.LogLaw`; a
        second state with the Nagata or a user law; the default ``mu_inf`` of Eq. (10)
        negative (k0 >= 19).

    Examples
    --------
    >>> import rsf
    >>> model = rsf.SpringSlider(k0=0.1)          # the paper's Eq. (10), Dc = 0.06, a = 0
    >>> round(model.K, 6), round(model.sigma_steady(1.0), 6)
    (0.006, 0.951494)
    """

    law: SteadyStateLaw = field(default_factory=HyperbolicLaw)
    k0: float = 0.01
    Dc: float = PAPER_DC
    a: float | None = None
    state_law: object = "aging"
    second_state: SecondState | None = None
    eta_rad: float = 0.0

    def __post_init__(self) -> None:
        if not isinstance(self.law, SteadyStateLaw):
            raise ValueError(f"law must be a SteadyStateLaw (HyperbolicLaw, ViscoelasticLaw, LogLaw, "
                             f"TabulatedLaw, CallableLaw), got {self.law!r}")
        k0 = positive("k0", self.k0)
        object.__setattr__(self, "k0", k0)
        Dc = positive("Dc", self.Dc)
        if Dc < DC_MIN:
            raise ValueError(f"Dc must be >= {DC_MIN:.3g} (the state is resolved down to "
                             f"{THETA_FLOOR:g} Dc, which must be a normal double), got {shown(self.Dc)}")
        object.__setattr__(self, "Dc", Dc)
        object.__setattr__(self, "law", self.law.bind(k0))
        a = self.a
        if a is None:
            a = self.law.a if isinstance(self.law, LogLaw) else 0.0
        object.__setattr__(self, "a", nonnegative("a", a))
        state = state_law_from(self.state_law)
        object.__setattr__(self, "state", state)
        if (not isinstance(self.state_law, str) and isinstance(state, (AgingLaw, SlipLaw, PRZLaw))
                and state == type(state)()):
            object.__setattr__(self, "state_law", state.name)  # a default law object: its name
        if isinstance(state, CallableStateLaw):
            rate_ss = state.rate(1.0, self.Dc, self.Dc)
            scale = max(abs(state.rate(1.0, 2.0 * self.Dc, self.Dc)), 1e-300)
            if not abs(rate_ss) <= 1e-9 * scale:
                raise ValueError(f"a user state law must have its steady state at theta = Dc/v "
                                 f"(the friction law assumes it): f(1, Dc) = {rate_ss!r}, not 0")
        if state.code != AgingLaw.code and self.a == 0.0:
            raise ValueError(f"state_law={state.name!r} needs a direct effect a > 0 (with a = 0 "
                             f"the instantaneous slip is defined for the aging law only); got a = 0")
        if isinstance(state, NagataLaw) and state.b is None and not isinstance(self.law, LogLaw):
            raise ValueError("NagataLaw(b=None) takes b from a LogLaw; give NagataLaw(c, b=...) "
                             "for another steady-state law")
        eta = nonnegative("eta_rad", self.eta_rad)
        object.__setattr__(self, "eta_rad", eta)
        if eta > 0.0 and self.a == 0.0:
            raise ValueError("eta_rad > 0 needs a direct effect a > 0; got a = 0")
        if self.second_state is not None:
            if not isinstance(self.second_state, SecondState):
                raise ValueError(f"second_state must be an rsf.SecondState, got {self.second_state!r}")
            if not isinstance(self.law, LogLaw) or self.a == 0.0:
                raise ValueError("second_state needs the log law (LogLaw) and a direct effect a > 0")
            if state.code not in (AgingLaw.code, SlipLaw.code, PRZLaw.code):
                raise ValueError(f"second_state works with the aging, slip or PRZ law, "
                                 f"not {state.name!r}")

    @property
    def K(self) -> float:
        r""":math:`k_0 D_c`, the only combination in which :math:`D_c` enters (with time
        measured in units of :math:`D_c`)."""
        return self.k0 * self.Dc

    def sigma_steady(self, V: float) -> float:
        r"""Friction of steady sliding at :math:`V`, :math:`\mu_{ss}(V)` (a
        :class:`~rsf.laws.TabulatedLaw` warns where it holds its end values, outside the
        table)."""
        V = positive("V", V)
        if isinstance(self.law, TabulatedLaw):
            self.law.check_velocities([V])
        return float(self.law.mu_ss(V))

    def check_resolved(self, V: float, names: dict[str, str] | None = None) -> None:
        r"""Raise ValueError where the stick-slip of the a = 0 model at driving velocity
        ``V`` cannot be resolved in double precision (else a "cycle" of period 0 with
        :math:`\sigma_{max} = \sigma_{min}` would come out).

        For a law whose threshold :math:`\phi(\theta) = \mu_{ss}(D_c/\theta)` (Eq. 11)
        levels off at a plateau, :math:`\Delta = \sup\mu_{ss} - \mu_\infty` (``concave_sup``;
        :math:`A/B` for Eq. 10), a slip lands near :math:`\theta = 0` and the next stick
        lasts at most :math:`t_s = \Delta/(k_0 V)` (Eq. 12, :math:`\dot\sigma = k_0 V`), in
        which :math:`\theta` grows at rate 1 (Eq. 8 at :math:`v = 0`).  So the next slip
        starts at :math:`\theta_0/D_c \le \Delta/(K V)` with :math:`K = k_0 D_c`:

        * ``theta0 / (THETA_FLOOR Dc)`` must be a finite double (the slip's length
          :math:`\ln(\theta_0/\theta_{floor})`): :math:`\Delta/(K V) <` ``THETA_FLOOR`` x
          1.8e308;
        * Eq. (10): the slip starts at :math:`u_0 = D_c/\theta_0 \ge K V B/A`, where the
          threshold lies :math:`A/B - A/(u_0 + B) \approx K V/B` below its plateau; relative
          to the friction :math:`\mu_\infty + A/B` this is :math:`K V/(A + B\mu_\infty)`,
          which must exceed ``ONSET_RESOLUTION`` (two units of roundoff), else the slip
          cannot tell the threshold from its plateau.

        Both are sufficient conditions (the worst case, a stick as long as the whole swing);
        a case between them and the true limit that still comes out degenerate gets the
        status ``DEGENERATE`` from the limit-cycle search, never "converged".

        Nothing is checked for :math:`a > 0` (a regular ODE) or a law without a plateau.

        Parameters
        ----------
        V : float
            The driving velocity, > 0.
        names : dict, optional
            The names to give the parameters in the message (the command line's options).
        """
        if self.a != 0.0:
            return
        swing = self.law.concave_sup
        if not (math.isfinite(swing) and swing > 0.0):
            return
        n = {k: k for k in ("k0", "Dc", "V", "A", "B", "mu_inf")}
        n.update(names or {})
        KV = self.K * V
        law = self.law
        ceiling = THETA_FLOOR * sys.float_info.max
        if not swing / KV < ceiling:
            what = (f"{n['A']}/{n['B']} = {law.A:g}/{law.B:g}" if isinstance(law, HyperbolicLaw)
                    else "the law's friction swing")
            raise ValueError(
                f"{n['Dc']} = {self.Dc:g}, {n['k0']} = {self.k0:g} and {n['V']} = {V:g} with {what} = "
                f"{swing:g} are out of range: a stick's state reaches swing / (k0 Dc V) = "
                f"{swing / KV:.3g} times Dc, which must be < {ceiling:.3g} (double range over the "
                f"state's floor {THETA_FLOOR:g} Dc); give a larger {n['Dc']}, {n['k0']} or {n['V']}"
                + (f", a larger {n['B']} or a smaller {n['A']}" if isinstance(law, HyperbolicLaw) else ""))
        if isinstance(law, HyperbolicLaw):
            depth = KV / (law.A + law.B * abs(law.mu_inf))
            if not depth >= ONSET_RESOLUTION:
                need = ONSET_RESOLUTION * (law.A + law.B * abs(law.mu_inf))
                raise ValueError(
                    f"{n['Dc']} = {self.Dc:g} with {n['k0']} = {self.k0:g}, {n['V']} = {V:g}, "
                    f"{n['A']} = {law.A:g}, {n['B']} = {law.B:g} and {n['mu_inf']} = {law.mu_inf:g} "
                    f"cannot be resolved: a slip starts where the threshold lies k0 Dc V / (A + B "
                    f"mu_inf) = {depth:.3g} (relative) below its plateau, less than double "
                    f"precision resolves ({ONSET_RESOLUTION:.3g}); k0 Dc V must be >= {need:.3g}, "
                    f"got {KV:.3g} (a larger {n['Dc']}, {n['k0']} or {n['V']}, a smaller {n['A']} "
                    f"or {n['mu_inf']})")

    def describe(self) -> dict[str, float | str]:
        """Parameters as a flat dict (for tables)."""
        out: dict[str, float | str] = {"k0": self.k0, "Dc": self.Dc, "a": self.a}
        out.update(self.state.describe())
        if self.second_state is not None:
            out.update(b2=self.second_state.b2, Dc2=self.second_state.Dc2)
        if self.eta_rad > 0.0:
            out["eta_rad"] = self.eta_rad
        out.update(self.law.describe())
        return out


def standard_rs(mu0: float = 0.6, a: float = 0.01, b: float = 0.015, Dc: float = 1e-5,
                k0: float = 1e3, v0: float = 1e-6, state_law: object = "aging",
                second_state: SecondState | None = None, eta_rad: float = 0.0) -> SpringSlider:
    r"""The classic rate-and-state spring-slider (Eq. 7 with a state law of
    :mod:`rsf.state_laws`):

    .. math:: \mu = \mu_0 + a\ln(v/v_0) + b\ln(\theta v_0/D_c)
              \;[+\, b_2\ln(\theta_2 v_0/D_{c2})].

    Defaults are laboratory-like (SI units: m, s), as in rsfmodel's examples.

    Parameters
    ----------
    mu0 : float
        Friction at the reference velocity ``v0`` in steady state.
    a, b : float
        Direct-effect and evolution-effect coefficients, >= 0 (``a`` is also the model's
        direct effect).
    Dc : float
        Critical slip distance, > 0.
    k0 : float
        Spring stiffness (per unit normal stress), > 0.
    v0 : float
        Reference velocity, > 0.
    state_law : {'aging', 'slip', 'prz', 'nagata'}, StateLaw or callable
        The state evolution; see :class:`SpringSlider`.
    second_state : SecondState, optional
        A second state variable with its own ``b2`` and ``Dc2``.
    eta_rad : float
        Radiation damping, >= 0.

    Returns
    -------
    SpringSlider
        With ``law=LogLaw(mu0, a, b, v0)`` and the direct effect ``a``.

    Raises
    ------
    ValueError
        If a parameter is out of range or the combination is refused by
        :class:`SpringSlider` (for instance ``a = 0`` with a state law other than aging).

    Examples
    --------
    >>> import rsf
    >>> cv = rsf.critical_velocity(rsf.standard_rs(b=0.025))   # b - a > k0 Dc = 0.01
    >>> cv.Vc, cv.status
    (inf, 'unstable at large V')
    """
    return SpringSlider(law=LogLaw(mu0=mu0, a=a, b=b, v0=v0), k0=k0, Dc=Dc, a=a,
                        state_law=state_law, second_state=second_state, eta_rad=eta_rad)


@dataclass(frozen=True, eq=False)
class Protocol:
    r"""Load-point velocity history :math:`V(t)`.

    With ``interpolation='previous'`` (default) it is piecewise constant:
    ``velocities[i]`` from ``times[i]`` to ``times[i + 1]`` (the last one forever); with
    ``'linear'`` it is the piecewise-linear interpolation of the samples (constant after
    the last one), a sampled history.  ``times[0]`` must be 0.

    Build it with :meth:`constant`, :meth:`velocity_steps`, :meth:`slide_hold_slide` or
    :meth:`sampled`.

    Parameters
    ----------
    times : array_like
        Sample times, finite and strictly increasing, starting at 0.
    velocities : array_like
        Load-point velocities at those times, finite and >= 0, as many as ``times``.
    interpolation : {'previous', 'linear'}
        Piecewise-constant steps (default) or linear interpolation between the samples
        (needs a direct effect :math:`a > 0` in :func:`~rsf.simulate`).

    Raises
    ------
    ValueError
        If ``times`` and ``velocities`` are empty or of different lengths, ``times[0]`` is
        not 0, the times are not finite and strictly increasing, a velocity is negative or
        not finite, or ``interpolation`` is neither 'previous' nor 'linear'.

    Examples
    --------
    >>> import rsf
    >>> shs = rsf.Protocol.slide_hold_slide(1.0, slide_time=10.0, hold_time=100.0)
    >>> shs.velocity_at(50.0), shs.velocity_at(120.0), float(shs.load_point(120.0))
    (0.0, 1.0, 20.0)
    """

    times: np.ndarray
    velocities: np.ndarray
    interpolation: str = "previous"

    def __post_init__(self) -> None:
        times = np.atleast_1d(np.asarray(self.times, dtype=float)).copy()
        vel = np.atleast_1d(np.asarray(self.velocities, dtype=float)).copy()
        if times.size != vel.size or times.size == 0:
            raise ValueError(f"times and velocities must be non-empty and of equal length, got "
                             f"{times.size} and {vel.size}")
        if times[0] != 0.0:
            raise ValueError(f"times[0] must be 0, got {float(times[0])!r}")
        bad = ~np.isfinite(times)
        bad[1:] |= ~(np.diff(times) > 0.0)
        if np.any(bad):
            i = int(np.argmax(bad))
            raise ValueError(f"times must be finite and strictly increasing: item {i + 1} of "
                             f"{times.size} is {float(times[i])!r}"
                             + (f", after {float(times[i - 1])!r}" if i > 0 else ""))
        bad = ~np.isfinite(vel) | (vel < 0.0)
        if np.any(bad):
            i = int(np.argmax(bad))
            raise ValueError(f"velocities must be finite and >= 0: item {i + 1} of {vel.size} "
                             f"is {float(vel[i])!r}")
        choice("interpolation", self.interpolation, ("previous", "linear"))
        times.setflags(write=False)
        vel.setflags(write=False)
        object.__setattr__(self, "times", times)
        object.__setattr__(self, "velocities", vel)
        # load-point displacement at each sample time
        dt = np.diff(times)
        if self.interpolation == "linear":
            steps = 0.5 * dt * (vel[:-1] + vel[1:])
        else:
            steps = dt * vel[:-1]
        xs = np.concatenate([[0.0], np.cumsum(steps)])
        xs.setflags(write=False)
        object.__setattr__(self, "_x_at_times", xs)

    @classmethod
    def sampled(cls, times: Sequence[float], velocities: Sequence[float]) -> Protocol:
        r"""A sampled history :math:`V(t)`: linear between the samples (``times[0] = 0``,
        strictly increasing; velocities >= 0), constant after the last one.  The load
        point :math:`X(t) = \int_0^t V` is then exact (piecewise quadratic)."""
        return cls(np.asarray(times, dtype=float), np.asarray(velocities, dtype=float),
                   interpolation="linear")

    @property
    def is_linear(self) -> bool:
        """Whether V(t) ramps linearly between samples (a sampled history)."""
        return self.interpolation == "linear" and self.times.size > 1

    def slope_at(self, t: float) -> float:
        """dV/dt on the sample interval that starts at or before ``t`` (0 for steps)."""
        if not self.is_linear:
            return 0.0
        i = int(np.searchsorted(self.times, t, side="right")) - 1
        if i < 0 or i >= self.times.size - 1:
            return 0.0
        return float((self.velocities[i + 1] - self.velocities[i])
                     / (self.times[i + 1] - self.times[i]))

    @classmethod
    def constant(cls, V: float) -> Protocol:
        """Constant driving at ``V`` > 0."""
        return cls(np.array([0.0]), np.array([positive("V", V)]))

    @classmethod
    def velocity_steps(cls, velocities: Sequence[float], durations: Sequence[float]) -> Protocol:
        """Velocity ``velocities[i]`` for ``durations[i]`` (the last one until the end of the
        run; ``durations`` may have one entry fewer than ``velocities``)."""
        vel = [nonnegative(f"velocities[{i}]", v) for i, v in enumerate(velocities)]
        dur = [positive(f"durations[{i}]", d) for i, d in enumerate(durations)]
        if len(dur) not in (len(vel), len(vel) - 1) or not vel:
            raise ValueError("durations must have as many entries as velocities, or one fewer")
        times = np.concatenate([[0.0], np.cumsum(dur[: len(vel) - 1])])
        return cls(times, np.array(vel))

    @classmethod
    def slide_hold_slide(cls, V: float, slide_time: float, hold_time: float,
                         V_reload: float | None = None) -> Protocol:
        """Slide at ``V`` for ``slide_time``, hold (V = 0) for ``hold_time``, then slide at
        ``V_reload`` (default ``V``)."""
        V = positive("V", V)
        V2 = V if V_reload is None else positive("V_reload", V_reload)
        return cls.velocity_steps([V, 0.0, V2], [slide_time, positive("hold_time", hold_time)])

    def velocity_at(self, t: float) -> float:
        """The load-point velocity at time ``t`` (right-continuous)."""
        if self.times.size == 1:
            return float(self.velocities[0])
        if self.is_linear:
            return float(np.interp(t, self.times, self.velocities))
        i = int(np.searchsorted(self.times, t, side="right")) - 1
        return float(self.velocities[max(i, 0)])

    def segment_end(self, t: float) -> float:
        """The next change of velocity strictly after ``t`` (inf if none)."""
        if self.times.size == 1:
            return math.inf
        i = int(np.searchsorted(self.times, t, side="right"))
        return float(self.times[i]) if i < self.times.size else math.inf

    def load_point(self, t: float) -> float:
        r"""Load-point displacement :math:`X(t) = \int_0^t V\,\mathrm{d}t'`."""
        if self.times.size == 1:
            return float(self.velocities[0]) * float(t)
        i = int(np.searchsorted(self.times, t, side="right")) - 1
        i = max(i, 0)
        tau = t - self.times[i]
        x = float(self._x_at_times[i]) + float(self.velocities[i]) * tau   # type: ignore[attr-defined]
        if self.is_linear:
            x += 0.5 * self.slope_at(t) * tau * tau
        return float(x)

    @property
    def is_constant(self) -> bool:
        return self.times.size == 1


@dataclass(frozen=True)
class InitialState:
    r"""Initial state.  ``theta`` defaults to the steady state at the initial driving
    velocity times ``1 + perturbation``; ``sigma`` defaults to the threshold
    :math:`\phi(\theta)` (for :math:`a > 0`: the friction at :math:`v = V`); ``x`` is 0.

    Parameters
    ----------
    theta : float or None
        State variable, > 0.
    sigma : float or None
        Spring force (for :math:`a = 0`: must be finite; above the threshold the run starts
        with a slip).
    perturbation : float or None
        Relative offset of the default theta from steady state, > -1.  ``None`` (default):
        0 (the exact steady state) for :func:`~rsf.simulate` with a velocity-step,
        slide-hold-slide or sampled protocol, 1e-3 for constant driving and for the
        limit-cycle searches (:func:`~rsf.limit_cycle`, :func:`~rsf.sweep`), where the
        perturbation lets an unstable steady state depart.

    Raises
    ------
    ValueError
        If ``theta`` is not a finite number > 0, ``sigma`` is not a finite number, or
        ``perturbation`` is not a finite number > -1.
    """

    theta: float | None = None
    sigma: float | None = None
    perturbation: float | None = None

    #: The perturbation used when none is given and the run looks for an attractor.
    DEFAULT_PERTURBATION = 1e-3

    def resolved(self, perturbation: float) -> "InitialState":
        """A copy with ``perturbation`` set to the given default if it is None."""
        if self.perturbation is not None:
            return self
        return InitialState(theta=self.theta, sigma=self.sigma, perturbation=perturbation)

    def __post_init__(self) -> None:
        if self.theta is not None:
            object.__setattr__(self, "theta", positive("theta", self.theta))
        if self.sigma is not None:
            s = real("sigma", self.sigma)
            if not math.isfinite(s):
                raise ValueError(f"sigma must be a finite number, got {shown(self.sigma)}")
            object.__setattr__(self, "sigma", s)
        if self.perturbation is None:
            return
        pert = real("perturbation", self.perturbation)
        if not (math.isfinite(pert) and pert > -1.0):
            raise ValueError(f"perturbation must be a finite number > -1, got {shown(self.perturbation)}")
        object.__setattr__(self, "perturbation", pert)


@dataclass(frozen=True)
class SolverOptions:
    r"""Numerical settings.

    Parameters
    ----------
    rtol : float
        CVODE relative tolerance, in [1e-14, 1e-2] (default 1e-10).
    atol : float
        CVODE absolute tolerance relative to each variable's natural scale, in
        [1e-16, 1e-2] (default 1e-12).
    cycle_rtol : float
        Limit cycle converged when :math:`\sigma_{max}`, :math:`\sigma_{min}` and the period
        change by less than this (relative) from one cycle to the next; also the relative
        distance :math:`|\ln(u/V)|` at which a stable slide is declared steady.  In
        [1e-14, 1e-1], default 1e-8.
    max_cycles : int
        Give up (status ``max_cycles``) after this many cycles (default 20000).
    max_events : int
        Give up after this many events in one run (default 2,000,000).
    accelerate : bool
        Extrapolate the cycle-to-cycle map (Aitken) to skip slow transients; the convergence
        test is always made on two consecutive simulated cycles (default True).
    method : {'Adams', 'BDF'}
        CVODE method for the slide phases (default 'Adams'; the a > 0 ODE always uses BDF).
    max_num_steps : int
        CVODE steps allowed per output interval (default 1,000,000).
    v_max : float or None
        Runaway bound (:math:`a > 0`): a run stops with status ``RUNAWAY`` as soon as the
        slip velocity passes ``v_max``.  ``None`` (default): :math:`10^3 \max V` (the
        largest load-point velocity of the protocol) when the model has a
        :class:`~rsf.laws.LogLaw` (classical rate and state, where a slip this fast
        without radiation damping is a finite-time blow-up), no bound for the other laws
        (their weakening vanishes at high speed and slips at :math:`v/V \sim 10^{50}`
        still arrest).  Give ``math.inf`` to switch the bound off.
    max_rhs_evals : int
        Step budget: a run (one :func:`~rsf.simulate` or :func:`~rsf.limit_cycle` call)
        stops with status ``STEP_BUDGET`` after this many right-hand-side evaluations of
        CVODE in total (default 20,000,000, minutes of run time), so that no input hangs.

    Raises
    ------
    ValueError
        If a tolerance lies outside its range, a count is not an integer >= 1,
        ``accelerate`` is not a bool, ``method`` is neither 'Adams' nor 'BDF', or
        ``v_max`` is not a number > 0 (inf allowed).

    Examples
    --------
    >>> import rsf
    >>> rsf.SolverOptions(rtol=1e-8, cycle_rtol=1e-6).max_cycles
    20000
    """

    rtol: float = 1e-10
    atol: float = 1e-12
    cycle_rtol: float = 1e-8
    max_cycles: int = 20000
    max_events: int = 2_000_000
    accelerate: bool = True
    method: str = "Adams"
    max_num_steps: int = 1_000_000
    v_max: float | None = None
    max_rhs_evals: int = 20_000_000

    def __post_init__(self) -> None:
        from ._validation import in_range

        object.__setattr__(self, "rtol", in_range("rtol", self.rtol, 1e-14, 1e-2))
        object.__setattr__(self, "atol", in_range("atol", self.atol, 1e-16, 1e-2))
        object.__setattr__(self, "cycle_rtol", in_range("cycle_rtol", self.cycle_rtol, 1e-14, 1e-1))
        object.__setattr__(self, "max_cycles", positive_int("max_cycles", self.max_cycles))
        object.__setattr__(self, "max_events", positive_int("max_events", self.max_events))
        object.__setattr__(self, "max_num_steps", positive_int("max_num_steps", self.max_num_steps))
        if not isinstance(self.accelerate, bool):
            raise ValueError(f"accelerate must be True or False, got {self.accelerate!r}")
        choice("method", self.method, ("Adams", "BDF"))
        if self.v_max is not None:
            v_max = _as_positive_or_inf("v_max", self.v_max)
            object.__setattr__(self, "v_max", v_max)
        object.__setattr__(self, "max_rhs_evals", positive_int("max_rhs_evals", self.max_rhs_evals))


def _as_positive_or_inf(name: str, value: object) -> float:
    try:
        result = real(name, value)
    except ValueError:
        raise ValueError(f"{name} must be a number > 0 (or inf), got {shown(value)}") from None
    if not result > 0.0:   # also rejects nan
        raise ValueError(f"{name} must be a number > 0 (or inf), got {shown(value)}")
    return result
