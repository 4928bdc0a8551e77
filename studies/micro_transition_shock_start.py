"""How micro's stick-slip shocks start near V^c: the closure H(X) at the moment the cohort
method takes the shock (docs/reference/micro_transition.md section 2).

For each (k0, d), V = V^c (1 - d) (V^c exact, renewal chain), the limit cycle is computed by
``micro.cohort.cycle_cohorts`` at ``--dt`` (default 0.02) and the default cell
h = kappa zbar / 20, to ``--tol`` (default 1e-5, at most ``--max-iter`` = 400 cycles).  From
its final state (``res.state``, just after the last shock, with its step ``state.dt``) one
more cycle is run by the method's own cycle (``micro.study_hooks.one_cycle``), on the same
state made an instance of ``Probe``, a subclass of ``micro.study_hooks.CohortState`` that
only observes (nothing in micro/ is changed; at
k0 = 0.1, d = 0.1 the probed cycle's extrema, period, unjumped fraction and shock slip
were bit-identical to a plain ``_one_cycle`` from a copy of the same state):

* after every loading step it records the state's branching ratio, b - 1 = H'(0) of the
  zero-time closure (the loop re-prepares the coefficients before it uses them again), and
  keeps a copy of the state before the step;
* at the shock, inside ``shock_root`` (which ``_one_cycle`` calls right after
  ``prepare(0.0)`` and ``root()``, on the state after the partial step that ends the
  loading, located by bisection to FOLD_TOL = 1e-7 of the step), it lets the code take its
  slip X_shock first, then evaluates H(X) and the analytic H'(X) of ``_Cohorts.closure`` on
  a linear grid of 2001 points on [0, 1.05 X_shock] and a log grid of 400 points from
  1e-10 zbar, and at X = e, 2 e (e = 1e-8 zbar; and 10 e, 20 e):
  b_s - 1 = H'(0) by Richardson on H(X) / X (H(0) = 0 to round-off), against the analytic
  H' at e and 2 e extrapolated to 0 (at X = 0 itself the kernel skips every cohort);
  H''(0) from the analytic H'.  From the grids: the share of [0, X_shock] where H is concave
  (H' falling) and the first inflection; the interior local minima of H (a fold of the
  zero-time closure; with one, its distance in time, delta* = -H_min / (dH/dt), against the
  bisection's resolution) and maxima; the sign changes of H (counting H(0) = 0 as not
  positive); and the root where H first goes from + to -, refined by Brent's method on the
  closure: it must equal the code's own X_shock (``root_rel_diff``; the check asked for at
  a total shock, k0 = 0.1, d = 0.5);
* the fold of the step closure that ended the loading: from the copy before the partial
  step, the closure of that step (length L) at its root x_lo (its slope there,
  ``step_slope_at_root``), its local minimum just beyond (``step_fold_X``, its value
  ``step_fold_H_lo`` and curvature ``step_fold_curv``), and the same minimum for the step
  L + FOLD_TOL * step that the bisection found without a root (``step_fold_H_hi``);
* the step's own dashpots: in a step of length L a unit of slip moves the margins by
  k1 + k2 - k2 phi, phi = 1 - (1 - e^{-gamma L}) / (gamma L), against k1 + k2 in zero time,
  so a fold of the step's closure (its slope 0) leaves the zero-time closure a slope
  b_artifact = k2 phi / (k1 + k2 - k2 phi) at 0; ``b_s_minus_artifact`` = b_s - 1 - b_artifact.

The bulk of the way: H's largest slope (``slope_max``, at ``X_slope_max``: the excess
branching ratio the closure reaches past its convex layer at 0) and its curvature over
the middle half of [0, X_shock] (``bulk_curvature``, a line through H' there), against
-k0 / lambda, the curvature of the contracted exponential at b = 1
(docs/reference/micro_transition.md §2; ``bulk_curvature_over_k0_lam``), and the drop
against 2 lambda ``slope_max``, the far root of that parabola (``drop_over_2lam_slope``).

Also: the drop k0 X_shock against the prediction 2 lambda (b_s - 1) of a start at b_s > 1
(lambda = kappa zbar), the fraction the shock leaves unjumped, the converged run's sigma_max,
sigma_min and amplitude and the extra cycle's (``extra_*``), the loading phase's last full
step (its b - 1, slip, time before the shock) and its largest step's slip over X_shock (a
burst taken as creep would show there), a fit b - 1 = c0 + a sqrt(t_shock - t) to the last
three full steps (``approach_*``), and steady sliding's branching ratio b_ss at the same V
(``micro.steady_sliding``): ``bs_over_bss`` = (b_s - 1) / (b_ss - 1).

Writes benchmarks/results/micro_transition_shock_start.csv (rows merge by k0, d, dt) and
prints a table.  Run times measured on 1 core (NUMBA_NUM_THREADS=1, another process busy on
the machine's other core):

    python -m studies micro_transition_shock_start --k0 0.1 --d 0.5 0.1 0.05 0.02 0.01   # 3.6 min
    python -m studies micro_transition_shock_start --k0 0.1 --d 0.005                    # 7.2 min
    python -m studies micro_transition_shock_start --k0 0.3 0.1 --d 0.1 0.05 0.02 0.01   # 17 min (bulk columns)
    python -m studies micro_transition_shock_start --k0 0.3 --d 0.005                    # 14 min
    python -m studies micro_transition_shock_start --k0 0.01 --d 0.5 0.1 0.05 0.02 0.01  # 3.9 min
    python -m studies micro_transition_shock_start --k0 0.01 --d 0.02 0.01 --tol 3e-5    # 3.5 min
    python -m studies micro_transition_shock_start --k0 0.1 0.01 --d 0.1 0.02 --dt 0.01  # 6.4 min

(the fourth replaced the k0 = 0.01 rows at d = 0.02 and 0.01 of the third, which had not
reached tol = 1e-5 in 400 cycles: d = 0.02 then converged, d = 0.01 again stopped at 400
cycles, error estimate 3.8e-5, its row flagged ``converged`` False; the fifth repeats four
points at half the step, to see what the step does to b_s - 1; its k0 = 0.01, d = 0.02 row
stopped at 400 cycles, error estimate 9.9e-6, also flagged).
"""
from __future__ import annotations

