"""Every rsf docs example runs (and writes its figure)."""
from __future__ import annotations

import runpy
import sys
from pathlib import Path

import pytest

EXAMPLES = sorted((Path(__file__).resolve().parents[2] / "docs" / "examples").glob("rsf_*.py"))


@pytest.mark.parametrize("path", EXAMPLES, ids=lambda p: p.name)
def test_example_runs(path, tmp_path, monkeypatch):
    out = tmp_path / "figure.png"
    monkeypatch.setattr(sys, "argv", [str(path), str(out), "--points", "12"])
    runpy.run_path(str(path), run_name="__main__")
    assert out.exists() and out.stat().st_size > 10_000


def test_there_is_an_example():
    assert EXAMPLES
