"""Command line: ``python -m rsf {sweep,critical,run} ...``.

* ``sweep``    limit cycles over driving velocities, one CSV row per V
  (k0, Dc, V, regime, sigma_max, sigma_min, sigma_mean, period, converged, status, ...);
* ``critical`` the critical velocity from the linear stability analysis (k0, Dc, Vc, ...);
* ``run``      a time series t, x, sigma, theta, v (and an events file).

Defaults are the paper's: Eq. (10) with A = 0.007, B = 0.078, mu_inf = 1 - 0.05 (k0 + 1),
and Dc = 0.06.  Exit status: 0 on success, 2 on bad input, 3 if some result did not
converge or the integration failed (the CSV then says which, in the status/message columns).
"""
from __future__ import annotations

import argparse
import contextlib
import dataclasses
import logging
import math
import os
import re
import sys
from pathlib import Path
from typing import Sequence

import numpy as np

from ._progress import Interrupted, reporting
from .stability import critical_velocity
from .laws import (PAPER_A, PAPER_B, PAPER_DC, PAPER_K0_MAX, HyperbolicLaw, LogLaw, TabulatedLaw,
                   ViscoelasticLaw)
from ._validation import positive
from .params import T_END_MAX, Protocol, SolverOptions, SpringSlider
from . import _outputs
from .results import STATUS_MESSAGES, Status
from .state_laws import NagataLaw, SecondState
from .solver import simulate, sweep

__all__ = ["main", "build_parser"]

logger = logging.getLogger(__name__)


#: Documented upper bounds on magnitudes (beyond them a run loses its digits or never ends).
#: T_END_MAX is rsf.params.T_END_MAX, the bound of rsf.simulate's t_end.
K0_MAX, V_MAX, N_V_MAX = 1e3, 1e7, 10_000

#: rsf run's default output step: --t-end / OUT_ROWS between events (--out-dt).
OUT_ROWS = 10_000


def _floats(text: str) -> list[float]:
    """Every item of a comma-separated list, each a finite number (no empty items)."""
    items = text.replace(" ", "").split(",")
    values = []
    for i, item in enumerate(items):
        try:
            v = float(item)
        except ValueError:
            raise argparse.ArgumentTypeError(f"item {i + 1} of {len(items)} must be a number, got {item!r}") from None
        if not math.isfinite(v):
            raise argparse.ArgumentTypeError(f"item {i + 1} must be finite, got {item!r}")
        values.append(v)
    return values


def _outputs_of(args: argparse.Namespace) -> tuple[_outputs.Target, _outputs.Target | None]:
    """Where ``--out`` (default ``-``: standard output) and ``--events`` go, checked before
    anything is computed (:mod:`rsf._outputs`): neither is the other, nor an input of the
    call (``--table``, ``--history``), compared by device and inode."""
    out = _outputs.target("-" if args.out is None else args.out, "--out", what="CSV file")
    events = getattr(args, "events", None)
    events = None if events is None else _outputs.target(events, "--events", what="CSV file")
    _outputs.check_distinct([out, events], {"--table": getattr(args, "table", None),
                                            "--history": getattr(args, "history", None)})
    return out, events


def _check_magnitudes(args: argparse.Namespace) -> None:
    k0s = args.k0 if isinstance(args.k0, list) else [args.k0]
    for k0 in k0s:
        if not (0.0 < k0 <= K0_MAX):
            raise ValueError(f"--k0 must be in (0, {K0_MAX:g}], got {k0:g}")
    for V in getattr(args, "V", None) if isinstance(getattr(args, "V", None), list) else [getattr(args, "V", None)]:
        if V is not None and not (0.0 < V <= V_MAX):
            raise ValueError(f"--V must be in (0, {V_MAX:g}], got {V:g}")
    t_end = getattr(args, "t_end", None)
    if t_end is not None and not (0.0 < t_end <= T_END_MAX):
        raise ValueError(f"--t-end must be in (0, {T_END_MAX:g}], got {t_end:g}")
    rng = getattr(args, "V_range", None)
    if rng is not None:
        vmin, vmax, n = rng
        if not (0 < vmin < vmax <= V_MAX and float(n).is_integer() and 1 <= n <= N_V_MAX):
            raise ValueError(f"--V-range needs 0 < VMIN < VMAX <= {V_MAX:g} and an integer N in [1, {N_V_MAX}], "
                             f"got {vmin:g} {vmax:g} {n:g}")