import argparse
import math

import numpy as np
import pandas as pd
from scipy import optimize

import micro
from micro import cohort as C
from micro.cohort import options as cohort_options
from micro import study_hooks as H  # the state class and the cycle map, for studies

from benchmarks._harness import RESULTS, Stopwatch, warm_up, write_csv

OUT = RESULTS / "micro_transition_shock_start.csv"
#: Points of the linear grid on [0, GRID_TOP X_shock], and of the log grid below it.
N_LIN, N_LOG, GRID_TOP = 2001, 400, 1.05
#: The small slips (in units of zbar) of the finite differences at 0: e and 2 e.
EPS = 1e-8


def b_minus_1(st: H.CohortState, e: float) -> tuple[float, float, float, float]:
    """From the current prepared coefficients: H'(0) by Richardson on H(X)/X at X = e, 2e
    (H(0) = 0), H'(0) from the analytic H' at e and 2e extrapolated linearly, H''(0)
    from the analytic H', and H(0)."""
    H0 = st.closure(0.0)[0]
    H1, d1 = st.closure(e)
    H2, d2 = st.closure(2.0 * e)
    fd = 2.0 * (H1 - H0) / e - (H2 - H0) / (2.0 * e)
    return fd, 2.0 * d1 - d2, (d2 - d1) / e, H0


