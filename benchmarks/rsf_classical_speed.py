"""CPU time per run of the classical spring-slider after a velocity step, against the code
of another commit (issue 38: rsf got 1.3-1.75x slower between bd9e37a and 742d67f and no
benchmark noticed).

The runs: ``rsf.standard_rs`` with the log law (mu0 = 0.6, a = 0.005, b = 0.01, Dc = 10,
v0 = 1), k0 = 1.2, 2 and 3 k_c (k_c = (b - a)/Dc), a velocity step at t = 10 and the end at
t = 60, from the exact steady state, output at every internal step (no ``t_eval``: the
older code has none), rtol 1e-6 and 1e-10 (atol = rtol / 100).  The aging law takes the
step 1 -> 10; the slip law 1 -> 2 (after 1 -> 3 it runs away at 1.2 k_c, a property of the
law).  For each run: the CPU time (``time.process_time``) of the first call, which holds
the numba compilation or cache load, apart; then the fastest and the median of
``--repeat`` calls; the number of samples and the largest error of sigma at the samples
against the independent reference of the tests (scipy DOP853 at rtol 1e-12,
``tests/rsf/_independent_rs.py``), so that codes are compared at equal error.

Each code runs in its own process (``--code PATH``: a checkout, put first on
``sys.path``); with ``--against REV`` a temporary ``git worktree`` of REV is made and
removed afterwards, and the two codes alternate round by round so that they share the
machine's load.  The load average is written with the results (the machine is shared:
compare the two codes of one table, not tables of different days).

    python benchmarks/rsf_classical_speed.py                       # this checkout only
    python benchmarks/rsf_classical_speed.py --against bd9e37a     # and the code of bd9e37a
    python benchmarks/rsf_classical_speed.py --against bd9e37a --rounds 5 --repeat 5

Writes ``benchmarks/results/rsf_classical_speed.csv`` (one row per code and run; ``--out``
to change).
"""
from __future__ import annotations

import argparse
import json
import os
import statistics
import subprocess
import sys
import tempfile
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
OUT = ROOT / "benchmarks" / "results" / "rsf_classical_speed.csv"

A, B, DC, V0, MU0 = 0.005, 0.01, 10.0, 1.0, 0.6
K_OVER_KC = (1.2, 2.0, 3.0)
STEPS = {"aging": 10.0, "slip": 2.0}      # the velocity after the step, from 1
RTOLS = (1e-6, 1e-10)
T_STEP, T_END = 10.0, 60.0


def _cases() -> list[tuple[str, float, float]]:
    return [(law, k, rtol) for law in STEPS for k in K_OVER_KC for rtol in RTOLS]


def measure(repeat: int) -> list[dict]:
    """In the child process: time every case with the rsf found first on sys.path."""
    import numpy as np

    import rsf
    # the tests' independent reference (scipy, no code shared with rsf), not a name of rsf
    from _independent_rs import mu_at

    from _harness import timed

    rows = []
    for law, k_over_kc, rtol in _cases():
        k0 = k_over_kc * (B - A) / DC
        v1 = STEPS[law]
        model = rsf.standard_rs(mu0=MU0, a=A, b=B, Dc=DC, k0=k0, v0=V0, state_law=law)
        protocol = rsf.Protocol.velocity_steps([1.0, v1], [T_STEP])
        options = rsf.SolverOptions(rtol=rtol, atol=rtol * 1e-2)
        initial = rsf.InitialState(perturbation=0.0)

        def run():
            return rsf.simulate(model, protocol=protocol, t_end=T_END, options=options,
                                initial=initial)

        tr, first = timed(run, cpu=True)      # the compilation or cache load: kept apart
        times = []
        for _ in range(repeat):
            tr, seconds = timed(run, cpu=True)
            times.append(seconds)
        t, index = np.unique(tr.t, return_index=True)    # a sample repeated at a step: once
        mu = mu_at(law, a=A, b=B, Dc=DC, k0=k0, v0=V0, mu0=MU0, velocities=[1.0, v1],
                   times=[0.0, T_STEP], t_eval=t)
        rows.append(dict(law=law, k_over_kc=k_over_kc, v_step=v1, rtol=rtol, atol=rtol * 1e-2,
                         status=int(tr.status), n_samples=int(tr.t.size),
                         err_sigma=float(np.max(np.abs(tr.sigma[index] - mu))),
                         cpu_ms_first=1e3 * first, cpu_ms=[1e3 * x for x in times]))
    return rows


