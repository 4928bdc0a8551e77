"""A bad argument is said at once (issue 52, "Bad input"): ``import micro`` loads none of
its submodules (PEP 562: each public name on first use), and ``python -m micro`` checks every
argument before it imports the modules that compute (pandas, scipy, numba: most of a second).

What each refused call imported is checked, not its wall time (a loaded machine makes any
time limit flaky); the times are in the commit messages of the change.
"""
from __future__ import annotations

import ast
import subprocess
import sys
import time
from pathlib import Path

import pytest

import micro

ROOT = Path(__file__).resolve().parents[2]

#: Modules a refused call must not have loaded (the packages by their top-level name).
HEAVY = ("pandas", "numba", "scipy", "micro.renewal", "micro.api", "micro.branch", "micro.cohort", "micro.fp",
         "micro.grid")

#: Runs ``python -m micro ARGS`` as ``-m`` does, and prints at exit which of HEAVY were imported
#: (micro/__main__.py ends a refused call by os._exit, skipping the interpreter's teardown).
PROBE = f"""
import os, runpy, sys
HEAVY = {HEAVY!r}
def loaded():
    print(" ".join(sorted({{next(h for h in HEAVY if m == h or m.startswith(h + "."))
                            for m in sys.modules if any(m == h or m.startswith(h + ".") for h in HEAVY)}})),
          flush=True)
exit_now = os._exit
os._exit = lambda code: (loaded(), exit_now(code))
sys.argv[0] = "micro"
try:
    runpy.run_module("micro", run_name="__main__", alter_sys=True)
finally:
    loaded()
"""


def _refused(args: list[str], tmp_path) -> tuple[str, set[str]]:
    """The one line a refused ``python -m micro`` call printed (exit code 2), and what it imported."""
    done = subprocess.run([sys.executable, "-c", PROBE, *args, "--out", str(tmp_path / "out.csv")], cwd=tmp_path,
                          capture_output=True, text=True, env={"PYTHONPATH": str(ROOT), "PATH": "/usr/bin:/bin"},
                          timeout=120)
    lines = done.stderr.strip().splitlines()
    assert done.returncode == 2, done.stderr
    assert len(lines) == 1 and lines[0].startswith("error: ") and "Traceback" not in done.stderr, done.stderr
    assert not (tmp_path / "out.csv").exists()
    return lines[0], set(done.stdout.split())


@pytest.mark.parametrize("args, says", [
    (["branch", "--k0", "0.1", "--d-min", "0"], "error: --d-min must be in (0, 1)"),
    (["branch", "--k0", "0.1", "--d-min", "1.5"], "error: --d-min must be in (0, 1)"),
    (["branch", "--k0", "0.1", "--d-min", "-0.1"], "error: --d-min must be in (0, 1)"),  # (past V^c)
    (["branch", "--k0", "0.1", "--dist", "delta"], "error: --dist: cycle_branch computes its cycles by the cohort "
                                                   "method, and the cohort method needs exponential jumps"),
    (["branch", "--k0", "0.1", "--max-error", "2"], "error: --max-error must be in (0, 1]"),
    (["branch", "--k0", "0.1", "--max-points", "1"], "error: --max-points must be an integer >= 2"),
    (["branch", "--k0", "0.1", "--cohort-dt", "1"], "error: --cohort-dt must be a finite number in (0, 0.1]"),
    (["sweep", "--k0", "0.1", "--V", "-1"], "error: --V item 1 must be in [1e-06, 1e+07]"),
    (["sweep", "--k0", "-1", "--V", "1"], "error: --k0 must be in (0, 1000]"),
    (["steady", "--k0", "0.1", "--V", "0"], "error: --V item 1 must be in [1e-06, 1e+07]"),
    (["critical", "--k0", "0.1", "--rel-tol", "2"], "error: --rel-tol must be in (0, 1)"),
    (["critical", "--k0", "0.1,-1"], "error: --k0 item 2 must be in [0, 1000]"),
])
def test_a_plain_range_error_is_said_before_anything_that_computes_is_imported(args, says, tmp_path):
    line, loaded = _refused(args, tmp_path)
    assert line.startswith(says), line
    assert loaded == set(), f"{' '.join(args)} imported {sorted(loaded)} before refusing"


