"""Issue 54, rows D1-D3, D12, D17-D19, D27 and "outputs never destroy what they replace":
one policy for every output of micro, rsf and compare (``micro/_outputs.py``, identical to
``rsf/_outputs.py``).

A regular file is replaced atomically, keeping its owner and mode; a device, a FIFO and
standard output are written in place; an output that is an input of the same call, or
another output, is refused before computing (by device and inode: hard and symbolic links
count); a file the user's permission bits do not let them write is refused.

Special files are made in ``tmp_path`` only (FIFOs, and a pseudo-terminal of our own for
a character device): never a real device.
"""
from __future__ import annotations

import io
import os
import pathlib
import stat
import subprocess
import sys
import threading

import pandas as pd
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

import micro._outputs
import rsf._outputs

ROOT = pathlib.Path(__file__).resolve().parents[1]
MODULES = [micro._outputs, rsf._outputs]
IS_ROOT = hasattr(os, "geteuid") and os.geteuid() == 0
OTHER = 4321  # a uid and gid nobody here has


def test_micro_and_rsf_have_the_same_policy_module():
    # micro and rsf do not import each other: each has the module, and the two must not drift apart
    assert (ROOT / "micro" / "_outputs.py").read_bytes() == (ROOT / "rsf" / "_outputs.py").read_bytes()


def _text(tmp: pathlib.Path, text: str = "a,b\n1,2\n"):
    return lambda p: pathlib.Path(p).write_text(text)


class _Reader:
    """A reader of a FIFO on a thread (a writer's open blocks until a reader opens it)."""

    def __init__(self, path) -> None:
        self.data = b""
        self.thread = threading.Thread(target=self._read, args=(path,), daemon=True)
        self.thread.start()

    def _read(self, path) -> None:
        with open(path, "rb") as f:
            self.data = f.read()

    def result(self) -> bytes:
        self.thread.join(timeout=30)
        assert not self.thread.is_alive(), "the FIFO's reader still waits"
        return self.data


# --- the module, on both copies -------------------------------------------------------------
@pytest.mark.parametrize("mod", MODULES, ids=lambda m: m.__name__)
def test_a_fifo_is_written_in_place_not_replaced(mod, tmp_path):
    fifo = tmp_path / "f"
    os.mkfifo(fifo)
    out = mod.target(fifo)
    assert out.kind == "stream" and not out.replaceable
    reader = _Reader(fifo)
    mod.write(out, _text(tmp_path))
    assert reader.result() == b"a,b\n1,2\n"
    assert stat.S_ISFIFO(os.lstat(fifo).st_mode)            # still the FIFO
    assert sorted(p.name for p in tmp_path.iterdir()) == ["f"]  # no temporary beside it


@pytest.mark.parametrize("mod", MODULES, ids=lambda m: m.__name__)
def test_a_character_device_is_written_in_place(mod, tmp_path):
    # a pseudo-terminal of this test's own: a character device that is no one else's
    master, slave = os.openpty()
    try:
        path = os.ttyname(slave)
        before = os.stat(path)
        assert stat.S_ISCHR(before.st_mode)
        out = mod.target(path)
        assert out.kind == "stream"
        mod.write(out, _text(tmp_path, "x,y\n3,4\n"))
        got = b""
        while b"3,4" not in got:
            got += os.read(master, 1024)
        assert got.replace(b"\r\n", b"\n") == b"x,y\n3,4\n"
        after = os.stat(path)
        assert stat.S_ISCHR(after.st_mode) and after.st_rdev == before.st_rdev and after.st_ino == before.st_ino
    finally:
        os.close(master)
        os.close(slave)


@pytest.mark.parametrize("mod", MODULES, ids=lambda m: m.__name__)
def test_an_open_descriptor_is_written_through_and_appended_to(mod, tmp_path):
    # /dev/fd/N (as the shell's process substitution gives): through the descriptor, at its offset
    log = tmp_path / "log.txt"
    log.write_text("kept\n")
    fd = os.open(log, os.O_WRONLY | os.O_APPEND)
    try:
        out = mod.target(f"/dev/fd/{fd}")
        assert out.kind == "fd" and out.fd == fd
        mod.write(out, _text(tmp_path))
    finally:
        os.close(fd)
    assert log.read_text() == "kept\na,b\n1,2\n"
    assert mod.target("-").kind == "fd" and mod.target("-").fd == 1


