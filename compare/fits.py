r"""Fits that connect the microscopic model to rate-and-state friction.

* :func:`fit_steady_law` — the paper's Eq. (10), :math:`\mu_{ss} = \mu_\infty + A/(V + B)`,
  fitted to micro's steady branch: one (A, B) shared by every k0 of a (k1, k2, zbar)
  set and one offset :math:`\mu_\infty` per k0 (the paper: k0 only shifts the curve).
* :func:`fit_dc` — the critical slip distance D_c that makes the RS bifurcation diagram
  (σ_max, σ_min against V) closest to micro's; D_c enters only as k0·D_c.
* :func:`dc_from_critical_velocity` — the closed form that matches the RS critical
  velocity to micro's, k0·D_c = W(V^c) = A V^c/(V^c + B)^2.
* :func:`fit_power_law` — the Hopf scaling σ_max − σ_min ∝ (V^c − V)^β, with V^c given or
  fitted.
* :func:`fit_growth_law` — the three growth laws of the slide-hold-slide peak.
"""
from __future__ import annotations

import logging
import math
from dataclasses import dataclass, field
from typing import Callable, Sequence

import numpy as np
import pandas as pd
from scipy.optimize import brentq, curve_fit, least_squares, minimize_scalar

import rsf

from ._validation import choice, in_range, positive

__all__ = [
    "SteadyLawFit",
    "fit_steady_law",
    "DcFit",
    "fit_dc",
    "rs_diagram",
    "dc_from_critical_velocity",
    "PowerLawFit",
    "fit_power_law",
    "GrowthFit",
    "GROWTH_LAWS",
    "fit_growth_law",
]

log = logging.getLogger(__name__)


# ============================================================================ steady law
@dataclass
class SteadyLawFit:
    r"""Eq. (10) fitted to a steady branch: shared A, B; one offset per k0.

    Attributes
    ----------
    A, B, A_err, B_err : float
        The fitted constants and their standard errors (from the Jacobian at the optimum,
        scaled by the residual variance).
    offsets : DataFrame
        One row per k0: ``k0, mu_inf, mu_inf_err, n_points`` and, when the fit was given
        a model description, ``fast_limit`` (:func:`micro.sigma_fast_limit`) and
        ``paper_offset`` (:math:`f_{th} - \kappa\bar z/2`, the paper's Eq. (6)).
    residuals : DataFrame
        The points used, with the fitted value and the residual.
    rms : float
        Root-mean-square residual.
    offset_mode : str
        ``'free'`` (fitted per k0), ``'fast_limit'`` or ``'paper'`` (held fixed).
    """

    A: float
    B: float
    A_err: float
    B_err: float
    offsets: pd.DataFrame
    residuals: pd.DataFrame
    rms: float
    offset_mode: str
    n_points: int
    params: dict = field(default_factory=dict)

    def mu_inf(self, k0: float) -> float:
        """The offset for ``k0`` (which must be one of the fitted k0)."""
        rows = self.offsets[np.isclose(self.offsets.k0, k0, rtol=1e-12, atol=0.0)]
        if rows.empty:
            raise ValueError(f"k0 = {k0!r} has no fitted offset; fitted k0: {sorted(self.offsets.k0)}")
        return float(rows.mu_inf.iloc[0])

    def law(self, k0: float | None = None, *, mu_inf: float | None = None) -> rsf.HyperbolicLaw:
        """The fitted Eq. (10) as an :class:`rsf.HyperbolicLaw` with the offset of ``k0``
        (or the given ``mu_inf``)."""
        if mu_inf is None:
            if k0 is None:
                raise ValueError("give k0 (a fitted one) or mu_inf")
            mu_inf = self.mu_inf(k0)
        return rsf.HyperbolicLaw(A=self.A, B=self.B, mu_inf=mu_inf)

    def predict(self, k0: float, V) -> np.ndarray:
        V = np.asarray(V, dtype=float)
        return self.mu_inf(k0) + self.A / (V + self.B)

    def to_frame(self) -> pd.DataFrame:
        """One row per k0 with A, B (shared) and the offset."""
        out = self.offsets.copy()
        out.insert(1, "A", self.A)
        out.insert(2, "A_err", self.A_err)
        out.insert(3, "B", self.B)
        out.insert(4, "B_err", self.B_err)
        out["rms"] = self.rms
        out["offset_mode"] = self.offset_mode
        return out


