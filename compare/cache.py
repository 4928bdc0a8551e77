"""A disk cache of task records, one JSON file per task, written atomically.

The file name is the task's key (SHA-256 of its parameters and the code version, see
:mod:`compare.tasks`), sharded by its first two hex digits.  A record is written to a
temporary file in the same directory, flushed to disk and renamed over the final name
(``os.replace`` is atomic on POSIX and Windows), so an interrupted run leaves either the
whole record or nothing: a rerun resumes with every finished point and recomputes none.

Unreadable files (a crash of the disk, an edit by hand) are treated as missing and
logged, never trusted.
"""
from __future__ import annotations

import json
import logging
import os
import tempfile
from pathlib import Path
from typing import Any

from rsf.results import write_atomically

__all__ = ["PointCache", "NullCache", "default_cache_dir", "check_cache_dir"]

log = logging.getLogger(__name__)


def default_cache_dir() -> Path:
    """``$COMPARE_CACHE_DIR`` if set, else ``~/.cache/frictionkit-compare``."""
    env = os.environ.get("COMPARE_CACHE_DIR")
    if env:
        return Path(env).expanduser()
    base = os.environ.get("XDG_CACHE_HOME") or os.path.join(os.path.expanduser("~"), ".cache")
    return Path(base) / "frictionkit-compare"


def check_cache_dir(directory: str | os.PathLike, out: str | os.PathLike | None = None, *,
                    option: str = "cache_dir", out_option: str = "out") -> Path:
    """The cache folder ``directory`` can be written, and is neither the report folder
    ``out`` nor inside it (the report would refuse the folder the cache filled): raise
    ValueError, one line naming ``option``, before anything is computed.

    Writable means that a folder can be created in it (the cache makes one per shard), or,
    if it does not exist yet, in its nearest existing parent; this is tried (and undone).
    """
    text = os.fspath(directory)
    if not text.strip():
        raise ValueError(f"{option} must name a folder, got {text!r}")
    path = Path(text)
    if path.exists() and not path.is_dir():
        raise ValueError(f"{option} {text!r} is a file, not a folder")
    existing = path
    while not existing.exists():
        existing = existing.parent
    if not existing.is_dir():
        raise ValueError(f"{option} {text!r} cannot be created: {str(existing)!r} is not a folder")
    try:
        os.rmdir(tempfile.mkdtemp(dir=existing, prefix=".compare-probe-"))
    except OSError as exc:
        raise ValueError(f"{option} {text!r} is not writable (cannot create a folder in {str(existing)!r}: "
                         f"{exc.strerror})") from None
    if out is not None:
        cache, report = Path(os.path.realpath(text)), Path(os.path.realpath(os.fspath(out)))
        if cache == report or report in cache.parents:
            where = "the report folder" if cache == report else "inside the report folder"
            raise ValueError(f"{option} {text!r} is {where} {out_option} {os.fspath(out)!r}; give a cache "
                             "folder outside it")
    return path


class PointCache:
    """Task records on disk under ``directory`` (created on first write).

    ``cache.get(key)`` returns the record or None (an unreadable file counts as missing);
    ``cache.put(key, record)`` writes it atomically.

    Parameters
    ----------
    directory : path, optional
        Default :func:`default_cache_dir`: ``$COMPARE_CACHE_DIR``, else
        ``~/.cache/frictionkit-compare``.

    Raises
    ------
    ValueError
        If ``directory`` exists and is not a directory.
    """

    def __init__(self, directory: str | os.PathLike | None = None) -> None:
        self.directory = Path(directory) if directory is not None else default_cache_dir()
        if self.directory.exists() and not self.directory.is_dir():
            raise ValueError(f"cache_dir must be a directory, got the file {str(self.directory)!r}")
        self.hits = 0
        self.misses = 0
        self.writes = 0

    def __repr__(self) -> str:
        return f"PointCache({str(self.directory)!r})"

    def path(self, key: str) -> Path:
        if len(key) < 8 or not all(c in "0123456789abcdef" for c in key):
            raise ValueError(f"key must be a lowercase hex digest, got {key!r}")
        return self.directory / key[:2] / f"{key}.json"

    def get(self, key: str) -> dict[str, Any] | None:
        """The stored record, or None."""
        path = self.path(key)
        try:
            with open(path, encoding="utf-8") as fh:
                record = json.load(fh)
        except FileNotFoundError:
            self.misses += 1
            return None
        except (OSError, ValueError) as exc:
            log.warning("ignoring unreadable cache file %s (%s)", path, exc)
            self.misses += 1
            return None
        if not isinstance(record, dict) or record.get("key") != key:
            log.warning("ignoring cache file %s: it holds another key", path)
            self.misses += 1
            return None
        self.hits += 1
        return record

    def put(self, key: str, record: dict[str, Any]) -> Path:
        """Write ``record`` atomically; returns the final path."""
        path = self.path(key)
        path.parent.mkdir(parents=True, exist_ok=True)
        text = json.dumps(record, allow_nan=True)  # key order kept: CSV columns do not depend on the cache
        # temporary file (.tmp: never counted as a record), fsync, rename; the mode a plain
        # write would give (rsf.results.write_atomically)
        write_atomically(path, lambda tmp: tmp.write_text(text, encoding="utf-8"), fsync=True,
                         suffix=".tmp")
        self.writes += 1
        return path

    def __contains__(self, key: str) -> bool:
        return self.path(key).exists()

    def __len__(self) -> int:
        if not self.directory.exists():
            return 0
        return sum(1 for _ in self.directory.glob("??/*.json"))


class NullCache:
    """A cache that stores nothing (``--no-cache``): every ``get`` misses, ``put`` drops the
    record.  It takes no parameters."""

    directory = None
    hits = misses = writes = 0

    def __repr__(self) -> str:
        return "NullCache()"

    def get(self, key: str) -> None:
        self.misses += 1
        return None

    def put(self, key: str, record: dict[str, Any]) -> None:
        return None

    def __contains__(self, key: str) -> bool:
        return False

    def __len__(self) -> int:
        return 0
