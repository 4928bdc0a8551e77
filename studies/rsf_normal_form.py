"""RS's transition at V^c: the normal forms against rsf's own limit cycles (issue 36, item 3).

Parts (one CSV, benchmarks/results/rsf_normal_form.csv, column ``part``):

* ``verdict``: rsf.hopf_normal_form for the laws and state laws of rsf (kind, l1, c).
* ``hopf`` (a > 0): the simulated amplitude sigma_max - sigma_min over c d^(1/2), c from
  the first Lyapunov coefficient (rsf.hopf_normal_form), at d = 1e-3 ... 1e-7, for Eq. (10)
  with a = 1e-3 (aging and slip law, k0 = 0.1) and for the classical log law with radiation
  damping (aging and slip; a = 0.005, b = 0.01, Dc = 10, k0 = 0.8 k_c, eta = 1e-3).  The
  cycles come from rsf.cycle_near_hopf (the section map's fixed point by the secant method
  on rsf.simulate, confirmed by rsf.limit_cycle), CVODE rtol 1e-14.
* ``above``: the damped slip law at 1.001 and 1.01 V^c from small and large perturbations
  (a subcritical bifurcation would let some of them reach a cycle).
* ``stick-slip`` (a = 0, Eq. 10, k0 = 0.3 ... 1e-3): rsf.limit_cycle's amplitude against the
  exact two-equation reduction of the return map and against c0 d^(1/2) (1 + c2 d)
  (rsf.stick_slip_normal_form), d = 1e-1 ... 1e-8.
* ``crossover`` (Eq. 10, aging, k0 = 0.1, a = 1e-4 and 1e-5): amplitude / (c0 d^(1/2)) and
  / (c d^(1/2)) from d = 0.3 down to 1e-6: the Hopf law holds below d ~ a/K, the a = 0 law
  above it.
* ``spectrum`` (k0 = 0.1, a = 1e-2 ... 1e-5 and 0): the unstable mode of steady sliding
  against d (rsf.transition_spectrum).
* ``classification``: the test of compare.fits.classify_transition (rsf.classify_spectrum)
  on each spectrum, with the born cycle's period over micro's range of d (0.02 - 0.3) and
  close to V^c (1e-5 - 1e-3).

    python -m studies rsf_normal_form [--quick]

(about 70 s on this 2-core machine under load; --quick: fewer points, about 40 s).
"""
from __future__ import annotations

import argparse
import math
import os
import sys

import numpy as np
import pandas as pd

sys.path.insert(0, os.path.dirname(os.path.dirname(os.path.abspath(__file__))))  # the repository

import rsf  # noqa: E402
from benchmarks._harness import RESULTS, Stopwatch, timed, warm_up, write_csv  # noqa: E402

OUT = RESULTS / "rsf_normal_form.csv"
TIGHT = rsf.SolverOptions(cycle_rtol=1e-11, rtol=1e-14, atol=1e-16)
A0_OPTIONS = rsf.SolverOptions(cycle_rtol=1e-12, rtol=1e-12, atol=1e-14)
B_LOG, DC_LOG, A_LOG = 0.01, 10.0, 0.005


