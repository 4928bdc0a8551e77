"""What a user gets with no options: the default ``micro sweep`` against its targets.

Each row runs ``python -m micro sweep --k0 K --V ... --out CSV`` exactly as a user would
(a new process, the default method ``auto``), twice: first with an empty numba cache
(``NUMBA_CACHE_DIR`` a new folder: compile included), then again with that cache warm.
The compile time is the difference.  The rows' ``method`` and errors come from the CSV.

At k0 = 0.01, V = 4 the rows are also checked against an independent N-block simulation
(``micro.nblock.stick_slip_extrema_nblock``, N = 1e6 by default, its standard errors
beside it; computed once and kept in the CSV, ``--nblock 0`` skips it).

Targets (issue "micro: the best method answers by default"): ``--k0 0.01 --V 4`` in
10 s or less and within 2e-4 of the N-block; ``--k0 0.001 --V 40,70`` and ``--k0 0.0001
--V 400,700`` in 30 s or less each, compile included.

    python benchmarks/micro_defaults.py            # about 3 minutes on 2 cores, N-block included
    python benchmarks/micro_defaults.py --nblock 0

Writes benchmarks/results/micro_defaults.csv.
"""
from __future__ import annotations

import argparse
import os
import subprocess
import sys
import tempfile
from pathlib import Path

import pandas as pd

from _harness import RESULTS, Stopwatch, timed, warm_up, write_csv

CALLS = (("0.01", "4"), ("0.001", "40,70"), ("0.0001", "400,700"))


def _run(k0: str, V: str, cache: str) -> tuple[float, pd.DataFrame]:
    with tempfile.TemporaryDirectory() as tmp:
        out = Path(tmp) / "sweep.csv"
        env = dict(os.environ, NUMBA_CACHE_DIR=cache)
        sw = Stopwatch()
        subprocess.run([sys.executable, "-m", "micro", "sweep", "--k0", k0, "--V", V, "--out", str(out)],
                       check=True, env=env, stderr=subprocess.DEVNULL)
        return sw.seconds, pd.read_csv(out)


def _nblock(N: int) -> dict:
    import micro
    from micro.nblock import stick_slip_extrema_nblock

    warm_up(stick_slip_extrema_nblock, micro.Model(k0=0.01), 4.0, 100, n_cycles=3, n_discard=1)
    res, wall = timed(stick_slip_extrema_nblock, micro.Model(k0=0.01), 4.0, N, n_cycles=20, n_discard=10, seed=1)
    return {"nblock_N": N, "nblock_sigma_max": res.sigma_max, "nblock_sigma_max_stderr": res.sigma_max_stderr,
            "nblock_sigma_min": res.sigma_min, "nblock_sigma_min_stderr": res.sigma_min_stderr,
            "nblock_wall_s": wall}


def _kept_nblock(csv: Path) -> dict:
    """The N-block columns of an earlier run (``--nblock 0``: the reference does not depend
    on the default's code, so it is kept rather than dropped)."""
    if not csv.exists():
        return {}
    old = pd.read_csv(csv)
    if "nblock_sigma_max" not in old:
        return {}
    row = old[(old.k0 == 0.01) & (old.V == 4.0)].dropna(subset=["nblock_sigma_max"])
    if row.empty:
        return {}
    keys = ("nblock_N", "nblock_sigma_max", "nblock_sigma_max_stderr", "nblock_sigma_min",
            "nblock_sigma_min_stderr", "nblock_wall_s")
    return {k: float(row.iloc[0][k]) for k in keys}


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--nblock", type=int, default=1_000_000, help="N of the N-block check (0: skip)")
    args = ap.parse_args()
    load = os.getloadavg()[0]
    rows = []
    for k0, V in CALLS:
        with tempfile.TemporaryDirectory() as cache:
            cold, frame = _run(k0, V, cache)
            warm, _ = _run(k0, V, cache)
        for _, r in frame.iterrows():
            rows.append({"command": f"micro sweep --k0 {k0} --V {V}", "k0": float(k0), "V": r.V, "method": r.method,
                         "regime": r.regime, "sigma_max": r.sigma_max, "sigma_min": r.sigma_min,
                         "sigma_stderr": r.sigma_stderr, "discretisation_error": r.discretisation_error,
                         "converged": r.converged, "wall_s_cold": cold, "wall_s_warm": warm,
                         "compile_s": cold - warm, "load_before": load})
        print(f"micro sweep --k0 {k0} --V {V}: {cold:.1f} s cold, {warm:.1f} s warm "
              f"(methods {', '.join(frame.method)})", flush=True)
    out = pd.DataFrame(rows)
    csv = RESULTS / "micro_defaults.csv"
    ref = _nblock(args.nblock) if args.nblock > 0 else _kept_nblock(csv)
    if ref:
        at = (out.k0 == 0.01) & (out.V == 4.0)
        for key, value in ref.items():
            out.loc[at, key] = value
        out.loc[at, "gap_sigma_max"] = out.loc[at, "sigma_max"] - ref["nblock_sigma_max"]
        out.loc[at, "gap_sigma_min"] = out.loc[at, "sigma_min"] - ref["nblock_sigma_min"]
        print(f"N-block N = {ref['nblock_N']:.0f}: sigma_max {ref['nblock_sigma_max']:.6f} ± "
              f"{ref['nblock_sigma_max_stderr']:.1e}, sigma_min {ref['nblock_sigma_min']:.6f} ± "
              f"{ref['nblock_sigma_min_stderr']:.1e} ({ref['nblock_wall_s']:.0f} s"
              f"{'' if args.nblock > 0 else ', kept from the CSV'})", flush=True)
    write_csv(out, csv)
    print(out.to_string(index=False))


if __name__ == "__main__":
    main()
