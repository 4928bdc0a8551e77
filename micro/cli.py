"""Command line: ``python -m micro steady|sweep|critical|run``.

Defaults are the paper's Fig. 4 parameters (k1 = 0.1, k2 = 0.9, zbar = 0.1, exponential
pinning distances with cutoff 10, eta_u = 1, f_th = 1).  The default bin eps is
kappa*zbar/50 (2e-3 for these parameters); its error on a stationary stress is about
1e-4 (second order in eps, see docs/micro_numerics.md), coarser bins run much faster.
"""
from __future__ import annotations

import argparse
import logging
import sys
import time

import pandas as pd

from .params import Deterministic, Exponential, Model
from .protocols import Drive
from .renewal import steady_sliding
from .solver import Convergence, Numerics, critical_velocity, default_eps, simulate, stationary

log = logging.getLogger("micro")


def _floats(text: str, name: str) -> list[float]:
    try:
        values = [float(v) for v in text.split(",") if v.strip()]
    except ValueError:
        raise argparse.ArgumentTypeError(f"--{name} must be comma-separated numbers, got {text!r}") from None
    if not values:
        raise argparse.ArgumentTypeError(f"--{name} needs at least one value")
    return values


def _schedule(text: str) -> Drive:
    """``V1:T1,V2:T2,...``: drive at V1 for T1, then V2 for T2, ..."""
    segments = []
    for part in text.split(","):
        try:
            v, d = part.split(":")
            segments.append((float(d), float(v)))
        except ValueError:
            raise argparse.ArgumentTypeError(f"--schedule must look like V1:T1,V2:T2, got {text!r}") from None
    return Drive.schedule(segments)


def _model_options(p: argparse.ArgumentParser, *, k0_list: bool = False) -> None:
    g = p.add_argument_group("model (defaults: the paper's Fig. 4)")
    if k0_list:
        g.add_argument("--k0", required=True, help="driving-spring stiffness(es), > 0; comma-separated for several")
    else:
        g.add_argument("--k0", type=float, required=True, help="driving-spring stiffness, > 0")
    g.add_argument("--k1", type=float, default=0.1, help="elastic coupling, >= 0 (default 0.1)")
    g.add_argument("--k2", type=float, default=0.9, help="viscoelastic coupling, >= 0 (default 0.9)")
    g.add_argument("--zbar", type=float, default=0.1, help="mean pinning distance, > 0 (default 0.1)")
    g.add_argument("--dist", choices=("exp", "delta"), default="exp",
                   help="pinning distances: exponential with cutoff 10 (default) or all equal to zbar")
    g.add_argument("--eta-u", type=float, default=1.0, help="dashpot viscosity, > 0 (default 1)")
    g.add_argument("--f-th", type=float, default=1.0, help="pinning threshold, > 0 (default 1)")
    n = p.add_argument_group("numerics")
    n.add_argument("--eps", type=float, default=None,
                   help="bin width of delta_F and delta_R (default kappa*zbar/50; error ~ (eps/0.004)^2 * 1.4e-4 on a steady stress)")
    n.add_argument("--rtol", type=float, default=1e-2,
                   help="convergence: relative agreement of 3 cycles / stress means (default 1e-2, the paper's)")
    n.add_argument("--t-max", type=float, default=None, help="longest simulated time (default from the model's time scales)")


def _model(args, k0: float) -> Model:
    jumps = Exponential(args.zbar, 10.0) if args.dist == "exp" else Deterministic(args.zbar)
    return Model(k0=k0, k1=args.k1, k2=args.k2, eta_u=args.eta_u, f_th=args.f_th, jumps=jumps)


def _numerics(args) -> tuple[Numerics, Convergence]:
    return Numerics(eps=args.eps), Convergence(rtol=args.rtol, t_max=args.t_max)


