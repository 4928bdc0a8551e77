"""Every compare docs example (docs/examples/plot_compare_*.py) runs: the four figure
examples write their figure with the quick settings, the D_c example fits from scratch."""
from __future__ import annotations

from pathlib import Path

import pytest

EXAMPLES = sorted((Path(__file__).resolve().parents[2] / "docs" / "examples").glob("plot_compare_*.py"))
FIGURES = ("bifurcation", "hopf", "phase", "shs")


def test_there_is_one_example_per_figure():
    assert {p.stem for p in EXAMPLES} == {f"plot_compare_{n}" for n in FIGURES + ("fit_dc",)}


@pytest.mark.slow
@pytest.mark.parametrize("path", EXAMPLES, ids=lambda p: p.name)
def test_example_runs(path, run_example, tmp_path, monkeypatch):
    monkeypatch.setenv("COMPARE_CACHE_DIR", str(tmp_path.parent / "compare-examples-cache"))
    namespace, figures = run_example(path)
    assert figures and all(fig.axes and fig.axes[0].has_data() for fig in figures)
    name = path.stem.removeprefix("plot_compare_")
    if name in FIGURES:
        figure = Path(namespace["rep"].figures[name])
        assert figure.exists() and figure.stat().st_size > 10_000
    else:
        assert 0.01 < namespace["dc"].Dc < 0.5 and 0.01 < namespace["crit"].Dc < 0.5


@pytest.mark.parametrize("path", [p for p in EXAMPLES if p.stem.removeprefix("plot_compare_") in FIGURES],
                         ids=lambda p: p.name)
def test_example_runs_on_the_quick_reports_cache(path, quick_report, run_example, monkeypatch):
    # the cheap default version of test_example_runs: every micro point of the quick preset is
    # in the session's cache (tests/compare/conftest.py), so each example only redoes the RS
    # side, the fits and its figure (~2 s); its summary says that nothing was recomputed
    _, cache = quick_report
    monkeypatch.setenv("COMPARE_CACHE_DIR", str(cache))
    namespace, figures = run_example(path)
    assert figures and all(fig.axes and fig.axes[0].has_data() for fig in figures)
    rep = namespace["rep"]
    figure = Path(rep.figures[path.stem.removeprefix("plot_compare_")])
    assert figure.exists() and figure.stat().st_size > 10_000
    assert "(0 micro tasks computed" in rep.summary