def _child(code: Path, repeat: int) -> list[dict]:
    env = dict(os.environ, PYTHONPATH=os.pathsep.join(
        [str(code), str(ROOT / "tests" / "rsf"), os.environ.get("PYTHONPATH", "")]))
    out = subprocess.run([sys.executable, __file__, "--child", "--code", str(code),
                          "--repeat", str(repeat)], env=env, capture_output=True, text=True,
                         check=True, cwd=tempfile.gettempdir())
    return json.loads(out.stdout.strip().splitlines()[-1])


def _describe(code: Path) -> str:
    rev = subprocess.run(["git", "-C", str(code), "rev-parse", "--short", "HEAD"],
                         capture_output=True, text=True).stdout.strip()
    dirty = subprocess.run(["git", "-C", str(code), "status", "--porcelain", "--untracked-files=no",
                            "--", "rsf"], capture_output=True, text=True).stdout.strip()
    return rev + ("+changes" if dirty else "")


def main(argv: list[str] | None = None) -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--against", metavar="REV", help="also time the rsf of this commit")
    parser.add_argument("--rounds", type=int, default=3, help="processes per code (default 3)")
    parser.add_argument("--repeat", type=int, default=5,
                        help="timed calls per run and process (default 5)")
    parser.add_argument("--out", type=Path, default=OUT)
    parser.add_argument("--child", action="store_true", help=argparse.SUPPRESS)
    parser.add_argument("--code", type=Path, default=ROOT, help=argparse.SUPPRESS)
    args = parser.parse_args(argv)
    if args.child:
        sys.path[:0] = [str(args.code), str(ROOT / "tests" / "rsf")]
        print(json.dumps(measure(args.repeat)))
        return

    import pandas as pd

    from _harness import write_csv

    codes = {f"{_describe(ROOT)} (this checkout)": ROOT}
    tmp = None
    if args.against:
        tmp = Path(tempfile.mkdtemp(prefix="rsf_speed_"))
        subprocess.run(["git", "-C", str(ROOT), "worktree", "add", "--detach", str(tmp / "code"),
                        args.against], check=True, capture_output=True)
        codes[args.against] = tmp / "code"
    load_before = os.getloadavg()
    results: dict[str, list[list[dict]]] = {name: [] for name in codes}
    try:
        for r in range(args.rounds):
            for name, code in (codes.items() if r % 2 == 0 else reversed(codes.items())):
                results[name].append(_child(code, args.repeat))
                print(f"round {r + 1}/{args.rounds}: {name} done", file=sys.stderr)
    finally:
        if tmp is not None:
            subprocess.run(["git", "-C", str(ROOT), "worktree", "remove", "--force",
                            str(tmp / "code")], check=False, capture_output=True)
            os.rmdir(tmp)
    load_after = os.getloadavg()
    rows = []
    for name, rounds in results.items():
        for i, case in enumerate(rounds[0]):
            times = [t for one in rounds for t in one[i]["cpu_ms"]]
            first = [one[i]["cpu_ms_first"] for one in rounds]
            rows.append(dict(code=name, law=case["law"], k_over_kc=case["k_over_kc"],
                             v_step=case["v_step"], rtol=case["rtol"], atol=case["atol"],
                             status=case["status"], n_samples=case["n_samples"],
                             err_sigma=case["err_sigma"], cpu_ms_min=min(times),
                             cpu_ms_median=statistics.median(times), n_timed=len(times),
                             cpu_ms_first_median=statistics.median(first),
                             load_1min_before=load_before[0], load_1min_after=load_after[0],
                             cpus=os.cpu_count()))
    table = write_csv(pd.DataFrame(rows), args.out, float_format="%.6g")
    shown = table[["code", "law", "k_over_kc", "rtol", "n_samples", "err_sigma", "cpu_ms_min",
                   "cpu_ms_median", "cpu_ms_first_median"]]
    print(shown.to_string(index=False, float_format=lambda x: f"{x:.4g}"))
    if args.against:
        here, there = list(codes)
        a = table[table.code == here].reset_index(drop=True)
        b = table[table.code == there].reset_index(drop=True)
        ratio = a.cpu_ms_median / b.cpu_ms_median
        print(f"\nmedian CPU time, {here} / {there}: {ratio.min():.2f} to {ratio.max():.2f} "
              f"(geometric mean {float(ratio.prod() ** (1 / len(ratio))):.3f}); errors equal: "
              f"{bool((a.err_sigma == b.err_sigma).all())}")
    print(f"load average (1 min) {load_before[0]:.2f} before, {load_after[0]:.2f} after, "
          f"on {os.cpu_count()} CPUs; wrote {args.out}")


if __name__ == "__main__":
    main()
