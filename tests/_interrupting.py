"""Run a command line in a subprocess, wait for a progress line on its stderr, send it
SIGINT (Ctrl-C) and collect how it stopped (tests of progress and prompt interrupts)."""
from __future__ import annotations

import os
import re
import select
import signal
import subprocess
import sys
import time
from dataclasses import dataclass
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]


@dataclass
class Stopped:
    first_progress: float     # seconds from the start to the first progress line (inf if none)
    trigger: float            # seconds from the start to the line that matched ``wait_for``
    stop_time: float          # seconds from SIGINT to the end of the process
    returncode: int
    before: str               # stderr up to the SIGINT
    after: str                # stderr after the SIGINT


def interrupt_after(package: str, args: list[str], *, cwd: Path, wait_for: str, progress: str = r" s\]$",
                    timeout: float = 60.0) -> Stopped:
    """Start ``python -m package args``; once a stderr line matches ``wait_for`` (a regular
    expression), send SIGINT and wait for the end.  Lines matching ``progress`` count as
    progress.  Fails (AssertionError) if no line matches within ``timeout`` seconds."""
    env = dict(os.environ, PYTHONPATH=str(ROOT), NUMBA_NUM_THREADS="1", OMP_NUM_THREADS="1")
    start = time.monotonic()
    # (SIGINT back to its default in the child: a shell's background job inherits it ignored,
    # and Python then installs no KeyboardInterrupt handler)
    proc = subprocess.Popen([sys.executable, "-m", package, *args], cwd=cwd, stderr=subprocess.PIPE,
                            stdout=subprocess.DEVNULL, env=env,
                            preexec_fn=lambda: signal.signal(signal.SIGINT, signal.SIG_DFL))
    fd = proc.stderr.fileno()
    buffer, lines = b"", []
    first, trigger = float("inf"), None
    try:
        while trigger is None:
            if time.monotonic() - start > timeout:
                raise AssertionError(f"no stderr line matched {wait_for!r} in {timeout:g} s; got {lines[-5:]}")
            ready, _, _ = select.select([fd], [], [], 0.05)
            if not ready:
                continue
            chunk = os.read(fd, 65536)
            if not chunk:
                raise AssertionError(f"the command ended (exit {proc.wait()}) before a line matched "
                                     f"{wait_for!r}; stderr tail {lines[-5:]}")
            buffer += chunk
            *complete, buffer = buffer.split(b"\n")
            for raw in complete:
                line = raw.decode(errors="replace")
                lines.append(line)
                now = time.monotonic() - start
                if first == float("inf") and re.search(progress, line):
                    first = now
                if trigger is None and re.search(wait_for, line):
                    trigger = now
        sent = time.monotonic()
        proc.send_signal(signal.SIGINT)
        rest = proc.stderr.read()
        code = proc.wait(timeout=60)
        stop_time = time.monotonic() - sent
    finally:
        if proc.poll() is None:
            proc.kill()
            proc.wait()
    return Stopped(first, trigger, stop_time, code, "\n".join(lines),
                   (buffer + rest).decode(errors="replace"))
