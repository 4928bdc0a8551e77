"""The report folder: checked before any computation, written atomically, never stale.

A folder that a report wrote holds a manifest, ``.compare-report.json``: the files the
report wrote and whether it finished (``complete``).  While a report is written the
manifest says ``complete: false``, so a folder left by a killed run is marked incomplete.
A report run into a folder of an earlier report replaces it: files the earlier report
listed and this one does not are removed (and logged).  A non-empty folder without a
manifest is refused: the report would overwrite files it did not write.  Temporary
files that an interrupted report left (``.NAME.XXXXXXXX.SUFFIX``, beside the file NAME
that was being written, and the probes ``.compare-probe-XXXXXXXX``) are removed by the
next report into the folder.
"""
from __future__ import annotations

import contextlib
import json
import logging
import os
import re
import tempfile
from pathlib import Path
from typing import Callable

from rsf import _outputs
from rsf.results import write_atomically

__all__ = ["MANIFEST", "check_folder", "ReportFolder"]

MANIFEST = ".compare-report.json"
log = logging.getLogger(__name__)

#: The temporary files of the folder's writes (tempfile.mkstemp: eight characters of
#: [a-z0-9_] between a prefix ``.NAME.`` and the suffix of NAME, or ``.tmp``).
_TEMPORARY = re.compile(r"^\.(?P<name>.+)\.[a-z0-9_]{8}(?P<suffix>\.[^.]+)?$")
_PROBE = re.compile(r"^\.compare-probe-[a-z0-9_]{8}$")


def _is_temporary(name: str) -> bool:
    """``name`` is one of the temporary files a report writes into its folder."""
    if _PROBE.match(name):
        return True
    match = _TEMPORARY.match(name)
    return bool(match) and (match.group("suffix") or "") in (Path(match.group("name")).suffix, ".tmp")


def check_folder(out: str | os.PathLike) -> Path:
    """The report folder ``out`` can be written: raise ValueError (one line, naming ``out``)
    before anything is computed if not."""
    text = os.fspath(out)
    if not text.strip():
        raise ValueError(f"out must name a folder, got {text!r}")
    path = Path(text)
    if path.exists() and not path.is_dir():
        raise ValueError(f"out {text!r} exists and is not a folder")
    if path.is_dir() and any(path.iterdir()) and not (path / MANIFEST).is_file():
        raise ValueError(f"out {text!r} is a non-empty folder that no report wrote (no {MANIFEST}); "
                         "give a new or empty folder")
    if path.is_dir() and (path / MANIFEST).is_file():  # an earlier report: its files are replaced
        for name in [MANIFEST, *_listed(path)]:
            file = path / name
            if os.path.lexists(file) and not file.is_dir():
                _outputs.target(file, f"out {text!r}: the earlier report's file", probe=False)
    existing = path
    while not existing.exists():
        existing = existing.parent
    if not existing.is_dir():
        raise ValueError(f"out {text!r}: {str(existing)!r} is not a folder")
    try:
        fd, probe = tempfile.mkstemp(dir=existing, prefix=".compare-probe-")
        os.close(fd)
        os.unlink(probe)
    except OSError as exc:
        raise ValueError(f"out {text!r}: cannot write in {str(existing)!r} ({exc.strerror})") from None
    return path


def _listed(folder: Path) -> list[str]:
    """The files the manifest in ``folder`` lists (none if it cannot be read)."""
    try:
        files = json.loads((folder / MANIFEST).read_text(encoding="utf-8"))["files"]
        return [str(f) for f in files if isinstance(f, str) and "/" not in f and f not in ("", ".", "..")]
    except (OSError, ValueError, KeyError, TypeError):
        return []


def _atomic(path: Path, write: Callable[[Path], None]) -> None:
    """``write(tmp)`` to a temporary file beside ``path``, then rename it over ``path``; the
    file is left as a plain write would leave it (the umask, an existing file's mode, a
    symbolic link written through to its target: :func:`rsf.results.write_atomically`)."""
    write_atomically(path, write)


class ReportFolder:
    """Writes one report into ``path`` (see the module docstring)."""

    def __init__(self, path: Path) -> None:
        self.path = check_folder(path)
        self.path.mkdir(parents=True, exist_ok=True)
        self._remove_temporaries()
        self.earlier = self._read_manifest()
        self.files: list[str] = []
        self._write_manifest(complete=False, files=sorted(set(self.earlier) | set(self.files)))

    def _read_manifest(self) -> list[str]:
        return _listed(self.path)

    def _remove_temporaries(self) -> None:
        """Remove the temporary files an interrupted report left in the folder."""
        stale = [p for p in self.path.iterdir() if _is_temporary(p.name) and p.is_file() and not p.is_symlink()]
        for p in stale:
            with contextlib.suppress(FileNotFoundError):
                p.unlink()
        if stale:
            log.info("removed %d temporary files an interrupted report left in %s (%s)", len(stale), self.path,
                     ", ".join(sorted(p.name for p in stale)))

    def _write_manifest(self, *, complete: bool, files: list[str]) -> None:
        text = json.dumps({"complete": complete, "files": files}, indent=1)
        _atomic(self.path / MANIFEST, lambda p: p.write_text(text, encoding="utf-8"))

    def write(self, name: str, write: Callable[[Path], None]) -> Path:
        """Write the file ``name`` atomically with ``write(tmp_path)``."""
        target = self.path / name
        _atomic(target, write)
        self.files.append(name)
        return target

    def finish(self) -> list[str]:
        """Remove what an earlier report listed and this one did not; mark the folder
        complete.  Returns the removed names."""
        stale = sorted(set(self.earlier) - set(self.files))
        for name in stale:
            with contextlib.suppress(FileNotFoundError):
                (self.path / name).unlink()
        if stale:
            log.warning("%s held an earlier report: removed %d of its files that this one does not write (%s)",
                        self.path, len(stale), ", ".join(stale))
        self._write_manifest(complete=True, files=sorted(self.files))
        return stale