def verdict_cases() -> list[tuple[str, rsf.SpringSlider, dict]]:
    kc = (B_LOG - A_LOG) / DC_LOG
    log = dict(mu0=0.6, a=A_LOG, b=B_LOG, Dc=DC_LOG, k0=0.8 * kc, v0=1.0)
    cases = [(f"Eq. 10, k0 = 0.1, {sl}, a = {a:g}", rsf.SpringSlider(k0=0.1, a=a, state_law=sl), {})
             for sl in ("aging", "slip", "prz") for a in (1e-2, 1e-3, 1e-5)]
    cases += [(f"Eq. 4, k0 = 0.01, {sl}, a = 1e-3",
               rsf.SpringSlider(law=rsf.ViscoelasticLaw(), k0=0.01, a=1e-3, state_law=sl), {})
              for sl in ("aging", "slip", "prz")]
    cases += [("Eq. 10, k0 = 0.1, Nagata c = 0.5 (b = 0.01), a = 1e-3",
               rsf.SpringSlider(k0=0.1, a=1e-3, state_law=rsf.NagataLaw(c=0.5, b=0.01)), {}),
              ("Eq. 10, k0 = 0.1, aging, a = 1e-3, eta = 1e-3", rsf.SpringSlider(k0=0.1, a=1e-3, eta_rad=1e-3), {})]
    cases += [(f"log law, {sl}, no damping (k0 varies, V = 1)", rsf.standard_rs(**log, state_law=sl),
               dict(parameter="k0", V=1.0)) for sl in ("aging", "slip", "prz")]
    cases += [(f"log law, {sl}, eta = 1e-3", rsf.standard_rs(**log, eta_rad=1e-3, state_law=sl), {})
              for sl in ("aging", "slip", "prz")]
    cases += [("log law, aging, eta = 1e-4, second state b2 = 0.004, Dc2 = 50, k0 = 4e-4",
               rsf.standard_rs(mu0=0.6, a=A_LOG, b=B_LOG, Dc=DC_LOG, k0=4e-4, v0=1.0, eta_rad=1e-4,
                               second_state=rsf.SecondState(0.004, 50.0)), {})]
    return cases


def part_verdicts() -> list[dict]:
    rows = []
    print("Hopf normal forms (rsf.hopf_normal_form): critical V (or k0), omega, l1, kind, c")
    for name, model, kw in verdict_cases():
        h = rsf.hopf_normal_form(model, **kw)
        crit = h.Vc if h.parameter == "V" else h.k0c
        print(f"  {name:<72} {h.parameter}c = {crit:<9.6g} omega = {h.omega:<8.4g} l1 = {h.l1:<11.4e} "
              f"{h.kind:<13} c = {h.prefactor:<9.5g} ({h.method})")
        rows.append({"part": "verdict", "case": name, "law": h.law, "state_law": h.state_law, "k0": model.k0,
                     "a": model.a, "eta_rad": model.eta_rad, "Vc": h.Vc, "k0c": h.k0c, "omega": h.omega,
                     "l1": h.l1, "l1_error": h.l1_error, "kind": h.kind, "prefactor": h.prefactor,
                     "method": h.method})
    return rows


def hopf_cases() -> dict[str, rsf.SpringSlider]:
    kc = (B_LOG - A_LOG) / DC_LOG
    log = dict(mu0=0.6, a=A_LOG, b=B_LOG, Dc=DC_LOG, k0=0.8 * kc, v0=1.0, eta_rad=1e-3)
    return {
        "Eq. 10, aging, a = 1e-3": rsf.SpringSlider(k0=0.1, a=1e-3),
        "Eq. 10, slip, a = 1e-3": rsf.SpringSlider(k0=0.1, a=1e-3, state_law="slip"),
        "log law, aging, eta = 1e-3": rsf.standard_rs(**log),
        "log law, slip, eta = 1e-3": rsf.standard_rs(**log, state_law="slip"),
    }


def near_cycle(model: rsf.SpringSlider, V: float, options: rsf.SolverOptions) -> rsf.CycleResult:
    """rsf.cycle_near_hopf, or rsf.limit_cycle where that does not converge."""
    try:
        r = rsf.cycle_near_hopf(model, V, options=options)
        if r.converged:
            return r
    except RuntimeError:
        pass
    return rsf.limit_cycle(model, V, options=options)


