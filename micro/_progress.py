"""Progress of long computations, and prompt returns to Python for Ctrl-C.

Library code marks what it is doing with :func:`stage` (a text, or a function giving
one, e.g. the simulated time so far) and calls :func:`beat` from its inner loops (a
cheap check: nothing happens unless a caller asked for progress).  A caller -- the
command line -- installs a callback with :func:`reporting`; at most every ``interval``
seconds a beat then calls it with the stages' texts joined by ``" > "`` (and a watcher
thread does, should the main thread not beat in time: while compiling, or in a long
solve).  Without :func:`reporting` a beat costs one context-variable lookup.

Ctrl-C needs no help from here: Python raises KeyboardInterrupt in the main thread at
its next bytecode, so every long loop must come back to Python often (the
Fokker-Planck kernel runs in chunks of bounded wall time, :data:`CHUNK_SECONDS`).
:class:`Interrupted` carries the work done so far up to a caller that keeps it.

The same module is ``rsf._progress`` (micro and rsf are independent packages and neither
imports the other).
"""
from __future__ import annotations

import contextlib
import threading
import time
from contextvars import ContextVar
from typing import Callable, Iterator, Union

__all__ = ["CHUNK_SECONDS", "Interrupted", "beat", "stage", "reporting", "restart"]

Text = Union[str, Callable[[], str]]

#: Wall time a compiled loop may run before it returns to Python (for Ctrl-C and progress).
CHUNK_SECONDS = 0.2


class Interrupted(KeyboardInterrupt):
    """A KeyboardInterrupt (Ctrl-C) that carries what was computed before it, as keyword
    arguments (``records`` and ``shocks`` from :meth:`micro.grid.Grid.advance`; ``run``, a
    partial :class:`~micro.results.Run`, from :func:`micro.fp.simulate_fp`), for a caller
    that keeps them."""

    def __init__(self, **partial) -> None:
        super().__init__()
        self.partial = partial


class _Reporter:
    """The installed callback, the stack of stages and the time of the next report."""

    def __init__(self, callback: Callable[[str, float], None], first: float, interval: float,
                 longest: float) -> None:
        self.callback = callback
        self.first = first
        self.start = time.monotonic()
        self.due = self.start + first
        self.interval = interval
        self.longest = longest
        self.stages: list[Text] = []
        self.lock = threading.Lock()

    def emit(self, now: float) -> None:
        if not self.lock.acquire(blocking=False):
            return  # (the other thread is reporting)
        try:
            if now < self.due:
                return
            parts = []
            for s in list(self.stages):
                try:
                    parts.append(s() if callable(s) else s)
                except Exception:  # a stage's text must never break the computation
                    continue
            text = " > ".join(p for p in parts if p)
            if text:  # (nothing before the first stage: checking the input prints no progress,
                # and the first line is still due as soon as a stage begins)
                self.due = now + self.interval
                self.interval = min(2.0 * self.interval, self.longest)
                self.callback(text, now - self.start)
        finally:
            self.lock.release()

    def watch(self, stop: threading.Event) -> None:
        """Report when due even while the main thread does not beat (compiling, a long
        solve): the texts are read from this thread then."""
        while not stop.wait(0.1):
            now = time.monotonic()
            if now >= self.due:
                self.emit(now)


_REPORTER: ContextVar[_Reporter | None] = ContextVar("micro_progress", default=None)


def beat() -> None:
    """Report the current stages if a report is due (call it from long loops)."""
    rep = _REPORTER.get()
    if rep is not None:
        now = time.monotonic()
        if now >= rep.due:
            rep.emit(now)


@contextlib.contextmanager
def stage(text: Text) -> Iterator[None]:
    """Within the block the progress text includes ``text`` (a string, or a function
    called at each report)."""
    rep = _REPORTER.get()
    if rep is None:
        yield
        return
    rep.stages.append(text)
    try:
        beat()
        yield
    finally:
        rep.stages.pop()


def restart() -> None:
    """Start the installed reporter's clock again, its first report due ``first`` seconds
    from now: a command line that imports its computing modules only after checking its
    input calls it when the computation begins (the imports are not computing)."""
    rep = _REPORTER.get()
    if rep is not None:
        rep.start = time.monotonic()
        rep.due = rep.start + rep.first


@contextlib.contextmanager
def reporting(callback: Callable[[str, float], None], *, first: float = 0.2, interval: float = 1.0,
              longest: float = 1.0) -> Iterator[None]:
    """Within the block, beats call ``callback(text, elapsed_seconds)``: the first time
    ``first`` seconds after entering, then every ``interval`` seconds, the interval
    doubling up to ``longest``."""
    rep = _Reporter(callback, first, interval, max(longest, interval))
    token = _REPORTER.set(rep)
    stop = threading.Event()
    watcher = threading.Thread(target=rep.watch, args=(stop,), name="progress", daemon=True)
    watcher.start()
    try:
        yield
    finally:
        stop.set()
        _REPORTER.reset(token)
