r"""The rate-and-state side of the comparison, on top of :mod:`rsf` (fast, not cached).

* :func:`rs_curves` — σ_max, σ_min of the RS attractor on a dense V grid per k0.
* :func:`rs_hopf` — amplitudes at :math:`V = V^c(1 - d)` for given relative distances d.
* :func:`rs_slide_hold_slide` — the peak after a hold, for any :class:`rsf.SpringSlider`
  (Eq. 11 with a = 0, or the classical Eq. 7 with a direct effect).
* :func:`classical_rs` — Eq. (7) with the same local velocity weakening as a given
  steady law at V: :math:`b - a = W(V)`.
"""
from __future__ import annotations

import math
import time
from typing import Callable, Sequence

import numpy as np
import pandas as pd

import rsf

from ._validation import positive

__all__ = ["rs_curves", "rs_hopf", "rs_slide_hold_slide", "classical_rs", "warm_up", "DEFAULT_OPTIONS"]

#: Limit cycles to 1e-7 (relative), CVODE rtol 1e-8: far below the micro errors.
DEFAULT_OPTIONS = rsf.SolverOptions(cycle_rtol=1e-7, rtol=1e-8)


def rs_curves(k0s: Sequence[float], law_for: Callable[[float], rsf.SteadyStateLaw], Dc: float, *,
              V_range: Callable[[float], tuple[float, float]], n: int = 80,
              options: rsf.SolverOptions | None = None, label: str = "") -> pd.DataFrame:
    """RS attractors on ``n`` log-spaced velocities per k0 (``V_range(k0)`` gives the ends).

    Where the critical velocity or the lower end of the unstable band falls inside the
    range, velocities just beside it are added, so that the curves resolve the
    bifurcation.

    Parameters
    ----------
    k0s : sequence of float
        Driving stiffnesses, > 0.
    law_for : callable
        k0 -> the RS steady-state law (an :class:`rsf.SteadyStateLaw`).
    Dc : float
        Critical slip distance, > 0.
    V_range : callable
        k0 -> (lowest, highest) velocity, both > 0.
    n : int
        Velocities per k0 before the additions (default 80).
    options : rsf.SolverOptions, optional
        For the limit cycles; default :data:`DEFAULT_OPTIONS`.
    label : str
        Written in the ``label`` column (which law or D_c the curves are for).

    Returns
    -------
    DataFrame
        ``k0, V, regime, sigma_max, sigma_min, sigma_mean, converged, Dc, label``, one row
        per velocity.

    Raises
    ------
    ValueError
        If rsf refuses a parameter (a k0, Dc or velocity that is not a finite number > 0).

    Examples
    --------
    >>> import rsf
    >>> from compare import rs_curves
    >>> curves = rs_curves([0.1], lambda k0: rsf.HyperbolicLaw(), 0.06, V_range=lambda k0: (0.5, 5.0), n=4)
    >>> sorted(set(curves.regime))
    ['steady', 'stick-slip']
    """
    options = options or DEFAULT_OPTIONS
    frames = []
    for k0 in k0s:
        lo, hi = V_range(k0)
        model = rsf.SpringSlider(law=law_for(k0), k0=k0, Dc=Dc)
        Vs = np.geomspace(lo, hi, int(n))
        cv = rsf.critical_velocity(model)
        if math.isfinite(cv.Vc) and lo < cv.Vc < hi:   # resolve the bifurcation point itself
            Vs = np.union1d(Vs, cv.Vc * (1.0 - np.array([1e-2, 3e-3, 1e-3, 1e-4])))
            Vs = np.union1d(Vs, [cv.Vc * (1.0 + 1e-4)])
        if math.isfinite(cv.V_lower) and lo < cv.V_lower < hi:
            Vs = np.union1d(Vs, cv.V_lower * np.array([1.0 - 1e-4, 1.0 + 1e-4]))
        frame = rsf.sweep(model, Vs, options=options).to_frame()
        frame["k0"] = k0
        frames.append(frame[["k0", "V", "regime", "sigma_max", "sigma_min", "sigma_mean", "converged"]])
    out = pd.concat(frames, ignore_index=True)
    out["Dc"] = Dc
    out["label"] = label
    return out


