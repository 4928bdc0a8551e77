r"""What the scenarios of a report share: the settings, the runner, and the stages that
several scenarios need, each computed at most once and only when first asked for.

* :meth:`Context.model`: the micro model at (k0, k1, k2), built once;
* :meth:`Context.Vc`: micro's exact V^c (the renewal chain, direct);
* :attr:`Context.branch`: micro's exact steady branch on both sides of V^c at every k0 of
  the settings (with the growth rate of the unstable mode below it), and the reference
  branch at ``reference_k0``;
* :attr:`Context.critical`: micro's exact V^c at every k0 of the diagram;
* :attr:`Context.steady_fit` and :meth:`Context.law_for`: the Eq. (10) fit to that branch
  (shared A, B, one offset per k0) and the law at any k0;
* :attr:`Context.micro_points`, :attr:`Context.dc_fit`, :attr:`Context.dc_critical` and
  :attr:`Context.Dc`: D_c two ways, from the stick-slip extrema (a) and from V^c matching
  (b), or the D_c given.

The stages write their tables and values into :attr:`Context.tables` and
:attr:`Context.values` as they are computed.  :meth:`Context.vc_k0` and
:meth:`Context.tasks` declare the micro tasks of the stages, so that the report can run
them in one batch with the scenarios' own (:func:`compare.report`).  The shared stages
have a figure each (``steady_fit.png``, ``dc_profile.png``) and a paragraph of the
summary (:meth:`Context.summary`).
"""
from __future__ import annotations

import logging
import math
from functools import cached_property, partial
from pathlib import Path
from typing import Any, Sequence

import numpy as np
import pandas as pd

import micro
import rsf

from . import figures, fits
from .params import PAPER_K0, Settings
from .runner import Runner
from .summary import STEADY_TOL, fmt, pct
from .tasks import StationaryTask, SteadyTask, Task, VcTask

__all__ = ["Context", "micro_frame", "sig"]

log = logging.getLogger(__name__)

#: The figures of the shared stages, in the order the report shows them.
SHARED_FIGURES = ("steady_fit", "dc_profile")


def micro_frame(records: Sequence[dict[str, Any]], **columns: Any) -> pd.DataFrame:
    """Stationary records of a :class:`Runner` as one row each (failed tasks keep their
    ``error`` with NaN results).

    Parameters
    ----------
    records : sequence of dict
        Records of :class:`StationaryTask` runs, as :meth:`Runner.run` or
        :func:`execute` return them.
    **columns
        Extra columns, each set on every row (a scalar, or one value per record).

    Returns
    -------
    pandas.DataFrame
        One row per record: the result's fields (:meth:`micro.Stationary.to_dict`), or
        for a failed task the model's ``k0, k1, k2, eta_u, f_th`` and ``V`` from its
        description; then ``status``, ``error`` (empty if none), ``wall_time``, and
        ``eps`` taken from the task's bin where the row has none (renewal rows, failed
        tasks); then ``columns``.

    Examples
    --------
    >>> import micro
    >>> from compare import StationaryTask, execute, micro_frame
    >>> task = StationaryTask(micro.Model(k0=0.1), 2.0, micro.Numerics(), micro.Convergence())
    >>> frame = micro_frame([execute(task)], role="demo")
    >>> frame.loc[0, ["method", "regime", "status", "role"]].tolist()
    ['renewal', 'steady', 'ok', 'demo']
    >>> round(float(frame.eps[0]), 12)                     # the task's bin, kappa zbar / 50
    0.0022
    """
    rows = []
    for rec in records:
        row = dict(rec.get("result") or {})
        task = rec["task"]
        if not row:
            row.update(task["model"])
            row.pop("jumps", None)
            if "V" in task:
                row["V"] = task["V"]
        row.pop("jumps", None)
        row["status"] = rec.get("status")
        row["error"] = rec.get("error", "")
        row["wall_time"] = rec.get("wall_time", math.nan)
        if not math.isfinite(row.get("eps", math.nan)):  # (the FP's bin where the row has no resolution)
            row["eps"] = task.get("numerics", {}).get("eps", math.nan)
        rows.append(row)
    frame = pd.DataFrame(rows)
    for k, v in columns.items():
        frame[k] = v
    return frame


