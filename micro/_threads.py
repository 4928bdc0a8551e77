"""Thread counts for micro's kernels on cores that other work shares.

Two kinds of threads spin when the cores are shared, and both made runs many times slower
under load than alone (issue 39, rows 6 and 13):

* **BLAS.**  The renewal chain solves systems of 32 to 384 unknowns, thousands of times
  in a growth-rate root.  Multithreaded OpenBLAS gains nothing at that size, and its
  threads busy-wait between calls: beside other busy processes on 2 cores one
  ``steady_sliding`` call used 7 times the CPU it needs, three at once 26 times
  (docs/validation/micro_results.md, "Threads on shared cores").  :func:`single_blas_thread` (a context
  manager, also :func:`blas_single_threaded` as a decorator) holds BLAS at one thread
  while micro's own solves run (threadpoolctl), and gives the previous limits back after.
  BLAS thread counts are process-wide: the first block entered sets the limit and the
  last one left restores it, whichever threads enter them.

* **numba.**  The cohort kernels sum their cohorts with ``prange`` on numba's OpenMP
  threads, which spin at each of the thousands of joins in a run; with a thread
  descheduled by another process the others spin until it comes back (one cohort cycle
  beside other busy processes: 49 s of CPU for 6 s of work, three at once 98 s each).  :func:`use_free_cores` sets the
  calling thread's numba thread count to the cores free to this process
  (:func:`numba_threads`): the processors in its affinity mask less the runnable
  threads of other processes (``/proc/loadavg`` less this process's own running
  threads), sampled at most every :data:`SAMPLE_SECONDS`, at least 1 and at most
  ``NUMBA_NUM_THREADS`` and at most what the caller set with ``numba.set_num_threads``.
  Alone on 2 cores a run keeps both threads; beside another busy process it runs
  serially, where threads do not pay.  A process that is one of
  several workers (compare's process pool) calls :func:`single_thread_process`, which
  pins numba and BLAS to one thread for the process's life.
"""
from __future__ import annotations

import contextlib
import functools
import os
import sys
import threading
import time
from typing import Callable, Iterator, TypeVar

__all__ = ["single_blas_thread", "blas_single_threaded", "available_cores", "busy_elsewhere", "free_cores",
           "numba_threads", "one_numba_thread", "use_free_cores", "single_thread_process", "SAMPLE_SECONDS"]

F = TypeVar("F", bound=Callable)

#: How often the load is looked at again (seconds); between two looks the count is kept.
SAMPLE_SECONDS = 0.1

# ------------------------------------------------------------------------------ BLAS
_blas_lock = threading.Lock()
_blas_depth = 0
_blas_limiter = None
_controller: tuple[int, int, object] | None = None  # (pid, modules imported, ThreadpoolController)


def _blas_controller():
    """A ThreadpoolController of the libraries loaded now (building one scans them, about
    3 ms; limiting through it about 0.05 ms): one per process, built again after new
    modules were imported, since an import can load another BLAS (measured: a library
    loaded after the first controller ran on 2 threads inside :func:`single_blas_thread`)."""
    global _controller
    here = (os.getpid(), len(sys.modules))
    if _controller is None or _controller[:2] != here:
        from threadpoolctl import ThreadpoolController

        _controller = (*here, ThreadpoolController())
    return _controller[2]


@contextlib.contextmanager
def single_blas_thread() -> Iterator[None]:
    """Hold the BLAS libraries (OpenBLAS, MKL, BLIS) at one thread inside the block.

    Re-entrant and safe to enter from several threads: BLAS limits are process-wide, so
    the first entry sets them and the last exit gives back the limits found then."""
    global _blas_depth, _blas_limiter
    with _blas_lock:
        if _blas_depth == 0:
            _blas_limiter = _blas_controller().limit(limits=1, user_api="blas")
        _blas_depth += 1
    try:
        yield
    finally:
        with _blas_lock:
            _blas_depth -= 1
            if _blas_depth == 0 and _blas_limiter is not None:
                _blas_limiter.restore_original_limits()
                _blas_limiter = None


def blas_single_threaded(func: F) -> F:
    """Decorator: ``func`` runs inside :func:`single_blas_thread`."""

    @functools.wraps(func)
    def call(*args, **kwargs):
        with single_blas_thread():
            return func(*args, **kwargs)

    return call  # type: ignore[return-value]