def _add_model_options(p: argparse.ArgumentParser, k0_list: bool = False) -> None:
    # -v also after the subcommand (SUPPRESS: an absent sub-level flag keeps the top-level one)
    p.add_argument("-v", "--verbose", action="store_true", default=argparse.SUPPRESS,
                   help="log progress (INFO)")
    g = p.add_argument_group("model")
    if k0_list:
        g.add_argument("--k0", type=_floats, required=True,
                       help=f"driving stiffness k0 in (0, {K0_MAX:g}] (comma-separated list allowed); "
                            f"< {PAPER_K0_MAX:g} with the default --mu-inf or the viscoelastic law's "
                            "defaults (the friction at large V, 0.95 - 0.05 k0, must be > 0)")
    else:
        g.add_argument("--k0", type=float, required=True,
                       help=f"driving stiffness k0 in (0, {K0_MAX:g}]; < {PAPER_K0_MAX:g} with the default "
                            "--mu-inf or the viscoelastic law's defaults (the friction at large V, "
                            "0.95 - 0.05 k0, must be > 0)")
    g.add_argument("--Dc", type=float, default=PAPER_DC,
                   help=f"critical slip distance Dc > 0 (default {PAPER_DC}, the paper's)")
    g.add_argument("--law", choices=("hyperbolic", "viscoelastic", "log", "table"),
                   default="hyperbolic",
                   help="steady-state law: hyperbolic = Eq. (10) A/(v+B) + mu_inf (default); "
                        "viscoelastic = Eq. (4); log = Eq. (9), mu0 + (a-b) ln(v/v0); "
                        "table = PCHIP interpolation of a CSV (--table)")
    g.add_argument("--state-law", choices=("aging", "slip", "prz", "nagata"), default="aging",
                   help="state evolution: aging (Eq. 8, default), Ruina slip, Perrin-Rice-Zheng "
                        "(prz) or Nagata; all but aging need --a > 0")
    g.add_argument("--nagata-c", type=float, default=2.0,
                   help="Nagata's stress-rate coefficient c >= 0 (with --state-law nagata; "
                        "b from the log law, default 2)")
    g.add_argument("--b2", type=float, default=None,
                   help="second state variable: its evolution effect b2 > 0 (log law, a > 0)")
    g.add_argument("--Dc2", type=float, default=None,
                   help="second state variable: its critical slip distance Dc2 > 0")
    g.add_argument("--eta-rad", type=float, default=0.0,
                   help="radiation damping eta_rad >= 0: k0 (X - x) = mu + eta_rad v (needs a > 0; "
                        "default 0, the paper's model)")
    g.add_argument("--a", type=float, default=None,
                   help="direct effect a >= 0 (default: the law's a for --law log, else 0, "
                        "the paper's model with stick, slide and instantaneous slip)")
    h = p.add_argument_group("hyperbolic law, Eq. (10)")
    h.add_argument("--A", type=float, default=None, help=f"amplitude A >= 0 (default {PAPER_A})")
    h.add_argument("--B", type=float, default=None, help=f"velocity scale B > 0 (default {PAPER_B})")
    h.add_argument("--mu-inf", type=float, default=None,
                   help="large-velocity friction mu_inf (default: the paper's "
                        "f_th - zbar (k0 + k1 + k2)/2 = 0.95 - 0.05 k0, which needs k0 < 19)")
    v = p.add_argument_group("viscoelastic law, Eq. (4)")
    v.add_argument("--f-th", type=float, default=None, help="pinning threshold f_th (default 1)")
    v.add_argument("--zbar", type=float, default=None, help="mean well spacing zbar > 0 (default 0.1)")
    v.add_argument("--k1", type=float, default=None, help="elastic coupling k1 >= 0 (default 0.1)")
    v.add_argument("--k2", type=float, default=None, help="viscoelastic spring k2 > 0 (default 0.9)")
    v.add_argument("--eta-u", type=float, default=None, help="dashpot viscosity eta_u > 0 (default 1)")
    lg = p.add_argument_group("log law, Eq. (9) / Eq. (7)")
    lg.add_argument("--mu0", type=float, default=None, help="reference friction mu0 (default 0.6)")
    lg.add_argument("--b", type=float, default=None, help="evolution effect b >= 0 (default 0.015)")
    lg.add_argument("--law-a", type=float, default=None,
                    help="a of the log steady state mu0 + (a-b) ln(v/v0) (default 0.01)")
    lg.add_argument("--v0", type=float, default=None, help="reference velocity v0 > 0 (default 1)")
    t = p.add_argument_group("table law")
    t.add_argument("--table", default=None,
                   help="CSV file with a velocity and a friction column (with --law table only; "
                        "outside its velocities the law is held flat: a warning names the velocity, a "
                        "driving velocity or the state velocity Dc/theta a run reaches)")
    t.add_argument("--table-v-column", default="V", help="velocity column (default V)")
    t.add_argument("--table-mu-column", default="sigma", help="friction column (default sigma)")
    t.add_argument("--table-where", default=None,
                   help="keep only the rows where this holds: comparisons of columns with numbers "
                        "or strings (==, !=, <, <=, >, >=, in), joined by and, or, not, e.g. "
                        "\"regime == 'steady'\" or \"k0 == 0.1 and V < 3\" (checked, never "
                        "evaluated as code)")


