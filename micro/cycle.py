r"""Stick-slip cycles with total global shocks, solved as a fixed point of their return map.

At small k0 a stick-slip cycle is a long loading phase ended by a global shock that
makes every block jump many times (docs/reference/micro_model.md §5).  During the shock
the dashpots are frozen, so every block keeps its delta_R; with exponential jumps every
block that jumped leaves with a margin delta ~ Exp(kappa zbar), independent of the rest
(no memory).  When the shock is total (the mass it leaves unjumped is below
``UNJUMPED_TOL``), the state after it is therefore

.. math:: P(\delta, \delta_R) = \frac{e^{-\delta/\kappa\bar z}}{\kappa\bar z}\, p(\delta_R),

and one cycle is a map :math:`p \mapsto \Phi(p)` of the 1-D marginal of delta_R alone
(kept as masses on nodes of spacing eps, each atom shared linearly between its two
nodes).  The Fokker-Planck equation (:mod:`micro.grid`) carries the product state
through the loading phase; the step in which the next shock starts is replayed in steps
``FINE`` times shorter, so that where the shock starts does not depend on where the
loading's steps fell; the kernel stops ``SHOCK_BINS`` bins into the shock, where every
delta_R still has its value (jumps keep u), and that marginal is the image.  The shock
itself is never time-stepped: its extent, solved in closed form (:func:`_shock`), only
tells whether it was total.  So a cycle costs the same at k0 = 1e-4 as at k0 = 0.01,
where time-stepping pays for a shock of ~0.06 / k0 mean jumps in every cycle.

The limit cycle is the fixed point :math:`p = \Phi(p)`.  It is found by iterating the
map from the first shock's image: the marginal relaxes by about 0.8 per cycle (a
block's lag survives a shock only through ``k2 u``, a factor ~ k2/kappa, and the
variance decays as its square), so 20-30 cycles are needed.  Anderson acceleration
was tried and stalls: the map is continuous only to the grid's resolution (where a
near-critical avalanche closes or runs away depends on single cells: jumps of
sigma_max of ~k0 eps, 1e-4 at k0 = 0.01, eps = 0.016, measured), which extrapolation
amplifies.  ``sigma_max`` is the stress at the start of the shock, ``sigma_min`` the
stress of the product state (``micro.sigma_fast_limit`` when every dashpot term averages
to 0, as at the fixed point, to the cells' eps^2 / (12 kappa zbar)), the period the
loading time.

The shock in closed form: a block of margin delta jumps once the common shift s reaches
delta, and then as a Poisson process of rate 1/(kappa zbar) in s, so the shift closes
at the first root of

.. math:: F(s) = s_0 + (k_1+k_2)\bar z\, E\left[1_{\delta<s}\left(1 + \frac{s-\delta}{\kappa\bar z}\right)\right] - s,

with :math:`s_0` the shift the kernel still owes where it stopped, SHOCK_BINS bins into the shock.
"""
from __future__ import annotations

import logging
import math
import time
from dataclasses import field, dataclass

import numpy as np

from . import _kernels as K
from .grid import Grid, GridSettings
from .params import KIND_EXPONENTIAL, Model

__all__ = ["CycleFixedPoint", "cycle_fixed_point"]

log = logging.getLogger(__name__)

#: A cascade that shifts more than this many bins is a global shock (as in ``stationary``).
SHOCK_BINS = 8.0
#: Largest mass a shock may leave unjumped for the product form to hold: that mass keeps
#: a margin of order 1 instead of Exp(kappa zbar), so the stress after the shock is off
#: by less than about this.
UNJUMPED_TOL = 1e-6
#: The loading runs in chunks of this many steps (a copy of the grid is kept at each
#: chunk's start); the step in which a shock starts is replayed in steps FINE times shorter.
CHUNK = 32
FINE = 64
#: Node masses below this are dropped from an iterate (round-off in nodes the density
#: never reaches would otherwise widen the grid).
MASS_FLOOR = 1e-15
#: Tail mass of Exp(kappa zbar) dropped beyond the last cell.
EXP_TAIL = 1e-16