def part_hopf(ds) -> list[dict]:
    rows = []
    for name, model in hopf_cases().items():
        nf = rsf.hopf_normal_form(model)
        print(f"\n{name}: Vc = {nf.Vc:.10g}, omega = {nf.omega:.6g}, l1 = {nf.l1:.6e} ({nf.kind}, "
              f"{nf.method}), c = {nf.prefactor:.8g}")
        print(f"{'d':>8} {'amplitude':>16} {'amp/(c d^1/2)':>15} {'period':>10} {'cycles':>6} {'s':>6}")
        for d in ds:
            r, t = timed(near_cycle, model, nf.Vc * (1.0 - d), TIGHT)
            amp = r.sigma_max - r.sigma_min
            ratio = amp / (nf.prefactor * math.sqrt(d))
            print(f"{d:>8.0e} {amp:>16.10e} {ratio:>15.9f} {r.period:>10.6g} {r.n_cycles:>6d} {t:>6.2f}"
                  + ("" if r.converged else "  NOT CONVERGED"))
            rows.append({"part": "hopf", "case": name, "law": nf.law, "state_law": nf.state_law,
                         "k0": model.k0, "a": model.a, "eta_rad": model.eta_rad, "Vc": nf.Vc,
                         "l1": nf.l1, "kind": nf.kind, "prefactor": nf.prefactor, "omega": nf.omega,
                         "d": d, "V": r.V, "amplitude": amp, "ratio": ratio, "period": r.period,
                         "converged": r.converged, "n_cycles": r.n_cycles, "seconds": t})
    return rows


def part_above(factors, perturbations) -> list[dict]:
    """The damped slip law just above V^c: does any start reach a cycle (subcritical)?"""
    rows = []
    model = hopf_cases()["log law, slip, eta = 1e-3"]
    Vc = rsf.critical_velocity(model).Vc
    print("\nlog law, slip, eta = 1e-3, above V^c: rsf.limit_cycle from theta perturbed (max 3000 cycles)")
    for f in factors:
        for pert in perturbations:
            r = rsf.limit_cycle(model, f * Vc, initial=rsf.InitialState(perturbation=pert),
                                options=rsf.SolverOptions(max_cycles=3000))
            amp = r.sigma_max - r.sigma_min
            print(f"  V = {f:g} Vc, perturbation {pert:g}: {r.regime} ({r.n_cycles} cycles; amplitude "
                  f"{amp:.3g}, last relative change {r.relative_change:.2g})")
            rows.append({"part": "above", "case": "log law, slip, eta = 1e-3", "law": "log", "state_law": "slip",
                         "k0": model.k0, "a": model.a, "eta_rad": model.eta_rad, "Vc": Vc, "d": 1.0 - f,
                         "V": f * Vc, "perturbation": pert, "regime": r.regime, "amplitude": amp,
                         "relative_change": r.relative_change, "n_cycles": r.n_cycles,
                         "converged": r.converged})
    return rows


def part_stick_slip(k0s, ds) -> list[dict]:
    rows = []
    print("\na = 0 (Eq. 10): rsf.limit_cycle against the exact reduction and c0 d^1/2 (1 + c2 d)")
    for k0 in k0s:
        model = rsf.SpringSlider(k0=k0)
        nf = rsf.stick_slip_normal_form(model)
        print(f"k0 = {k0:g}: Vc = {nf.Vc:.10g}, c0 = {nf.prefactor:.10g}, c2 = {nf.correction:.6g}")
        print(f"{'d':>8} {'amplitude':>18} {'sim/exact - 1':>14} {'amp/(c0 d^1/2)':>15} "
              f"{'amp/(c0 d^1/2 (1+c2 d))':>24} {'period':>12}")
        for d in ds:
            V = nf.Vc * (1.0 - d)
            r = rsf.limit_cycle(model, V, options=A0_OPTIONS)
            amp = r.sigma_max - r.sigma_min
            try:
                ex = nf.cycle(V)["amplitude"]
            except RuntimeError:
                ex = math.nan
            lead = amp / (nf.prefactor * math.sqrt(d))
            second = amp / float(nf.amplitude(d))
            print(f"{d:>8.0e} {amp:>18.12e} {amp / ex - 1:>14.1e} {lead:>15.9f} {second:>24.9f} {r.period:>12.6g}")
            rows.append({"part": "stick-slip", "case": f"Eq. 10, a = 0, k0 = {k0:g}", "law": "hyperbolic",
                         "state_law": "aging", "k0": k0, "a": 0.0, "eta_rad": 0.0, "Vc": nf.Vc,
                         "prefactor": nf.prefactor, "correction": nf.correction, "d": d, "V": V,
                         "amplitude": amp, "amplitude_exact": ex, "ratio": lead, "ratio_2": second,
                         "period": r.period, "converged": r.converged, "n_cycles": r.n_cycles})
    return rows