def _add_solver_options(p: argparse.ArgumentParser) -> None:
    g = p.add_argument_group("solver")
    g.add_argument("--rtol", type=float, default=1e-10,
                   help="CVODE relative tolerance, in [1e-14, 1e-2] (default 1e-10)")
    g.add_argument("--atol", type=float, default=1e-12,
                   help="CVODE absolute tolerance, in [1e-16, 1e-2] (default 1e-12)")
    g.add_argument("--cycle-rtol", type=float, default=1e-8,
                   help="limit cycle converged when sigma_max, sigma_min and the period change by "
                        "less than this from one cycle to the next, in [1e-14, 0.1] (default 1e-8)")
    g.add_argument("--max-cycles", type=int, default=20000,
                   help="give up after this many cycles (default 20000): the row then says "
                        "converged False, status -1 (MAX_CYCLES), and the run exits with 3; -v logs "
                        "the cycles every 1000")
    g.add_argument("--no-accelerate", action="store_true",
                   help="simulate every cycle of the transient (no Aitken extrapolation)")
    g.add_argument("--v-max", type=float, default=None,
                   help="runaway bound on the slip velocity (a > 0): stop with status RUNAWAY "
                        "when v passes it (default 1e3 x max V for the log law, none otherwise; "
                        "inf: off)")
    g.add_argument("--max-rhs-evals", type=int, default=20_000_000,
                   help="step budget: stop after this many right-hand-side evaluations "
                        "(default 20000000)")


#: The API's parameter names and the options that set them (for the messages).
_LAW_NAMES = {"k0": "--k0", "A": "--A", "B": "--B", "mu_inf": "--mu-inf", "f_th": "--f-th",
              "zbar": "--zbar", "k1": "--k1", "k2": "--k2", "eta_u": "--eta-u", "mu0": "--mu0",
              "a": "--law-a", "b": "--b", "v0": "--v0"}
_MODEL_NAMES = {"k0": "--k0", "Dc": "--Dc", "a": "--a", "eta_rad": "--eta-rad", "c": "--nagata-c",
                "b2": "--b2", "Dc2": "--Dc2", "state_law": "--state-law",
                "second_state": "--b2 and --Dc2"}
_SOLVER_NAMES = {"rtol": "--rtol", "atol": "--atol", "cycle_rtol": "--cycle-rtol",
                 "max_cycles": "--max-cycles", "v_max": "--v-max", "max_rhs_evals": "--max-rhs-evals"}


def _resolve_names(velocity: str) -> dict[str, str]:
    """The options behind the parameters :meth:`rsf.SpringSlider.check_resolved` names."""
    return {"k0": "--k0", "Dc": "--Dc", "V": velocity, "A": "--A", "B": "--B", "mu_inf": "--mu-inf"}


@contextlib.contextmanager
def _named(names: dict[str, str]):
    """Re-raise a ValueError of the API whose message starts with a parameter name with the
    option's name instead (``Dc must be ...`` -> ``--Dc must be ...``)."""
    try:
        yield
    except ValueError as exc:
        text = str(exc)
        match = re.match(r"[A-Za-z_][A-Za-z0-9_]*", text)
        if match and match.group(0) in names and not text.startswith("--"):
            raise ValueError(names[match.group(0)] + text[match.end():]) from None
        raise


def _law(args: argparse.Namespace, k0: float):
    with _named(_LAW_NAMES):
        positive("k0", k0)
        if args.law == "hyperbolic":
            if args.mu_inf is None and not k0 < PAPER_K0_MAX:
                raise ValueError(f"--k0 must be < {PAPER_K0_MAX:g} with the default --mu-inf (0.95 - 0.05 k0, "
                                 f"the friction at large V, would be {0.95 - 0.05 * k0:g}), got {k0:g}; "
                                 "give --mu-inf for a stiffer spring")
            return HyperbolicLaw(A=args.A, B=args.B, mu_inf=args.mu_inf).bind(k0)
        if args.law == "viscoelastic":
            return ViscoelasticLaw(f_th=args.f_th, zbar=args.zbar, k1=args.k1, k2=args.k2,
                                   eta_u=args.eta_u, k0=k0)
        if args.law == "log":
            return LogLaw(mu0=args.mu0, a=args.law_a, b=args.b, v0=args.v0)
    if args.table is None:
        raise ValueError("--law table needs --table FILE.csv")
    return TabulatedLaw.from_csv(args.table, args.table_v_column, args.table_mu_column,
                                 args.table_where, names=_TABLE_OPTIONS)


