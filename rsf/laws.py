r"""Steady-state friction laws :math:`\mu_{ss}(v)`.

A law gives the friction of steady sliding at velocity :math:`v`.  The paper's
rate-and-state description (Sec. V.B) turns it into a state-dependent friction through
Eq. (11), :math:`\mu(\theta) = \mu_{ss}(D_c/\theta)`.  Every law offers

* ``mu_ss(v)`` and ``dmu_ss(v)`` (numpy, vectorised),
* ``weakening(v)`` :math:`= W(v) = -v\,\mathrm{d}\mu_{ss}/\mathrm{d}v` (positive where the
  law is velocity weakening; the stability of steady sliding is decided by :math:`W`),
* ``kernel_params`` — the float array ``p`` (law code and parameters) that the solver's
  numba kernels evaluate as ``law_eval(v, p) -> (mu_ss - mu_ref, W)``, and ``kernels()``,
  the kernel set to use; ``mu_ref`` is a constant reference level (the large-velocity
  limit where it exists), subtracted so that frictions just above it keep full relative
  precision,
* ``bind(k0)`` — a copy with the defaults that depend on the driving stiffness resolved.

The laws: :class:`HyperbolicLaw` (Eq. 10), :class:`ViscoelasticLaw` (Eq. 4),
:class:`LogLaw` (Eq. 9, the standard rate-and-state law), :class:`TabulatedLaw` (data,
for instance a sweep of the microscopic model) and :class:`CallableLaw` (any function
with its derivative).
"""
from __future__ import annotations

import ast
import logging
import math
import operator
from dataclasses import dataclass, field, replace
from functools import cached_property
from pathlib import Path
from typing import Callable

import numpy as np

from . import _kernels
from ._validation import finite, nonnegative, positive

__all__ = [
    "SteadyStateLaw",
    "HyperbolicLaw",
    "ViscoelasticLaw",
    "LogLaw",
    "TabulatedLaw",
    "CallableLaw",
    "paper_mu_inf",
    "select_rows",
    "PAPER_A",
    "PAPER_B",
    "PAPER_DC",
]

logger = logging.getLogger(__name__)

#: Eq. (10) constants of the paper (fit for k1 = 0.1, k2 = 0.9, zbar = 0.1).
PAPER_A = 0.007
PAPER_B = 0.078
#: The critical slip distance the paper uses for Fig. 8.
PAPER_DC = 0.06
#: Above this stiffness the paper's friction at large velocity, 0.95 - 0.05 k0 (Eq. 6 with
#: its constants), is negative: the default mu_inf of HyperbolicLaw and the
#: ViscoelasticLaw with its default constants refuse k0 >= 19.
PAPER_K0_MAX = 19.0


def paper_mu_inf(k0: float, f_th: float = 1.0, zbar: float = 0.1, k1: float = 0.1,
                 k2: float = 0.9) -> float:
    r"""The offset of Eq. (10): the large-velocity friction of Eq. (6),

    .. math:: \mu_\infty = f^{th} - \frac{\bar z}{2}(k_0 + k_1 + k_2).

    With the paper's constants (:math:`f^{th} = 1`, :math:`\bar z = 0.1`, :math:`k_1 = 0.1`,
    :math:`k_2 = 0.9`) this is :math:`0.95 - 0.05\,k_0`.

    Parameters
    ----------
    k0 : float
        Driving stiffness, >= 0.
    f_th : float
        Pinning threshold, finite (paper: 1).
    zbar : float
        Mean well spacing, > 0 (paper: 0.1).
    k1, k2 : float
        Elastic and viscoelastic couplings, >= 0 (paper: 0.1, 0.9).

    Returns
    -------
    float
        :math:`\mu_\infty` (it may be negative for a stiff spring; :class:`HyperbolicLaw`
        refuses that).

    Raises
    ------
    ValueError
        If a parameter is out of its range.

    Examples
    --------
    >>> from rsf.laws import paper_mu_inf
    >>> paper_mu_inf(0.1)
    0.945
    """
    nonnegative("k0", k0)
    return finite("f_th", f_th) - 0.5 * positive("zbar", zbar) * (
        k0 + nonnegative("k1", k1) + nonnegative("k2", k2))


def _as_velocity_array(v: object) -> np.ndarray:
    arr = np.asarray(v, dtype=float)
    if np.any(~np.isfinite(arr)) or np.any(arr < 0.0):
        raise ValueError("v must be finite velocities >= 0")
    return arr


