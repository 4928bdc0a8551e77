"""Interruptions: a PointCache write cut short (an exception at each step of the atomic write,
a SIGKILL in the middle of writing the data) leaves no entry that reads back corrupt, and
``python -m compare`` killed with SIGKILL mid-run resumes from its cache with fewer tasks and
writes the tables an uninterrupted run writes."""
from __future__ import annotations

import csv
import json
import os
import pathlib
import re
import signal
import subprocess
import sys
import time

import pytest

from compare.cache import PointCache

OLD = {"key": "ab" * 32, "result": {"k0": 0.1, "V": 2.0, "sigma_mean": 0.9, "regime": "steady"}}
NEW = {"key": "ab" * 32, "result": {"k0": 0.1, "V": 2.0, "sigma_mean": 0.8, "regime": "stick-slip",
                                    "history": list(range(2000))}}
FRESH = {"key": "cd" * 32, "result": {"k0": 0.3, "V": 1.0, "sigma_mean": 0.7}}


def _files(directory: pathlib.Path) -> list[str]:
    return sorted(str(p.relative_to(directory)) for p in directory.rglob("*") if p.is_file())


def _half_then(exc):
    """A Path.write_text that writes half of the text, then raises ``exc``."""
    real = pathlib.Path.write_text

    def write_text(self, text, *args, **kwargs):
        real(self, text[: len(text) // 2], *args, **kwargs)
        raise exc

    return write_text


@pytest.mark.parametrize("where", ["data", "fsync", "rename"])
def test_interrupted_cache_write_leaves_the_old_record_or_none(tmp_path, monkeypatch, where):
    cache = PointCache(tmp_path)
    cache.put(OLD["key"], OLD)
    before = _files(tmp_path)
    if where == "data":
        monkeypatch.setattr(pathlib.Path, "write_text", _half_then(KeyboardInterrupt()))
        exc = KeyboardInterrupt
    else:
        def fail(*args, **kwargs):
            raise OSError(28, "No space left on device")
        monkeypatch.setattr(os, "fsync" if where == "fsync" else "replace", fail)
        exc = OSError
    for record in (NEW, FRESH):            # an overwrite and a new key, both cut short
        with pytest.raises(exc):
            cache.put(record["key"], record)
    monkeypatch.undo()
    assert _files(tmp_path) == before      # the temporary files are gone, nothing else written
    reader = PointCache(tmp_path)
    assert reader.get(OLD["key"]) == OLD   # the old record, whole
    assert reader.get(FRESH["key"]) is None and FRESH["key"] not in reader
    assert len(reader) == 1 and (reader.hits, reader.misses) == (1, 1)
    reader.put(NEW["key"], NEW)            # and the next write goes through
    reader.put(FRESH["key"], FRESH)
    assert PointCache(tmp_path).get(NEW["key"]) == NEW and PointCache(tmp_path).get(FRESH["key"]) == FRESH


@pytest.mark.skipif(not hasattr(os, "fork"), reason="forks a writer to kill")
def test_cache_write_killed_in_the_middle_of_the_data(tmp_path):
    """A process SIGKILLed halfway through writing a record (no clean-up runs) leaves half a
    JSON in its temporary file, which no reader takes for a record: the old one is read back.
    (The writer is a fork of this process, not a new interpreter: a new one spends 2 s
    importing compare.)"""
    PointCache(tmp_path).put(OLD["key"], OLD)
    pid = os.fork()
    if pid == 0:                           # the writer: killed in the middle of the data
        try:
            real = pathlib.Path.write_text

            def write_text(self, text, *args, **kwargs):
                real(self, text[: len(text) // 2], *args, **kwargs)
                os.kill(os.getpid(), signal.SIGKILL)

            pathlib.Path.write_text = write_text
            PointCache(tmp_path).put(OLD["key"], NEW)
        finally:
            os._exit(3)                    # only if it was not killed
    deadline = time.monotonic() + 60
    while (done := os.waitpid(pid, os.WNOHANG))[0] == 0 and time.monotonic() < deadline:
        time.sleep(0.01)
    if done[0] == 0:
        os.kill(pid, signal.SIGKILL)
        os.waitpid(pid, 0)
        pytest.fail("the writer hung")
    assert os.WIFSIGNALED(done[1]) and os.WTERMSIG(done[1]) == signal.SIGKILL
    leftovers = [p for p in tmp_path.rglob("*") if p.is_file() and p.name.endswith(".tmp")]
    assert len(leftovers) == 1                       # killed while writing the data
    with pytest.raises(ValueError):
        json.loads(leftovers[0].read_text())         # half a record
    cache = PointCache(tmp_path)
    assert len(cache) == 1 and cache.get(OLD["key"]) == OLD
    cache.put(OLD["key"], NEW)
    assert PointCache(tmp_path).get(OLD["key"]) == NEW


# ------------------------------------------------------------------------------------------------
# the report, killed and resumed
# ------------------------------------------------------------------------------------------------
def _records(cache: pathlib.Path) -> list[pathlib.Path]:
    return sorted(cache.glob("??/*.json"))


def _children(pid: int) -> list[int]:
    out = []
    for task in pathlib.Path(f"/proc/{pid}/task").glob("*"):
        try:
            out += [int(c) for c in (task / "children").read_text().split()]
        except OSError:
            pass
    return out


def _alive(pid: int) -> bool:
    try:
        stat = pathlib.Path(f"/proc/{pid}/stat").read_text()
    except OSError:
        return False
    return stat.rsplit(")", 1)[1].split()[0] != "Z"


def _table(path: pathlib.Path) -> list[list[str]]:
    """A CSV's cells as written, but for the column of each task's compute time."""
    with open(path, newline="") as fh:
        rows = list(csv.reader(fh))
    keep = [i for i, name in enumerate(rows[0]) if name != "wall_time"]
    return [[row[i] for i in keep] for row in rows]


def _counts(folder: pathlib.Path) -> tuple[int, int]:
    """(tasks computed, tasks from the cache) from the first lines of summary.md."""
    m = re.search(r"\((\d+) micro tasks computed, (\d+) from the cache", (folder / "summary.md").read_text())
    assert m, (folder / "summary.md").read_text()[:500]
    return int(m.group(1)), int(m.group(2))


@pytest.mark.slow
@pytest.mark.skipif(not sys.platform.startswith("linux"), reason="reads the workers' pids from /proc")
def test_report_killed_mid_run_resumes_with_fewer_tasks_and_the_same_tables(tmp_path):
    """``python -m compare --quick --scenario shs`` (17 micro tasks) on two workers, SIGKILLed
    once 8 records are in its cache: its workers die with it, every record it left reads back,
    the rerun computes only the missing tasks, and its tables are those of a run with no
    cache (cell for cell but for the tasks' compute times; summary.md but for its line of timings)."""
    from compare.tasks import code_version

    version = code_version.__wrapped__()   # micro's sources now (the cache keys depend on them)
    cache = tmp_path / "cache"
    base = [sys.executable, "-m", "compare", "--quick", "--scenario", "shs", "--workers", "2", "--no-progress"]
    with open(tmp_path / "first.log", "w") as log:
        first = subprocess.Popen(base + ["--cache-dir", str(cache), "--out", str(tmp_path / "first")],
                                 stdout=log, stderr=subprocess.STDOUT)
        try:
            deadline = time.monotonic() + 600
            while first.poll() is None and len(_records(cache)) < 8 and time.monotonic() < deadline:
                time.sleep(0.02)
            assert first.poll() is None, ("the report ended before it could be killed:\n"
                                          + (tmp_path / "first.log").read_text()[-2000:])
            workers = _children(first.pid)
            first.send_signal(signal.SIGKILL)
            assert first.wait(timeout=60) == -signal.SIGKILL
        finally:
            if first.poll() is None:
                first.kill()
                first.wait()
    assert workers, "no pool workers seen"
    deadline = time.monotonic() + 30
    while any(_alive(p) for p in workers) and time.monotonic() < deadline:
        time.sleep(0.1)
    assert not any(_alive(p) for p in workers), "pool workers outlived their killed parent"
    manifest = tmp_path / "first" / ".compare-report.json"
    assert not manifest.exists() or json.loads(manifest.read_text())["complete"] is False
    left = _records(cache)
    reader = PointCache(cache)
    assert all(reader.get(p.stem) is not None for p in left) and reader.misses == 0

    resumed = subprocess.run(base + ["--cache-dir", str(cache), "--out", str(tmp_path / "resumed")],
                             capture_output=True, text=True, timeout=1200)
    assert resumed.returncode == 0, resumed.stderr[-2000:]
    fresh = subprocess.run(base + ["--no-cache", "--out", str(tmp_path / "fresh")],
                           capture_output=True, text=True, timeout=1200)
    assert fresh.returncode == 0, fresh.stderr[-2000:]

    if code_version.__wrapped__() != version:
        pytest.skip("micro's sources changed while the test ran: the rerun rightly found no record to reuse")
    computed, cached = _counts(tmp_path / "resumed")
    total, none = _counts(tmp_path / "fresh")
    assert none == 0 and cached == len(left) and 0 < computed == total - len(left) < total
    assert len(_records(cache)) == total

    names = sorted(p.name for p in (tmp_path / "fresh").iterdir())
    assert sorted(p.name for p in (tmp_path / "resumed").iterdir()) == names
    assert sum(n.endswith(".csv") for n in names) >= 10
    for name in names:
        if name.endswith(".csv"):
            got, want = (_table(tmp_path / d / name) for d in ("resumed", "fresh"))
            assert got == want, name
    timing = re.compile(r"wall time .* loading or compiling kernels\)")
    text = [timing.sub("", (tmp_path / d / "summary.md").read_text()) for d in ("resumed", "fresh")]
    assert text[0] == text[1]