@dataclass
class CycleFixedPoint:
    """The limit cycle at one bin ``eps``: extrema, period, and how the iteration ended.

    ``error`` estimates the distance of sigma_max and sigma_min from the fixed point at
    this eps, including half a fine step's drive (it is not the discretisation error of
    eps); ``unjumped`` is the mass the last shock left unjumped (the product form needs
    it below ``UNJUMPED_TOL``); ``applicable`` is False when a loading phase ended
    without a global shock or a shock was not total (the map does not describe such
    cycles); ``history`` holds the rows (sigma_max, sigma_min, period, sigma_mean) of
    every cycle (the cohort method adds sigma_before and sigma_after), ``p`` the delta_R
    marginal (nodes, masses).  The cohort method only: ``state``, the whole state after
    the last shock, from which a run at a nearby V or at half the cell continues;
    ``sigma_before`` and ``sigma_after``, the stress when the shock starts and right
    after it (the paper's sigma_B and sigma_A: ``sigma_max`` is the largest stress of
    the cycle, which the creep before a shock can put above ``sigma_before``).
    """

    model: Model
    V: float
    eps: float
    sigma_max: float
    sigma_min: float
    period: float
    sigma_mean: float
    mass_error: float
    min_mass: float
    iterations: int
    error: float
    unjumped: float
    converged: bool
    message: str
    wall_time: float
    applicable: bool = True
    history: np.ndarray | None = None
    p: tuple[np.ndarray, np.ndarray] | None = None
    state: object | None = field(default=None, repr=False)
    sigma_before: float = math.nan
    sigma_after: float = math.nan


# ------------------------------------------------------------------------------ the product state
def _product_grid(model: Model, settings: GridSettings, j: np.ndarray, mass: np.ndarray, eta: np.ndarray) -> Grid:
    """The grid of the state after a total shock: delta ~ Exp(kappa zbar) in every row
    ``j`` of delta_R, with the row masses ``mass`` at offsets ``eta`` (``(j + eta) eps``).
    Cell d of row j holds delta in ``[(d + eta) eps, (d + 1 + eta) eps)``: its mass is the
    exact Exp mass there, and the cell that straddles delta = 0 is filled only above it."""
    eps = settings.eps
    lam = model.kappa * model.zbar
    n_col = int(math.ceil(lam * math.log(1.0 / EXP_TAIL) / eps)) + 2
    d = np.arange(-1, n_col)
    lo = np.maximum((d[None, :] + eta[:, None]) * eps, 0.0)
    hi = np.maximum((d[None, :] + 1 + eta[:, None]) * eps, 0.0)
    w = (np.exp(-lo / lam) - np.exp(-hi / lam)) * mass[:, None]
    w[:, -1] += np.exp(-hi[:, -1] / lam) * mass  # the tail joins the last cell
    omega = np.clip(d[None, :] + 1 + eta[:, None], 1e-300, 1.0)  # the cell straddling delta = 0 is filled above it
    jj = np.broadcast_to(j[:, None], w.shape)
    ee = np.broadcast_to(eta[:, None], w.shape)
    dd = np.broadcast_to(d[None, :], w.shape)
    return Grid.from_cells(model, settings, jj, ee, dd, w, omega)


def _rows(delta_R: np.ndarray, mass: np.ndarray, eps: float, j_lo: int, n_rows: int) -> tuple[np.ndarray, float]:
    """The delta_R marginal as masses on the nodes ``(j_lo + i) eps``, each atom shared
    linearly between its two neighbours (mass and first moment kept; the map is then
    continuous in the atoms' positions); also the mass that fell outside the nodes."""
    u = delta_R / eps - j_lo
    i = np.floor(u).astype(np.int64)
    f = u - i
    x = np.zeros(n_rows)
    outside = 0.0
    for idx, w in ((i, mass * (1.0 - f)), (i + 1, mass * f)):
        inside = (idx >= 0) & (idx < n_rows)
        np.add.at(x, idx[inside], w[inside])
        outside += float(w[~inside].sum())
    return x, outside


