"""Command line: ``python -m micro steady|sweep|critical|run``.

Defaults are the paper's Fig. 4 parameters (k1 = 0.1, k2 = 0.9, zbar = 0.1, exponential
pinning distances with cutoff 10, eta_u = 1, f_th = 1).  The default bin eps is
kappa*zbar/50 (2e-3 for these parameters); its error on a stationary stress is about
1e-4 (second order in eps, see docs/reference/micro_numerics.md), coarser bins run much faster.
"""
from __future__ import annotations

import argparse
import contextlib
import logging
import math
import os
import sys
import tempfile
import time
from pathlib import Path

import pandas as pd

from .params import Deterministic, Exponential, Model
from .protocols import Drive
from .renewal import steady_sliding
from .solver import Convergence, Numerics, critical_velocity, default_eps, simulate, stationary

log = logging.getLogger("micro")


#: Largest drive velocity and stiffness the commands accept (V^c ~ 0.08/k0 reaches 1e7 at
#: k0 ~ 1e-8; beyond these the stresses lose every significant digit).
V_RANGE = (1e-6, 1e7)
K0_MAX = 1e3
#: Longest simulated time a command accepts (as rsf's t_end): 1e8 relaxation times.
T_MAX = 1e8


def _floats(text: str, name: str, low: float, high: float) -> list[float]:
    """Every item of a comma-separated list, each finite and in [low, high], or one error
    naming the option and the item."""
    items = text.split(",")
    values = []
    for i, item in enumerate(items):
        try:
            v = float(item)
        except ValueError:
            raise ValueError(f"--{name} item {i + 1} of {len(items)} must be a number, got {item.strip()!r}") from None
        if not (math.isfinite(v) and low <= v <= high):
            raise ValueError(f"--{name} item {i + 1} must be in [{low:g}, {high:g}], got {item.strip()!r}")
        values.append(v)
    return values


def _check_out(path: str, option: str = "--out") -> Path:
    """The CSV can be written there: fail now, not after the computation.  A symbolic link
    is checked (and later written) at its target."""
    if not path.strip():
        raise ValueError(f"{option} must name a CSV file, got {path!r}")
    out = Path(path)
    if out.is_dir():
        raise ValueError(f"{option} {path!r} is a directory; give a file name")
    parent = Path(os.path.realpath(path)).parent
    if not parent.is_dir():
        raise ValueError(f"{option} {path!r}: the directory {str(parent)!r} does not exist")
    try:
        fd, probe = tempfile.mkstemp(dir=parent, prefix=f".{out.name}.", suffix=".tmp")
        os.close(fd)
        os.unlink(probe)
    except OSError as exc:
        raise ValueError(f"{option} {path!r}: cannot write in {str(parent)!r} ({exc.strerror})") from None
    return out


def _write_csv(frame: pd.DataFrame, out: Path) -> None:
    """Atomically: a temporary file beside ``out``, renamed over it once complete, and left
    as a plain write would leave it: a new file gets ``0o666 & ~umask`` (mkstemp creates
    0600), an existing file keeps its mode, and a symbolic link stays a link (its target
    gets the data).

    The same logic is ``rsf.results.write_atomically`` (which compare uses); micro keeps
    this copy because micro and rsf are independent packages and neither imports the other.
    """
    import stat

    target = Path(os.path.realpath(out))
    try:
        mode = stat.S_IMODE(os.stat(target).st_mode)
    except FileNotFoundError:
        mask = os.umask(0o022)      # read the umask (only possible by setting it) ...
        os.umask(mask)              # ... and put it back at once
        mode = 0o666 & ~mask
    fd, tmp = tempfile.mkstemp(dir=target.parent, prefix=f".{target.name}.", suffix=".tmp")
    try:
        with os.fdopen(fd, "w", newline="") as f:
            frame.to_csv(f, index=False)
        os.chmod(tmp, mode)
        os.replace(tmp, target)
    except BaseException:
        with contextlib.suppress(OSError):
            os.unlink(tmp)
        raise


def _bounded(value: float, name: str, low: float, high: float, *, open_low: bool = False) -> float:
    """``value`` finite and in [low, high] (``(low, high]`` with ``open_low``), or one error
    naming the option."""
    ok = math.isfinite(value) and (low < value if open_low else low <= value) and value <= high
    if not ok:
        raise ValueError(f"{name} must be in {'(' if open_low else '['}{low:g}, {high:g}], got {value!r}")
    return value