def rs_hopf(model: rsf.SpringSlider, distances: Sequence[float], *,
            options: rsf.SolverOptions | None = None) -> pd.DataFrame:
    """Limit cycles at :math:`V = V^c (1 - d)`; columns ``d, V, Vc, amplitude, sigma_max,
    sigma_min, regime, converged``.

    Parameters
    ----------
    model : rsf.SpringSlider
        The RS model; it must have a finite critical velocity.
    distances : sequence of float
        Relative distances d below V^c, each in (0, 1).
    options : rsf.SolverOptions, optional
        Default ``cycle_rtol=1e-10, rtol=1e-11, atol=1e-13`` (small amplitudes near V^c).

    Returns
    -------
    DataFrame
        One row per distance, with the columns above.

    Raises
    ------
    ValueError
        If the model has no finite critical velocity or a distance lies outside (0, 1).

    Examples
    --------
    >>> import rsf
    >>> from compare import rs_hopf
    >>> rs_hopf(rsf.SpringSlider(k0=0.1), [0.01]).regime.tolist()
    ['stick-slip']
    """
    cv = rsf.critical_velocity(model)
    if not (math.isfinite(cv.Vc) and cv.Vc > 0):
        raise ValueError(f"no finite RS critical velocity for k0 = {model.k0!r}, Dc = {model.Dc!r}")
    options = options or rsf.SolverOptions(cycle_rtol=1e-10, rtol=1e-11, atol=1e-13)
    rows = []
    for d in distances:
        d = float(d)
        if not 0.0 < d < 1.0:
            raise ValueError(f"distances must lie in (0, 1), got {d!r}")
        V = cv.Vc * (1.0 - d)
        r = rsf.limit_cycle(model, V, options=options)
        rows.append({"d": d, "V": V, "Vc": cv.Vc, "amplitude": r.sigma_max - r.sigma_min,
                     "sigma_max": r.sigma_max, "sigma_min": r.sigma_min, "regime": r.regime,
                     "converged": r.converged})
    return pd.DataFrame(rows)


def rs_slide_hold_slide(model: rsf.SpringSlider, V: float, hold_times: Sequence[float], *,
                        options: rsf.SolverOptions | None = None) -> pd.DataFrame:
    r"""Peak stress after a hold, starting from steady sliding at ``V``.

    For each hold: slide for :math:`D_c/V` from the exact steady state, stop the drive for
    the hold, reload at V; the peak is the largest σ after the reload starts (a stick end
    on the threshold for a = 0, the σ-maximum event for a > 0).

    Parameters
    ----------
    model : rsf.SpringSlider
        Any RS model (Eq. 11 with a = 0, or a direct effect a > 0).
    V : float
        The sliding velocity before and after the hold, > 0.
    hold_times : sequence of float
        Hold durations, each > 0.
    options : rsf.SolverOptions, optional
        Default ``rtol=1e-9``.

    Returns
    -------
    DataFrame
        ``hold_time, sigma_steady, sigma_peak, delta_sigma_max, status`` per hold (a run
        that fails keeps its negative rsf status; its peak is what it reached).

    Raises
    ------
    ValueError
        If ``V`` or a hold time is not a finite number > 0.

    Examples
    --------
    >>> import rsf
    >>> from compare import rs_slide_hold_slide
    >>> shs = rs_slide_hold_slide(rsf.SpringSlider(k0=0.1), 1.0, [1.0, 10.0])
    >>> bool(shs.delta_sigma_max.iloc[1] > shs.delta_sigma_max.iloc[0] > 0)
    True
    """
    V = positive("V", V)
    options = options or rsf.SolverOptions(rtol=1e-9)
    sigma_ss = model.sigma_steady(V)
    slide = model.Dc / V
    rows = []
    for h in hold_times:
        h = positive("hold_time", h)
        # reload until well past the peak: the stick needs (peak - sigma_ss)/(k0 V); the
        # peak is below sup(mu_ss) (Eq. 10) or ~ b ln(1 + h V/Dc) (Eq. 7)
        law = model.law
        if isinstance(law, rsf.LogLaw):
            gain = law.b * math.log1p(h * V / model.Dc) + law.a * 10.0
        else:
            gain = float(np.max(law.mu_ss(np.array([1e-12])))) - sigma_ss
        reload = 4.0 * max(gain, 1e-6) / (model.k0 * V) + 200.0 * model.Dc / V
        protocol = rsf.Protocol.slide_hold_slide(V, slide, h)
        run = rsf.simulate(model, protocol=protocol, t_end=slide + h + reload,
                           initial=rsf.InitialState(perturbation=0.0), options=options)
        after = run.t >= slide + h
        peak = float(np.max(run.sigma[after])) if np.any(after) else math.nan
        ev = run.events_frame()
        ev = ev[ev.t >= slide + h]
        if len(ev):
            peak = max(peak, float(ev.sigma.max()))
        rows.append({"hold_time": h, "sigma_steady": sigma_ss, "sigma_peak": peak,
                     "delta_sigma_max": peak - sigma_ss, "status": run.status})
    return pd.DataFrame(rows)


