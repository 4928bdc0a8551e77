"""Small helpers that turn a bad parameter into a ValueError naming the parameter and
the allowed range.  Every public dataclass of :mod:`rsf` validates itself with them on
construction."""
from __future__ import annotations

import math

__all__ = ["finite", "positive", "nonnegative", "in_range", "choice", "positive_int"]


def _as_float(name: str, value: object) -> float:
    try:
        result = float(value)  # type: ignore[arg-type]
    except (TypeError, ValueError):
        raise ValueError(f"{name} must be a real number, got {value!r}") from None
    return result


def finite(name: str, value: object) -> float:
    """Return ``value`` as a float, or raise unless it is finite."""
    result = _as_float(name, value)
    if not math.isfinite(result):
        raise ValueError(f"{name} must be a finite number, got {value!r}")
    return result


def positive(name: str, value: object) -> float:
    """Return ``value`` as a float, or raise unless it is finite and > 0."""
    result = _as_float(name, value)
    if not (math.isfinite(result) and result > 0.0):
        raise ValueError(f"{name} must be a finite number > 0, got {value!r}")
    return result


def nonnegative(name: str, value: object) -> float:
    """Return ``value`` as a float, or raise unless it is finite and >= 0."""
    result = _as_float(name, value)
    if not (math.isfinite(result) and result >= 0.0):
        raise ValueError(f"{name} must be a finite number >= 0, got {value!r}")
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
        raise ValueError(f"{name} must lie in {left}{low!r}, {high!r}{right}, got {value!r}")
    return result


def choice(name: str, value: object, allowed: tuple[str, ...]) -> str:
    """Return ``value`` if it is one of ``allowed``, or raise naming the choices."""
    if value not in allowed:
        raise ValueError(f"{name} must be one of {', '.join(map(repr, allowed))}, got {value!r}")
    return str(value)


def positive_int(name: str, value: object) -> int:
    """Return ``value`` as an int, or raise unless it is an integer >= 1."""
    if isinstance(value, bool) or not isinstance(value, (int,)) and not (
        isinstance(value, float) and value.is_integer()
    ):
        try:
            import numpy as np

            if isinstance(value, np.integer):
                value = int(value)
            else:
                raise TypeError
        except TypeError:
            raise ValueError(f"{name} must be an integer >= 1, got {value!r}") from None
    result = int(value)  # type: ignore[arg-type]
    if result < 1:
        raise ValueError(f"{name} must be an integer >= 1, got {value!r}")
    return result
