"""Command line: ``python -m micro steady|sweep|branch|critical|run``.

Defaults are the paper's Fig. 4 parameters (k1 = 0.1, k2 = 0.9, zbar = 0.1, exponential
pinning distances with cutoff 10, eta_u = 1, f_th = 1), and each question's best method
(:mod:`micro.api`): the renewal chain for steady sliding and V^c, the cohort method for
stick-slip cycles, the Fokker-Planck equation for a protocol's transient.  A method's
options are flags of their own (``--eps`` the Fokker-Planck bin, ``--cohort-dt`` and
``--cohort-h`` the cohort's step and cell); a flag for a method the command does not use
is an error.

Every argument is checked before the modules that compute are imported (pandas, scipy and
numba take most of a second): a bad one is said at once.  A check that needs V^c (``micro
branch``'s ``--V-start``) loads the renewal chain only.
"""
from __future__ import annotations

import argparse
import contextlib
import logging
import math
import re
import os
import sys
import time
from pathlib import Path
from typing import TYPE_CHECKING

from . import _outputs
from ._branch_checks import check_arguments as check_branch_arguments, check_start as check_branch_start
from ._progress import Interrupted, reporting, restart
from .methods import FP, RETIRED, Auto, Cohort, Convergence, default_eps
from .params import Deterministic, Exponential, Model
from .protocols import Drive

if TYPE_CHECKING:  # pragma: no cover  (imported where a command computes, after its checks)
    import pandas as pd

log = logging.getLogger("micro")


#: Largest drive velocity and stiffness the commands accept (V^c ~ 0.08/k0 reaches 1e7 at
#: k0 ~ 1e-8; beyond these the stresses lose every significant digit).
V_RANGE = (1e-6, 1e7)
K0_MAX = 1e3
#: Longest simulated time a command accepts (as rsf's t_end): 1e8 relaxation times.
T_MAX = 1e8
#: `micro run` refuses a run that would take longer than this many hours at the pace of its
#: first second (micro.simulate's max_wall_time): a duration mistyped by decades is said at
#: once, not after an ETA of weeks.
RUN_HOURS_MAX = 24.0


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


def _check_out(path: str, option: str = "--out") -> _outputs.Target:
    """Where the CSV goes, checked now, not after the computation (:mod:`micro._outputs`:
    ``-`` is standard output; a symbolic link is checked, and later written, at its target)."""
    return _outputs.target(path, option, what="CSV file")


def _write_csv(frame: pd.DataFrame, out: _outputs.Target | str | os.PathLike) -> None:
    """By the policy of every output (:mod:`micro._outputs`, the same module as rsf's): a
    regular file atomically (a temporary file beside it, renamed over it once complete; a
    new file gets ``0o666 & ~umask``, an existing one keeps its owner and mode, a symbolic
    link stays a link and its target gets the data), standard output (``-``), a device or
    a FIFO in place."""
    def fill(tmp: Path) -> None:
        with open(tmp, "w", newline="") as f:
            frame.to_csv(f, index=False)

    _outputs.write(out, fill)


