"""What the user sets: the model's constants and the distribution of pinning distances.

Both are small frozen dataclasses that validate themselves on construction, so that a
bad parameter fails at once and names itself.
"""
from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Callable

import numpy as np

__all__ = [
    "JumpDistribution",
    "Exponential",
    "Deterministic",
    "Tabulated",
    "Model",
]

# Integer codes that the numba kernels dispatch on.
KIND_EXPONENTIAL = 0
KIND_DETERMINISTIC = 1
KIND_TABULATED = 2


def _require(condition: bool, message: str) -> None:
    if not condition:
        raise ValueError(message)


def _number(name: str, value) -> float:
    """``value`` as a float, or one ValueError naming it: a bool (an int to Python) or a
    string is not a number here."""
    if isinstance(value, (bool, str, bytes)) or not isinstance(value, (int, float)) and not hasattr(value, "__float__"):
        shown = value.item() if isinstance(value, np.generic) else value   # 'x', not np.str_('x')
        raise ValueError(f"{name} must be a number, got {shown!r}")
    return float(value)


def _finite_positive(name: str, value: float, high: float = math.inf) -> float:
    value = _number(name, value)
    if high < math.inf:
        _require(math.isfinite(value) and 0.0 < value <= high, f"{name} must be in (0, {high:g}], got {value:g}")
    _require(math.isfinite(value) and value > 0.0, f"{name} must be a finite number > 0, got {value:g}")
    return value


def _finite_nonnegative(name: str, value: float, high: float = math.inf) -> float:
    value = _number(name, value)
    if high < math.inf:
        _require(math.isfinite(value) and 0.0 <= value <= high, f"{name} must be in [0, {high:g}], got {value:g}")
    _require(math.isfinite(value) and value >= 0.0, f"{name} must be a finite number >= 0, got {value:g}")
    return value


#: Largest stiffness a Model accepts, in units of the threshold over a mean jump (f_th /
#: zbar = 10 for the paper's parameters): beyond it a mean jump changes the stress by more
#: than a thousand thresholds and every stress loses its meaning (k0 = 1e300 gave
#: sigma = -1e299 with converged=True).
STIFFNESS_MAX = 1e3


class JumpDistribution:
    """The distribution g(z) of distances z > 0 between consecutive pinning wells.

    Subclasses provide the cumulative distribution, its first two moments, a quantile
    function for sampling and a support bound.  ``kind`` is the integer code the numba
    kernels dispatch on.

    Not used directly: :class:`Model` takes one of its subclasses as ``jumps``.

    See Also
    --------
    Exponential, Deterministic, Tabulated
    """

    kind: int
    zbar: float

    def cdf(self, z: np.ndarray) -> np.ndarray:  # pragma: no cover - abstract
        raise NotImplementedError

    def quantile(self, u: np.ndarray) -> np.ndarray:  # pragma: no cover - abstract
        raise NotImplementedError

    @property
    def mean(self) -> float:  # pragma: no cover - abstract
        raise NotImplementedError

    @property
    def second_moment(self) -> float:  # pragma: no cover - abstract
        raise NotImplementedError

    @property
    def z_max(self) -> float:  # pragma: no cover - abstract
        """An upper bound of the support (where the remaining mass is below 1e-16)."""
        raise NotImplementedError

    @property
    def mean_residual(self) -> float:
        r"""The mean overshoot of a renewal process with these increments,
        :math:`\langle z^2\rangle / (2\langle z\rangle)`."""
        return self.second_moment / (2.0 * self.mean)

    def sample(self, rng: np.random.Generator, size: int | tuple[int, ...]) -> np.ndarray:
        """Draw pinning distances by inverting the cumulative distribution."""
        return self.quantile(rng.random(size))


