"""Every compare docs example runs (quick settings) and writes its figure."""
from __future__ import annotations

import runpy
import sys
from pathlib import Path

import pytest

EXAMPLES = sorted((Path(__file__).resolve().parents[2] / "docs" / "examples").glob("compare_*.py"))


def test_there_is_one_example_per_figure():
    assert {p.stem for p in EXAMPLES} == {f"compare_{n}" for n in ("bifurcation", "hopf", "phase", "shs")}


@pytest.mark.slow
@pytest.mark.parametrize("path", EXAMPLES, ids=lambda p: p.name)
def test_example_runs(path, tmp_path, monkeypatch):
    monkeypatch.setenv("COMPARE_CACHE_DIR", str(tmp_path.parent / "compare-examples-cache"))
    monkeypatch.setattr(sys, "argv", [str(path), str(tmp_path), "--quick"])
    runpy.run_path(str(path), run_name="__main__")
    figure = tmp_path / (path.stem.removeprefix("compare_") + ".png")
    assert figure.exists() and figure.stat().st_size > 10_000


@pytest.mark.parametrize("path", EXAMPLES, ids=lambda p: p.name)
def test_example_runs_on_the_quick_reports_cache(path, quick_report, tmp_path, monkeypatch, capsys):
    # the cheap default version of test_example_runs: every micro point of the quick preset is
    # in the session's cache (tests/compare/conftest.py), so each example only redoes the RS
    # side, the fits and its figure (~2 s); its summary says that nothing was recomputed
    _, cache = quick_report
    monkeypatch.setenv("COMPARE_CACHE_DIR", str(cache))
    monkeypatch.setattr(sys, "argv", [str(path), str(tmp_path), "--quick"])
    runpy.run_path(str(path), run_name="__main__")
    figure = tmp_path / (path.stem.removeprefix("compare_") + ".png")
    assert figure.exists() and figure.stat().st_size > 10_000
    assert "(0 micro tasks computed" in capsys.readouterr().out
