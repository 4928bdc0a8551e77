"""The cohort method's fixed point close to V^c, checked by Newton's method on the cycle map.

Close to V^c the cycle-to-cycle sequence contracts slowly (by up to 0.98 a cycle);
``micro.cohort.cycle_cohorts`` solves the fixed point by Anderson's iteration
preconditioned by the map at frozen slips (a band), and bounds the error by its last
plain cycles.  This script solves the same fixed point by Newton's method with the
whole Jacobian, by forward differences (it was written when the method rested on
Aitken's extrapolation of five cycles, which missed a slower mode).

For each point (Fig. 4 parameters, k0 and V / V^c, total shocks: k0 <= 0.01) the cohort
method is run at ``--dt``, ``--h`` to ``--tol``.  Its last cycle fixes the map: one
cycle, at the run's own step and graded-grid reference, from a product state (Exp
margins times a delta_R marginal x) to the delta_R marginal of the blocks the shock
leaves (the blocks it leaves unjumped, ``unjumped`` of the mass, dropped; the method's
own map carries them to the next cycle).  Its Jacobian on the marginal's support is taken by
forward differences (one cycle per node, step ``--fd``), its eigenvalues are the cycle's
Floquet multipliers, and Newton's iteration x <- x + (I - J)^-1 (G(x) - x) (the Jacobian
of the start, a chord method) is run until the cycle moves less than 1e-10 of the mass.
The distance of the cohort method's sigma_max and sigma_min from Newton's is the true
error of its claimed ``error``; Newton's own uncertainty is its last step's change.
Where the shocks leave more than 1e-6 of the mass unjumped (k0 = 0.01 at 0.95 V^c:
8e-5), the map that drops them has another fixed point (those blocks lag by about the
shock's slip: sigma_min moves by 8e-5), and no true error is given.
The row also gives the last plain cycle's steps and the tail that a mode of the slowest
multiplier would add to them (step * m / (1 - m)), to set against the true error.

Writes benchmarks/results/micro_cohort_newton_check.csv (rows merge by k0, V / V^c, dt,
h and tol).

    python -m studies micro_cohort_newton_check                     # about 2 minutes on 2 cores
    python -m studies micro_cohort_newton_check --dt 0.01 --h 0 --points 0.0001:0.95,0.001:0.95
                                                                       # the default resolution: ~3 minutes
"""
from __future__ import annotations

import argparse
from pathlib import Path

import numpy as np
import pandas as pd

import micro
# Newton's method needs the cohort method's cycle map itself (product_cycle), the support
# of its marginal (support), the state cycle_cohorts returns (res.state: its step,
# graded-grid reference and last marginal) and a start without the coarse first run
# (NO_COARSE): the hooks for studies; the public API gives only the fixed point
from micro import cohort as C
from micro import study_hooks as H

from benchmarks._harness import RESULTS, Stopwatch, warm_up, write_csv

POINTS = "0.0001:0.95,0.001:0.95,0.01:0.95,0.0001:0.9,0.001:0.9,0.01:0.9"
#: Newton's map drops the blocks a shock leaves unjumped (they lag by about the shock's
#: slip, ~1 at k0 = 0.01, so sigma moves by about their fraction): its fixed point is
#: compared only where they are at most this fraction.
UNJUMPED = 1e-6


def cycle_map(model: micro.Model, V: float, h: float, step: float, ref: float):
    """G(x): the method's own map (``micro.study_hooks.product_cycle``), the normalised delta_R
    marginal after one cycle from the product state with marginal x, and the cycle's row."""
    def G(x: np.ndarray) -> tuple[np.ndarray, dict]:
        _, out, g = H.product_cycle(model, V, h, step, ref, x)
        if g is None:
            raise RuntimeError(out["message"])
        return g, out
    return G


