"""Issue 18's first-contact contract across the three command lines: bad input fails
before anything is computed (no solver entry point is called) with one line naming the
option, log lines have one format, and the report lists its unconverged points (not only
a log line)."""
from __future__ import annotations

import os
import re
import signal
import subprocess
import sys
from pathlib import Path

import pandas as pd
import pytest

ROOT = Path(__file__).resolve().parents[1]


def _main(package: str):
    return __import__(f"{package}.cli", fromlist=["main"]).main


#: Where each command line starts computing: the solver entry points its CLI calls (and,
#: for compare, the task runner behind every computation of the report), by module (micro's
#: command line imports them from their modules when a command runs, after its checks).
COMPUTE = {
    "micro": [("micro.api", ["critical_velocity", "simulate", "sweep"]), ("micro.renewal", ["steady_sliding"]),
              ("micro.branch", ["cycle_branch"])],
    "rsf": [("rsf.cli", ["critical_velocity", "simulate", "sweep"])],
    "compare": [("compare.report", ["Runner"])],
}


def _spy_on_computing(package: str, monkeypatch) -> list[str]:
    """Replace the package's entry points by spies that record the call and stop it."""
    import importlib

    calls: list[str] = []
    for module_name, names in COMPUTE[package]:
        module = importlib.import_module(module_name)
        for name in names:
            assert callable(getattr(module, name)), (module_name, name)  # the spy must replace something real

            def spy(*args, _name=name, **kwargs):
                calls.append(_name)
                raise RuntimeError(f"{_name} was called: bad input reached the computation")
            monkeypatch.setattr(module, name, spy)
    return calls


@pytest.mark.parametrize("package, argv, option", [
    ("micro", ["sweep", "--k0", "0.1", "--V", "5,nan", "--out", "x.csv"], "--V"),
    ("micro", ["critical", "--k0", "0.1,1e400", "--out", "x.csv"], "--k0"),
    ("micro", ["run", "--k0", "0.3", "--shs", "1", "50", "10", "20", "--out", ""], "--out"),
    ("micro", ["steady", "--k0", "0.1", "--V", "1", "--out", "/nonexistent-dir/x.csv"], "--out"),
    ("rsf", ["sweep", "--k0", "0.1", "--V-range", "0.1", "1", "1e9"], "--V-range"),
    ("rsf", ["run", "--k0", "0.3", "--V", "1", "--t-end", "1e12", "--out", "x.csv"], "--t-end"),
    ("rsf", ["sweep", "--k0", "1e300", "--V", "1"], "--k0"),
    ("compare", ["--quick", "--out", ""], "folder"),
    ("compare", ["--quick", "--out", "/proc/x"], "write"),
])
def test_bad_input_fails_before_computing_with_one_line(package, argv, option, tmp_path, monkeypatch, capsys):
    monkeypatch.chdir(tmp_path)
    monkeypatch.setenv("COMPARE_CACHE_DIR", str(tmp_path / "cache"))
    main = _main(package)
    calls = _spy_on_computing(package, monkeypatch)  # (was: under 1 s of wall clock)
    handler = signal.getsignal(signal.SIGTERM)  # compare's main installs its own
    try:
        try:
            code = main(argv)
        except SystemExit as exc:  # argparse-level errors exit from inside main
            code = exc.code
    finally:
        signal.signal(signal.SIGTERM, handler)
    err = capsys.readouterr().err.strip().splitlines()
    assert calls == [] and code == 2, (calls, code)
    assert option in err[-1] and "Traceback" not in "\n".join(err)
    assert not list(tmp_path.glob("*.csv")) and not (tmp_path / "cache").exists()


LEVEL_LINE = re.compile(r"^(DEBUG|INFO|WARNING|ERROR|CRITICAL)\b")
FORMAT = re.compile(r"^(DEBUG|INFO|WARNING|ERROR|CRITICAL) (micro|rsf|compare)(\.\w+)*: \S")