#: The table options, as the messages of TabulatedLaw.from_csv name them.
_TABLE_OPTIONS = {"path": "--table", "where": "--table-where", "v_column": "--table-v-column",
                  "mu_column": "--table-mu-column"}


#: Each law's own options (the Namespace's names, their options and their defaults): an
#: option of another law than --law's is refused (it would be ignored), then the chosen
#: law's options not given take their defaults.
_LAW_OPTIONS = {
    "hyperbolic": {"A": ("--A", PAPER_A), "B": ("--B", PAPER_B)},
    "viscoelastic": {"f_th": ("--f-th", 1.0), "zbar": ("--zbar", 0.1), "k1": ("--k1", 0.1), "k2": ("--k2", 0.9),
                     "eta_u": ("--eta-u", 1.0)},
    "log": {"mu0": ("--mu0", 0.6), "b": ("--b", 0.015), "law_a": ("--law-a", 0.01), "v0": ("--v0", 1.0)},
}


def _check_law_options(args: argparse.Namespace) -> None:
    """Options of a law other than --law's are refused (else they would be ignored); the
    chosen law's options that were not given take their defaults."""
    for law, options in _LAW_OPTIONS.items():
        for name, (option, default) in options.items():
            if getattr(args, name, None) is None:
                setattr(args, name, default)
            elif law != args.law:
                raise ValueError(f"{option} is for --law {law}; got --law {args.law} (give --law {law}, "
                                 f"or drop {option})")
    if args.mu_inf is not None and args.law != "hyperbolic":
        raise ValueError(f"--mu-inf is for --law hyperbolic; got --law {args.law} (give --law hyperbolic, "
                         "or drop --mu-inf)")
    if args.law != "table":
        for option, value in (("--table", args.table), ("--table-where", args.table_where)):
            if value is not None:
                raise ValueError(f"{option} is for --law table; got --law {args.law} (give --law table, "
                                 f"or drop {option})")


def _model(args: argparse.Namespace, k0: float) -> SpringSlider:
    law = _law(args, k0)
    with _named(_MODEL_NAMES):
        state_law: object = args.state_law
        if state_law == "nagata":
            if args.law != "log":
                raise ValueError(f"--state-law nagata takes b from the log law: give --law log, "
                                 f"got --law {args.law}")
            state_law = NagataLaw(c=args.nagata_c)
        second = None
        if (args.b2 is None) != (args.Dc2 is None):
            raise ValueError("give both --b2 and --Dc2 for a second state variable")
        if args.b2 is not None:
            second = SecondState(args.b2, args.Dc2)
        return SpringSlider(law=law, k0=k0, Dc=args.Dc, a=args.a, state_law=state_law,
                            second_state=second, eta_rad=args.eta_rad)


def _options(args: argparse.Namespace) -> SolverOptions:
    with _named(_SOLVER_NAMES):
        return SolverOptions(rtol=args.rtol, atol=args.atol, cycle_rtol=args.cycle_rtol,
                             max_cycles=args.max_cycles, accelerate=not args.no_accelerate,
                             v_max=args.v_max, max_rhs_evals=args.max_rhs_evals)


def _write(frame, out: _outputs.Target | str | None, note: str = "", *, quiet: bool = False) -> None:
    """By the policy of every output (:mod:`rsf._outputs`): a regular file atomically (its
    owner and mode kept, a symbolic link written through), standard output (``-``, None),
    a device or a FIFO in place.  The count of rows goes to standard error (unless
    ``quiet``), so that standard output carries nothing but data."""
    if not isinstance(out, _outputs.Target):
        out = _outputs.target("-" if out is None else out, "--out", what="CSV file", probe=False)

    def fill(tmp: Path) -> None:
        with open(tmp, "w", newline="") as f:
            frame.to_csv(f, index=False)

    _outputs.write(out, fill)
    if out.given != "-" and not quiet:
        print(f"wrote {len(frame)} rows to {out}{note}", file=sys.stderr)