class SteadyStateLaw:
    """Base class of the steady-state laws (see the module docstring).

    Not used directly: a law is one of its subclasses, which :class:`~rsf.params.SpringSlider`
    takes as ``law``.  Every law has the numpy methods :meth:`mu_ss`, :meth:`dmu_ss` and
    :meth:`weakening` (velocities >= 0, vectorised; a negative or non-finite velocity
    raises ValueError) and the solver's interface (``kernel_params``, :meth:`kernels`,
    ``mu_ref``, :meth:`bind`).

    See Also
    --------
    HyperbolicLaw, ViscoelasticLaw, LogLaw, TabulatedLaw, CallableLaw
    """

    #: A short name used in tables and logs.
    name: str = "law"

    # -- numpy interface ----------------------------------------------------------------
    def mu_ss(self, v: np.ndarray | float) -> np.ndarray:
        r"""Steady-state friction :math:`\mu_{ss}(v)`."""
        raise NotImplementedError

    def dmu_ss(self, v: np.ndarray | float) -> np.ndarray:
        r"""Derivative :math:`\mathrm{d}\mu_{ss}/\mathrm{d}v`."""
        raise NotImplementedError

    def weakening(self, v: np.ndarray | float) -> np.ndarray:
        r"""Velocity-weakening rate :math:`W(v) = -v\,\mathrm{d}\mu_{ss}/\mathrm{d}v`."""
        v = _as_velocity_array(v)
        return -v * self.dmu_ss(v)

    # -- solver interface ---------------------------------------------------------------
    @property
    def kernel_params(self) -> np.ndarray:
        """``p`` for ``_kernels.law_eval(v, p) -> (mu_ss - mu_ref, W)``: the law's code then
        its parameters."""
        raise NotImplementedError

    def kernels(self) -> dict[str, Callable]:
        """The kernel set (name -> function) that evaluates this law: the module's cached
        numba kernels for the built-in laws."""
        return {name: getattr(_kernels, name) for name in _kernels.KERNEL_NAMES}

    @property
    def mu_ref(self) -> float:
        """The constant that the kernels subtract from the friction."""
        return 0.0

    @property
    def jitted(self) -> bool:
        """Whether the kernels are numba-compiled (else the solver runs pure Python)."""
        return True

    @property
    def concave_sup(self) -> float:
        r"""NaN unless :math:`\phi(\theta) = \mu_{ss}(D_c/\theta)` is concave in
        :math:`\theta` (equivalently :math:`v W(v)` non-decreasing); then
        :math:`\sup_v \mu_{ss} - \mu_{ref}` (inf if unbounded).  Lets the stick search
        bracket its root directly."""
        return math.nan

    def weakening_bounds(self) -> tuple[float, float]:
        r"""Lower and upper bounds of :math:`W(v)` over :math:`v > 0` (used only to size
        safe steps of the root searches)."""
        raise NotImplementedError

    def bind(self, k0: float) -> SteadyStateLaw:
        """A copy with the defaults that depend on the driving stiffness ``k0`` resolved."""
        return self

    @property
    def is_bound(self) -> bool:
        """Whether every parameter is set (``bind`` has nothing left to resolve)."""
        return True

    def describe(self) -> dict[str, float | str]:
        """The law's parameters as a flat dict (for tables and CSV files)."""
        return {"law": self.name}


def _require_bound(law: SteadyStateLaw) -> None:
    if not law.is_bound:
        raise ValueError(f"{law!r} depends on the driving stiffness k0; call .bind(k0) first "
                         "(SpringSlider does this for you)")


# --------------------------------------------------------------------------------------
@dataclass(frozen=True)
class HyperbolicLaw(SteadyStateLaw):
    r"""The paper's fit, Eq. (10):

    .. math:: \mu_{ss}(v) = \mu_\infty + \frac{A}{v + B},
              \qquad W(v) = \frac{A v}{(v + B)^2} \le \frac{A}{4B}.

    Parameters
    ----------
    A : float
        Amplitude, >= 0 (paper: 0.007).
    B : float
        Velocity scale, > 0 (paper: 0.078).
    mu_inf : float or None
        Large-velocity friction, finite and >= 0.  ``None`` means the paper's value for the driving stiffness,
        :math:`\mu_\infty = f^{th} - \bar z (k_0 + k_1 + k_2)/2` (:func:`paper_mu_inf`),
        resolved by :meth:`bind` (which :class:`~rsf.params.SpringSlider` calls).

    Raises
    ------
    ValueError
        If ``A`` is negative, ``B`` is not a finite number > 0 or ``mu_inf`` is not a finite
        number >= 0;
        :meth:`bind` if the default ``mu_inf`` is not positive (k0 >= 19).

    Examples
    --------
    >>> from rsf.laws import HyperbolicLaw
    >>> law = HyperbolicLaw().bind(0.1)             # mu_inf = 0.95 - 0.05 k0 = 0.945
    >>> round(float(law.mu_ss(1.0)), 6)
    0.951494
    """

    A: float = PAPER_A
    B: float = PAPER_B
    mu_inf: float | None = None
    name: str = field(default="hyperbolic", init=False, repr=False)

    def __post_init__(self) -> None:
        object.__setattr__(self, "A", nonnegative("A", self.A))
        object.__setattr__(self, "B", positive("B", self.B))
        if self.mu_inf is not None:
            mu_inf = finite("mu_inf", self.mu_inf)
            if mu_inf < 0.0:   # Eq. (6): the friction of steady sliding at large V
                raise ValueError(f"mu_inf must be >= 0 (the friction at large V, Eq. 6; a negative "
                                 f"one pulls the block forward), got {mu_inf:g}")
            object.__setattr__(self, "mu_inf", mu_inf)

    def bind(self, k0: float) -> HyperbolicLaw:
        """The law with the default ``mu_inf`` resolved for ``k0``.  The default, the paper's
        :math:`0.95 - 0.05 k_0`, is a friction only while it is positive: ``k0`` >=
        ``PAPER_K0_MAX`` (19) is refused (give ``mu_inf`` for a stiffer spring)."""
        if self.mu_inf is not None:
            return self
        mu_inf = paper_mu_inf(k0)
        if not mu_inf > 0.0:
            raise ValueError(f"k0 must be < {PAPER_K0_MAX:g} with the default mu_inf = 0.95 - 0.05 k0, "
                             f"got k0 = {float(k0):g} (mu_inf = {mu_inf:g}, a negative friction); give "
                             f"mu_inf for a stiffer spring")
        return replace(self, mu_inf=mu_inf)

    @property
    def is_bound(self) -> bool:
        return self.mu_inf is not None

    def mu_ss(self, v):
        _require_bound(self)
        v = _as_velocity_array(v)
        return self.mu_inf + self.A / (v + self.B)

    def dmu_ss(self, v):
        v = _as_velocity_array(v)
        d = v + self.B
        return -self.A / d / d

    def weakening(self, v):
        v = _as_velocity_array(v)
        d = v + self.B
        return self.A * (v / d) / d

    @property
    def kernel_params(self):
        return np.array([_kernels.KIND_HYPERBOLIC, self.A, self.B], dtype=float)

    @property
    def mu_ref(self) -> float:
        _require_bound(self)
        return float(self.mu_inf)

    def weakening_bounds(self):
        return 0.0, self.A / (4.0 * self.B)

    @property
    def concave_sup(self) -> float:
        # v W = A v^2 / (v + B)^2 increases; sup mu_ss - mu_inf = A / B at v = 0
        return self.A / self.B

    def describe(self):
        return {"law": self.name, "A": self.A, "B": self.B, "mu_inf": self.mu_inf}