def newton(G, x: np.ndarray, fd: float, iterations: int = 8) -> dict:
    """Newton's chord iteration on G(x) = x with the forward-difference Jacobian at ``x``."""
    sw = Stopwatch()
    g, out = G(x)
    S = H.support(x, g)
    J = np.empty((S.size, S.size))
    for k, i in enumerate(S):
        xi = x.copy()
        xi[i] += fd
        gi, _ = G(xi)
        J[:, k] = (gi[S] - g[S]) / fd
    jac_s = sw.seconds
    mult = np.sort(np.abs(np.linalg.eigvals(J)))[::-1]
    A = np.eye(S.size) - J
    history = [(float(np.abs(g - x).sum()), out["sigma_max"], out["sigma_min"])]
    for _ in range(iterations):
        x = x.copy()
        x[S] += np.linalg.solve(A, (g - x)[S])
        x = np.maximum(x, 0.0)
        x /= x.sum()
        g, out = G(x)
        history.append((float(np.abs(g - x).sum()), out["sigma_max"], out["sigma_min"]))
        if history[-1][0] < 1e-10:
            break
    h = np.array(history)
    return dict(nodes=S.size, jac_s=jac_s, newton_s=sw.seconds - jac_s, iterations=len(h) - 1,
                residual=h[-1, 0], sigma_max=h[-1, 1], sigma_min=h[-1, 2],
                last_change=float(np.abs(h[-1, 1:] - h[-2, 1:]).max()), multipliers=mult,
                unjumped=out["unjumped"], residuals=h[:, 0])


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--points", default=POINTS, help="k0:V/V^c, comma separated")
    ap.add_argument("--dt", type=float, default=0.02)
    ap.add_argument("--h", type=float, default=None, help="default kappa zbar / 10; 0: the method's default")
    ap.add_argument("--tol", type=float, default=5e-5)
    ap.add_argument("--fd", type=float, default=1e-6, help="the finite-difference step, in mass")
    ap.add_argument("--out", default=str(RESULTS / "micro_cohort_newton_check.csv"))
    args = ap.parse_args()
    out = Path(args.out)
    warm_up(C.cycle_cohorts, micro.Model(k0=0.1), 0.3, tol=1e-3, max_iter=6)
    for point in args.points.split(","):
        k0, frac = (float(v) for v in point.split(":"))
        model = micro.Model(k0=k0)
        V = frac * micro.critical_velocity(model).Vc
        if args.h == 0:  # the method's default resolution, its default start (a coarse run first)
            h = model.kappa * model.zbar / 20.0
            res = C.cycle_cohorts(model, V, dt=args.dt, tol=args.tol, max_iter=2000)
        else:
            h = model.kappa * model.zbar / 10.0 if args.h is None else args.h
            res = C.cycle_cohorts(model, V, dt=args.dt, h=h, tol=args.tol, max_iter=2000, start=H.NO_COARSE)
        st = res.state
        x = st.dense(st.n - 1)
        nt = newton(cycle_map(model, V, h, st.dt, st.period_ref), x / x.sum(), args.fd)
        true = np.abs(np.array([res.sigma_max - nt["sigma_max"], res.sigma_min - nt["sigma_min"]]))
        if nt["unjumped"] > UNJUMPED:
            true[:] = np.nan
        m = nt["multipliers"]
        # the last plain cycles' steps, and the tail a mode of the slowest multiplier would add to them
        steps = np.abs(np.diff(res.history[-2:, :2], axis=0)).ravel()
        tail = steps * m[0] / (1.0 - m[0])
        row = dict(k0=k0, V_over_Vc=frac, dt=args.dt, h=h, tol=args.tol, step=st.dt, sigma_max=res.sigma_max,
                   sigma_min=res.sigma_min, claimed=res.error, converged=res.converged, cycles=res.iterations,
                   wall_s=res.wall_time, newton_sigma_max=nt["sigma_max"], newton_sigma_min=nt["sigma_min"],
                   newton_residual=nt["residual"], newton_last_change=nt["last_change"],
                   newton_iterations=nt["iterations"], nodes=nt["nodes"], jacobian_s=nt["jac_s"],
                   newton_s=nt["newton_s"], multiplier_1=m[0], multiplier_2=m[1], multiplier_3=m[2],
                   above_0_9=int((m > 0.9).sum()), above_0_5=int((m > 0.5).sum()), unjumped=nt["unjumped"],
                   true_sigma_max=true[0], true_sigma_min=true[1], true_over_claimed=float(true.max() / res.error),
                   last_step_sigma_max=steps[0], last_step_sigma_min=steps[1], slow_tail_sigma_max=tail[0],
                   slow_tail_sigma_min=tail[1],
                   message=res.message)
        print(f"k0 = {k0:g}, {frac:g} V^c (step {st.dt:.3g}): cohorts sigma_max {res.sigma_max:.7f} sigma_min "
              f"{res.sigma_min:.7f}, claimed {res.error:.1e}; Newton {nt['sigma_max']:.7f} {nt['sigma_min']:.7f} "
              f"(residuals {', '.join(f'{r:.0e}' for r in nt['residuals'])}); true error {true.max():.1e}; "
              f"(unjumped {nt['unjumped']:.0e}); multipliers {m[0]:.4f} {m[1]:.4f} {m[2]:.4f}, {row['above_0_9']} above 0.9 of {nt['nodes']}; "
              f"Jacobian {nt['jac_s']:.0f} s; last steps {steps[0]:.1e} {steps[1]:.1e}, slow tails {tail[0]:.1e} "
              f"{tail[1]:.1e} against true {true[0]:.1e} {true[1]:.1e}", flush=True)
        write_csv(pd.DataFrame([row]), out, keys=["k0", "V_over_Vc", "dt", "h", "tol"])


if __name__ == "__main__":
    main()
