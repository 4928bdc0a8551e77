"""The harness every benchmark script and every study (``studies/``) uses: timing with the compile time apart, writing CSV
files and figures, and the pieces the micro scripts share.

Timing
    ``Stopwatch`` (wall time by default, CPU time with ``cpu=True``) and ``timed(fn, ...)``
    time one call; ``median_time`` the median of repeats.  ``warm_up(fn, ...)`` makes the
    first call (numba's compilation or the load of its disk cache, CVODE's set-up), prints
    its time as the compile time and returns it, so that no timing after it holds any.

Writing
    ``write_csv(frame, path, keys=...)`` writes a table (index left out) through a
    temporary file, so that an interrupted run leaves the previous file whole; with
    ``keys`` it first merges the rows of the file already there (``merged``).
    ``pyplot()`` gives matplotlib's pyplot on the Agg backend (no screen needed) and
    ``save_figure(fig, path)`` writes a figure and closes it.  ``RESULTS`` is
    ``benchmarks/results/``, ``FIGURES`` and ``DATA`` are ``docs/figures/`` and
    ``docs/data/``.

The micro scripts
    ``K0`` and ``VC_RS``: the paper's five k0 and their RS critical velocities;
    ``capped_t_max``: a Fokker-Planck run's simulated time that fits a wall-time budget.

Scripts import it as ``from _harness import ...``: run as ``python benchmarks/NAME.py``,
the script's folder is first on ``sys.path``.  Studies, run as ``python -m studies NAME``
from the repository's top, import it as ``from benchmarks._harness import ...``.  The
indexes are ``benchmarks/README.md`` and ``studies/README.md``.
"""
from __future__ import annotations

import os
import statistics
import time
from collections.abc import Callable
from pathlib import Path
from typing import Any

import numpy as np
import pandas as pd

#: The repository, the benchmarks' results, and the documentation's figures and data.
ROOT = Path(__file__).resolve().parents[1]
RESULTS = ROOT / "benchmarks" / "results"
FIGURES = ROOT / "docs" / "figures"
DATA = ROOT / "docs" / "data"

#: The paper's k0 values (Figs. 4, 10).
K0 = (0.3, 0.1, 0.01, 0.001, 0.0001)
#: RS critical velocity of Eq. (12) with the paper's A = 0.007, B = 0.078, D_c = 0.06
#: (compare/ reports 0.2029, 1.005, 11.51, 116.5, 1167); micro's lies within ~25 % where
#: measured (docs/reference/micro_numerics.md §4): velocities are placed around it.
VC_RS = {0.3: 0.2029, 0.1: 1.005, 0.01: 11.51, 0.001: 116.5, 0.0001: 1167.0}


# --- timing ---------------------------------------------------------------------------

class Stopwatch:
    """A clock started when made: ``seconds`` is the time since then (wall time from
    ``time.perf_counter``, or the process's CPU time from ``time.process_time`` with
    ``cpu=True``).  As a context manager it stops at the end of the block::

        with Stopwatch() as sw:
            run()
        print(sw.seconds)
    """

    def __init__(self, cpu: bool = False) -> None:
        self._clock = time.process_time if cpu else time.perf_counter
        self._start = self._clock()
        self._stop: float | None = None

    def restart(self) -> Stopwatch:
        self._start, self._stop = self._clock(), None
        return self

    @property
    def seconds(self) -> float:
        return (self._clock() if self._stop is None else self._stop) - self._start

    def __enter__(self) -> Stopwatch:
        return self.restart()

    def __exit__(self, *exc: object) -> None:
        self._stop = self._clock()


def timed(fn: Callable[..., Any], *args: Any, cpu: bool = False, **kwargs: Any) -> tuple[Any, float]:
    """``fn(*args, **kwargs)`` and the seconds it took (wall, or CPU with ``cpu=True``)."""
    sw = Stopwatch(cpu=cpu)
    value = fn(*args, **kwargs)
    return value, sw.seconds


def median_time(fn: Callable[[], Any], repeats: int = 7, cpu: bool = False) -> float:
    """The median of ``repeats`` timed calls of ``fn()``, in seconds."""
    return float(statistics.median(timed(fn, cpu=cpu)[1] for _ in range(repeats)))


