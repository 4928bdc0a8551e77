"""Turn a bad argument into a ``ValueError`` that names the parameter and the allowed
range.  Every public dataclass and entry point of :mod:`compare` uses these."""
from __future__ import annotations

import math
from typing import Iterable, Sequence

import numpy as np

__all__ = ["positive", "nonnegative", "in_range", "positive_int", "choice", "positive_array",
           "choices", "shown"]


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
    if isinstance(value, (bool, np.bool_, str, bytes)):
        raise ValueError(f"{name} must be a real number, got {shown(value)}")
    try:
        return float(value)  # type: ignore[arg-type]
    except (TypeError, ValueError):
        raise ValueError(f"{name} must be a real number, got {shown(value)}") from None


def positive(name: str, value: object) -> float:
    """``value`` as a float; raise unless finite and > 0."""
    v = _as_float(name, value)
    if not (math.isfinite(v) and v > 0.0):
        raise ValueError(f"{name} must be a finite number > 0, got {shown(value)}")
    return v


def nonnegative(name: str, value: object) -> float:
    """``value`` as a float; raise unless finite and >= 0."""
    v = _as_float(name, value)
    if not (math.isfinite(v) and v >= 0.0):
        raise ValueError(f"{name} must be a finite number >= 0, got {shown(value)}")
    return v


def in_range(name: str, value: object, low: float, high: float, *, low_open: bool = False,
             high_open: bool = False) -> float:
    """``value`` as a float; raise unless it lies in the interval."""
    v = _as_float(name, value)
    ok = math.isfinite(v) and (v > low if low_open else v >= low) and (v < high if high_open else v <= high)
    if not ok:
        left, right = "(" if low_open else "[", ")" if high_open else "]"
        raise ValueError(f"{name} must lie in {left}{low:g}, {high:g}{right}, got {shown(value)}")
    return v


def positive_int(name: str, value: object, low: int = 1, high: int | None = None) -> int:
    """``value`` as an int; raise unless it is an integer >= ``low`` (and <= ``high``)."""
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


def choice(name: str, value: object, allowed: Iterable[str]) -> str:
    """``value`` if it is one of ``allowed``; raise naming the choices otherwise."""
    allowed = tuple(allowed)
    if value not in allowed:
        raise ValueError(f"{name} must be one of {', '.join(map(repr, allowed))}, got {shown(value)}")
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
        raw = None if isinstance(values, (str, bytes)) else np.atleast_1d(np.asarray(values))
        # booleans and text are not numbers, even where float() would take them
        arr = None if raw is None or raw.dtype.kind in "bUSV" else raw.astype(float)
    except (TypeError, ValueError):
        arr = None
    if arr is None or arr.ndim != 1:
        raise ValueError(f"{name} must be a sequence of numbers, got {shown(values)}")
    if arr.size < min_size:
        raise ValueError(f"{name} must hold at least {min_size} value(s), got {arr.size}")
    bad = ~np.isfinite(arr) | (arr <= low) | (arr >= high)
    if np.any(bad):
        i = int(np.argmax(bad))
        raise ValueError(f"{name} must hold finite values in ({low:g}, {high:g}): item {i + 1} of "
                         f"{arr.size} is {float(arr[i])!r}")
    return tuple(float(x) for x in arr)