def _steady_points(frame: pd.DataFrame, *, converged_only: bool) -> pd.DataFrame:
    need = {"k0", "V", "regime", "sigma_mean"}
    missing = need - set(frame.columns)
    if missing:
        raise ValueError(f"frame must have columns {sorted(need)}; missing {sorted(missing)}")
    sel = frame.regime == "steady"
    if converged_only and "converged" in frame.columns:
        sel &= frame.converged.astype(bool)
    pts = frame.loc[sel & np.isfinite(frame.sigma_mean) & (frame.V > 0)].copy()
    return pts


def fit_steady_law(frame: pd.DataFrame, *, offset: str = "free", fixed_offsets: dict | None = None,
                   converged_only: bool = True, B_bounds: tuple[float, float] = (1e-4, 1e2)) -> SteadyLawFit:
    r"""Fit Eq. (10) to the steady rows of a micro sweep.

    .. math:: \sigma_i = \mu_\infty(k_{0,i}) + \frac{A}{V_i + B}

    For a fixed B the model is linear in A and the offsets, so the fit is a 1-D bounded
    minimisation over :math:`\ln B` of the linear least-squares residual (variable
    projection): robust, no starting guess.

    Parameters
    ----------
    frame : DataFrame
        Rows with ``k0, V, regime, sigma_mean`` (and ``converged``), e.g. from
        :func:`compare.micro_sweep`; only ``regime == 'steady'`` rows are used.
    offset : {'free', 'fixed'}
        ``'free'``: one fitted offset per k0.  ``'fixed'``: offsets from ``fixed_offsets``
        (a dict k0 -> mu_inf), only A and B fitted.
    converged_only : bool
        Skip steady rows whose run did not meet its convergence test (default True).
    B_bounds : (float, float)
        Search range of B, > 0.

    Returns
    -------
    SteadyLawFit
    """
    offset = choice("offset", offset, ("free", "fixed"))
    lo, hi = positive("B_bounds[0]", B_bounds[0]), positive("B_bounds[1]", B_bounds[1])
    if not hi > lo:
        raise ValueError(f"B_bounds must be increasing, got {B_bounds!r}")
    pts = _steady_points(frame, converged_only=converged_only)
    k0s = sorted(pts.k0.unique())
    V = pts.V.to_numpy(float)
    y = pts.sigma_mean.to_numpy(float)
    group = np.searchsorted(k0s, pts.k0.to_numpy(float))
    n_off = len(k0s) if offset == "free" else 0
    n_par = 2 + n_off
    if len(pts) < n_par + 1:
        raise ValueError(f"need at least {n_par + 1} steady points for {n_par} parameters, got {len(pts)} "
                         f"(steady, converged rows of frame)")
    if offset == "fixed":
        if fixed_offsets is None:
            raise ValueError("offset='fixed' needs fixed_offsets, a dict k0 -> mu_inf")
        try:
            shift = np.array([float(fixed_offsets[k]) for k in pts.k0])
        except KeyError as exc:
            raise ValueError(f"fixed_offsets has no entry for k0 = {exc.args[0]!r}") from None
    else:
        shift = np.zeros_like(y)

    def design(B: float) -> np.ndarray:
        cols = [1.0 / (V + B)]
        if offset == "free":
            onehot = np.zeros((len(V), n_off))
            onehot[np.arange(len(V)), group] = 1.0
            cols.extend(onehot.T)
        return np.column_stack(cols)

    def linear(B: float) -> tuple[np.ndarray, float]:
        X = design(B)
        coef, *_ = np.linalg.lstsq(X, y - shift, rcond=None)
        r = y - shift - X @ coef
        return coef, float(r @ r)

    grid = np.linspace(math.log(lo), math.log(hi), 161)
    rss = np.array([linear(math.exp(g))[1] for g in grid])
    i = int(np.argmin(rss))
    a, b = grid[max(i - 1, 0)], grid[min(i + 1, len(grid) - 1)]
    opt = minimize_scalar(lambda g: linear(math.exp(g))[1], bounds=(a, b), method="bounded",
                          options={"xatol": 1e-10})
    B = float(math.exp(opt.x))
    coef, rss_min = linear(B)
    A = float(coef[0])
    offsets_fit = coef[1:] if offset == "free" else None
    if i in (0, len(grid) - 1):
        log.warning("fit_steady_law: B = %.4g sits at the bound of B_bounds %s", B, B_bounds)
    # Jacobian of the full nonlinear model for the standard errors
    J = np.column_stack([1.0 / (V + B), -A / (V + B) ** 2] + (list(design(B)[:, 1:].T) if offset == "free" else []))
    dof = len(y) - n_par
    s2 = rss_min / dof
    try:
        cov = np.linalg.inv(J.T @ J) * s2
        errs = np.sqrt(np.clip(np.diag(cov), 0.0, None))
    except np.linalg.LinAlgError:
        errs = np.full(n_par, math.nan)
    fitted = (shift + design(B) @ coef)
    resid = pts.assign(fitted=fitted, residual=y - fitted)[["k0", "V", "sigma_mean", "fitted", "residual"]]
    rows = []
    for j, k0 in enumerate(k0s):
        n = int(np.sum(group == j))
        if offset == "free":
            mu, mu_err = float(offsets_fit[j]), float(errs[2 + j])
        else:
            mu, mu_err = float(fixed_offsets[k0]), 0.0
        rows.append({"k0": float(k0), "mu_inf": mu, "mu_inf_err": mu_err, "n_points": n})
    return SteadyLawFit(A=A, B=B, A_err=float(errs[0]), B_err=float(errs[1]) * 1.0,
                        offsets=pd.DataFrame(rows), residuals=resid.reset_index(drop=True),
                        rms=math.sqrt(rss_min / len(y)), offset_mode=offset, n_points=len(y))


