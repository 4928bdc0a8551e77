"""Every rsf docs example (docs/examples/plot_rsf_*.py) runs and draws its figures."""
from __future__ import annotations

from pathlib import Path

import pytest

EXAMPLES = sorted((Path(__file__).resolve().parents[2] / "docs" / "examples").glob("plot_rsf_*.py"))


def test_there_is_one_example_per_task():
    assert {p.stem for p in EXAMPLES} == {f"plot_rsf_{n}" for n in
                                          ("bifurcation", "stability", "stick_slip", "protocol")}


@pytest.mark.parametrize("path", EXAMPLES, ids=lambda p: p.name)
def test_example_runs(path, run_example):
    namespace, figures = run_example(path)
    assert figures and all(fig.axes and fig.axes[0].has_data() for fig in figures)
    if path.stem == "plot_rsf_stick_slip":
        assert namespace["cycle"].converged and abs(namespace["fit"].exponent - 0.5) < 1e-3