def classical_rs(law: rsf.SteadyStateLaw, V: float, b: float, k0: float, Dc: float) -> rsf.SpringSlider:
    r"""The classical RS spring-slider, Eq. (7), tangent to ``law`` at ``V``:

    .. math:: \mu = \mu_0 + a\ln(v/V) + b\ln(\theta V/D_c),\qquad \mu_0 = \mu_{ss}(V),\quad
              b - a = W(V) = -V\,\mu_{ss}'(V),

    so that its steady friction and its velocity weakening at V equal those of ``law``;
    ``b`` (> W(V)) is the one free constant.

    Parameters
    ----------
    law : rsf.SteadyStateLaw
        The steady law to be tangent to, with every parameter set (a
        :class:`rsf.HyperbolicLaw` with its ``mu_inf``, or bound to a k0).
    V : float
        The velocity of tangency and the log law's reference velocity, > 0.
    b : float
        The evolution effect, > W(V).
    k0, Dc : float
        Stiffness and critical slip distance of the spring-slider, > 0.

    Returns
    -------
    rsf.SpringSlider
        With ``LogLaw(mu0=law.mu_ss(V), a=b - W(V), b=b, v0=V)`` and the direct effect
        ``a``.

    Raises
    ------
    ValueError
        If ``V``, ``b``, ``k0`` or ``Dc`` is not a finite number > 0, ``b <= W(V)``, or the
        law still depends on k0 (its ``mu_inf`` unset).

    Examples
    --------
    >>> import rsf
    >>> from compare import classical_rs
    >>> model = classical_rs(rsf.HyperbolicLaw().bind(0.1), V=1.0, b=0.02, k0=0.1, Dc=0.06)
    >>> round(model.law.b - model.law.a, 6), round(model.sigma_steady(1.0), 6)
    (0.006024, 0.951494)
    """
    V, b = positive("V", V), positive("b", b)
    W = float(law.weakening(np.array([V]))[0])
    if not b > W:
        raise ValueError(f"b must be > W(V) = {W!r} so that a = b - W(V) > 0, got {b!r}")
    mu0 = float(law.mu_ss(np.array([V]))[0])
    return rsf.SpringSlider(law=rsf.LogLaw(mu0=mu0, a=b - W, b=b, v0=V), k0=k0, Dc=Dc)


def warm_up() -> float:
    """Compile (or load from numba's disk cache) the rsf kernels the report uses, with
    tiny runs of each kind of call (curves with their limit cycles on Eq. 11, and a
    slide-hold-slide of the classical law, Eq. 7); returns the seconds it took.  The
    report runs it in a thread of its own process while the pool's workers compile micro's
    kernels, so that the two compilations overlap on a fresh install."""
    start = time.perf_counter()
    rs_curves([0.1], lambda k0: rsf.HyperbolicLaw(), 0.06, V_range=lambda k0: (0.5, 5.0), n=4)
    law = rsf.HyperbolicLaw().bind(0.1)
    # (D_c = 0.3: stiffer than critical, (b - a) / D_c = 0.02 < k0, so the reload after the hold
    # does not run away and the warm-up logs nothing; at D_c = 0.06 it was exactly critical and
    # every report printed a 'runaway slip' warning of its own warm-up)
    rs_slide_hold_slide(classical_rs(law, 1.0, 0.02, 0.1, 0.3), 1.0, [1.0])
    rs_slide_hold_slide(rsf.SpringSlider(k0=0.1), 1.0, [1.0])
    return time.perf_counter() - start
