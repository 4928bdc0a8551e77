"""Every micro docs example (docs/examples/plot_micro_*.py) runs and draws its figures."""
from __future__ import annotations

from pathlib import Path

import pytest

EXAMPLES = sorted((Path(__file__).resolve().parents[2] / "docs" / "examples").glob("plot_micro_*.py"))
# the Fokker-Planck examples take 3-10 s each (coarse bin); the direct solver's takes about one
FAST = {"plot_micro_steady_branch.py"}


def test_there_is_one_example_per_task():
    assert {p.stem for p in EXAMPLES} == {f"plot_micro_{n}" for n in
                                          ("steady_branch", "stick_slip", "sweep", "slide_hold_slide")}


@pytest.mark.parametrize("path", [p if p.name in FAST else pytest.param(p, marks=pytest.mark.slow) for p in EXAMPLES],
                         ids=lambda p: p.name)
def test_example_runs(path, run_example):
    namespace, figures = run_example(path)
    assert figures and all(fig.axes and fig.axes[0].has_data() for fig in figures)
    if path.stem == "plot_micro_steady_branch":
        assert namespace["vc"].status == "converged" and abs(namespace["vc"].Vc - 0.72750434) < 1e-7
    if path.stem == "plot_micro_stick_slip":
        assert namespace["cycle"].regime == "stick-slip" and namespace["cycle"].converged
    if path.stem == "plot_micro_sweep":
        assert set(namespace["table"].regime) == {"stick-slip", "steady"}
    if path.stem == "plot_micro_slide_hold_slide":
        assert namespace["peaks"].delta_sigma_max.is_monotonic_increasing
