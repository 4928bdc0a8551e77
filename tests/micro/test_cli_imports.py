"""``import micro`` loads none of its submodules (PEP 562: each public name on first use),
and the modules that check arguments load neither pandas nor numba nor scipy, so that a
command line can say a bad argument before it imports the modules that compute (most of a
second)."""
from __future__ import annotations

import ast
import subprocess
import sys
from pathlib import Path

import pytest

import micro

ROOT = Path(__file__).resolve().parents[2]


@pytest.mark.parametrize("modules, not_loaded", [
    # what the command line checks its arguments with: the model, the methods' options, the
    # protocols, the output paths, the progress lines
    ("micro.params, micro.methods, micro.protocols, micro._outputs, micro._progress",
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
