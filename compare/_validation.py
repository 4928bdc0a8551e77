"""Turn a bad argument into a ``ValueError`` that names the parameter and the allowed
range.  Every public dataclass and entry point of :mod:`compare` uses these."""
from __future__ import annotations

import math
from typing import Iterable, Sequence

import numpy as np

__all__ = ["positive", "nonnegative", "in_range", "positive_int", "choice", "positive_array",
           "choices"]


def _as_float(name: str, value: object) -> float:
    if isinstance(value, bool):
        raise ValueError(f"{name} must be a real number, got {value!r}")
    try:
        return float(value)  # type: ignore[arg-type]
    except (TypeError, ValueError):
        raise ValueError(f"{name} must be a real number, got {value!r}") from None


def positive(name: str, value: object) -> float:
    """``value`` as a float; raise unless finite and > 0."""
    v = _as_float(name, value)
    if not (math.isfinite(v) and v > 0.0):
        raise ValueError(f"{name} must be a finite number > 0, got {value!r}")
    return v


def nonnegative(name: str, value: object) -> float:
    """``value`` as a float; raise unless finite and >= 0."""
    v = _as_float(name, value)
    if not (math.isfinite(v) and v >= 0.0):
        raise ValueError(f"{name} must be a finite number >= 0, got {value!r}")
    return v


def in_range(name: str, value: object, low: float, high: float, *, low_open: bool = False,
             high_open: bool = False) -> float:
    """``value`` as a float; raise unless it lies in the interval."""
    v = _as_float(name, value)
    ok = math.isfinite(v) and (v > low if low_open else v >= low) and (v < high if high_open else v <= high)
    if not ok:
        left, right = "(" if low_open else "[", ")" if high_open else "]"
        raise ValueError(f"{name} must lie in {left}{low!r}, {high!r}{right}, got {value!r}")
    return v


def positive_int(name: str, value: object, low: int = 1, high: int | None = None) -> int:
    """``value`` as an int; raise unless it is an integer >= ``low`` (and <= ``high``)."""
    if isinstance(value, bool):
        raise ValueError(f"{name} must be an integer >= {low}, got {value!r}")
    if isinstance(value, (int, np.integer)):
        v = int(value)
    elif isinstance(value, float) and value.is_integer():
        v = int(value)
    else:
        raise ValueError(f"{name} must be an integer >= {low}, got {value!r}")
    if v < low or (high is not None and v > high):
        bound = f">= {low}" if high is None else f"in [{low}, {high}]"
        raise ValueError(f"{name} must be an integer {bound}, got {value!r}")
    return v


def choice(name: str, value: object, allowed: Iterable[str]) -> str:
    """``value`` if it is one of ``allowed``; raise naming the choices otherwise."""
    allowed = tuple(allowed)
    if value not in allowed:
        raise ValueError(f"{name} must be one of {', '.join(map(repr, allowed))}, got {value!r}")
    return str(value)


def choices(name: str, values: Iterable[str], allowed: Sequence[str]) -> tuple[str, ...]:
    """Every entry of ``values`` checked with :func:`choice`; duplicates dropped, order kept."""
    out: list[str] = []
    for v in values:
        v = choice(name, v, allowed)
        if v not in out:
            out.append(v)
    if not out:
        raise ValueError(f"{name} must name at least one of {', '.join(map(repr, allowed))}")
    return tuple(out)


def positive_array(name: str, values: object, *, low: float = 0.0, high: float = math.inf,
                   min_size: int = 1) -> tuple[float, ...]:
    """A tuple of floats in ``(low, high)``; raise naming the parameter otherwise."""
    try:
        arr = np.atleast_1d(np.asarray(values, dtype=float)) if not isinstance(values, str) else None
    except (TypeError, ValueError):
        arr = None
    if arr is None or arr.ndim != 1:
        raise ValueError(f"{name} must be a sequence of numbers, got {values!r}")
    if arr.size < min_size:
        raise ValueError(f"{name} must hold at least {min_size} value(s), got {arr.size}")
    if not np.all(np.isfinite(arr)) or np.any(arr <= low) or np.any(arr >= high):
        raise ValueError(f"{name} must hold finite values in ({low!r}, {high!r}), got {values!r}")
    return tuple(float(x) for x in arr)
