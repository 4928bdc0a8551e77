r"""The whole comparison: micro and RS side by side, as tables, figures and ``summary.md``.

:func:`report` runs the scenarios of a :class:`~compare.params.Settings` (``bifurcation``,
``hopf``, ``phase``, ``shs``) and returns a :class:`Report` whose tables are pandas
DataFrames; with ``out`` it also writes them as CSV, the figures as PNG and a summary.

Micro answers by its defaults: the stationary questions directly
(:func:`micro.critical_velocity` and :func:`micro.steady_sliding`: the renewal chain of
one block, milliseconds per V); the stick-slip points of the diagram and of the
transition study are limit cycles solved as fixed points of the cycle map
(:mod:`micro.cohort`, seconds per point at every k0, each with its discretisation error
where it is known), checked in the transition study by the N-block simulation at two
sizes; slide-hold-slide and the paper's traces time-step the Fokker-Planck equation (the
only method that carries a transient), and the paper's Fig. 10 is the FP against its bin.  Stages
are computed when a scenario needs them and shared between scenarios:

* micro's exact V^c at every k0 (and at dozens of k0 per (k1, k2) set for the phase
  diagram), then its exact steady branch on both sides of V^c (the growth rate of the
  unstable mode below it);
* the Eq. (10) fit to that branch (shared A, B, one offset per k0) with its residual
  against the exact tail and offset;
* the stick-slip points (micro's default, the cohort method; the N-block), every one in
  one batch on the runner;
* D_c two ways: from the stick-slip extrema (:func:`~compare.fits.fit_dc`) and from V^c
  matching (:func:`~compare.fits.fit_dc_critical`).

Every micro evaluation goes through a :class:`~compare.runner.Runner` (disk cache,
process pool or dask); the RS side is fast and recomputed each time.
"""
from __future__ import annotations

import logging
import math
import time
from dataclasses import dataclass, field
from functools import cached_property
from pathlib import Path
from typing import Any, Sequence

import numpy as np
import pandas as pd

import micro
import rsf

from . import fits
from ._validation import positive
from .cache import NullCache, PointCache
from .output import ReportFolder, check_folder
from .params import PAPER_K0, Settings
from .rs_side import classical_rs, rs_curves, rs_hopf, rs_slide_hold_slide
from .runner import Runner
from .tasks import NBlockTask, SlideHoldSlideTask, StationaryTask, SteadyTask, TraceTask, VcTask

__all__ = ["Report", "report", "micro_frame"]

log = logging.getLogger(__name__)


def micro_frame(records: Sequence[dict[str, Any]], **columns: Any) -> pd.DataFrame:
    """Stationary records of a :class:`Runner` as one row each (failed tasks keep their
    ``error`` with NaN results)."""
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


@dataclass
class Report:
    """What :func:`report` computed: tables (DataFrames, also written as CSV), figure paths,
    the summary text, the run time and the runner's statistics."""

    settings: Settings
    tables: dict[str, pd.DataFrame] = field(default_factory=dict)
    figures: dict[str, Path] = field(default_factory=dict)
    values: dict[str, Any] = field(default_factory=dict)
    summary: str = ""
    out: Path | None = None
    wall_time: float = 0.0
    stats: Any = None

    def __getitem__(self, name: str) -> pd.DataFrame:
        if name not in self.tables:
            raise KeyError(f"no table {name!r}; tables: {sorted(self.tables)}")
        return self.tables[name]


def _sig(x: float) -> float:
    """A velocity rounded to 6 significant digits (readable, and the same task twice)."""
    return float(f"{x:.6g}")