def _keep_so_far(frame: pd.DataFrame, out: _outputs.Target, kept: list[str], what: str) -> None:
    """A file holds every row computed so far: a later row that fails, or a kill, loses
    nothing (standard output, a device or a FIFO take the rows once, at the end).  ``kept``
    gets ``what`` (the message of a Ctrl-C)."""
    if out.replaceable:
        _write_csv(frame, out)
        kept.append(f"{what} finished and written to {out}")


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
        g.add_argument("--k0", required=True,
                       help=f"driving-spring stiffness(es), in (0, {K0_MAX:g}]; comma-separated for several")
    else:
        g.add_argument("--k0", type=float, required=True, help=f"driving-spring stiffness, in (0, {K0_MAX:g}]")
    g.add_argument("--k1", type=float, default=0.1, help="elastic coupling, >= 0 (default 0.1)")
    g.add_argument("--k2", type=float, default=0.9, help="viscoelastic coupling, >= 0 (default 0.9)")
    g.add_argument("--zbar", type=float, default=0.1,
                   help="mean pinning distance, > 0 (default 0.1); <= 0.38 with --dist exp (the cut at 10 "
                        "must not lower the mean by more than 1e-10)")
    g.add_argument("--dist", choices=("exp", "delta"), default="exp",
                   help="pinning distances: exponential with cutoff 10 (default) or all equal to zbar")
    g.add_argument("--eta-u", type=float, default=1.0, help="dashpot viscosity, > 0 (default 1)")
    g.add_argument("--f-th", type=float, default=1.0, help="pinning threshold, > 0 (default 1)")
    n = p.add_argument_group("method options (each only with a method that uses it)")
    n.add_argument("--eps", type=float, default=None,
                   help="Fokker-Planck bin of delta_F and delta_R (default kappa*zbar/50; error ~ (eps/0.004)^2 * "
                        "1.4e-4 on a steady stress)")
    n.add_argument("--rtol", type=float, default=None,
                   help="Fokker-Planck stopping rule: relative agreement of 3 cycles / stress means "
                        "(default 1e-2, the paper's)")
    n.add_argument("--t-max", type=float, default=None,
                   help="Fokker-Planck: longest simulated time, <= 1e8 (default from the model's time scales)")
    n.add_argument("--cohort-dt", type=float, default=None,
                   help="cohort method: time step, in (0, 0.1] (default 0.01; error second order in it)")
    n.add_argument("--cohort-h", type=float, default=None,
                   help="cohort method: delta_R cell, in (0, kappa*zbar/2] (default kappa*zbar/20)")
    n.add_argument("--cohort-tol", type=float, default=None,
                   help="cohort method: the fixed point's tolerance in stress, in [1e-9, 1e-2] (default 2e-5)")


#: The flags of each method's options.
FP_FLAGS = ("eps", "rtol", "t_max")
COHORT_FLAGS = ("cohort_dt", "cohort_h", "cohort_tol")


def _refuse(args, flags, why: str) -> None:
    """One error naming the first of ``flags`` that was given, and why it does not apply."""
    for name in flags:
        if getattr(args, name, None) is not None:
            raise ValueError(f"--{name.replace('_', '-')} {why}")


#: The model's parameters set by flags of the same name (``eta_u``: ``--eta-u``; for the messages).
_MODEL_FLAGS = ("k0", "k1", "k2", "zbar", "eta_u", "f_th")


#: The command line's exponential jumps are cut at this distance (the paper's Appendix B).
CUTOFF = 10.0
#: The relative amount by which the cut may lower the jumps' mean below --zbar (the tables
#: report the mean as zbar): the renewal chain's own accuracy, ~1e-10.
CUT_MEAN_RTOL = 1e-10


def _zbar_max_for_cutoff() -> float:
    """The largest --zbar whose exponential jumps, cut at ``CUTOFF``, keep their mean within
    ``CUT_MEAN_RTOL`` of it: the mean is zbar (1 - (c/zbar) e^(-c/zbar) / (1 - e^(-c/zbar))),
    solved for c/zbar by bisection."""
    def deficit(r: float) -> float:   # r = c / zbar
        return r * math.exp(-r) / -math.expm1(-r)
    lo, hi = 1.0, 100.0               # deficit falls with r: above the tolerance at lo, below at hi
    for _ in range(200):
        mid = 0.5 * (lo + hi)
        lo, hi = (mid, hi) if deficit(mid) > CUT_MEAN_RTOL else (lo, mid)
    return CUTOFF / hi


ZBAR_MAX_EXP = _zbar_max_for_cutoff()


def _model(args, k0: float) -> Model:
    if args.dist == "exp" and math.isfinite(args.zbar) and args.zbar > ZBAR_MAX_EXP:
        mean = Exponential(args.zbar, CUTOFF).mean if args.zbar < CUTOFF else math.nan
        raise ValueError(f"--zbar must be <= {ZBAR_MAX_EXP:.4g} with --dist exp: the jumps are cut at {CUTOFF:g}, which "
                         f"lowers their mean, the zbar the tables report, by more than {CUT_MEAN_RTOL:g} (relative) "
                         f"above it; got {args.zbar:g}" + (f" (mean {mean:.3g})" if mean == mean else "")
                         + "; --dist delta has no cutoff")
    try:
        jumps = Exponential(args.zbar, CUTOFF) if args.dist == "exp" else Deterministic(args.zbar)
        return Model(k0=k0, k1=args.k1, k2=args.k2, eta_u=args.eta_u, f_th=args.f_th, jumps=jumps)
    except ValueError as exc:  # (name the flag the user typed: "zbar must be ..." -> "--zbar must be ...")
        text = str(exc)
        if text.startswith("cutoff"):  # (the CLI's exponential jumps are cut at 10)
            raise ValueError(f"--zbar must be below the exponential jumps' cutoff 10, got {args.zbar:g}") from None
        name = re.match(r"[A-Za-z_][A-Za-z0-9_]*", text)
        if name and name.group(0) in _MODEL_FLAGS:
            raise ValueError(_flag(name.group(0), text)) from None
        raise