def _shock(cells: dict, owed: float, model: Model) -> tuple[float, float]:
    """The shift that closes a shock from the cells' margins, and the mass it leaves
    unjumped (exponential jumps, mean field): the first root of F (module docstring).
    Between margins F falls with slope ``(k1 + k2)/kappa * P(delta < s) - 1 < 0`` and it
    rises by ``(k1 + k2) zbar m`` at each margin."""
    order = np.argsort(cells["delta"])
    delta = cells["delta"][order]
    m = cells["mass"][order] / cells["mass"].sum()
    c = (model.k1 + model.k2) * model.zbar
    r = (model.k1 + model.k2) / model.kappa
    P = np.concatenate(([0.0], np.cumsum(m)))  # mass below each margin
    Q = np.concatenate(([0.0], np.cumsum(m * delta)))
    # on segment i (between margins i-1 and i) F(s) = owed + c P_i + r (P_i s - Q_i) - s
    s_end = np.append(delta, np.inf)
    s_root = (owed + c * P - r * Q) / (1.0 - r * P)
    s_start = np.concatenate(([0.0], delta))
    ok = (s_root >= s_start) & (s_root <= s_end)
    i = int(np.argmax(ok))
    s = float(s_root[i])
    return s, float(1.0 - P[i])


# ------------------------------------------------------------------------------ the return map
class _Map:
    """Phi on the delta_R marginal (rows ``j_lo ... j_lo + n_rows``), with its outputs."""

    def __init__(self, model: Model, settings: GridSettings, V: float, t_max: float, j_lo: int) -> None:
        self.model, self.settings, self.V, self.t_max, self.j_lo = model, settings, V, t_max, j_lo

    def __call__(self, x: np.ndarray) -> dict:
        rows = np.flatnonzero(x > 0.0)
        grid = _product_grid(self.model, self.settings, rows + self.j_lo, x[rows], np.zeros(rows.size))
        sigma_start = grid.sigma
        # load in chunks of CHUNK steps; when a chunk starts the shock, replay it from its
        # start to the step before, and that step in steps FINE times shorter: the shock
        # then starts within a drive of theta_shift / FINE bins of where a continuous
        # drive would start it (a step's cascade runs past SHOCK_BINS only once the
        # branching ratio at the threshold exceeds 1 - drive / SHOCK_BINS)
        self._integral = 0.0
        while True:
            t0, start = grid.t, grid.copy()
            rec, shocks, code = self._advance(grid, self.t_max, max_steps=CHUNK)
            if not len(shocks):
                self._integral += _time_integral(rec, t0)
                if code == K.MAX_STEPS:
                    continue
                return dict(ok=False, message=f"no global shock by t = {grid.t:.4g} (kernel code {code})")
            t_shock = float(shocks[0, 0])
            ends = np.unique(rec[rec[:, 0] < t_shock, 0])  # every step writes one record
            grid = start
            if ends.size:
                rec, _, _ = self._advance(grid, float(ends[-1]), max_steps=ends.size)
                self._integral += _time_integral(rec, t0)
            t1 = grid.t
            grid.prm[K.P_THETA_S] = self.settings.theta_shift / FINE
            rec, shocks, code = self._advance(grid, self.t_max)
            if not len(shocks):
                return dict(ok=False, message=f"the shock did not repeat in the finer steps (kernel code {code})")
            earlier = rec[rec[:, 0] < grid.t]  # the fine steps before the one the shock starts in
            self._integral += _time_integral(earlier, t1)
            break
        quantum = self.model.k0 * self.V * (grid.t - (float(earlier[-1, 0]) if len(earlier) else t1))
        sigma_max = float(shocks[0, 1])
        cells = grid.cells()
        s, unjumped = _shock(cells, float(grid.fst[K.F_OWED]) * self.settings.eps, self.model)
        x_new, outside = _rows(cells["delta_R"], cells["mass"], self.settings.eps, self.j_lo, x.size)
        return dict(ok=True, x=x_new, outside=outside, sigma_max=sigma_max, sigma_min=sigma_start,
                    period=grid.t, sigma_mean=self._integral / grid.t, shift=s, unjumped=unjumped, quantum=quantum,
                    mass_error=abs(grid.mass() - 1.0), min_mass=min(grid.min_mass(), 0.0))

    def _advance(self, grid: Grid, t_stop: float, max_steps: int = 1 << 62) -> tuple[np.ndarray, np.ndarray, int]:
        """Advance with a record at every step, stopping SHOCK_BINS into a shock."""
        return grid.advance(self.V, t_stop, record_dsigma=math.inf, record_dt=0.0, shock_bins=SHOCK_BINS,
                            stop_shift=SHOCK_BINS + 1e-9, max_steps=max_steps)


