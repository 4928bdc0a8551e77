r"""The whole comparison: micro and RS side by side, as tables, figures and ``summary.md``.

:func:`report` runs the scenarios of a :class:`~compare.params.Settings` (``bifurcation``,
``hopf``, ``phase``, ``shs``) and returns a :class:`Report` whose tables are pandas
DataFrames; with ``out`` it also writes them as CSV, the figures as PNG and a summary.

Stages are computed only when a scenario needs them and shared between scenarios:

* micro points of the bifurcation diagram and of the reference steady branch
  (``reference_k0 >= k2``: steady at every V, so it pins the shape of Eq. 10);
* the Eq. (10) fit (shared A, B, one offset per k0) and the D_c fit (needed by every RS
  curve; skipped when ``Dc`` is given);
* micro critical velocities (bisection, :class:`~compare.tasks.CriticalTask`);
* the Hopf points, the phase-diagram sets, the slide-hold-slide run.

Every micro evaluation goes through a :class:`~compare.runner.Runner` (disk cache, process
pool or dask); the RS side is fast and recomputed each time.
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
from .params import PAPER_K0, Settings
from .rs_side import DEFAULT_OPTIONS, classical_rs, rs_curves, rs_hopf, rs_slide_hold_slide
from .runner import Runner
from .tasks import CriticalTask, SlideHoldSlideTask, StationaryTask

__all__ = ["Report", "report", "micro_frame"]

log = logging.getLogger(__name__)


def micro_frame(records: Sequence[dict[str, Any]], **columns: Any) -> pd.DataFrame:
    """Stationary/critical records of a :class:`Runner` as one row each (failed tasks keep
    their ``error`` with NaN results)."""
    rows = []
    for rec in records:
        row = dict(rec.get("result") or {})
        task = rec["task"]
        if not row:
            row.update(task["model"])
            if "V" in task:
                row["V"] = task["V"]
        row.pop("jumps", None)
        row["status"] = rec.get("status")
        row["error"] = rec.get("error", "")
        row["wall_time"] = rec.get("wall_time", math.nan)
        row["eps"] = task["numerics"]["eps"]
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


class _Study:
    """The shared stages of a report (each computed at most once)."""

    def __init__(self, settings: Settings, runner: Runner, Dc: float | None) -> None:
        self.s = settings
        self.runner = runner
        self.Dc_given = Dc
        self.tables: dict[str, pd.DataFrame] = {}
        self.values: dict[str, Any] = {}

    # -- micro building blocks -------------------------------------------------------------
    def _stationary(self, pairs, *, eps=None, desc: str) -> pd.DataFrame:
        s = self.s
        tasks = [StationaryTask(s.model(k0, k1, k2), V, s.numerics(eps), s.convergence())
                 for (k0, k1, k2, V) in pairs]
        return micro_frame(self.runner.run(tasks, desc=desc))

    def _critical(self, triples, *, eps, rel_tol, desc: str) -> pd.DataFrame:
        """Micro Vc by bisection for (k0, k1, k2, V_guess)."""
        s = self.s
        tasks = []
        for k0, k1, k2, guess in triples:
            guess = float(min(max(guess, 1e-4), 1e3))
            tasks.append(CriticalTask(s.model(k0, k1, k2), V_min=1e-4, V_max=1e3, rel_tol=rel_tol,
                                      numerics=s.numerics(eps), convergence=s.convergence(),
                                      V_guess=guess, factor=2.0, refine=s.vc_refine))
        recs = self.runner.run(tasks, desc=desc)
        rows = []
        for rec in recs:
            r = dict(rec.get("result") or {})
            m = rec["task"]["model"]
            rows.append({"k0": m["k0"], "k1": m["k1"], "k2": m["k2"], "Vc": r.get("Vc", math.nan),
                         "V_low": r.get("V_low", math.nan), "V_high": r.get("V_high", math.nan),
                         "status": r.get("status", rec.get("status")), "eps": rec["task"]["numerics"]["eps"],
                         "rel_tol": rel_tol, "evaluations": len(r.get("evaluations", [])),
                         "wall_time": rec.get("wall_time", math.nan), "error": rec.get("error", "")})
        return pd.DataFrame(rows)

    # -- stage: micro diagram + reference branch ----------------------------------------------
    @cached_property
    def micro_points(self) -> pd.DataFrame:
        s = self.s
        pairs = [(k0, None, None, V) for k0 in s.k0 for V in s.diagram_velocities(k0)]
        ref = [(s.reference_k0, None, None, V) for V in s.reference_V]
        frame = self._stationary(pairs + ref, desc="micro diagram")
        frame["role"] = ["diagram"] * len(pairs) + ["reference"] * len(ref)
        self.tables["micro_points"] = frame
        return frame

    @cached_property
    def steady_fit(self) -> fits.SteadyLawFit:
        fit = fits.fit_steady_law(self.micro_points)
        self.tables["steady_fit"] = fit.to_frame()
        self.tables["steady_fit_residuals"] = fit.residuals
        self.values.update(A=fit.A, A_err=fit.A_err, B=fit.B, B_err=fit.B_err, steady_rms=fit.rms)
        return fit

    def law_for(self, k0: float) -> rsf.HyperbolicLaw:
        """The fitted Eq. (10) at ``k0``: its own offset if micro has steady points there,
        else the nearest fitted offset shifted by micro's exact fast-sliding limit
        (:func:`micro.sigma_fast_limit`), which carries the k0 dependence of the offset."""
        fit = self.steady_fit
        fitted = fit.offsets.k0.to_numpy(float)
        if np.any(np.isclose(fitted, k0, rtol=1e-12, atol=0)):
            return fit.law(k0)
        near = float(fitted[np.argmin(np.abs(np.log(fitted) - math.log(k0)))])
        shift = micro.sigma_fast_limit(self.s.model(k0)) - micro.sigma_fast_limit(self.s.model(near))
        return fit.law(mu_inf=fit.mu_inf(near) + shift)

    @cached_property
    def dc_fit(self) -> fits.DcFit | None:
        if self.Dc_given is not None:
            return None
        pts = self.micro_points[self.micro_points.role == "diagram"]
        fit = fits.fit_dc(pts, self.law_for, bounds=self.s.dc_bounds, n_grid=self.s.dc_grid,
                          n_bootstrap=self.s.bootstrap)
        self.tables["dc_fit"] = fit.to_frame()
        self.tables["dc_profile"] = fit.profile
        self.tables["dc_points"] = fit.points
        self.tables["dc_rms_per_k0"] = fit.rms_per_k0
        self.values.update(Dc=fit.Dc, Dc_err=fit.Dc_err, Dc_rms=fit.rms, Dc_profile=fit.Dc_profile,
                           regime_agreement=fit.regime_agreement)
        return fit

    @property
    def Dc(self) -> float:
        fit = self.dc_fit
        return float(self.Dc_given) if fit is None else fit.Dc

    @cached_property
    def critical(self) -> pd.DataFrame:
        """Micro Vc (bisection) at ``critical_k0`` next to RS Vc (fitted law and D_c) at
        every k0 of the paper."""
        s = self.s
        k0_micro = [k for k in s.critical_k0 if k < s.k2]
        guess = lambda k: self._rs_vc(k) if math.isfinite(self._rs_vc(k)) else s.rs_guess_vc(k)  # noqa: E731
        micro_vc = self._critical([(k, None, None, guess(k)) for k in k0_micro], eps=s.eps, rel_tol=s.critical_rel_tol,
                                  desc="micro Vc") if k0_micro else pd.DataFrame()
        rows = []
        pts = self.micro_points
        for k0 in sorted(set(PAPER_K0) | set(s.k0) | set(k0_micro), reverse=True):
            row = {"k0": k0, "Vc_rs": self._rs_vc(k0), "Vc_rs_paper": s.rs_guess_vc(k0)}
            # bracket from the diagram points: last stick-slip below first steady
            d = pts[(pts.role == "diagram") & np.isclose(pts.k0, k0)]
            ss = d[d.regime == "stick-slip"].V
            st = d[d.regime == "steady"].V
            row["diagram_V_low"] = float(ss.max()) if len(ss) else math.nan
            row["diagram_V_high"] = float(st[st > row["diagram_V_low"]].min()) if len(ss) and len(st) else math.nan
            if len(micro_vc) and np.any(np.isclose(micro_vc.k0, k0)):
                m = micro_vc[np.isclose(micro_vc.k0, k0)].iloc[0]
                row.update(Vc_micro=m.Vc, Vc_micro_low=m.V_low, Vc_micro_high=m.V_high, micro_status=m.status,
                           micro_eps=m.eps)
            else:
                row.update(Vc_micro=math.nan, Vc_micro_low=math.nan, Vc_micro_high=math.nan,
                           micro_status="not computed", micro_eps=math.nan)
            lo, hi = row["diagram_V_low"], row["diagram_V_high"]
            vc = row["Vc_micro"]
            # the bisection's regime calls (capped runs) against the diagram's full runs
            row["micro_consistent"] = (not (math.isfinite(vc) and math.isfinite(lo)) or vc >= lo) and \
                (not (math.isfinite(vc) and math.isfinite(hi)) or vc <= hi)
            rows.append(row)
        frame = pd.DataFrame(rows)
        self.tables["critical_velocity"] = frame
        return frame

    def _rs_vc(self, k0: float) -> float:
        cv = rsf.critical_velocity(self.law_for(k0), k0, self.Dc)
        return float(cv.Vc) if math.isfinite(cv.Vc) else math.nan

    # -- scenarios -----------------------------------------------------------------------------
    def bifurcation(self) -> None:
        s = self.s
        pts = self.micro_points
        Dc = self.Dc

        def V_range(k0: float) -> tuple[float, float]:
            vc = self._rs_vc(k0)
            hi = 5.0 * vc if math.isfinite(vc) else 10.0
            return 1e-3, max(hi, 10.0)

        curves = rs_curves(PAPER_K0, self.law_for, Dc, V_range=V_range, n=s.rs_points, label="fitted Dc")
        self.tables["rs_bifurcation"] = curves
        self.critical
        self.values["bifurcation_points"] = int((pts.role == "diagram").sum())

    def hopf(self) -> None:
        s = self.s
        k0 = s.hopf_k0
        crit = self._critical([(k0, None, None, self._rs_vc(k0))], eps=s.eps, rel_tol=s.hopf_rel_tol,
                              desc="micro Vc (Hopf)")
        row = crit.iloc[0]
        rows = []
        if row.status == "converged":
            Vc = float(row.Vc)
            frame = self._stationary([(k0, None, None, float(f"{Vc * (1 - d):.6g}")) for d in s.hopf_distances],
                                     desc="micro Hopf")
            frame["Vc"] = Vc
            frame["amplitude"] = frame.sigma_max - frame.sigma_min
            frame["model"] = "micro"
            rows.append(frame[["model", "k0", "V", "Vc", "regime", "sigma_max", "sigma_min", "amplitude"]])
        else:
            log.warning("micro Vc at k0=%g not found (%s): no micro Hopf points", k0, row.status)
        model = rsf.SpringSlider(law=self.law_for(k0), k0=k0, Dc=self.Dc)
        rs = rs_hopf(model, np.geomspace(1e-3, 0.6, 12))
        rs["model"] = "RS"
        rs["k0"] = k0
        rows.append(rs[["model", "k0", "V", "Vc", "regime", "sigma_max", "sigma_min", "amplitude"]])
        points = pd.concat(rows, ignore_index=True)
        self.tables["hopf_points"] = points
        fits_rows = []
        for name, grp in points.groupby("model"):
            grp = grp[grp.regime == "stick-slip"]
            for vc_mode in ("bisection", "fitted"):
                if name == "RS" and vc_mode == "fitted":
                    continue
                try:
                    f = fits.fit_power_law(grp.V, grp.amplitude, Vc=None if vc_mode == "fitted" else float(grp.Vc.iloc[0]))
                except ValueError as exc:
                    log.warning("Hopf fit %s (%s): %s", name, vc_mode, exc)
                    continue
                fits_rows.append({"model": name, "Vc_mode": "exact (linear stability)" if name == "RS" else vc_mode,
                                  **f.to_dict()})
        self.tables["hopf_fit"] = pd.DataFrame(fits_rows)

    def phase(self) -> None:
        s = self.s
        Dc = self.Dc
        laws, law_rows, ref_frames = {}, [], []
        ref_pairs = []
        for k1, k2 in s.phase_sets:
            k_ref = max(s.reference_k0, 1.2 * k2)
            ref_pairs += [(k_ref, k1, k2, V) for V in s.phase_reference_V]
        ref = self._stationary(ref_pairs, eps=s.phase_eps, desc="micro phase reference")
        self.tables["phase_reference"] = ref
        for k1, k2 in s.phase_sets:
            sel = ref[np.isclose(ref.k1, k1) & np.isclose(ref.k2, k2)]
            try:
                f = fits.fit_steady_law(sel)
                laws[(k1, k2)] = f
                law_rows.append({"k1": k1, "k2": k2, "A": f.A, "A_err": f.A_err, "B": f.B, "B_err": f.B_err,
                                 "mu_inf": float(f.offsets.mu_inf.iloc[0]), "rms": f.rms})
            except ValueError as exc:
                log.warning("phase set (k1=%g, k2=%g): no Eq. (10) fit: %s", k1, k2, exc)
        self.tables["phase_laws"] = pd.DataFrame(law_rows)
        triples = []
        for k1, k2 in s.phase_sets:
            f = laws.get((k1, k2))
            for k0 in s.phase_k0:
                if k0 >= k2:
                    continue
                guess = math.nan
                if f is not None:
                    guess = rsf.critical_velocity(f.law(mu_inf=0.0), k0, Dc).Vc
                triples.append((k0, k1, k2, guess if math.isfinite(guess) else 1.0))
        micro_vc = self._critical(triples, eps=s.phase_eps, rel_tol=s.phase_rel_tol, desc="micro phase Vc")
        micro_vc["model"] = "micro"
        rows = []
        for (k1, k2), f in laws.items():
            for k0 in np.geomspace(1e-4, 1.0, 81):
                cv = rsf.critical_velocity(f.law(mu_inf=0.0), float(k0), Dc)
                rows.append({"model": "RS", "k1": k1, "k2": k2, "k0": float(k0),
                             "Vc": float(cv.Vc) if math.isfinite(cv.Vc) else math.nan,
                             "asymptote": f.A / (k0 * Dc), "k0_max_rs": f.A / (4 * f.B * Dc)})
        self.tables["phase_micro"] = micro_vc
        self.tables["phase_rs"] = pd.DataFrame(rows)

    def shs(self) -> None:
        s = self.s
        k0, V = s.shs_k0, s.shs_V
        rec = self.runner.run([SlideHoldSlideTask(s.model(k0), V, s.hold_times, s.numerics(), s.convergence())],
                              desc="micro slide-hold-slide")[0]
        frames = []
        if rec.get("status") == "ok":
            m = pd.DataFrame(rec["result"]["rows"])
            m["model"] = "micro"
            frames.append(m[["model", "hold_time", "sigma_steady", "sigma_peak", "delta_sigma_max"]])
        else:
            log.warning("micro slide-hold-slide failed: %s", rec.get("error"))
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


def _fmt(x: Any, digits: int = 4) -> str:
    try:
        xf = float(x)
    except (TypeError, ValueError):
        return str(x)
    return "nan" if not math.isfinite(xf) else f"{xf:.{digits}g}"


def _summary(study: _Study, rep: Report, scenarios: Sequence[str]) -> str:
    s, t, v = study.s, study.tables, study.values
    lines = ["# micro vs rate-and-state: comparison report", "",
             f"Preset `{s.preset}`; scenarios: {', '.join(scenarios)}; wall time {rep.wall_time:.1f} s "
             f"({rep.stats.computed} micro tasks computed, {rep.stats.cached} from the cache, "
             f"{rep.stats.compute_seconds:.1f} s of micro compute).", "",
             f"Model: k1 = {s.k1:g}, k2 = {s.k2:g}, exponential jumps zbar = {s.zbar:g} (cutoff {s.cutoff:g}), "
             f"eta_u = f_th = 1; micro bin eps = {s.eps:g} (phase diagram: {s.phase_eps:g}), rtol = {s.rtol:g}.", ""]
    if "steady_fit" in t:
        lines += ["## Eq. (10) fitted to micro's steady branch", "",
                  f"A = {_fmt(v['A'])} ± {_fmt(v['A_err'], 2)}, B = {_fmt(v['B'])} ± {_fmt(v['B_err'], 2)} "
                  f"(paper: A = {rsf.PAPER_A}, B = {rsf.PAPER_B}); rms residual {_fmt(v['steady_rms'], 3)}.", "",
                  "| k0 | mu_inf | ± | steady points |", "|---|---|---|---|"]
        for _, r in t["steady_fit"].iterrows():
            lines.append(f"| {r.k0:g} | {_fmt(r.mu_inf, 6)} | {_fmt(r.mu_inf_err, 2)} | {int(r.n_points)} |")
        lines.append("")
    if "Dc" in v:
        lo, hi = v["Dc_profile"]
        lines += ["## D_c", "",
                  f"D_c = {_fmt(v['Dc'])} ± {_fmt(v['Dc_err'], 2)} (bootstrap 16-84 %; profile interval "
                  f"[{_fmt(lo, 3)}, {_fmt(hi, 3)}]); paper: D_c = {rsf.PAPER_DC}. rms residual of sigma_max, "
                  f"sigma_min: {_fmt(v['Dc_rms'], 3)}; regime agreement {100 * v['regime_agreement']:.0f} % "
                  f"over {v.get('bifurcation_points', '?')} micro points.", ""]
    elif study.Dc_given is not None:
        lines += ["## D_c", "", f"D_c = {study.Dc_given:g} given (not fitted).", ""]
    if "critical_velocity" in t:
        lines += ["## Critical velocity per k0", "",
                  "Micro: bisection (bracket [low, high]) where computed; 'diagram' is the bracket from the "
                  "diagram points. RS: linear stability with the fitted law and D_c (paper's law and D_c in "
                  "the last column).", "",
                  "| k0 | Vc micro | micro bracket | diagram bracket | Vc RS | Vc RS (paper) |",
                  "|---|---|---|---|---|---|"]
        for _, r in t["critical_velocity"].iterrows():
            lines.append(f"| {r.k0:g} | {_fmt(r.Vc_micro)} | [{_fmt(r.Vc_micro_low)}, {_fmt(r.Vc_micro_high)}] | "
                         f"[{_fmt(r.diagram_V_low)}, {_fmt(r.diagram_V_high)}] | {_fmt(r.Vc_rs)} | "
                         f"{_fmt(r.Vc_rs_paper)} |")
        bad = t["critical_velocity"][~t["critical_velocity"].micro_consistent.astype(bool)]
        if len(bad):
            lines += ["", "**Inconsistent micro Vc** at k0 = " + ", ".join(f"{k:g}" for k in bad.k0) +
                      ": the bisection (micro.critical_velocity, whose runs are capped in time and called "
                      "steady when an oscillation decays) lies outside the bracket of the full diagram runs. "
                      "The transition is then hysteretic (a finite-amplitude stick-slip cycle coexists with "
                      "steady sliding) or the capped runs misjudge slowly growing oscillations; trust the "
                      "diagram bracket."]
        missing = [k for k in PAPER_K0 if k not in s.k0]
        if missing:
            lines += ["", f"The micro side leaves out k0 = {', '.join(f'{k:g}' for k in missing)} "
                          "(Vc ~ 1/k0 is large and micro's cost grows like V); the RS side covers all five."]
        lines.append("")
    if "hopf_fit" in t:
        lines += ["## Hopf scaling, sigma_max - sigma_min ∝ (Vc - V)^beta", "",
                  "| model | Vc | beta | ± | points |", "|---|---|---|---|---|"]
        for _, r in t["hopf_fit"].iterrows():
            lines.append(f"| {r.model} ({r.Vc_mode}) | {_fmt(r.Vc)} | {_fmt(r.exponent, 3)} | "
                         f"{_fmt(r.exponent_err, 2)} | {int(r.n_points)} |")
        lines.append("")
    if "phase_micro" in t:
        lines += ["## Phase diagram (k0, V)", "", "Eq. (10) per (k1, k2) set, fitted to micro's steady branch "
                  "at k0 = max(reference_k0, 1.2 k2):", "", "| k1 | k2 | A | B | RS k0_max = A/(4 B D_c) |",
                  "|---|---|---|---|---|"]
        for _, r in t["phase_laws"].iterrows():
            lines.append(f"| {r.k1:g} | {r.k2:g} | {_fmt(r.A)} | {_fmt(r.B)} | {_fmt(r.A / (4 * r.B * study.Dc))} |")
        lines += ["", "| k1 | k2 | k0 | Vc micro | bracket | Vc RS |", "|---|---|---|---|---|---|"]
        rs = t["phase_rs"]
        for _, r in t["phase_micro"].iterrows():
            f = t["phase_laws"][np.isclose(t["phase_laws"].k1, r.k1) & np.isclose(t["phase_laws"].k2, r.k2)]
            vc_rs = math.nan
            if len(f):
                cv = rsf.critical_velocity(rsf.HyperbolicLaw(A=f.A.iloc[0], B=f.B.iloc[0], mu_inf=0.0), r.k0, study.Dc)
                vc_rs = cv.Vc
            lines.append(f"| {r.k1:g} | {r.k2:g} | {r.k0:g} | {_fmt(r.Vc)} | [{_fmt(r.V_low)}, {_fmt(r.V_high)}] "
                         f"| {_fmt(vc_rs)} |")
        lines.append("")
    if "shs_fit" in t:
        lines += ["## Slide-hold-slide peak vs hold time", "",
                  f"k0 = {s.shs_k0:g}, V = {s.shs_V:g}; classical RS with b = {_fmt(v['shs_b'], 3)}; "
                  f"A/B of the fitted law = {_fmt(v['shs_A_over_B'])}.", "",
                  "| model | law | p1 | p2 | rel. rms | best |", "|---|---|---|---|---|---|"]
        for _, r in t["shs_fit"].iterrows():
            lines.append(f"| {r.model} | {r.law} | {r.p1_name} = {_fmt(r.p1)} | {r.p2_name} = {_fmt(r.p2)} | "
                         f"{_fmt(r.rel_rms, 2)} | {'yes' if r.best else ''} |")
        lines.append("")
    if rep.figures:
        lines += ["## Figures", ""] + [f"![{name}]({p.name})" for name, p in rep.figures.items()] + [""]
    lines += ["## Tables", "", ", ".join(f"`{n}.csv`" for n in sorted(t)), ""]
    return "\n".join(lines)


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
        Use this D_c instead of fitting it (the fit needs the micro diagram points).
    cache_dir, use_cache : where micro records are cached (default: ``$COMPARE_CACHE_DIR`` or
        ``~/.cache/frictionkit-compare``), or no cache at all.
    workers, scheduler, progress : see :class:`~compare.runner.Runner`.
    """
    start = time.perf_counter()
    settings = Settings.default() if settings is None else settings
    if not isinstance(settings, Settings):
        raise ValueError(f"settings must be a compare.Settings, got {type(settings).__name__}")
    if scenarios is not None:
        settings = settings.with_(scenarios=tuple(scenarios))
    if Dc is not None:
        Dc = positive("Dc", Dc)
    cache = PointCache(cache_dir) if use_cache else NullCache()
    rep = Report(settings=settings)
    with Runner(cache, workers=workers, scheduler=scheduler, progress=progress) as runner:
        study = _Study(settings, runner, Dc)
        for name in settings.scenarios:
            log.info("scenario %s", name)
            getattr(study, name)()
        rep.stats = runner.stats
    rep.tables, rep.values = study.tables, study.values
    rep.tables["settings"] = pd.DataFrame([{k: repr(v) if isinstance(v, tuple) else v
                                            for k, v in settings.to_dict().items()}])
    if out is not None:
        from . import figures
        rep.out = Path(out)
        rep.out.mkdir(parents=True, exist_ok=True)
        for name, table in rep.tables.items():
            table.to_csv(rep.out / f"{name}.csv", index=False)
        rep.figures = figures.draw(study, rep.out)
    rep.wall_time = time.perf_counter() - start
    rep.summary = _summary(study, rep, settings.scenarios)
    if rep.out is not None:
        (rep.out / "summary.md").write_text(rep.summary, encoding="utf-8")
    return rep