def _fp_options(args) -> tuple[FP, Convergence]:
    conv = Convergence() if args.rtol is None else Convergence(rtol=_bounded(args.rtol, "--rtol", 0.0, 1.0,
                                                                              open_low=True))
    if args.t_max is not None:
        conv = Convergence(rtol=conv.rtol, t_max=_bounded(args.t_max, "--t-max", 0.0, T_MAX, open_low=True))
    try:
        return FP(eps=args.eps), conv
    except ValueError as exc:  # (name the flag the user typed: "eps must be ..." -> "--eps must be ...")
        raise ValueError(_flag("eps", str(exc)).replace(" (or None for the default)", "")) from None


def _flag(name: str, message: str) -> str:
    """``message`` starting with the parameter ``name`` as the flag's name instead."""
    return f"--{name.replace('_', '-')}{message[len(name):]}" if message.startswith(name + " ") else message


def _cohort_options(args) -> Cohort:
    given = {k: v for k, v in (("dt", args.cohort_dt), ("h", args.cohort_h), ("tol", args.cohort_tol))
             if v is not None}
    try:
        return Cohort(**given)
    except ValueError as exc:  # (name the flag the user typed)
        raise ValueError(str(exc).replace("Cohort dt", "--cohort-dt").replace("Cohort h", "--cohort-h")
                         .replace("Cohort tol", "--cohort-tol")) from None


