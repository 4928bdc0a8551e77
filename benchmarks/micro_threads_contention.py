"""k copies of one micro computation at once: does each cost at most about k times one alone?

Two workloads, each in its own process, ``k`` = 1, 2, 3 of them started together:

* ``cohort``: ``micro.stationary(micro.Model(k0=0.01), 4.0, method="cohort")``, a stick-slip
  cycle by the cohort method (numba's parallel kernels, issue 39 row 13);
* ``renewal``: ``micro.steady_sliding(micro.Model(k0=0.1), np.logspace(-1, 3, 100))``, the
  steady branch with growth rates (thousands of small BLAS solves, row 6).

Compilation is apart: for each variant one process first runs each workload once (it
fills numba's disk cache; its time is the ``compile`` row).  Then each copy imports
micro, says it is ready, and waits; when all ``k`` are ready they are released at once
and each times the call alone (wall and CPU seconds; loading the kernels from the disk
cache, a fraction of a second, is in it, as in any run).  The machine's load is written
beside each batch: the 1-minute load average when the batch starts and ends, and how
many threads of other processes were running or waiting for a processor as it started
(``others_runnable``).

Variants (``--variant LABEL [VAR=VALUE ...]``, repeatable) are environments for the
copies: another checkout first on ``PYTHONPATH``, or numba's and OpenMP's variables.
Their batches are interleaved (repeat by repeat, k by k, variant by variant) so that a
drift of the background load falls on all of them alike.  Without ``--variant``: this
environment alone, labelled ``current``.

    python benchmarks/micro_threads_contention.py                    # about 2 minutes alone
    python benchmarks/micro_threads_contention.py --workloads cohort \
        --variant after PYTHONPATH=/path/to/new --variant before PYTHONPATH=/path/to/old \
        --variant "before, 1 thread" PYTHONPATH=/path/to/old NUMBA_NUM_THREADS=1

Rows go to ``benchmarks/results/micro_threads_contention.csv`` (``--append`` keeps the
rows of other (variant, workload) pairs); the env column leaves ``PYTHONPATH`` out.
"""
from __future__ import annotations

import argparse
import json
import os
import subprocess
import sys
import time
from pathlib import Path

import pandas as pd

from _harness import RESULTS, Stopwatch, write_csv

OUT = RESULTS / "micro_threads_contention.csv"

WORKLOADS = {
    "cohort": 'micro.stationary(micro.Model(k0=0.01), 4.0, method="cohort")',
    "renewal": "micro.steady_sliding(micro.Model(k0=0.1), np.logspace(-1, 3, 100))",
}

# Each copy times itself (wall and CPU around the call alone): it runs in a fresh
# interpreter with the variant's PYTHONPATH, where the harness (_harness) is not importable.
CHILD = r"""
import json, os, sys, time
t0 = time.perf_counter()
import numpy as np
import micro
import numba
t1 = time.perf_counter()
print(json.dumps({"ready": True, "import_s": t1 - t0}), flush=True)
if sys.stdin.readline().strip() != "go":
    sys.exit(1)
c0, w0 = time.process_time(), time.perf_counter()
CALL
w1, c1 = time.perf_counter(), time.process_time()
print(json.dumps({"wall_s": w1 - w0, "cpu_s": c1 - c0, "import_s": t1 - t0,
                  "numba_threads_after": numba.get_num_threads()}), flush=True)
"""


def _load() -> tuple[float, int]:
    """The 1-minute load average, and the threads of other processes running or waiting
    for a processor now (the machine's runnable count less this one; Linux)."""
    try:
        with open("/proc/loadavg") as f:
            fields = f.read().split()
        return float(fields[0]), int(fields[3].split("/")[0]) - 1
    except (OSError, ValueError, IndexError):
        return os.getloadavg()[0], -1


def batch(workload: str, k: int, env: dict[str, str], timeout: float) -> list[dict]:
    """``k`` copies of ``workload`` released together; a dict per copy."""
    code = CHILD.replace("CALL", WORKLOADS[workload])
    procs = [subprocess.Popen([sys.executable, "-c", code], stdin=subprocess.PIPE, stdout=subprocess.PIPE,
                              text=True, env=env) for _ in range(k)]
    try:
        for p in procs:
            line = p.stdout.readline()
            if not line or not json.loads(line).get("ready"):
                raise RuntimeError(f"a copy of {workload} did not start (exit {p.wait()})")
        load1, runnable = _load()
        for p in procs:
            p.stdin.write("go\n")
            p.stdin.flush()
        rows = []
        deadline = time.monotonic() + timeout
        for i, p in enumerate(procs):
            out, _ = p.communicate(timeout=max(1.0, deadline - time.monotonic()))
            rec = json.loads(out.strip().splitlines()[-1])
            rows.append({"workload": workload, "phase": "run", "k": k, "copy": i + 1, "wall_s": rec["wall_s"],
                         "cpu_s": rec["cpu_s"], "numba_threads_after": rec["numba_threads_after"],
                         "load1_start": load1, "others_runnable": runnable})
        load1_end, _ = _load()
        for r in rows:
            r["load1_end"] = load1_end
        return rows
    finally:
        for p in procs:
            if p.poll() is None:
                p.kill()
                p.wait()