def test_a_start_above_vc_needs_the_renewal_chain_only(tmp_path):
    # V^c (0.7275 at k0 = 0.1) comes from the renewal chain (numba's cached kernels, scipy's
    # root finder); pandas and the cohort's and Fokker-Planck's modules are not needed to refuse
    line, loaded = _refused(["branch", "--k0", "0.1", "--V-start", "5"], tmp_path)
    assert line.startswith("error: --V-start must be in (0, V^c = 0.727504)"), line
    assert loaded == {"micro.renewal", "numba", "scipy"}, sorted(loaded)


@pytest.mark.parametrize("modules, not_loaded", [
    # what the command line checks its arguments with: the model, the methods' options, the
    # protocols, the output paths, the progress lines
    ("micro.cli", ("pandas", "numba", "scipy", "micro.renewal", "micro.grid", "micro.cohort", "micro.api")),
    ("micro.params, micro.methods, micro.protocols, micro._outputs, micro._progress, micro._branch_checks",
     ("pandas", "numba", "scipy", "micro.grid", "micro.cohort")),
    # V^c (micro.renewal.cached_vc): numba's kernels and scipy's root finder, no pandas
    ("micro.renewal", ("pandas", "micro.grid", "micro.cohort", "micro.fp", "micro.api")),
])
def test_what_the_checks_import_loads_nothing_they_do_not_need(modules, not_loaded):
    code = f"import sys, {modules}; print(sorted(m for m in sys.modules if m.startswith({not_loaded!r})))"
    done = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True,
                          env={"PYTHONPATH": str(ROOT), "PATH": "/usr/bin:/bin"}, timeout=120)
    assert done.stdout.strip() == "[]", done.stdout


def test_import_micro_loads_no_submodule_and_every_public_name_on_use():
    code = ("import sys, micro; print(sorted(m for m in sys.modules if m.startswith(('micro', 'pandas', 'numba', "
            "'scipy'))))")
    done = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True,
                          env={"PYTHONPATH": str(ROOT), "PATH": "/usr/bin:/bin"}, timeout=120)
    assert done.stdout.strip() == "['micro']", done.stdout
    names: dict = {}
    exec("from micro import *", names)
    assert set(micro.__all__) <= set(names) and all(names[n] is getattr(micro, n) for n in micro.__all__)
    assert micro.Numerics is micro.FP and micro.cycle_branch.__module__ == "micro.branch"
    assert micro.cohort.cycle_cohorts is not None and "Model" in dir(micro)  # a submodule, on first use
    with pytest.raises(AttributeError, match="no attribute 'no_such_name'"):
        micro.no_such_name


def test_the_names_type_checkers_see_are_the_names_micro_loads():
    # micro/__init__.py imports its names under TYPE_CHECKING (for type checkers and IDEs) and
    # loads them from its table _SOURCES: the two lists must not drift apart
    tree = ast.parse((ROOT / "micro" / "__init__.py").read_text())
    block, = (node for node in tree.body if isinstance(node, ast.If) and getattr(node.test, "id", "") == "TYPE_CHECKING")
    imported = {(node.module, alias.name) for node in block.body for alias in node.names}
    assert imported == {(module, name) for module, names in micro._SOURCES.items() for name in names}
    assert set(micro.__all__) <= set(micro._MODULE_OF)


def test_the_progress_clock_starts_when_the_computation_begins_not_at_the_imports():
    # the command line imports its computing modules inside its progress reporter, after the
    # checks: they are not computing, and the first line is still due 0.2 s into the computation
    from micro import _progress

    seen = []
    with _progress.reporting(lambda text, elapsed: seen.append((text, elapsed)), first=0.2):
        time.sleep(0.3)                  # (the imports)
        _progress.restart()
        with _progress.stage("computing"):
            _progress.beat()
            assert seen == []            # (without the restart: due at once, 0.3 s "computed")
            time.sleep(0.3)
            _progress.beat()
    assert seen and seen[0][0] == "computing" and 0.2 <= seen[0][1] < 0.3 + 5.0