# --------------------------------------------------------------------------------------
@dataclass(frozen=True)
class ViscoelasticLaw(SteadyStateLaw):
    r"""The exact steady friction of the viscoelastic model, Eq. (4):

    .. math:: \mu_{ss}(v) = f^{th} - \left[v\eta_u - \frac{\bar z k_2}{e^{\bar z k_2/(v\eta_u)} - 1}\right]
              - \frac{\bar z}{2}(k_0 + k_1),

    bounded by Eq. (5) at :math:`v \to 0` and Eq. (6) at :math:`v \to \infty`.  With
    :math:`y = \bar z k_2/(v\eta_u)`: :math:`W(v) = \bar z k_2\,[1/y - y e^{y}/(e^{y}-1)^2]`.

    Parameters
    ----------
    f_th : float
        Pinning threshold, > 0 (paper: 1).
    zbar : float
        Mean well spacing, > 0 (paper: 0.1).
    k1 : float
        Elastic coupling, >= 0 (paper: 0.1).
    k2 : float
        Viscoelastic spring, > 0 (paper: 0.9).
    eta_u : float
        Dashpot viscosity, > 0 (paper: 1).
    k0 : float or None
        Driving stiffness entering the offset; ``None`` is resolved by :meth:`bind`.

    Raises
    ------
    ValueError
        If a parameter is out of its range, or ``k0`` makes the large-velocity friction
        :math:`f^{th} - \bar z(k_0 + k_1 + k_2)/2` non-positive.
    """

    f_th: float = 1.0
    zbar: float = 0.1
    k1: float = 0.1
    k2: float = 0.9
    eta_u: float = 1.0
    k0: float | None = None
    name: str = field(default="viscoelastic", init=False, repr=False)

    def __post_init__(self) -> None:
        object.__setattr__(self, "f_th", positive("f_th", self.f_th))
        object.__setattr__(self, "zbar", positive("zbar", self.zbar))
        object.__setattr__(self, "k1", nonnegative("k1", self.k1))
        object.__setattr__(self, "k2", positive("k2", self.k2))
        object.__setattr__(self, "eta_u", positive("eta_u", self.eta_u))
        if self.k0 is not None:
            object.__setattr__(self, "k0", nonnegative("k0", self.k0))
            if not self.mu_ref > 0.0:
                k0_max = 2.0 * self.f_th / self.zbar - self.k1 - self.k2
                if not k0_max > 0.0:   # no stiffness helps: blame the well spacing
                    raise ValueError(
                        f"zbar must be < 2 f_th / (k0 + k1 + k2) = "
                        f"{2.0 * self.f_th / (self.k0 + self.k1 + self.k2):g} for this law (f_th - zbar "
                        f"(k0 + k1 + k2)/2, the friction at large V, Eq. 6, must be > 0), got zbar = "
                        f"{self.zbar:g} with f_th = {self.f_th:g}, k0 = {self.k0:g}, k1 = {self.k1:g}, "
                        f"k2 = {self.k2:g}")
                raise ValueError(
                    f"k0 must be < {k0_max:g} for this law (f_th - zbar (k0 + k1 + k2)/2, the friction "
                    f"at large V, must be > 0), got k0 = {self.k0:g} (friction {self.mu_ref:g})")

    def bind(self, k0: float) -> ViscoelasticLaw:
        return self if self.k0 is not None else replace(self, k0=nonnegative("k0", k0))

    @property
    def is_bound(self) -> bool:
        return self.k0 is not None

    @property
    def offset(self) -> float:
        r""":math:`f^{th} - \bar z(k_0 + k_1)/2`, the friction at :math:`v \to 0` (Eq. 5)."""
        _require_bound(self)
        return self.f_th - 0.5 * self.zbar * (self.k0 + self.k1)

    def mu_ss(self, v):
        v = _as_velocity_array(v)
        c = self.zbar * self.k2
        with np.errstate(divide="ignore", over="ignore", invalid="ignore"):
            y = c / (v * self.eta_u)
            series = 0.5 - y / 12.0 + y ** 3 / 720.0 - y ** 5 / 30240.0 + y ** 7 / 1209600.0
            h = np.where(y < 0.05, series, 1.0 / y - 1.0 / np.expm1(np.clip(y, 0.05, 700.0)))
        h = np.where(v == 0.0, 0.0, h)
        return self.offset - c * h

    def dmu_ss(self, v):
        v = _as_velocity_array(v)
        c = self.zbar * self.k2
        with np.errstate(divide="ignore", over="ignore", invalid="ignore"):
            y = c / (v * self.eta_u)
            ym = np.minimum(y, 700.0)
            # d(mu)/dv = -c h'(y) dy/dv = c y h'(y) / v, with
            # y h'(y) = -1/y + y e^y/(e^y - 1)^2 = -1/y + y / (4 sinh^2(y/2))
            series = -y / 12.0 + y ** 3 / 240.0 - y ** 5 / 6048.0 + y ** 7 / 172800.0
            yc = np.maximum(ym, 0.05)
            yh = np.where(y < 0.05, series, -1.0 / yc + yc / (4.0 * np.sinh(0.5 * yc) ** 2))
            out = c * yh / v
        return np.where((v == 0.0) | (y > 700.0), np.where(v == 0.0, 0.0, -c / (y * v)), out)

    @property
    def kernel_params(self):
        return np.array([_kernels.KIND_VISCOELASTIC, self.zbar * self.k2, self.eta_u], dtype=float)

    @property
    def mu_ref(self) -> float:
        """Eq. (6), the large-velocity limit."""
        return self.offset - 0.5 * self.zbar * self.k2

    @cached_property
    def _w_max(self) -> float:
        y = np.logspace(-4, np.log10(300.0), 4001)
        w = 1.0 / y - y / (4.0 * np.sinh(0.5 * y) ** 2)
        return float(self.zbar * self.k2 * w.max())

    def weakening_bounds(self):
        return 0.0, self._w_max

    @property
    def concave_sup(self) -> float:
        # v W(v) = (zbar k2)^2 / eta_u * F(y), F(y) = (1/y)(1/y - y / (4 sinh^2(y/2))) decreases
        # in y = zbar k2 / (v eta_u) (checked in the tests); sup = mu_ss(0) - mu_ss(inf)
        return 0.5 * self.zbar * self.k2

    def describe(self):
        return {"law": self.name, "f_th": self.f_th, "zbar": self.zbar, "k1": self.k1,
                "k2": self.k2, "eta_u": self.eta_u}