def build_parser() -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(
        prog="python -m rsf",
        description="Rate-and-state spring-slider (Landes, Rosso & Jagla 2015, Sec. V): limit "
                    "cycles, critical velocity and time series.",
        epilog="Exit status: 0 success, 2 bad input, 3 some result not converged or failed.")
    parser.add_argument("-v", "--verbose", action="store_true", help="log progress (INFO)")
    sub = parser.add_subparsers(dest="command", required=True)

    ps = sub.add_parser("sweep", help="limit cycles over driving velocities (one CSV row per V)",
                        description="Run to the attractor at each V and write k0, Dc, V, regime "
                                    "(steady or stick-slip), sigma_max, sigma_min, sigma_mean, "
                                    "period, converged, status, message, n_cycles.")
    ps.add_argument("--V", type=_floats, default=None,
                    help=f"driving velocities, comma-separated (e.g. 0.1,1,10), each in (0, {V_MAX:g}]")
    ps.add_argument("--V-range", type=float, nargs=3, metavar=("VMIN", "VMAX", "N"), default=None,
                    help=f"alternatively N log-spaced velocities from VMIN to VMAX (0 < VMIN < VMAX <= "
                         f"{V_MAX:g}, N an integer in [1, {N_V_MAX}])")
    ps.add_argument("--out", default=None, help="output CSV (default: standard output)")
    _add_model_options(ps)
    _add_solver_options(ps)

    pc = sub.add_parser("critical", help="critical velocity from the linear stability analysis",
                        description="Solve k0 Dc = -V dmu_ss/dV and write k0, Dc, Vc (the upper "
                                    "end of the unstable band, the paper's V^c), V_lower (its "
                                    "lower end) and the method.")
    pc.add_argument("--out", default=None, help="output CSV (default: standard output)")
    _add_model_options(pc, k0_list=True)

    pr = sub.add_parser("run", help="time series t, x, sigma, theta, v (and events)",
                        description="Integrate from the (perturbed) steady state and write the "
                                    "samples t, x, sigma, theta, v; a slip appears as two rows "
                                    "at one time.")
    pr.add_argument("--V", type=float, default=None,
                    help=f"constant driving velocity, in (0, {V_MAX:g}]")
    pr.add_argument("--steps", default=None,
                    help="velocity steps V1:T1,V2:T2,...,Vn (velocity:duration, last open-ended)")
    pr.add_argument("--shs", type=float, nargs=3, metavar=("V", "SLIDE", "HOLD"), default=None,
                    help="slide-hold-slide: slide at V for SLIDE, hold for HOLD, slide again")
    pr.add_argument("--history", default=None,
                    help="sampled load-point velocity V(t): a CSV file with columns t and V "
                         "(t from 0, strictly increasing), linear between the samples (a > 0)")
    pr.add_argument("--t-end", type=float, required=True,
                    help=f"end time, in (0, {T_END_MAX:g}] (the bound of rsf.simulate's t_end)")
    pr.add_argument("--out", required=True, help="output CSV for the time series (- for standard output)")
    pr.add_argument("--events", default=None,
                    help="output CSV for the events t, kind, sigma, theta, x (- for standard output)")
    pr.add_argument("--t-eval", type=_floats, default=None,
                    help="output times t1,t2,... (strictly increasing, in [0, t-end]): samples "
                         "exactly there instead of at every integrator step")
    pr.add_argument("--t-eval-n", type=int, default=None,
                    help="output at N equally spaced times from 0 to t-end, N in [2, 10000000]")
    pr.add_argument("--out-dt", type=float, default=None,
                    help=f"without --t-eval or --t-eval-n the rows are the integrator's own steps "
                         f"(exact, no interpolation), at most one per OUT_DT of time besides the "
                         f"rows at events (a slip's two rows, the extrema of the spring force), so at most "
                         f"about t-end/OUT_DT + 2 per event; in [0, t-end]; 0: every step. "
                         f"Default: every step if there are at most {OUT_ROWS}, else OUT_DT = "
                         f"t-end/{OUT_ROWS} (a fast cycle at rtol 1e-10 takes hundreds of steps, "
                         f"and a long run 100000s)")
    _add_model_options(pr)
    _add_solver_options(pr)
    return parser


def _number(option: str, value: float, low: float, high: float, *, open_low: bool = False) -> float:
    """``value`` finite and in [low, high] (``(low, high]`` with ``open_low``), or one error
    naming the option."""
    ok = math.isfinite(value) and (value > low if open_low else value >= low) and value <= high
    if not ok:
        raise ValueError(f"{option} must be in {'(' if open_low else '['}{low:g}, {high:g}], got {value:g}")
    return value


