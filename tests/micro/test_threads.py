"""Thread counts on shared cores (issue 39, rows 6 and 13): BLAS held at one thread inside
micro's renewal solves, numba's thread count taken from the cores free to the process,
one thread each in compare's pool workers.  Behaviour only; the timings are in
benchmarks/micro_threads_contention.py."""
from __future__ import annotations

import os
import subprocess
import sys
import textwrap
import threading

import numba
import numpy as np
import pytest
import threadpoolctl

import micro
from micro.cohort import kernels as CK
from micro import _threads


def _blas_threads() -> list[int]:
    return [lib["num_threads"] for lib in threadpoolctl.threadpool_info() if lib["user_api"] == "blas"]


@pytest.fixture
def solve_spy(monkeypatch):
    """np.linalg.solve, recording the BLAS thread counts in force at each call."""
    seen: list[list[int]] = []
    real = np.linalg.solve

    def solve(a, b):
        seen.append(_blas_threads())
        return real(a, b)

    monkeypatch.setattr(np.linalg, "solve", solve)
    return seen


def test_renewal_solves_run_on_one_blas_thread(solve_spy):
    """Inside steady_sliding (the chain's stationary weights and, at an unstable V, the
    growth-rate root's solves) BLAS runs on one thread; the limits found before are back
    after.  (With two BLAS threads per process, their spinning made this call 100 times
    slower under load.)"""
    if not _blas_threads():
        pytest.skip("no BLAS library that threadpoolctl can see")
    with threadpoolctl.threadpool_limits(2, user_api="blas"):
        before = _blas_threads()
        res = micro.steady_sliding(micro.Model(k0=0.1), [0.3, 30.0])
        assert _blas_threads() == before
    assert not res.stable[0] and np.isfinite(res.growth_rate[0])  # the root was searched
    assert len(solve_spy) > 10
    assert all(threads and max(threads) == 1 for threads in solve_spy)


def test_other_renewal_entry_points_run_on_one_blas_thread(solve_spy):
    if not _blas_threads():
        pytest.skip("no BLAS library that threadpoolctl can see")
    model = micro.Model(k0=0.1)
    with threadpoolctl.threadpool_limits(2, user_api="blas"):
        micro.characteristic_function(model, 0.3, [0.5, 1.0 + 1.0j])
        from micro.renewal import critical_velocity_renewal

        critical_velocity_renewal(model)
    assert solve_spy and all(max(threads) == 1 for threads in solve_spy)


def test_single_blas_thread_nests_and_restores():
    if not _blas_threads():
        pytest.skip("no BLAS library that threadpoolctl can see")
    with threadpoolctl.threadpool_limits(2, user_api="blas"):
        before = _blas_threads()
        with _threads.single_blas_thread():
            with _threads.single_blas_thread():
                assert max(_blas_threads()) == 1
            assert max(_blas_threads()) == 1  # the inner exit keeps the outer's limit
        assert _blas_threads() == before


@pytest.fixture
def fresh_sample(monkeypatch):
    """Look at the load again at every call, and put numba's thread count back after."""
    monkeypatch.setattr(_threads, "_sample", None)
    monkeypatch.setattr(_threads, "SAMPLE_SECONDS", 0.0)
    monkeypatch.setattr(_threads, "_pinned", None)
    monkeypatch.setattr(_threads, "_local", threading.local())
    threads = numba.get_num_threads()
    yield
    numba.set_num_threads(threads)


def test_numba_threads_follow_the_affinity_mask(monkeypatch, fresh_sample):
    monkeypatch.setattr(_threads, "busy_elsewhere", lambda: 0)
    assert _threads.numba_threads() == min(_threads.available_cores(), numba.config.NUMBA_NUM_THREADS)
    monkeypatch.setattr(os, "sched_getaffinity", lambda pid: {0}, raising=False)
    assert _threads.available_cores() == 1
    assert _threads.numba_threads() == 1


def test_numba_threads_leave_the_cores_other_processes_use(monkeypatch, fresh_sample):
    monkeypatch.setattr(_threads, "available_cores", lambda: 4)
    monkeypatch.setattr(os, "cpu_count", lambda: 4)
    monkeypatch.setattr(_threads, "_numba_limit", lambda: 8)
    for others, expected in [(0, 4), (1, 3), (3, 1), (10, 1)]:
        monkeypatch.setattr(_threads, "busy_elsewhere", lambda others=others: others)
        assert _threads.numba_threads() == expected
    monkeypatch.setattr(_threads, "busy_elsewhere", lambda: None)  # no /proc: the mask alone
    assert _threads.numba_threads() == 4


