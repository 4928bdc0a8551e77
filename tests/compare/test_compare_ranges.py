"""Issue 54 (reliability, round three), compare's range rows: D14 (workers beyond the
cores), D15 (a D_c outside the fit's range, refused before computing, naming --dc) and D16
(messages name the options, not the fields)."""
from __future__ import annotations

import logging
import sys
import time
from pathlib import Path

import pytest

import compare
from compare.cli import main
from compare.runner import Runner
from compare.cache import NullCache
from micro._threads import available_cores

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))
from _cli_checks import error_line as _error_line  # noqa: E402


@pytest.mark.parametrize("value", ["1e300", "1e-300", "0.6"])
def test_a_dc_outside_the_fit_range_is_refused_at_once(value, tmp_path, capsys):
    start = time.perf_counter()
    assert main(["--quick", "--dc", value, "--out", str(tmp_path / "r"), "--no-progress", "--no-cache"]) == 2
    assert time.perf_counter() - start < 5.0           # was refused after 21 s of computing
    assert _error_line(capsys).startswith("error: --dc must be in [0.005, 0.5] (the range the D_c fit searches")
    assert not (tmp_path / "r").exists()


def test_api_dc_outside_the_fit_range():
    with pytest.raises(ValueError, match=r"^Dc must be in \[0.005, 0.5\]"):
        compare.report(compare.Settings.quick(), Dc=1e300, out=None, use_cache=False, progress=False)


def test_eps_message_names_the_option(tmp_path, capsys):
    assert main(["--quick", "--eps", "1e300", "--out", str(tmp_path / "r"), "--no-progress", "--no-cache"]) == 2
    line = _error_line(capsys)
    assert line.startswith("error: --eps must be in [kappa*zbar/1000, kappa*zbar/4]")


def test_workers_beyond_the_cores_are_capped_with_a_warning(caplog):
    with caplog.at_level(logging.WARNING, logger="compare.runner"):
        runner = Runner(NullCache(), workers=100000, progress=False)
    assert runner.workers == available_cores()
    assert f"workers=100000 is more than the {available_cores()} cores" in caplog.text
    assert Runner(NullCache(), workers=1, progress=False).workers == 1
