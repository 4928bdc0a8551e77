"""Output files that never destroy what they replace: one policy for every command.

This module is ``micro/_outputs.py`` and, byte for byte, ``rsf/_outputs.py``: micro and
rsf are independent packages (neither imports the other), and compare uses rsf's copy.
``tests/test_outputs_safety.py`` checks that the two copies are identical and runs its
tests on both.

Where an output goes (:func:`target`, checked before anything is computed):

* ``-`` is standard output; a path that is this process's standard output or error, or
  one of its open descriptors (``/dev/stdout``, ``/dev/fd/N``, ``/proc/self/fd/N``, the
  file the shell redirected standard output to), is written through the open
  descriptor: where the shell appends, the data are appended, and what the shell wrote
  before stays;
* a device or a FIFO is opened for writing in place (never truncated, never replaced);
* a regular file, or a new one, is written to a temporary file in its folder, which is
  then renamed over it (``os.replace``): a reader, or a crash, sees the old file or the
  whole new one.  A replaced file keeps its owner and mode; a new one gets
  ``0o666 & ~umask``; a symbolic link stays a link, and the file it points to gets the data.

Refused before anything is computed (``ValueError``, one line naming the option): a
folder, a socket, a folder that does not exist or cannot be written in, a file that the
user's permission bits do not let them write (a read-only file, a file of another user:
for root too), a file whose owner this process could not keep, and (:func:`check_distinct`)
an output that is an input of the same call or another output, compared by device and
inode, so that hard links and symbolic links count.
"""
from __future__ import annotations

import contextlib
import os
import re
import stat
import sys
import tempfile
from dataclasses import dataclass
from pathlib import Path
from typing import Callable, Mapping, Sequence

__all__ = ["Target", "target", "check_distinct", "write"]

#: Paths that name an open descriptor of this process: /dev/stdout, /dev/fd/N, /proc/self/fd/N.
_FD_PATH = re.compile(r"^/(?:dev|proc/(?:self|thread-self|(?P<pid>\d+)))/fd/(?P<fd>\d+)$")
_STD_PATH = {"/dev/stdin": 0, "/dev/stdout": 1, "/dev/stderr": 2}


@dataclass(frozen=True)
class Target:
    """Where one output goes, as :func:`target` found it.

    Attributes
    ----------
    option : str
        The option that named it (``--out``), for messages.
    given : str
        The path as given.
    kind : str
        ``'file'`` (a regular file or a new one: replaced atomically), ``'stream'`` (a
        device or a FIFO: written in place) or ``'fd'`` (an open descriptor of this process,
        standard output for ``-``: written through it).
    path : pathlib.Path or None
        The file written, symbolic links resolved (None for ``'fd'``).
    fd : int or None
        The descriptor of ``'fd'``.
    key : tuple
        Its identity: device and inode of an existing file, else the resolved path.
    """

    option: str
    given: str
    kind: str
    path: Path | None
    fd: int | None
    key: tuple

    @property
    def replaceable(self) -> bool:
        """True for a regular (or new) file, which may be written again as a whole; a stream
        or a descriptor takes the data once."""
        return self.kind == "file"

    def __str__(self) -> str:
        return "standard output" if self.given == "-" else self.given


def _fd_key(fd: int) -> tuple | None:
    try:
        st = os.fstat(fd)
    except OSError:
        return None
    return (st.st_dev, st.st_ino)


def _named_fd(text: str) -> int | None:
    """The descriptor that ``text`` names (``/dev/stdout``, ``/dev/fd/3``, a link to one), or None."""
    path = os.path.abspath(text)
    for _ in range(40):  # (as the kernel's limit on nested links)
        if path in _STD_PATH:
            return _STD_PATH[path]
        match = _FD_PATH.match(path)
        if match and match.group("pid") in (None, str(os.getpid())):
            return int(match.group("fd"))
        if not os.path.islink(path):
            return None
        path = os.path.normpath(os.path.join(os.path.dirname(path), os.readlink(path)))
    return None


def _groups() -> set[int]:
    return {os.getegid(), *os.getgroups()} if hasattr(os, "getegid") else set()


