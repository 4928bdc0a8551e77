"""Runner: disk cache (resume after an interruption, instant rerun), pool == serial;
bad input raises a ValueError that names the parameter."""
from __future__ import annotations

import json
import os

import pandas as pd
import pytest

import compare
import micro
from compare import runner as runner_module
from compare.cache import PointCache
from compare.runner import Runner
from compare.tasks import StationaryTask, execute

# cheap micro points: a stiff spring (k0 > k2: always steady), a coarse bin
MODEL = micro.Model(k0=1.0)
NUM = micro.Numerics(eps=0.03)
CONV = micro.Convergence()


def _same(records_a, records_b) -> bool:
    """Equal results (NaN == NaN, as in the JSON the cache stores)."""
    dump = lambda recs: [json.dumps(r["result"], sort_keys=True) for r in recs]  # noqa: E731
    return dump(records_a) == dump(records_b)


def _tasks(velocities=(1.0, 2.0, 4.0)):
    return [StationaryTask(MODEL, V, NUM, CONV) for V in velocities]


def test_interrupted_sweep_resumes_and_rerun_is_instant(tmp_path, monkeypatch):
    tasks = _tasks()
    calls = []

    def interrupted(task):
        if len(calls) == 1:
            raise KeyboardInterrupt
        calls.append(task.V)
        return execute(task)

    monkeypatch.setattr(runner_module, "execute", interrupted)
    with pytest.raises(KeyboardInterrupt):
        with Runner(PointCache(tmp_path), workers=1, progress=False) as r:
            r.run(tasks)
    assert len(PointCache(tmp_path)) == 1                      # the finished point was kept
    monkeypatch.setattr(runner_module, "execute", execute)

    with Runner(PointCache(tmp_path), workers=1, progress=False) as r:
        first = r.run(tasks)
        assert (r.stats.cached, r.stats.computed) == (1, 2)    # only the missing points
    with Runner(PointCache(tmp_path), workers=1, progress=False) as r:
        again = r.run(tasks)
        assert (r.stats.cached, r.stats.computed) == (3, 0)    # nothing recomputed
    assert _same(again, first)
    assert all(rec["status"] == "ok" and rec["result"]["regime"] == "steady" for rec in first)


def test_cache_key_changes_with_every_parameter():
    base = StationaryTask(MODEL, 1.0, NUM, CONV)
    variants = [StationaryTask(MODEL, 1.0 + 1e-9, NUM, CONV),
                StationaryTask(micro.Model(k0=1.0, k1=0.2), 1.0, NUM, CONV),
                StationaryTask(MODEL, 1.0, micro.Numerics(eps=0.031), CONV),
                StationaryTask(MODEL, 1.0, NUM, micro.Convergence(rtol=2e-2)),
                StationaryTask(MODEL, 1.0, NUM, CONV, "fp")]
    keys = {base.key} | {v.key for v in variants}
    assert len(keys) == 1 + len(variants)
    assert StationaryTask(micro.Model(k0=1.0), 1.0, micro.Numerics(eps=0.03), micro.Convergence()).key == base.key


def test_fp_method_time_steps_where_the_direct_state_exists():
    # Fig. 10 measures the FP's error against the direct steady state: a task that let
    # "auto" answer would compare the direct method with itself (error 2e-8, flat in eps)
    model = micro.Model(k0=0.3)
    exact = float(micro.steady_sliding(model, 0.3, growth_rate=False).sigma)
    auto = StationaryTask(model, 0.3, micro.Numerics(eps=0.025), CONV).run()
    fp = StationaryTask(model, 0.3, micro.Numerics(eps=0.025), CONV, "fp").run()
    assert abs(auto["sigma_mean"] - exact) < 1e-7
    assert 2e-5 < abs(fp["sigma_mean"] - exact) < 1e-3  # the FP's first-order bin error


def test_unreadable_cache_file_is_recomputed(tmp_path):
    task = _tasks((2.0,))[0]
    cache = PointCache(tmp_path)
    cache.path(task.key).parent.mkdir(parents=True)
    cache.path(task.key).write_text("{not json")
    with Runner(cache, workers=1, progress=False) as r:
        rec = r.run([task])[0]
        assert r.stats.computed == 1
    assert _same([json.loads(cache.path(task.key).read_text())], [rec])