# ============================================================================ RS diagram
def rs_diagram(points: pd.DataFrame, law_for: Callable[[float], rsf.SteadyStateLaw], Dc: float, *,
               options: rsf.SolverOptions | None = None) -> pd.DataFrame:
    """RS attractors at the (k0, V) of ``points`` (columns ``k0, V``) with the law
    ``law_for(k0)`` and critical slip distance ``Dc``.

    Returns ``k0, V, regime, sigma_max, sigma_min, sigma_mean, converged, status`` per row.
    """
    Dc = positive("Dc", Dc)
    options = options or rsf.SolverOptions(cycle_rtol=1e-7, rtol=1e-8)
    rows = []
    models: dict[float, rsf.SpringSlider] = {}
    for k0, V in zip(points.k0.to_numpy(float), points.V.to_numpy(float)):
        model = models.get(k0)
        if model is None:
            model = models[k0] = rsf.SpringSlider(law=law_for(k0), k0=k0, Dc=Dc)
        r = rsf.limit_cycle(model, V, options=options)
        rows.append({"k0": k0, "V": V, "regime": r.regime, "sigma_max": r.sigma_max, "sigma_min": r.sigma_min,
                     "sigma_mean": r.sigma_mean, "converged": r.converged, "status": r.status})
    return pd.DataFrame(rows)


def dc_from_critical_velocity(A: float, B: float, k0: float, Vc: float) -> float:
    r"""The D_c at which the RS critical velocity (Eq. 10 law) equals ``Vc``:

    .. math:: k_0 D_c = W(V^c) = \frac{A V^c}{(V^c + B)^2}

    (the upper root V_+ of the stability boundary; valid for :math:`V^c > B`)."""
    A, B, k0, Vc = positive("A", A), positive("B", B), positive("k0", k0), positive("Vc", Vc)
    if Vc <= B:
        raise ValueError(f"Vc must be > B = {B!r} to be the upper root V_+ of W(V) = k0 Dc, got {Vc!r}")
    return A * Vc / (Vc + B) ** 2 / k0


