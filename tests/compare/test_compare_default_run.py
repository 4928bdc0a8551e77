"""The default ``python -m compare`` end to end, as a user runs it (slow: about a minute
on 2 idle cores once numba has compiled, see README.md; .ci/run runs it with the slow tier).

A fresh cache, so every micro point is computed.  The report's exact V^c (micro's renewal
chain) must be micro.critical_velocity's to the last digits and the independent renewal
reference's (tests/micro/_independent_renewal.py, no code shared) to 1e-9; every table of
the report is written with its shape.  The shapes are those of the default settings at
this commit (29 tables): a change of the settings, the scenarios or a table's columns
must update SHAPES on purpose."""
from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

import pandas as pd
import pytest

import compare
import micro

sys.path.insert(0, str(Path(__file__).parents[1] / "micro"))
import _independent_renewal as IR  # noqa: E402

ROOT = Path(__file__).resolve().parents[2]

#: (rows, columns) of each table of the default report
SHAPES = {
    "critical_velocity": (5, 14), "dc_critical": (5, 8), "dc_fit": (1, 14), "dc_per_k0": (5, 15),
    "dc_points": (35, 13), "dc_profile": (41, 6), "dc_profile_per_k0": (205, 7), "dc_rms_per_k0": (4, 3),
    "hopf_fit": (4, 23), "hopf_micro_laws": (129, 5), "hopf_points": (23, 21), "micro_branch": (315, 15),
    "micro_points": (35, 28), "micro_spectrum": (17, 8), "phase_laws": (4, 10), "phase_micro": (96, 7),
    "phase_reference": (76, 13), "phase_rs": (324, 7), "rs_bifurcation": (272, 9), "rs_spectrum": (12, 12),
    "rs_unstable_band": (5, 3), "settings": (1, 48), "shs_fit": (9, 14), "shs_points": (21, 5),
    "shs_trace": (3024, 5), "steady_fit": (6, 10), "steady_fit_checks": (6, 12), "steady_fit_residuals": (220, 5),
    "vc_curves": (24, 5),
}
FIGURES = ("bifurcation", "critical_velocity", "dc_profile", "hopf", "phase", "shs", "steady_fit")


@pytest.fixture(scope="module")
def default_report(tmp_path_factory):
    tmp = tmp_path_factory.mktemp("default")
    out = tmp / "report"
    env = dict(os.environ, PYTHONPATH=str(ROOT), COMPARE_CACHE_DIR=str(tmp / "cache"), MPLBACKEND="Agg")
    proc = subprocess.run([sys.executable, "-m", "compare", "--no-progress", "--out", str(out)], cwd=tmp, env=env,
                          capture_output=True, text=True, timeout=3600)
    assert proc.returncode == 0, proc.stderr[-3000:]
    assert proc.stdout.strip().splitlines()[-1].startswith(f"wrote {out} ({len(SHAPES)} tables, 7 figures)"), proc.stdout
    return out


@pytest.mark.slow
def test_the_default_report_has_every_table_with_its_shape_and_every_figure(default_report):
    tables = {p.stem: pd.read_csv(p) for p in default_report.glob("*.csv")}
    assert {name: t.shape for name, t in tables.items()} == SHAPES
    for name in FIGURES:
        assert (default_report / f"{name}.png").stat().st_size > 10_000, name
    summary = (default_report / "summary.md").read_text()
    assert "Preset `default`" in summary and "0 from the cache" in summary


@pytest.mark.slow
def test_the_default_report_has_the_exact_critical_velocity(default_report):
    crit = pd.read_csv(default_report / "critical_velocity.csv")
    assert list(crit.k0) == sorted(compare.PAPER_K0, reverse=True)
    assert (crit.micro_status == "converged").all()
    for k0, vc, err in zip(crit.k0, crit.Vc_micro, crit.Vc_micro_err):
        model = micro.Model(k0=float(k0))
        assert vc == pytest.approx(micro.critical_velocity(model).Vc, rel=1e-13), k0
        assert vc == pytest.approx(IR.critical_velocity(model), rel=1e-9), k0
        assert 0.0 < err < 1e-8 * vc, k0  # (its claimed error: 1e-10 to 2.7e-9 of V^c)