def sig(x: float) -> float:
    """A velocity rounded to 6 significant digits (readable, and the same task twice)."""
    return float(f"{x:.6g}")


class Context:
    """The settings, the runner and the shared stages of one report.

    Parameters
    ----------
    settings : Settings
        The report's settings (also :attr:`s`).
    runner : Runner
        Runs every micro task; its records are kept here, so a task is asked for once.
    Dc : float or None
        A D_c given instead of fitted (D_c from V^c matching is still computed).
    """

    def __init__(self, settings: Settings, runner: Runner, Dc: float | None = None) -> None:
        self.settings = self.s = settings
        self.runner = runner
        self.Dc_given = Dc
        self.tables: dict[str, pd.DataFrame] = {}
        self.values: dict[str, Any] = {}
        self._records: dict[str, dict[str, Any]] = {}
        self._models: dict[tuple[float, float, float], micro.Model] = {}
        self._figures: dict[str, Path] = {}

    # -- models and micro tasks ------------------------------------------------------------------
    def model(self, k0: float, k1: float | None = None, k2: float | None = None) -> micro.Model:
        """The micro model at ``k0`` (and optionally another (k1, k2)), built once."""
        key = (float(k0), float(self.s.k1 if k1 is None else k1), float(self.s.k2 if k2 is None else k2))
        if key not in self._models:
            self._models[key] = self.s.model(*key)
        return self._models[key]

    def run(self, tasks: Sequence[Task], desc: str) -> list[dict[str, Any]]:
        """Records of ``tasks``: the ones fetched already, the rest from the runner."""
        todo = [t for t in tasks if t.key not in self._records]
        if todo:
            for rec in self.runner.run(todo, desc=desc):
                self._records[rec["key"]] = rec
        return [self._records[t.key] for t in tasks]

    def vc_k0(self) -> list[float]:
        """The k0 whose exact V^c the shared stages place their tasks at (the first batch)."""
        s = self.s
        k0 = list(s.k0) + list(PAPER_K0) + [s.reference_k0]
        if self.Dc_given is None:
            k0 += list(s.fp_k0)
        return k0

    def tasks(self) -> list[Task]:
        """The shared stages' micro tasks (once the V^c of :meth:`vc_k0` are known): the
        steady branches and, without a D_c given, the stick-slip points of D_c (a)."""
        return self.branch_tasks() + (self.dc_tasks() if self.Dc_given is None else [])

    # -- micro, direct: V^c and the steady branch ------------------------------------------------
    def Vc(self, k0: float, k1: float | None = None, k2: float | None = None) -> float:
        """Micro's exact V^c (NaN when k0 >= k2: no stick-slip)."""
        rec = self.run([VcTask(self.model(k0, k1, k2))], "micro Vc (direct)")[0]
        if rec.get("status") != "ok":
            raise RuntimeError(f"micro V^c at k0 = {k0:g} failed: {rec.get('error')}")
        return float(rec["result"]["Vc"])

    def phase_k0(self, k2: float) -> list[float]:
        """The k0 of a V^c(k0) curve at ``k2`` (Figs. 4/8 and 5): ``phase_points``
        log-spaced from ``phase_k0_min`` to 0.98 k2."""
        s = self.s
        return [sig(k) for k in np.geomspace(s.phase_k0_min, 0.98 * k2, s.phase_points)]

    def branch_V(self, k0: float, k1: float | None = None, k2: float | None = None,
                 reference: tuple[float, ...] | None = None) -> tuple[float, ...]:
        """The velocities of the steady branch at ``k0``: both sides of V^c and the pair
        around it that gives micro's own slope there (``reference``: these)."""
        s = self.s
        if reference is not None:
            return tuple(sig(v) for v in reference)
        vc = self.Vc(k0, k1, k2)
        if not vc > 0.0:  # (NaN: no stick-slip)
            return tuple(sig(v) for v in np.geomspace(1e-3, 1e3, s.branch_points))
        hi = max(min(s.branch_span * vc, s.branch_V_max), 10 * vc)
        stable = vc * np.geomspace(1.0 + 1e-3, hi / vc, s.branch_points)
        below = vc * np.geomspace(s.unstable_from, 0.995, s.unstable_points)
        slope = vc * np.array([1.0 - 1e-3, 1.0 + 1e-3])          # -V dsigma/dV at V^c
        return tuple(sorted({sig(v) for v in np.concatenate([below, stable])} | {float(v) for v in slope}))

    def branch_tasks(self) -> list[SteadyTask]:
        s = self.s
        tasks = [SteadyTask(self.model(k0), self.branch_V(k0)) for k0 in s.k0]
        tasks.append(SteadyTask(self.model(s.reference_k0), self.branch_V(s.reference_k0, reference=s.reference_V)))
        return tasks

    @cached_property
    def branch(self) -> pd.DataFrame:
        """Micro's exact steady branch (stable above V^c, unstable below) per k0, and the
        reference branch at ``reference_k0`` (steady at every V)."""
        s = self.s
        tasks = self.branch_tasks()
        frames = []
        for task, rec in zip(tasks, self.run(tasks, "micro steady branch")):
            if rec.get("status") != "ok":
                raise RuntimeError(f"micro steady branch at k0 = {task.model.k0:g} failed: {rec.get('error')}")
            f = pd.DataFrame(rec["result"]["rows"])
            f["role"] = "reference" if task is tasks[-1] else "branch"
            frames.append(f)
        frame = pd.concat(frames, ignore_index=True)
        vcs = {k0: self.Vc(k0) for k0 in set(s.k0) | {s.reference_k0}}
        frame["Vc"] = [vcs[k] for k in frame.k0]
        self.tables["micro_branch"] = frame
        bad = frame[~frame.converged.astype(bool)]
        if len(bad):
            log.warning("micro steady branch: %d of %d points did not reach the tolerance 1e-11 (largest "
                        "sigma_error %.2g, branching_error %.2g); they are kept and flagged", len(bad), len(frame),
                        float(bad.sigma_error.max()), float(bad.branching_error.max()))
        return frame

    @cached_property
    def critical(self) -> pd.DataFrame:
        """Micro's exact V^c at every k0 with its error and small-k0 asymptote (the
        bifurcation scenario adds RS's)."""
        s = self.s
        rows = []
        for k0 in sorted(set(s.k0) | set(PAPER_K0), reverse=True):
            rec = self.run([VcTask(self.model(k0))], "micro Vc (direct)")[0]
            r = rec.get("result") or {}
            vc = float(r.get("Vc", math.nan))
            rows.append({"k0": k0, "Vc_micro": vc, "Vc_micro_err": 0.5 * (r.get("V_high", math.nan) - r.get("V_low", math.nan)),
                         "Vc_micro_small_k0": micro.vc_small_k0(self.model(k0)),
                         "micro_status": r.get("status", rec.get("error", "failed"))})
        return pd.DataFrame(rows)

    # -- Eq. (10) on the exact branch -----------------------------------------------------------
    @cached_property
    def steady_fit(self) -> fits.SteadyLawFit:
        """Eq. (10) fitted to the stable exact branch and the reference branch."""
        b = self.branch
        pts = b[b.stable.astype(bool) & np.isfinite(b.sigma) & (b.V > 0)]
        pts = pts[(pts.role == "reference") | (pts.V >= pts.Vc * (1.0 + 5e-3))]   # not the slope pair
        frame = pts.assign(regime="steady", sigma_mean=pts.sigma)
        fit = fits.fit_steady_law(frame)
        self.tables["steady_fit"] = fit.to_frame()
        self.tables["steady_fit_residuals"] = fit.residuals
        models = {float(k0): self.model(k0) for k0 in fit.offsets.k0}
        sigma_inf = {k0: micro.sigma_fast_limit(m) for k0, m in models.items()}
        tail = {k0: micro.sigma_fast_limit(m, 1.0) - sigma_inf[k0] for k0, m in models.items()}
        checks = fits.steady_law_checks(fit, sigma_inf, tail)
        self.tables["steady_fit_checks"] = checks
        self.values.update(A=fit.A, A_err=fit.A_err, B=fit.B, B_err=fit.B_err, steady_rms=fit.rms,
                           steady_max_residual=float(np.max(np.abs(fit.residuals.residual))))
        return fit

    def law_for(self, k0: float) -> rsf.HyperbolicLaw:
        """The fitted Eq. (10) at ``k0``: its own offset if micro's branch has steady
        points there, else the nearest fitted offset shifted by micro's exact fast-sliding
        limit (:func:`micro.sigma_fast_limit`), which carries the k0 dependence of the offset."""
        fit = self.steady_fit
        fitted = fit.offsets.k0.to_numpy(float)
        if np.any(np.isclose(fitted, k0, rtol=1e-12, atol=0)):
            return fit.law(k0)
        near = float(fitted[np.argmin(np.abs(np.log(fitted) - math.log(k0)))])
        shift = micro.sigma_fast_limit(self.model(k0)) - micro.sigma_fast_limit(self.model(near))
        return fit.law(mu_inf=fit.mu_inf(near) + shift)

    # -- micro, time-stepped: the stick-slip points --------------------------------------------
    def stationary_task(self, k0: float, V: float, eps: float, method: str = "auto") -> StationaryTask:
        """Micro's stationary state at (k0, V) by ``method`` at the bin ``eps``."""
        s = self.s
        return StationaryTask(self.model(k0), sig(V), s.numerics(eps), s.convergence(), method)

    def cycle_task(self, k0: float, V: float) -> StationaryTask:
        """Micro's stick-slip cycle at V by ``cycle_method``: ``"auto"``, micro's default
        (the cohort method at the step ``cycle_dt`` and its default cell, its fixed point to
        ``cycle_rtol`` of the velocity weakening), or the FP at ``eps``."""
        s = self.s
        if s.cycle_method == "fp":
            return self.stationary_task(k0, V, s.eps, "fp")
        model = self.model(k0)
        tol = s.cycle_rtol * (model.f_th - micro.sigma_fast_limit(model))
        return StationaryTask(model, V, s.numerics(), s.convergence(), "auto",
                              cohort=micro.Cohort(dt=s.cycle_dt, tol=min(max(tol, 1e-9), 1e-2)))

    def cycle_tasks(self, pairs) -> list[StationaryTask]:
        """The cycles at ``pairs`` (k0, V / V^c), where k0 has stick-slip."""
        return [self.cycle_task(k0, sig(r * self.Vc(k0))) for k0, r in pairs if self.Vc(k0) > 0]

    def points(self, pairs, role: str) -> pd.DataFrame:
        """The stick-slip cycles at ``pairs`` (k0, V / V^c), with their k0's V^c."""
        frame = micro_frame(self.run(self.cycle_tasks(pairs), "micro stick-slip"), role=role)
        frame["Vc"] = [self.Vc(k) for k in frame.k0]
        return frame

    def dc_tasks(self) -> list[StationaryTask]:
        """The stick-slip points that D_c (a) is fitted to (``fp_points``)."""
        return self.cycle_tasks(self.s.fp_points)

    @cached_property
    def micro_points(self) -> pd.DataFrame:
        """Micro's stick-slip points (by ``cycle_method``) and exact steady points that the
        D_c fit matches."""
        s = self.s
        frame = self.points(s.fp_points, "diagram")
        rows = []
        for k0 in s.fp_k0:
            vc = self.Vc(k0)
            V = [sig(r * vc) for r in s.steady_ratios] if vc > 0 else []
            if V:
                st = micro.steady_sliding(self.model(k0), V, growth_rate=False, warn=False)
                for v, sg, ok in zip(V, st.sigma, st.converged):
                    rows.append({"k0": k0, "k1": s.k1, "k2": s.k2, "zbar": s.zbar, "V": v, "regime": "steady",
                                 "sigma_max": sg, "sigma_min": sg, "sigma_mean": sg, "converged": bool(ok),
                                 "role": "diagram", "method": "renewal", "Vc": vc, "status": "ok", "error": ""})
        frame = pd.concat([frame, pd.DataFrame(rows)], ignore_index=True)
        self.tables["micro_points"] = frame
        return frame

    # -- D_c two ways ----------------------------------------------------------------------------
    @cached_property
    def dc_fit(self) -> fits.DcFit | None:
        """D_c (a), fitted to micro's stick-slip extrema (None when D_c is given)."""
        if self.Dc_given is not None:
            return None
        pts = self.micro_points
        self._per_k0_fits  # started: the per-k0 fits run on the pool's workers meanwhile
        fit = fits.fit_dc(pts, self.law_for, bounds=self.s.dc_bounds, n_grid=self.s.dc_grid,
                          n_bootstrap=self.s.bootstrap)
        self.tables["dc_fit"] = fit.to_frame()
        self.tables["dc_profile"] = fit.profile
        self.tables["dc_points"] = fit.points
        self.tables["dc_rms_per_k0"] = fit.rms_per_k0
        self.values.update(Dc=fit.Dc, Dc_err=fit.Dc_err, Dc_rms=fit.rms, Dc_profile=fit.Dc_profile,
                           regime_agreement=fit.regime_agreement, Dc_one_sided=fit.one_sided,
                           Dc_switch=fit.switch, Dc_n_stick_slip=fit.n_stick_slip, Dc_n_disagree=fit.n_disagree,
                           Dc_profile_factor=fit.profile_factor)
        return fit

    @cached_property
    def dc_per_k0(self) -> pd.DataFrame:
        """D_c (a) fitted at each k0 of ``fp_k0`` alone (its stick-slip and steady points),
        beside D_c (b) at that k0 (the fitted law's slope at micro's exact V^c): how far one
        D_c is from carrying every k0.  Columns ``k0, n_points`` (steady and stick-slip),
        ``n_cycles`` (micro's stick-slip points), ``n_stick_slip`` (those in the misfit at the
        optimum: RS in stick-slip too), ``Dc_a, Dc_a_lo, Dc_a_hi`` (the profile interval:
        the misfit within ``profile_factor`` of its minimum), ``profile_factor``, ``rms_a``,
        ``one_sided``, ``n_disagree`` (points whose regimes differ at the optimum), ``Dc_b``,
        ``ratio_a_b``, and the small-k0 closed form of D_c (a) (:func:`compare.fits.dc_small_k0`)
        and its ratio to D_c (b), ``Dc_a_small_k0, ratio_small_k0``.  Each k0's misfit
        profile is the table ``dc_profile_per_k0``."""
        per_b = self.dc_critical.per_k0.set_index("k0").Dc_law
        rows, profiles = [], []
        for k0, grp, future in self._per_k0_fits:
            try:
                try:
                    fit = future.result()
                except ValueError:
                    raise
                except Exception as exc:  # noqa: BLE001 - the worker's failure, not the fit's: fit here
                    log.warning("D_c (a) at k0 = %g alone failed on a worker (%s); fitting it here", k0, exc)
                    fit = self._fit_alone(grp, self.law_for)
            except ValueError as exc:  # (fewer than 3 usable points at this k0)
                log.warning("D_c (a) at k0 = %g alone: %s", k0, exc)
                continue
            Dc_b = float(per_b.get(k0, math.nan))
            Dc_lim = fits.dc_small_k0(grp, self.law_for(k0))
            rows.append({"k0": float(k0), "n_points": fit.n_points,
                         "n_cycles": int((fit.points.regime_micro == "stick-slip").sum()),
                         "n_stick_slip": fit.n_stick_slip, "Dc_a": fit.Dc, "Dc_a_lo": fit.Dc_profile[0],
                         "Dc_a_hi": fit.Dc_profile[1], "profile_factor": fit.profile_factor, "rms_a": fit.rms,
                         "one_sided": fit.one_sided, "n_disagree": fit.n_disagree,
                         "Dc_b": Dc_b, "ratio_a_b": fit.Dc / Dc_b if Dc_b > 0 else math.nan,
                         "Dc_a_small_k0": Dc_lim, "ratio_small_k0": Dc_lim / Dc_b if Dc_b > 0 else math.nan})
            profiles.append(fit.profile.assign(k0=float(k0)))
        frame = pd.DataFrame(rows).sort_values("k0", ascending=False, ignore_index=True) if rows else pd.DataFrame()
        self.tables["dc_per_k0"] = frame
        if profiles:
            prof = pd.concat(profiles, ignore_index=True)
            self.tables["dc_profile_per_k0"] = prof[["k0"] + [c for c in prof.columns if c != "k0"]]
        return frame

    @cached_property
    def _per_k0_fits(self) -> list[tuple[float, pd.DataFrame, Any]]:
        """The fits of :attr:`dc_per_k0`: (k0, its points, a future of its fit) per k0,
        started on the pool's workers (:meth:`Runner.submit`) while this process fits D_c (a)
        to every k0 (with the laws as a dict: this context does not travel)."""
        pts = self.micro_points
        laws = {float(k0): self.law_for(float(k0)) for k0 in pts.k0.unique()}
        return [(float(k0), grp, self.runner.submit(self._fit_alone, grp, laws.__getitem__))
                for k0, grp in pts.groupby("k0", sort=False)]

    @property
    def _fit_alone(self) -> partial:
        """The D_c (a) fit of one k0's points (``fit(points, law_for)``): no bootstrap."""
        return partial(fits.fit_dc, bounds=self.s.dc_bounds, n_grid=self.s.dc_grid, n_bootstrap=0)

    @cached_property
    def dc_critical(self) -> fits.DcCriticalFit:
        """D_c (b), from micro's exact V^c at every k0 of :attr:`critical`."""
        crit = self.critical
        crit = crit[crit.Vc_micro > 0]
        fit = fits.fit_dc_critical(crit.k0.to_numpy(float), crit.Vc_micro.to_numpy(float), self.law_for,
                                   slopes=self.exact_slopes(), bounds=self.s.dc_bounds)
        self.tables["dc_critical"] = fit.per_k0
        self.values.update(Dc_vc=fit.Dc, Dc_vc_err=fit.Dc_err, Dc_vc_range=fit.Dc_range,
                           Dc_vc_rms_log=fit.rms_log)
        return fit

    def exact_slopes(self) -> dict[float, float]:
        """W(V^c) = -V dsigma/dV of micro's exact branch at its V^c, by central difference
        over V^c (1 -+ 1e-3) (second order: a relative error ~ 1e-6)."""
        b = self.branch
        out = {}
        for k0, grp in b[b.role == "branch"].groupby("k0"):
            vc = float(grp.Vc.iloc[0])
            if not vc > 0:
                continue
            lo, hi = vc * (1 - 1e-3), vc * (1 + 1e-3)
            a = grp[np.isclose(grp.V, lo, rtol=1e-12)]
            c = grp[np.isclose(grp.V, hi, rtol=1e-12)]
            if len(a) and len(c):
                out[float(k0)] = -vc * float(c.sigma.iloc[0] - a.sigma.iloc[0]) / (hi - lo)
        return out

    @property
    def Dc(self) -> float:
        """The D_c of the RS side: the one given, else D_c (a)."""
        if self.Dc_given is not None:
            return float(self.Dc_given)
        return self.dc_fit.Dc

    def rs_vc(self, k0: float, Dc: float | None = None) -> float:
        """RS's V^c at ``k0`` with the fitted law and ``Dc`` (default :attr:`Dc`); NaN if none."""
        cv = rsf.critical_velocity(self.law_for(k0), k0, self.Dc if Dc is None else Dc)
        return float(cv.Vc) if math.isfinite(cv.Vc) else math.nan

    # -- what the shared stages show -----------------------------------------------------------
    def figure(self, name: str, out) -> Path | None:
        """The shared stage's figure ``name`` (one of :data:`SHARED_FIGURES`) in the folder
        ``out``, drawn once; None if its stage was not computed."""
        if name not in self._figures:
            t, v, dest = self.tables, self.values, figures.target(out, f"{name}.png")
            if name == "steady_fit" and "steady_fit_checks" in t:
                self._figures[name] = figures.steady_fit(t, v, dest)
            elif name == "dc_profile" and "dc_profile" in t:
                self._figures[name] = figures.dc_profile(t, v, dest)
            else:
                return None
        return self._figures[name]

    def summary(self, dc: bool = True) -> list[str]:
        """The shared stages' paragraphs: the Eq. (10) fit and (with ``dc``) the D_c given."""
        lines = self._steady_summary()
        if dc and self.Dc_given is not None:
            lines += ["## D_c", "", f"D_c = {self.Dc_given:g} given (not fitted).", ""]
        return lines

    def _steady_summary(self) -> list[str]:
        t, v, s = self.tables, self.values, self.s
        if "steady_fit" not in t:
            return []
        chk = t["steady_fit_checks"]
        lines = ["## Eq. (10) fitted to micro's exact steady branch", "",
                 f"mu_ss = mu_inf(k0) + A/(V + B) fitted to {len(t['steady_fit_residuals'])} exact steady points "
                 f"(micro's direct method, to {STEADY_TOL:g}; V from just above V^c to {fmt(s.branch_span, 3)} V^c "
                 f"at each "
                 f"k0, and the reference branch at k0 = {s.reference_k0:g}, steady at every V):", "",
                 f"A = {fmt(v['A'])} ± {fmt(v['A_err'], 2)}, B = {fmt(v['B'])} ± {fmt(v['B_err'], 2)} "
                 f"(paper: A = {rsf.PAPER_A}, B = {rsf.PAPER_B}); rms residual {fmt(v['steady_rms'], 3)}, "
                 f"largest {fmt(v['steady_max_residual'], 3)}.", "",
                 "| k0 | mu_inf | exact sigma(V→∞) | offset error | A / exact tail C | largest residual (at V) | "
                 "residual / (sigma − sigma_∞) at the largest V |", "|---|---|---|---|---|---|---|"]
        for _, r in chk.iterrows():
            lines.append(f"| {r.k0:g} | {fmt(r.mu_inf, 6)} | {fmt(r.sigma_inf_exact, 6)} | {fmt(r.offset_error, 3)} | "
                         f"{fmt(r.tail_ratio, 3)} | {fmt(r.max_abs_residual, 2)} (V = {fmt(r.V_at_max, 3)}) | "
                         f"{pct(r.tail_residual)} (V = {fmt(r.V_max, 3)}) |")
        worst = chk.iloc[int(np.argmax(chk.max_abs_residual.to_numpy()))]
        lines += ["", f"Where the form fails: exact micro decays as sigma_∞ + C/V with C = k2 γ Var(R) = "
                      f"{fmt(chk.tail_exact.iloc[0], 4)} (micro.sigma_fast_limit), Eq. (10) as mu_inf + A/V, so its "
                      f"tail is off by the factor A/C = {fmt(chk.tail_ratio.iloc[0], 3)} and its offset by "
                      f"{fmt(chk.offset_error.abs().min(), 2)} to {fmt(chk.offset_error.abs().max(), 2)} "
                      f"(mu_inf − sigma_∞). The largest residual, {fmt(worst.max_abs_residual, 2)}, is at k0 = "
                      f"{worst.k0:g}, V = {fmt(worst.V_at_max, 3)}. Residuals: `steady_fit_residuals.csv`, figure "
                      f"`steady_fit.png`.", ""]
        return lines
