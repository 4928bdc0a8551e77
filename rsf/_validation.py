"""Small helpers that turn a bad parameter into a ValueError naming the parameter and
the allowed range.  Every public dataclass of :mod:`rsf` validates itself with them on
construction, and :mod:`compare` uses them too (``compare/_validation.py``).  :mod:`micro`
has its own: micro and rsf do not import each other."""
from __future__ import annotations

import math
from typing import Iterable

import numpy as np

__all__ = ["finite", "positive", "nonnegative", "in_range", "choice", "positive_int", "shown",
           "real"]


def shown(value: object) -> str:
    """``repr(value)`` with numpy scalars and arrays as plain Python numbers and lists, so
    that a message reads ``got 1.0``, never ``got np.float64(1.0)``."""
    if isinstance(value, np.generic):
        return repr(value.item())
    if isinstance(value, np.ndarray):
        return repr(value.tolist())
    if isinstance(value, (tuple, list)) and any(isinstance(v, np.generic) for v in value):
        return repr(type(value)(v.item() if isinstance(v, np.generic) else v for v in value))
    return repr(value)


def _as_float(name: str, value: object) -> float:
    # strict: True, "1" and b"1" are not numbers, even though float() takes them
    if isinstance(value, (bool, np.bool_, str, bytes)):
        raise ValueError(f"{name} must be a real number, got {shown(value)}")
    try:
        result = float(value)  # type: ignore[arg-type]
    except (TypeError, ValueError):
        raise ValueError(f"{name} must be a real number, got {shown(value)}") from None
    return result


def real(name: str, value: object) -> float:
    """Return ``value`` as a float, or raise unless it is a real number (not a bool or a
    string); nan and inf pass."""
    return _as_float(name, value)


def finite(name: str, value: object) -> float:
    """Return ``value`` as a float, or raise unless it is finite."""
    result = _as_float(name, value)
    if not math.isfinite(result):
        raise ValueError(f"{name} must be a finite number, got {shown(value)}")
    return result


def positive(name: str, value: object) -> float:
    """Return ``value`` as a float, or raise unless it is finite and > 0."""
    result = _as_float(name, value)
    if not (math.isfinite(result) and result > 0.0):
        raise ValueError(f"{name} must be a finite number > 0, got {shown(value)}")
    return result


def nonnegative(name: str, value: object) -> float:
    """Return ``value`` as a float, or raise unless it is finite and >= 0."""
    result = _as_float(name, value)
    if not (math.isfinite(result) and result >= 0.0):
        raise ValueError(f"{name} must be a finite number >= 0, got {shown(value)}")
    return result


def in_range(name: str, value: object, low: float, high: float, *, low_open: bool = False,
             high_open: bool = False) -> float:
    """Return ``value`` as a float, or raise unless it lies in the given interval."""
    result = _as_float(name, value)
    ok_low = result > low if low_open else result >= low
    ok_high = result < high if high_open else result <= high
    if not (math.isfinite(result) and ok_low and ok_high):
        left = "(" if low_open else "["
        right = ")" if high_open else "]"
        raise ValueError(f"{name} must lie in {left}{low:g}, {high:g}{right}, got {shown(value)}")
    return result


def choice(name: str, value: object, allowed: Iterable[str]) -> str:
    """Return ``value`` if it is one of ``allowed``, or raise naming the choices."""
    allowed = tuple(allowed)
    if value not in allowed:
        raise ValueError(f"{name} must be one of {', '.join(map(repr, allowed))}, got {shown(value)}")
    return str(value)


def positive_int(name: str, value: object, low: int = 1, high: int | None = None) -> int:
    """Return ``value`` as an int, or raise unless it is an integer >= ``low`` (and <=
    ``high``); an integral float passes, a bool does not."""
    if isinstance(value, (bool, np.bool_)):
        raise ValueError(f"{name} must be an integer >= {low}, got {shown(value)}")
    if isinstance(value, (int, np.integer)):
        v = int(value)
    elif isinstance(value, float) and value.is_integer():
        v = int(value)
    else:
        raise ValueError(f"{name} must be an integer >= {low}, got {shown(value)}")
    if v < low or (high is not None and v > high):
        bound = f">= {low}" if high is None else f"in [{low}, {high}]"
        raise ValueError(f"{name} must be an integer {bound}, got {shown(value)}")
    return v