def build_parser() -> argparse.ArgumentParser:
    p = argparse.ArgumentParser(
        prog="python -m micro",
        description="Mean-field viscoelastic friction model (Landes, Rosso & Jagla 2015): steady sliding and "
                    "V^c from the renewal chain, stick-slip cycles by the cohort method, transients by the "
                    "Fokker-Planck equation for P(delta_F, delta_R).",
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
                    help="output CSV (- for standard output): k0,k1,k2,zbar,V,sigma,branching_ratio,stable,"
                         "growth_rate,sigma_error,converged,method (chain, fixed point or no dashpot)")

    s = sub.add_parser("sweep", help="stationary state for each drive velocity: one CSV row per V")
    _model_options(s)
    s.add_argument("--V", required=True, help="drive velocities, comma-separated, each in [1e-6, 1e7]")
    s.add_argument("--method", default="auto", metavar="{auto,cohort,fp}",
                   help="auto (default): steady rows from the renewal chain, stick-slip rows by the cohort method "
                        "(seconds per row at every k0; the Fokker-Planck equation only for non-exponential jumps); "
                        "cohort: the same, never the Fokker-Planck state; fp: time-step every row (minutes)")
    s.add_argument("--out", required=True,
                   help="output CSV (- for standard output), a file rewritten after every row: k0,k1,k2,zbar,V,"
                        "method,regime,sigma_max,sigma_min,sigma_mean,...,sigma_stderr,discretisation_error,...")

    b = sub.add_parser("branch", help="the stick-slip branch from --V-start towards V^c, point by point in "
                                      "log d (d = 1 - V/V^c), each point with its errors: one CSV row per point")
    _model_options(b)
    b.add_argument("--V-start", type=float, default=None,
                   help="the first point's drive velocity, in (0, V^c) (default 0.2 V^c)")
    b.add_argument("--d-min", type=float, default=1e-3,
                   help="where to stop, d = 1 - V/V^c in (0, 1), below the start's (default 1e-3; today the walk "
                        "ends at d = 0.02, closer than which the cohort method's discretisation error is not known)")
    b.add_argument("--max-error", type=float, default=0.1,
                   help="a point is certified when its fixed-point plus discretisation error is at most this "
                        "fraction of its amplitude, in (0, 1] (default 0.1); the walk ends at the first that is not")
    b.add_argument("--max-points", type=int, default=60, help="most points, >= 2 (default 60)")
    b.add_argument("--multipliers", action="store_true",
                   help="also the cycle map's two leading (Floquet) multipliers at each point: columns floquet_1 "
                        "(largest modulus; stable below 1), floquet_1_angle, floquet_2; about 14 more cycles a point")
    b.add_argument("--out", required=True,
                   help="output CSV (- for standard output), a file rewritten after every point: k0,k1,k2,zbar,V,d,"
                        "sigma_max,sigma_min,sigma_before,sigma_after,sigma_mean,period,amplitude,"
                        "fixed_point_error,discretisation_error,certified,floquet_1,floquet_1_angle,floquet_2,"
                        "method,n_cycles,wall_time,message")

    c = sub.add_parser("critical", help="critical velocity Vc: where the branching ratio of steady sliding reaches 1 "
                                        "(--method fp: bisection on Fokker-Planck runs, the paper's Appendix B)")
    _model_options(c, k0_list=True)
    c.add_argument("--method", choices=("auto", "renewal", "fp"), default="auto",
                   help="auto = renewal (default): the direct solution, ~1e-10 relative in < 1 s; fp: bisection on "
                        "Fokker-Planck runs (minutes, uncertain by the bin)")
    c.add_argument("--V-min", type=float, default=1e-4,
                   help="lower end of the bracket, in [1e-6, 1e7] (default 1e-4); a V^c below it is reported "
                        "as status 'V^c below --V-min'")
    c.add_argument("--V-max", type=float, default=None,
                   help="upper end of the bracket, in [1e-6, 1e7] (default 1e7 with --method renewal, 1e3 with "
                        "fp); a V^c above it is reported as status 'V^c above --V-max'")
    c.add_argument("--rel-tol", type=float, default=1e-2,
                   help="stop when V_high/V_low - 1 <= this, in (0, 1) (default 1e-2)")
    c.add_argument("--no-refine", dest="refine", action="store_false",
                   help="decide oscillations smaller than 2 eps by their size and global shocks instead of "
                        "rerunning them at eps/2 (several times faster near Vc, but Vc then carries the "
                        "grid's error: k0=0.1, eps=0.016: 0.90 against 0.73)")
    c.add_argument("--out", required=True,
                   help="output CSV (- for standard output): k0,k1,k2,zbar,Vc,V_low,V_high,status,message,method")

    r = sub.add_parser("run", help="stress time series of one protocol: columns t,w,sigma")
    _model_options(r)
    drive = r.add_mutually_exclusive_group(required=True)
    drive.add_argument("--V", type=float, help="constant drive velocity in [1e-6, 1e7] (with --duration)")
    drive.add_argument("--schedule", help="piecewise drive V1:T1,V2:T2,... (velocity:duration, V in [0, 1e7], total T <= 1e8)")
    drive.add_argument("--shs", nargs=4, type=float, metavar=("V", "SLIDE", "HOLD", "RESUME"),
                       help="slide-hold-slide: drive at V for SLIDE, hold for HOLD, resume for RESUME")
    r.add_argument("--duration", type=float,
                   help="run length for --V (only), in (0, 1e8]; a run that would take more than "
                        f"{RUN_HOURS_MAX:g} h at the pace of its first second is refused, with the longest duration allowed")
    r.add_argument("--out", required=True,
                   help="output CSV (- for standard output): t,w,sigma (plus window min/max/mean)")
    return p


def main(argv: list[str] | None = None) -> int:
    parser = build_parser()
    args = parser.parse_args(argv)
    logging.basicConfig(level=logging.INFO if args.verbose else logging.WARNING,
                        format="%(levelname)s %(name)s: %(message)s")
    kept: list[str] = []  # what a Ctrl-C leaves on disk, as the commands write it
    try:
        with reporting(_progress_line(f"micro {args.command}"), first=0.2, interval=1.0, longest=10.0):
            return _run(args, kept)
    except (ValueError, argparse.ArgumentTypeError) as exc:
        print(f"error: {exc}", file=sys.stderr)
        return 2
    except KeyboardInterrupt:
        print(f"interrupted: {kept[-1] if kept else 'nothing was finished, nothing written'}", file=sys.stderr)
        return 130