def _protocol(args: argparse.Namespace) -> tuple[float | None, Protocol | None]:
    """The driving of ``rsf run``, every number checked with the option's name (items
    counted from 1)."""
    given = [x is not None for x in (args.V, args.steps, args.shs, args.history)]
    if sum(given) != 1:
        raise ValueError("give exactly one of --V, --steps, --shs, --history")
    if args.V is not None:
        return args.V, None
    if args.history is not None:
        return None, _history(args.history, args.t_end)
    if args.shs is not None:
        V, slide, hold = args.shs
        _number("--shs V", V, 0.0, V_MAX, open_low=True)
        _number("--shs SLIDE", slide, 0.0, T_END_MAX, open_low=True)
        _number("--shs HOLD", hold, 0.0, T_END_MAX, open_low=True)
        return None, Protocol.slide_hold_slide(V, slide, hold)
    velocities, durations = [], []
    items = args.steps.split(",")
    for i, item in enumerate(items):
        parts = item.split(":")
        last = i == len(items) - 1
        try:
            if len(parts) > 2 or (len(parts) == 1 and not last):
                raise ValueError
            velocities.append(float(parts[0]))
            if len(parts) > 1:
                durations.append(float(parts[1]))
        except ValueError:
            form = "velocity[:duration]" if last else "velocity:duration (only the last item may omit it)"
            raise ValueError(f"--steps item {i + 1} of {len(items)} must be {form}, got {item!r}") from None
        _number(f"--steps item {i + 1} velocity", velocities[-1], 0.0, V_MAX)
        if len(parts) > 1:
            _number(f"--steps item {i + 1} duration", durations[-1], 0.0, T_END_MAX, open_low=True)
    if velocities[0] == 0.0:
        raise ValueError("--steps must start with a velocity > 0 (the run starts from steady sliding)")
    return None, Protocol.velocity_steps(velocities, durations[: len(velocities) - 1])


def _history(path: str, t_end: float) -> Protocol:
    """The sampled V(t) of ``--history``, checked row by row (rows counted from 1, as a
    spreadsheet without its header)."""
    import pandas as pd

    if os.path.isdir(path):
        raise ValueError(f"--history {path!r} is a folder, not a CSV file")
    try:
        frame = pd.read_csv(path)
    except OSError as exc:
        raise ValueError(f"--history {path!r} cannot be read ({exc.strerror or type(exc).__name__})") from None
    except (UnicodeDecodeError, pd.errors.ParserError, pd.errors.EmptyDataError) as exc:
        reason = str(exc).strip().splitlines()[0] if str(exc).strip() else type(exc).__name__
        raise ValueError(f"--history {path!r} is not a readable CSV file ({reason})") from None
    if not {"t", "V"} <= set(frame.columns):
        raise ValueError(f"--history needs columns t and V, got {', '.join(map(str, frame.columns))}")
    if frame.empty:
        raise ValueError(f"--history {path!r} has no rows")
    columns = {}
    for name in ("t", "V"):
        try:
            columns[name] = frame[name].to_numpy(float)
        except (TypeError, ValueError):
            raise ValueError(f"--history column {name} must hold numbers") from None
    t, V = columns["t"], columns["V"]
    if t[0] != 0.0:
        raise ValueError(f"--history must start at t = 0, got t = {t[0]:g} in row 1")
    for i in range(t.size):
        if not math.isfinite(t[i]) or (i > 0 and not t[i] > t[i - 1]):
            raise ValueError(f"--history times must increase strictly: row {i + 1} has t = {t[i]:g}"
                             + (f" after {t[i - 1]:g}" if i > 0 else ""))
        if not (math.isfinite(V[i]) and 0.0 <= V[i] <= V_MAX):
            raise ValueError(f"--history velocities must be in [0, {V_MAX:g}]: row {i + 1} has V = {V[i]:g}")
    if t[-1] < t_end:
        logger.warning("--history ends at t = %g, before --t-end = %g: the driving holds its last "
                       "velocity, V = %g, from there on", t[-1], t_end, V[-1])
    return Protocol.sampled(t, V)


def _out_dt(args: argparse.Namespace, steps: int) -> float:
    """The smallest time between two rows of ``rsf run`` apart from events (``--out-dt``;
    by default 0 for a run of at most ``OUT_ROWS`` steps, else ``--t-end / OUT_ROWS``); 0
    with ``--t-eval`` or ``--t-eval-n``."""
    if args.out_dt is None:
        if args.t_eval is not None or args.t_eval_n is not None or steps <= OUT_ROWS:
            return 0.0
        return args.t_end / OUT_ROWS
    if args.t_eval is not None or args.t_eval_n is not None:
        raise ValueError("give at most one of --t-eval, --t-eval-n and --out-dt")
    return _number("--out-dt", args.out_dt, 0.0, args.t_end)


