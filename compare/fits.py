r"""Fits that connect the microscopic model to rate-and-state friction.

* :func:`fit_steady_law` — the paper's Eq. (10), :math:`\mu_{ss} = \mu_\infty + A/(V + B)`,
  fitted to micro's steady branch: one (A, B) shared by every k0 of a (k1, k2, zbar)
  set and one offset :math:`\mu_\infty` per k0 (the paper: k0 only shifts the curve).
* :func:`fit_dc` — the critical slip distance D_c that makes the RS bifurcation diagram
  (σ_max, σ_min against V) closest to micro's; D_c enters only as k0·D_c.
* :func:`dc_from_critical_velocity` — the closed form that matches the RS critical
  velocity to micro's, k0·D_c = W(V^c) = A V^c/(V^c + B)^2.
* :func:`fit_power_law` — the Hopf scaling σ_max − σ_min ∝ (V^c − V)^β, with V^c given or
  fitted; :func:`transition_fits` — one such law per method of the transition study, with
  its confidence interval and the range of d it rests on.
* :func:`fit_growth_law` — the three growth laws of the slide-hold-slide peak.
"""
from __future__ import annotations

import logging
import math
from dataclasses import dataclass, field
from typing import Any, Callable

import numpy as np
import pandas as pd
from scipy.optimize import curve_fit, least_squares, minimize_scalar

import rsf

from ._validation import choice, positive

