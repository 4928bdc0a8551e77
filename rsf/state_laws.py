r"""State evolution laws :math:`\dot\theta = f(v, \theta)` for the rate-and-state slider
with a direct effect (:math:`a > 0`), and the optional second state variable.

Every law is written for the state variable normalised so that its steady state is
:math:`\theta_{ss} = D_c/v`; the friction is then

.. math::
    \mu = \mu_{ss}(D_c/\theta) + a\ln\frac{v\,\theta}{D_c}
    \quad\Big(= \mu_0 + a\ln\frac{v}{v_0} + b\ln\frac{v_0\theta}{D_c}
    \text{ for the log law, Eq. 7}\Big).

The solver integrates :math:`\ln\theta`; each law gives
:math:`\mathrm{d}\ln\theta/\mathrm{d}t`.  The laws: :class:`AgingLaw`
(Dieterich 1979; the paper's Eq. 8), :class:`SlipLaw` (Ruina 1983), :class:`PRZLaw`
(Perrin, Rice & Zheng 1995), :class:`NagataLaw` (Nagata et al. 2012) and
:class:`CallableStateLaw` (any :math:`f(v, \theta)`).  :class:`SecondState` adds
:math:`b_2\ln(v_0\theta_2/D_{c2})` to the friction (two state variables, as rsfmodel).
"""
from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Callable

from ._validation import choice, nonnegative, positive

__all__ = ["StateLaw", "AgingLaw", "SlipLaw", "PRZLaw", "NagataLaw", "CallableStateLaw",
           "SecondState", "state_law_from"]

# codes understood by rsf._kernels.rs_rhs
AGING, SLIP, PRZ, NAGATA, USER = 0, 1, 2, 3, 4


class StateLaw:
    r"""Base class: a state evolution law (see the module docstring).

    Not used directly: :class:`~rsf.params.SpringSlider` takes a subclass, its name, or a
    callable as ``state_law``.  Each law has a ``name``, the ``code`` the kernels
    understand, and :meth:`rate`, :math:`\mathrm{d}\theta/\mathrm{d}t` in plain Python.

    See Also
    --------
    AgingLaw, SlipLaw, PRZLaw, NagataLaw, CallableStateLaw
    """

    name: str = "state"
    code: int = -1

    def rate(self, v: float, theta: float, Dc: float) -> float:
        r""":math:`\mathrm{d}\theta/\mathrm{d}t` at slip rate ``v`` and state ``theta``
        (plain Python, for checks and the user law)."""
        raise NotImplementedError

    def describe(self) -> dict[str, float | str]:
        return {"state_law": self.name}


@dataclass(frozen=True)
class AgingLaw(StateLaw):
    r"""Dieterich's aging (slowness) law, the paper's Eq. (8):

    .. math:: \dot\theta = 1 - \frac{v\theta}{D_c}.

    It takes no parameters; ``state_law='aging'`` is the same.

    References
    ----------
    Dieterich, J. H. (1979), J. Geophys. Res. 84(B5), 2161-2168.

    Examples
    --------
    >>> from rsf.state_laws import AgingLaw
    >>> AgingLaw().rate(v=2.0, theta=0.03, Dc=0.06)     # steady at theta = Dc / v
    0.0
    """

    name = "aging"
    code = AGING

    def rate(self, v: float, theta: float, Dc: float) -> float:
        return 1.0 - v * theta / Dc


@dataclass(frozen=True)
class SlipLaw(StateLaw):
    r"""Ruina's slip law:

    .. math:: \dot\theta = -\frac{v\theta}{D_c}\ln\frac{v\theta}{D_c}.

    It takes no parameters; ``state_law='slip'`` is the same.  It needs a direct effect
    :math:`a > 0`.

    References
    ----------
    Ruina, A. (1983), J. Geophys. Res. 88(B12), 10359-10370.
    """

    name = "slip"
    code = SLIP

    def rate(self, v: float, theta: float, Dc: float) -> float:
        x = v * theta / Dc
        return -x * math.log(x)


@dataclass(frozen=True)
class PRZLaw(StateLaw):
    r"""The Perrin-Rice-Zheng law, with its state :math:`\theta_{PRZ} = 2\theta`:

    .. math::
        \dot\theta_{PRZ} = 1 - \Big(\frac{v\,\theta_{PRZ}}{2D_c}\Big)^2,
        \qquad \mu = \mu_0 + a\ln\frac{v}{v_0} + b\ln\frac{v_0\theta_{PRZ}}{2D_c}

    (the friction as in rsfmodel).  rsf integrates and reports
    :math:`\theta = \theta_{PRZ}/2`, whose steady state is :math:`D_c/v` as for the other
    laws: :math:`\dot\theta = \tfrac12\,[1 - (v\theta/D_c)^2]`.

    It takes no parameters; ``state_law='prz'`` is the same.  It needs a direct effect
    :math:`a > 0`.

    References
    ----------
    Perrin, G., Rice, J. R. & Zheng, G. (1995), J. Mech. Phys. Solids 43(9), 1461-1495.
    """

    name = "prz"
    code = PRZ

    def rate(self, v: float, theta: float, Dc: float) -> float:
        return 0.5 * (1.0 - (v * theta / Dc) ** 2)