@dataclass
class DcFit:
    r"""The critical slip distance that best matches the bifurcation diagrams.

    Attributes
    ----------
    Dc : float
        Least-squares optimum of the stress residual over the points.
    Dc_err : float
        Standard error: half the width of the bootstrap 16-84 % interval (resampling the
        points); ``Dc_profile`` is the profile interval where
        :math:`RSS \le RSS_{min}(1 + 1/(n-1))`.
    rms : float
        Root-mean-square residual at the optimum (stress units), over the 2n values
        (σ_max and σ_min of each point); ``rms_per_k0`` splits it by k0.
    profile : DataFrame
        ``Dc, rss, rms`` on the scan grid.
    points : DataFrame
        The micro points used with the RS values at the optimum and the residuals.
    """

    Dc: float
    Dc_err: float
    Dc_profile: tuple[float, float]
    Dc_bootstrap: tuple[float, float]
    rms: float
    rms_per_k0: pd.DataFrame
    profile: pd.DataFrame
    points: pd.DataFrame
    n_points: int
    regime_agreement: float
    bootstrap: np.ndarray = field(repr=False, default_factory=lambda: np.zeros(0))

    def to_frame(self) -> pd.DataFrame:
        return pd.DataFrame([{"Dc": self.Dc, "Dc_err": self.Dc_err, "Dc_profile_low": self.Dc_profile[0],
                              "Dc_profile_high": self.Dc_profile[1], "Dc_bootstrap_16": self.Dc_bootstrap[0],
                              "Dc_bootstrap_84": self.Dc_bootstrap[1], "rms": self.rms,
                              "n_points": self.n_points, "regime_agreement": self.regime_agreement}])


def _diagram_points(frame: pd.DataFrame, converged_only: bool) -> pd.DataFrame:
    need = {"k0", "V", "regime", "sigma_max", "sigma_min"}
    missing = need - set(frame.columns)
    if missing:
        raise ValueError(f"frame must have columns {sorted(need)}; missing {sorted(missing)}")
    sel = frame.regime.isin(["steady", "stick-slip"]) & np.isfinite(frame.sigma_max) & np.isfinite(frame.sigma_min)
    if converged_only and "converged" in frame.columns:
        sel &= frame.converged.astype(bool)
    return frame.loc[sel].reset_index(drop=True)