def _started() -> float:
    """The computation begins (its modules imported): the clock of the times printed, and of
    the progress lines, which start ``first`` = 0.2 s later."""
    restart()
    return time.perf_counter()


def _progress_line(prefix: str):
    """The command line's progress callback: one line on stderr per report (every second
    at first, then every 2, 4, ... up to 10 seconds)."""
    def show(text: str, elapsed: float) -> None:
        print(f"{prefix}: {text} [{elapsed:.0f} s]", file=sys.stderr, flush=True)
    return show


def _options(args, models: list[Model]):
    """The method's options from its flags, refusing flags of methods the command does
    not use (all before anything is computed)."""
    fp_used = {"steady": False, "sweep": args.command == "sweep", "critical": getattr(args, "method", "") == "fp",
               "run": True, "branch": False}[args.command]
    cohort_used = args.command in ("sweep", "branch")
    if args.command == "sweep":
        if args.method in RETIRED:
            raise ValueError("--method cycle was retired (its cycles are wrong close to V^c): use --method cohort, "
                             "or auto (the default), which solves the same stick-slip cycles at every k0")
        if args.method not in ("auto", "cohort", "fp"):
            raise ValueError(f"--method must be auto, cohort or fp, got {args.method!r}")
        cohort_used = args.method != "fp"
        # the Fokker-Planck equation answers a sweep row of auto or cohort only for jumps the
        # cohort method does not take: not exponential, or cut at 10 < 30 zbar
        fp_used = args.method == "fp" or args.dist != "exp" or 10.0 < 30.0 * args.zbar
    if not cohort_used:
        how = f" --method {args.method}" if getattr(args, "method", None) else ""
        _refuse(args, COHORT_FLAGS, f"sets the cohort method, which `micro {args.command}{how}` does not use")
    if not fp_used:
        where = ("with exponential jumps, stick-slip rows come from the cohort method (--cohort-dt, --cohort-h) "
                 "and steady rows from the renewal chain; --method fp time-steps every row"
                 if args.command == "sweep" else
                 f"`micro {args.command}{' --method ' + args.method if getattr(args, 'method', None) else ''}` "
                 "does not use the Fokker-Planck equation")
        _refuse(args, FP_FLAGS, f"sets the Fokker-Planck method: {where}")
    if args.command == "run":
        _refuse(args, ("rtol",), "sets the Fokker-Planck stopping rule; `micro run` runs for --duration")
    fp_opts, convergence = _fp_options(args)
    if fp_used:
        for model in models:
            try:
                fp_opts.settings(model)
            except ValueError as exc:
                raise ValueError(_flag("eps", str(exc))) from None
    cohort = _cohort_options(args) if cohort_used else None
    if cohort is not None:
        for model in models:
            try:
                cohort.cell(model)
            except ValueError as exc:
                raise ValueError(str(exc).replace("Cohort h", "--cohort-h")) from None
    return fp_opts, convergence, cohort


#: The parameters of micro.critical_velocity and the flags that set them.
_CRITICAL_FLAGS = {"V_min": "--V-min", "V_max": "--V-max", "rel_tol": "--rel-tol"}


def _as_flags(text: str, flags: dict[str, str] = _CRITICAL_FLAGS) -> str:
    """``text`` with the parameters of an API call (by default :func:`micro.critical_velocity`'s)
    named as their flags."""
    for name, flag in flags.items():
        text = re.sub(rf"\b{re.escape(name)}\b", flag, text)
    return text


@contextlib.contextmanager
def _critical_flags():
    """A ValueError of :func:`micro.critical_velocity` names the flags, not the parameters."""
    try:
        yield
    except ValueError as exc:
        raise ValueError(_as_flags(str(exc))) from None