@dataclass(frozen=True)
class Exponential(JumpDistribution):
    r"""Exponential distances with mean parameter ``zbar`` and an upper cutoff.

    .. math:: g(z) = \frac{1}{\bar z}\, e^{-z/\bar z}\, \Theta(z)\,\Theta(z_c - z) / (1 - e^{-z_c/\bar z})

    The paper (Appendix B) uses the cutoff :math:`z_c = 10`; the normalisation
    :math:`1 - e^{-z_c/\bar z}` is kept so that g is a probability density for any cutoff.

    Parameters
    ----------
    zbar : float
        The mean of the exponential before the cutoff, > 0 (default 0.1); the
        distribution's ``mean`` is below it by the cut tail (equal to double precision
        for the default cutoff).
    cutoff : float
        Largest distance :math:`z_c`, finite and > ``zbar`` (default 10).

    Raises
    ------
    ValueError
        If ``zbar`` is not a finite number > 0, or ``cutoff`` is not finite and > ``zbar``.

    Examples
    --------
    >>> from micro import Exponential
    >>> g = Exponential(0.1)
    >>> round(g.mean, 12), round(g.mean_residual, 12)     # <z^2> / (2 <z>) = zbar
    (0.1, 0.1)
    """

    zbar: float = 0.1
    cutoff: float = 10.0
    kind: int = field(default=KIND_EXPONENTIAL, init=False, repr=False)

    def __post_init__(self) -> None:
        _finite_positive("zbar", self.zbar)
        _require(
            math.isfinite(float(self.cutoff)) and float(self.cutoff) > float(self.zbar),
            f"cutoff must be a finite number > zbar = {self.zbar!r}, got {self.cutoff!r}",
        )

    @property
    def _norm(self) -> float:
        return -math.expm1(-self.cutoff / self.zbar)

    def cdf(self, z):
        z = np.clip(np.asarray(z, dtype=float), 0.0, self.cutoff)
        return -np.expm1(-z / self.zbar) / self._norm

    def quantile(self, u):
        u = np.asarray(u, dtype=float)
        return -self.zbar * np.log1p(-u * self._norm)

    @property
    def mean(self) -> float:
        c, b = self.cutoff, self.zbar
        tail = math.exp(-c / b)
        return (b - (c + b) * tail) / self._norm

    @property
    def second_moment(self) -> float:
        c, b = self.cutoff, self.zbar
        tail = math.exp(-c / b)
        return (2.0 * b * b - (c * c + 2.0 * c * b + 2.0 * b * b) * tail) / self._norm

    @property
    def z_max(self) -> float:
        return min(self.cutoff, self.zbar * 37.0)


@dataclass(frozen=True)
class Deterministic(JumpDistribution):
    r"""All pinning wells at the same distance: :math:`g(z) = \delta(z - \bar z)`.

    Parameters
    ----------
    zbar : float
        The distance, > 0 (default 0.1).

    Raises
    ------
    ValueError
        If ``zbar`` is not a finite number > 0.
    """

    zbar: float = 0.1
    kind: int = field(default=KIND_DETERMINISTIC, init=False, repr=False)

    def __post_init__(self) -> None:
        _finite_positive("zbar", self.zbar)

    def cdf(self, z):
        return (np.asarray(z, dtype=float) >= self.zbar).astype(float)

    def quantile(self, u):
        return np.full(np.shape(u), self.zbar)

    @property
    def mean(self) -> float:
        return self.zbar

    @property
    def second_moment(self) -> float:
        return self.zbar * self.zbar

    @property
    def z_max(self) -> float:
        return self.zbar