@dataclass(frozen=True)
class NagataLaw(StateLaw):
    r"""Nagata's law: aging with a stress-rate term,

    .. math:: \dot\theta = 1 - \frac{v\theta}{D_c} - \frac{c}{b}\,\theta\,\dot\mu,

    with :math:`\dot\mu` the rate of the friction (quasi-static:
    :math:`\dot\mu = k_0(V - v)`; with radiation damping
    :math:`\dot\mu = k_0(V - v) - \eta_{rad}\dot v`).

    Parameters
    ----------
    c : float
        Stress-weakening coefficient, >= 0 (Nagata et al. found c of about 2).
    b : float or None
        The evolution effect :math:`b` in :math:`c/b`, > 0; None: the model's
        :class:`~rsf.laws.LogLaw` ``b`` (then the model must have a log law).

    Raises
    ------
    ValueError
        If ``c`` is negative or not finite, or ``b`` is given and not a finite number > 0.

    References
    ----------
    Nagata, K., Nakatani, M. & Yoshida, S. (2012), J. Geophys. Res. 117, B02314.
    """

    c: float = 2.0
    b: float | None = None
    name = "nagata"
    code = NAGATA

    def __post_init__(self) -> None:
        object.__setattr__(self, "c", nonnegative("c", self.c))
        if self.b is not None:
            object.__setattr__(self, "b", positive("b", self.b))

    def rate(self, v: float, theta: float, Dc: float, mu_rate: float = 0.0,
             b: float | None = None) -> float:
        bb = self.b if self.b is not None else b
        return 1.0 - v * theta / Dc - self.c / bb * theta * mu_rate

    def describe(self) -> dict[str, float | str]:
        return {"state_law": self.name, "nagata_c": self.c}


@dataclass(frozen=True, eq=False)
class CallableStateLaw(StateLaw):
    r"""Any law :math:`\dot\theta = f(v, \theta)`, a Python function of two floats.

    It must have its steady state at :math:`\theta = D_c/v` (the friction law assumes it)
    and is evaluated in plain Python at every step (slower than the built-in laws).

    Parameters
    ----------
    func : callable
        ``func(v, theta) -> dtheta/dt``.
    name : str
        Its name in tables (default ``'user'``).

    Raises
    ------
    ValueError
        If ``func`` is not callable, or ``func(1.0, 1.0)`` fails or is not finite.
        (:class:`~rsf.params.SpringSlider` also checks that the steady state is
        :math:`\theta = D_c/v`.)

    Examples
    --------
    >>> import rsf
    >>> law = rsf.CallableStateLaw(lambda v, theta: 1.0 - v * theta / 0.06, name="aging, by hand")
    >>> model = rsf.SpringSlider(rsf.LogLaw(), k0=0.01, Dc=0.06, state_law=law)
    """

    func: Callable[[float, float], float] = field(default=None)  # type: ignore[assignment]
    name: str = "user"
    code = USER

    def __post_init__(self) -> None:
        if not callable(self.func):
            raise ValueError(f"func must be a callable f(v, theta) -> dtheta/dt, got {self.func!r}")
        try:
            value = float(self.func(1.0, 1.0))
        except Exception as exc:  # noqa: BLE001 - report any failure of the user's code
            raise ValueError(f"func(1.0, 1.0) failed: {exc!r}") from None
        if not math.isfinite(value):
            raise ValueError(f"func(1.0, 1.0) must be a finite number, got {value!r}")

    def rate(self, v: float, theta: float, Dc: float) -> float:
        return float(self.func(v, theta))


_BY_NAME = {"aging": AgingLaw, "slip": SlipLaw, "prz": PRZLaw, "nagata": NagataLaw}


def state_law_from(value: object) -> StateLaw:
    """A :class:`StateLaw` from a name ('aging', 'slip', 'prz', 'nagata'), a StateLaw, or a
    callable ``f(v, theta)``."""
    if isinstance(value, StateLaw):
        return value
    if isinstance(value, str):
        choice("state_law", value, tuple(_BY_NAME))
        return _BY_NAME[value]()
    if callable(value):
        return CallableStateLaw(value)
    raise ValueError(f"state_law must be one of 'aging', 'slip', 'prz', 'nagata', a StateLaw or "
                     f"a callable f(v, theta), got {value!r}")


@dataclass(frozen=True)
class SecondState:
    r"""A second state variable :math:`\theta_2` (log law only), evolving by the same
    law as the first with its own :math:`D_{c2}`:

    .. math:: \mu = \mu_0 + a\ln\frac{v}{v_0} + b_1\ln\frac{v_0\theta_1}{D_{c1}}
              + b_2\ln\frac{v_0\theta_2}{D_{c2}}.

    Parameters
    ----------
    b2 : float
        Its evolution effect, > 0.
    Dc2 : float
        Its critical slip distance, > 0.

    Raises
    ------
    ValueError
        If ``b2`` or ``Dc2`` is not a finite number > 0.

    Examples
    --------
    >>> import rsf
    >>> model = rsf.standard_rs(second_state=rsf.SecondState(b2=0.005, Dc2=1e-4))
    """

    b2: float
    Dc2: float

    def __post_init__(self) -> None:
        object.__setattr__(self, "b2", positive("b2", self.b2))
        object.__setattr__(self, "Dc2", positive("Dc2", self.Dc2))
