"""Issue 39 (reliability, round two), rsf's rows: each call of the issue's table behaves as
its last column says."""
from __future__ import annotations

import io
import logging
import os
import re

import numpy as np
import pandas as pd
import pytest

import rsf
from rsf.cli import build_parser, main


def _error_line(capsys) -> str:
    """The one line of a refused call (and nothing else on stderr)."""
    err = capsys.readouterr().err
    lines = err.strip().splitlines()
    assert len(lines) == 1, err
    assert lines[0].startswith("error: ") and "Traceback" not in err
    return lines[0]


# --- row 8: the same file twice ----------------------------------------------------------
def test_run_refuses_out_and_events_on_one_file(tmp_path, capsys, monkeypatch):
    out = tmp_path / "o.csv"
    argv = ["run", "--k0", "0.3", "--V", "0.05", "--t-end", "2"]
    assert main([*argv, "--out", str(out), "--events", str(out)]) == 2
    assert "--out and --events name the same file" in _error_line(capsys)
    assert not out.exists()                       # refused before anything was computed
    # the same file under another spelling: relative, or through a link
    monkeypatch.chdir(tmp_path)
    assert main([*argv, "--out", "o.csv", "--events", str(out)]) == 2
    link = tmp_path / "link.csv"
    link.symlink_to(out)
    assert main([*argv, "--out", str(link), "--events", "o.csv"]) == 2
    capsys.readouterr()
    assert main([*argv, "--out", "o.csv", "--events", "e.csv"]) == 0


# --- row 12: "wrote N rows" on stderr, stdout for data only ------------------------------
def test_wrote_rows_goes_to_stderr(tmp_path, capsys):
    out = tmp_path / "c.csv"
    assert main(["critical", "--k0", "0.1", "--out", str(out)]) == 0
    captured = capsys.readouterr()
    assert captured.out == ""
    assert f"wrote 1 rows to {out}" in captured.err
    assert main(["critical", "--k0", "0.1"]) == 0                 # to stdout: the CSV alone
    frame = pd.read_csv(io.StringIO(capsys.readouterr().out))
    assert list(frame.columns[:3]) == ["k0", "Dc", "Vc"]