@dataclass(frozen=True)
class Tabulated(JumpDistribution):
    """A distribution the user supplies as a density ``pdf`` on ``[0, z_max]``.

    The density is tabulated on ``n`` points, normalised, and its cumulative distribution
    and quantile function are built by the trapezoidal rule; ``zbar`` is its mean.

    Parameters
    ----------
    pdf : callable
        ``pdf(z) -> g(z)`` for an array ``z`` (vectorised), finite and >= 0 on
        ``[0, support_max]``; it need not be normalised.
    support_max : float
        Upper end of the support, > 0 (default 1).
    n : int
        Tabulation points, >= 17 (default 4097).

    Raises
    ------
    ValueError
        If ``pdf`` is not callable, returns an array of another shape, a negative or
        non-finite value, or no mass; ``support_max`` is not a finite number > 0; or
        ``n`` < 17.

    Examples
    --------
    >>> import numpy as np
    >>> from micro import Tabulated
    >>> g = Tabulated(lambda z: z * np.exp(-z / 0.05))    # a gamma density, mean 0.1
    >>> round(g.zbar, 5)
    0.1
    """

    pdf: Callable[[np.ndarray], np.ndarray] = field(repr=False, default=None)  # type: ignore[assignment]
    support_max: float = 1.0
    n: int = 4097
    kind: int = field(default=KIND_TABULATED, init=False, repr=False)
    zbar: float = field(init=False)
    _z: np.ndarray = field(init=False, repr=False, compare=False)
    _cdf: np.ndarray = field(init=False, repr=False, compare=False)

    def __post_init__(self) -> None:
        _require(callable(self.pdf), "pdf must be a callable returning g(z) >= 0 for an array z")
        _finite_positive("support_max", self.support_max)
        _require(int(self.n) >= 17, f"n must be an integer >= 17, got {self.n!r}")
        z = np.linspace(0.0, float(self.support_max), int(self.n))
        g = np.asarray(self.pdf(z), dtype=float)
        _require(g.shape == z.shape, "pdf must return an array of the same shape as its argument")
        _require(bool(np.all(np.isfinite(g))) and bool(np.all(g >= 0.0)), "pdf must be finite and >= 0 on [0, support_max]")
        cdf = np.concatenate([[0.0], np.cumsum(0.5 * (g[1:] + g[:-1]) * np.diff(z))])
        _require(cdf[-1] > 0.0, "pdf must have positive mass on [0, support_max]")
        cdf /= cdf[-1]
        object.__setattr__(self, "_z", z)
        object.__setattr__(self, "_cdf", cdf)
        object.__setattr__(self, "zbar", float(self.mean))

    def cdf(self, z):
        return np.interp(np.asarray(z, dtype=float), self._z, self._cdf, left=0.0, right=1.0)

    def quantile(self, u):
        # The cumulative distribution may be flat where g vanishes: interpolate on its
        # strictly increasing part.
        keep = np.concatenate([[True], np.diff(self._cdf) > 0.0])
        return np.interp(np.asarray(u, dtype=float), self._cdf[keep], self._z[keep])

    @property
    def mean(self) -> float:
        # E[z] = integral of (1 - F)
        s = 1.0 - self._cdf
        return float(np.sum(0.5 * (s[1:] + s[:-1]) * np.diff(self._z)))

    @property
    def second_moment(self) -> float:
        # E[z^2] = integral of 2 z (1 - F)
        s = 2.0 * self._z * (1.0 - self._cdf)
        return float(np.sum(0.5 * (s[1:] + s[:-1]) * np.diff(self._z)))

    @property
    def z_max(self) -> float:
        return float(self.support_max)