def test_busy_elsewhere_reads_the_machine():
    others = _threads.busy_elsewhere()
    if sys.platform.startswith("linux"):
        assert isinstance(others, int) and others >= 0
    assert 1 <= _threads.free_cores() <= _threads.available_cores()


def _empty_closure_args():
    """closure() on no cohorts, with the argument types micro.cohort passes."""
    i64 = np.zeros(1, np.int64)
    return (0.5, 0, np.zeros((1, 6)), i64, i64.copy(), i64.copy(), np.zeros(2), np.zeros(4), 0.0, 0.1, 0.1, 0.1)


def test_cohort_kernels_set_numba_threads_from_the_free_cores(monkeypatch, fresh_sample):
    """The parallel cohort kernels, called from Python, first set the calling thread's
    numba thread count to the free cores: serial beside busy processes (where numba's
    OpenMP threads spun at every join), all the mask's threads when nothing else runs."""
    top = min(_threads.available_cores(), numba.config.NUMBA_NUM_THREADS)
    numba.set_num_threads(top)
    monkeypatch.setattr(_threads, "busy_elsewhere", lambda: 64)
    H, dH = CK.closure(*_empty_closure_args())
    assert (H, dH) == (-0.5, -1.0)
    assert numba.get_num_threads() == 1
    monkeypatch.setattr(_threads, "busy_elsewhere", lambda: 0)
    CK.closure(*_empty_closure_args())
    assert numba.get_num_threads() == top
    assert CK.commit.__wrapped__ is CK._commit and CK.smallest_root.__wrapped__ is CK._smallest_root


def test_a_thread_count_the_caller_set_caps_the_kernels(monkeypatch, fresh_sample):
    """numba.set_num_threads(1) before a call is kept (benchmarks compare 1 and 2 threads
    that way); a larger count set later is the new cap."""
    monkeypatch.setattr(_threads, "busy_elsewhere", lambda: 0)
    top = min(_threads.available_cores(), numba.config.NUMBA_NUM_THREADS)
    numba.set_num_threads(1)
    CK.closure(*_empty_closure_args())
    assert numba.get_num_threads() == 1
    numba.set_num_threads(top)
    CK.closure(*_empty_closure_args())
    assert numba.get_num_threads() == top


def _run(code: str) -> str:
    env = dict(os.environ)
    for var in ("OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS", "NUMBA_NUM_THREADS"):
        env.pop(var, None)
    out = subprocess.run([sys.executable, "-c", textwrap.dedent(code)], capture_output=True, text=True, env=env,
                         timeout=300)
    assert out.returncode == 0, out.stderr
    return out.stdout.split()[-1]


def test_single_thread_process_pins_numba_and_blas():
    """A worker process (started without the thread variables in its environment): one
    numba thread, whatever the load, and one BLAS thread."""
    assert _run("""
        import numba, threadpoolctl
        import micro
        from micro import _threads
        _threads.single_thread_process()
        _threads.busy_elsewhere = lambda: 0
        blas = [lib["num_threads"] for lib in threadpoolctl.threadpool_info() if lib["user_api"] == "blas"]
        print(f"{numba.get_num_threads()},{_threads.numba_threads()},{max(blas, default=1)}")
    """) == "1,1,1"


def test_compare_pool_workers_run_on_one_thread():
    """compare's pool initializer pins its worker to one numba and one BLAS thread even
    when the environment would allow more."""
    assert _run("""
        import os, numba, threadpoolctl
        import compare.runner as R
        R._worker_init(os.getppid())
        from micro import _threads
        blas = [lib["num_threads"] for lib in threadpoolctl.threadpool_info() if lib["user_api"] == "blas"]
        print(f"{numba.get_num_threads()},{_threads.numba_threads()},{max(blas, default=1)}")
    """) == "1,1,1"


def test_runner_defaults_to_the_cores_in_the_affinity_mask():
    from compare.cache import NullCache
    from compare.runner import Runner

    assert Runner(NullCache(), progress=False).workers == _threads.available_cores()