def build_parser() -> argparse.ArgumentParser:
    p = argparse.ArgumentParser(
        prog="python -m micro",
        description="Mean-field viscoelastic friction model (Landes, Rosso & Jagla 2015) solved as a "
                    "Fokker-Planck equation for P(delta_F, delta_R) at finite driving velocity.",
    )
    p.add_argument("-v", "--verbose", action="store_true", help="log progress to stderr")
    sub = p.add_subparsers(dest="command", required=True)

    st = sub.add_parser("steady", help="steady sliding from the renewal chain (either branch): one CSV row per V, "
                                       "milliseconds each")
    _model_options(st)
    st.add_argument("--V", required=True, help="drive velocities, comma-separated, each in [1e-6, 1e7]")
    st.add_argument("--no-growth-rate", dest="growth_rate", action="store_false",
                    help="skip the growth rate of the unstable mode (about 0.03 s per unstable V)")
    st.add_argument("--out", required=True,
                    help="output CSV: k0,k1,k2,zbar,V,sigma,branching_ratio,stable,growth_rate,sigma_error,converged")

    s = sub.add_parser("sweep", help="stationary state for each drive velocity: one CSV row per V")
    _model_options(s)
    s.add_argument("--V", required=True, help="drive velocities, comma-separated, each > 0")
    s.add_argument("--out", required=True, help="output CSV: k0,k1,k2,zbar,V,regime,sigma_max,sigma_min,sigma_mean,...")

    c = sub.add_parser("critical", help="critical velocity Vc: where the branching ratio of steady sliding reaches 1 "
                                        "(--method fp: bisection on Fokker-Planck runs, the paper's Appendix B)")
    _model_options(c, k0_list=True)
    c.add_argument("--method", choices=("renewal", "fp"), default="renewal",
                   help="renewal (default): the direct solution, ~1e-10 relative in < 1 s; fp: bisection on "
                        "Fokker-Planck runs (minutes, uncertain by the bin)")
    c.add_argument("--V-min", type=float, default=1e-4, help="lower end of the bracket (default 1e-4)")
    c.add_argument("--V-max", type=float, default=None,
                   help="upper end of the bracket (default 1e7 with --method renewal, 1e3 with fp)")
    c.add_argument("--rel-tol", type=float, default=1e-2, help="stop when V_high/V_low - 1 <= this (default 1e-2)")
    c.add_argument("--no-refine", dest="refine", action="store_false",
                   help="decide oscillations smaller than 2 eps by their size and global shocks instead of "
                        "rerunning them at eps/2 (several times faster near Vc, but Vc then carries the "
                        "grid's error: k0=0.1, eps=0.016: 0.90 against 0.73)")
    c.add_argument("--out", required=True, help="output CSV: k0,k1,k2,zbar,Vc,V_low,V_high,status")

    r = sub.add_parser("run", help="stress time series of one protocol: columns t,w,sigma")
    _model_options(r)
    drive = r.add_mutually_exclusive_group(required=True)
    drive.add_argument("--V", type=float, help="constant drive velocity (with --duration)")
    drive.add_argument("--schedule", help="piecewise drive V1:T1,V2:T2,... (velocity:duration, V >= 0)")
    drive.add_argument("--shs", nargs=4, type=float, metavar=("V", "SLIDE", "HOLD", "RESUME"),
                       help="slide-hold-slide: drive at V for SLIDE, hold for HOLD, resume for RESUME")
    r.add_argument("--duration", type=float, help="run length for --V")
    r.add_argument("--out", required=True, help="output CSV: t,w,sigma (plus window min/max/mean)")
    return p


def main(argv: list[str] | None = None) -> int:
    parser = build_parser()
    args = parser.parse_args(argv)
    logging.basicConfig(level=logging.INFO if args.verbose else logging.WARNING, format="%(name)s: %(message)s")
    try:
        return _run(args)
    except (ValueError, argparse.ArgumentTypeError) as exc:
        print(f"error: {exc}", file=sys.stderr)
        return 2


def _run(args) -> int:
    start = time.perf_counter()
    if args.command == "steady":
        velocities = _floats(args.V, "V")
        model = _model(args, args.k0)
        res = steady_sliding(model, velocities, growth_rate=args.growth_rate)
        frame = res.to_frame()
        frame.to_csv(args.out, index=False)
        print(f"wrote {len(frame)} rows to {args.out} in {time.perf_counter() - start:.2f} s"
              f"{'' if frame.converged.all() else ' (' + res.message + ')'}", file=sys.stderr)
        return 0 if frame.converged.all() else 3
    if args.command == "sweep":
        velocities = _floats(args.V, "V")
        model = _model(args, args.k0)
        numerics, convergence = _numerics(args)
        rows = []
        for V in velocities:
            res = stationary(model, V, numerics=numerics, convergence=convergence)
            rows.append(res.to_dict())
            print(f"V={V:g}: {res.regime}, sigma_max={res.sigma_max:.6f}, sigma_min={res.sigma_min:.6f}"
                  f"{'' if res.converged else ' (NOT converged: ' + res.message + ')'}", file=sys.stderr)
        frame = pd.DataFrame(rows)
        frame.to_csv(args.out, index=False)
        print(f"wrote {len(frame)} rows to {args.out} in {time.perf_counter() - start:.1f} s", file=sys.stderr)
        return 0 if frame.converged.all() else 3
    if args.command == "critical":
        rows = []
        for k0 in _floats(args.k0, "k0"):
            model = _model(args, k0)
            numerics, convergence = _numerics(args)
            crit = critical_velocity(model, V_min=args.V_min, V_max=args.V_max, rel_tol=args.rel_tol,
                                     numerics=numerics, convergence=convergence, refine=args.refine,
                                     method=args.method)
            rows.append(crit.to_dict())
            print(f"k0={k0:g}: Vc={crit.Vc:.6g} ({crit.status})", file=sys.stderr)
        pd.DataFrame(rows).to_csv(args.out, index=False)
        print(f"wrote {len(rows)} rows to {args.out} in {time.perf_counter() - start:.1f} s", file=sys.stderr)
        return 0
    # run
    model = _model(args, args.k0)
    numerics, _ = _numerics(args)
    if args.V is not None:
        if args.duration is None:
            raise ValueError("--duration is required with --V")
        drive = Drive.uniform(args.V, args.duration)
    elif args.schedule is not None:
        drive = _schedule(args.schedule)
    else:
        v, slide, hold, resume = args.shs
        drive = Drive.slide_hold_slide(v, slide, hold, resume)
    run = simulate(model, drive, numerics=numerics)
    run.records.to_csv(args.out, index=False)
    eps = numerics.eps if numerics.eps is not None else default_eps(model)
    print(f"wrote {len(run.records)} rows to {args.out} (eps={eps:g}) in {time.perf_counter() - start:.1f} s",
          file=sys.stderr)
    return 0


if __name__ == "__main__":  # pragma: no cover
    raise SystemExit(main())