# --------------------------------------------------------------------------------------
@dataclass(frozen=True)
class LogLaw(SteadyStateLaw):
    r"""The standard rate-and-state steady state, Eq. (9):

    .. math:: \mu_{ss}(v) = \mu_0 + (a - b)\ln(v/v_0), \qquad W = b - a .

    With the direct effect ``a`` of :class:`~rsf.params.SpringSlider` set to the same
    ``a`` (the default for this law), the friction of the model is Eq. (7),
    :math:`\mu = \mu_0 + a\ln(v/v_0) + b\ln(\theta v_0/D_c)`.

    Parameters
    ----------
    mu0 : float
        Reference friction at ``v0``.
    a, b : float
        Direct-effect and evolution-effect coefficients, >= 0.
    v0 : float
        Reference velocity, > 0.

    Raises
    ------
    ValueError
        If ``mu0`` is not finite, ``a`` or ``b`` is negative, or ``v0`` is not a finite
        number > 0.
    """

    mu0: float = 0.6
    a: float = 0.01
    b: float = 0.015
    v0: float = 1.0
    name: str = field(default="log", init=False, repr=False)

    def __post_init__(self) -> None:
        object.__setattr__(self, "mu0", finite("mu0", self.mu0))
        object.__setattr__(self, "a", nonnegative("a", self.a))
        object.__setattr__(self, "b", nonnegative("b", self.b))
        object.__setattr__(self, "v0", positive("v0", self.v0))

    def mu_ss(self, v):
        v = _as_velocity_array(v)
        with np.errstate(divide="ignore"):
            return self.mu0 + (self.a - self.b) * np.log(v / self.v0)

    def dmu_ss(self, v):
        v = _as_velocity_array(v)
        with np.errstate(divide="ignore"):
            return (self.a - self.b) / v

    def weakening(self, v):
        v = _as_velocity_array(v)
        return np.full_like(v, self.b - self.a)

    @property
    def kernel_params(self):
        return np.array([_kernels.KIND_LOG, self.a - self.b, self.v0], dtype=float)

    @property
    def mu_ref(self) -> float:
        return self.mu0

    def weakening_bounds(self):
        return self.b - self.a, self.b - self.a

    @property
    def concave_sup(self) -> float:
        # phi = mu0 + (b - a) ln(theta v0 / Dc): concave iff b >= a; unbounded above
        return math.inf if self.b >= self.a else math.nan

    def describe(self):
        return {"law": self.name, "mu0": self.mu0, "a": self.a, "b": self.b, "v0": self.v0}