__all__ = [
    "SteadyLawFit",
    "fit_steady_law",
    "DcFit",
    "fit_dc",
    "rs_diagram",
    "dc_small_k0",
    "dc_from_critical_velocity",
    "DcCriticalFit",
    "fit_dc_critical",
    "steady_law_checks",
    "classify_transition",
    "PowerLawFit",
    "fit_power_law",
    "transition_fits",
    "AMPLITUDE_ERROR_KINDS",
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
        One row per k0: ``k0, mu_inf, mu_inf_err, n_points``.
    residuals : DataFrame
        The points used, with the fitted value and the residual.
    rms : float
        Root-mean-square residual.
    offset_mode : str
        ``'free'`` (fitted per k0) or ``'fixed'`` (held at the given offsets).
    n_points : int
        Steady points in the fit.
    params : dict
        Unused by the fit itself (empty unless a caller records the model there).
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
        :func:`micro.sweep`; only ``regime == 'steady'`` rows with V > 0 and a finite
        ``sigma_mean`` are used.
    offset : {'free', 'fixed'}
        ``'free'``: one fitted offset per k0.  ``'fixed'``: offsets from ``fixed_offsets``,
        only A and B fitted.
    fixed_offsets : dict, optional
        k0 -> mu_inf for every k0 of the steady rows; needed with ``offset='fixed'``.
    converged_only : bool
        Skip steady rows whose run did not meet its convergence test (default True).
    B_bounds : (float, float)
        Search range of B, > 0 and increasing (default (1e-4, 1e2)); an optimum at its
        end is logged as a warning.

    Returns
    -------
    SteadyLawFit
        A, B and their standard errors, the offsets per k0, the residuals and their rms.

    Raises
    ------
    ValueError
        If ``offset`` is not a choice, ``B_bounds`` is not positive and increasing,
        ``frame`` lacks a column, there are fewer steady points than parameters plus one,
        or ``offset='fixed'`` comes without ``fixed_offsets`` or without the offset of a
        k0.

    Examples
    --------
    >>> import numpy as np, pandas as pd
    >>> from compare import fit_steady_law
    >>> V = np.geomspace(0.5, 50.0, 8)
    >>> frame = pd.DataFrame({"k0": 0.1, "V": V, "regime": "steady",
    ...                       "sigma_mean": 0.945 + 0.007 / (V + 0.078)})
    >>> fit = fit_steady_law(frame)
    >>> round(fit.A, 6), round(fit.B, 6), round(fit.mu_inf(0.1), 6)
    (0.007, 0.078, 0.945)
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

    Parameters
    ----------
    points : DataFrame
        Columns ``k0`` and ``V`` (> 0).
    law_for : callable
        k0 -> the RS steady-state law (an :class:`rsf.SteadyStateLaw`).
    Dc : float
        Critical slip distance, > 0.
    options : rsf.SolverOptions, optional
        For :func:`rsf.limit_cycle`; default ``cycle_rtol=1e-7, rtol=1e-8``.

    Returns
    -------
    DataFrame
        ``k0, V, regime, sigma_max, sigma_min, sigma_mean, converged, status`` per row of
        ``points``.

    Raises
    ------
    ValueError
        If ``Dc`` is not a finite number > 0, or rsf refuses a model or velocity (a k0 or V
        out of range, a law that is not an rsf law).

    Examples
    --------
    >>> import pandas as pd, rsf
    >>> from compare import rs_diagram
    >>> rs_diagram(pd.DataFrame({"k0": [0.1, 0.1], "V": [0.05, 2.0]}),
    ...            lambda k0: rsf.HyperbolicLaw(), Dc=0.06).regime.tolist()
    ['stick-slip', 'steady']
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

    (the upper root V_+ of the stability boundary; valid for :math:`V^c > B`).

    Parameters
    ----------
    A, B : float
        The constants of Eq. (10), > 0.
    k0 : float
        Driving stiffness, > 0.
    Vc : float
        The critical velocity to match, > ``B``.

    Returns
    -------
    float
        :math:`D_c = A V^c / (k_0 (V^c + B)^2)`.

    Raises
    ------
    ValueError
        If a parameter is not a finite number > 0, or ``Vc <= B``.

    Examples
    --------
    >>> from compare import dc_from_critical_velocity
    >>> round(dc_from_critical_velocity(0.007, 0.078, 0.1, 1.0046), 4)   # rsf's V^c at Dc = 0.06
    0.06
    """
    A, B, k0, Vc = positive("A", A), positive("B", B), positive("k0", k0), positive("Vc", Vc)
    if Vc <= B:
        raise ValueError(f"Vc must be > B = {B!r} to be the upper root V_+ of W(V) = k0 Dc, got {Vc!r}")
    return A * Vc / (Vc + B) ** 2 / k0


@dataclass
class DcFit:
    r"""The critical slip distance that best matches micro's stick-slip extrema.

    Attributes
    ----------
    Dc : float
        The optimum of the extrema misfit: the mean over the points where both models are
        in stick-slip of :math:`(\sigma^{RS}_{max} - \sigma^{micro}_{max})^2 +
        (\sigma^{RS}_{min} - \sigma^{micro}_{min})^2`.  Which points those are depends on
        D_c (RS is in stick-slip at (k0, V) for :math:`k_0 D_c < W(V)`), so the misfit is
        smooth between the points' regime switches and steps at each; regime agreement is
        reported apart (``n_disagree``, ``regime_agreement``, ``points.regime_rs``).
    one_sided, switch : str, float
        When the optimum sits on a regime switch of a point (within 1 %), the data bound
        D_c from one side only: ``one_sided`` is ``'upper'`` (D_c <= switch) or ``'lower'``,
        and ``switch`` is that D_c; otherwise ``''`` and NaN.
    Dc_err : float
        Half the width of the bootstrap 16-84 % interval (resampling the points).
    Dc_profile : (float, float)
        The profile interval: the D_c range about the optimum where the misfit stays within
        the factor ``profile_factor`` = 1 + 1/(n - 1) of its minimum (n = ``n_stick_slip``).
    Dc_bootstrap : (float, float)
        The bootstrap's 16 % and 84 % quantiles.
    rms : float
        Root-mean-square extrema residual at the optimum over the ``n_stick_slip`` points
        (2 values each); ``rms_per_k0`` splits it by k0.
    profile : DataFrame
        ``Dc, rss, rms, misfit, n_stick_slip, n_disagree`` on the scan grid: the sum of the
        squared residuals over the points in the misfit, its rms per value, the misfit (their
        mean per point), how many points it has and how many disagree in regime.
    points : DataFrame
        The micro points with RS's values at the optimum, the residuals, whether each enters
        the misfit there (``in_misfit``), whether the regimes agree, and the D_c at which its
        RS regime switches (``Dc_switch``, W(V)/k0).
    n_points : int
        Micro points used (steady and stick-slip).
    n_stick_slip : int
        Points in the misfit at the optimum: both models in stick-slip.
    n_disagree : int
        Points whose RS regime at the optimum is not micro's.
    regime_agreement : float
        The fraction of points whose RS regime at the optimum is micro's.
    profile_factor : float
        The factor of the profile interval.
    bootstrap : ndarray
        The bootstrap optima.
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
    one_sided: str = ""
    switch: float = math.nan
    n_stick_slip: int = 0
    n_disagree: int = 0
    profile_factor: float = math.nan

    def to_frame(self) -> pd.DataFrame:
        return pd.DataFrame([{"Dc": self.Dc, "Dc_err": self.Dc_err, "Dc_profile_low": self.Dc_profile[0],
                              "Dc_profile_high": self.Dc_profile[1], "Dc_bootstrap_16": self.Dc_bootstrap[0],
                              "Dc_bootstrap_84": self.Dc_bootstrap[1], "rms": self.rms,
                              "n_points": self.n_points, "n_stick_slip": self.n_stick_slip,
                              "n_disagree": self.n_disagree, "regime_agreement": self.regime_agreement,
                              "profile_factor": self.profile_factor, "one_sided": self.one_sided,
                              "switch": self.switch}])


def _diagram_points(frame: pd.DataFrame, converged_only: bool) -> pd.DataFrame:
    need = {"k0", "V", "regime", "sigma_max", "sigma_min"}
    missing = need - set(frame.columns)
    if missing:
        raise ValueError(f"frame must have columns {sorted(need)}; missing {sorted(missing)}")
    sel = frame.regime.isin(["steady", "stick-slip"]) & np.isfinite(frame.sigma_max) & np.isfinite(frame.sigma_min)
    if converged_only and "converged" in frame.columns:
        sel &= frame.converged.astype(bool)
    return frame.loc[sel].reset_index(drop=True)


def _misfit(sq: np.ndarray, both: np.ndarray, weights: np.ndarray, need: float) -> np.ndarray:
    """The extrema misfit per row of ``sq`` (n_D, n): the weighted mean of ``sq`` over the
    points where ``both`` (n_D, n) holds; NaN where their weight is below ``need``."""
    w = both * weights
    total = w.sum(axis=1)
    with np.errstate(invalid="ignore", divide="ignore"):
        out = np.where(total >= need, (np.where(both, sq, 0.0) * weights).sum(axis=1) / total, np.nan)
    return out


def fit_dc(frame: pd.DataFrame, law_for: Callable[[float], rsf.SteadyStateLaw], *,
           bounds: tuple[float, float] = (1e-3, 1.0), n_grid: int = 49, n_bootstrap: int = 400,
           converged_only: bool = True, seed: int = 0, min_share: float = 0.5,
           options: rsf.SolverOptions | None = None) -> DcFit:
    r"""Fit D_c so that RS's stick-slip extrema match micro's.

    The misfit at a D_c is the mean, over the points where both models are in stick-slip,
    of :math:`(\sigma^{RS}_{max} - \sigma^{micro}_{max})^2 + (\sigma^{RS}_{min} -
    \sigma^{micro}_{min})^2`.  Regime agreement is kept apart: RS is in stick-slip at (k0, V)
    for :math:`k_0 D_c < W(V)` (``Dc_switch`` = W(V)/k0 of each point), so a point enters or
    leaves the misfit at its switch, and the misfit is smooth between switches.  Because
    D_c enters only as k0·D_c, the problem is one-dimensional: the misfit is scanned on a
    log-spaced grid of ``n_grid`` values in ``bounds`` (each point a handful of RS limit
    cycles, ~1 ms), the best grid value is refined by a bounded scalar minimisation within
    its stretch between switches, and the uncertainty comes from the same grid: the profile
    interval and a bootstrap over the points (resampled with replacement).  Only D_c at
    which at least ``min_share`` of micro's stick-slip points are in stick-slip in RS too
    are candidates (the misfit of a handful of points is no fit).

    Parameters
    ----------
    frame : DataFrame
        Micro points with ``k0, V, regime, sigma_max, sigma_min`` (and ``converged``);
        steady points count for regime agreement only.
    law_for : callable
        k0 -> the RS steady-state law to use (e.g. ``fit.law`` of a :class:`SteadyLawFit`).
    bounds : (float, float)
        Search range of D_c, > 0.
    n_grid, n_bootstrap : int
        Scan resolution (>= 7, default 49) and number of bootstrap samples (default 400).
    converged_only : bool
        Skip micro points whose run did not converge (default True).
    seed : int
        Seed of the bootstrap's resampling.
    min_share : float
        In (0, 1]: the least share of micro's stick-slip points that must be in the misfit
        at a candidate D_c (default 0.5; at least two points in any case).
    options : rsf.SolverOptions, optional
        For the RS limit cycles (:func:`rs_diagram`'s default).

    Returns
    -------
    DcFit
        The optimum, its bootstrap error and profile interval, the residuals, the regime
        agreement, and whether the data bound D_c from one side only.

    Raises
    ------
    ValueError
        If ``bounds`` is not positive and increasing, ``n_grid`` < 7, ``min_share`` is not
        in (0, 1], ``frame`` lacks a column, fewer than 3 usable (steady or stick-slip,
        finite, converged) points remain or fewer than 2 of them are stick-slip, or no D_c
        in ``bounds`` has ``min_share`` of them in stick-slip in RS.
    """
    lo, hi = positive("bounds[0]", bounds[0]), positive("bounds[1]", bounds[1])
    if not hi > lo:
        raise ValueError(f"bounds must be increasing, got {bounds!r}")
    if int(n_grid) < 7:
        raise ValueError(f"n_grid must be an integer >= 7, got {n_grid!r}")
    if not 0.0 < float(min_share) <= 1.0:
        raise ValueError(f"min_share must lie in (0, 1], got {min_share!r}")
    pts = _diagram_points(frame, converged_only)
    if len(pts) < 3:
        raise ValueError(f"need at least 3 usable micro points (steady or stick-slip, converged), got {len(pts)}")
    micro_ss = (pts.regime == "stick-slip").to_numpy()
    if micro_ss.sum() < 2:
        raise ValueError(f"need at least 2 usable micro stick-slip points, got {int(micro_ss.sum())}")
    n = len(pts)
    need = max(2.0, float(min_share) * float(micro_ss.sum()))
    ones = np.ones(n)
    smax, smin = pts.sigma_max.to_numpy(float), pts.sigma_min.to_numpy(float)
    # regime switches: RS is unstable at (k0, V) for k0 Dc < W(V)
    switches = np.array([float(law_for(k).weakening(np.array([v]))[0]) / k
                         for k, v in zip(pts.k0.to_numpy(float), pts.V.to_numpy(float))])

    def at(Dc: float) -> tuple[np.ndarray, np.ndarray, pd.DataFrame]:
        """(squared residual per point, both in stick-slip per point, RS's diagram)."""
        rs = rs_diagram(pts, law_for, Dc, options=options)
        sq = (rs.sigma_max.to_numpy(float) - smax) ** 2 + (rs.sigma_min.to_numpy(float) - smin) ** 2
        return sq, micro_ss & (rs.regime.to_numpy() == "stick-slip"), rs

    ss_pts = pts[micro_ss].reset_index(drop=True)
    ones_ss = np.ones(len(ss_pts))

    def misfit(Dc: float) -> float:
        """The misfit alone (RS at micro's stick-slip points only)."""
        rs = rs_diagram(ss_pts, law_for, Dc, options=options)
        sq = (rs.sigma_max.to_numpy(float) - smax[micro_ss]) ** 2 + (rs.sigma_min.to_numpy(float) - smin[micro_ss]) ** 2
        m = _misfit(sq[None], (rs.regime.to_numpy() == "stick-slip")[None], ones_ss, need)[0]
        return float(m) if math.isfinite(m) else math.inf

    grid = np.geomspace(lo, hi, int(n_grid))
    runs = [at(d) for d in grid]
    SQ = np.array([r[0] for r in runs])                         # (n_grid, n)
    BOTH = np.array([r[1] for r in runs])
    DIS = np.array([(r[2].regime.to_numpy() != pts.regime.to_numpy()).sum() for r in runs])
    mis_grid = _misfit(SQ, BOTH, ones, need)
    if not np.isfinite(mis_grid).any():
        raise ValueError(f"no D_c in bounds {bounds!r} has {min_share:g} of micro's {int(micro_ss.sum())} "
                         f"stick-slip points in stick-slip in RS too")
    i = int(np.nanargmin(mis_grid))
    # refine within the stretch between switches that holds the grid's best value
    sw = np.sort(switches[np.isfinite(switches) & (switches > 0)])
    a = float(grid[max(i - 1, 0)])
    b = float(grid[min(i + 1, len(grid) - 1)])
    below, above = sw[sw <= grid[i]], sw[sw > grid[i]]
    if below.size:
        a = max(a, float(below[-1]) * (1 + 1e-9))
    if above.size:
        b = min(b, float(above[0]) * (1 - 1e-9))
    if b > a:
        opt = minimize_scalar(lambda g: misfit(math.exp(g)), bounds=(math.log(a), math.log(b)), method="bounded",
                              options={"xatol": 1e-5})
        Dc = float(math.exp(opt.x)) if opt.fun <= mis_grid[i] else float(grid[i])
    else:
        Dc = float(grid[i])
    sq_opt, both_opt, rs_opt = at(Dc)
    mis_min = float(_misfit(sq_opt[None], both_opt[None], ones, need)[0])
    n_ss = int(both_opt.sum())
    if i in (0, len(grid) - 1):
        log.warning("fit_dc: the optimum D_c = %.4g sits at the bound of %s", Dc, bounds)
    # profile interval: where the misfit stays within the factor of its minimum, located by
    # bisection on each side of the optimum (the misfit steps at switches: bisection, not a root)
    factor = 1.0 + 1.0 / max(n_ss - 1, 1)
    level = mis_min * factor
    log_grid = np.log(grid)
    g_opt = math.log(Dc)
    ends = []
    for direction in (-1, +1):
        j = i
        while 0 <= j < len(grid) and ((math.isfinite(mis_grid[j]) and mis_grid[j] <= level)
                                       or (log_grid[j] - g_opt) * direction <= 0):
            j += direction
        if not 0 <= j < len(grid):
            ends.append(float(grid[0] if direction < 0 else grid[-1]))   # open at the search bound
            continue
        inner, outer = g_opt, float(log_grid[j])
        for _ in range(40):
            mid = 0.5 * (inner + outer)
            if misfit(math.exp(mid)) <= level:
                inner = mid
            else:
                outer = mid
            if abs(outer - inner) < 1e-4:
                break
        ends.append(math.exp(0.5 * (inner + outer)))
    profile_interval = (float(ends[0]), float(ends[1]))
    # bootstrap over points
    rng = np.random.default_rng(seed)
    boot = np.empty(int(n_bootstrap))
    for k in range(boot.size):
        w = np.bincount(rng.integers(0, n, n), minlength=n).astype(float)
        y = _misfit(SQ, BOTH, w, need * w[micro_ss].sum() / micro_ss.sum())
        boot[k] = math.exp(_parabolic_min(log_grid, np.where(np.isfinite(y), y, np.inf))) if np.isfinite(y).any() \
            else math.nan
    boot = boot[np.isfinite(boot)]
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
    out["residual_max"] = out.sigma_max_rs - out.sigma_max_micro
    out["residual_min"] = out.sigma_min_rs - out.sigma_min_micro
    out["in_misfit"] = both_opt
    out["regime_agrees"] = out.regime_rs.to_numpy() == out.regime_micro.to_numpy()
    out["Dc_switch"] = switches
    used = out[out.in_misfit]
    per_k0 = (used.assign(sq=used.residual_max ** 2 + used.residual_min ** 2)
              .groupby("k0").agg(n_points=("sq", "size"), sq=("sq", "sum")).reset_index())
    per_k0["rms"] = np.sqrt(per_k0.sq / (2 * per_k0.n_points))
    per_k0 = per_k0.drop(columns="sq")
    agree = float(np.mean(out.regime_agrees))
    profile = pd.DataFrame({"Dc": grid, "rss": mis_grid * BOTH.sum(axis=1), "rms": np.sqrt(mis_grid / 2.0),
                            "misfit": mis_grid, "n_stick_slip": BOTH.sum(axis=1), "n_disagree": DIS})
    one_sided, switch = "", math.nan
    if sw.size:
        j = int(np.argmin(np.abs(np.log(sw / Dc))))
        if abs(math.log(sw[j] / Dc)) < 0.01:
            switch = float(sw[j])
            one_sided = "upper" if Dc <= switch else "lower"
    return DcFit(Dc=Dc, Dc_err=Dc_err, Dc_profile=profile_interval, Dc_bootstrap=(q16, q84),
                 rms=math.sqrt(mis_min / 2.0), rms_per_k0=per_k0, profile=profile, points=out,
                 n_points=n, regime_agreement=agree, bootstrap=boot, one_sided=one_sided, switch=switch,
                 n_stick_slip=n_ss, n_disagree=int((~out.regime_agrees).sum()), profile_factor=factor)


def _parabolic_min(x: np.ndarray, y: np.ndarray) -> float:
    i = int(np.argmin(y))
    if i == 0 or i == len(y) - 1 or not (np.isfinite(y[i - 1]) and np.isfinite(y[i + 1])):
        return float(x[i])
    x0, x1, x2 = x[i - 1], x[i], x[i + 1]
    y0, y1, y2 = y[i - 1], y[i], y[i + 1]
    den = (x0 - x1) * (x0 - x2) * (x1 - x2)
    a = (x2 * (y1 - y0) + x1 * (y0 - y2) + x0 * (y2 - y1)) / den
    b = (x2 * x2 * (y0 - y1) + x1 * x1 * (y2 - y0) + x0 * x0 * (y1 - y2)) / den
    if a <= 0:
        return float(x1)
    return float(np.clip(-b / (2 * a), x0, x2))


def dc_small_k0(frame: pd.DataFrame, law: rsf.HyperbolicLaw) -> float:
    r"""D_c (a) at one k0 in the limit of small k0, in closed form.

    For :math:`V \gg B` and :math:`k_0 D_c \ll A/B` RS's cycle at a = 0 (Eq. 10) is a stick
    from :math:`\sigma_{min} = \mu_\infty` (the long slip empties the state) up to where the
    stress catches the saturating strength, :math:`\sigma_{max} = \mu_\infty + (A - k_0 V D_c)/B`:
    its extrema depend on :math:`k_0 V D_c` alone, and linearly.  Least squares of
    :math:`\sigma_{max}` against micro's at its stick-slip points is then linear in D_c,

    .. math:: D_c = \frac{\sum_i g_i h_i}{\sum_i h_i^2}, \quad g_i = \mu_\infty + A/B -
              \sigma^{micro}_{max,i}, \quad h_i = k_0 V_i / B

    (σ_min does not depend on D_c there).  With :math:`V_i = r_i V^c` and micro's
    :math:`k_0 V^c` and cycles functions of the loading rate :math:`k_0 V` alone at small k0
    (docs/reference/micro_transition.md, (L) and (V)), this D_c and D_c (b)
    :math:`= W(V^c)/k_0 \to A/(k_0 V^c)` both tend to constants: their ratio
    :math:`B \sum_i r_i g_i / (A \sum_i r_i^2)` is constant at small k0.

    Parameters
    ----------
    frame : DataFrame
        Micro points at one k0 with ``k0, V, regime, sigma_max``; only stick-slip rows are used.
    law : rsf.HyperbolicLaw
        The fitted Eq. (10) at that k0.

    Returns
    -------
    float
        The closed-form D_c; NaN without stick-slip points.

    Examples
    --------
    >>> import pandas as pd, rsf
    >>> from compare.fits import dc_small_k0
    >>> law = rsf.HyperbolicLaw(A=0.0075, B=0.083, mu_inf=0.9)
    >>> k0, Dc = 1e-4, 0.085
    >>> V = [200.0, 400.0]
    >>> smax = [rsf.limit_cycle(rsf.SpringSlider(law=law, k0=k0, Dc=Dc), v).sigma_max for v in V]
    >>> round(dc_small_k0(pd.DataFrame({"k0": k0, "V": V, "regime": "stick-slip", "sigma_max": smax}), law), 5)
    0.085
    """
    ss = frame[(frame.regime == "stick-slip") & np.isfinite(frame.sigma_max)]
    if not len(ss):
        return math.nan
    g = law.mu_inf + law.A / law.B - ss.sigma_max.to_numpy(float)
    h = ss.k0.to_numpy(float) * ss.V.to_numpy(float) / law.B
    return float(g @ h / (h @ h))


# ============================================================================ D_c from V^c
@dataclass
class DcCriticalFit:
    r"""D_c from matching the RS critical velocity to micro's, over several k0.

    Attributes
    ----------
    Dc : float
        Least squares of :math:`\ln V^c_{RS}(k_0; D_c) - \ln V^c_{micro}(k_0)` over the k0.
    Dc_err : float
        Its standard error (Gauss-Newton, residual variance); it says how well one D_c
        fits every k0 only together with ``Dc_range``.
    Dc_range : (float, float)
        The smallest and largest per-k0 D_c (each reproduces its k0 exactly).
    rms_log : float
        Root-mean-square of the log residual at the optimum (0.01 = 1 % in V^c).
    per_k0 : DataFrame
        ``k0, Vc_micro, W_law, Dc_law`` (k0 D_c = W(V^c) of the fitted law),
        ``W_exact, Dc_exact_slope`` (with micro's own slope -V dsigma/dV at V^c),
        ``Vc_rs`` (at the optimum) and ``rel_diff``.
    """

    Dc: float
    Dc_err: float
    Dc_range: tuple[float, float]
    rms_log: float
    per_k0: pd.DataFrame

    def to_frame(self) -> pd.DataFrame:
        return pd.DataFrame([{"Dc": self.Dc, "Dc_err": self.Dc_err, "Dc_min": self.Dc_range[0],
                              "Dc_max": self.Dc_range[1], "rms_log": self.rms_log}])


def fit_dc_critical(k0, Vc, law_for: Callable[[float], rsf.SteadyStateLaw], *,
                    slopes: dict[float, float] | None = None,
                    bounds: tuple[float, float] = (1e-3, 1.0)) -> DcCriticalFit:
    r"""D_c such that the RS critical velocity matches micro's ``Vc`` at each ``k0``.

    Per k0 the match is exact: :math:`k_0 D_c = W(V^c) = -V\,\mu_{ss}'(V)|_{V^c}` with
    the law's weakening (``Dc_law``) and, given ``slopes`` (k0 -> micro's own W at its
    V^c), with micro's (``Dc_exact_slope``): the two differ by the error of the law's
    slope.  One D_c for every k0 is the least-squares fit of the log critical velocities.

    Parameters
    ----------
    k0, Vc : array_like
        Stiffnesses and micro's critical velocities, 1-D, of equal length, finite and > 0.
    law_for : callable
        k0 -> the RS steady-state law (an :class:`rsf.SteadyStateLaw`).
    slopes : dict, optional
        k0 -> micro's own weakening :math:`-V\,\mathrm{d}\sigma/\mathrm{d}V` at its V^c.
    bounds : (float, float)
        Search range of D_c, > 0 (default (1e-3, 1)).

    Returns
    -------
    DcCriticalFit
        The fitted D_c, its error, the range of the per-k0 D_c and the table per k0.

    Raises
    ------
    ValueError
        If ``k0`` and ``Vc`` are not 1-D of equal non-zero length with finite positive
        values, or ``bounds`` is not positive.

    Examples
    --------
    >>> import rsf
    >>> from compare import fit_dc_critical
    >>> Vc = [rsf.critical_velocity(k0=k0, Dc=0.06).Vc for k0 in (0.1, 0.3)]
    >>> fit = fit_dc_critical([0.1, 0.3], Vc, lambda k0: rsf.HyperbolicLaw())
    >>> round(fit.Dc, 6)
    0.06
    """
    k0 = np.asarray(k0, dtype=float)
    Vc = np.asarray(Vc, dtype=float)
    if k0.shape != Vc.shape or k0.ndim != 1 or k0.size < 1:
        raise ValueError("k0 and Vc must be 1-D arrays of equal, non-zero length")
    if not (np.all(np.isfinite(Vc)) and np.all(Vc > 0) and np.all(k0 > 0)):
        raise ValueError(f"k0 and Vc must be finite and > 0, got k0 = {k0!r}, Vc = {Vc!r}")
    lo, hi = positive("bounds[0]", bounds[0]), positive("bounds[1]", bounds[1])
    slopes = slopes or {}
    rows = []
    for k, v in zip(k0, Vc):
        W = float(law_for(k).weakening(np.array([v]))[0])
        We = slopes.get(float(k), math.nan)
        rows.append({"k0": float(k), "Vc_micro": float(v), "W_law": W, "Dc_law": W / k,
                     "W_exact": We, "Dc_exact_slope": We / k})
    per = pd.DataFrame(rows)

    def vc_rs(D: float) -> np.ndarray:
        return np.array([rsf.critical_velocity(law_for(k), k, D).Vc for k in k0])

    def resid(g: float) -> np.ndarray:
        r = np.log(vc_rs(math.exp(g))) - np.log(Vc)
        return np.where(np.isfinite(r), r, 10.0)

    opt = minimize_scalar(lambda g: float(resid(g) @ resid(g)), bounds=(math.log(lo), math.log(hi)),
                          method="bounded", options={"xatol": 1e-9})
    g = float(opt.x)
    Dc = math.exp(g)
    r = resid(g)
    h = 1e-4
    J = (resid(g + h) - resid(g - h)) / (2 * h)
    dof = max(k0.size - 1, 1)
    s2 = float(r @ r) / dof
    Dc_err = Dc * math.sqrt(s2 / float(J @ J)) if k0.size > 1 and float(J @ J) > 0 else math.nan
    per["Vc_rs"] = vc_rs(Dc)
    per["rel_diff"] = per.Vc_rs / per.Vc_micro - 1.0
    return DcCriticalFit(Dc=Dc, Dc_err=Dc_err, Dc_range=(float(per.Dc_law.min()), float(per.Dc_law.max())),
                         rms_log=float(math.sqrt(np.mean(r * r))), per_k0=per)


def steady_law_checks(fit: SteadyLawFit, sigma_inf: dict[float, float], tail: dict[float, float]) -> pd.DataFrame:
    r"""Where Eq. (10) departs from an exact steady branch, per k0.

    ``sigma_inf`` and ``tail`` hold the exact large-V behaviour of the branch,
    :math:`\sigma \to \sigma_\infty + C/V` (micro: :func:`micro.sigma_fast_limit`); Eq. (10)
    has :math:`\mu_\infty + A/V`.  Returns ``k0, mu_inf, sigma_inf_exact, offset_error``
    (:math:`\mu_\infty - \sigma_\infty`), ``A, tail_exact, tail_ratio`` (A / C),
    ``max_abs_residual, V_at_max, rms`` and ``tail_residual`` (the residual at the largest V
    relative to the exact :math:`\sigma - \sigma_\infty` there).

    Parameters
    ----------
    fit : SteadyLawFit
        The fit of Eq. (10).
    sigma_inf : dict
        k0 -> the exact large-V limit :math:`\sigma_\infty` (nan where missing).
    tail : dict
        k0 -> the exact coefficient :math:`C` of :math:`C/V`.

    Returns
    -------
    DataFrame
        One row per fitted k0, with the columns above and ``V_max``.
    """
    res = fit.residuals
    rows = []
    for _, off in fit.offsets.iterrows():
        k0 = float(off.k0)
        r = res[np.isclose(res.k0, k0, rtol=1e-12, atol=0)]
        i = int(np.argmax(np.abs(r.residual.to_numpy())))
        last = r.iloc[int(np.argmax(r.V.to_numpy()))]
        si = sigma_inf.get(k0, math.nan)
        rows.append({"k0": k0, "mu_inf": float(off.mu_inf), "sigma_inf_exact": si,
                     "offset_error": float(off.mu_inf) - si, "A": fit.A, "tail_exact": tail.get(k0, math.nan),
                     "tail_ratio": fit.A / tail.get(k0, math.nan),
                     "max_abs_residual": float(abs(r.residual.iloc[i])), "V_at_max": float(r.V.iloc[i]),
                     "rms": float(np.sqrt(np.mean(r.residual.to_numpy() ** 2))),
                     "tail_residual": float(last.residual / (last.sigma_mean - si)) if math.isfinite(si) else math.nan,
                     "V_max": float(last.V)})
    return pd.DataFrame(rows)


# ============================================================================ transition
def classify_transition(spectrum: pd.DataFrame, amplitude_fits: pd.DataFrame, points: pd.DataFrame) -> dict:
    r"""What kind of bifurcation micro's loss of stability at V^c is, from the evidence.

    A Hopf bifurcation has a complex pair of eigenvalues crossing the imaginary axis at a
    finite frequency: the growth rate vanishes at V^c and the period of the born cycle stays
    finite, its amplitude growing like :math:`(V^c - V)^{1/2}`.  ``spectrum`` holds the growth
    rate of micro's unstable (real) mode against d = (V^c - V)/V^c; ``amplitude_fits`` the
    fitted amplitude laws; ``points`` the N-block periods.

    Parameters
    ----------
    spectrum : DataFrame
        Columns ``d`` and ``growth_rate``; the growth test needs two finite rates.
    amplitude_fits : DataFrame
        Columns ``model, method, resolution, exponent, exponent_err``: the N-block fits of
        micro (``model == 'micro'``, ``method == 'N-block'``) give beta, the largest N its
        value.
    points : DataFrame
        Columns ``model, method, regime, resolution, d, period``: the periods of micro's
        N-block cycles at the largest N give the period exponent (at least 3 needed).

    Returns
    -------
    dict
        What could be measured of ``d_near, growth_near, d_far, growth_far,
        growth_diverges``, ``beta, beta_err, beta_spread, beta_N`` and ``period_exponent,
        period_near, d_period_near``; ``hopf`` (True, False, or None without a spectrum)
        and ``text``, the verdict as a paragraph.  Evidence that is missing is left out,
        not an error.
    """
    out: dict[str, Any] = {}
    sp = spectrum[np.isfinite(spectrum.growth_rate)].sort_values("d")
    if len(sp) >= 2:
        near, far = sp.iloc[0], sp.iloc[int(np.argmin(np.abs(sp.d.to_numpy() - 0.5)))]
        out.update(d_near=float(near.d), growth_near=float(near.growth_rate), d_far=float(far.d),
                   growth_far=float(far.growth_rate))
        out["growth_diverges"] = bool(near.growth_rate > 10 * far.growth_rate)
    micro_fits = amplitude_fits[(amplitude_fits.model == "micro")] if len(amplitude_fits) else amplitude_fits
    nb = micro_fits[micro_fits.method == "N-block"] if len(micro_fits) else micro_fits
    if len(nb):
        best = nb.sort_values("resolution").iloc[-1]
        out.update(beta=float(best.exponent), beta_err=float(best.exponent_err),
                   beta_spread=float(nb.exponent.max() - nb.exponent.min()) if len(nb) > 1 else math.nan,
                   beta_N=float(best.resolution))
    per = points[(points.model == "micro") & (points.method == "N-block") & (points.regime == "stick-slip")]
    if len(per) >= 3 and "period" in per:
        per = per[per.resolution == per.resolution.max()]
        per = per[np.isfinite(per.period) & (per.period > 0)]
        if len(per) >= 3:
            slope = np.polyfit(np.log(per.d.to_numpy(float)), np.log(per.period.to_numpy(float)), 1)[0]
            out["period_exponent"] = float(slope)
            out["period_near"] = float(per.sort_values("d").period.iloc[0])
            out["d_period_near"] = float(per.sort_values("d").d.iloc[0])
    parts = []
    if "growth_diverges" in out:
        if out["growth_diverges"]:
            parts.append(f"the unstable mode of steady sliding is real and its growth rate rises from "
                         f"{out['growth_far']:.3g} at d = {out['d_far']:.2g} to {out['growth_near']:.3g} at "
                         f"d = {out['d_near']:.2g}: it diverges at V^c instead of vanishing, so the eigenvalue "
                         f"enters from infinity (the branching ratio reaches 1) and no complex pair crosses the "
                         f"imaginary axis")
        else:
            parts.append(f"the growth rate of the unstable mode falls to {out['growth_near']:.3g} at "
                         f"d = {out['d_near']:.2g}, as at a local bifurcation")
    if "beta" in out:
        parts.append(f"the N-block amplitude vanishes continuously, as d^beta with beta = {out['beta']:.2f} "
                     f"± {out['beta_err']:.2f} (N = {out['beta_N']:.0f}"
                     + (f"; {out['beta_spread']:.2f} between the two N)" if math.isfinite(out.get("beta_spread", math.nan))
                        else ")"))
    if "period_exponent" in out:
        parts.append(f"the cycle period scales as d^{out['period_exponent']:.2f} "
                     f"({out['period_near']:.3g} at d = {out['d_period_near']:.2g})")
    hopf = None
    if "growth_diverges" in out:
        hopf = not out["growth_diverges"] and abs(out.get("period_exponent", 0.0)) < 0.25
    out["hopf"] = hopf
    verdict = {True: "consistent with a Hopf bifurcation", False: "not a Hopf bifurcation",
               None: "not classified (no spectrum)"}[hopf]
    out["text"] = f"Micro's transition is {verdict}: " + "; ".join(parts) + "." if parts else verdict
    return out


# ============================================================================ power law
@dataclass
class PowerLawFit:
    r""":math:`\sigma_{max} - \sigma_{min} = c\,(V^c - V)^\beta` (the Hopf scaling), from
    :func:`fit_power_law`.

    Attributes
    ----------
    exponent, exponent_err : float
        :math:`\beta` and its standard error.
    prefactor : float
        :math:`c`.
    Vc, Vc_err : float
        The critical velocity used (given, error 0) or fitted, with its standard error.
    Vc_fitted : bool
        Whether V^c was a fitted parameter.
    n_points : int
        Points in the fit (amplitude > 0, finite).
    rms_log : float
        Root-mean-square residual of :math:`\ln(\sigma_{max} - \sigma_{min})`.
    """

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

    With ``Vc`` given the fit is linear (least squares in log-log, :func:`rsf.fit_power_law`).
    Without it V^c is a third parameter (bounded above the largest V), fitted by nonlinear
    least squares in log space — the right choice when V^c is only known to a bisection
    bracket.

    Parameters
    ----------
    V, amplitude : array_like
        Velocities and stick-slip amplitudes, 1-D and of equal length; points that are not
        finite or have amplitude <= 0 are dropped.
    Vc : float, optional
        The critical velocity, > every V; fitted if not given.

    Returns
    -------
    PowerLawFit
        Exponent, prefactor, V^c (given or fitted) with their errors, and the rms in log.

    Raises
    ------
    ValueError
        If ``V`` and ``amplitude`` are not 1-D of equal length, fewer than 3 usable points
        remain (4 without ``Vc``), or ``Vc`` is not a finite number > every V.

    Examples
    --------
    >>> import numpy as np
    >>> from compare import fit_power_law
    >>> V = 1.3 * (1.0 - np.geomspace(1e-3, 0.1, 6))
    >>> fit = fit_power_law(V, 0.2 * (1.3 - V) ** 0.5, Vc=1.3)
    >>> round(fit.exponent, 6), round(fit.prefactor, 6)
    (0.5, 0.2)
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
        # the linear fit in log-log is rsf's (the same least squares; compare builds on rsf)
        beta, beta_err, c, _ = rsf.fit_power_law(Vc - V, amp)
        r = np.log(amp) - (math.log(c) + beta * np.log(Vc - V))
        return PowerLawFit(beta, beta_err, c, Vc, 0.0, False, int(V.size), float(math.sqrt(np.mean(r * r))))
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


#: How a transition point's amplitude error is known (the column ``amplitude_error_kind`` of
#: the report's ``hopf_points``); :func:`transition_fits` fits only the points whose error is known.
AMPLITUDE_ERROR_KINDS: dict[str, str] = {
    "bound": "a bound on the error: the cohort method's discretisation error (the change from twice the time "
             "step and cell) plus its fixed point's, for each extremum",
    "standard error": "a standard error: the N-block's, from the spread of its cycles",
    "solver tolerance": "below the solver's tolerance (RS by CVODE at rtol 1e-11): no bar",
    "not known": "not known (the cohort method closer to V^c than micro.api.NEAR_VC; the Fokker-Planck "
                 "equation without a study in eps): drawn open, not fitted",
}


def transition_fits(points: pd.DataFrame, *, level: float = 0.95) -> pd.DataFrame:
    r"""The amplitude law :math:`\sigma_{max} - \sigma_{min} = c\,(V^c - V)^\beta` of each
    method of a transition study, with the confidence interval of β and the range of
    :math:`d = (V^c - V)/V^c` it rests on.

    One fit per (model, method, resolution) group of ``points``, by
    :func:`fit_power_law` at the group's exact ``Vc``, on its stick-slip points with an
    amplitude > 0 whose error is known: a point whose ``amplitude_error_kind`` is
    ``'not known'`` (:data:`AMPLITUDE_ERROR_KINDS`) is left out and counted in
    ``n_not_fitted``, so a method none of whose points has a known error (a
    Fokker-Planck cycle not converged in eps) has no row.

    The interval is at ``level``: Student's t with n − 2 degrees of freedom on the
    scatter about the line (``exponent_err``), combined in quadrature with what the
    points' own error bars can move the slope (the slope's weights
    :math:`(x_i - \bar x)/S_{xx}` on :math:`\ln` amplitude, :math:`x = \ln d`, times the
    relative error :math:`e_i/A_i`): summed in absolute value for bounds, at the normal
    quantile of ``level`` in quadrature for standard errors.  The scatter term is large
    with few points (t = 12.7 for 3 points at 95 %): the interval says how little three
    points settle.

    Parameters
    ----------
    points : DataFrame
        Columns ``model, method, resolution, V, Vc, d, regime, amplitude``; optional
        ``amplitude_stderr`` (the error bar of the amplitude) and
        ``amplitude_error_kind`` (a key of :data:`AMPLITUDE_ERROR_KINDS`; without it
        every point counts as known, without a bar).
    level : float
        Confidence level of ``beta_low, beta_high``, in (0, 1); default 0.95.

    Returns
    -------
    DataFrame
        One row per fitted group, in the order the groups first appear: ``model, method,
        resolution``, :meth:`PowerLawFit.to_dict`'s columns (``exponent, exponent_err,
        prefactor, Vc, Vc_err, Vc_fitted, n_points, rms_log``), then ``beta`` (=
        ``exponent``), ``beta_low, beta_high, ci_level, ci_basis`` (what the interval
        covers), ``d_min, d_max`` (the fitted points' range), ``n_not_fitted``, and
        ``error_kind`` (of the fitted points).

    Raises
    ------
    ValueError
        If ``level`` is not in (0, 1) or ``points`` lacks a column.

    Examples
    --------
    >>> import numpy as np, pandas as pd
    >>> from compare.fits import transition_fits
    >>> d = np.array([0.01, 0.03, 0.1, 0.3])
    >>> pts = pd.DataFrame({"model": "RS", "method": "CVODE", "resolution": np.nan, "Vc": 1.0, "d": d,
    ...                     "V": 1.0 - d, "regime": "stick-slip", "amplitude": 0.2 * d ** 0.5})
    >>> row = transition_fits(pts).iloc[0]
    >>> round(float(row.beta), 6), float(row.d_min), float(row.d_max), int(row.n_points)
    (0.5, 0.01, 0.3, 4)
    """
    from scipy import stats

    if not 0.0 < float(level) < 1.0:
        raise ValueError(f"level must lie in (0, 1), got {level!r}")
    need = {"model", "method", "resolution", "V", "Vc", "d", "regime", "amplitude"}
    missing = need - set(points.columns)
    if missing:
        raise ValueError(f"points must have columns {sorted(need)}; missing {sorted(missing)}")
    rows = []
    for (name, method, res), grp in points.groupby(["model", "method", "resolution"], dropna=False, sort=False):
        cyc = grp[(grp.regime == "stick-slip") & np.isfinite(grp.amplitude) & (grp.amplitude > 0)]
        kind = (cyc.amplitude_error_kind.fillna("not known").astype(str) if "amplitude_error_kind" in cyc
                else pd.Series("solver tolerance", index=cyc.index))
        use = cyc[kind != "not known"]
        kind = kind[use.index]
        if not len(use):
            if len(cyc):
                log.info("amplitude law %s %s %s: no point with a known error (%d shown, not fitted)",
                         name, method, res, len(cyc))
            continue
        try:
            f = fit_power_law(use.V, use.amplitude, Vc=float(use.Vc.iloc[0]))
        except (ValueError, IndexError) as exc:
            log.warning("amplitude law %s %s %s: %s", name, method, res, exc)
            continue
        x = np.log(use.d.to_numpy(float))
        xc = x - x.mean()
        w = xc / float(xc @ xc)
        err = use.amplitude_stderr.to_numpy(float) if "amplitude_stderr" in use else np.full(len(use), np.nan)
        rel = np.where(np.isfinite(err), err, 0.0) / use.amplitude.to_numpy(float)
        is_bound = (kind == "bound").to_numpy()
        is_se = (kind == "standard error").to_numpy()
        bound = float(np.sum(np.abs(w[is_bound]) * rel[is_bound]))
        se_pts = float(stats.norm.ppf(0.5 + level / 2) * math.sqrt(np.sum((w[is_se] * rel[is_se]) ** 2)))
        dof = f.n_points - 2
        scatter = float(stats.t.ppf(0.5 + level / 2, dof)) * f.exponent_err
        half = math.sqrt(scatter ** 2 + bound ** 2 + se_pts ** 2)
        basis = f"t ({dof} dof) on the scatter" + (" + the points' error bounds" if is_bound.any() else "") + (
            " + the points' standard errors" if is_se.any() else "")
        kinds = sorted(set(kind))
        rows.append({"model": name, "method": method, "resolution": res, **f.to_dict(),
                     "beta": f.exponent, "beta_low": f.exponent - half, "beta_high": f.exponent + half,
                     "ci_level": float(level), "ci_basis": basis, "d_min": float(use.d.min()),
                     "d_max": float(use.d.max()), "n_not_fitted": int(len(cyc) - len(use)),
                     "error_kind": ", ".join(kinds)})
    return pd.DataFrame(rows)


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
    """A two-parameter growth law fitted to peak-versus-hold data (:func:`fit_growth_law`).

    Attributes
    ----------
    law : str
        The law's name, a key of :data:`GROWTH_LAWS`.
    formula : str
        Its formula in the parameters' names.
    names, values, errors : tuple of two
        The parameters' names, fitted values and standard errors (nan if the fit failed).
    rms : float
        Root-mean-square residual in Δσ.
    rel_rms : float
        ``rms`` over the largest Δσ.
    n_points : int
        Points fitted.
    success : bool
        Whether the least squares converged (else ``values`` are the starting guess).
    message : str
        Why it did not.
    """

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

    Parameters
    ----------
    hold_time, delta_sigma : array_like
        Hold times (>= 0) and peak increases, 1-D of equal length; non-finite points and
        negative hold times are dropped.
    law : {'exponential', 'algebraic', 'logarithmic'}
        The law to fit.

    Returns
    -------
    GrowthFit
        Its two parameters with errors and the residual; a fit that does not converge is
        returned with ``success=False`` and its ``message``, not raised.

    Raises
    ------
    ValueError
        If ``law`` is unknown, the arrays are not 1-D of equal length, or fewer than 3
        usable points remain.

    Examples
    --------
    >>> import numpy as np
    >>> from compare import fit_growth_law
    >>> t = np.geomspace(0.1, 100.0, 10)
    >>> g = fit_growth_law(t, 0.05 * (1.0 - np.exp(-t / 2.0)), "exponential")
    >>> g.names, tuple(round(x, 6) for x in g.values)
    (('d_inf', 'tau'), (0.05, 2.0))
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