def warm_up(fn: Callable[..., Any], *args: Any, label: str = "compilation (or numba's cache) and a first call",
            **kwargs: Any) -> float:
    """Call ``fn(*args, **kwargs)`` once before any clock that counts starts, print its time
    as the compile time and return it (seconds)."""
    _, seconds = timed(fn, *args, **kwargs)
    print(f"{label}: {seconds:.2f} s (kept apart from the timings)", flush=True)
    return seconds


# --- writing --------------------------------------------------------------------------

def merged(path: Path, new: pd.DataFrame, keys: list[str], replace: pd.DataFrame | None = None) -> pd.DataFrame:
    """``new`` and the rows of the CSV at ``path`` (if any) whose ``keys`` match no row of
    ``replace`` (default ``new``; numbers equal to a relative 1e-9, with no absolute slack, so
    that 1e-13 and 1e-20 differ; other keys exactly).
    The file is read now, so points another run wrote meanwhile are kept."""
    path = Path(path)
    if not path.exists():
        return new.reset_index(drop=True)
    old = pd.read_csv(path)
    replace = new if replace is None else replace
    same = np.ones((len(old), len(replace)), dtype=bool)
    for key in keys:
        if pd.api.types.is_numeric_dtype(replace[key]):
            same &= np.isclose(old[key].to_numpy(float)[:, None], replace[key].to_numpy(float), rtol=1e-9, atol=0.0)
        else:
            same &= old[key].to_numpy(str)[:, None] == replace[key].to_numpy(str)
    return pd.concat([old[~same.any(axis=1)], new], ignore_index=True)


def write_csv(frame: pd.DataFrame | list[dict], path: str | Path, keys: list[str] | None = None,
              replace: pd.DataFrame | None = None, **to_csv: Any) -> pd.DataFrame:
    """Write ``frame`` (a DataFrame or a list of row dicts) to ``path`` without its index,
    through a temporary file in the same folder (made if missing).  With ``keys``, the rows
    of the file already at ``path`` that match no row of ``replace`` (default ``frame``) on
    ``keys`` are kept before the new ones (``merged``).  ``to_csv`` goes to
    ``DataFrame.to_csv`` (``float_format=...``).  Returns the table written."""
    path = Path(path)
    frame = pd.DataFrame(frame) if not isinstance(frame, pd.DataFrame) else frame
    if keys is not None:
        frame = merged(path, frame, keys, replace)
    path.parent.mkdir(parents=True, exist_ok=True)
    tmp = path.with_name(f".{path.name}.{os.getpid()}.tmp")
    try:
        frame.to_csv(tmp, index=False, **to_csv)
        os.replace(tmp, path)
    finally:
        if tmp.exists():
            tmp.unlink()
    return frame


def pyplot():
    """matplotlib.pyplot on the Agg backend (files only, no screen)."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    return plt


def save_figure(fig, path: str | Path, dpi: int = 120) -> Path:
    """Write ``fig`` to ``path`` (its folder made if missing) and close it."""
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(path, dpi=dpi)
    pyplot().close(fig)
    print(f"wrote {path}", flush=True)
    return path


# --- the micro scripts' shared pieces -------------------------------------------------

def capped_t_max(model, V: float, eps: float, budget: float) -> float:
    """Simulated time of a Fokker-Planck run (``micro.simulate``) that fits ``budget``
    seconds at drive velocity ``V`` and bin ``eps``.

    The cost per unit time is measured on a second short run that continues the first
    (the first loads the springs from rest, which is cheaper than sliding and made a
    one-run calibration underestimate the cost four-fold at k0 = 1e-3, V = 175).
    """
    import micro

    # a twentieth of a loading time, but at most 2 time units (at small V the cost is
    # the synchronisations, ~140 per unit time, not the drive)
    probe = min(0.05 * max(model.kappa * model.zbar / (model.k0 * V), 1.0), 2.0)
    numerics = micro.Numerics(eps=eps)
    first = micro.simulate(model, V, duration=probe, numerics=numerics)
    second = micro.simulate(model, V, duration=probe, numerics=numerics, initial=first.grid)
    rate = max(second.wall_time, 1e-4) / probe
    return budget / rate