@pytest.mark.parametrize("mod", MODULES, ids=lambda m: m.__name__)
def test_a_replaced_file_keeps_its_mode_and_owner(mod, tmp_path):
    path = tmp_path / "old.csv"
    path.write_text("old\n")
    os.chmod(path, 0o646)
    if IS_ROOT:   # a file of another user that others may write: root replaces it and keeps the owner
        os.chown(path, OTHER, OTHER)
    before = os.stat(path)
    mod.write(mod.target(path), _text(tmp_path))
    after = os.stat(path)
    assert path.read_text() == "a,b\n1,2\n" and after.st_ino != before.st_ino   # replaced, atomically
    assert stat.S_IMODE(after.st_mode) == 0o646
    assert (after.st_uid, after.st_gid) == (before.st_uid, before.st_gid)
    assert sorted(p.name for p in tmp_path.iterdir()) == ["old.csv"]


@pytest.mark.parametrize("mod", MODULES, ids=lambda m: m.__name__)
def test_a_file_the_user_may_not_write_is_refused(mod, tmp_path):
    path = tmp_path / "ro.csv"
    path.write_text("keep\n")
    os.chmod(path, 0o444)
    if IS_ROOT:   # root too: a read-only file of another user is not replaced (nor its owner changed)
        os.chown(path, OTHER, OTHER)
    with pytest.raises(ValueError, match=r"^--out '.*ro\.csv' is .*mode 0444.*not replaced"):
        mod.target(str(path))
    with pytest.raises(ValueError, match="not replaced"):     # and at write time, for an API caller
        mod.write(path, _text(tmp_path))
    assert path.read_text() == "keep\n" and stat.S_IMODE(os.stat(path).st_mode) == 0o444
    if IS_ROOT:
        assert os.stat(path).st_uid == OTHER
    assert sorted(p.name for p in tmp_path.iterdir()) == ["ro.csv"]


