"""Extrema, cycles and convergence tests on a recorded stress signal.

The Fokker-Planck solver records the stress adaptively (a record whenever it has moved by
a set resolution, at most a set time apart, and on both sides of every shock).  This
module turns such records into the quantities a user asks for: the cycles of a
stick-slip oscillation (from the peaks and troughs of the stress, found with a
hysteresis that ignores discretisation jitter), and the two tests that end a run: a
steady state (the stress is flat) or a converged limit cycle (consecutive cycles agree).
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import pandas as pd

__all__ = ["Records", "find_cycles", "cycle_converged", "flat_since"]


@dataclass
class Records:
    """Adaptive stress records: times, values, and per-window min, max and time mean."""

    t: np.ndarray
    sigma: np.ndarray
    sigma_min: np.ndarray
    sigma_max: np.ndarray
    sigma_mean: np.ndarray

    @classmethod
    def empty(cls) -> "Records":
        z = np.zeros(0)
        return cls(z, z, z, z, z)

    @classmethod
    def from_array(cls, a: np.ndarray) -> "Records":
        return cls(a[:, 0].copy(), a[:, 1].copy(), a[:, 2].copy(), a[:, 3].copy(), a[:, 4].copy())

    def extend(self, other: "Records") -> "Records":
        return Records(*(np.concatenate([getattr(self, f), getattr(other, f)]) for f in
                         ("t", "sigma", "sigma_min", "sigma_max", "sigma_mean")))

    def since(self, t0: float) -> "Records":
        keep = self.t > t0
        return Records(self.t[keep], self.sigma[keep], self.sigma_min[keep], self.sigma_max[keep],
                       self.sigma_mean[keep])

    def __len__(self) -> int:
        return int(self.t.size)

    def time_mean(self, t0: float, t1: float) -> float:
        """Time average of the stress over (t0, t1], from the windows that lie inside it."""
        if self.t.size < 2:
            return float("nan")
        starts = np.concatenate([[self.t[0]], self.t[:-1]])
        length = self.t - starts
        inside = (starts >= t0) & (self.t <= t1) & (length > 0.0)
        total = float(np.sum(length[inside]))
        if total <= 0.0:
            return float("nan")
        return float(np.sum(length[inside] * self.sigma_mean[inside]) / total)

    def to_frame(self) -> pd.DataFrame:
        return pd.DataFrame({"t": self.t, "sigma": self.sigma, "sigma_min": self.sigma_min,
                             "sigma_max": self.sigma_max, "sigma_mean": self.sigma_mean})


def _turning_points(s: np.ndarray, hysteresis: float) -> tuple[list[int], list[int]]:
    """Indices of the peaks and troughs of ``s``.

    A peak is confirmed once ``s`` has fallen ``hysteresis`` below it, a trough once it
    has risen ``hysteresis`` above it; smaller wiggles are ignored.
    """
    peaks: list[int] = []
    troughs: list[int] = []
    i_max = i_min = 0
    state = 0  # +1 rising (looking for a peak), -1 falling (looking for a trough), 0 undecided
    for i in range(1, s.size):
        v = s[i]
        if state >= 0 and v > s[i_max]:
            i_max = i
        if state <= 0 and v < s[i_min]:
            i_min = i
        if state >= 0 and s[i_max] - v >= hysteresis:
            peaks.append(i_max)
            state, i_min = -1, i
        elif state <= 0 and v - s[i_min] >= hysteresis:
            troughs.append(i_min)
            state, i_max = 1, i
    return peaks, troughs


def find_cycles(rec: Records, hysteresis: float) -> pd.DataFrame:
    """Cycles of the stress, from one peak to the next.

    Returns one row per complete cycle with ``t_start, t_end, period, sigma_max`` (the
    peak that starts it), ``sigma_min`` (the lowest value before the next peak) and
    ``sigma_mean`` (the time average over the cycle).
    """
    cols = ["t_start", "t_end", "period", "sigma_max", "sigma_min", "sigma_mean"]
    if len(rec) < 3:
        return pd.DataFrame(columns=cols)
    peaks, troughs = _turning_points(rec.sigma, hysteresis)
    rows = []
    troughs_arr = np.asarray(troughs, dtype=int)
    for a, b in zip(peaks[:-1], peaks[1:]):
        between = troughs_arr[(troughs_arr > a) & (troughs_arr < b)]
        if between.size == 0:
            continue
        lo = float(rec.sigma[between].min())
        rows.append((rec.t[a], rec.t[b], rec.t[b] - rec.t[a], float(rec.sigma[a]), lo,
                     rec.time_mean(rec.t[a], rec.t[b])))
    return pd.DataFrame(rows, columns=cols)


def cycle_converged(cycles: pd.DataFrame, rtol: float, atol: float, n: int = 3) -> bool:
    """True when the last ``n`` cycles agree: sigma_max and sigma_min within
    ``rtol * amplitude + atol`` and the period within ``rtol * period`` (the paper's
    criterion, with rtol = 1e-2, is on the stress drop of three consecutive shocks)."""
    if len(cycles) < n:
        return False
    last = cycles.iloc[-n:]
    amplitude = float((last.sigma_max - last.sigma_min).mean())
    tol_s = rtol * amplitude + atol
    ok_max = float(last.sigma_max.max() - last.sigma_max.min()) <= tol_s
    ok_min = float(last.sigma_min.max() - last.sigma_min.min()) <= tol_s
    ok_period = float(last.period.max() - last.period.min()) <= rtol * float(last.period.mean())
    return bool(ok_max and ok_min and ok_period)


def flat_since(rec: Records, t0: float, tolerance: float) -> bool:
    """True when every recorded stress value after ``t0`` lies within ``tolerance`` of
    every other (max - min <= tolerance), and there are records after ``t0``."""
    keep = rec.t > t0
    if not np.any(keep):
        return False
    hi = float(max(rec.sigma_max[keep].max(), rec.sigma[keep].max()))
    lo = float(min(rec.sigma_min[keep].min(), rec.sigma[keep].min()))
    return hi - lo <= tolerance