def _schedule(text: str) -> Drive:
    """``V1:T1,V2:T2,...``: drive at V1 for T1, then V2 for T2, ... (each V in [0, 1e7], each
    T in (0, 1e8], the total within 1e8)."""
    segments = []
    parts = text.split(",")
    for i, part in enumerate(parts):
        try:
            v, d = (float(x) for x in part.split(":"))
        except ValueError:
            raise argparse.ArgumentTypeError(f"--schedule must look like V1:T1,V2:T2, got {text!r}") from None
        _bounded(v, f"--schedule item {i + 1} velocity", 0.0, V_RANGE[1])
        _bounded(d, f"--schedule item {i + 1} duration", 0.0, T_MAX, open_low=True)
        segments.append((d, v))
    _bounded(sum(d for d, _ in segments), "--schedule total duration", 0.0, T_MAX, open_low=True)
    return Drive.schedule(segments)


def _progress(i: int, n: int, elapsed: float) -> str:
    """``[i/n, elapsed, ETA]`` of a list of points, the ETA from the mean time per point."""
    eta = f", ETA {elapsed / i * (n - i):.0f} s" if i < n else ""
    return f"[{i}/{n}, {elapsed:.0f} s{eta}]"


def _model_options(p: argparse.ArgumentParser, *, k0_list: bool = False) -> None:
    # -v also after the subcommand (SUPPRESS: an absent sub-level flag keeps the top-level one)
    p.add_argument("-v", "--verbose", action="store_true", default=argparse.SUPPRESS,
                   help="log progress to stderr")
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
    n.add_argument("--cohort-dt", type=float, default=0.01,
                   help="time step of --method cohort, in (0, 0.1] (default 0.01; --eps is its delta_R cell)")
    n.add_argument("--rtol", type=float, default=1e-2,
                   help="convergence: relative agreement of 3 cycles / stress means (default 1e-2, the paper's)")
    n.add_argument("--t-max", type=float, default=None, help="longest simulated time, <= 1e8 (default from the model's time scales)")


def _model(args, k0: float) -> Model:
    jumps = Exponential(args.zbar, 10.0) if args.dist == "exp" else Deterministic(args.zbar)
    return Model(k0=k0, k1=args.k1, k2=args.k2, eta_u=args.eta_u, f_th=args.f_th, jumps=jumps)


def _numerics(args) -> tuple[Numerics, Convergence]:
    return Numerics(eps=args.eps, cohort_dt=args.cohort_dt), Convergence(rtol=args.rtol, t_max=args.t_max)


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
    s.add_argument("--V", required=True, help="drive velocities, comma-separated, each in [1e-6, 1e7]")
    s.add_argument("--method", choices=("auto", "fp", "cycle", "cohort"), default="auto",
                   help="auto: steady rows from the renewal chain, others by Fokker-Planck time-stepping (default); "
                        "fp: time-step every row; cycle: stick-slip rows as the fixed point of the shock-to-shock map "
                        "(small k0; default eps kappa*zbar/8; falls back to time-stepping where shocks are not total); "
                        "cohort: stick-slip rows by the grid-free cohort method, at any k0 (default delta_R cell "
                        "kappa*zbar/20; falls back to time-stepping where jumps are not exponential)")
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
    drive.add_argument("--V", type=float, help="constant drive velocity in [1e-6, 1e7] (with --duration)")
    drive.add_argument("--schedule", help="piecewise drive V1:T1,V2:T2,... (velocity:duration, V in [0, 1e7], total T <= 1e8)")
    drive.add_argument("--shs", nargs=4, type=float, metavar=("V", "SLIDE", "HOLD", "RESUME"),
                       help="slide-hold-slide: drive at V for SLIDE, hold for HOLD, resume for RESUME")
    r.add_argument("--duration", type=float, help="run length for --V, in (0, 1e8]")
    r.add_argument("--out", required=True, help="output CSV: t,w,sigma (plus window min/max/mean)")
    return p


def main(argv: list[str] | None = None) -> int:
    parser = build_parser()
    args = parser.parse_args(argv)
    logging.basicConfig(level=logging.INFO if args.verbose else logging.WARNING,
                        format="%(levelname)s %(name)s: %(message)s")
    try:
        return _run(args)
    except (ValueError, argparse.ArgumentTypeError) as exc:
        print(f"error: {exc}", file=sys.stderr)
        return 2