def part_crossover(a_values, ds) -> list[dict]:
    rows = []
    print("\nCrossover (Eq. 10, aging, k0 = 0.1): amplitude / (c0 d^1/2) [a = 0 law] and / (c d^1/2) [Hopf]")
    for a in a_values:
        model = rsf.SpringSlider(k0=0.1, a=a)
        hopf = rsf.hopf_normal_form(model)
        ss = rsf.stick_slip_normal_form(model)
        print(f"a = {a:g}: c = {hopf.prefactor:.8g}, c0 = {ss.prefactor:.8g}, c/c0 = "
              f"{hopf.prefactor / ss.prefactor:.6f} (2/sqrt(3) (1 + a/K)^1/2 = "
              f"{2 / math.sqrt(3) * math.sqrt(1 + a / model.K):.6f})")
        for d in ds:
            V = hopf.Vc * (1.0 - d)
            if d < 1e-3:
                r = near_cycle(model, V, TIGHT)
            else:
                r = rsf.limit_cycle(model, V, options=rsf.SolverOptions(cycle_rtol=1e-10, rtol=1e-12, atol=1e-14))
            amp = r.sigma_max - r.sigma_min
            print(f"  d = {d:>7.0e}: amp/(c0 d^1/2) = {amp / (ss.prefactor * math.sqrt(d)):.6f}, "
                  f"amp/(c d^1/2) = {amp / (hopf.prefactor * math.sqrt(d)):.6f}, period = {r.period:.6g}"
                  + ("" if r.converged else "  NOT CONVERGED"))
            rows.append({"part": "crossover", "case": f"Eq. 10, aging, a = {a:g}", "law": "hyperbolic",
                         "state_law": "aging", "k0": 0.1, "a": a, "eta_rad": 0.0, "Vc": hopf.Vc,
                         "prefactor": hopf.prefactor, "prefactor_a0": ss.prefactor, "d": d, "V": V,
                         "amplitude": amp, "ratio": amp / (hopf.prefactor * math.sqrt(d)),
                         "ratio_a0": amp / (ss.prefactor * math.sqrt(d)), "period": r.period,
                         "converged": r.converged, "n_cycles": r.n_cycles})
    return rows


def periods(model: rsf.SpringSlider, ds) -> pd.DataFrame:
    out = []
    for d in ds:
        if model.a == 0.0:
            nf = rsf.stick_slip_normal_form(model)
            out.append({"d": d, "period": nf.cycle(nf.Vc * (1.0 - d))["period"]})
            continue
        Vc = rsf.critical_velocity(model).Vc
        V = Vc * (1.0 - d)
        r = near_cycle(model, V, TIGHT) if d < 1e-3 else rsf.limit_cycle(model, V)
        out.append({"d": d, "period": r.period if r.converged else math.nan})
    return pd.DataFrame(out)


