"""Pieces shared by the micro benchmark scripts: the paper's five k0 and their RS critical
velocities, fitting a Fokker-Planck run into a wall-time budget, and merging a partial
run's rows into the results of a previous one."""
from __future__ import annotations

from pathlib import Path

import numpy as np
import pandas as pd

import micro

#: The paper's k0 values (Figs. 4, 10).
K0 = (0.3, 0.1, 0.01, 0.001, 0.0001)
#: RS critical velocity of Eq. (12) with the paper's A = 0.007, B = 0.078, D_c = 0.06
#: (compare/ reports 0.2029, 1.005, 11.51, 116.5, 1167); micro's lies within ~25 % where
#: measured (docs/reference/micro_numerics.md §4): velocities are placed around it.
VC_RS = {0.3: 0.2029, 0.1: 1.005, 0.01: 11.51, 0.001: 116.5, 0.0001: 1167.0}


def merged(path: Path, new: pd.DataFrame, keys: list[str], replace: pd.DataFrame | None = None) -> pd.DataFrame:
    """``new`` and the rows of the CSV at ``path`` (if any) whose ``keys`` match no row of
    ``replace`` (default ``new``; numbers compared with np.isclose, other keys exactly).
    The file is read now, so points another run wrote meanwhile are kept."""
    if not path.exists():
        return new.reset_index(drop=True)
    old = pd.read_csv(path)
    replace = new if replace is None else replace
    same = np.ones((len(old), len(replace)), dtype=bool)
    for key in keys:
        if pd.api.types.is_numeric_dtype(replace[key]):
            same &= np.isclose(old[key].to_numpy(float)[:, None], replace[key].to_numpy(float))
        else:
            same &= old[key].to_numpy(str)[:, None] == replace[key].to_numpy(str)
    return pd.concat([old[~same.any(axis=1)], new], ignore_index=True)


def capped_t_max(model: micro.Model, V: float, eps: float, budget: float) -> float:
    """Simulated time that fits ``budget`` seconds at drive velocity ``V``.

    The cost per unit time is measured on a second short run that continues the first
    (the first loads the springs from rest, which is cheaper than sliding and made a
    one-run calibration underestimate the cost four-fold at k0 = 1e-3, V = 175).
    """
    # a twentieth of a loading time, but at most 2 time units (at small V the cost is
    # the synchronisations, ~140 per unit time, not the drive)
    probe = min(0.05 * max(model.kappa * model.zbar / (model.k0 * V), 1.0), 2.0)
    numerics = micro.Numerics(eps=eps)
    first = micro.simulate(model, V, duration=probe, numerics=numerics)
    second = micro.simulate(model, V, duration=probe, numerics=numerics, initial=first.grid)
    rate = max(second.wall_time, 1e-4) / probe
    return budget / rate