class Probe(H.CohortState):
    """``_Cohorts`` that records, without changing it, what one cycle does (module
    docstring).  ``copy()`` makes plain ``_Cohorts`` (the replays of the peak do not record)."""

    def start_probe(self) -> None:
        self.trail = []  # per loading step: (t, sigma, length, slip, b - 1)
        self.info = {}

    def commit(self, dX: float, dt: float, phi: float, Edt: float) -> None:
        if dt > 0.0:
            # the state before this loading step (without the one before it: no chain of copies)
            self.__dict__.pop("pre", None)
            self.pre = (self.copy(), dX)
        super().commit(dX, dt, phi, Edt)
        if dt > 0.0:
            # (every commit in _one_cycle is followed by a prepare before the coefficients are used)
            self.prepare(0.0)
            fd, _, _, _ = b_minus_1(self, EPS * self.model.zbar)
            self.trail.append((self.t, self.sigma, dt, dX, fd))

    def shock_root(self, x0: float) -> float:
        slip = super().shock_root(x0)
        self.info = self.probe(x0, slip)
        self.prepare(0.0)  # (the coefficients the shock is committed with, as before the probe)
        return slip

    def step_fold(self, et: float) -> dict:
        """The fold of the step closure that ended the loading (:func:`step_fold_of`): from the
        state before the last (partial) loading step, or, where the bisection left no
        partial step, from this state with a step of length 0."""
        step = self.dt
        if self.trail and self.trail[-1][2] < (1.0 - 1e-9) * step:
            pre, x_lo = self.pre
            return step_fold_of(pre.copy(), self.trail[-1][2], et, x_lo)
        return step_fold_of(self.copy(), 0.0, et, 1e-12 * self.model.zbar)

    def probe(self, x0: float, slip: float) -> dict:
        md = self.model
        zbar = md.zbar
        e = EPS * zbar
        fd, an, H2_0, H_at_0 = b_minus_1(self, e)
        # a second pair ten times larger: how far the extrapolation to 0 holds
        fd10, _, _, _ = b_minus_1(self, 10.0 * e)
        lin = np.linspace(0.0, GRID_TOP * slip, N_LIN)
        log = np.geomspace(1e-10 * zbar, lin[1], N_LOG, endpoint=False)
        X = np.unique(np.concatenate([lin, log]))
        HH = np.array([self.closure(x) for x in X])
        H, dH = HH[:, 0], HH[:, 1]
        dH[0] = np.nan  # (at X = 0 exactly the kernel skips every cohort: its H' is not the limit)
        # the root: where H first goes from + to - after being positive
        pos = np.flatnonzero(H > 0.0)
        root, n_changes = math.nan, int(np.sum((H[1:] > 0.0) != (H[:-1] > 0.0)))
        if pos.size:
            after = np.flatnonzero((H[:-1] > 0.0) & (H[1:] <= 0.0))
            if after.size:
                i = after[0]
                root = optimize.brentq(lambda x: self.closure(x)[0], X[i], X[i + 1], xtol=1e-300, rtol=1e-15,
                                       maxiter=200) if H[i + 1] < 0.0 else X[i + 1]
        # curvature on [0, X_shock] from the analytic H' (between grid points)
        inside = (X > 0.0) & (X <= slip)
        Xi, dHi = X[inside], dH[inside]
        d2 = np.diff(dHi) / np.diff(Xi)
        widths = np.diff(Xi)
        concave_share = float(widths[d2 < 0.0].sum() / widths.sum())
        infl = np.flatnonzero(np.sign(d2[1:]) != np.sign(d2[:-1]))
        first_inflection = float(Xi[infl[0] + 1]) if infl.size else math.nan
        # the bulk: H's largest slope on the way (the excess branching ratio the closure
        # reaches past the convex layer at 0) and its curvature over the middle half of the
        # way (a least-squares line through H' on [X_shock / 4, 3 X_shock / 4])
        ok = np.isfinite(dHi)
        k = int(np.argmax(np.where(ok, dHi, -np.inf)))
        slope_max, X_slope_max = float(dHi[k]), float(Xi[k])
        mid = ok & (Xi >= 0.25 * slip) & (Xi <= 0.75 * slip)
        bulk_curvature = float(np.polyfit(Xi[mid], dHi[mid], 1)[0]) if mid.sum() >= 3 else math.nan
        # interior extrema of H on (0, X_shock] from the sign of the analytic H'
        sgn = np.sign(dHi)
        mins = np.flatnonzero((sgn[:-1] < 0.0) & (sgn[1:] > 0.0))
        maxs = np.flatnonzero((sgn[:-1] > 0.0) & (sgn[1:] < 0.0))
        Xm = Hm = Xp = Hp = math.nan
        if mins.size:
            j = mins[0]
            Xm = optimize.brentq(lambda x: self.closure(x)[1], Xi[j], Xi[j + 1], xtol=1e-300, rtol=1e-12)
            Hm = self.closure(Xm)[0]
        if maxs.size:
            j = maxs[0]
            Xp = optimize.brentq(lambda x: self.closure(x)[1], Xi[j], Xi[j + 1], xtol=1e-300, rtol=1e-12)
            Hp = self.closure(Xp)[0]
        # the fold's distance in time: a loading step of FOLD_TOL * step from here
        et = cohort_options.DEFAULT.FOLD_TOL * self.dt
        c1 = delta_star = b_pred = math.nan
        if math.isfinite(Xm):
            H0m = self.closure(Xm)[0]
            self.prepare(et)
            c1 = (self.closure(Xm)[0] - H0m) / et
            self.prepare(0.0)
            if c1 > 0.0:
                delta_star = -Hm / c1
                b_pred = -math.sqrt(max(2.0 * H2_0 * c1 * max(delta_star, 0.0), 0.0))
        fold = self.step_fold(et)
        return dict(fold, H_at_0=H_at_0, b_s_minus_1=fd, b_s_minus_1_analytic=an, b_s_minus_1_10e=fd10, H2_0=H2_0,
                    concave_share=concave_share, first_inflection=first_inflection, slope_max=slope_max,
                    X_slope_max=X_slope_max, bulk_curvature=bulk_curvature, n_minima=int(mins.size),
                    n_maxima=int(maxs.size), X_min=Xm, H_min=Hm, X_max=Xp, H_max=Hp, sign_changes=n_changes,
                    grid_root=root, x0=x0, fold_c1=c1, fold_delta_over_et=delta_star / et, b_fold_pred=b_pred,
                    sigma_at_shock=self.sigma, t_at_shock=self.t, n_grid=int(X.size))