def part_spectrum(a_values, ds) -> list[dict]:
    rows = []
    print("\nThe one test (k0 = 0.1): growth rate of the unstable mode against d, and the verdict")
    try:
        from compare import classify_transition
    except ImportError:          # compare is being restructured: the same test is in rsf
        classify_transition = None
    ranges = {"0.02-0.3": [0.02, 0.05, 0.1, 0.2, 0.3], "1e-5-1e-3": [1e-5, 1e-4, 1e-3]}
    for a in a_values:
        model = rsf.SpringSlider(k0=0.1, a=a)
        sp = rsf.transition_spectrum(model, ds)
        for _, row in sp.iterrows():
            rows.append({"part": "spectrum", "case": f"Eq. 10, aging, a = {a:g}", "law": "hyperbolic",
                         "state_law": "aging", "k0": 0.1, "a": a, "d": row.d, "V": row.V,
                         "growth_rate": row.growth_rate, "frequency": row.frequency,
                         "other_rate": row.other_rate, "fast_rate": row.fast_rate,
                         "growth_rate_tau": row.growth_rate_tau, "frequency_tau": row.frequency_tau})
        print(f"a = {a:g}: growth rate / |Im| of the unstable mode (1/time): "
              + ", ".join(f"d = {r.d:.0e}: {r.growth_rate:.4g} / {r.frequency:.4g}" for r in sp.itertuples()))
        near = sp.iloc[int(np.argmin(sp.d))]
        print(f"   in units of V/Dc at d = {near.d:g}: Re {near.growth_rate_tau:.4g}, Im {near.frequency_tau:.4g}")
        for label, dd in ranges.items():
            per = periods(model, dd)
            verdict = rsf.classify_spectrum(sp, per)
            same = math.nan
            if classify_transition is not None:      # compare's own function on RS's numbers
                pts = per.assign(model="micro", method="N-block", regime="stick-slip", resolution=1.0)
                ref = classify_transition(sp, pd.DataFrame(), pts)
                same = float(ref["hopf"] == verdict["hopf"])
            print(f"   periods over d = {label}: exponent {verdict.get('period_exponent', math.nan):.3f} "
                  f"(periods {per.period.min():.4g} - {per.period.max():.4g}) -> "
                  f"{'Hopf' if verdict['hopf'] else 'not Hopf'}"
                  + ("" if math.isnan(same) else f" (compare.fits.classify_transition agrees: {bool(same)})"))
            rows.append({"part": "classification", "case": f"Eq. 10, aging, a = {a:g}", "law": "hyperbolic",
                         "state_law": "aging", "k0": 0.1, "a": a, "period_range": label,
                         "d_near": verdict["d_near"], "growth_near": verdict["growth_near"],
                         "d_far": verdict["d_far"], "growth_far": verdict["growth_far"],
                         "frequency": verdict.get("frequency_near", math.nan),
                         "growth_diverges": verdict["growth_diverges"],
                         "period_exponent": verdict.get("period_exponent", math.nan),
                         "hopf": verdict["hopf"], "compare_agrees": same})
    return rows


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--quick", action="store_true", help="fewer points (about 1 minute)")
    args = parser.parse_args()
    sw = Stopwatch()
    if args.quick:
        hopf_ds, a0_k0, a0_ds, cross_a, cross_ds = [1e-3, 1e-4, 1e-5, 1e-6], [0.1], \
            [1e-2, 1e-4, 1e-6], [1e-5], [0.1, 1e-2, 1e-3, 1e-4]
    else:
        hopf_ds, a0_k0, a0_ds = [1e-3, 1e-4, 1e-5, 1e-6, 1e-7], [0.3, 0.1, 0.01, 0.001], \
            [1e-1, 1e-2, 1e-3, 1e-4, 1e-5, 1e-6, 1e-7, 1e-8]
        cross_a, cross_ds = [1e-4, 1e-5], [0.3, 0.1, 0.03, 1e-2, 3e-3, 1e-3, 1e-4, 1e-5, 1e-6]
    warm_up(rsf.limit_cycle, rsf.SpringSlider(k0=0.1, a=1e-3), 0.5)
    rows = part_verdicts()
    rows += part_hopf(hopf_ds)
    rows += part_above([1.001, 1.01], [1e-3, 0.3, 3.0, 30.0] if not args.quick else [0.3])
    rows += part_stick_slip(a0_k0, a0_ds)
    rows += part_crossover(cross_a, cross_ds)
    rows += part_spectrum([1e-2, 1e-3, 1e-4, 1e-5, 0.0], [1e-6, 1e-5, 1e-4, 1e-3, 1e-2, 0.1, 0.5])
    write_csv(rows, OUT)
    print(f"\nwrote {OUT} ({len(rows)} rows) in {sw.seconds:.0f} s")


if __name__ == "__main__":
    main()