class _Study:
    """The shared stages of a report (each computed at most once)."""

    def __init__(self, settings: Settings, runner: Runner, Dc: float | None) -> None:
        self.s = settings
        self.runner = runner
        self.Dc_given = Dc
        self.tables: dict[str, pd.DataFrame] = {}
        self.values: dict[str, Any] = {}
        self._records: dict[str, dict[str, Any]] = {}

    # -- running micro tasks -----------------------------------------------------------------
    def _run(self, tasks: Sequence, desc: str) -> list[dict[str, Any]]:
        """Records of ``tasks``: the ones fetched already, the rest from the runner."""
        todo = [t for t in tasks if t.key not in self._records]
        if todo:
            for rec in self.runner.run(todo, desc=desc):
                self._records[rec["key"]] = rec
        return [self._records[t.key] for t in tasks]

    def prefetch(self, scenarios: Sequence[str]) -> None:
        """Run every micro task the scenarios need in two batches, so that the pool stays
        busy: first the exact V^c at the k0 whose other tasks sit at multiples of it, then
        everything else at once, the slowest tasks first."""
        s = self.s
        self._run([VcTask(s.model(k0)) for k0 in self._vc_k0(scenarios)], "micro Vc (direct)")
        tasks: list = []
        if "bifurcation" in scenarios:
            tasks += [VcTask(s.model(k0)) for k0 in self._phase_k0(s.k2)]
        if "phase" in scenarios:
            tasks += [VcTask(s.model(k0, k1, k2)) for k1, k2 in s.phase_sets for k0 in self._phase_k0(k2)]
        tasks += self._branch_tasks()
        if "bifurcation" in scenarios:
            tasks += self._diagram_tasks(fitted=self.Dc_given is None) + self._paper_tasks()
        if "hopf" in scenarios:
            tasks += self._hopf_tasks()
        if "phase" in scenarios:
            tasks += self._phase_reference_tasks()
        if "shs" in scenarios:
            tasks += self._shs_tasks()
        # the slowest first: a long FP point started last would leave the other worker idle
        order = {"stationary": 0, "slide_hold_slide": 0, "trace": 1, "nblock": 2, "steady": 3, "vc": 4}
        self._run(sorted(tasks, key=lambda t: order.get(t.kind, 0)), "micro")

    def _vc_k0(self, scenarios: Sequence[str]) -> list[float]:
        s = self.s
        k0 = list(s.k0) + list(PAPER_K0) + [s.reference_k0]
        if "hopf" in scenarios:
            k0.append(s.hopf_k0)
        if "shs" in scenarios:
            k0.append(s.shs_k0)
        if "bifurcation" in scenarios:
            k0 += list(s.fp_k0) + [k for k, _ in s.shown_points]
        return sorted(set(k0), reverse=True)

    # -- micro, direct: V^c and the steady branch ------------------------------------------------
    def Vc(self, k0: float, k1: float | None = None, k2: float | None = None) -> float:
        """Micro's exact V^c (0 when k0 >= k2: no stick-slip)."""
        rec = self._run([VcTask(self.s.model(k0, k1, k2))], "micro Vc (direct)")[0]
        if rec.get("status") != "ok":
            raise RuntimeError(f"micro V^c at k0 = {k0:g} failed: {rec.get('error')}")
        return float(rec["result"]["Vc"])

    def _branch_V(self, k0: float, k1: float | None = None, k2: float | None = None,
                  reference: tuple[float, ...] | None = None) -> tuple[float, ...]:
        s = self.s
        if reference is not None:
            return tuple(_sig(v) for v in reference)
        vc = self.Vc(k0, k1, k2)
        if vc == 0.0:
            return tuple(_sig(v) for v in np.geomspace(1e-3, 1e3, s.branch_points))
        hi = max(min(s.branch_span * vc, s.branch_V_max), 10 * vc)
        stable = vc * np.geomspace(1.0 + 1e-3, hi / vc, s.branch_points)
        below = vc * np.geomspace(s.unstable_from, 0.995, s.unstable_points)
        slope = vc * np.array([1.0 - 1e-3, 1.0 + 1e-3])          # -V dsigma/dV at V^c
        return tuple(sorted({_sig(v) for v in np.concatenate([below, stable])} | {float(v) for v in slope}))

    def _branch_tasks(self) -> list[SteadyTask]:
        s = self.s
        tasks = [SteadyTask(s.model(k0), self._branch_V(k0)) for k0 in s.k0]
        tasks.append(SteadyTask(s.model(s.reference_k0), self._branch_V(s.reference_k0, reference=s.reference_V)))
        return tasks

    @cached_property
    def branch(self) -> pd.DataFrame:
        """Micro's exact steady branch (stable above V^c, unstable below) per k0, and the
        reference branch at ``reference_k0`` (steady at every V)."""
        s = self.s
        tasks = self._branch_tasks()
        frames = []
        for task, rec in zip(tasks, self._run(tasks, "micro steady branch")):
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
        """Micro's exact V^c at every k0 with its error and small-k0 asymptote (RS columns
        are added once D_c is known)."""
        s = self.s
        rows = []
        for k0 in sorted(set(s.k0) | set(PAPER_K0), reverse=True):
            rec = self._run([VcTask(s.model(k0))], "micro Vc (direct)")[0]
            r = rec.get("result") or {}
            vc = float(r.get("Vc", math.nan))
            rows.append({"k0": k0, "Vc_micro": vc, "Vc_micro_err": 0.5 * (r.get("V_high", math.nan) - r.get("V_low", math.nan)),
                         "Vc_micro_small_k0": micro.vc_small_k0(s.model(k0)),
                         "micro_status": r.get("status", rec.get("error", "failed"))})
        return pd.DataFrame(rows)

    # -- Eq. (10) on the exact branch -----------------------------------------------------------
    @cached_property
    def steady_fit(self) -> fits.SteadyLawFit:
        b = self.branch
        pts = b[b.stable.astype(bool) & np.isfinite(b.sigma) & (b.V > 0)]
        pts = pts[(pts.role == "reference") | (pts.V >= pts.Vc * (1.0 + 5e-3))]   # not the slope pair
        frame = pts.assign(regime="steady", sigma_mean=pts.sigma)
        fit = fits.fit_steady_law(frame)
        self.tables["steady_fit"] = fit.to_frame()
        self.tables["steady_fit_residuals"] = fit.residuals
        models = {float(k0): self.s.model(k0) for k0 in fit.offsets.k0}
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
        shift = micro.sigma_fast_limit(self.s.model(k0)) - micro.sigma_fast_limit(self.s.model(near))
        return fit.law(mu_inf=fit.mu_inf(near) + shift)

    # -- micro, time-stepped: the stick-slip points --------------------------------------------
    def _stationary_task(self, k0: float, V: float, eps: float, method: str = "auto") -> StationaryTask:
        s = self.s
        return StationaryTask(s.model(k0), _sig(V), s.numerics(eps), s.convergence(), method)

    def _cycle_task(self, k0: float, V: float) -> StationaryTask:
        """Micro's stick-slip cycle at V by ``cycle_method``: ``"auto"``, micro's default
        (the cohort method at its default step and cell, its fixed point to ``cycle_rtol``
        of the velocity weakening), or the FP at ``eps``."""
        s = self.s
        if s.cycle_method == "fp":
            return self._stationary_task(k0, V, s.eps, "fp")
        model = s.model(k0)
        tol = s.cycle_rtol * (model.f_th - micro.sigma_fast_limit(model))
        return StationaryTask(model, V, s.numerics(), s.convergence(), "auto",
                              cohort=micro.Cohort(tol=min(max(tol, 1e-9), 1e-2)))

    def _diagram_tasks(self, fitted: bool = True) -> list[StationaryTask]:
        """The stick-slip points: those the D_c fit matches (with ``fitted``), and those
        only shown."""
        s = self.s
        return self._cycle_tasks((list(s.fp_points) if fitted else []) + list(s.shown_points))

    def _cycle_tasks(self, pairs) -> list[StationaryTask]:
        return [self._cycle_task(k0, _sig(r * self.Vc(k0))) for k0, r in pairs if self.Vc(k0) > 0]

    def _points(self, pairs, role: str) -> pd.DataFrame:
        """The stick-slip cycles at ``pairs`` (k0, V / V^c), with their k0's V^c."""
        frame = micro_frame(self._run(self._cycle_tasks(pairs), "micro stick-slip"), role=role)
        frame["Vc"] = [self.Vc(k) for k in frame.k0]
        return frame

    @cached_property
    def shown_points(self) -> pd.DataFrame:
        """Micro's stick-slip points that the diagram shows but the D_c fit does not match."""
        frame = self._points(self.s.shown_points, "shown")
        self.tables["micro_shown_points"] = frame
        return frame

    @cached_property
    def micro_points(self) -> pd.DataFrame:
        """Micro's stick-slip points (by ``cycle_method``) and exact steady points that the
        D_c fit matches."""
        s = self.s
        frame = self._points(s.fp_points, "diagram")
        rows = []
        for k0 in s.fp_k0:
            vc = self.Vc(k0)
            V = [_sig(r * vc) for r in s.steady_ratios] if vc > 0 else []
            if V:
                st = micro.steady_sliding(s.model(k0), V, growth_rate=False, warn=False)
                for v, sig, ok in zip(V, st.sigma, st.converged):
                    rows.append({"k0": k0, "k1": s.k1, "k2": s.k2, "zbar": s.zbar, "V": v, "regime": "steady",
                                 "sigma_max": sig, "sigma_min": sig, "sigma_mean": sig, "converged": bool(ok),
                                 "role": "diagram", "method": "renewal", "Vc": vc, "status": "ok", "error": ""})
        frame = pd.concat([frame, pd.DataFrame(rows)], ignore_index=True)
        self.tables["micro_points"] = frame
        return frame

    # -- D_c two ways ----------------------------------------------------------------------------
    @cached_property
    def dc_fit(self) -> fits.DcFit | None:
        if self.Dc_given is not None:
            return None
        pts = self.micro_points
        fit = fits.fit_dc(pts, self.law_for, bounds=self.s.dc_bounds, n_grid=self.s.dc_grid,
                          n_bootstrap=self.s.bootstrap)
        self.tables["dc_fit"] = fit.to_frame()
        self.tables["dc_profile"] = fit.profile
        self.tables["dc_points"] = fit.points
        self.tables["dc_rms_per_k0"] = fit.rms_per_k0
        self.values.update(Dc=fit.Dc, Dc_err=fit.Dc_err, Dc_rms=fit.rms, Dc_profile=fit.Dc_profile,
                           regime_agreement=fit.regime_agreement, Dc_one_sided=fit.one_sided,
                           Dc_switch=fit.switch)
        return fit

    @cached_property
    def dc_critical(self) -> fits.DcCriticalFit:
        crit = self.critical
        crit = crit[crit.Vc_micro > 0]
        fit = fits.fit_dc_critical(crit.k0.to_numpy(float), crit.Vc_micro.to_numpy(float), self.law_for,
                                   slopes=self._exact_slopes(), bounds=self.s.dc_bounds)
        self.tables["dc_critical"] = fit.per_k0
        self.values.update(Dc_vc=fit.Dc, Dc_vc_err=fit.Dc_err, Dc_vc_range=fit.Dc_range,
                           Dc_vc_rms_log=fit.rms_log)
        return fit

    def _exact_slopes(self) -> dict[float, float]:
        """W(V^c) = -V dsigma/dV of micro's exact branch at its V^c, by central difference
        over V^c (1 -+ 1e-3) (second order: a relative error ~ 1e-6)."""
        b = self.branch
        out = {}
        for k0, grp in b[b.role == "branch"].groupby("k0"):
            vc = float(grp.Vc.iloc[0])
            if vc <= 0:
                continue
            lo, hi = vc * (1 - 1e-3), vc * (1 + 1e-3)
            a = grp[np.isclose(grp.V, lo, rtol=1e-12)]
            c = grp[np.isclose(grp.V, hi, rtol=1e-12)]
            if len(a) and len(c):
                out[float(k0)] = -vc * float(c.sigma.iloc[0] - a.sigma.iloc[0]) / (hi - lo)
        return out

    @property
    def Dc(self) -> float:
        if self.Dc_given is not None:
            return float(self.Dc_given)
        return self.dc_fit.Dc

    def _rs_vc(self, k0: float, Dc: float | None = None) -> float:
        cv = rsf.critical_velocity(self.law_for(k0), k0, self.Dc if Dc is None else Dc)
        return float(cv.Vc) if math.isfinite(cv.Vc) else math.nan

    def critical_table(self) -> pd.DataFrame:
        """Micro's exact V^c against RS's with each D_c, per k0 (``critical_velocity.csv``)."""
        frame = self.critical.copy()
        dcv = self.dc_critical
        frame["Vc_rs"] = [self._rs_vc(k) for k in frame.k0]
        frame["Vc_rs_dc_vc"] = [self._rs_vc(k, dcv.Dc) for k in frame.k0]
        frame["Vc_rs_paper"] = [self.s.rs_paper_vc(k) for k in frame.k0]
        frame["rel_diff_rs"] = frame.Vc_rs / frame.Vc_micro - 1.0
        frame["rel_diff_rs_dc_vc"] = frame.Vc_rs_dc_vc / frame.Vc_micro - 1.0
        per = dcv.per_k0.set_index("k0")
        frame["Dc_match"] = [float(per.Dc_law.get(k, math.nan)) for k in frame.k0]
        frame["Dc_match_exact_slope"] = [float(per.Dc_exact_slope.get(k, math.nan)) for k in frame.k0]
        frame["Dc"] = self.Dc
        frame["Dc_vc"] = dcv.Dc
        self.tables["critical_velocity"] = frame
        if self.Dc_given is None and "micro_points" in self.tables:
            # what D_c (b) implies for the extrema that D_c (a) was fitted to
            pts = self.tables["dc_points"]
            rs = fits.rs_diagram(pts, self.law_for, dcv.Dc)
            r = np.concatenate([rs.sigma_max.to_numpy() - pts.sigma_max_micro.to_numpy(),
                                rs.sigma_min.to_numpy() - pts.sigma_min_micro.to_numpy()])
            self.values["Dc_vc_extrema_rms"] = float(np.sqrt(np.mean(r * r)))
            self.values["Dc_vc_regime_agreement"] = float(np.mean(rs.regime.to_numpy() == pts.regime_micro.to_numpy()))
        return frame

    # -- scenarios -------------------------------------------------------------------------------
    def bifurcation(self) -> None:
        s = self.s
        self.steady_fit
        if self.Dc_given is None:
            self.dc_fit
        if s.shown_points:
            self.shown_points
        crit = self.critical_table()
        Dc = self.Dc

        def V_range(k0: float) -> tuple[float, float]:
            vc = self._rs_vc(k0)
            hi = 5.0 * vc if math.isfinite(vc) else 10.0
            return 1e-3, max(hi, 10.0, 3.0 * float(crit.Vc_micro[np.isclose(crit.k0, k0)].max()))

        curves = rs_curves(sorted(set(PAPER_K0) | set(s.k0), reverse=True), self.law_for, Dc, V_range=V_range,
                           n=s.rs_points, label="fitted Dc")
        self.tables["rs_bifurcation"] = curves
        lower = {k0: rsf.critical_velocity(self.law_for(k0), k0, Dc).V_lower for k0 in curves.k0.unique()}
        self.tables["rs_unstable_band"] = pd.DataFrame(
            [{"k0": k, "V_lower": v, "Vc": self._rs_vc(k)} for k, v in lower.items()])
        # the RS V^c curve of each D_c and micro's, over k0 (the set of Figs. 4/8)
        k0s = self._phase_k0(s.k2)
        rows = []
        for k0 in k0s:
            law = self.law_for(k0)
            row = {"k0": k0, "Vc_micro": self.Vc(k0),
                   "Vc_rs": rsf.critical_velocity(law, k0, Dc).Vc,
                   "Vc_rs_dc_vc": rsf.critical_velocity(law, k0, self.dc_critical.Dc).Vc,
                   "Vc_rs_paper": self.s.rs_paper_vc(k0)}
            rows.append(row)
        self.tables["vc_curves"] = pd.DataFrame(rows)
        if s.paper_figures:
            self._paper_figures()

    def _hopf_cycle_tasks(self) -> list[StationaryTask]:
        """The transition's cycles by micro's default (``cycle_method``), one per distance."""
        s = self.s
        vc = self.Vc(s.hopf_k0)
        if vc <= 0:
            return []
        return [self._cycle_task(s.hopf_k0, _sig(vc * (1 - d))) for d in s.hopf_distances]

    def _hopf_nblock_tasks(self) -> list[NBlockTask]:
        s = self.s
        vc = self.Vc(s.hopf_k0)
        if vc <= 0:
            return []
        return [NBlockTask(s.model(s.hopf_k0), _sig(vc * (1 - d)), int(N)) for N in s.nblock_N
                for d in s.nblock_distances]

    def _hopf_tasks(self) -> list:
        return self._hopf_cycle_tasks() + self._hopf_nblock_tasks()

    def hopf(self) -> None:
        """The transition at ``hopf_k0``: micro's spectrum and its stick-slip amplitude
        against (V^c - V)/V^c (micro's default method, the cohort's cycles with their
        error where it is known; the N-block at two sizes) next to RS's Hopf scaling, each
        against its own V^c."""
        s = self.s
        k0 = s.hopf_k0
        vc = self.Vc(k0)
        rows = []
        cyc, nb = self._hopf_cycle_tasks(), self._hopf_nblock_tasks()
        f = micro_frame(self._run(cyc, "micro amplitude"))
        if len(f):
            f["resolution"] = f["eps"]
            # an error bar on each extremum: the discretisation's (NaN where not known) and the fixed point's
            if "discretisation_error" in f:
                f["amplitude_stderr"] = 2.0 * (f.discretisation_error + f.sigma_stderr)
            rows.append(f)
        for N in s.nblock_N:
            tasks = [t for t in nb if t.n_blocks == N]
            recs = self._run(tasks, "micro amplitude (N-block)")
            f = pd.DataFrame([{**(r.get("result") or {"V": t.V, "regime": "failed"}), "error": r.get("error", "")}
                              for t, r in zip(tasks, recs)])
            f["method"], f["resolution"] = "N-block", float(N)
            rows.append(f)
        rows = [f for f in rows if len(f)]
        micro_pts = pd.concat(rows, ignore_index=True) if rows else pd.DataFrame()
        if len(micro_pts):
            micro_pts["model"], micro_pts["k0"], micro_pts["Vc"] = "micro", k0, vc
            micro_pts["d"] = 1.0 - micro_pts.V / vc
            micro_pts["amplitude"] = micro_pts.sigma_max - micro_pts.sigma_min
            if "sigma_max_stderr" in micro_pts:
                nb_rows = micro_pts.method == "N-block"
                micro_pts.loc[nb_rows, "amplitude_stderr"] = np.hypot(micro_pts.sigma_max_stderr,
                                                                      micro_pts.sigma_min_stderr)[nb_rows]
        model = rsf.SpringSlider(law=self.law_for(k0), k0=k0, Dc=self.Dc)
        rs = rs_hopf(model, s.rs_hopf_distances)
        rs["model"], rs["k0"], rs["method"], rs["resolution"] = "RS", k0, "CVODE", math.nan
        cols = ["model", "method", "resolution", "k0", "V", "Vc", "d", "regime", "sigma_max", "sigma_min",
                "amplitude", "amplitude_stderr", "period"]
        points = pd.concat([micro_pts, rs], ignore_index=True).reindex(columns=cols)
        self.tables["hopf_points"] = points
        fit_rows = []
        for (name, method, res), grp in points.groupby(["model", "method", "resolution"], dropna=False):
            grp = grp[(grp.regime == "stick-slip") & (grp.amplitude > 0)]
            try:
                f = fits.fit_power_law(grp.V, grp.amplitude, Vc=float(grp.Vc.iloc[0]))
            except (ValueError, IndexError) as exc:
                log.warning("amplitude law %s %s %s: %s", name, method, res, exc)
                continue
            fit_rows.append({"model": name, "method": method, "resolution": res,
                             "Vc_mode": "exact (direct)" if name == "micro" else "exact (linear stability)",
                             **f.to_dict()})
        self.tables["hopf_fit"] = pd.DataFrame(fit_rows)
        b = self.branch
        spec = b[(b.role == "branch") & np.isclose(b.k0, k0) & (b.V < vc)].sort_values("V")
        self.tables["micro_spectrum"] = spec[["k0", "V", "Vc", "branching_ratio", "stable", "growth_rate"]].assign(
            d=1.0 - spec.V / vc)
        self.values["transition"] = fits.classify_transition(self.tables["micro_spectrum"], self.tables["hopf_fit"],
                                                             points)

    def _phase_k0(self, k2: float) -> list[float]:
        s = self.s
        return [_sig(k) for k in np.geomspace(s.phase_k0_min, 0.98 * k2, s.phase_points)]

    def _phase_reference_tasks(self) -> list[SteadyTask]:
        s = self.s
        return [SteadyTask(s.model(max(s.reference_k0, 1.2 * k2), k1, k2), tuple(_sig(v) for v in s.phase_reference_V))
                for k1, k2 in s.phase_sets]

    def phase(self) -> None:
        s = self.s
        Dc, Dc_vc = self.Dc, self.dc_critical.Dc
        tasks = self._phase_reference_tasks()
        recs = self._run(tasks, "micro phase reference")
        laws, law_rows, refs = {}, [], []
        for (k1, k2), rec in zip(s.phase_sets, recs):
            f = pd.DataFrame(rec["result"]["rows"])
            refs.append(f)
            try:
                fit = fits.fit_steady_law(f.assign(regime="steady", sigma_mean=f.sigma))
            except ValueError as exc:
                log.warning("phase set (k1=%g, k2=%g): no Eq. (10) fit: %s", k1, k2, exc)
                continue
            laws[(k1, k2)] = fit
            law_rows.append({"k1": k1, "k2": k2, "A": fit.A, "A_err": fit.A_err, "B": fit.B, "B_err": fit.B_err,
                             "mu_inf": float(fit.offsets.mu_inf.iloc[0]), "rms": fit.rms,
                             "k0_max_rs": fit.A / (4 * fit.B * Dc), "k0_max_rs_dc_vc": fit.A / (4 * fit.B * Dc_vc)})
        self.tables["phase_reference"] = pd.concat(refs, ignore_index=True)
        self.tables["phase_laws"] = pd.DataFrame(law_rows)
        rows = []
        for k1, k2 in s.phase_sets:
            for k0 in self._phase_k0(k2):
                rec = self._run([VcTask(s.model(k0, k1, k2))], "micro phase Vc")[0]
                r = rec.get("result") or {}
                rows.append({"k1": k1, "k2": k2, "k0": k0, "Vc": r.get("Vc", math.nan),
                             "Vc_err": 0.5 * (r.get("V_high", math.nan) - r.get("V_low", math.nan)),
                             "asymptote": micro.vc_small_k0(s.model(k0, k1, k2)), "status": r.get("status", "failed")})
        self.tables["phase_micro"] = pd.DataFrame(rows)
        rows = []
        for (k1, k2), f in laws.items():
            for k0 in np.geomspace(s.phase_k0_min, 1.0, 81):
                law = f.law(mu_inf=0.0)
                rows.append({"k1": k1, "k2": k2, "k0": float(k0),
                             "Vc": rsf.critical_velocity(law, float(k0), Dc).Vc,
                             "Vc_dc_vc": rsf.critical_velocity(law, float(k0), Dc_vc).Vc,
                             "asymptote": f.A / (k0 * Dc), "k0_max_rs": f.A / (4 * f.B * Dc)})
        self.tables["phase_rs"] = pd.DataFrame(rows)

    def _shs_tasks(self) -> list:
        s = self.s
        tasks: list = [SlideHoldSlideTask(s.model(s.shs_k0), s.shs_V, s.hold_times, s.numerics(), s.convergence())]
        tasks.append(self._shs_trace_task())
        return tasks

    def _shs_trace_task(self) -> TraceTask:
        """Fig. 7 (left): sigma(t) around the reload after the longest hold."""
        s = self.s
        model = s.model(s.shs_k0)
        slide = 30.0 * model.kappa * model.zbar / (s.shs_k0 * s.shs_V)   # 30 loading times: steady
        hold = max(s.hold_times)
        reload = 10.0 * model.kappa * model.zbar / (s.shs_k0 * s.shs_V)
        return TraceTask(model, ((slide, s.shs_V), (hold, 0.0), (reload, s.shs_V)), s.numerics())

    def shs(self) -> None:
        s = self.s
        k0, V = s.shs_k0, s.shs_V
        rec, trace = self._run(self._shs_tasks(), "micro slide-hold-slide")
        frames = []
        if rec.get("status") == "ok":
            m = pd.DataFrame(rec["result"]["rows"])
            m["model"] = "micro"
            frames.append(m[["model", "hold_time", "sigma_steady", "sigma_peak", "delta_sigma_max"]])
        else:
            log.warning("micro slide-hold-slide failed: %s", rec.get("error"))
        if trace.get("status") == "ok":
            segs = trace["task"]["segments"]
            t0 = segs[0][0] + segs[1][0]
            self.tables["shs_trace"] = pd.DataFrame({"t": np.asarray(trace["result"]["t"]) - t0,
                                                     "sigma": trace["result"]["sigma"]}).assign(
                k0=k0, V=V, hold_time=segs[1][0])
        law = self.law_for(k0)
        rs11 = rs_slide_hold_slide(rsf.SpringSlider(law=law, k0=k0, Dc=self.Dc), V, s.hold_times)
        rs11["model"] = "RS Eq. (11)"
        W = float(law.weakening(np.array([V]))[0])
        b = max(s.classical_b, 1.5 * W)
        rs7 = rs_slide_hold_slide(classical_rs(law, V, b, k0, self.Dc), V, s.hold_times)
        rs7["model"] = "classical RS Eq. (7)"
        for f in (rs11, rs7):
            frames.append(f[["model", "hold_time", "sigma_steady", "sigma_peak", "delta_sigma_max"]])
        points = pd.concat(frames, ignore_index=True)
        self.tables["shs_points"] = points
        rows = []
        for name, grp in points.groupby("model", sort=False):
            for law_name in fits.GROWTH_LAWS:
                g = fits.fit_growth_law(grp.hold_time, grp.delta_sigma_max, law_name)
                rows.append({"model": name, **g.to_dict()})
        table = pd.DataFrame(rows)
        table["best"] = table.groupby("model").rel_rms.transform(lambda r: r == r.min())
        self.tables["shs_fit"] = table
        self.values.update(shs_b=b, shs_A_over_B=law.A / law.B)

    # -- the paper's remaining micro figures (Figs. 3 and 10; opt-in) ---------------------------
    def _paper_tasks(self) -> list:
        return self._fig3_tasks() + self._fig10_tasks() if self.s.paper_figures else []

    def _fig3_tasks(self) -> list[TraceTask]:
        s = self.s
        model = s.model(0.01)
        out = []
        for V in (0.001, 5.0, 9.8):
            w = 2.5 * 0.1 / 0.01 if V < 1 else 30 * model.kappa * model.zbar / 0.01   # drive displacement
            out.append(TraceTask(model, ((w / V, V),), s.numerics()))
        return out

    def _fig10_tasks(self) -> list[StationaryTask]:
        s = self.s
        # method "fp": above V^c the default would return the direct steady state, not the FP's
        return [self._stationary_task(k0, 1.5 * self.Vc(k0), eps, "fp") for k0 in s.fig10_k0 for eps in s.fig10_eps
                if eps <= s.model(k0).kappa * s.zbar / 4]

    def _paper_figures(self) -> None:
        s = self.s
        traces = []
        for task, rec in zip(self._fig3_tasks(), self._run(self._fig3_tasks(), "micro Fig. 3")):
            if rec.get("status") == "ok":
                traces.append(pd.DataFrame(rec["result"]).assign(V=task.segments[0][1], k0=task.model.k0))
        if traces:
            self.tables["fig3_traces"] = pd.concat(traces, ignore_index=True)
        tasks = self._fig10_tasks()
        f = micro_frame(self._run(tasks, "micro Fig. 10"))
        exact = {k0: float(micro.steady_sliding(s.model(k0), [1.5 * self.Vc(k0)], growth_rate=False).sigma[0])
                 for k0 in s.fig10_k0}
        f["sigma_exact"] = [exact[k] for k in f.k0]
        f["error"] = f.sigma_mean - f.sigma_exact
        self.tables["fig10_eps"] = f


