"""The critical velocity V^c of the Fokker-Planck solver against the bin eps.

V^c comes from `micro.critical_velocity`, the paper's bisection on the regime (1 %).
Near V^c the finite-eps dynamics is a noisy oscillation a few grid resolutions (k0 eps)
wide, so the regime labels there, and the bisection, depend on eps; this script measures
by how much, and whether V^c settles as eps shrinks.  Each bisection starts from the same
guess (the RS V^c of Eq. (12) with the paper's A, B, D_c).  With ``--refine yes`` (the
default of `critical_velocity`) an oscillation smaller than 2 eps is rerun at eps / 2 and
counts as stick-slip only if it keeps its amplitude; ``no`` is the rule without that check
(a cycle without global shocks below min(10 k0 eps, 2 eps) counts as steady).  The
independent check is `micro_fp_vs_nblock_hopf_amplitude.py` (cycle amplitudes of both solvers against V).

Writes benchmarks/results/micro_fp_vc_convergence.csv.

    python -m studies micro_fp_vc_convergence                      # k0 = 0.1, three bins
    python -m studies micro_fp_vc_convergence --k0 0.3 --eps 0.016,0.008
    python -m studies micro_fp_vc_convergence --k0 0.1,0.3 --eps 0.024,0.016 --refine both
"""
from __future__ import annotations

import argparse

import pandas as pd

import micro
from benchmarks._harness import RESULTS, VC_RS, Stopwatch, warm_up, write_csv



def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--k0", type=str, default="0.1", help="comma-separated k0 values (0.3, 0.1, 0.01)")
    ap.add_argument("--eps", type=str, default="0.016,0.012,0.008", help="comma-separated bins")
    ap.add_argument("--refine", choices=("yes", "no", "both"), default="yes",
                    help="check oscillations smaller than 2 eps at eps / 2 (critical_velocity's refine)")
    args = ap.parse_args()
    warm_up(micro.stationary, micro.Model(k0=0.1), 2.0, numerics=micro.Numerics(eps=0.024), method="fp")
    out = RESULTS / "micro_fp_vc_convergence.csv"
    refines = {"yes": (True,), "no": (False,), "both": (False, True)}[args.refine]
    rows = []
    for k0 in (float(k) for k in args.k0.split(",")):
        model = micro.Model(k0=k0)
        for eps, refine in ((float(e), r) for e in args.eps.split(",") for r in refines):
            sw = Stopwatch()
            crit = micro.critical_velocity(model, V_guess=VC_RS[k0], factor=1.5, numerics=micro.Numerics(eps=eps),
                                           refine=refine, method="fp")
            evals = pd.DataFrame(crit.evaluations)
            unconverged = int((~evals.converged.astype(bool)).sum())
            grid_cycles = int(((evals.regime == "stick-slip") & (evals.label == "steady")).sum())
            checked = int(evals.amplitude_fine.notna().sum())
            rows.append(dict(crit.to_dict(), eps=eps, refine=int(refine), evaluations=len(evals),
                             unconverged=unconverged, grid_cycles=grid_cycles, checked_at_half_eps=checked,
                             wall_s=sw.seconds))
            print(evals[["V", "regime", "label", "started_from", "sigma_max", "sigma_min", "amplitude",
                         "amplitude_fine", "converged", "t_end", "wall_time", "wall_time_fine"]].to_string(index=False),
                  flush=True)
            print(f"k0 = {k0:g}, eps = {eps:g}, refine = {refine}: Vc = {crit.Vc:.4f} [{crit.V_low:.4f}, "
                  f"{crit.V_high:.4f}] ({crit.status}; {len(evals)} runs, {unconverged} unconverged, {checked} "
                  f"checked at eps / 2, {grid_cycles} cycles taken for the grid's; {rows[-1]['wall_s']:.0f} s)",
                  flush=True)
            write_csv(pd.DataFrame(rows[-1:]), out, keys=["k0", "eps", "refine"])
    print(pd.read_csv(out).to_string(index=False))


if __name__ == "__main__":
    main()