def _min_after(st: H.CohortState, x: float) -> tuple[float, float, float]:
    """The first local minimum of the prepared closure of ``st`` to the right of ``x``
    (where H' < 0): its position, value and H'' there (NaN if H' stays negative up to 10 x)."""
    d0 = st.closure(x)[1]
    if not d0 < 0.0:
        return math.nan, math.nan, math.nan
    span = 1e-7 * x
    while st.closure(x + span)[1] < 0.0:
        span *= 2.0
        if span > 10.0 * x:
            return math.nan, math.nan, math.nan
    lo = x + 0.5 * span if span > 1e-7 * x else x
    xm = optimize.brentq(lambda v: st.closure(v)[1], lo, x + span, xtol=1e-300, rtol=1e-13)
    e = 1e-6 * xm
    curv = (st.closure(xm + e)[1] - st.closure(xm - e)[1]) / (2.0 * e)
    return xm, st.closure(xm)[0], curv


def step_fold_of(pre: H.CohortState, length: float, et: float, x_lo: float) -> dict:
    """The step closure of ``pre`` at the shock's start: for a step of ``length`` (the
    bisection's last step with a root, slip ``x_lo``) its slope at that root and the
    local minimum just beyond it; and for ``length + et`` (the shortest step found
    without a root) the minimum's value."""
    pre.prepare(length)
    H_lo, dH_lo = pre.closure(x_lo)
    xm, Hm, curv = _min_after(pre, x_lo)
    pre.prepare(length + et)
    _, Hm_hi, _ = _min_after(pre, x_lo)
    return dict(step_len=length, step_root=x_lo, step_H_at_root=H_lo, step_slope_at_root=dH_lo, step_fold_X=xm,
                step_fold_H_lo=Hm, step_fold_H_hi=Hm_hi, step_fold_curv=curv)