def _replace_refusal(st: os.stat_result) -> str | None:
    """Why a regular file with status ``st`` may not be replaced, or None.  Root is judged
    by the permission bits too: a read-only file is not written over."""
    if not hasattr(os, "geteuid"):
        return None if st.st_mode & stat.S_IWUSR else "is read-only"
    euid, groups, mode = os.geteuid(), _groups(), stat.S_IMODE(st.st_mode)
    bit = stat.S_IWUSR if st.st_uid == euid else stat.S_IWGRP if st.st_gid in groups else stat.S_IWOTH
    if not mode & bit:
        whose = ("read-only" if st.st_uid == euid else
                 f"a file of another user (uid {st.st_uid}) that this user may not write")
        return f"is {whose} (mode {mode:04o}): it is not replaced; give another file"
    if euid != 0 and (st.st_uid != euid or st.st_gid not in groups):
        return (f"belongs to uid {st.st_uid}, gid {st.st_gid}: replacing it would change its owner; "
                "give another file")
    return None


def _umask() -> int:
    """The process's umask (read from /proc where it can be, since ``os.umask`` can only be
    read by setting it)."""
    with contextlib.suppress(OSError, ValueError):
        with open("/proc/self/status", encoding="ascii") as f:
            for line in f:
                if line.startswith("Umask:"):
                    return int(line.split()[1], 8)
    mask = os.umask(0o022)
    os.umask(mask)
    return mask


def target(path: str | os.PathLike, option: str = "--out", *, what: str = "file", probe: bool = True) -> Target:
    """Where the output ``path`` goes (``-``: standard output), checked before computing.

    Parameters
    ----------
    path : str or path-like
        As the user gave it.
    option : str
        The option's name, for the messages.
    what : str
        What it must name, for the messages (``'CSV file'``).
    probe : bool
        Also create and remove a temporary file in the folder of a regular or new file,
        to find out now whether the folder can be written.

    Raises
    ------
    ValueError
        One line naming ``option``: see the module's docstring.
    """
    text = os.fspath(path)
    if text == "-":
        return Target(option, text, "fd", None, 1, _fd_key(1) or ("fd", 1))
    if not text.strip():
        raise ValueError(f"{option} must name a {what} (or - for standard output), got {text!r}")
    fd = _named_fd(text)
    if fd is not None:
        key = _fd_key(fd)
        if key is None:
            raise ValueError(f"{option} {text!r} names descriptor {fd}, which is not open")
        return Target(option, text, "fd", None, fd, key)
    try:
        st = os.stat(text)
    except FileNotFoundError:
        st = None
    except OSError as exc:
        raise ValueError(f"{option} {text!r} cannot be reached ({exc.strerror})") from None
    real = Path(os.path.realpath(text))
    if st is not None:
        key = (st.st_dev, st.st_ino)
        for fd in (1, 2):  # the file the shell sent standard output (or error) to
            if _fd_key(fd) == key:
                return Target(option, text, "fd", None, fd, key)
        if stat.S_ISDIR(st.st_mode):
            raise ValueError(f"{option} {text!r} is a directory; give a file name")
        if stat.S_ISSOCK(st.st_mode):
            raise ValueError(f"{option} {text!r} is a socket, which cannot be written as a file")
        if not stat.S_ISREG(st.st_mode):  # a device or a FIFO
            if not os.access(text, os.W_OK):
                raise ValueError(f"{option} {text!r} cannot be written (no write permission)")
            return Target(option, text, "stream", real, None, key)
        why = _replace_refusal(st)
        if why:
            raise ValueError(f"{option} {text!r} {why}")
    else:
        key = ("path", str(real))
        if not real.parent.is_dir():
            raise ValueError(f"{option} {text!r}: the directory {str(real.parent)!r} does not exist")
    if probe:
        try:
            fd_, tmp = tempfile.mkstemp(dir=real.parent, prefix=f".{real.name}.", suffix=".tmp")
            os.close(fd_)
            os.unlink(tmp)
        except OSError as exc:
            raise ValueError(f"{option} {text!r}: cannot write in {str(real.parent)!r} ({exc.strerror})") from None
    return Target(option, text, "file", real, None, key)


def _input_key(path: str) -> tuple:
    try:
        st = os.stat(path)
    except OSError:
        return ("path", os.path.realpath(path))
    return (st.st_dev, st.st_ino)


