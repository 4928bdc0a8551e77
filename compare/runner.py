"""Run many micro tasks: from the disk cache when possible, else in parallel.

:class:`Runner` takes a list of tasks (:mod:`compare.tasks`) and returns their records
in the same order.  Records already in the cache are returned at once; the others are
computed

* in this process when ``workers == 1`` (no pool; what the tests compare against),
* on a local process pool by default (``workers`` processes, ``spawn`` start method; the
  workers compile micro's numba kernels first, each group of kernels on one worker, all
  at once; later processes load them from numba's disk cache),
* on a dask.distributed cluster when ``scheduler`` is an address such as
  ``tcp://10.0.0.5:8786`` (or a ``distributed.Client``).  The workers need ``micro`` and
  ``compare`` importable; results come back to this process, which alone writes the
  cache, so the workers need no shared file system.

Each record is written to the cache as soon as it arrives (atomically), so an
interrupted sweep loses only the points that were running.  A progress bar (tqdm) counts
the points, cached ones included.
"""
from __future__ import annotations

import contextlib
import logging
import multiprocessing
import os
import signal
import threading
import time
from concurrent.futures import FIRST_COMPLETED, Future, ProcessPoolExecutor, wait
from dataclasses import dataclass, field
from typing import Any, Callable, Iterable, Iterator, Sequence

from tqdm.auto import tqdm

from micro._threads import available_cores

from ._validation import positive_int
from .cache import NullCache, PointCache
from .tasks import WARM_GROUPS, Task, execute, warm_up

__all__ = ["Runner", "RunStats"]

log = logging.getLogger(__name__)


@dataclass
class RunStats:
    """What a runner did: tasks asked for, served from the cache, computed, failed, and the
    summed compute time of the computed ones.

    Attributes
    ----------
    requested : int
        Distinct tasks asked for.
    cached : int
        Of them, served from the cache.
    computed : int
        Computed (each written to the cache as it arrived).
    failed : int
        Computed with a status other than ``'ok'``.
    compute_seconds : float
        Summed wall time of the computed tasks (over all workers).
    warm_up_seconds : float
        Time spent compiling micro's kernels before the pool started.
    slowest : list of (float, str)
        The five slowest computed tasks: (seconds, label), slowest first.
    """

    requested: int = 0
    cached: int = 0
    computed: int = 0
    failed: int = 0
    compute_seconds: float = 0.0
    warm_up_seconds: float = 0.0
    slowest: list[tuple[float, str]] = field(default_factory=list)

    def add(self, record: dict[str, Any], label: str) -> None:
        self.computed += 1
        self.compute_seconds += float(record.get("wall_time", 0.0))
        if record.get("status") != "ok":
            self.failed += 1
        self.slowest.append((float(record.get("wall_time", 0.0)), label))
        self.slowest.sort(reverse=True)
        del self.slowest[5:]


#: Environment variables that set the thread count of the BLAS libraries numpy may use, and
#: of numba's parallel kernels (micro.cohort's).
_THREADS = ("OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS", "NUMBA_NUM_THREADS")


def _worker_init(parent_pid: int) -> None:
    """A pool worker: Ctrl-C is the parent's to handle (it stops the pool at once), and the
    worker dies with its parent however the parent ends (SIGKILL included).  It runs
    numba's kernels and BLAS on one thread (the workers already fill the cores): the
    environment it was started with says so, and so does micro, whatever the environment."""
    signal.signal(signal.SIGINT, signal.SIG_IGN)
    _die_with_parent(parent_pid)
    logging.basicConfig(level=logging.WARNING, format="%(levelname)s %(name)s: %(message)s")
    from micro._threads import single_thread_process

    single_thread_process()