@pytest.mark.parametrize("mod", MODULES, ids=lambda m: m.__name__)
def test_same_file_by_hard_link_symbolic_link_or_spelling_is_refused(mod, tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    table = tmp_path / "t.csv"
    table.write_text("V,sigma\n1,0.9\n")
    os.link(table, tmp_path / "hard.csv")
    (tmp_path / "sym.csv").symlink_to(table)
    for spelling in ("t.csv", "./t.csv", str(table), "hard.csv", "sym.csv"):
        out = mod.target(spelling)
        with pytest.raises(ValueError, match=r"^--out is the --table file"):
            mod.check_distinct([out], {"--table": "t.csv"})
        with pytest.raises(ValueError, match=r"^--out and --events name the same file"):
            mod.check_distinct([out, mod.target("hard.csv", "--events")])
    # two new files, one spelled through a link to the folder
    (tmp_path / "dir").symlink_to(tmp_path)
    with pytest.raises(ValueError, match="name the same file"):
        mod.check_distinct([mod.target("new.csv"), mod.target("dir/new.csv", "--events")])
    with pytest.raises(ValueError, match="name the same file"):
        mod.check_distinct([mod.target("-"), mod.target("/dev/stdout", "--events")])
    mod.check_distinct([mod.target("a.csv"), mod.target("b.csv", "--events")], {"--table": "t.csv"})
    assert table.read_text() == "V,sigma\n1,0.9\n"


# --- the command lines ----------------------------------------------------------------------
def _main(main, argv, capsys):
    status = main(argv)
    captured = capsys.readouterr()
    return status, captured.out, captured.err


def test_d1_micro_sweep_and_rsf_sweep_write_into_a_fifo(tmp_path, capsys):
    import micro.cli
    import rsf.cli

    fifo = tmp_path / "n"
    os.mkfifo(fifo)
    reader = _Reader(fifo)
    # two rows: a FIFO takes the table once, at the end (a file gets it after every row)
    status, _, err = _main(micro.cli.main, ["sweep", "--k0", "0.1", "--V", "2,5", "--out", str(fifo)], capsys)
    assert status == 0, err
    frame = pd.read_csv(io.BytesIO(reader.result()))
    assert frame.V.tolist() == [2.0, 5.0]
    reader = _Reader(fifo)
    status, _, err = _main(rsf.cli.main, ["sweep", "--k0", "0.1", "--V", "1", "--out", str(fifo)], capsys)
    assert status == 0, err
    assert pd.read_csv(io.BytesIO(reader.result())).V.tolist() == [1.0]
    assert stat.S_ISFIFO(os.lstat(fifo).st_mode) and sorted(p.name for p in tmp_path.iterdir()) == ["n"]


def test_d2_dev_stdout_keeps_what_the_shell_wrote(tmp_path):
    # standard output redirected to a file (">" and ">>") and to a pipe: never replaced
    env = {**os.environ, "PYTHONPATH": str(ROOT) + os.pathsep + os.environ.get("PYTHONPATH", ""),
           "NUMBA_NUM_THREADS": "1", "OMP_NUM_THREADS": "1"}
    (tmp_path / "app.txt").write_text("earlier\n")
    script = (f"{{ echo h; {sys.executable} -m micro steady --k0 1 --V 1 --out /dev/stdout; echo f; }} > x.txt\n"
              f"{sys.executable} -m rsf critical --k0 0.1 --out /dev/stdout >> app.txt\n"
              f"{sys.executable} -m micro steady --k0 1 --V 1,2 --out /dev/stdout | cat > piped.txt\n")
    done = subprocess.run(["bash", "-c", script], cwd=tmp_path, env=env, capture_output=True, text=True,
                          timeout=300)
    assert done.returncode == 0, done.stderr
    lines = (tmp_path / "x.txt").read_text().splitlines()
    assert lines[0] == "h" and lines[1].startswith("k0,k1,k2") and lines[-1] == "f" and len(lines) == 4
    lines = (tmp_path / "app.txt").read_text().splitlines()
    assert lines[0] == "earlier" and lines[1].startswith("k0,Dc,Vc") and len(lines) == 3
    assert pd.read_csv(tmp_path / "piped.txt").V.tolist() == [1.0, 2.0]


def test_d3_an_input_is_never_an_output(tmp_path, capsys, monkeypatch):
    import rsf.cli

    monkeypatch.chdir(tmp_path)
    pd.DataFrame({"V": [0.01, 0.1, 1.0, 10.0], "sigma": [0.95, 0.93, 0.91, 0.9]}).to_csv("t.csv", index=False)
    pd.DataFrame({"t": [0.0, 10.0], "V": [0.1, 0.1]}).to_csv("h.csv", index=False)
    os.link("t.csv", "hard.csv")
    before = {name: pathlib.Path(name).read_bytes() for name in ("t.csv", "h.csv")}
    for argv, message in [
        (["critical", "--k0", "0.1", "--law", "table", "--table", "t.csv", "--out", "t.csv"], "--out is the --table file"),
        (["critical", "--k0", "0.1", "--law", "table", "--table", "t.csv", "--out", "hard.csv"], "--out is the --table file"),
        (["run", "--k0", "0.1", "--law", "log", "--a", "0.01", "--history", "h.csv", "--t-end", "5", "--out", "h.csv"],
         "--out is the --history file"),
        (["run", "--k0", "0.1", "--law", "log", "--a", "0.01", "--history", "h.csv", "--t-end", "5", "--out", "o.csv",
          "--events", "./h.csv"], "--events is the --history file"),
    ]:
        status, out, err = _main(rsf.cli.main, argv, capsys)
        assert status == 2 and err.startswith(f"error: {message}") and len(err.strip().splitlines()) == 1, err
    assert {name: pathlib.Path(name).read_bytes() for name in ("t.csv", "h.csv")} == before
    assert not pathlib.Path("o.csv").exists()


def test_d27_hard_links_and_foreign_read_only_files(tmp_path, capsys):
    import micro.cli
    import rsf.cli

    a = tmp_path / "a.csv"
    a.write_text("old\n")
    os.link(a, tmp_path / "b.csv")
    argv = ["run", "--k0", "0.3", "--V", "0.05", "--t-end", "2", "--out", str(a), "--events", str(tmp_path / "b.csv")]
    status, _, err = _main(rsf.cli.main, argv, capsys)
    assert status == 2 and "--out and --events name the same file" in err
    ro = tmp_path / "ro.csv"
    ro.write_text("keep\n")
    os.chmod(ro, 0o444)
    if IS_ROOT:
        os.chown(ro, OTHER, OTHER)
    for main, argv in [(rsf.cli.main, ["critical", "--k0", "0.1"]), (micro.cli.main, ["steady", "--k0", "1", "--V", "1"])]:
        status, _, err = _main(main, [*argv, "--out", str(ro)], capsys)
        assert status == 2 and err.startswith(f"error: --out '{ro}' is ") and "not replaced" in err, err
    assert ro.read_text() == "keep\n" and a.read_text() == "old\n"
    if IS_ROOT:
        assert os.stat(ro).st_uid == OTHER


def test_micro_out_dash_is_standard_output(tmp_path, capsys, monkeypatch):
    import micro.cli

    monkeypatch.chdir(tmp_path)
    status, out, err = _main(micro.cli.main, ["steady", "--k0", "1", "--V", "1,2", "--out", "-"], capsys)
    assert status == 0 and pd.read_csv(io.StringIO(out)).V.tolist() == [1.0, 2.0]
    assert "to standard output" in err and not list(tmp_path.iterdir())    # no file named '-'


# --- properties: any combination of spellings, links and special files ----------------------
_NAMES = ["t.csv", "./t.csv", "hard.csv", "sym.csv", "new.csv", "sub/../new.csv", "other.csv", "fifo", "-",
          "/dev/stdout"]


@settings(max_examples=60, deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture])
@given(out=st.sampled_from(_NAMES), events=st.sampled_from(_NAMES + [None]))
def test_outputs_are_refused_exactly_when_they_are_one_file(tmp_path_factory, out, events):
    """For every pair of --out and --events among spellings of one input file (a hard link,
    a symbolic link), new files, a FIFO and standard output: refused (exit 2, before
    computing, nothing written) exactly when two of the three are one file; the input is
    never touched."""
    import rsf.cli

    folder = tmp_path_factory.mktemp("prop")
    (folder / "sub").mkdir()
    (folder / "t.csv").write_text("V,sigma\n0.01,0.95\n1,0.9\n100,0.85\n")
    os.link(folder / "t.csv", folder / "hard.csv")
    (folder / "sym.csv").symlink_to(folder / "t.csv")
    (folder / "other.csv").write_text("x\n")
    os.mkfifo(folder / "fifo")

    def identity(name):
        if name in ("-", "/dev/stdout"):
            return "stdout"
        path = folder / name
        return (os.stat(path).st_ino if path.exists() else os.path.realpath(path))

    names = [n for n in (out, events) if n is not None]
    keys = [identity(n) for n in names]
    clash = len(set(keys)) < len(keys) or identity("t.csv") in keys
    if not clash and ("fifo" in names or "-" in names or "/dev/stdout" in names):
        return  # (a FIFO needs a reader, and standard output is pytest's: the clash-free cases are above)
    argv = ["run", "--k0", "0.3", "--law", "table", "--table", "t.csv", "--V", "0.5", "--t-end", "0.5",
            "--out", out] + ([] if events is None else ["--events", events])
    before = sorted(p.name for p in folder.iterdir())
    cwd = os.getcwd()
    os.chdir(folder)
    try:
        err = io.StringIO()
        with pytest.MonkeyPatch.context() as m:
            m.setattr(sys, "stderr", err)
            status = rsf.cli.main(argv)
    finally:
        os.chdir(cwd)
    assert (status == 2) == clash, (argv, err.getvalue())
    if clash:
        line, = err.getvalue().strip().splitlines()
        assert "name the same file" in line or "is the --table file" in line, line
        assert sorted(p.name for p in folder.iterdir()) == before
    assert (folder / "t.csv").read_text().startswith("V,sigma\n0.01,0.95")