def _check_critical_range(args) -> None:
    """``--V-min``, ``--V-max`` and ``--rel-tol`` checked before the first k0 is computed: the
    velocities within the steady branch's range (as ``--V``), ``--V-min < --V-max``."""
    _bounded(args.V_min, "--V-min", *V_RANGE)
    if args.V_max is not None:
        _bounded(args.V_max, "--V-max", *V_RANGE)
        if not args.V_max > args.V_min:
            raise ValueError(f"--V-max must be > --V-min, got --V-min {args.V_min:g}, --V-max {args.V_max:g}")
    if not (math.isfinite(args.rel_tol) and 0.0 < args.rel_tol < 1.0):
        raise ValueError(f"--rel-tol must be in (0, 1), got {args.rel_tol!r}")


def _run(args, kept: list[str]) -> int:
    """Run the command; ``kept`` gets a line saying what is on disk after each write (the
    message of a Ctrl-C).  Everything is checked before anything is computed, and before the
    modules that compute are imported; the times printed start once they are (as they did
    when they were imported with this module)."""
    out = _check_out(args.out)
    k0s = _floats(args.k0, "k0", 0.0, K0_MAX) if args.command == "critical" else [args.k0]
    if args.command != "critical" and not (math.isfinite(args.k0) and 0.0 < args.k0 <= K0_MAX):
        raise ValueError(f"--k0 must be in (0, {K0_MAX:g}], got {args.k0:g}")
    models = [_model(args, k0) for k0 in k0s]
    numerics, convergence, cohort = _options(args, models)
    if args.command == "steady":
        velocities = _floats(args.V, "V", *V_RANGE)
        import pandas  # noqa: F401  (the table's, SteadySliding.to_frame: imported before the clock starts)

        from .renewal import steady_sliding

        start = _started()
        res = steady_sliding(models[0], velocities, growth_rate=args.growth_rate)
        frame = res.to_frame()
        _write_csv(frame, out)
        print(f"wrote {len(frame)} rows to {out} in {time.perf_counter() - start:.2f} s"
              f"{'' if frame.converged.all() else ' (' + res.message + ')'}", file=sys.stderr)
        return 0 if frame.converged.all() else 3
    if args.command == "sweep":
        velocities = _floats(args.V, "V", *V_RANGE)
        method = "fp" if args.method == "fp" else cohort if args.method == "cohort" else Auto(cohort=cohort)
        from .api import sweep

        start = _started()

        def row_done(frame: pd.DataFrame) -> None:
            _keep_so_far(frame, out, kept, f"{len(frame)} of {len(velocities)} rows")
            last = frame.iloc[-1]
            print(f"{_progress(len(frame), len(velocities), time.perf_counter() - start)} V={last.V:g}: "
                  f"{last.regime} ({last.method}), sigma_max={last.sigma_max:.6f}, sigma_min={last.sigma_min:.6f}"
                  f"{'' if last.converged else ' (NOT converged: ' + last.message + ')'}", file=sys.stderr)

        try:
            frame = sweep(models[0], velocities, method=method, numerics=numerics, convergence=convergence,
                          on_row=row_done)
        except ValueError as exc:  # (name the flags the user typed)
            raise ValueError(str(exc).replace("Cohort dt", "--cohort-dt").replace("Cohort h", "--cohort-h")) from None
        if not out.replaceable:
            _write_csv(frame, out)
        print(f"wrote {len(frame)} rows to {out} in {time.perf_counter() - start:.1f} s", file=sys.stderr)
        return 0 if frame.converged.all() else 3
    if args.command == "branch":
        return _branch(args, models[0], cohort, out, kept)
    if args.command == "critical":
        _check_critical_range(args)
        import pandas as pd

        from .api import critical_velocity

        start = _started()
        rows = []
        for i, model in enumerate(models):
            with _critical_flags():
                crit = critical_velocity(model, V_min=args.V_min, V_max=args.V_max, rel_tol=args.rel_tol,
                                         numerics=numerics, convergence=convergence, refine=args.refine,
                                         method=args.method)
            row = crit.to_dict()
            row["status"], row["message"] = _as_flags(row["status"]), _as_flags(row["message"])
            rows.append(row)
            # (every finished row is kept: a later one may take minutes, or fail)
            _keep_so_far(pd.DataFrame(rows), out, kept, f"{len(rows)} of {len(models)} rows")
            print(f"{_progress(i + 1, len(models), time.perf_counter() - start)} k0={model.k0:g}: "
                  f"Vc={crit.Vc:.6g} ({row['status']})", file=sys.stderr)
        if not out.replaceable:
            _write_csv(pd.DataFrame(rows), out)
        print(f"wrote {len(rows)} rows to {out} in {time.perf_counter() - start:.1f} s", file=sys.stderr)
        return 0
    # run
    if args.duration is not None and args.V is None:
        raise ValueError(f"--duration goes with --V only: --{'schedule' if args.schedule else 'shs'} sets its own "
                         "length (the sum of its durations)")
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
    from .api import simulate
    from .fp import TooLong

    start = _started()
    try:
        run = simulate(models[0], drive, numerics=numerics, max_wall_time=RUN_HOURS_MAX * 3600.0)
    except TooLong as exc:  # (the option the user typed: --duration, or the protocol's)
        raise ValueError(str(exc).replace("duration", "--duration" if args.duration is not None else
                                          "the protocol's duration", 1)) from None
    except Interrupted as stop:
        partial = stop.partial.get("run")
        if partial is not None and len(partial.records):
            _write_csv(partial.records, out)
            kept.append(f"stopped at t = {partial.records.t.iloc[-1]:.6g} of {drive.duration:g}; "
                        f"the {len(partial.records)} rows so far written to {out}")
        raise
    _write_csv(run.records, out)
    eps = numerics.eps if numerics.eps is not None else default_eps(models[0])
    print(f"wrote {len(run.records)} rows to {out} (eps={eps:g}) in {time.perf_counter() - start:.1f} s",
          file=sys.stderr)
    return 0


