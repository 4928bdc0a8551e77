r"""The stick-slip amplitude near the Hopf bifurcation: :func:`hopf_scaling` measures
:math:`\sigma_{max} - \sigma_{min}` at :math:`V = V^c(1 - \epsilon)` with
:func:`rsf.limit_cycle` and fits :math:`(V^c - V)^\beta` with :func:`fit_power_law`
(``docs/reference/rsf.md`` §7)."""
from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Sequence

import numpy as np
import pandas as pd

from .params import SolverOptions, SpringSlider
from .solver import limit_cycle
from .stability import critical_velocity

__all__ = ["HopfFit", "hopf_scaling", "fit_power_law"]


def fit_power_law(x: np.ndarray, y: np.ndarray) -> tuple[float, float, float, float]:
    r"""Least-squares fit of :math:`\ln y = \ln c + \beta \ln x`.

    The standard errors come from the residuals (``s^2 = SSR / (n - 2)``), so that they
    stay right for a nearly exact power law: the textbook form through the correlation
    coefficient, :math:`\sqrt{(1 - r^2)\,S_{yy}/S_{xx}/(n-2)}`, loses every digit once
    :math:`1 - r^2` is below the round-off (amplitudes converged to 1e-8 gave 0).
    :func:`compare.fit_power_law` uses this fit when V^c is given.

    Parameters
    ----------
    x, y : array_like
        Positive abscissae and ordinates of equal length, at least 3 of them (a zero or
        negative value gives nan: its logarithm is taken as it is).

    Returns
    -------
    beta : float
        The exponent (the slope in log-log).
    beta_stderr : float
        Its standard error.
    c : float
        The prefactor, :math:`e^{\ln c}`.
    lnc_stderr : float
        The standard error of :math:`\ln c` (the intercept).

    Raises
    ------
    ValueError
        If fewer than 3 points are given (no uncertainty without a degree of freedom).

    Examples
    --------
    >>> beta, dbeta, c, _ = fit_power_law([1e-4, 1e-3, 1e-2], [0.02, 0.0632, 0.2])
    >>> round(beta, 3), round(c, 2)
    (0.5, 2.0)
    """
    lx = np.log(np.asarray(x, dtype=float))
    ly = np.log(np.asarray(y, dtype=float))
    n = lx.size
    if n < 3:
        raise ValueError(f"need at least 3 points for a fit with an uncertainty, got {n}")
    xm, ym = float(np.mean(lx)), float(np.mean(ly))
    dx = lx - xm
    sxx = float(dx @ dx)
    beta = float(dx @ (ly - ym)) / sxx
    lnc = ym - beta * xm
    r = ly - (lnc + beta * lx)
    s2 = float(r @ r) / (n - 2)
    return beta, math.sqrt(s2 / sxx), math.exp(lnc), math.sqrt(s2 * (1.0 / n + xm * xm / sxx))


@dataclass
class HopfFit:
    r"""Amplitude :math:`\sigma_{max} - \sigma_{min}` against :math:`V^c - V` near the
    bifurcation (:func:`hopf_scaling`).

    ``exponent`` and ``exponent_stderr`` come from a least-squares fit of
    :math:`\ln(\sigma_{max}-\sigma_{min})` on :math:`\ln(V^c - V)` over the points with
    :math:`(V^c - V)/V^c \le` ``fit_max``; ``local_exponents`` are the slopes between
    neighbouring points (they show where the scaling holds).

    Attributes
    ----------
    k0 : float
        The driving stiffness of the model.
    Vc : float
        Its critical velocity (:func:`~rsf.critical_velocity`).
    epsilon : ndarray
        The relative distances :math:`(V^c - V)/V^c` measured, as given.
    amplitude, sigma_min, sigma_max : ndarray
        :math:`\sigma_{max} - \sigma_{min}` and the extrema of the limit cycle at each
        epsilon.
    exponent, exponent_stderr : float
        The fitted :math:`\beta` and its standard error.
    prefactor : float
        The fitted :math:`c` in :math:`c\,(V^c - V)^\beta`.
    fit_max : float
        The largest epsilon that entered the fit.
    local_exponents : ndarray
        :math:`\mathrm{d}\ln A/\mathrm{d}\ln(V^c - V)` between neighbouring points, in
        increasing :math:`V^c - V` (one fewer than the points).
    converged : bool
        Whether every limit cycle converged to a stick-slip cycle.
    """

    k0: float
    Vc: float
    epsilon: np.ndarray          # (Vc - V) / Vc
    amplitude: np.ndarray
    sigma_min: np.ndarray
    sigma_max: np.ndarray
    exponent: float
    exponent_stderr: float
    prefactor: float
    fit_max: float
    local_exponents: np.ndarray
    converged: bool

    def to_frame(self) -> pd.DataFrame:
        return pd.DataFrame({"k0": self.k0, "Vc": self.Vc, "epsilon": self.epsilon,
                             "V": self.Vc * (1.0 - self.epsilon), "amplitude": self.amplitude,
                             "sigma_min": self.sigma_min, "sigma_max": self.sigma_max})