@dataclass(frozen=True)
class Model:
    r"""The mean-field viscoelastic depinning model, Eqs. (1)-(2) of Landes, Rosso & Jagla (2015).

    .. math::
        \eta_0 \partial_t h_i &= k_0 (w - h_i) + (k_1 + k_2)(\bar h - h_i) - k_2 u_i + f_i^{dis}(h_i) \\
        \eta_u \partial_t u_i &= k_2 (\bar h - h_i) - k_2 u_i

    in the narrow-wells limit with a constant threshold ``f_th`` and pinning distances
    drawn from ``jumps``; avalanches are instantaneous (:math:`\tau_0 \to 0`).

    Parameters
    ----------
    k0 : float
        Driving-spring stiffness, in (0, 1e3 f_th / zbar] (1e4 for the paper's parameters),
        and small enough that fast steady sliding keeps a positive friction:
        :math:`f^{th} - (k_0 + k_1 + k_2)\langle z^2\rangle/(2\langle z\rangle) > 0` (Eq. 6;
        k0 < 9 for the paper's parameters).
    k1 : float
        Elastic coupling between blocks, in [0, 1e3 f_th / zbar] (default 0.1).
    k2 : float
        Stiffness of the viscoelastic (spring + dashpot) coupling, in [0, 1e3 f_th / zbar]
        (default 0.9).
    eta_u : float
        Dashpot viscosity, > 0 (default 1); the relaxation rate is ``gamma = k2 / eta_u``.
    f_th : float
        Pinning threshold, > 0 (default 1).
    jumps : JumpDistribution
        Distribution of pinning distances; default exponential with mean 0.1 and cutoff 10
        (the paper's Fig. 4 parameters).

    Raises
    ------
    ValueError
        If ``jumps`` is not a :class:`JumpDistribution`, a constant is not a number (a
        bool or a string is refused) or lies outside its range, or the steady friction at
        :math:`V \to \infty` is not positive (the message names ``k0``, or ``zbar`` where
        no stiffness would do).

    Examples
    --------
    >>> import micro
    >>> model = micro.Model(k0=0.1)
    >>> round(model.kappa, 12), model.gamma, round(model.zbar, 12)
    (1.1, 0.9, 0.1)
    """

    k0: float
    k1: float = 0.1
    k2: float = 0.9
    eta_u: float = 1.0
    f_th: float = 1.0
    jumps: JumpDistribution = field(default_factory=lambda: Exponential(0.1, 10.0))

    def __post_init__(self) -> None:
        _require(
            isinstance(self.jumps, JumpDistribution),
            f"jumps must be a JumpDistribution (Exponential, Deterministic or Tabulated), got {type(self.jumps).__name__}",
        )
        object.__setattr__(self, "f_th", _finite_positive("f_th", self.f_th))
        top = STIFFNESS_MAX * self.f_th / float(self.jumps.mean)
        object.__setattr__(self, "k0", _finite_positive("k0", self.k0, top))
        object.__setattr__(self, "k1", _finite_nonnegative("k1", self.k1, top))
        object.__setattr__(self, "k2", _finite_nonnegative("k2", self.k2, top))
        object.__setattr__(self, "eta_u", _finite_positive("eta_u", self.eta_u))
        self._check_positive_friction()

    def _check_positive_friction(self) -> None:
        r"""The steady stress at :math:`V \to \infty`, :math:`f^{th} - \kappa \langle z^2\rangle /
        (2\langle z\rangle)` (Eq. (6) of the paper for equal jumps, where the mean residual is
        :math:`\bar z/2`; :func:`micro.analytic.sigma_fast_limit`), is the lowest steady
        friction: it must be > 0, else fast steady sliding has a negative friction."""
        residual = float(self.jumps.mean_residual)
        if self.f_th - self.kappa * residual > 0.0:
            return
        sigma = self.f_th - self.kappa * residual
        k0_max = self.f_th / residual - self.k1 - self.k2
        where = (f"(the steady stress at V -> infinity, f_th - (k0 + k1 + k2) <z^2>/(2<z>), Eq. 6, must be > 0; "
                 f"it is {sigma:g} with f_th = {self.f_th:g}, k0 = {self.k0:g}, k1 = {self.k1:g}, k2 = {self.k2:g}, "
                 f"zbar = {self.jumps.zbar:g}, <z^2>/(2<z>) = {residual:g})")
        if k0_max > 0.0:
            raise ValueError(f"k0 must be < {k0_max:g} {where}")
        # no stiffness helps: the jumps are too long for the threshold
        zbar_max = self.jumps.zbar * (self.f_th / self.kappa) / residual
        raise ValueError(f"zbar must be < {zbar_max:g} for these couplings {where}")

    @property
    def kappa(self) -> float:
        """Total stiffness seen by a block that jumps, ``k0 + k1 + k2``."""
        return self.k0 + self.k1 + self.k2

    @property
    def gamma(self) -> float:
        """Viscoelastic relaxation rate ``k2 / eta_u`` (inverse of the paper's tau_u)."""
        return self.k2 / self.eta_u

    @property
    def zbar(self) -> float:
        """Mean pinning distance of ``jumps``."""
        return self.jumps.mean