def test_pool_result_equals_serial_result():
    tasks = _tasks((1.0, 3.0))
    with Runner(compare.NullCache(), workers=1, progress=False) as r:
        serial = r.run(tasks)
    with Runner(compare.NullCache(), workers=2, progress=False) as r:
        pooled = r.run(tasks)
        # the pool running, submit() hands work to its workers; without one, it runs here
        assert r.submit(os.getpid).result() != os.getpid()
    assert r.submit(os.getpid).result() == os.getpid()
    with pytest.raises(ZeroDivisionError):
        r.submit(divmod, 1, 0).result()
    for a, b in zip(serial, pooled):
        for name in ("regime", "sigma_max", "sigma_min", "sigma_mean", "t_end"):
            assert a["result"][name] == b["result"][name]


def test_painter_draws_elsewhere_the_same_figure_and_leaves_no_temporary_file(tmp_path):
    """A figure handed to a Painter is drawn by its submit (here a thread), returns its final
    path at once, and lands in the folder byte for byte as drawn in place; a figure whose
    job failed is drawn again in place; temporary files are gone either way."""
    from concurrent.futures import ThreadPoolExecutor

    from compare import figures
    from compare.output import ReportFolder

    t = {"fig10_eps": pd.DataFrame({"k0": [0.1, 0.1], "V": [1.0, 1.0], "eps": [0.02, 0.01],
                                    "error": [2e-4, 1e-4], "converged": [True, False]})}
    here = ReportFolder(tmp_path / "here")
    figures.fig10(t, figures.target(here, "fig10.png"))
    with ThreadPoolExecutor(1) as pool:
        folder = ReportFolder(tmp_path / "there")
        painter = figures.Painter(folder, pool.submit)
        path = figures.fig10(t, figures.target(painter, "fig10.png"))
        assert path == folder.path / "fig10.png"
        painter.finish()
    assert path.read_bytes() == (here.path / "fig10.png").read_bytes()
    assert folder.files == ["fig10.png"]

    def broken(fn, *args):
        raise RuntimeError("worker died")

    folder = ReportFolder(tmp_path / "broken")
    painter = figures.Painter(folder, broken)
    figures.fig10(t, figures.target(painter, "fig10.png"))
    painter.finish()
    assert (folder.path / "fig10.png").read_bytes() == (here.path / "fig10.png").read_bytes()
    for f in (tmp_path / "there", tmp_path / "broken"):
        assert sorted(p.name for p in f.iterdir() if p.suffix == ".png") == ["fig10.png"]


@pytest.mark.parametrize("make,name", [
    (lambda: compare.Settings(k0=(-0.1,)), "k0"),
    (lambda: compare.Settings(eps=0.0), "eps"),
    (lambda: compare.Settings(k1=-1.0), "k1"),
    (lambda: compare.Settings(hopf_distances=(0.1, 2.0, 0.3)), "hopf_distances"),
    (lambda: compare.Settings(scenarios=("bifurcation", "nope")), "scenarios"),
    (lambda: compare.Settings(dc_bounds=(0.1, 0.01)), "dc_bounds"),
    (lambda: compare.Settings(k0=("a",)), "k0"),
    (lambda: Runner(compare.NullCache(), workers=0), "workers"),
    (lambda: StationaryTask(MODEL, -1.0, NUM, CONV), "V"),
    (lambda: compare.report(Dc=-0.06), "Dc"),
    (lambda: compare.fit_growth_law([1, 2, 3], [1, 2, 3], "linear"), "law"),
    (lambda: compare.fit_power_law([0.1, 0.2, 0.3], [1, 2, 3], Vc=0.2), "Vc"),
])
def test_bad_input_names_the_parameter(make, name):
    with pytest.raises(ValueError, match=rf"^{name}\b"):
        make()


def test_fit_dc_rejects_bad_bounds():
    import pandas as pd
    with pytest.raises(ValueError, match=r"bounds"):
        compare.fit_dc(pd.DataFrame(columns=["k0", "V", "regime", "sigma_max", "sigma_min"]), None, bounds=(0.1, 0.01))