def _run(args) -> int:
    start = time.perf_counter()
    # everything is checked before anything is computed
    out = _check_out(args.out)
    k0s = _floats(args.k0, "k0", 0.0, K0_MAX) if args.command == "critical" else [args.k0]
    models = [_model(args, k0) for k0 in k0s]
    if models[0].k0 > K0_MAX:
        raise ValueError(f"--k0 must be in (0, {K0_MAX:g}], got {args.k0!r}")
    if args.t_max is not None:
        _bounded(args.t_max, "--t-max", 0.0, T_MAX, open_low=True)
    numerics, convergence = _numerics(args)
    for model in models:
        numerics.settings(model)
    if args.command == "steady":
        velocities = _floats(args.V, "V", *V_RANGE)
        res = steady_sliding(models[0], velocities, growth_rate=args.growth_rate)
        frame = res.to_frame()
        _write_csv(frame, out)
        print(f"wrote {len(frame)} rows to {out} in {time.perf_counter() - start:.2f} s"
              f"{'' if frame.converged.all() else ' (' + res.message + ')'}", file=sys.stderr)
        return 0 if frame.converged.all() else 3
    if args.command == "sweep":
        velocities = _floats(args.V, "V", *V_RANGE)
        rows = []
        seed = "auto"  # with --method cycle or cohort, each row starts from the previous row's fixed point
        for i, V in enumerate(velocities):
            res = stationary(models[0], V, numerics=numerics, convergence=convergence, method=args.method,
                             initial=seed)
            if res.cycle is not None and res.cycle.applicable:
                seed = res.cycle
            rows.append(res.to_dict())
            print(f"{_progress(i + 1, len(velocities), time.perf_counter() - start)} V={V:g}: {res.regime}, "
                  f"sigma_max={res.sigma_max:.6f}, sigma_min={res.sigma_min:.6f}"
                  f"{'' if res.converged else ' (NOT converged: ' + res.message + ')'}", file=sys.stderr)
        frame = pd.DataFrame(rows)
        _write_csv(frame, out)
        print(f"wrote {len(frame)} rows to {out} in {time.perf_counter() - start:.1f} s", file=sys.stderr)
        return 0 if frame.converged.all() else 3
    if args.command == "critical":
        rows = []
        for i, model in enumerate(models):
            crit = critical_velocity(model, V_min=args.V_min, V_max=args.V_max, rel_tol=args.rel_tol,
                                     numerics=numerics, convergence=convergence, refine=args.refine,
                                     method=args.method)
            rows.append(crit.to_dict())
            print(f"{_progress(i + 1, len(models), time.perf_counter() - start)} k0={model.k0:g}: "
                  f"Vc={crit.Vc:.6g} ({crit.status})", file=sys.stderr)
        _write_csv(pd.DataFrame(rows), out)
        print(f"wrote {len(rows)} rows to {out} in {time.perf_counter() - start:.1f} s", file=sys.stderr)
        return 0
    # run
    if args.V is not None:
        if args.duration is None:
            raise ValueError("--duration is required with --V")
        drive = Drive.uniform(_bounded(args.V, "--V", *V_RANGE),
                              _bounded(args.duration, "--duration", 0.0, T_MAX, open_low=True))
    elif args.schedule is not None:
        drive = _schedule(args.schedule)
    else:
        v, slide, hold, resume = args.shs
        _bounded(v, "--shs V", *V_RANGE)
        for name, value in (("SLIDE", slide), ("HOLD", hold), ("RESUME", resume)):
            _bounded(value, f"--shs {name}", 0.0, T_MAX, open_low=name != "HOLD")
        _bounded(slide + hold + resume, "--shs SLIDE + HOLD + RESUME", 0.0, T_MAX, open_low=True)
        drive = Drive.slide_hold_slide(v, slide, hold, resume)
    run = simulate(models[0], drive, numerics=numerics, progress=True)
    _write_csv(run.records, out)
    eps = numerics.eps if numerics.eps is not None else default_eps(models[0])
    print(f"wrote {len(run.records)} rows to {out} (eps={eps:g}) in {time.perf_counter() - start:.1f} s",
          file=sys.stderr)
    return 0


if __name__ == "__main__":  # pragma: no cover
    raise SystemExit(main())
