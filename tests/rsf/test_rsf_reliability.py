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


# --- rows 2 and 3: the table law's file and --table-where ---------------------------------
@pytest.fixture
def table(tmp_path):
    path = tmp_path / "table.csv"
    V = [0.01, 0.1, 1.0, 10.0, 100.0]
    pd.DataFrame({"V": V, "sigma": rsf.HyperbolicLaw(mu_inf=0.9).mu_ss(V), "k0": [0.1, 0.1, 0.2, 0.1, 0.1],
                  "regime": ["steady", "stick-slip", "steady", "steady", "steady"]}).to_csv(path, index=False)
    return path


@pytest.mark.parametrize("extra, match", [
    (["--table", "/nope.csv"], r"--table '/nope.csv' cannot be read \(No such file"),
    (["--table", "{tmp}"], r"--table '.*' is a folder"),
    (["--table", "/dev/null"], r"--table '/dev/null' is not a readable CSV file"),
    (["--table", "{table}", "--table-where", "V >>> 1"], r"--table-where 'V >>> 1' is not a valid expression"),
    (["--table", "{table}", "--table-where", "V > 1e9"], r"has 0 row\(s\) after --table-where"),
    (["--table", "{table}", "--table-where", "W > 1"], r"--table-where 'W > 1': no column 'W'"),
    (["--table", "{table}", "--table-where", "regime > 1"], r"--table-where 'regime > 1' cannot be evaluated"),
    (["--table", "{table}", "--table-v-column", "W"], r"--table-v-column: column 'W' not in"),
    (["--table", "{table}", "--table-mu-column", "regime"], r"--table-mu-column: column 'regime' .* must hold numbers"),
])
def test_table_problems_are_one_line_and_exit_2(extra, match, table, tmp_path, capsys):
    extra = [x.format(tmp=tmp_path, table=table) for x in extra]
    assert main(["sweep", "--k0", "0.3", "--V", "1", "--law", "table", *extra]) == 2
    assert re.search(match, _error_line(capsys))


@pytest.mark.parametrize("where", [
    "@pd.io.common.os.system('touch {marker}')",
    "__import__('os').system('touch {marker}') == 0",
    "V.__class__.__init__.__globals__ > 1",
    "V[0] > 1",
    "V @ V > 1",
    "(lambda: open('{marker}', 'w'))() is None",
    "[c for c in V] == 1",
    "V",
])
def test_table_where_refuses_everything_but_column_comparisons(where, table, tmp_path, capsys):
    marker = tmp_path / "marker"
    where = where.format(marker=marker)
    assert main(["sweep", "--k0", "0.3", "--V", "1", "--law", "table", "--table", str(table),
                 "--table-where", where]) == 2
    assert _error_line(capsys).startswith("error: --table-where")
    assert not marker.exists()


def test_table_where_keeps_the_rows_of_column_comparisons(table, monkeypatch):
    # evaluated by rsf on the columns: neither pandas' query nor eval is ever called
    def forbidden(*args, **kwargs):
        raise AssertionError("pandas evaluated the expression")

    monkeypatch.setattr(pd.DataFrame, "query", forbidden)
    monkeypatch.setattr(pd.DataFrame, "eval", forbidden)
    monkeypatch.setattr(pd, "eval", forbidden)
    frame = pd.read_csv(table)
    keep = {
        "V > 1": [10.0, 100.0],
        "k0 == 0.1 and V < 3": [0.01, 0.1],
        "regime == 'steady'": [0.01, 1.0, 10.0, 100.0],
        "0.05 < V <= 10": [0.1, 1.0, 10.0],
        "not (V > 0.5) or k0 > 0.15": [0.01, 0.1, 1.0],
        "regime in ['stick-slip'] or V * 10 >= 1000": [0.1, 100.0],
        "-V < -50": [100.0],
    }
    for where, V in keep.items():
        assert list(rsf.laws.select_rows(frame, where).V) == V, where
    law = rsf.TabulatedLaw.from_csv(table, where="regime == 'steady'")
    assert list(law.V) == [0.01, 1.0, 10.0, 100.0]


def test_table_options_need_the_table_law(table, capsys):
    assert main(["sweep", "--k0", "0.3", "--V", "1", "--table", str(table)]) == 2
    assert "--table is for --law table" in _error_line(capsys)
    assert main(["sweep", "--k0", "0.3", "--V", "1", "--law", "log", "--table-where", "V > 1"]) == 2
    assert "--table-where is for --law table" in _error_line(capsys)