# --------------------------------------------------------------------------------------
_COMPARISONS = {ast.Eq: operator.eq, ast.NotEq: operator.ne, ast.Lt: operator.lt,
                ast.LtE: operator.le, ast.Gt: operator.gt, ast.GtE: operator.ge}
_ARITHMETIC = {ast.Add: operator.add, ast.Sub: operator.sub, ast.Mult: operator.mul,
               ast.Div: operator.truediv}
_WHERE_HELP = ("comparisons of columns with numbers or strings (==, !=, <, <=, >, >=, in, "
               "not in), joined by and, or, not")


def select_rows(frame, where: str, name: str = "where"):
    """The rows of ``frame`` (a pandas DataFrame) where ``where`` holds.

    ``where`` may hold only comparisons of columns, numbers and strings (``==``, ``!=``,
    ``<``, ``<=``, ``>``, ``>=``, chained as in ``0.1 < V <= 10``; ``in``/``not in`` a list
    of constants), the arithmetic ``+ - * /`` between them, joined by ``and``, ``or``,
    ``not`` and parentheses: for instance ``"regime == 'steady'"`` or
    ``"k0 == 0.1 and V < 3"``.  Its syntax tree is checked node by node and evaluated here
    on the columns (no ``eval``, no ``pandas.query``): calls, attributes, subscripts,
    ``@`` references, lambdas and the like are refused with a ValueError, as are unknown
    columns.  ``name`` is what the messages call the expression.
    """
    text = str(where)
    shown = text if len(text) <= 80 else text[:77] + "..."
    try:
        tree = ast.parse(text.strip(), mode="eval")
    except (SyntaxError, RecursionError, MemoryError) as exc:
        raise ValueError(f"{name} {shown!r} is not a valid expression "
                         f"({getattr(exc, 'msg', None) or type(exc).__name__}); use "
                         f"{_WHERE_HELP}") from None

    def refuse(node: ast.AST, what: str | None = None) -> ValueError:
        piece = ast.get_source_segment(text.strip(), node) or type(node).__name__
        return ValueError(f"{name} {shown!r}: {what or f'{piece!r} is not allowed'}; use {_WHERE_HELP}")

    def value(node: ast.AST):
        if isinstance(node, ast.Name):
            if node.id not in frame.columns:
                raise refuse(node, f"no column {node.id!r} (columns: "
                                   f"{', '.join(map(str, frame.columns))})")
            return frame[node.id].to_numpy()
        if isinstance(node, ast.Constant) and type(node.value) in (int, float, str, bool):
            return node.value
        if isinstance(node, ast.UnaryOp) and isinstance(node.op, (ast.USub, ast.UAdd)):
            operand = value(node.operand)
            return -operand if isinstance(node.op, ast.USub) else +operand
        if isinstance(node, ast.BinOp) and type(node.op) in _ARITHMETIC:
            return _ARITHMETIC[type(node.op)](value(node.left), value(node.right))
        raise refuse(node)

    def constants(node: ast.AST) -> list:
        if isinstance(node, (ast.List, ast.Tuple, ast.Set)):
            out = []
            for elt in node.elts:
                item = value(elt)
                if isinstance(item, np.ndarray):
                    raise refuse(elt, "the list after 'in' must hold constants")
                out.append(item)
            return out
        raise refuse(node, "'in' needs a list of constants, as in regime in ['steady', 'stick-slip']")

    def test(node: ast.AST):
        if isinstance(node, ast.BoolOp):
            parts = [test(v) for v in node.values]
            combine = np.logical_and if isinstance(node.op, ast.And) else np.logical_or
            out = parts[0]
            for part in parts[1:]:
                out = combine(out, part)
            return out
        if isinstance(node, ast.UnaryOp) and isinstance(node.op, ast.Not):
            return np.logical_not(test(node.operand))
        if isinstance(node, ast.Compare):
            out = True
            left = value(node.left)
            for op, right_node in zip(node.ops, node.comparators):
                if isinstance(op, (ast.In, ast.NotIn)):
                    right = constants(right_node)
                    hit = np.isin(left, right)
                    out = np.logical_and(out, hit if isinstance(op, ast.In) else ~hit)
                    continue
                if type(op) not in _COMPARISONS:
                    raise refuse(node, f"the comparison {type(op).__name__} is not allowed")
                right = value(right_node)
                out = np.logical_and(out, _COMPARISONS[type(op)](left, right))
                left = right
            return out
        if isinstance(node, ast.Constant) and isinstance(node.value, bool):
            return node.value
        if isinstance(node, (ast.Name, ast.Constant, ast.BinOp)):
            value(node)     # refuses what is not allowed in it first
            raise refuse(node, f"{ast.get_source_segment(text.strip(), node)!r} is not a comparison")
        raise refuse(node)

    try:
        with np.errstate(all="ignore"):
            mask = test(tree.body)
        mask = np.broadcast_to(np.asarray(mask, dtype=bool), (len(frame),))
    except RecursionError:
        raise ValueError(f"{name} {shown!r} is nested too deeply") from None
    except TypeError as exc:        # e.g. a text column compared with a number
        raise ValueError(f"{name} {shown!r} cannot be evaluated on these columns ({exc})") from None
    return frame[mask]