def _die_with_parent(parent_pid: int) -> None:
    """On Linux the kernel sends SIGKILL when the parent dies (``prctl(PR_SET_PDEATHSIG)``);
    elsewhere a daemon thread checks once a second that the parent is still there."""
    try:
        import ctypes

        libc = ctypes.CDLL(None, use_errno=True)
        if libc.prctl(1, int(signal.SIGKILL)) == 0:  # 1 = PR_SET_PDEATHSIG
            if os.getppid() != parent_pid:  # the parent died before the call
                os._exit(1)
            return
    except (OSError, AttributeError):
        pass

    def watch() -> None:
        while os.getppid() == parent_pid:
            time.sleep(1.0)
        os._exit(1)

    threading.Thread(target=watch, name="parent-watch", daemon=True).start()


@contextlib.contextmanager
def _signals_deferred() -> Iterator[None]:
    """Hold SIGINT and SIGTERM until the block is done, then raise KeyboardInterrupt if one
    came (in the main thread only: elsewhere signals are not delivered to Python code)."""
    if threading.current_thread() is not threading.main_thread():
        yield
        return
    caught: list[int] = []
    previous = {sig: signal.signal(sig, lambda signum, frame: caught.append(signum))
                for sig in (signal.SIGINT, signal.SIGTERM)}
    try:
        yield
    finally:
        for sig, handler in previous.items():
            signal.signal(sig, handler)
    if caught:
        raise KeyboardInterrupt