@pytest.mark.slow
def test_dask_local_cluster_gives_the_serial_result(tmp_path):
    # distributed is in the test extra: a missing one fails here instead of skipping silently
    import distributed

    tasks = _tasks()
    with Runner(PointCache(tmp_path / "serial"), workers=1, progress=False) as r:
        serial = r.run(tasks)
    with distributed.LocalCluster(n_workers=2, threads_per_worker=1, processes=True, dashboard_address=None) as cluster, \
            distributed.Client(cluster) as client:
        with Runner(PointCache(tmp_path / "dask"), scheduler=client, progress=False) as r:
            remote = r.run(tasks)
            assert r.stats.computed == len(tasks) and "dask" in r.mode
    strip = lambda recs: [{**r, "result": {k: v for k, v in r["result"].items() if k != "wall_time"}}  # noqa: E731
                          for r in recs]
    assert _same(strip(remote), strip(serial))  # everything but the wall time


def test_report_folder_is_checked_before_computing_and_never_left_stale(tmp_path, monkeypatch):
    import importlib

    from compare.output import MANIFEST, ReportFolder, check_folder

    for bad, match in [("", "must name a folder"), (str(tmp_path / "f.txt"), "is not a folder"),
                       ("/proc/x", "cannot write")]:
        (tmp_path / "f.txt").write_text("x")
        with pytest.raises(ValueError, match=match):
            check_folder(bad)
    foreign = tmp_path / "foreign"
    foreign.mkdir()
    (foreign / "summary.md").write_text("someone else's")
    with pytest.raises(ValueError, match="no report wrote"):
        check_folder(foreign)
    # compare.report refuses before computing anything (with no Runner it could not compute)
    monkeypatch.setattr(importlib.import_module("compare.report"), "Runner", None)
    with pytest.raises(ValueError, match="no report wrote"):
        compare.report(out=foreign)
    assert (foreign / "summary.md").read_text() == "someone else's"

    out = tmp_path / "rep"
    first = ReportFolder(out)
    for name in ("a.csv", "b.csv", "summary.md"):
        first.write(name, lambda p: p.write_text("1"))
    assert first.finish() == []
    second = ReportFolder(out)  # a narrower report into the same folder
    assert json.loads((out / MANIFEST).read_text())["complete"] is False  # incomplete while written
    second.write("a.csv", lambda p: p.write_text("2"))
    second.write("summary.md", lambda p: p.write_text("2"))
    assert second.finish() == ["b.csv"] and not (out / "b.csv").exists()
    assert json.loads((out / MANIFEST).read_text()) == {"complete": True, "files": ["a.csv", "summary.md"]}
    assert sorted(p.name for p in out.iterdir()) == sorted([MANIFEST, "a.csv", "summary.md"])


def test_scheduler_without_dask_is_a_clear_error(monkeypatch):
    import importlib.util

    real = importlib.util.find_spec
    monkeypatch.setattr(importlib.util, "find_spec", lambda name, *a: None if name == "distributed" else real(name, *a))
    with pytest.raises(ValueError, match="scheduler needs the optional dependency"):
        Runner(compare.NullCache(), scheduler="tcp://127.0.0.1:8786", progress=False)


def test_cached_records_keep_their_key_order(tmp_path):
    # CSV columns come from the record's keys: a cache that sorted them reordered the
    # columns of a resumed report
    cache = PointCache(tmp_path)
    record = {"key": "ab" * 32, "result": {"k0": 0.1, "V": 2.0, "regime": "steady", "eps": 0.01}}
    cache.put(record["key"], record)
    assert list(cache.get(record["key"])["result"]) == ["k0", "V", "regime", "eps"]


