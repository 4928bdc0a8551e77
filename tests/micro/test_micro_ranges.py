"""Issue 54 (reliability, round three), micro's range and status rows: D10, D11, D16, D20
(the cohort's step), D21, D23-D26.  Each bad value fails at once with one line naming the
flag (CLI) or the parameter (API) and its range; a V^c outside the searched range says so."""
from __future__ import annotations

import math
import sys
from pathlib import Path

import numpy as np
import pandas as pd
import pytest

import micro
from micro.cli import main

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))
from _cli_checks import error_line as _error_line  # noqa: E402


# --- D21: negative friction, and zbar against the cutoff ------------------------------------
def test_a_stiffness_with_negative_fast_friction_is_refused(tmp_path, capsys):
    out = tmp_path / "s.csv"
    assert main(["steady", "--k0", "1000", "--V", "1", "--out", str(out)]) == 2
    line = _error_line(capsys)
    assert line.startswith("error: --k0 must be < 9 ") and "-99.1" in line
    assert not out.exists()
    with pytest.raises(ValueError, match=r"^k0 must be < 9 "):
        micro.Model(k0=9.0)
    assert micro.Model(k0=8.99).k0 == 8.99
    # where no stiffness helps, the jumps are blamed
    with pytest.raises(ValueError, match=r"^zbar must be < 0.909091 "):
        micro.Model(k0=0.1, jumps=micro.Exponential(5.0, 100.0))


def test_zbar_near_the_cutoff_is_refused(tmp_path, capsys):
    out = tmp_path / "s.csv"
    assert main(["steady", "--k0", "1", "--V", "1", "--zbar", "9.99", "--out", str(out)]) == 2
    line = _error_line(capsys)
    assert line.startswith("error: --zbar must be <= 0.3803 with --dist exp") and "(mean 4.18)" in line
    assert main(["steady", "--k0", "0.1", "--V", "1", "--zbar", "0.3", "--out", str(out)]) == 0
    assert pd.read_csv(out).zbar[0] == pytest.approx(0.3, rel=1e-10)   # the mean is --zbar


# --- D10, D11, D26, D16: the critical velocity's range ---------------------------------------
def test_vc_above_the_range_is_a_status_and_finished_rows_are_kept(tmp_path, capsys):
    out = tmp_path / "c.csv"
    assert main(["critical", "--k0", "0.1,5e-9", "--out", str(out)]) == 0
    frame = pd.read_csv(out)
    assert list(frame.status) == ["converged", "V^c above --V-max"]
    assert frame.Vc[0] == pytest.approx(0.7275, rel=1e-3) and math.isinf(frame.Vc[1])
    crit = micro.critical_velocity(micro.Model(k0=5e-9))
    assert crit.status == "V^c above V_max" and math.isinf(crit.Vc)


@pytest.mark.parametrize("argv", [["--k0", "0.1", "--zbar", "1e-6"], ["--k0", "0.8999"]])
def test_vc_below_the_range_is_not_no_stick_slip(argv, tmp_path, capsys):
    out = tmp_path / "c.csv"
    assert main(["critical", *argv, "--out", str(out)]) == 0
    row = pd.read_csv(out).iloc[0]
    assert row.status == "V^c below --V-min" and "--V-min = 0.0001" in row.message
    assert math.isnan(row.Vc) and row.V_high == 1e-4


def test_vc_below_the_range_is_found_with_a_lower_v_min(tmp_path):
    out = tmp_path / "c.csv"
    assert main(["critical", "--k0", "0.8999", "--V-min", "1e-6", "--out", str(out)]) == 0
    row = pd.read_csv(out).iloc[0]
    assert row.status in ("converged", "V^c below --V-min")   # never 'no stick-slip' for k0 < k2


@pytest.mark.parametrize("flag, value, message", [
    ("--V-min", "0", "error: --V-min must be in [1e-06, 1e+07], got 0.0"),
    ("--V-max", "2e7", "error: --V-max must be in [1e-06, 1e+07], got 20000000.0"),
    ("--V-max", "1e300", "error: --V-max must be in [1e-06, 1e+07], got 1e+300"),
    ("--rel-tol", "0", "error: --rel-tol must be in (0, 1), got 0.0"),
])
def test_critical_range_options_name_their_flag(flag, value, message, tmp_path, capsys):
    assert main(["critical", "--k0", "0.1", flag, value, "--out", str(tmp_path / "c.csv")]) == 2
    assert _error_line(capsys) == message


def test_api_critical_range():
    with pytest.raises(ValueError, match=r"^V_max must be in \[1e-06, 1e\+07\]"):
        micro.critical_velocity(micro.Model(k0=0.1), V_max=2e7)