@dataclass(frozen=True, eq=False)
class TabulatedLaw(SteadyStateLaw):
    r"""A steady-state law interpolated from data :math:`(V_i, \mu_i)`.

    The interpolant is the monotone piecewise-cubic Hermite (PCHIP, Fritsch-Carlson)
    interpolant of :math:`\mu` against :math:`\ln V`: it is C1, never overshoots the data
    and keeps monotone data monotone (a velocity-weakening table stays velocity weakening,
    :math:`W \ge 0`).  Outside the data range the law is continued as a constant
    (:math:`W = 0`).  Duplicate velocities are rejected.

    Parameters
    ----------
    V : array_like
        Velocities, > 0, at least two distinct values (sorted on construction).
    mu : array_like
        Friction values, finite, same length as ``V``.

    Raises
    ------
    ValueError
        If ``V`` and ``mu`` differ in length, fewer than 2 velocities are given, a velocity
        is not finite and > 0, a friction is not finite, or a velocity repeats.

    Examples
    --------
    >>> import numpy as np
    >>> from rsf.laws import TabulatedLaw
    >>> law = TabulatedLaw([0.1, 1.0, 10.0], [0.96, 0.95, 0.94])
    >>> law.mu_ss(np.array([1.0, 100.0]))        # held flat beyond the table
    array([0.95, 0.94])
    """

    V: np.ndarray
    mu: np.ndarray
    name: str = field(default="table", init=False, repr=False)

    def __post_init__(self) -> None:
        V = np.asarray(self.V, dtype=float).ravel()
        mu = np.asarray(self.mu, dtype=float).ravel()
        if V.size != mu.size:
            raise ValueError(f"V and mu must have the same length, got {V.size} and {mu.size}")
        if V.size < 2:
            raise ValueError(f"V must hold at least 2 velocities, got {V.size}")
        if not np.all(np.isfinite(V)) or np.any(V <= 0.0):
            raise ValueError("V must hold finite velocities > 0")
        if not np.all(np.isfinite(mu)):
            raise ValueError("mu must hold finite values")
        order = np.argsort(V, kind="stable")
        V = V[order]
        mu = mu[order]
        if np.any(np.diff(V) <= 0.0):
            raise ValueError("V must not contain duplicate velocities")
        V.setflags(write=False)
        mu.setflags(write=False)
        object.__setattr__(self, "V", V)
        object.__setattr__(self, "mu", mu)

    @classmethod
    def from_csv(cls, path: str | Path, v_column: str = "V", mu_column: str = "sigma",
                 where: str | None = None, *, names: dict[str, str] | None = None) -> TabulatedLaw:
        """Read a table from a CSV file with columns ``v_column`` and ``mu_column``.

        ``where`` optionally keeps some rows first: comparisons of columns with numbers or
        strings, joined by ``and``, ``or``, ``not`` (see :func:`select_rows`), for instance
        ``"regime == 'steady'"`` to keep only the steady rows of a sweep, or
        ``"V > 1 and k0 == 0.1"``.  It is checked and evaluated by rsf itself, never by
        ``eval`` or ``pandas.query``.

        Every problem (a missing or unreadable file, a folder, a bad ``where``, a missing
        column, fewer than two rows) raises one ValueError.  ``names`` maps the argument
        names (``path``, ``where``, ``v_column``, ``mu_column``) to the names the messages
        use (the command line passes its options).
        """
        import pandas as pd

        name = {"path": "path", "where": "where", "v_column": "v_column", "mu_column": "mu_column",
                **(names or {})}
        text = str(path)
        if Path(text).is_dir():
            raise ValueError(f"{name['path']} {text!r} is a folder, not a CSV file")
        try:
            frame = pd.read_csv(path)
        except OSError as exc:
            raise ValueError(f"{name['path']} {text!r} cannot be read "
                             f"({exc.strerror or type(exc).__name__})") from None
        except (UnicodeDecodeError, pd.errors.ParserError, pd.errors.EmptyDataError) as exc:
            reason = str(exc).strip().splitlines()[0] if str(exc).strip() else type(exc).__name__
            raise ValueError(f"{name['path']} {text!r} is not a readable CSV file ({reason})") from None
        if where is not None:
            frame = select_rows(frame, where, name=name["where"])
        for column, key in ((v_column, "v_column"), (mu_column, "mu_column")):
            if column not in frame.columns:
                raise ValueError(f"{name[key]}: column {column!r} not in {text!r}; available: "
                                 f"{', '.join(map(str, frame.columns))}")
        if len(frame) < 2:
            kept = f" after {name['where']} {where!r}" if where is not None else ""
            raise ValueError(f"{name['path']} {text!r} has {len(frame)} row(s){kept}; a table needs "
                             f"at least 2")
        values = []
        for column, key in ((v_column, "v_column"), (mu_column, "mu_column")):
            try:
                values.append(frame[column].to_numpy(float))
            except (TypeError, ValueError):
                raise ValueError(f"{name[key]}: column {column!r} of {text!r} must hold numbers") from None
        try:
            return cls(*values)
        except ValueError as exc:
            raise ValueError(f"{name['path']} {text!r}: {exc}") from None

    def check_velocities(self, velocities, what: str = "V") -> bool:
        """Warn if some of ``velocities`` lie outside the table, where the law is held flat
        (the friction of the nearest end, no weakening): one logging warning per law, the
        first time (later ones are logged at DEBUG).  Returns whether all lie inside."""
        v = np.atleast_1d(np.asarray(velocities, dtype=float)).ravel()
        v = v[np.isfinite(v) & (v > 0.0)]
        outside = np.unique(v[(v < self.V[0]) | (v > self.V[-1])])
        if outside.size:
            shown = ", ".join(f"{x:g}" for x in outside[:5])
            more = f" and {outside.size - 5} more" if outside.size > 5 else ""
            level = logging.DEBUG if self.__dict__.get("_warned") else logging.WARNING
            object.__setattr__(self, "_warned", True)
            logger.log(level, "%s = %s%s outside the table's velocities [%g, %g]: the law is held "
                       "flat there (the friction at the nearest end, no velocity weakening)",
                       what, shown, more, self.V[0], self.V[-1])
        return not outside.size

    @cached_property
    def _pchip(self):
        from scipy.interpolate import PchipInterpolator

        return PchipInterpolator(np.log(self.V), self.mu, extrapolate=False)

    @cached_property
    def _slopes(self) -> np.ndarray:
        return self._pchip.derivative()(np.log(self.V))

    def mu_ss(self, v):
        v = _as_velocity_array(v)
        with np.errstate(divide="ignore"):
            x = np.clip(np.log(np.maximum(v, 1e-300)), np.log(self.V[0]), np.log(self.V[-1]))
        return self._pchip(x)

    def dmu_ss(self, v):
        v = _as_velocity_array(v)
        with np.errstate(divide="ignore"):
            x = np.log(np.maximum(v, 1e-300))
        inside = (x > np.log(self.V[0])) & (x < np.log(self.V[-1]))
        xc = np.clip(x, np.log(self.V[0]), np.log(self.V[-1]))
        out = self._pchip.derivative()(xc) / np.maximum(v, 1e-300)
        return np.where(inside, out, 0.0)

    @cached_property
    def _params(self) -> np.ndarray:
        n = self.V.size
        return np.concatenate([[float(_kernels.KIND_TABLE), float(n)], np.log(self.V),
                               self.mu - self.mu[-1], self._slopes])

    @property
    def mu_ref(self) -> float:
        """The last tabulated value (the friction beyond the largest velocity)."""
        return float(self.mu[-1])

    @property
    def kernel_params(self):
        return self._params

    @cached_property
    def _bounds(self) -> tuple[float, float]:
        x = np.log(self.V)
        grid = np.concatenate([np.linspace(x[i], x[i + 1], 41) for i in range(x.size - 1)])
        w = -self._pchip.derivative()(grid)
        return float(min(w.min(), 0.0)), float(max(w.max(), 0.0))

    def weakening_bounds(self):
        return self._bounds

    def describe(self):
        return {"law": self.name, "n_points": int(self.V.size), "V_min": float(self.V[0]),
                "V_max": float(self.V[-1])}