def measure(k0: float, d: float, dt: float, tol: float, max_iter: int) -> dict:
    model = micro.Model(k0=k0)
    Vc = micro.critical_velocity(model).Vc
    V = Vc * (1.0 - d)
    lam = model.kappa * model.zbar
    sw = Stopwatch()
    res = C.cycle_cohorts(model, V, dt=dt, tol=tol, max_iter=max_iter)
    cycle_s = sw.seconds
    row = dict(k0=k0, d=d, V=V, Vc=Vc, dt=dt, h=res.eps, tol=tol, converged=res.converged, applicable=res.applicable,
               error=res.error, cycles=res.iterations, accelerated=res.accelerated, sigma_max=res.sigma_max,
               sigma_min=res.sigma_min, amplitude=res.sigma_max - res.sigma_min, period=res.period,
               unjumped_run=res.unjumped, cycle_wall_s=cycle_s)
    st = getattr(res, "state", None)
    if st is None:
        row.update(message=res.message)
        return row
    step = st.dt
    st.__class__ = Probe
    st.start_probe()
    sw2 = Stopwatch()
    out = H.one_cycle(st, step)
    probe_s = sw2.seconds
    info = st.info
    slip = out["steps"][-1][1] if out.get("ok") else math.nan
    bss = float(micro.steady_sliding(model, [V]).branching_ratio[0])
    loads = [s for s in st.trail]
    last_full = loads[-2] if len(loads) >= 2 and loads[-1][2] < 0.999 * step else (loads[-1] if loads else None)
    partial = loads[-1][2] / step if loads else math.nan
    max_load = max((s[3] for s in loads), default=math.nan)
    bs1 = info.get("b_s_minus_1", math.nan)
    # the step's own dashpot relaxation: in a step of length L a slip moves the margins by
    # (k1 + k2 - k2 phi) per unit, phi = 1 - (1 - e^{-gamma L}) / (gamma L), against k1 + k2 in
    # zero time, so a fold of the step's closure (slope 0) leaves b - 1 ~ k2 phi / (k1 + k2 - k2 phi)
    L = loads[-1][2] if loads else math.nan
    gL = model.gamma * L
    phi = 1.0 - (-math.expm1(-gL)) / gL if gL > 0.0 else 0.0
    b_art = model.k2 * phi / (model.k1 + model.k2 - model.k2 * phi)
    # the approach: b - 1 at the ends of the last three full steps against sqrt(t_shock - t)
    full = [s for s in loads if abs(s[2] - step) <= 1e-9 * step][-3:]
    c0 = slope = math.nan
    if len(full) == 3 and "t_at_shock" in info:
        u = np.sqrt(np.array([info["t_at_shock"] - s[0] for s in full]))
        slope, c0 = np.polyfit(u, np.array([s[4] for s in full]), 1)
    row.update(step=step, ok=out.get("ok"), X_shock=slip, drop=k0 * slip, pred_2lam_b=2.0 * lam * bs1,
               pred_over_drop=2.0 * lam * bs1 / (k0 * slip), unjumped=out.get("unjumped", math.nan),
               bulk_curvature_over_k0_lam=info.get("bulk_curvature", math.nan) / (-k0 / lam),
               drop_over_2lam_slope=k0 * slip / (2.0 * lam * info.get("slope_max", math.nan)),
               extra_sigma_max=out.get("sigma_max"), extra_sigma_min=out.get("sigma_min"),
               extra_sigma_before=out.get("sigma_before"), extra_sigma_after=out.get("sigma_after"),
               extra_period=out.get("period"), b_ss=bss, b_ss_minus_1=bss - 1.0,
               bs_over_bss=bs1 / (bss - 1.0), root_rel_diff=abs(info.get("grid_root", math.nan) - slip) / slip,
               partial_step=partial, n_load_steps=len(loads), b_artifact=b_art, b_s_minus_artifact=bs1 - b_art,
               approach_intercept=c0, approach_slope=slope,
               b_minus_1_cycle_start=loads[0][4] if loads else math.nan,
               last_full_b_minus_1=last_full[4] if last_full else math.nan,
               last_full_before=(info["t_at_shock"] - last_full[0]) if last_full else math.nan,
               last_full_slip=last_full[3] if last_full else math.nan,
               max_load_slip_over_X=max_load / slip, probe_wall_s=probe_s, message=res.message)
    row.update({k: v for k, v in info.items()})
    return row