def report(settings: Settings | None = None, *, out: str | Path | None = None,
           scenarios: Sequence[str] | None = None, Dc: float | None = None, cache_dir: str | Path | None = None,
           use_cache: bool = True, workers: int | None = None, scheduler: Any = None,
           progress: bool = True) -> Report:
    """Run the comparison and (with ``out``) write the report folder.

    Parameters
    ----------
    settings : Settings, optional
        Default :meth:`Settings.default`.
    out : path, optional
        Folder for PNG figures, CSV tables and ``summary.md`` (created).
    scenarios : sequence of str, optional
        Subset of ``('bifurcation', 'hopf', 'phase', 'shs')``; default ``settings.scenarios``.
    Dc : float, optional
        Use this D_c instead of fitting it to the stick-slip extrema (D_c from V^c
        matching is still reported).
    cache_dir, use_cache : where micro records are cached (default: ``$COMPARE_CACHE_DIR`` or
        ``~/.cache/frictionkit-compare``), or no cache at all.
    workers, scheduler, progress : see :class:`~compare.runner.Runner`.
    """
    from .summary import summary

    start = time.perf_counter()
    settings = Settings.default() if settings is None else settings
    if not isinstance(settings, Settings):
        raise ValueError(f"settings must be a compare.Settings, got {type(settings).__name__}")
    if scenarios is not None:
        settings = settings.with_(scenarios=tuple(scenarios))
    if Dc is not None:
        Dc = positive("Dc", Dc)
    if out is not None:
        check_folder(out)  # before any computation
    cache = PointCache(cache_dir) if use_cache else NullCache()
    rep = Report(settings=settings)
    with Runner(cache, workers=workers, scheduler=scheduler, progress=progress) as runner:
        study = _Study(settings, runner, Dc)
        study.prefetch(settings.scenarios)
        for name in settings.scenarios:
            log.info("scenario %s", name)
            getattr(study, name)()
        rep.stats = runner.stats
    rep.tables, rep.values = study.tables, study.values
    rep.tables["settings"] = pd.DataFrame([{k: repr(v) if isinstance(v, tuple) else v
                                            for k, v in settings.to_dict().items()}])
    folder = None
    if out is not None:
        from . import figures
        folder = ReportFolder(Path(out))
        rep.out = folder.path
        for name, table in rep.tables.items():
            folder.write(f"{name}.csv", lambda p, t=table: t.to_csv(p, index=False))
        rep.figures = figures.draw(study, folder)
    rep.wall_time = time.perf_counter() - start
    rep.summary = summary(study, rep)
    if folder is not None:
        folder.write("summary.md", lambda p: p.write_text(rep.summary, encoding="utf-8"))
        folder.finish()
    return rep
