"""Issue 54, compare's rows D12, D17, D18 and D19: the cache folder is checked before
computing (writable, not the report folder), the interrupt message is true with
``--no-cache``, and an interrupted figure leaves no temporary file (a rerun removes the ones
an older run left).  Everything in ``tmp_path``; the CLI is called in-process, and every
refusal comes before any computation (the computing stage fails the test if reached)."""
from __future__ import annotations

import importlib
import os
import stat

import pytest

import compare
import compare.cli
from compare import figures
from compare.cache import check_cache_dir
from compare.output import MANIFEST, ReportFolder, check_folder

report_module = importlib.import_module("compare.report")  # (compare.report is also the function)
IS_ROOT = hasattr(os, "geteuid") and os.geteuid() == 0


@pytest.fixture
def no_computing(monkeypatch):
    """Fail the test if the report starts computing."""
    def computing(*args, **kwargs):
        raise AssertionError("the report started computing")

    monkeypatch.setattr(report_module, "_prefetch", computing)


def _main(argv, capsys):
    status = compare.cli.main(["--quick", "--no-progress", *argv])
    return status, capsys.readouterr().err


@pytest.mark.skipif(not os.path.isdir("/proc"), reason="needs /proc")
def test_d12_an_unwritable_cache_dir_is_refused_before_computing(tmp_path, capsys, no_computing):
    for cache in ("/proc/x", str(tmp_path / "file.csv" / "x")):
        (tmp_path / "file.csv").write_text("x\n")
        status, err = _main(["--out", str(tmp_path / "r"), "--cache-dir", cache], capsys)
        line, = err.strip().splitlines()
        assert status == 2 and line.startswith(f"error: --cache-dir '{cache}' "), err
        assert "not writable" in line or "not a folder" in line
    with pytest.raises(ValueError, match=r"^cache_dir '/proc/x' is not writable"):
        check_cache_dir("/proc/x")
    assert not (tmp_path / "r").exists()


@pytest.mark.skipif(IS_ROOT or not hasattr(os, "geteuid"), reason="root may write in a read-only folder")
def test_d12_a_read_only_cache_folder_is_refused(tmp_path, capsys, no_computing):
    locked = tmp_path / "locked"
    locked.mkdir()
    os.chmod(locked, 0o555)
    try:
        status, err = _main(["--out", str(tmp_path / "r"), "--cache-dir", str(locked / "cache")], capsys)
    finally:
        os.chmod(locked, 0o755)
    assert status == 2 and f"--cache-dir '{locked / 'cache'}' is not writable" in err


def test_d19_the_cache_in_the_report_folder_is_refused_before_computing(tmp_path, capsys, no_computing):
    folder = tmp_path / "D"
    for cache, where in ((folder, "is the report folder"), (folder / "cache", "is inside the report folder")):
        status, err = _main(["--out", str(folder), "--cache-dir", str(cache)], capsys)
        line, = err.strip().splitlines()
        assert status == 2 and line.startswith(f"error: --cache-dir '{cache}' {where} --out"), err
    assert not folder.exists()
    # the same through a symbolic link, and from the API (naming its parameters)
    folder.mkdir()
    (tmp_path / "link").symlink_to(folder)
    with pytest.raises(ValueError, match=r"^cache_dir '.*link' is the report folder out"):
        compare.report(compare.Settings.quick(), out=folder, cache_dir=tmp_path / "link", progress=False)
    # without the cache there is nothing to refuse; a cache beside the report is fine
    check_cache_dir(tmp_path / "cache", folder)


def test_d17_the_interrupt_message_is_true(tmp_path, capsys, monkeypatch):
    def interrupted(*args, **kwargs):
        raise KeyboardInterrupt

    monkeypatch.setattr(compare.cli, "report", interrupted)
    status, err = _main(["--out", str(tmp_path / "r"), "--no-cache"], capsys)
    assert status == 130 and "in the cache" not in err and "--no-cache" in err and "nothing was kept" in err
    status, err = _main(["--out", str(tmp_path / "r"), "--cache-dir", str(tmp_path / "c")], capsys)
    assert status == 130 and "the finished micro points are in the cache" in err


def _hidden(folder):
    return sorted(p.name for p in folder.iterdir() if p.name.startswith(".") and p.name != MANIFEST)


def test_d18_a_figure_interrupted_while_drawn_leaves_no_temporary_file(tmp_path):
    folder = ReportFolder(tmp_path / "R")

    def drawn_here_then_interrupted(fn, *args):  # (no pool: Runner.submit draws in this process)
        raise KeyboardInterrupt

    painter = figures.Painter(folder, drawn_here_then_interrupted)
    with pytest.raises(KeyboardInterrupt):
        painter.submit("phase_diagram", (1, 2), "phase.png")
    painter.discard()
    assert _hidden(folder.path) == []


def test_d18_a_rerun_removes_the_temporary_files_an_interrupted_one_left(tmp_path):
    path = tmp_path / "R"
    ReportFolder(path).finish()
    stale = [".phase.png.abc_123.png", ".phase.png.k3j4h5g6.png", "..compare-report.json.zz_x9k2a.json",
             ".compare-probe-abcdefgh", ".summary.md.a1b2c3d4.tmp", ".table.csv.q1w2e3r4.csv"]
    kept = [".keep", ".phase.png.short.png", ".phase.png.abcdefgh.csv", "phase.png", "notes.txt"]
    for name in stale + kept:
        (path / name).write_text("x")
    stale.remove(".phase.png.abc_123.png")    # (seven characters: not mkstemp's)
    kept.append(".phase.png.abc_123.png")
    ReportFolder(path)
    assert sorted(p.name for p in path.iterdir() if p.name != MANIFEST) == sorted(kept)


def test_an_earlier_reports_file_that_may_not_be_replaced_is_refused_upfront(tmp_path):
    path = tmp_path / "R"
    folder = ReportFolder(path)
    folder.write("summary.md", lambda p: p.write_text("earlier\n"))
    folder.finish()
    os.chmod(path / "summary.md", 0o444)
    if IS_ROOT:
        os.chown(path / "summary.md", 4321, 4321)
    with pytest.raises(ValueError, match=r"^out '.*R': the earlier report's file '.*summary\.md' is .*0444"):
        check_folder(path)
    assert (path / "summary.md").read_text() == "earlier\n" and stat.S_IMODE(os.stat(path / "summary.md").st_mode) == 0o444