# --- D16, D20: the cohort's cell and step --------------------------------------------------
def test_a_tiny_cohort_cell_names_the_flag(tmp_path, capsys):
    assert main(["sweep", "--k0", "0.1", "--V", "0.5", "--cohort-h", "1e-300", "--out", str(tmp_path / "s.csv")]) == 2
    line = _error_line(capsys)
    assert line.startswith("error: --cohort-h must be in [8.1e-07, 0.055]")
    assert "Maximum allowed dimension" not in line and "Recursion" not in line


def test_a_tiny_cohort_step_is_refused_before_computing(tmp_path, capsys):
    out = tmp_path / "s.csv"
    assert main(["sweep", "--k0", "0.1", "--V", "1,0.5", "--cohort-dt", "1e-300", "--out", str(out)]) == 2
    line = _error_line(capsys)
    assert line.startswith("error: --cohort-dt must be >= 5.5e-10 at V = 0.5")
    assert not out.exists()          # the steady row at V = 1 was not computed either
    with pytest.raises(ValueError, match=r"^Cohort dt must be >= "):
        micro.stationary(micro.Model(k0=0.1), 0.5, method=micro.Cohort(dt=1e-300))


# --- D23: --duration with another drive ------------------------------------------------------
@pytest.mark.parametrize("drive", [["--shs", "1", "1", "1", "1"], ["--schedule", "1:1"]])
def test_duration_with_another_drive_is_refused(drive, tmp_path, capsys):
    assert main(["run", "--k0", "0.1", *drive, "--duration", "5", "--out", str(tmp_path / "r.csv")]) == 2
    assert _error_line(capsys).startswith("error: --duration goes with --V only")


# --- D24, D25: API arguments ----------------------------------------------------------------
@pytest.mark.parametrize("call, message", [
    (lambda m: micro.slide_hold_slide(m, 1, []), "hold_times must hold at least one hold time"),
    (lambda m: micro.slide_hold_slide(m, 1, [1.0], resume=-5), "resume must be in (0, 1e+08]"),
    (lambda m: micro.slide_hold_slide(m, 1, "x"), "hold_times item 1 of 1 must be a number, got 'x'"),
    (lambda m: micro.slide_hold_slide(m, 1, np.array(["x"])), "hold_times item 1 of 1 must be a number, got 'x'"),
    (lambda m: micro.simulate(m, 2, duration="1"), "duration must be a number, got '1'"),
    (lambda m: micro.simulate(m, 2, duration=1, record_dt=-1), "record_dt must be a finite number > 0"),
    (lambda m: micro.simulate(m, micro.Drive.uniform(1.0, 1.0), duration=3), "duration goes with a constant"),
    (lambda m: micro.steady_sliding(m, np.array([])), "V must hold at least one velocity"),
])
def test_bad_api_arguments_are_one_error_naming_them(call, message):
    with pytest.raises(ValueError) as info:
        call(micro.Model(k0=0.1))
    assert str(info.value).startswith(message), str(info.value)
    assert "np." not in str(info.value)


# --- D20, the Fokker-Planck half: a run far beyond a day is refused at its pace ---------------
def test_a_run_that_would_take_days_is_refused_after_a_second(tmp_path):
    """`micro run --k0 1 --V 1e-6 --duration 1e8` showed an ETA of about 1200 h and ran on;
    now it stops once it has computed for a second, with the duration the 24 h bound
    allows (its pace measured, not derived), exit 2 and nothing written."""
    import subprocess
    import sys
    import time

    start = time.monotonic()
    done = subprocess.run([sys.executable, "-m", "micro", "run", "--k0", "1", "--V", "1e-6", "--duration", "1e8",
                           "--out", "r.csv"], cwd=tmp_path, capture_output=True, text=True, timeout=300)
    assert time.monotonic() - start < 120
    assert done.returncode == 2, done.stderr
    last = done.stderr.strip().splitlines()[-1]
    assert last.startswith("error: --duration 1e+08 would take about ") and "Traceback" not in done.stderr
    assert "more than the 24 h allowed; give a duration <= " in last
    reach = float(last.rsplit("<= ", 1)[1])
    assert 1.0 < reach < 1e8
    assert not (tmp_path / "r.csv").exists()


def test_max_wall_time_is_checked_and_lets_a_short_run_finish():
    model = micro.Model(k0=1.0)
    with pytest.raises(ValueError, match=r"max_wall_time must be a finite number > 0"):
        micro.simulate(model, 1.0, duration=1.0, max_wall_time=0.0)
    run = micro.simulate(model, 1.0, duration=0.5, max_wall_time=3600.0)
    assert run.records.t.iloc[-1] == pytest.approx(0.5)