# ------------------------------------------------------------------------------ numba
_pinned: int | None = None
_sample_lock = threading.Lock()
_sample: tuple[float, int] | None = None  # (time.monotonic() of the look, thread count)


def available_cores() -> int:
    """Processors this process may run on (its affinity mask; ``os.cpu_count()`` where
    there is none)."""
    try:
        return max(1, len(os.sched_getaffinity(0)))
    except (AttributeError, OSError):
        return max(1, os.cpu_count() or 1)


def _own_running() -> int:
    """This process's threads that are running or runnable now (state R)."""
    n = 0
    with os.scandir("/proc/self/task") as tasks:
        for task in tasks:
            try:
                with open(f"/proc/self/task/{task.name}/stat", "rb") as f:
                    stat = f.read()
            except OSError:  # the thread ended meanwhile
                continue
            # the state follows the command name, which is in parentheses and may hold any
            if stat[stat.rfind(b")") + 2:stat.rfind(b")") + 3] == b"R":
                n += 1
    return n


def busy_elsewhere() -> int | None:
    """Threads of other processes running or waiting for a processor now (Linux: the
    runnable count of ``/proc/loadavg`` less this process's own); None where unknown."""
    try:
        with open("/proc/loadavg", "rb") as f:
            runnable = int(f.read().split()[3].split(b"/")[0])
        return max(0, runnable - _own_running())
    except (OSError, ValueError, IndexError):
        return None


def free_cores() -> int:
    """Processors free to this process now: its :func:`available_cores` less those the
    other processes' runnable threads take (at least 1)."""
    cores = available_cores()
    others = busy_elsewhere()
    if others is None:
        return cores
    online = max(os.cpu_count() or cores, cores)
    return max(1, min(cores, online - others))


def _numba_limit() -> int:
    from numba import config

    return max(1, int(config.NUMBA_NUM_THREADS))


def one_numba_thread() -> bool:
    """Whether numba can run one thread only in this process, for its whole life
    (``NUMBA_NUM_THREADS=1``, as in compare's pool workers, or a single core): then
    micro's parallel kernels have serial twins that compile faster."""
    return _numba_limit() == 1


def _sampled() -> tuple[float, int]:
    """(when it was decided, the thread count): see :func:`numba_threads`."""
    global _sample
    if _pinned is not None:
        return (-1.0, _pinned)
    now = time.monotonic()
    sample = _sample
    if sample is not None and now - sample[0] < SAMPLE_SECONDS:
        return sample
    with _sample_lock:
        if _sample is None or now - _sample[0] >= SAMPLE_SECONDS:
            _sample = (now, min(free_cores(), _numba_limit()))
        return _sample


def numba_threads() -> int:
    """The numba thread count for micro's parallel kernels now: 1 in a process pinned by
    :func:`single_thread_process`, else :func:`free_cores` (looked at again at most every
    :data:`SAMPLE_SECONDS`), at most ``NUMBA_NUM_THREADS``."""
    return _sampled()[1]


_local = threading.local()  # per thread: the count set here last ("ours"), when, and the caller's cap


def use_free_cores() -> int:
    """Set the calling thread's numba thread count (numba keeps one per thread) to
    :func:`numba_threads` before a parallel kernel; returns it.  Between two looks at the
    load it costs a clock read (numba's own get and set take about 10 us).

    A count the caller set (``numba.set_num_threads(n)``: one this function did not set)
    is kept as a cap: the kernels then use at most n threads (from the next look at the
    load on; until then the caller's count is in force as it is)."""
    stamp, n = _sampled()
    if getattr(_local, "stamp", None) == stamp:
        return _local.ours
    import numba

    current = numba.get_num_threads()
    if current != getattr(_local, "ours", None):
        _local.cap = current
    n = min(n, _local.cap)
    if current != n:
        numba.set_num_threads(n)
    _local.ours, _local.stamp = n, stamp
    return n


def single_thread_process() -> None:
    """For one of several worker processes that share the cores: numba's kernels and the
    BLAS libraries run on one thread each in this process from now on (the workers
    already fill the cores; threads of their own would only compete)."""
    global _pinned
    _pinned = 1
    from threadpoolctl import threadpool_limits

    threadpool_limits(1)  # every library threadpoolctl knows (BLAS and OpenMP), for good
    import numba

    numba.set_num_threads(1)
