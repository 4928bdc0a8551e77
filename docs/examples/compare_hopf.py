"""The transition near V^c: micro's growth rate of the unstable mode, and both models' amplitude against (Vc - V)/Vc (each its own exact Vc), with fitted exponents.

    python docs/examples/compare_hopf.py [OUT_DIR] [--quick]

Writes OUT_DIR/hopf.png (default docs/figures/compare) with its CSV tables and summary.md.
Micro results are cached on disk ($COMPARE_CACHE_DIR), so a second run is instant.
"""
from __future__ import annotations

import argparse
import os
import sys

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", ".."))

import compare  # noqa: E402


def main(argv: list[str] | None = None) -> str:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("out", nargs="?", default=os.path.join(
        os.path.dirname(os.path.abspath(__file__)), "..", "figures", "compare"))
    parser.add_argument("--quick", action="store_true", help="few coarse points (a smoke run)")
    args = parser.parse_args(argv)

    settings = compare.Settings.quick() if args.quick else compare.Settings.default()
    rep = compare.report(settings, scenarios=["hopf"], out=args.out, progress=False)
    print(rep.summary)
    return str(rep.figures["hopf"])


if __name__ == "__main__":
    print("wrote", main())
