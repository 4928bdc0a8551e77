"""``python -m compare``: run the comparison and write the report folder.

With no arguments: the default settings (:meth:`compare.Settings.default`), every
scenario, a process pool over the machine's cores, the disk cache, ``./compare-report``.
"""
from __future__ import annotations

import argparse
import contextlib
import logging
import math
import re
import signal
import sys
import threading

from tqdm.contrib.logging import logging_redirect_tqdm

from .cache import check_cache_dir, default_cache_dir
from .params import SCENARIOS, Settings
from .report import report

__all__ = ["main", "build_parser"]


def build_parser() -> argparse.ArgumentParser:
    p = argparse.ArgumentParser(prog="python -m compare", description=(
        "Micro model vs rate-and-state friction (Landes, Rosso & Jagla 2015, Sec. V): fits A, B, offset "
        "and D_c, and writes bifurcation, Hopf, phase-diagram and slide-hold-slide figures, CSV tables and "
        "summary.md."))
    p.add_argument("--out", default="compare-report", help="report folder (created; default: %(default)s)")
    preset = p.add_mutually_exclusive_group()
    preset.add_argument("--quick", action="store_true", help="smoke-test preset: few coarse points (~15 s)")
    preset.add_argument("--paper", action="store_true", help="more points, finer N-block, Figs. 3 and 10 (~2 min on 2 cores)")
    p.add_argument("--scenario", action="append", choices=SCENARIOS, metavar="NAME",
                   help=f"run only this scenario (repeatable): {', '.join(SCENARIOS)}; default all")
    p.add_argument("--k0", type=float, nargs="+", metavar="K0",
                   help=f"k0 of the micro bifurcation diagram, each in (0, {K0_MAX:g}) (the RS side always "
                        "shows the paper's five)")
    p.add_argument("--eps", type=float, help="micro bin eps > 0 (smaller: more accurate, cost ~ eps^-2.6)")
    p.add_argument("--dc", type=float, metavar="DC",
                   help="use this D_c instead of fitting it, in the fit's range [0.005, 0.5]")
    p.add_argument("--workers", type=int,
                   help="local worker processes >= 1 (default: the cores this process may use; more are capped at "
                        "them, with a warning; 1: serial)")
    p.add_argument("--scheduler", metavar="ADDRESS",
                   help="dask.distributed scheduler address, e.g. tcp://host:8786 (needs the 'dask' extra)")
    p.add_argument("--cache-dir", metavar="DIR",
                   help="micro result cache (default: $COMPARE_CACHE_DIR or ~/.cache/frictionkit-compare)")
    p.add_argument("--no-cache", action="store_true", help="neither read nor write the cache")
    p.add_argument("--no-progress", action="store_true", help="no progress bars")
    p.add_argument("-v", "--verbose", action="count", default=0, help="more logging (-v info, -vv debug)")
    p.epilog = (f"Limits: --k0 in (0, {K0_MAX:g}), --eps > 0, --dc in [0.005, 0.5], --workers >= 1 (at most "
                "the cores).  Exit status: 0 "
                "success, 2 bad input (one line on stderr), 130 interrupted.")
    return p


#: k0 of the micro diagram must lie in (0, K0_MAX) (compare.Settings checks the same bound).
K0_MAX = 10.0


def _check_args(args: argparse.Namespace) -> None:
    """The numbers the user typed, checked with the option's name before anything runs (the
    messages of compare.Settings name its fields instead)."""
    for i, k0 in enumerate(args.k0 or ()):
        if not (math.isfinite(k0) and 0.0 < k0 < K0_MAX):
            n = len(args.k0)
            raise ValueError(f"--k0 must be in (0, {K0_MAX:g}), got {k0:g}"
                             + (f" (value {i + 1} of {n})" if n > 1 else ""))
    for option, value in (("--eps", args.eps), ("--dc", args.dc)):
        if value is not None and not (math.isfinite(value) and value > 0.0):
            raise ValueError(f"{option} must be a finite number > 0, got {value:g}")
    if args.workers is not None and args.workers < 1:
        raise ValueError(f"--workers must be an integer >= 1, got {args.workers}")


#: The parameters of compare.Settings and compare.report that options set, and the options.
_OPTIONS = {"eps": "--eps", "Dc": "--dc", "cache_dir": "--cache-dir", "workers": "--workers", "k0": "--k0",
            "scenarios": "--scenario"}


@contextlib.contextmanager
def _named():
    """A ValueError whose message starts with a parameter an option sets names the option
    (``eps must be ...`` -> ``--eps must be ...``)."""
    try:
        yield
    except ValueError as exc:
        text = str(exc)
        match = re.match(r"[A-Za-z_][A-Za-z0-9_]*", text)
        if match and match.group(0) in _OPTIONS:
            raise ValueError(_OPTIONS[match.group(0)] + text[match.end():]) from None
        raise


def _terminate(signum, frame) -> None:
    raise KeyboardInterrupt  # SIGTERM (timeout, batch schedulers) stops like Ctrl-C


def main(argv: list[str] | None = None) -> int:
    args = build_parser().parse_args(argv)
    if threading.current_thread() is threading.main_thread():
        signal.signal(signal.SIGTERM, _terminate)
    logging.basicConfig(level=[logging.WARNING, logging.INFO, logging.DEBUG][min(args.verbose, 2)],
                        format="%(levelname)s %(name)s: %(message)s")
    changes = {}
    if args.k0:
        changes["k0"] = tuple(args.k0)
    if args.eps is not None:
        changes["eps"] = args.eps
    if args.scenario:
        changes["scenarios"] = tuple(args.scenario)
    try:
        _check_args(args)
        if not args.no_cache:  # (report() checks the same, naming its parameters)
            check_cache_dir(default_cache_dir() if args.cache_dir is None else args.cache_dir, args.out,
                            option="--cache-dir", out_option="--out")
        factory = Settings.quick if args.quick else Settings.paper if args.paper else Settings.default
        with _named():
            settings = factory(**changes)
        with logging_redirect_tqdm():  # log lines above the progress bars, not glued to them
            with _named():
                rep = report(settings, out=args.out, Dc=args.dc, cache_dir=args.cache_dir,
                             use_cache=not args.no_cache, workers=args.workers, scheduler=args.scheduler,
                             progress=not args.no_progress)
    except ValueError as exc:
        print(f"error: {exc}", file=sys.stderr)
        return 2
    except KeyboardInterrupt:
        if args.no_cache:
            print("interrupted: with --no-cache nothing was kept; the same command computes every point again",
                  file=sys.stderr)
        else:
            print("interrupted: the finished micro points are in the cache; the same command resumes from them",
                  file=sys.stderr)
        return 130
    print(f"wrote {rep.out} ({len(rep.tables)} tables, {len(rep.figures)} figures) in {rep.wall_time:.1f} s; "
          f"read {rep.out / 'summary.md'}")
    return 0