def fit_dc(frame: pd.DataFrame, law_for: Callable[[float], rsf.SteadyStateLaw], *,
           bounds: tuple[float, float] = (1e-3, 1.0), n_grid: int = 49, n_bootstrap: int = 400,
           converged_only: bool = True, seed: int = 0,
           options: rsf.SolverOptions | None = None) -> DcFit:
    r"""Fit D_c so that the RS diagram matches micro's σ_max and σ_min.

    The residual is :math:`\sum_i (\sigma^{RS}_{max} - \sigma^{micro}_{max})^2 +
    (\sigma^{RS}_{min} - \sigma^{micro}_{min})^2` over the micro points (steady rows have
    σ_max = σ_min = σ, so a regime mismatch costs the RS amplitude).  Because D_c enters
    only as k0·D_c, the problem is one-dimensional: the residual is scanned on a
    log-spaced grid of ``n_grid`` values in ``bounds`` (each point a handful of RS limit
    cycles, ~1 ms), the best grid cell is refined by a bounded scalar minimisation, and
    the uncertainty comes from the same grid: the profile interval and a bootstrap over
    the points (resampled with replacement, optimum located on the grid by a parabola).

    Parameters
    ----------
    frame : DataFrame
        Micro points with ``k0, V, regime, sigma_max, sigma_min`` (and ``converged``).
    law_for : callable
        k0 -> the RS steady-state law to use (e.g. ``fit.law`` of a :class:`SteadyLawFit`).
    bounds : (float, float)
        Search range of D_c, > 0.
    n_grid, n_bootstrap : int
        Scan resolution and number of bootstrap samples.
    """
    lo, hi = positive("bounds[0]", bounds[0]), positive("bounds[1]", bounds[1])
    if not hi > lo:
        raise ValueError(f"bounds must be increasing, got {bounds!r}")
    if int(n_grid) < 7:
        raise ValueError(f"n_grid must be an integer >= 7, got {n_grid!r}")
    pts = _diagram_points(frame, converged_only)
    if len(pts) < 3:
        raise ValueError(f"need at least 3 usable micro points (steady or stick-slip, converged), got {len(pts)}")
    target = np.concatenate([pts.sigma_max.to_numpy(float), pts.sigma_min.to_numpy(float)])

    def residuals(Dc: float) -> tuple[np.ndarray, pd.DataFrame]:
        rs = rs_diagram(pts, law_for, Dc, options=options)
        model = np.concatenate([rs.sigma_max.to_numpy(float), rs.sigma_min.to_numpy(float)])
        return model - target, rs

    grid = np.geomspace(lo, hi, int(n_grid))
    R = np.array([residuals(d)[0] for d in grid])            # (n_grid, 2 n)
    n = len(pts)
    per_point = R[:, :n] ** 2 + R[:, n:] ** 2                 # (n_grid, n)
    rss_grid = per_point.sum(axis=1)
    i = int(np.argmin(rss_grid))
    a, b = math.log(grid[max(i - 1, 0)]), math.log(grid[min(i + 1, len(grid) - 1)])
    opt = minimize_scalar(lambda g: float(np.sum(residuals(math.exp(g))[0] ** 2)), bounds=(a, b),
                          method="bounded", options={"xatol": 1e-4})
    Dc = float(math.exp(opt.x))
    r_opt, rs_opt = residuals(Dc)
    rss_min = float(r_opt @ r_opt)
    if i in (0, len(grid) - 1):
        log.warning("fit_dc: the optimum D_c = %.4g sits at the bound of %s", Dc, bounds)
    # profile interval: where RSS(D_c) <= level, located by root finding on each side of the
    # optimum (the grid alone cannot resolve a sharp minimum)
    level = rss_min * (1.0 + 1.0 / max(n - 1, 1))
    log_grid = np.log(grid)
    rss_of = lambda g: float(np.sum(residuals(math.exp(g))[0] ** 2)) - level  # noqa: E731
    g_opt = math.log(Dc)
    ends = []
    for direction in (-1, +1):
        j = i
        while 0 <= j < len(grid) and (rss_grid[j] <= level or (log_grid[j] - g_opt) * direction <= 0):
            j += direction
        if not 0 <= j < len(grid):
            ends.append(float(grid[0] if direction < 0 else grid[-1]))   # open at the search bound
            continue
        a, b = sorted((g_opt, float(log_grid[j])))
        try:
            ends.append(math.exp(brentq(rss_of, a, b, xtol=1e-6)))
        except ValueError:  # no sign change (level reached at the optimum itself)
            ends.append(Dc)
    profile_interval = (float(ends[0]), float(ends[1]))
    # bootstrap over points
    rng = np.random.default_rng(seed)
    boot = np.empty(int(n_bootstrap))
    for k in range(boot.size):
        w = np.bincount(rng.integers(0, n, n), minlength=n)
        boot[k] = math.exp(_parabolic_min(log_grid, per_point @ w))
    if boot.size:
        q16, q84 = (float(x) for x in np.quantile(boot, [0.16, 0.84]))
    else:
        q16 = q84 = math.nan
    Dc_err = 0.5 * (q84 - q16)
    out = pts[["k0", "V", "regime", "sigma_max", "sigma_min"]].copy()
    out = out.rename(columns={"regime": "regime_micro", "sigma_max": "sigma_max_micro",
                              "sigma_min": "sigma_min_micro"})
    out["regime_rs"] = rs_opt.regime.to_numpy()
    out["sigma_max_rs"] = rs_opt.sigma_max.to_numpy()
    out["sigma_min_rs"] = rs_opt.sigma_min.to_numpy()
    out["residual_max"] = r_opt[:n]
    out["residual_min"] = r_opt[n:]
    per_k0 = (out.assign(sq=out.residual_max ** 2 + out.residual_min ** 2)
              .groupby("k0").agg(n_points=("sq", "size"), sq=("sq", "sum")).reset_index())
    per_k0["rms"] = np.sqrt(per_k0.sq / (2 * per_k0.n_points))
    per_k0 = per_k0.drop(columns="sq")
    agree = float(np.mean(out.regime_rs.to_numpy() == out.regime_micro.to_numpy()))
    profile = pd.DataFrame({"Dc": grid, "rss": rss_grid, "rms": np.sqrt(rss_grid / (2 * n))})
    return DcFit(Dc=Dc, Dc_err=Dc_err, Dc_profile=profile_interval, Dc_bootstrap=(q16, q84),
                 rms=math.sqrt(rss_min / (2 * n)), rms_per_k0=per_k0, profile=profile, points=out,
                 n_points=n, regime_agreement=agree, bootstrap=boot)