#: The parameters of micro.cycle_branch and the flags that set them.
_BRANCH_FLAGS = {"V_start": "--V-start", "d_min": "--d-min", "max_error": "--max-error",
                 "max_points": "--max-points", "Cohort dt": "--cohort-dt", "Cohort h": "--cohort-h"}


@contextlib.contextmanager
def _branch_flags():
    """A ValueError of :func:`micro.cycle_branch` (or of its checks) names the flags, not the parameters."""
    try:
        yield
    except ValueError as exc:
        raise ValueError(_as_flags(str(exc).replace("model: ", "--dist: ", 1), _BRANCH_FLAGS)) from None


def _branch(args, model: Model, cohort: Cohort, out: _outputs.Target, kept: list[str]) -> int:
    """``micro branch``: the points written after each one; exit 0 when the walk reached
    --d-min with every point certified, 3 when it ended before (the reason on stderr).

    micro.cycle_branch's checks run first on their own, in its order: those that need no
    V^c, then the start against V^c from the renewal chain alone (cached: the branch reuses
    it); pandas, scipy's solvers and the cohort's kernels are imported only after them."""
    with _branch_flags():
        d_min, _ = check_branch_arguments(model, args.d_min, args.max_error, args.max_points, cohort,
                                          args.multipliers)
        from .renewal import cached_vc

        check_branch_start(args.V_start, d_min, cached_vc(model))
    from .branch import cycle_branch

    start = _started()

    def point_done(frame: pd.DataFrame) -> None:
        _keep_so_far(frame, out, kept, f"{len(frame)} points")
        last = frame.iloc[-1]
        print(f"[{len(frame)}, {time.perf_counter() - start:.0f} s] d={last.d:.4g} V={last.V:.6g}: "
              f"sigma_max={last.sigma_max:.6f}, amplitude={last.amplitude:.3g}, errors "
              f"{last.fixed_point_error:.1e} (fixed point) + {last.discretisation_error:.1e} (discretisation)"
              + (f", leading multiplier {last.floquet_1:.4f}" if args.multipliers else "")
              + ("" if last.certified else ", NOT certified"), file=sys.stderr)

    with _branch_flags():
        res = cycle_branch(model, args.V_start, d_min=args.d_min, max_error=args.max_error,
                           max_points=args.max_points, method=cohort, multipliers=args.multipliers,
                           on_point=point_done)
    if not out.replaceable or res.points.empty:
        _write_csv(res.points, out)
    print(f"wrote {len(res.points)} points to {out} in {time.perf_counter() - start:.1f} s; {res.reason}",
          file=sys.stderr)
    return 0 if res.complete else 3


if __name__ == "__main__":  # pragma: no cover
    raise SystemExit(main())