def _time_integral(rec: np.ndarray, t0: float) -> float:
    """Time integral of the stress over records written at every step since ``t0``
    (each row's last column is the mean since the previous row)."""
    if len(rec) == 0:
        return 0.0
    return float(np.sum(rec[:, 4] * np.diff(np.concatenate(([t0], rec[:, 0])))))


def _initial_marginal(model: Model, eps: float, j_lo: int, n_rows: int) -> np.ndarray:
    """A start: every dashpot relaxed to the lag of an Exp(kappa zbar) margin, the
    marginal of ``(k2 / kappa) (<delta> - delta)`` (the first shock's image)."""
    lam = model.kappa * model.zbar
    delta = (np.arange(4000) + 0.5) * (lam * 40.0 / 4000)
    w = np.exp(-delta / lam)
    y = model.k2 / model.kappa * (lam - delta)
    x, _ = _rows(y, w / w.sum(), eps, j_lo, n_rows)
    return x


def cycle_fixed_point(model: Model, V: float, eps: float, *, tol: float = 1e-5, max_iter: int = 200,
                      n: int = 10, start: CycleFixedPoint | None = None, theta_shift: float = 0.5,
                      theta_relax: float = 0.5) -> CycleFixedPoint:
    """The stick-slip limit cycle at drive velocity ``V`` and bin ``eps`` as the fixed
    point of the shock-to-shock return map (module docstring), by iterating the map.

    Each evaluation is one loading phase on the Fokker-Planck grid, and no shock is
    time-stepped, so the cost per cycle does not grow as k0 falls.  The iteration stops
    when the last ``n`` cycles show no significant drift (fitted slope times ``n`` below
    twice its standard error plus ``tol / 4``) and the error is below ``tol``; the
    result is their mean.  The error is the standard error of that mean combined with
    the drift, plus half the stress the drive adds in one of the finer steps in which
    the shock's start is found.  It is the error of the fixed point at this eps, not
    the discretisation error of eps.  At most ``max_iter`` evaluations.  ``start`` (a
    result at another eps or V) seeds the marginal.
    Needs exponential jumps and total shocks; otherwise the result says so
    (``converged=False``) and :func:`micro.stationary`'s time-stepping applies.
    """
    begin = time.perf_counter()
    if model.jumps.kind != KIND_EXPONENTIAL:
        raise ValueError("the cycle method needs exponential jumps (the shock's product form is exact only for them)")
    for name, value in (("V", V), ("eps", eps), ("tol", tol)):
        if not (math.isfinite(value) and value > 0.0):
            raise ValueError(f"{name} must be a finite number > 0, got {value!r}")
    if int(n) != n or n < 4 or int(max_iter) != max_iter or max_iter < n + 1:
        raise ValueError(f"n must be an integer >= 4 and max_iter an integer > n, got n={n!r}, max_iter={max_iter!r}")
    settings = GridSettings(eps=eps, theta_shift=theta_shift, theta_relax=theta_relax, dt_max=math.inf)
    settings.check(model)
    lam = model.kappa * model.zbar
    # delta_R relaxes towards (k2/kappa)(<delta_F> - delta_F), and the margins reach
    # ~37 kappa zbar (the 1e-16 tail of Exp): nodes for |delta_R| <= 45 k2 zbar
    half = int(math.ceil(45.0 * model.k2 * model.zbar / eps)) + 8
    j_lo, n_rows = -half, 2 * half
    if start is not None and start.p is not None:
        x, _ = _rows(start.p[0], start.p[1], eps, j_lo, n_rows)
    else:
        x = _initial_marginal(model, eps, j_lo, n_rows)
    # a loading phase raises the stress from about f_th - kappa zbar to below f_th at a
    # rate that creep lowers from k0 V: allow 20 times kappa zbar / (k0 V)
    phi = _Map(model, settings, V, t_max=20.0 * lam / (model.k0 * V), j_lo=j_lo)
    hist: list[tuple[float, float, float, float]] = []
    out: dict = {}
    error = math.nan
    converged, message, applicable = False, "", True
    for it in range(1, max_iter + 1):
        x = np.where(x > MASS_FLOOR, x, 0.0)
        x /= x.sum()
        out = phi(x)
        if not out["ok"]:
            message, applicable = out["message"], False
            break
        if out["unjumped"] > UNJUMPED_TOL:
            applicable = False
            message = (f"the shock left {out['unjumped']:.2g} of the mass unjumped (> {UNJUMPED_TOL:g}): "
                       f"not a total shock, so the state after it is not a product; use method='fp'")
            break
        if out["outside"] > 1e-12:
            message = f"the delta_R marginal left the nodes ({out['outside']:.2g} of the mass)"
            break
        hist.append((out["sigma_max"], out["sigma_min"], out["period"], out["sigma_mean"]))
        x = out["x"]
        log.debug("cycle %d: sigma_max %.10f sigma_min %.10f", it, out["sigma_max"], out["sigma_min"])
        if len(hist) >= n:
            mean, sem, drift, drift_err = _window(np.array(hist)[:, :2], n)
            settled = bool(np.all(drift <= 2.0 * drift_err + 0.25 * tol))
            # (the shock's start is resolved to the drive of one of the finer steps)
            error = float(np.max(np.hypot(sem, drift))) + 0.5 * out["quantum"]
            # converged: no significant drift over the window and a small enough error
            if settled and error <= tol:
                converged = True
                message = (f"limit cycle of the return map: the last {n} cycles (of {it}) agree, sigma_max and "
                           f"sigma_min to {error:.1e} (standard error, drift, half a fine step's drive)")
                break
    else:
        message = f"no fixed point to {tol:g} in {max_iter} cycles (error estimate {error:.2g})"
    ok = bool(hist) and out.get("ok", False)
    values = np.array(hist).reshape(-1, 4)
    last = values[-min(n, len(values)):].mean(axis=0) if len(values) else np.full(4, math.nan)
    res = CycleFixedPoint(
        model=model, V=V, eps=eps, sigma_max=float(last[0]), sigma_min=float(last[1]), period=float(last[2]),
        sigma_mean=float(last[3]), mass_error=out.get("mass_error", math.nan), min_mass=out.get("min_mass", math.nan),
        iterations=len(hist), error=error, unjumped=out.get("unjumped", math.nan),
        converged=converged, message=message, wall_time=time.perf_counter() - begin, applicable=applicable,
        history=values)
    if ok:
        keep = x > 0.0
        res.p = ((np.arange(n_rows)[keep] + j_lo) * eps, x[keep])
    return res


def _window(values: np.ndarray, n: int) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """Over the last ``n`` rows of ``values`` (one column per quantity): the means, their
    standard errors, and the drift (fitted slope times n) with its standard error."""
    w = values[-n:]
    k = np.arange(n) - 0.5 * (n - 1)
    slope = k @ (w - w.mean(axis=0)) / (k @ k)
    resid = w - w.mean(axis=0) - np.outer(k, slope)
    s2 = (resid ** 2).sum(axis=0) / (n - 2)
    return w.mean(axis=0), np.sqrt(w.var(axis=0, ddof=1) / n), np.abs(slope) * n, np.sqrt(s2 / (k @ k)) * n