def _parabolic_min(x: np.ndarray, y: np.ndarray) -> float:
    i = int(np.argmin(y))
    if i == 0 or i == len(y) - 1:
        return float(x[i])
    x0, x1, x2 = x[i - 1], x[i], x[i + 1]
    y0, y1, y2 = y[i - 1], y[i], y[i + 1]
    den = (x0 - x1) * (x0 - x2) * (x1 - x2)
    a = (x2 * (y1 - y0) + x1 * (y0 - y2) + x0 * (y2 - y1)) / den
    b = (x2 * x2 * (y0 - y1) + x1 * x1 * (y2 - y0) + x0 * x0 * (y1 - y2)) / den
    if a <= 0:
        return float(x1)
    return float(np.clip(-b / (2 * a), x0, x2))


# ============================================================================ power law
@dataclass
class PowerLawFit:
    r""":math:`\sigma_{max} - \sigma_{min} = c\,(V^c - V)^\beta` (the Hopf scaling)."""

    exponent: float
    exponent_err: float
    prefactor: float
    Vc: float
    Vc_err: float
    Vc_fitted: bool
    n_points: int
    rms_log: float

    def to_dict(self) -> dict:
        return {"exponent": self.exponent, "exponent_err": self.exponent_err, "prefactor": self.prefactor,
                "Vc": self.Vc, "Vc_err": self.Vc_err, "Vc_fitted": self.Vc_fitted, "n_points": self.n_points,
                "rms_log": self.rms_log}


def fit_power_law(V, amplitude, *, Vc: float | None = None) -> PowerLawFit:
    r"""Fit :math:`\ln(\sigma_{max}-\sigma_{min}) = \ln c + \beta\ln(V^c - V)`.

    With ``Vc`` given the fit is linear (least squares in log-log).  Without it V^c is a
    third parameter (bounded above the largest V), fitted by nonlinear least squares in
    log space — the right choice when V^c is only known to a bisection bracket.
    """
    V = np.asarray(V, dtype=float)
    amp = np.asarray(amplitude, dtype=float)
    if V.shape != amp.shape or V.ndim != 1:
        raise ValueError("V and amplitude must be 1-D arrays of equal length")
    ok = np.isfinite(V) & np.isfinite(amp) & (amp > 0)
    V, amp = V[ok], amp[ok]
    need = 3 if Vc is not None else 4
    if V.size < need:
        raise ValueError(f"need at least {need} points with amplitude > 0, got {V.size}")
    if Vc is not None:
        Vc = positive("Vc", Vc)
        if np.any(V >= Vc):
            raise ValueError(f"Vc must be > every V (largest V = {float(V.max())!r}), got {Vc!r}")
        x, y = np.log(Vc - V), np.log(amp)
        X = np.column_stack([np.ones_like(x), x])
        coef, *_ = np.linalg.lstsq(X, y, rcond=None)
        r = y - X @ coef
        s2 = float(r @ r) / (x.size - 2)
        cov = np.linalg.inv(X.T @ X) * s2
        return PowerLawFit(float(coef[1]), float(math.sqrt(cov[1, 1])), float(math.exp(coef[0])), Vc, 0.0, False,
                           int(x.size), float(math.sqrt(np.mean(r * r))))
    vmax = float(V.max())
    span = float(V.max() - V.min()) or vmax

    def resid(p):
        beta, lnc, log_gap = p
        return lnc + beta * np.log(vmax + math.exp(log_gap) - V) - np.log(amp)

    start = [0.5, float(np.log(amp.max())), math.log(0.1 * span)]
    sol = least_squares(resid, start, bounds=([0.05, -50.0, math.log(1e-6 * span)], [5.0, 50.0, math.log(100 * span)]))
    J = sol.jac
    dof = V.size - 3
    s2 = float(sol.fun @ sol.fun) / dof
    try:
        cov = np.linalg.inv(J.T @ J) * s2
        err = np.sqrt(np.clip(np.diag(cov), 0, None))
    except np.linalg.LinAlgError:
        err = np.full(3, math.nan)
    gap = math.exp(sol.x[2])
    return PowerLawFit(float(sol.x[0]), float(err[0]), float(math.exp(sol.x[1])), vmax + gap, float(gap * err[2]),
                       True, int(V.size), float(math.sqrt(np.mean(sol.fun ** 2))))


# ============================================================================ growth laws
def _exponential(t, d_inf, tau):
    return d_inf * -np.expm1(-t / tau)


def _algebraic(t, d_inf, t_a):
    return d_inf * t / (t + t_a)


def _logarithmic(t, beta, t_c):
    return beta * np.log1p(t / t_c)