# --------------------------------------------------------------------------------------
@dataclass(frozen=True, eq=False)
class CallableLaw(SteadyStateLaw):
    r"""Any steady-state law given as two scalar functions, :math:`\mu_{ss}(v)` and its
    derivative :math:`\mathrm{d}\mu_{ss}/\mathrm{d}v`.

    The derivative is checked against central differences of ``mu_ss`` at velocities from
    1e-6 to 1e6 (relative mismatch above 1e-4 is an error).  If numba can compile both
    functions the solver runs compiled kernels (compiled for this law on first use);
    otherwise it runs the same kernels as pure Python, which is correct but slow.

    Parameters
    ----------
    mu_ss_fn : callable
        ``float -> float``, the steady-state friction for v > 0.
    dmu_ss_fn : callable
        ``float -> float``, its derivative.
    label : str
        Name used in tables.
    w_range : tuple of float or None
        Bounds of :math:`W = -v\mu_{ss}'` over v > 0; if None they are estimated on a grid
        from 1e-12 to 1e12 with a 50 % margin.

    Raises
    ------
    ValueError
        If either function is not callable, gives a non-finite value at a probe velocity
        in [1e-6, 1e6], the derivative does not match central differences of ``mu_ss_fn``
        there, or ``w_range`` is not a finite (low, high) with low <= high.

    Examples
    --------
    >>> from rsf.laws import CallableLaw
    >>> law = CallableLaw(lambda v: 0.945 + 0.007 / (v + 0.078),    # Eq. (10) again
    ...                   lambda v: -0.007 / (v + 0.078) ** 2, label="eq10")
    >>> round(float(law.weakening(1.0)), 6)                         # A v / (v + B)^2
    0.006024
    """

    mu_ss_fn: Callable[[float], float]
    dmu_ss_fn: Callable[[float], float]
    label: str = "callable"
    w_range: tuple[float, float] | None = None
    name: str = field(default="callable", init=False, repr=False)

    def __post_init__(self) -> None:
        if not callable(self.mu_ss_fn):
            raise ValueError(f"mu_ss_fn must be callable, got {self.mu_ss_fn!r}")
        if not callable(self.dmu_ss_fn):
            raise ValueError(f"dmu_ss_fn must be callable, got {self.dmu_ss_fn!r}")
        object.__setattr__(self, "name", str(self.label))
        probe = np.logspace(-6, 6, 25)
        for v in probe:
            m = float(self.mu_ss_fn(float(v)))
            d = float(self.dmu_ss_fn(float(v)))
            if not (math.isfinite(m) and math.isfinite(d)):
                raise ValueError(f"mu_ss_fn and dmu_ss_fn must be finite for v > 0; at v = {v:g} "
                                 f"they give {m!r}, {d!r}")
            h = 1e-5 * v
            up, down = float(self.mu_ss_fn(v + h)), float(self.mu_ss_fn(v - h))
            fd = (up - down) / (2.0 * h)
            # the difference's truncation error is relative (1e-10 for smooth laws); its
            # round-off is absolute, a few ulps of mu over 2h (1e-5 at v = 1e-6 for mu ~ 0.6)
            roundoff = 8.0 * np.finfo(float).eps * max(abs(up), abs(down), abs(m)) / (2.0 * h)
            if abs(fd - d) > 1e-4 * max(abs(fd), abs(d)) + roundoff:
                raise ValueError(f"dmu_ss_fn does not match the derivative of mu_ss_fn at v = {v:g}: "
                                 f"{d!r} against the finite difference {fd!r}")
        if self.w_range is not None:
            lo, hi = (finite("w_range[0]", self.w_range[0]), finite("w_range[1]", self.w_range[1]))
            if lo > hi:
                raise ValueError(f"w_range must be (low, high) with low <= high, got {self.w_range!r}")
            object.__setattr__(self, "w_range", (lo, hi))
        object.__setattr__(self, "_kernel_set", self._build_kernels())

    def _build_kernels(self) -> tuple[dict, bool]:
        mu, dmu = self.mu_ss_fn, self.dmu_ss_fn
        try:
            import numba

            mu_j = numba.njit(mu)
            dmu_j = numba.njit(dmu)

            @numba.njit
            def law_eval(v, p):
                return mu_j(v), -v * dmu_j(v)

            law_eval(1.0, np.zeros(1))
            return _kernels.kernel_namespace(law_eval, jit=True), True
        except Exception as exc:  # numba raises many error types when it cannot compile
            logger.info("numba cannot compile %s (%s); the solver will run pure Python",
                        self.label, type(exc).__name__)

        def law_eval_py(v, p):
            return float(mu(v)), -v * float(dmu(v))

        return _kernels.kernel_namespace(law_eval_py, jit=False), False

    @property
    def jitted(self) -> bool:
        return self._kernel_set[1]  # type: ignore[attr-defined]

    def kernels(self):
        return self._kernel_set[0]  # type: ignore[attr-defined]

    @property
    def kernel_params(self):
        return np.array([float(_kernels.KIND_USER)])

    def mu_ss(self, v):
        v = _as_velocity_array(v)
        return np.vectorize(lambda x: float(self.mu_ss_fn(float(x))), otypes=[float])(v)

    def dmu_ss(self, v):
        v = _as_velocity_array(v)
        return np.vectorize(lambda x: float(self.dmu_ss_fn(float(x))), otypes=[float])(v)

    @cached_property
    def _bounds(self) -> tuple[float, float]:
        if self.w_range is not None:
            return self.w_range
        v = np.logspace(-12, 12, 2401)
        w = self.weakening(v)
        lo, hi = float(w.min()), float(w.max())
        return min(1.5 * lo, 0.0), max(1.5 * hi, 0.0)

    def weakening_bounds(self):
        return self._bounds

    def describe(self):
        return {"law": self.name}