def _t_eval(args: argparse.Namespace) -> np.ndarray | None:
    """``--t-eval`` or ``--t-eval-n``, checked against ``--t-end`` with the options' names."""
    if args.t_eval is not None and args.t_eval_n is not None:
        raise ValueError("give at most one of --t-eval and --t-eval-n")
    if args.t_eval_n is not None:
        if not 2 <= args.t_eval_n <= 10_000_000:
            raise ValueError(f"--t-eval-n must lie in [2, 10000000], got {args.t_eval_n}")
        return np.linspace(0.0, args.t_end, args.t_eval_n)
    if args.t_eval is None:
        return None
    times = args.t_eval
    n = len(times)
    for i, t in enumerate(times):
        if not 0.0 <= t <= args.t_end:
            raise ValueError(f"--t-eval item {i + 1} of {n} must be in [0, --t-end = {args.t_end:g}], "
                             f"got {t:g}")
        if i > 0 and not t > times[i - 1]:
            raise ValueError(f"--t-eval must increase strictly: item {i + 1} of {n} is {t:g}, "
                             f"after {times[i - 1]:g}")
    return np.asarray(times, dtype=float)


#: ``rsf run`` first integrates this many events: a run that ends within them is the result,
#: else their pace tells whether --t-end fits in the event budget (SolverOptions.max_events).
PROBE_EVENTS = 1000


class _DropProbeStop(logging.Filter):
    """Drops the warning of a run stopped at its event budget (the probe's)."""

    def filter(self, record: logging.LogRecord) -> bool:
        return not record.getMessage().startswith("simulate: " + STATUS_MESSAGES[Status.MAX_EVENTS])


def _simulate_within_budget(model: SpringSlider, V, protocol, t_end: float, options: SolverOptions,
                            t_eval):
    """:func:`rsf.simulate`, refused before the long part of the work if ``t_end`` lies
    beyond the event budget at the pace of the first ``PROBE_EVENTS`` events (the transient
    from the steady state included, so that the pace is underestimated, never over)."""
    budget = options.max_events
    if budget <= PROBE_EVENTS:
        return simulate(model, V, protocol=protocol, t_end=t_end, options=options, t_eval=t_eval)
    probe_options = dataclasses.replace(options, max_events=PROBE_EVENTS)
    quiet = _DropProbeStop()       # the probe's own stop is not the run's: not logged
    solver_logger = logging.getLogger("rsf.solver")
    solver_logger.addFilter(quiet)
    try:
        probe = simulate(model, V, protocol=protocol, t_end=t_end, options=probe_options, t_eval=t_eval)
    finally:
        solver_logger.removeFilter(quiet)
    if probe.status != Status.MAX_EVENTS:
        return probe          # the whole run (max_events plays no other part)
    t_probe = float(probe.events[-1].t) if probe.events else float(probe.t[-1])
    reach = t_probe * budget / PROBE_EVENTS
    if t_end > reach:
        raise ValueError(f"--t-end {t_end:g} is beyond the event budget: the first {PROBE_EVENTS} events "
                         f"took t = {t_probe:.4g}, so the run would need about "
                         f"{PROBE_EVENTS * t_end / t_probe:.3g} events, more than the {budget} allowed "
                         f"(rsf.SolverOptions.max_events); give --t-end <= {reach:.3g}")
    return simulate(model, V, protocol=protocol, t_end=t_end, options=options, t_eval=t_eval)


def _driving_velocities(V, protocol: Protocol | None) -> np.ndarray:
    """The load-point velocities of a run (its nonzero ones for a protocol)."""
    if protocol is None:
        return np.atleast_1d(np.asarray(V, dtype=float))
    return np.asarray(protocol.velocities)[np.asarray(protocol.velocities) > 0.0]


def _option_values(argv: Sequence[str], parser: argparse.ArgumentParser) -> list[str]:
    """``--t-eval -1,2`` as ``--t-eval=-1,2``: argparse takes a value that starts with a
    minus for an option unless it is a plain negative number (``-1`` but not ``-1,2`` or
    ``-1e-3``); joined to its option it is an ordinary value (and then checked)."""
    takes_value = set()
    actions = list(parser._actions)
    for action in parser._actions:
        if isinstance(action, argparse._SubParsersAction):
            for sub in action.choices.values():
                actions.extend(sub._actions)
    for action in actions:
        if action.option_strings and action.nargs is None and not isinstance(
                action, (argparse._StoreTrueAction, argparse._StoreFalseAction, argparse._HelpAction)):
            takes_value.update(action.option_strings)
    out: list[str] = []
    for token in argv:
        if (out and out[-1] in takes_value and re.match(r"^-(\d|\.\d|inf|nan)", token, re.IGNORECASE)):
            out[-1] = f"{out[-1]}={token}"
        else:
            out.append(token)
    return out


