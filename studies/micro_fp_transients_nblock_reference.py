"""N-block references for the Fokker-Planck transients (issue 53, item 4): the slide-hold-slide
peak against hold time, and the paper's Fig. 3 slow trace from a start.

The two share nothing with the Fokker-Planck solver but the parameters.  Every row is one
independent run (one seed of the pinning landscape); the test
(tests/micro/test_fp_transients_vs_nblock.py) takes the mean over seeds and its standard error.

Slide-hold-slide (``--what shs``), k0 = 0.3 (V^c = 0.195), V = 1: from the relaxed state, slide
for 20 time units (the steady stress is the mean of the binned stress over t in (10, 20]), then
for each hold time, from that state, hold (V = 0) and resume at V for 1 time unit; the peak is
the largest stress after resuming (the N-block's exact maximum within each bin of 0.002).
Rows: kind = "shs", N, seed, hold, sigma_steady, sigma_peak, delta_sigma_max.

Fig. 3 (``--what fig3``), k0 = 0.01, V = 0.001, from the relaxed state (the FP's default there):
the stress averaged over windows of +-25 time units around t = 250, 500, 1000, 2000, 3000,
5000, 6000, 7000 (the first slow shock comes near t = 8100).
Rows: kind = "fig3", N, seed, t, sigma.

Writes tests/data/micro_fp_transients_nblock.csv, its first line a comment giving the command,
the date and the commit.  With NUMBA_NUM_THREADS=1, on 2 shared cores:

    python -m studies micro_fp_transients_nblock_reference --N 10000,100000 --seeds 1-8   # ~10 minutes
"""
from __future__ import annotations

import argparse
import datetime
import subprocess
import sys

import pandas as pd

import micro
from benchmarks._harness import ROOT, Stopwatch, warm_up
from micro.nblock import simulate_nblock

CSV = ROOT / "tests" / "data" / "micro_fp_transients_nblock.csv"

SHS_K0, SHS_V = 0.3, 1.0
SHS_SLIDE, SHS_STEADY_FROM, SHS_RESUME = 20.0, 10.0, 1.0
SHS_HOLDS = (1.0, 3.0, 10.0)
SHS_BIN = 0.002

FIG3_K0, FIG3_V = 0.01, 0.001
FIG3_TIMES = (250.0, 500.0, 1000.0, 2000.0, 3000.0, 5000.0, 6000.0, 7000.0)
FIG3_HALF_WINDOW = 25.0
FIG3_BIN = 1.0


def shs_rows(N: int, seed: int) -> list[dict]:
    """One seed's slide-hold-slide: the steady stress and each hold's peak."""
    model = micro.Model(k0=SHS_K0)
    slide = simulate_nblock(model, [(SHS_SLIDE, SHS_V)], N, seed=seed, record_every=0.05)
    ts = slide.timeseries
    steady = float(ts.sigma_mean[(ts.t > SHS_STEADY_FROM + 1e-9)].mean())
    rows = []
    for hold in SHS_HOLDS:
        run = simulate_nblock(model, [(hold, 0.0), (SHS_RESUME, SHS_V)], N, seed=seed + 1000 * (1 + SHS_HOLDS.index(hold)),
                              record_every=SHS_BIN, initial=slide.final_state)
        after = run.timeseries[run.timeseries.t > hold + 1e-9]
        peak = float(after.sigma_max.max())
        rows.append(dict(kind="shs", N=N, seed=seed, hold=hold, sigma_steady=steady, sigma_peak=peak,
                         delta_sigma_max=peak - steady))
    return rows


def fig3_rows(N: int, seed: int) -> list[dict]:
    """One seed's Fig. 3 trace: window means of the stress at FIG3_TIMES."""
    model = micro.Model(k0=FIG3_K0)
    t_end = max(FIG3_TIMES) + 2.0 * FIG3_HALF_WINDOW
    ts = simulate_nblock(model, FIG3_V, N, t_max=t_end, seed=seed, record_every=FIG3_BIN).timeseries
    t, s = ts.t.to_numpy(), ts.sigma_mean.to_numpy()
    return [dict(kind="fig3", N=N, seed=seed, t=tc,
                 sigma=float(s[(t > tc - FIG3_HALF_WINDOW + 1e-9) & (t <= tc + FIG3_HALF_WINDOW + 1e-9)].mean()))
            for tc in FIG3_TIMES]


def _seeds(text: str) -> list[int]:
    if "-" in text:
        a, b = text.split("-")
        return list(range(int(a), int(b) + 1))
    return [int(s) for s in text.split(",") if s]


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--N", default="10000,100000", help="N-block sizes (comma-separated)")
    ap.add_argument("--seeds", default="1-8", help="seeds, 'a-b' or comma-separated")
    ap.add_argument("--what", default="shs,fig3", help="shs, fig3 or both")
    ap.add_argument("--out", default=str(CSV))
    args = ap.parse_args()
    whats = [w for w in args.what.split(",") if w]
    warm_up(simulate_nblock, micro.Model(k0=SHS_K0), [(1.0, SHS_V), (1.0, 0.0)], 1000)
    rows = []
    for N in (int(float(n)) for n in args.N.split(",") if n):
        for seed in _seeds(args.seeds):
            for what, fn in (("shs", shs_rows), ("fig3", fig3_rows)):
                if what not in whats:
                    continue
                with Stopwatch(cpu=True) as sw:
                    new = fn(N, seed)
                rows += new
                print(f"{what} N = {N} seed {seed}: {sw.seconds:.1f} CPU s; "
                      + ", ".join(f"{r.get('delta_sigma_max', r.get('sigma')):.6f}" for r in new), flush=True)
    commit = subprocess.run(["git", "-C", str(ROOT), "rev-parse", "--short", "HEAD"], capture_output=True,
                            text=True).stdout.strip()
    date = datetime.datetime.now(datetime.timezone.utc).strftime("%Y-%m-%d")
    command = "NUMBA_NUM_THREADS=1 python -m studies " + " ".join(["micro_fp_transients_nblock_reference"] + sys.argv[1:])
    frame = pd.DataFrame(rows)
    with open(args.out, "w") as fh:
        fh.write(f"# made by: {command}  (date {date}, commit {commit})\n")
        frame.to_csv(fh, index=False, float_format="%.9g")
    print(f"wrote {args.out} ({len(frame)} rows)")


if __name__ == "__main__":
    main()