SHOW = [("k0", "{:g}"), ("d", "{:g}"), ("dt", "{:g}"), ("b_s_minus_1", "{:+.3e}"),
        ("b_s_minus_1_analytic", "{:+.3e}"), ("bs_over_bss", "{:+.2e}"), ("partial_step", "{:.3f}"),
        ("b_artifact", "{:+.3e}"), ("b_s_minus_artifact", "{:+.1e}"), ("H2_0", "{:+.3g}"),
        ("concave_share", "{:.3f}"), ("bulk_curvature_over_k0_lam", "{:.3f}"), ("drop_over_2lam_slope", "{:.3f}"),
        ("n_minima", "{:d}"), ("step_fold_H_lo", "{:+.1e}"), ("step_fold_H_hi", "{:+.1e}"),
        ("X_shock", "{:.5g}"), ("drop", "{:.4e}"), ("pred_2lam_b", "{:+.3e}"), ("pred_over_drop", "{:+.2e}"),
        ("unjumped", "{:.3e}"), ("sigma_max", "{:.6f}"), ("sigma_min", "{:.6f}"), ("amplitude", "{:.6f}"),
        ("b_ss_minus_1", "{:+.3e}"), ("root_rel_diff", "{:.1e}"), ("cycle_wall_s", "{:.0f}")]


def table(frame: pd.DataFrame) -> str:
    lines = []
    for _, r in frame.iterrows():
        parts = []
        for name, fmt in SHOW:
            v = r.get(name, math.nan)
            try:
                parts.append(f"{name}={fmt.format(v)}")
            except (TypeError, ValueError):
                parts.append(f"{name}={v}")
        lines.append("  ".join(parts))
    return "\n".join(lines)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--k0", type=float, nargs="+", default=[0.1])
    ap.add_argument("--d", type=float, nargs="+", default=[0.5, 0.1, 0.05, 0.02, 0.01])
    ap.add_argument("--dt", type=float, default=0.02)
    ap.add_argument("--tol", type=float, default=1e-5, help="the limit cycle's tolerance in stress")
    ap.add_argument("--max-iter", type=int, default=400)
    args = ap.parse_args()
    warm_up(C.cycle_cohorts, micro.Model(k0=0.1), 0.3, tol=1e-3, max_iter=6)
    rows = []
    for k0 in args.k0:
        for d in args.d:
            sw = Stopwatch()
            row = measure(k0, d, args.dt, args.tol, args.max_iter)
            row["wall_s"] = sw.seconds
            rows.append(row)
            print(table(pd.DataFrame([row])), f"wall {row['wall_s']:.1f} s", flush=True)
            write_csv(pd.DataFrame(rows), OUT, keys=["k0", "d", "dt"])
    frame = pd.read_csv(OUT).sort_values(["k0", "d"], ascending=[False, False])
    print("\nall rows of", OUT)
    print(table(frame))


if __name__ == "__main__":
    main()