def hopf_scaling(model: SpringSlider, epsilon: Sequence[float] | None = None, *,
                 fit_max: float = 1e-4, options: SolverOptions | None = None) -> HopfFit:
    r"""Measure the stick-slip amplitude at :math:`V = V^c(1 - \epsilon)` and fit
    :math:`\sigma_{max} - \sigma_{min} \propto (V^c - V)^\beta`.

    Parameters
    ----------
    model : SpringSlider
        The slider; it must have a finite critical velocity :math:`V^c > 0`.
    epsilon : sequence of float, optional
        Relative distances below Vc, in (0, 1); default 13 values from 1e-7 to 1e-1
        (geometric).
    fit_max : float
        Only points with epsilon <= fit_max enter the fit (default 1e-4: the scaling
        region next to the bifurcation); at least 3 must.
    options : SolverOptions, optional
        Default: cycle_rtol = 1e-11, rtol = 1e-12, atol = 1e-14 (the amplitude at
        epsilon = 1e-7 is ~1e-4 of sigma).

    Returns
    -------
    HopfFit
        The amplitudes, the fitted exponent and prefactor and the local exponents;
        ``converged`` is False if a limit cycle did not converge to stick-slip.

    Raises
    ------
    ValueError
        If the model has no finite critical velocity, ``epsilon`` holds a value outside
        (0, 1), or fewer than 3 points have epsilon <= ``fit_max``.

    Examples
    --------
    >>> import rsf
    >>> fit = rsf.hopf_scaling(rsf.SpringSlider(k0=0.3), [1e-6, 1e-5, 1e-4])
    >>> round(fit.exponent, 3)
    0.5
    """
    cv = critical_velocity(model)
    if not (math.isfinite(cv.Vc) and cv.Vc > 0):
        raise ValueError(f"no finite critical velocity for k0 = {model.k0!r}, Dc = {model.Dc!r}")
    eps = np.asarray(np.geomspace(1e-7, 1e-1, 13) if epsilon is None else epsilon, dtype=float)
    if np.any(~np.isfinite(eps)) or np.any(eps <= 0.0) or np.any(eps >= 1.0):
        raise ValueError("epsilon must hold values in (0, 1)")
    options = options or SolverOptions(cycle_rtol=1e-11, rtol=1e-12, atol=1e-14)
    amp, smin, smax, ok = [], [], [], True
    for e in eps:
        r = limit_cycle(model, cv.Vc * (1.0 - e), options=options)
        ok = ok and r.converged and r.regime == "stick-slip"
        amp.append(r.sigma_max - r.sigma_min)
        smin.append(r.sigma_min)
        smax.append(r.sigma_max)
    amp = np.array(amp)
    x = eps * cv.Vc
    sel = eps <= fit_max
    beta, dbeta, c, _ = fit_power_law(x[sel], amp[sel])
    order = np.argsort(x)
    local = np.diff(np.log(amp[order])) / np.diff(np.log(x[order]))
    return HopfFit(model.k0, cv.Vc, eps, amp, np.array(smin), np.array(smax), beta, dbeta, c,
                   fit_max, local, ok)