@pytest.mark.parametrize("argv", [
    # an unconverged Fokker-Planck run (warns) and an unconverged RS limit cycle (warns)
    ["micro", "sweep", "--k0", "0.3", "--V", "0.15", "--method", "fp", "--eps", "0.025", "--t-max", "2", "-v"],
    ["rsf", "-v", "sweep", "--k0", "0.3", "--V", "0.2029", "--max-cycles", "3", "--no-accelerate"],
])
def test_log_lines_have_one_format(argv, tmp_path):
    env = dict(os.environ, PYTHONPATH=str(ROOT), MPLBACKEND="Agg")
    proc = subprocess.run([sys.executable, "-m", *argv, "--out", str(tmp_path / "x.csv")], cwd=tmp_path, env=env,
                          capture_output=True, text=True, timeout=120)
    levelled = [line for line in proc.stderr.splitlines() if LEVEL_LINE.match(line)]
    assert any(line.startswith("WARNING") for line in levelled), proc.stderr
    assert all(FORMAT.match(line) for line in levelled), levelled
    assert "WARNING:" not in proc.stderr  # logging's default format, the second of the two formats seen


def test_summary_lists_every_unconverged_point():
    from compare.summary import _warnings

    points = pd.DataFrame({"k0": [0.1, 0.1, 0.3], "V": [0.2, 0.5, 0.1], "method": ["fp"] * 3,
                           "converged": [True, False, False], "error": ["", "", ""]})
    text = "\n".join(_warnings(None, {"micro_points": points}))
    assert text.startswith("## Warnings")
    assert "2 Fokker-Planck points" in text and "k0 = 0.1, V = 0.5" in text and "k0 = 0.3, V = 0.1" in text
    assert "V = 0.2" not in text


class _Interrupted(BaseException):
    pass


def _interrupting_writer(frame_or_path, *args, **kwargs):
    raise _Interrupted  # as if Ctrl-C arrived in the middle of writing


def test_writes_are_atomic_an_interrupted_write_leaves_the_old_file(tmp_path, monkeypatch):
    from compare.output import ReportFolder
    from micro.cli import _write_csv
    from rsf.cli import _write

    frame = pd.DataFrame({"a": [1.0, 2.0]})
    for write in (lambda out: _write_csv(frame, out), lambda out: _write(frame, str(out))):
        out = tmp_path / f"{id(write)}.csv"
        out.write_text("old\n")
        with monkeypatch.context() as m:
            m.setattr(pd.DataFrame, "to_csv", _interrupting_writer)
            with pytest.raises(_Interrupted):
                write(out)
        assert out.read_text() == "old\n"
        write(out)
        assert pd.read_csv(out).a.tolist() == [1.0, 2.0]
    folder = ReportFolder(tmp_path / "report")
    folder.write("t.csv", lambda p: p.write_text("old\n"))
    with pytest.raises(_Interrupted):
        folder.write("t.csv", _interrupting_writer)
    assert (tmp_path / "report" / "t.csv").read_text() == "old\n"
    assert not [p for p in tmp_path.rglob("*") if p.name.endswith(".tmp") or p.name.startswith(".t.csv")]


def test_micro_sweep_and_critical_report_each_point_as_it_finishes(tmp_path, capsys):
    # issue 18 item 6: micro's long commands were silent for minutes
    from micro.cli import main

    assert main(["sweep", "--k0", "0.1", "--V", "2,5", "--out", str(tmp_path / "s.csv")]) == 0
    # (without the progress lines, "micro sweep: row 1 of 2, V=2 [0 s]", printed once a row has
    # computed for 0.2 s: the first row's numba kernels load in 0.2-0.35 s where nothing before
    # in the process loaded them, which failed this test run alone on a loaded machine)
    lines = [line for line in capsys.readouterr().err.splitlines() if not line.startswith("micro sweep: ")]
    # the first point's line carries an ETA for the rest; the last one none
    assert re.match(r"^\[1/2, \d+ s, ETA \d+ s\] V=2: steady \(renewal\), sigma_max=0\.89", lines[0])
    assert re.match(r"^\[2/2, \d+ s\] V=5", lines[1])
    assert main(["critical", "--k0", "0.3,0.1", "--out", str(tmp_path / "c.csv"), "-v"]) == 0
    lines = [line for line in capsys.readouterr().err.splitlines() if line.startswith("[")]
    assert [line.split("]")[0] for line in lines][0].startswith("[1/2") and "k0=0.1: Vc=0.727504" in lines[1]


def test_rsf_takes_verbose_after_the_subcommand(tmp_path):
    # issue 18 item 6: '-v' was accepted only before the subcommand in rsf
    from rsf.cli import build_parser

    for argv in (["sweep", "--k0", "0.1", "--V", "1", "-v"], ["-v", "sweep", "--k0", "0.1", "--V", "1"]):
        assert build_parser().parse_args(argv).verbose is True
    assert build_parser().parse_args(["sweep", "--k0", "0.1", "--V", "1"]).verbose is False
