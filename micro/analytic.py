"""Closed-form results for the stationary stress of the mean-field model.

* Eq. (4) of the paper: steady sliding with deterministic jumps, any V.
* The V -> infinity limit for any g (Eq. (6) is its deterministic case), with the first
  1/V correction, and the V -> 0 limit of steady sliding (k0 > k2) for any g (Eq. (5)).

The derivations are in ``docs/reference/micro_model.md`` (and, for the corrections, in
``docs/reference/micro_nblock.md``).  Both solvers are tested against these.
"""
from __future__ import annotations

import math

import numpy as np

from .params import JumpDistribution, Model

__all__ = ["sigma_deterministic_steady", "sigma_fast_limit", "sigma_slow_limit"]


def _check_model(model: Model) -> None:
    if not isinstance(model, Model):
        raise ValueError(f"model must be a micro.Model, got {type(model).__name__}")


def _check_float(name: str, value, *, low: float = -math.inf, strict: bool = False) -> float:
    try:
        v = float(value)
    except (TypeError, ValueError):
        raise ValueError(f"{name} must be a number, got {value!r}") from None
    ok = math.isfinite(v) and (v > low if strict else v >= low)
    if not ok:
        raise ValueError(f"{name} must be a finite number {'>' if strict else '>='} {low}, got {value!r}")
    return v


def sigma_deterministic_steady(model: Model, velocity: float) -> float:
    r"""Eq. (4): the stationary stress for deterministic jumps :math:`g(z) = \delta(z - \bar z)`.

    .. math:: \sigma(V) = f_{th} - \left[V\eta_u - \frac{\bar z k_2}{e^{\bar z k_2/V\eta_u} - 1}\right]
              - \frac{\bar z}{2}(k_0 + k_1)

    It assumes steady sliding (each block jumps every :math:`\bar z / V`); it uses the mean of
    ``model.jumps`` as :math:`\bar z` and is exact only for :class:`Deterministic` jumps.

    Parameters
    ----------
    model : Model
        The model (its jumps' mean is :math:`\bar z`).
    velocity : float
        The drive velocity V >= 0.

    Returns
    -------
    float
        The stationary stress of Eq. (4).

    Raises
    ------
    ValueError
        If ``model`` is not a :class:`Model` or ``velocity`` is not a finite number >= 0.
    """
    _check_model(model)
    v = _check_float("velocity", velocity, low=0.0)
    zbar, k2, eta = model.jumps.mean, model.k2, model.eta_u
    if v == 0.0:
        bracket = 0.0
    else:
        a = zbar * k2 / (v * eta)
        if a < 0.1:
            # V eta (1 - a / (e^a - 1)) by its Bernoulli series: the difference loses
            # 2e-16 / a of the bracket (1.7e-11 in sigma at a = 1e-6); the first term left
            # out, a^11 / 1.9e9, is below 1e-20 of it here
            bracket = zbar * k2 * (0.5 - a / 12.0 + a**3 / 720.0 - a**5 / 30240.0 + a**7 / 1209600.0
                                   - a**9 / 47900160.0)
        else:
            bracket = v * eta - zbar * k2 * math.exp(-a) / -math.expm1(-a)  # (no overflow at small V)
    return model.f_th - bracket - 0.5 * zbar * (model.k0 + model.k1)


def _residual_variance(dist: JumpDistribution, n_grid: int = 400_001) -> float:
    r"""Variance of the equilibrium residual R (density :math:`(1 - G(r))/\langle z\rangle`),
    :math:`\langle z^3\rangle/(3\langle z\rangle) - (\langle z^2\rangle/(2\langle z\rangle))^2`, by the midpoint rule."""
    edges = np.linspace(0.0, float(dist.z_max), n_grid)
    mid = 0.5 * (edges[1:] + edges[:-1])
    weight = (1.0 - np.asarray(dist.cdf(mid), dtype=float)) * np.diff(edges)
    total = weight.sum()
    mean = float(np.sum(weight * mid) / total)
    second = float(np.sum(weight * mid * mid) / total)
    return second - mean * mean


def sigma_fast_limit(model: Model, velocity: float | None = None) -> float:
    r"""The large-V stationary stress for any g.

    .. math:: \sigma(V) = f_{th} - \kappa \frac{\langle z^2\rangle}{2\langle z\rangle}
              + \frac{k_2 \gamma}{V} \operatorname{Var}(R) + O(V^{-2})

    At :math:`V \to \infty` dashpots are frozen and every :math:`\delta_i` is a renewal
    process that decreases at speed :math:`\kappa V` and jumps by :math:`\kappa z`; its
    mean is :math:`\kappa` times the mean residual. Eq. (6) is the deterministic case
    (:math:`\kappa \bar z / 2`). With ``velocity`` the first correction is added: the
    dashpot slows the decrease of :math:`\delta` by :math:`k_2\gamma(\langle R\rangle - R)`,
    which reweights the residual R (whose variance is :math:`\bar z^2/12` for deterministic
    g, reproducing the large-V expansion of Eq. (4), and :math:`\approx \bar z^2` for
    exponential g). Valid for :math:`V \gg \gamma \bar z`.

    Parameters
    ----------
    model : Model
        The model.
    velocity : float, optional
        The drive velocity V > 0 for the first correction; None (default) gives the
        V -> infinity limit.

    Returns
    -------
    float
        The stress at V -> infinity, or with its 1/V correction.

    Raises
    ------
    ValueError
        If ``model`` is not a :class:`Model` or ``velocity`` is not a finite number > 0.
    """
    _check_model(model)
    sigma = model.f_th - model.kappa * model.jumps.mean_residual
    if velocity is not None:
        v = _check_float("velocity", velocity, low=0.0, strict=True)
        sigma += model.k2 * model.gamma * _residual_variance(model.jumps) / v
    return sigma


def sigma_slow_limit(model: Model, velocity: float = 0.0) -> float:
    r"""The small-V stationary stress for k0 > k2 (steady quasi-static sliding), any g:

    .. math:: \sigma(V) = f_{th} - (k_0 + k_1)\frac{\langle z^2\rangle}{2\langle z\rangle} - \eta_u V + O(V^2)

    Dashpots relax between a block's jumps, so its relaxed margin is a renewal process with
    increments :math:`(k_0+k_1) z`; a block jumps when the common relaxed signal lags
    :math:`\bar h` by :math:`V/\gamma`, i.e. with relaxed margin :math:`k_2 V/\gamma = \eta_u V`.
    Eq. (5) is the deterministic case at V = 0.

    Parameters
    ----------
    model : Model
        The model.
    velocity : float, optional
        The drive velocity V >= 0 (default 0: the V -> 0 limit).

    Returns
    -------
    float
        The stress to first order in V.

    Raises
    ------
    ValueError
        If ``model`` is not a :class:`Model` or ``velocity`` is not a finite number >= 0.
    """
    _check_model(model)
    v = _check_float("velocity", velocity, low=0.0)
    return model.f_th - (model.k0 + model.k1) * model.jumps.mean_residual - model.eta_u * v
