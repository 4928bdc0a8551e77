"""The validation studies (``studies/``) apart from the benchmarks: one entry point that lists
and dispatches them, no private name of the packages reached from a study or a benchmark
(they go through ``micro.study_hooks``), and the hooks doing what they wrap."""
from __future__ import annotations

import ast
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

import micro
from micro import study_hooks as H

ROOT = Path(__file__).resolve().parents[1]
STUDIES = sorted(p.stem for p in (ROOT / "studies").glob("*.py") if not p.stem.startswith("_"))
PACKAGES = ("micro", "rsf", "compare")


def _private_uses(path: Path) -> list[str]:
    """Private names of micro/rsf/compare a file reaches: a private module or name imported,
    or ``alias._name`` on a module alias of those packages."""
    tree = ast.parse(path.read_text())
    aliases, found = set(), []
    for node in ast.walk(tree):
        if isinstance(node, ast.Import):
            for a in node.names:
                if a.name.split(".")[0] in PACKAGES:
                    if any(part.startswith("_") for part in a.name.split(".")):
                        found.append(a.name)
                    aliases.add(a.asname or a.name.split(".")[0])
        elif isinstance(node, ast.ImportFrom) and node.module and node.module.split(".")[0] in PACKAGES:
            for a in node.names:
                if a.name.startswith("_") or any(p.startswith("_") for p in node.module.split(".")):
                    found.append(f"{node.module}.{a.name}")
                aliases.add(a.asname or a.name)
    for node in ast.walk(tree):
        if isinstance(node, ast.Attribute) and node.attr.startswith("_") and not node.attr.startswith("__"):
            base = node.value
            while isinstance(base, ast.Attribute):
                base = base.value
            if isinstance(base, ast.Name) and base.id in aliases:
                found.append(f"{base.id}.{node.attr}")
    return found


def test_the_private_name_finder_sees_a_private_use(tmp_path):
    src = tmp_path / "s.py"
    src.write_text("import micro.cohort as C\nfrom micro.nblock import _drifts\nC._one_cycle(1, 2)\nC.cycle_cohorts\n")
    assert _private_uses(src) == ["micro.nblock._drifts", "C._one_cycle"]


@pytest.mark.parametrize("folder", ["studies", "benchmarks"])
def test_no_study_or_benchmark_reaches_a_private_name(folder):
    files = [p for p in (ROOT / folder).rglob("*.py") if p.name != "_harness.py"]
    assert files
    uses = {str(p.relative_to(ROOT)): u for p in files if (u := _private_uses(p))}
    assert not uses, uses


def _studies(*args: str) -> subprocess.CompletedProcess:
    return subprocess.run([sys.executable, "-m", "studies", *args], cwd=ROOT, capture_output=True, text=True,
                          timeout=300)


def test_studies_alone_prints_one_line_per_study():
    out = _studies()
    assert out.returncode == 0, out.stderr
    listed = [line.split()[0] for line in out.stdout.splitlines() if line.startswith("  ")]
    assert listed == STUDIES
    assert "micro_transition_fits" in listed and "rsf_normal_form" in listed


def test_studies_unknown_name_is_one_line_and_exit_2():
    out = _studies("no_such_study")
    assert out.returncode == 2
    assert out.stderr.strip().count("\n") == 0 and "no_such_study" in out.stderr


def test_studies_dispatches_to_the_study_and_its_options():
    out = _studies("rsf_normal_form", "--help")
    assert out.returncode == 0, out.stderr
    assert out.stdout.startswith("usage: python -m studies rsf_normal_form") and "--quick" in out.stdout


def test_every_study_is_in_the_index_and_no_moved_script_is_left_in_benchmarks():
    index = (ROOT / "studies" / "README.md").read_text()
    missing = [s for s in STUDIES if f"`{s}`" not in index or f"python -m studies {s}" not in index]
    assert not missing, missing
    assert not set(STUDIES) & {p.stem for p in (ROOT / "benchmarks").glob("*.py")}


def test_studies_are_not_a_package_of_the_distribution():
    text = (ROOT / "pyproject.toml").read_text()
    assert 'include = ["micro*", "rsf*", "compare*"]' in text
    assert 'testpaths = ["tests"]' in text


def test_gauss_rule_hook_replaces_and_restores_the_rule():
    from micro.cohort import state
    before = state._GX.copy(), state._GW.copy()
    x, w = np.polynomial.legendre.leggauss(4)
    with H.gauss_rule(0.5 * x + 0.5, 0.5 * w):
        assert state._GX.size == 4 and state._GW.sum() == pytest.approx(1.0)
    assert np.array_equal(state._GX, before[0]) and np.array_equal(state._GW, before[1])


def test_chain_on_grid_hook_gives_the_steady_stress():
    model, V = micro.Model(k0=0.1), 20.0
    chain = H.chain_on_grid(model, V, H.quadrature(model, V), H.chain_grid(160, model=model))
    assert chain.sigma == pytest.approx(float(micro.steady_sliding(model, V).sigma), abs=1e-8)
    with pytest.raises(ValueError, match="width or model"):
        H.chain_grid(10)


def test_every_study_parses_its_options_so_help_does_not_run_it():
    """``python -m studies NAME --help`` must print and exit, never start a study of minutes
    to hours: every study's ``main`` parses its command line (argparse) before any work."""
    silent = []
    for name in STUDIES:
        tree = ast.parse((ROOT / "studies" / f"{name}.py").read_text())
        main = next(n for n in tree.body if isinstance(n, ast.FunctionDef) and n.name == "main")
        calls = [n for n in ast.walk(main) if isinstance(n, ast.Call) and getattr(n.func, "attr", "") == "parse_args"]
        if not calls:
            silent.append(name)
    assert not silent, silent