class Runner:
    """Cached, parallel execution of tasks.

    Parameters
    ----------
    cache : PointCache, NullCache or None
        Where records live; None means a :class:`PointCache` in the default directory.
    workers : int or None
        Local processes (None: the processors this process may run on, its affinity
        mask); 1 runs the tasks in this process.  Each worker runs on one thread.  More
        than those processors are capped at their number, with a warning.  Ignored when
        ``scheduler`` is given.
    scheduler : str or distributed.Client or None
        Address of a dask.distributed scheduler (needs the optional ``dask`` extra).
    progress : bool
        Show a progress bar.

    Raises
    ------
    ValueError
        If ``cache`` is not a cache, ``workers`` is not an integer >= 1, or ``scheduler``
        is neither an address nor a client, or is an address without dask.distributed
        installed.

    Notes
    -----
    Use it as a context manager (or call :meth:`close`) to shut the pool down.

    Examples
    --------
    >>> import micro
    >>> from compare import NullCache, Runner, SteadyTask
    >>> with Runner(NullCache(), workers=1, progress=False) as runner:
    ...     [record] = runner.run([SteadyTask(micro.Model(k0=0.1), (0.5, 2.0))])
    >>> record["status"]
    'ok'
    """

    def __init__(self, cache: PointCache | NullCache | None = None, *, workers: int | None = None,
                 scheduler: Any = None, progress: bool = True) -> None:
        self.cache = PointCache() if cache is None else cache
        if not isinstance(self.cache, (PointCache, NullCache)):
            raise ValueError(f"cache must be a PointCache or NullCache, got {type(self.cache).__name__}")
        self.workers = available_cores() if workers is None else positive_int("workers", workers)
        if scheduler is None and self.workers > available_cores():
            # more local processes than cores only share them, each with its own memory
            # (16 workers on 2 cores: 17 processes, 2 GB in 12 s)
            log.warning("workers=%d is more than the %d cores this process may use: using %d",
                        self.workers, available_cores(), available_cores())
            self.workers = available_cores()
        if scheduler is not None and not isinstance(scheduler, str) and not hasattr(scheduler, "submit"):
            raise ValueError(f"scheduler must be an address like 'tcp://host:8786' or a distributed.Client, "
                             f"got {scheduler!r}")
        if isinstance(scheduler, str):
            # an address needs the dask extra: say so now, not when the first task is due
            import importlib.util

            if importlib.util.find_spec("distributed") is None:
                raise ValueError("scheduler needs the optional dependency dask.distributed: "
                                 "pip install '.[dask]' (or 'dask[distributed]')")
        self.scheduler = scheduler
        self.progress = bool(progress)
        self.stats = RunStats()
        self._pool: ProcessPoolExecutor | None = None
        self._client = None
        self._own_client = False
        self._warm = False

    # -- life cycle ------------------------------------------------------------------------
    def __enter__(self) -> Runner:
        return self

    def __exit__(self, exc_type, *exc) -> None:
        # on an exception (Ctrl-C, SIGTERM) the running tasks are not waited for
        self.close(kill=exc_type is not None)

    def close(self, kill: bool = False) -> None:
        """Shut the pool down: wait for running tasks, or with ``kill`` terminate them at
        once (their points are lost; finished ones are already in the cache)."""
        if self._pool is not None:
            if kill:
                procs = list((getattr(self._pool, "_processes", None) or {}).values())
                for proc in procs:
                    proc.terminate()
                self._pool.shutdown(wait=False)
                for proc in procs:  # gone before the caller removes what they were writing (a figure)
                    proc.join(timeout=2.0)
            else:
                self._pool.shutdown(wait=True, cancel_futures=True)
            self._pool = None
        if self._client is not None and self._own_client:
            self._client.close()
        self._client = None

    @property
    def mode(self) -> str:
        if self.scheduler is not None:
            return f"dask ({self.scheduler if isinstance(self.scheduler, str) else 'client'})"
        return "serial" if self.workers == 1 else f"process pool ({self.workers} workers)"

    # -- running ---------------------------------------------------------------------------
    def run(self, tasks: Sequence[Task], *, desc: str = "micro points") -> list[dict[str, Any]]:
        """Records of ``tasks`` in their order (duplicates are computed once)."""
        tasks = list(tasks)
        keys = [t.key for t in tasks]
        records: dict[str, dict[str, Any]] = {}
        todo: list[Task] = []
        queued: set[str] = set()
        for key, task in zip(keys, tasks):
            if key in records or key in queued:
                continue
            rec = self.cache.get(key)
            if rec is not None:
                records[key] = rec
            else:
                todo.append(task)
                queued.add(key)
        n_unique = len(records) + len(todo)
        self.stats.requested += n_unique
        self.stats.cached += len(records)
        log.info("%s: %d points, %d from the cache, %d to compute (%s)", desc, n_unique, len(records),
                 len(todo), self.mode if todo else "nothing to run")
        bar = tqdm(total=n_unique, initial=len(records), desc=desc, unit="pt", disable=not self.progress,
                   dynamic_ncols=True, leave=True)
        try:
            if todo:
                for rec in self._compute(todo):
                    self._store(rec)
                    records[rec["key"]] = rec
                    bar.update(1)
        finally:
            bar.close()
        return [records[k] for k in keys]

    def submit(self, fn: Callable[..., Any], *args: Any) -> Future:
        """``fn(*args)`` on a worker of the local pool if it is running (``fn`` and ``args``
        picklable), else at once in this process; a future either way.  For the work that
        follows the micro tasks (a report's figures and its D_c fits): the pool's workers
        are warm by then, and a pool is not started for it (spawning one costs seconds)."""
        if self._pool is not None:
            try:
                return self._pool.submit(fn, *args)
            except RuntimeError as exc:  # a broken pool (BrokenProcessPool): run it here
                log.warning("the pool cannot take more work (%s); running it in this process", exc)
        fut: Future = Future()
        try:
            fut.set_result(fn(*args))
        except Exception as exc:  # noqa: BLE001 - handed to the caller through the future
            fut.set_exception(exc)
        return fut

    def _store(self, record: dict[str, Any]) -> None:
        task = record.get("task", {})
        label = f"{task.get('kind')} {task.get('model', {}).get('k0')} {task.get('V', '')}"
        self.stats.add(record, label)
        if record.get("status") != "ok":
            log.warning("micro point failed: %s: %s", label, record.get("error"))
        if record.get("cacheable"):
            self.cache.put(record["key"], record)

    def _ensure_warm(self) -> None:
        if not self._warm:
            seconds = warm_up()
            self.stats.warm_up_seconds += seconds
            log.info("micro kernels ready in this process after %.1f s", seconds)
            self._warm = True

    def _compute(self, todo: list[Task]) -> Iterable[dict[str, Any]]:
        if self.scheduler is not None:
            yield from self._compute_dask(todo)
        elif self.workers == 1 or len(todo) == 1:
            self._ensure_warm()
            for task in todo:
                yield execute(task)
        else:
            yield from self._compute_pool(todo)

    def _compute_pool(self, todo: list[Task]) -> Iterable[dict[str, Any]]:
        if self._pool is None:
            self._start_pool()
        # submit() hands the tasks to the workers' queue; a Ctrl-C or SIGTERM in the middle
        # of it is acted on once the submits are done
        with _signals_deferred():
            pending: set[Future] = {self._pool.submit(execute, task) for task in todo}
        try:
            while pending:
                done, pending = wait(pending, return_when=FIRST_COMPLETED)
                for fut in done:
                    yield fut.result()
        except BaseException:
            # Ctrl-C, SIGTERM or a failure: stop the pool now (its running points are lost,
            # the finished ones are cached).  The queued futures are not cancelled one by one:
            # the pool's manager thread fails them itself once its workers are gone.
            self.close(kill=True)
            raise

    def _start_pool(self) -> None:
        """Start the workers and have them compile micro's kernels, each group once
        (:data:`compare.tasks.WARM_GROUPS`), all workers at once: the groups compile
        independently, so on 2 cores this takes about half the time of compiling them in
        one process, and each is compiled by one worker only (a task given to a worker
        before its group was in numba's disk cache would compile it again).  With a full
        disk cache each group is a load of a second or less."""
        pool = ProcessPoolExecutor(max_workers=self.workers, mp_context=multiprocessing.get_context("spawn"),
                                   initializer=_worker_init, initargs=(os.getpid(),))
        # one BLAS (and numba) thread per worker: the workers already fill the cores, and
        # OpenBLAS threads competing with another worker's made micro's direct solver 4-8x
        # slower (measured); the spawned workers read these when they import numpy and numba
        saved = {var: os.environ.get(var) for var in _THREADS}
        os.environ.update({var: "1" for var in _THREADS})
        try:
            # submit() spawns the workers: a Ctrl-C or SIGTERM in the middle of writing a new
            # worker's start-up data to its pipe left that worker to die printing a traceback
            # ("EOFError: Ran out of input"); the signal is acted on once the submits are done
            with _signals_deferred():
                warming = [pool.submit(warm_up, (name,)) for name in WARM_GROUPS]
        finally:
            for var, value in saved.items():
                if value is None:
                    os.environ.pop(var, None)
                else:
                    os.environ[var] = value
        self._pool = pool
        start = time.perf_counter()
        try:
            for fut in warming:
                fut.result()
        except BaseException:
            self.close(kill=True)
            raise
        seconds = time.perf_counter() - start
        self.stats.warm_up_seconds += seconds
        log.info("micro kernels ready on %d workers after %.1f s", self.workers, seconds)

    def _compute_dask(self, todo: list[Task]) -> Iterable[dict[str, Any]]:
        try:
            from distributed import Client, as_completed
        except ImportError as exc:  # pragma: no cover - depends on the environment
            raise ImportError("a dask scheduler needs the optional dependency: pip install 'dask[distributed]' "
                              "(or this project's 'dask' extra)") from exc
        if self._client is None:
            if isinstance(self.scheduler, str):
                self._client = Client(self.scheduler, timeout="30s")
                self._own_client = True
            else:
                self._client = self.scheduler
            start = time.perf_counter()
            self._client.run(warm_up)
            self.stats.warm_up_seconds += time.perf_counter() - start
        futures = self._client.map(execute, todo, pure=False)
        try:
            for fut in as_completed(futures):
                yield fut.result()
        except BaseException:
            self._client.cancel(futures)
            raise