def check_distinct(outputs: Sequence[Target | None], inputs: Mapping[str, str | None] | None = None) -> None:
    """No two of ``outputs`` are one file, and none is one of ``inputs`` (option -> path):
    compared by device and inode (hard links and symbolic links count), and for files that
    do not exist yet by their resolved paths.

    Raises
    ------
    ValueError
        ``--out and --events name the same file (...)``, or ``--out is the --table file (...)``.
    """
    seen: dict[tuple, Target] = {}
    for out in outputs:
        if out is None:
            continue
        if out.key in seen:
            first = seen[out.key]
            raise ValueError(f"{first.option} and {out.option} name the same file ({first.given!r} and "
                             f"{out.given!r}); give two different files")
        seen[out.key] = out
    for option, path in (inputs or {}).items():
        if path is None or os.fspath(path) == "-":
            continue
        out = seen.get(_input_key(os.fspath(path)))
        if out is not None:
            names = repr(out.given) if out.given == os.fspath(path) else f"{out.given!r} and {os.fspath(path)!r}"
            raise ValueError(f"{out.option} is the {option} file ({names}): writing it would destroy the "
                             "input; give another output file")


def _copy_to(tmp: str, out: Target) -> None:
    """The bytes of the file ``tmp`` written in place to a stream or descriptor."""
    with open(tmp, "rb") as src:
        data = src.read()
    if out.kind == "fd" and out.fd in (1, 2):
        stream = sys.stdout if out.fd == 1 else sys.stderr
        stream.flush()
        buffer = getattr(stream, "buffer", None)
        if buffer is None:
            stream.write(data.decode())
        else:
            buffer.write(data)
            buffer.flush()
        stream.flush()
        return
    fd = out.fd if out.kind == "fd" else os.open(out.path, os.O_WRONLY | getattr(os, "O_NOCTTY", 0))
    try:
        view = memoryview(data)
        while view:
            view = view[os.write(fd, view):]
    finally:
        if out.kind != "fd":
            os.close(fd)


def write(out: Target | str | os.PathLike, fill: Callable[[Path], None], *, fsync: bool = False,
          suffix: str | None = None) -> Path | None:
    """Write an output by the module's policy: ``fill(tmp)`` writes the data to a temporary
    file, which then replaces a regular file or is copied to a stream or descriptor.

    Parameters
    ----------
    out : Target or path
        From :func:`target` (a path is checked here, without probing its folder).
    fill : callable
        ``fill(tmp)`` writes the whole content to the path ``tmp``.
    fsync : bool
        Flush a regular file's data to disk before the rename.
    suffix : str, optional
        Of the temporary file (default the target's, so that a writer that picks a format
        from the name picks the target's).

    Returns
    -------
    pathlib.Path or None
        The file written (a symbolic link's target), None for a descriptor.
    """
    if not isinstance(out, Target):
        out = target(out, "path", probe=False)
    if out.kind != "file":
        name = out.path.name if out.path is not None else "stdout"
        fd, tmp = tempfile.mkstemp(prefix=f".{name}.", suffix=suffix if suffix is not None else
                                   (out.path.suffix if out.path is not None else ""))
        os.close(fd)
        try:
            fill(Path(tmp))
            _copy_to(tmp, out)
        finally:
            with contextlib.suppress(OSError):
                os.unlink(tmp)
        return out.path
    path = out.path
    try:
        st = os.stat(path)
    except FileNotFoundError:
        st = None
    if st is not None:
        why = _replace_refusal(st) if stat.S_ISREG(st.st_mode) else "is no longer a regular file"
        if why:
            raise ValueError(f"{out.option} {out.given!r} {why}")
    fd, tmp = tempfile.mkstemp(dir=path.parent, prefix=f".{path.name}.",
                               suffix=path.suffix if suffix is None else suffix)
    os.close(fd)
    try:
        fill(Path(tmp))
        if st is not None and hasattr(os, "chown"):
            tmp_st = os.stat(tmp)
            if (tmp_st.st_uid, tmp_st.st_gid) != (st.st_uid, st.st_gid):
                os.chown(tmp, st.st_uid, st.st_gid)  # (before the mode: chown clears set-id bits)
        os.chmod(tmp, stat.S_IMODE(st.st_mode) if st is not None else 0o666 & ~_umask())
        if fsync:
            fd = os.open(tmp, os.O_RDONLY)
            try:
                os.fsync(fd)
            finally:
                os.close(fd)
        os.replace(tmp, path)
    except BaseException:
        with contextlib.suppress(OSError):
            os.unlink(tmp)
        raise
    return path
