"""Turn a bad argument into a ``ValueError`` that names the parameter and the allowed
range.  Every public dataclass and entry point of :mod:`compare` uses these.

The scalar checks are rsf's (:mod:`rsf._validation`, re-exported here: compare builds on
rsf); the checks of lists are compare's own."""
from __future__ import annotations

import math
from typing import Iterable, Sequence

import numpy as np

from rsf._validation import choice, in_range, nonnegative, positive, positive_int, shown

__all__ = ["positive", "nonnegative", "in_range", "positive_int", "choice", "positive_array",
           "choices", "shown"]


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
