"""Close to V^c (k0 = 0.01, V = 0.9 V^c): the cohort method's fixed point by Newton-Krylov on
the whole cycle map, certified by its residual, for cells kappa zbar / 20, /40, /80.

Each point ``H:DT`` (cell ``kappa zbar / H``, time step ``DT``) is first run by
``micro.cohort.cycle_cohorts`` with micro's default stopping (tol = 2e-5; its result, its
error and its CPU time are kept in the row).  Its last state (just after a shock) fixes
the map (``micro.study_hooks.carried_cycle``: one cycle from that state with its newborns'
delta_R marginal replaced, at the run's step), whose fixed point is then solved by
``micro.study_hooks.newton_krylov`` (the Newton-Krylov that cycle_cohorts runs where its frozen-slip
preconditioner grows: ``micro.cohort.newton.solve``, each system (I - J) d = G(x) - x by
GMRES with Jacobian-vector products by forward differences of the map, the map taken
again from each Newton step's state) to 1e-9 in the cycle's stresses.  With
``--consistent`` (the default) the step is then set to the one the fixed point's own
loading phase asks for (``dt T / 0.5``: cycle_cohorts keeps the step of the
transient's period unless it is off by a quarter, so its map depends on the path) and the
fixed point solved again (from the last one's state), until the step moves less than 1e-5
of itself.  From the fixed point ``--verify`` plain cycles of the full dynamics are run
(their largest distance from it in sigma_max is ``drift``).  With ``--multipliers`` the map's three largest multipliers
at the fixed point are found by Arnoldi's method on the same difference quotients.

Before that, the difference quotients themselves are measured at the first point
(``--fd-check``): ``|J v|`` for the residual's direction at steps 1e-3 ... 1e-8 of the
mass, forward and central, written to ``micro_cohort_newton_krylov_fd.csv``.

Writes benchmarks/results/micro_cohort_newton_krylov.csv (rows merge by k0, V / V^c, dt,
h_div, consistent, floor).  CPU seconds (process time) and the 1-minute load are in the rows.

    python -m studies micro_cohort_newton_krylov                         # /20, /40, /80, /40 at dt 0.01
    python -m studies micro_cohort_newton_krylov --points 40:0.02 --multipliers --fd-check
    python -m studies micro_cohort_newton_krylov --points 40:0.01 --tol 1e-7 --max-solves 3

Recorded in docs/validation/micro_cohort.md, section 5 ("Newton-Krylov on the whole cycle
map").  Inside the method it uses ``cycle_cohorts``' state and the hooks for studies
(``micro.study_hooks``: ``carried_cycle``, ``newton_krylov``, ``one_cycle``,
``phase_step``, ``NEWTON_FD_STEP``).
"""
from __future__ import annotations

import argparse
import dataclasses
import os

import numpy as np
import pandas as pd

import micro
import micro.cohort as C
from micro.cohort import options as cohort_options
from micro import study_hooks as H  # the cycle map, its Newton-Krylov, the step rule
from benchmarks._harness import RESULTS, Stopwatch, merged, write_csv


def _load() -> float:
    return os.getloadavg()[0]


def fd_check(base, step, ref) -> list[dict]:
    """|J v| along the residual's direction at several difference steps."""
    dep = base.dense(base.n - 1)
    x = dep / dep.sum()
    G = lambda v: H.carried_cycle(base, step, ref, v)  # noqa: E731
    _, o0, g0 = G(x)
    v = g0 - x
    v /= np.abs(v).sum()
    rows, prev = [], None
    for e in (1e-3, 1e-4, 1e-5, 1e-6, 1e-7, 1e-8):
        _, op, gp = G(x + e * v)
        _, om, gm = G(x - e * v)
        jf, jc = (gp - g0) / e, (gp - gm) / (2 * e)
        rows.append(dict(step=e, Jv_forward=np.abs(jf).sum(), Jv_central=np.abs(jc).sum(),
                         forward_minus_central=np.abs(jf - jc).sum(),
                         central_change=np.abs(jc - prev).sum() if prev is not None else np.nan,
                         dsigma_max_forward=(op["sigma_max"] - o0["sigma_max"]) / e,
                         dsigma_max_central=(op["sigma_max"] - om["sigma_max"]) / (2 * e)))
        prev = jc
        print({k: f"{val:.4g}" for k, val in rows[-1].items()}, flush=True)
    return rows


def multipliers(base, step, ref, x, k: int = 3) -> tuple[np.ndarray, int]:
    """The map's ``k`` largest multipliers at ``x`` (Arnoldi on difference quotients,
    ``micro.study_hooks.map_multipliers``: 25 vectors to 1e-4) and the cycles used."""
    return H.map_multipliers(base, step, ref, x, k)