@pytest.mark.slow
def test_a_fresh_pool_compiles_each_kernel_once_and_every_group_of_them(tmp_path):
    """With an empty numba cache a pool of two compiles micro's kernels on its workers,
    each group on one worker (compare.tasks.WARM_GROUPS), so that every kernel is saved
    to the cache exactly once, and the tasks after it compile nothing more; the parent,
    which only waits, compiles none of them (it did all of them alone before)."""
    import subprocess
    import sys
    from collections import Counter

    code = (
        "import micro\n"
        "from compare.cache import NullCache\n"
        "from compare.runner import Runner\n"
        "from compare.tasks import StationaryTask, VcTask\n"
        "m = micro.Model(k0=0.3)\n"
        "num, conv = micro.Numerics(eps=0.025), micro.Convergence(rtol=2e-2)\n"
        "tasks = [VcTask(m), StationaryTask(m, 0.05, num, conv),"
        " StationaryTask(micro.Model(k0=0.1), 2.0, num, conv, method='fp')]\n"
        "with Runner(NullCache(), workers=2, progress=False) as r:\n"
        "    recs = r.run(tasks)\n"
        "print('STATUS', [rec['status'] for rec in recs])\n"
        "from micro import _fp_kernels, _renewal_kernels\n"
        "from micro.cohort import kernels as _cohort_kernels\n"
        "loaded = [f.__name__ for mod in (_cohort_kernels, _fp_kernels, _renewal_kernels)"
        " for f in vars(mod).values() if getattr(f, 'signatures', None)]\n"
        "print('PARENT', loaded)\n"
    )
    env = dict(os.environ, NUMBA_CACHE_DIR=str(tmp_path / "numba"), NUMBA_DEBUG_CACHE="1")
    out = subprocess.run([sys.executable, "-c", code], env=env, capture_output=True, text=True, timeout=900)
    assert out.returncode == 0, out.stderr[-2000:]
    assert "STATUS ['ok', 'ok', 'ok']" in out.stdout
    assert "PARENT []" in out.stdout
    # (a cache file's name, and its folder's name without numba's hash of the folder's path:
    # micro/_fp_kernels._step-..., cohort/kernels._closure-...)
    saved = Counter(folder.rsplit("_", 1)[0] + "/" + name for folder, name in
                    (line.rsplit("/", 2)[-2:] for line in out.stdout.splitlines() if "data saved to" in line))
    assert saved, "nothing was compiled: the numba cache was not empty"
    twice = {name: n for name, n in saved.items() if n > 1}
    assert not twice, f"compiled more than once: {twice}"
    modules = {name.split(".")[0] for name in saved}
    assert {"cohort/kernels", "micro/_fp_kernels", "micro/_nblock_kernels", "micro/_renewal_kernels"} <= modules


@pytest.mark.slow
def test_every_warm_up_group_brings_kernels_of_its_own():
    """Run one after another in a fresh process, each group of compare.tasks.WARM_GROUPS
    loads or compiles kernels the groups before it did not: a group that brought none
    (the renewal kernels, which cohort's run compiles too) was compiled a second time
    beside the other group on a pool of three workers or more."""
    import subprocess
    import sys

    code = (
        "import numba\n"
        "from micro import _fp_kernels, _nblock_kernels, _renewal_kernels\n"
        "from micro.cohort import kernels as _cohort_kernels\n"
        "from compare.tasks import WARM_GROUPS, warm_up\n"
        "mods = (_cohort_kernels, _fp_kernels, _nblock_kernels, _renewal_kernels)\n"
        "def count():\n"
        "    return sum(len(f.signatures) for m in mods for f in vars(m).values()\n"
        "               if isinstance(f, numba.core.registry.CPUDispatcher))\n"
        "before = count()\n"
        "for name in WARM_GROUPS:\n"
        "    warm_up([name])\n"
        "    print('GROUP', name, count() - before)\n"
        "    before = count()\n"
    )
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=900)
    assert out.returncode == 0, out.stderr[-2000:]
    added = {line.split()[1]: int(line.split()[2]) for line in out.stdout.splitlines() if line.startswith("GROUP")}
    assert added and min(added.values()) > 0, added


def test_rsf_warm_up_logs_nothing(caplog):
    # the warm-up runs in a thread beside the pool; a warning of its own tiny runs reached every
    # report's stderr, and after a SIGTERM it could be the last line, after "interrupted:"
    import logging

    from compare import rs_side

    with caplog.at_level(logging.INFO):
        rs_side.warm_up()
    assert not [r for r in caplog.records if r.levelno >= logging.WARNING], caplog.text
