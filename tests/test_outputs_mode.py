"""Issue 39, row 7: every file that micro, rsf and compare write is left as a plain
``open(path, 'w')`` would leave it: a new file gets ``0o666 & ~umask`` (not mkstemp's
0600), an existing file keeps its mode, and a symbolic link stays a link whose target gets
the data."""
from __future__ import annotations

import os
import stat

import pandas as pd
import pytest

from compare.cache import PointCache
from compare.output import ReportFolder
from rsf.results import write_atomically


@pytest.fixture
def umask022():
    old = os.umask(0o022)
    try:
        yield
    finally:
        os.umask(old)


def _mode(path) -> int:
    return stat.S_IMODE(os.stat(path).st_mode)


def _rsf_write(path):
    write_atomically(path, lambda tmp: tmp.write_text("a,b\n1,2\n"))


def _micro_write(path):
    from micro.cli import _write_csv

    _write_csv(pd.DataFrame({"a": [1], "b": [2]}), path)


def _compare_write(path):
    folder = ReportFolder(path.parent)
    folder.write(path.name, lambda tmp: tmp.write_text("a,b\n1,2\n"))


WRITERS = {"rsf": _rsf_write, "micro": _micro_write, "compare": _compare_write}


@pytest.mark.parametrize("package", sorted(WRITERS))
def test_new_file_respects_the_umask(package, tmp_path, umask022):
    out = tmp_path / "out" / "new.csv"
    out.parent.mkdir()
    WRITERS[package](out)
    assert _mode(out) == 0o644
    assert out.read_text().startswith("a,b")


@pytest.mark.parametrize("package", sorted(WRITERS))
def test_existing_file_keeps_its_mode(package, tmp_path, umask022):
    out = tmp_path / "out" / "old.csv"
    out.parent.mkdir()
    if package == "compare":   # a folder that an earlier report wrote
        ReportFolder(out.parent).finish()
    out.write_text("old\n")
    os.chmod(out, 0o640)
    WRITERS[package](out)
    assert _mode(out) == 0o640
    assert out.read_text().startswith("a,b")


@pytest.mark.parametrize("package", sorted(WRITERS))
def test_symlink_is_written_through(package, tmp_path, umask022):
    real_dir = tmp_path / "real"
    real_dir.mkdir()
    target = real_dir / "target.csv"
    target.write_text("old\n")
    os.chmod(target, 0o600)
    link_dir = tmp_path / "out"
    link_dir.mkdir()
    if package == "compare":
        ReportFolder(link_dir).finish()
    link = link_dir / "link.csv"
    link.symlink_to(target)
    WRITERS[package](link)
    assert link.is_symlink() and os.readlink(link) == str(target)
    assert target.read_text().startswith("a,b")
    assert _mode(target) == 0o600
    assert not [p for p in real_dir.iterdir() if p.name != "target.csv"]   # no temporary left


def test_umask_077_gives_0600(tmp_path):
    old = os.umask(0o077)
    try:
        _rsf_write(tmp_path / "x.csv")
    finally:
        os.umask(old)
    assert _mode(tmp_path / "x.csv") == 0o600


def test_cache_records_respect_the_umask(tmp_path, umask022):
    cache = PointCache(tmp_path / "cache")
    key = "ab" * 32
    path = cache.put(key, {"key": key, "x": 1})
    assert _mode(path) == 0o644
    assert cache.get(key) == {"key": key, "x": 1} and len(cache) == 1


def test_cli_outputs_respect_the_umask(tmp_path, umask022, capsys):
    from rsf.cli import main

    out = tmp_path / "c.csv"
    assert main(["critical", "--k0", "0.1", "--out", str(out)]) == 0
    assert _mode(out) == 0o644
    link = tmp_path / "link.csv"
    link.symlink_to(out)
    os.chmod(out, 0o640)
    assert main(["critical", "--k0", "0.2", "--out", str(link)]) == 0
    assert link.is_symlink() and _mode(out) == 0o640 and pd.read_csv(out).k0[0] == 0.2