def solve_point(model, V, h_div, dt, consistent, verify, want_multipliers, fd, tol=1e-8,
                max_solves=6) -> tuple[dict, list[dict]]:
    h = model.kappa * model.zbar / h_div
    load0 = _load()
    with Stopwatch(cpu=True) as sw0:
        r = C.cycle_cohorts(model, V, dt=dt, h=h, tol=2e-5)
    base, step, ref = r.state, r.state.dt, r.state.period_ref
    fd_rows = fd_check(base, step, ref) if fd else []
    row = dict(k0=model.k0, V_over_Vc=0.9, dt=dt, h_div=h_div, consistent=consistent,
               default_sigma_max=r.sigma_max, default_error=r.error, default_cycles=r.iterations,
               default_cpu_s=sw0.seconds, default_step=step, default_load=load0, default_message=r.message)
    evals, solves, cpu = 0, 0, 0.0
    tried = []  # (step, the step its fixed point asks for)
    first = None
    with Stopwatch(cpu=True) as sw:
        while True:
            # (cycle_cohorts' own Newton-Krylov: the map from ``base``, taken again from each
            # Newton step's state; each judged stress to NEWTON_TOL * tol, 1e-9 by default)
            out = H.newton_krylov(step, dt, base, tol, 400)
            evals += out.evals
            solves += 1
            first = first or out
            print(f"  h/{h_div:g} dt {dt}: step {step:.10f}: {out.message}", flush=True)
            if not consistent or out.state is None:
                break
            want = H.phase_step(out.row["period"], dt)
            tried.append((step, want))
            if abs(want / step - 1.0) < 1e-5 or solves >= max_solves:
                break
            # the step the fixed point's own loading phase asks for (by the secant of
            # want(step) - step after the first): solve again from this fixed point's marginal
            if len(tried) >= 2:
                (s0, w0), (s1, w1) = tried[-2:]
                f0, f1 = w0 - s0, w1 - s1
                want = s1 - f1 * (s1 - s0) / (f1 - f0) if f1 != f0 else w1
            step, base = want, out.state
    cpu = sw.seconds
    row.update(tol=tol, nk_at_default_step=first.row.get("sigma_max", np.nan),
               nk_at_default_step_error=first.error if first.errors else np.nan,
               nk_at_default_step_certified=first.certified, step=step,
               phase_step=H.phase_step(out.row["period"], dt), solves=solves,
               sigma_max=out.row["sigma_max"], sigma_min=out.row["sigma_min"], period=out.row["period"],
               sigma_before=out.row["sigma_before"], sigma_after=out.row["sigma_after"],
               residual=out.residual, error_sigma_max=out.errors.get("sigma_max", np.nan), error=out.error,
               certified=out.certified, newton_steps=len(out.history) - 1, evals=evals, cpu_s=cpu,
               cycle_cpu_s=cpu / max(evals, 1), unjumped=out.row["unjumped"], dropped_mass=float(base.dropped),
               message=out.message)
    if verify and out.state is not None:
        st = out.state.copy()
        st.period_ref = ref
        drift = 0.0
        for _ in range(verify):
            o = H.one_cycle(st, step)
            drift = max(drift, abs(o["sigma_max"] - out.row["sigma_max"]))
        row.update(verify_cycles=verify, drift=drift, verify_last=o["sigma_max"])
    if want_multipliers and out.state is not None:
        vals, used = multipliers(out.state, step, ref, out.x)
        row.update(multipliers=" ".join(f"{abs(v):.5f}" for v in vals), multiplier_cycles=used)
    row["load"] = 0.5 * (load0 + _load())
    return row, fd_rows


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--points", default="20:0.02,40:0.02,80:0.02,40:0.01",
                    help="comma-separated H:DT (cell kappa zbar / H, time step DT)")
    ap.add_argument("--k0", type=float, default=0.01)
    ap.add_argument("--fraction", type=float, default=0.9)
    ap.add_argument("--no-consistent", dest="consistent", action="store_false")
    ap.add_argument("--verify", type=int, default=20, help="plain cycles from the fixed point")
    ap.add_argument("--multipliers", action="store_true")
    ap.add_argument("--fd-check", action="store_true")
    ap.add_argument("--tol", type=float, default=1e-8, help="cycle_cohorts' tol for its Newton-Krylov (stresses "
                    "to NEWTON_TOL times it)")
    ap.add_argument("--max-solves", type=int, default=6, help="solves at most in the search for the consistent step")
    ap.add_argument("--floor", type=float, default=cohort_options.DEFAULT.CELL_FLOOR,
                    help="the cell floor, CELL_FLOOR of micro.cohort.options")
    a = ap.parse_args()
    cohort_options.DEFAULT = dataclasses.replace(cohort_options.DEFAULT, CELL_FLOOR=a.floor)
    model = micro.Model(k0=a.k0)
    V = a.fraction * micro.critical_velocity(model).Vc
    path = RESULTS / "micro_cohort_newton_krylov.csv"
    for i, point in enumerate(a.points.split(",")):
        h_div, dt = (float(s) for s in point.split(":"))
        row, fd_rows = solve_point(model, V, h_div, dt, a.consistent, a.verify, a.multipliers, a.fd_check and i == 0,
                                   a.tol, a.max_solves)
        row["V_over_Vc"] = a.fraction
        row["floor"] = f"{a.floor:g}"
        print(row, flush=True)
        if path.exists() and "floor" not in pd.read_csv(path, nrows=1).columns:
            # (rows written before the floor was an option: the default then, 1e-13)
            write_csv(pd.read_csv(path).assign(floor="1e-13"), path)
        write_csv(merged(path, pd.DataFrame([row]), ["k0", "V_over_Vc", "dt", "h_div", "consistent", "floor"]), path)
        if fd_rows:
            fd_path = RESULTS / "micro_cohort_newton_krylov_fd.csv"
            write_csv(pd.DataFrame([dict(k0=a.k0, V_over_Vc=a.fraction, dt=dt, h_div=h_div, **r) for r in fd_rows]),
                      fd_path)


if __name__ == "__main__":
    main()