def compile_once(workload: str, env: dict[str, str]) -> dict:
    """One process runs ``workload`` once: numba compiles what its disk cache lacks."""
    load1, runnable = _load()
    sw = Stopwatch()
    subprocess.run([sys.executable, "-c", f"import numpy as np, micro; {WORKLOADS[workload]}"], check=True, env=env)
    return {"workload": workload, "phase": "compile", "k": 1, "copy": 1, "wall_s": sw.seconds,
            "load1_start": load1, "others_runnable": runnable, "load1_end": _load()[0]}


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--variant", nargs="+", action="append", metavar=("LABEL", "VAR=VALUE"),
                    help="a label and the environment variables of its copies (repeatable)")
    ap.add_argument("--k", default="1,2,3", help="numbers of copies at once (default 1,2,3)")
    ap.add_argument("--repeats", type=int, default=3, help="batches of each k and variant (default 3)")
    ap.add_argument("--workloads", default="cohort,renewal", help="of: " + ", ".join(WORKLOADS))
    ap.add_argument("--timeout", type=float, default=900.0, help="seconds for one batch (default 900)")
    ap.add_argument("--out", type=Path, default=OUT)
    ap.add_argument("--append", action="store_true", help="keep the rows of other variants and workloads in --out")
    args = ap.parse_args()
    ks = [int(x) for x in args.k.split(",")]
    workloads = args.workloads.split(",")
    for w in workloads:
        if w not in WORKLOADS:
            ap.error(f"--workloads: unknown {w!r} (known: {', '.join(WORKLOADS)})")
    variants: list[tuple[str, dict[str, str], str]] = []
    for label, *assignments in args.variant or [["current"]]:
        env, shown = dict(os.environ), []
        for a in assignments:
            var, eq, value = a.partition("=")
            if not eq or not var:
                ap.error(f"--variant {label}: expected VAR=VALUE, got {a!r}")
            env[var] = value
            if var != "PYTHONPATH":
                shown.append(a)
        variants.append((label, env, " ".join(shown)))
    rows: list[dict] = []

    def add(new: list[dict], label: str, shown: str, rep: int | None) -> None:
        for r in new:
            r.update(label=label, env=shown, repeat=rep)
        rows.extend(new)

    for w in workloads:
        for label, env, shown in variants:
            add([compile_once(w, env)], label, shown, None)
            print(f"{w} [{label}]: compile and first run {rows[-1]['wall_s']:.1f} s", flush=True)
        for rep in range(1, args.repeats + 1):
            for k in ks:
                turn = rep + k  # the variants' order turns from batch to batch
                for label, env, shown in variants[turn % len(variants):] + variants[:turn % len(variants)]:
                    got = batch(w, k, env, args.timeout)
                    add(got, label, shown, rep)
                    print(f"{w} [{label}] k={k} repeat {rep}: " + ", ".join(f"{r['wall_s']:.2f}" for r in got)
                          + f" s (load {got[0]['load1_start']:.2f}, {got[0]['others_runnable']} other threads "
                          "runnable)", flush=True)
    frame = pd.DataFrame(rows).reindex(columns=["label", "workload", "phase", "k", "repeat", "copy", "wall_s",
                                                "cpu_s", "load1_start", "load1_end", "others_runnable",
                                                "numba_threads_after", "env"])
    frame.insert(1, "date", time.strftime("%Y-%m-%d %H:%M"))
    for col in ("repeat", "numba_threads_after"):
        frame[col] = frame[col].astype("Int64")
    if args.append and args.out.exists():
        old = pd.read_csv(args.out)
        done = set(zip(frame["label"], frame["workload"]))
        old = old[[pair not in done for pair in zip(old["label"], old["workload"])]]
        frame = pd.concat([old, frame], ignore_index=True)
    write_csv(frame, args.out)
    # the verdict: a copy's median wall time at k at once, against k times one alone
    runs = frame[frame["phase"] == "run"]
    for w in workloads:
        for label, _, _ in variants:
            sub = runs[(runs["workload"] == w) & (runs["label"] == label)]
            one = sub[sub["k"] == 1]["wall_s"].median() if (sub["k"] == 1).any() else float("nan")
            for k in ks:
                part = sub[sub["k"] == k]
                print(f"{w} [{label}] k={k}: median {part['wall_s'].median():.2f} s per copy "
                      f"(min {part['wall_s'].min():.2f}, max {part['wall_s'].max():.2f}; CPU "
                      f"{part['cpu_s'].median():.2f} s), {part['wall_s'].median() / one:.2f} x one alone "
                      f"(target <= {k}); background: load {part['load1_start'].median():.1f}, "
                      f"{part['others_runnable'].median():.0f} other threads runnable")
    print(f"wrote {args.out}")


if __name__ == "__main__":
    main()