#: name -> (function of hold time and two parameters, parameter names, formula)
GROWTH_LAWS: dict[str, tuple[Callable, tuple[str, str], str]] = {
    "exponential": (_exponential, ("d_inf", "tau"), "d_inf (1 - exp(-t/tau))"),
    "algebraic": (_algebraic, ("d_inf", "t_a"), "d_inf t / (t + t_a)"),
    "logarithmic": (_logarithmic, ("beta", "t_c"), "beta ln(1 + t/t_c)"),
}


@dataclass
class GrowthFit:
    """A two-parameter growth law fitted to peak-versus-hold data."""

    law: str
    formula: str
    names: tuple[str, str]
    values: tuple[float, float]
    errors: tuple[float, float]
    rms: float
    rel_rms: float
    n_points: int
    success: bool
    message: str = ""

    def predict(self, t) -> np.ndarray:
        return GROWTH_LAWS[self.law][0](np.asarray(t, dtype=float), *self.values)

    def to_dict(self) -> dict:
        return {"law": self.law, "formula": self.formula, "p1_name": self.names[0], "p1": self.values[0],
                "p1_err": self.errors[0], "p2_name": self.names[1], "p2": self.values[1], "p2_err": self.errors[1],
                "rms": self.rms, "rel_rms": self.rel_rms, "n_points": self.n_points, "success": self.success}


def fit_growth_law(hold_time, delta_sigma, law: str) -> GrowthFit:
    r"""Fit one growth law of the slide-hold-slide peak :math:`\Delta\sigma_{max}(\Delta t)`:

    * ``'exponential'``: :math:`\Delta\sigma_\infty(1 - e^{-\Delta t/\tau})` (the paper's
      fit to the micro model, τ = 2);
    * ``'algebraic'``: :math:`\Delta\sigma_\infty\,\Delta t/(\Delta t + t_a)` (RS with
      Eq. (11): the peak is :math:`\phi(\theta_0 + \Delta t)` with
      :math:`\phi(\theta) = \mu_\infty + A/(D_c/\theta + B)`, so
      :math:`\Delta\sigma_\infty = A/B - A/(V + B)` and :math:`t_a = D_c/B + D_c/V`);
    * ``'logarithmic'``: :math:`\beta\ln(1 + \Delta t/t_c)` (classical RS, Eq. (7): β ≈ b,
      :math:`t_c \approx D_c/V`).

    Points with hold time 0 are kept (every law is 0 there).  The fit is unweighted least
    squares in Δσ; ``rel_rms`` is the rms residual over the largest Δσ.
    """
    law = choice("law", law, tuple(GROWTH_LAWS))
    t = np.asarray(hold_time, dtype=float)
    d = np.asarray(delta_sigma, dtype=float)
    if t.shape != d.shape or t.ndim != 1:
        raise ValueError("hold_time and delta_sigma must be 1-D arrays of equal length")
    ok = np.isfinite(t) & np.isfinite(d) & (t >= 0)
    t, d = t[ok], d[ok]
    if t.size < 3:
        raise ValueError(f"need at least 3 finite points, got {t.size}")
    fn, names, formula = GROWTH_LAWS[law]
    pos = t[t > 0]
    t_mid = float(np.exp(np.mean(np.log(pos)))) if pos.size else 1.0
    scale = float(np.max(np.abs(d))) or 1.0
    p0 = (scale, t_mid) if law != "logarithmic" else (scale / max(math.log1p(t.max() / t_mid), 1e-3), t_mid)
    try:
        popt, pcov = curve_fit(fn, t, d, p0=p0, bounds=([-np.inf, 1e-12], [np.inf, np.inf]), maxfev=20000)
        err = np.sqrt(np.clip(np.diag(pcov), 0, None)) if np.all(np.isfinite(pcov)) else np.full(2, math.nan)
        success, message = True, ""
    except (RuntimeError, ValueError) as exc:
        popt, err, success, message = np.array(p0, dtype=float), np.full(2, math.nan), False, str(exc)
    r = fn(t, *popt) - d
    rms = float(math.sqrt(np.mean(r * r)))
    return GrowthFit(law, formula, names, (float(popt[0]), float(popt[1])), (float(err[0]), float(err[1])), rms,
                     rms / scale, int(t.size), success, message)