def main(argv: Sequence[str] | None = None) -> int:
    parser = build_parser()
    args = parser.parse_args(_option_values(sys.argv[1:] if argv is None else list(argv), parser))
    logging.basicConfig(level=logging.INFO if args.verbose else logging.WARNING,
                        format="%(levelname)s %(name)s: %(message)s")
    kept: list[str] = []  # what a Ctrl-C leaves on disk
    try:
        with reporting(_progress_line(f"rsf {args.command}"), first=0.2, interval=1.0, longest=10.0):
            return _run(args, kept)
    except KeyboardInterrupt:
        print(f"interrupted: {kept[-1] if kept else 'nothing was finished, nothing written'}", file=sys.stderr)
        return 130


def _progress_line(prefix: str):
    """The command line's progress callback: one line on stderr per report (every second
    at first, then every 2, 4, ... up to 10 seconds)."""
    def show(text: str, elapsed: float) -> None:
        print(f"{prefix}: {text} [{elapsed:.0f} s]", file=sys.stderr, flush=True)
    return show


def _kept(frame, out: str | None, what: str, kept: list[str]) -> None:
    """After a Ctrl-C: write ``frame`` (the finished part) to ``out`` and say so in ``kept``."""
    if frame is None or not len(frame):
        return
    _write(frame, out, quiet=True)  # (the Ctrl-C's one line says it)
    kept.append(f"{what} written to {out or 'standard output'}")


def _run(args: argparse.Namespace, kept: list[str]) -> int:
    """The command of ``args`` (``kept`` gets a line saying what is on disk, for a Ctrl-C)."""
    try:
        # everything is checked before anything is computed
        out, events = _outputs_of(args)
        _check_magnitudes(args)
        _check_law_options(args)
        if args.command == "critical":
            import pandas as pd

            results = [critical_velocity(_model(args, k0)) for k0 in args.k0]
            for r in results:
                if r.status != "unstable band":
                    print(f"k0={r.k0:g}: {r.status} (Vc = {r.Vc:g})", file=sys.stderr)
            frame = pd.concat([r.to_frame() for r in results], ignore_index=True)
            _write(frame, out)
            return 0
        model = _model(args, args.k0)
        options = _options(args)
        if args.command == "sweep":
            if (args.V is None) == (args.V_range is None):
                raise ValueError("give exactly one of --V and --V-range")
            if args.V is not None:
                velocities = args.V
            else:
                vmin, vmax, n = args.V_range
                velocities = np.geomspace(vmin, vmax, int(n))
            if isinstance(model.law, TabulatedLaw):
                model.law.check_velocities(velocities, "--V")
            for V in velocities:     # a stick-slip double precision cannot resolve: refused now
                model.check_resolved(float(V), _resolve_names("--V" if args.V is not None else "--V-range"))
            try:
                result = sweep(model, velocities, options=options, progress=args.verbose)
            except Interrupted as stop:
                done = stop.partial.get("result")
                _kept(done.to_frame() if done else None, out,
                      f"{len(done.results) if done else 0} of {len(velocities)} rows finished and", kept)
                raise
            _write(result.to_frame(), out)
            if not result.all_converged:
                print(f"warning: {result.message}", file=sys.stderr)
                return 3
            return 0
        V, protocol = _protocol(args)
        t_eval = _t_eval(args)
        _out_dt(args, 0)
        if isinstance(model.law, TabulatedLaw):
            model.law.check_velocities(_driving_velocities(V, protocol), "the driving velocity V")
        for v in _driving_velocities(V, protocol):
            model.check_resolved(float(v), _resolve_names("--V" if V is not None else "the driving velocity"))
        try:
            traj = _simulate_within_budget(model, V, protocol, args.t_end, options, t_eval)
        except Interrupted as stop:
            part = stop.partial.get("trajectory")
            if part is not None and part.t.size:
                part = part.thinned(_out_dt(args, part.t.size))
                if events is not None:
                    _write(part.events_frame(), events, quiet=True)
                _kept(part.to_frame(), out, f"stopped at t = {part.t[-1]:.6g} of {args.t_end:g}; the "
                                            f"{part.t.size} rows so far"
                                            + (f" (and the events, to {events})" if events is not None else ""), kept)
            raise
        steps = traj.t.size
        out_dt = _out_dt(args, steps)
        traj = traj.thinned(out_dt)
        note = "" if traj.t.size == steps else (f" (of {steps} integrator steps: one row per --out-dt = "
                                                f"{out_dt:g} between events; --out-dt 0 writes them all)")
        _write(traj.to_frame(), out, note)
        if events is not None:
            _write(traj.events_frame(), events)
        if not traj.success:
            print(f"warning: {traj.message}", file=sys.stderr)
            return 3
        return 0
    except ValueError as exc:
        print(f"error: {exc}", file=sys.stderr)
        return 2
