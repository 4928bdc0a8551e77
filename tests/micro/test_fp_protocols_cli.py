"""Slide-hold-slide and the command line of the Fokker-Planck solver."""
from __future__ import annotations

import math
import re
import subprocess
import sys
from pathlib import Path

import numpy as np
import pandas as pd
import pytest

import micro

sys.path.insert(0, str(Path(__file__).parent))
import _independent_renewal as IR  # noqa: E402

ROOT = Path(__file__).resolve().parents[2]


def test_peak_after_a_hold_grows_with_the_hold_and_saturates():
    # the dashpots relax during the hold (a single relaxation time, 1/gamma = 1.1), so
    # the peak grows with the hold and saturates: growth between 10 and 30 is far
    # below the growth between 0.3 and 3 (the paper's Fig. 7, exponential saturation)
    model = micro.Model(k0=1.0)
    holds = [0.0, 0.3, 3.0, 10.0, 30.0]
    table = micro.slide_hold_slide(model, 5.0, holds, numerics=micro.Numerics(eps=0.02))
    d = table.delta_sigma_max.to_numpy()
    assert np.all(np.isfinite(d))
    assert np.all(np.diff(d) > -2e-3)  # non-decreasing within the jitter k0 * eps
    assert d[2] - d[1] > 5.0 * max(d[4] - d[3], 2e-3)
    assert abs(d[0]) < 0.05 * d[-1]  # no hold, no peak


def _cli(*args, cwd):
    return subprocess.run([sys.executable, "-m", "micro", *args], cwd=cwd, capture_output=True, text=True,
                          env={"PYTHONPATH": str(ROOT), "PATH": "/usr/bin:/bin"}, timeout=300)


def test_cli_sweep_and_run_write_the_documented_columns(tmp_path):
    out = tmp_path / "sweep.csv"
    res = _cli("sweep", "--k0", "0.1", "--V", "0.3,2", "--out", str(out), cwd=tmp_path)
    assert res.returncode == 0, res.stderr
    table = pd.read_csv(out)
    for col in "k0,k1,k2,zbar,V,method,regime,sigma_max,sigma_min,sigma_mean,discretisation_error".split(","):
        assert col in table.columns
    assert list(table.regime) == ["stick-slip", "steady"]
    assert list(table.method) == ["cohort", "renewal"]  # the default: each row by its best method
    steady = table.iloc[1]
    assert steady.sigma_max == steady.sigma_min == steady.sigma_mean
    assert steady.sigma_mean == pytest.approx(0.893759123072792, abs=1e-10)  # the exact steady state
    assert table.iloc[0].sigma_max > table.iloc[0].sigma_min + 0.03

    out = tmp_path / "run.csv"
    res = _cli("run", "--k0", "0.3", "--schedule", "1:5,0:5,1:5", "--eps", "0.02", "--out", str(out), cwd=tmp_path)
    assert res.returncode == 0, res.stderr
    run = pd.read_csv(out)
    assert {"t", "w", "sigma"} <= set(run.columns)
    assert run.w.iloc[-1] == pytest.approx(10.0)


def test_cli_critical_writes_the_documented_columns(tmp_path):
    # the entry point, direct method (the default): V^c at k0 = 0.3 where micro's exact
    # branching ratio is 1 (checked here), and no V^c for k0 >= k2
    out = tmp_path / "vc.csv"
    res = _cli("critical", "--k0", "0.3,1.0", "--out", str(out), cwd=tmp_path)
    assert res.returncode == 0, res.stderr
    table = pd.read_csv(out)
    for col in "k0,k1,k2,zbar,Vc".split(","):
        assert col in table.columns
    stick, never = table.iloc[0], table.iloc[1]
    assert stick.status == "converged" and stick.V_low <= stick.Vc <= stick.V_high <= stick.V_low * (1 + 1e-8)
    b = float(micro.steady_sliding(micro.Model(k0=0.3), stick.Vc, growth_rate=False).branching_ratio)
    assert abs(b - 1.0) < 1e-9
    # against the independent reference (tests/micro/_independent_renewal.py), not a printed number
    assert stick.Vc == pytest.approx(IR.critical_velocity(micro.Model(k0=0.3)), rel=1e-9)
    assert never.status == "no stick-slip" and math.isnan(never.Vc)  # k0 >= k2
    assert "--no-refine" in _cli("critical", "--help", cwd=tmp_path).stdout


def test_cli_critical_fp_options_reach_the_bisection(tmp_path, monkeypatch):
    # --method fp and its numerics (a bisection costs 8+ s, so the call is intercepted and
    # answered by the direct method): a dropped --no-refine, --eps or --method passes silently
    import micro.api
    import micro.cli as cli

    seen = []
    direct = micro.api.critical_velocity

    def spy(model, **kw):
        seen.append((model, kw))
        return direct(model)

    # (the command imports micro.api's function when it runs, after its checks)
    monkeypatch.setattr(micro.api, "critical_velocity", spy)
    out = tmp_path / "vc.csv"
    assert cli.main(["critical", "--k0", "0.3", "--k1", "0.2", "--k2", "0.7", "--method", "fp", "--eps", "0.02",
                     "--rel-tol", "0.3", "--V-min", "0.02", "--no-refine", "--rtol", "0.005", "--out", str(out)]) == 0
    (model, kw), = seen
    assert (model.k0, model.k1, model.k2) == (0.3, 0.2, 0.7)
    assert kw["method"] == "fp" and kw["refine"] is False and kw["numerics"].eps == 0.02
    assert kw["rel_tol"] == 0.3 and kw["V_min"] == 0.02 and kw["convergence"].rtol == 0.005
    assert pd.read_csv(out).Vc.iloc[0] == pytest.approx(direct(model).Vc, rel=1e-12)


def test_cli_model_options_reach_the_model(tmp_path):
    # every model option of the CLI against Eq. (4) (deterministic jumps, closed form) at
    # values away from the defaults: a misrouted --eta-u, --f-th, --zbar, --k1 or --k2, or a
    # --dist that is not read, moves the stress by > 1e-2
    from micro.cli import main as micro_main

    out = tmp_path / "steady.csv"
    assert micro_main(["steady", "--k0", "0.4", "--k1", "0.2", "--k2", "0.6", "--zbar", "0.3", "--dist", "delta",
                       "--eta-u", "2.5", "--f-th", "0.7", "--V", "0.05,3", "--out", str(out)]) == 0
    frame = pd.read_csv(out)
    model = micro.Model(k0=0.4, k1=0.2, k2=0.6, eta_u=2.5, f_th=0.7, jumps=micro.Deterministic(0.3))
    want = [micro.sigma_deterministic_steady(model, V) for V in (0.05, 3.0)]
    np.testing.assert_allclose(frame.sigma, want, atol=1e-12)
    default = micro.Model(k0=0.4, jumps=micro.Deterministic(0.1))
    assert min(abs(micro.sigma_deterministic_steady(default, V) - w) for V, w in zip((0.05, 3.0), want)) > 1e-2
    assert list(frame.zbar) == [0.3, 0.3] and list(frame.k1) == [0.2, 0.2]


def test_cli_help_and_bad_input(tmp_path, capsys):
    from micro.cli import main as micro_main

    res = _cli("sweep", "--help", cwd=tmp_path)
    assert res.returncode == 0 and "--eps" in res.stdout and "--dist" in res.stdout
    # in this process (a subprocess each cost ~5 s of imports)
    assert micro_main(["sweep", "--k0", "-1", "--V", "1", "--out", str(tmp_path / "x.csv")]) == 2
    assert "k0 must be" in capsys.readouterr().err
    assert micro_main(["sweep", "--k0", "0.1", "--V", "1,abc", "--out", str(tmp_path / "x.csv")]) == 2
    assert "--V" in capsys.readouterr().err


def test_cli_run_slide_hold_slide_and_constant_velocity(tmp_path):
    from micro.cli import main as micro_main

    # slide 20 at V = 0.05 (stick-slip at k0 = 0.3), hold 10, resume 5: w ends at 1.25, the
    # stress never rises during the hold, and the table is the Python API's run
    out = tmp_path / "shs.csv"
    assert micro_main(["run", "--k0", "0.3", "--shs", "0.05", "20", "10", "5", "--eps", "0.025",
                       "--out", str(out)]) == 0
    run = pd.read_csv(out)
    assert {"t", "w", "sigma"} <= set(run.columns)
    assert run.t.iloc[-1] == pytest.approx(35.0) and run.w.iloc[-1] == pytest.approx(1.25)
    hold = run[(run.t > 20.0 + 1e-9) & (run.t < 30.0 - 1e-9)]
    assert len(hold) > 3 and np.all(np.diff(hold.sigma) <= 1e-12)
    api = micro.simulate(micro.Model(k0=0.3), micro.Drive.slide_hold_slide(0.05, 20.0, 10.0, 5.0),
                         numerics=micro.Numerics(eps=0.025)).records
    assert len(api) == len(run) and np.abs(api.sigma.to_numpy() - run.sigma.to_numpy()).max() < 1e-12

    # constant V = 2 for 5 time units: steady sliding, the late stress at the exact value
    # (0.87378 at k0 = 0.3; the frozen start is 0.0033 below it; measured 5.5e-5 off)
    out = tmp_path / "run.csv"
    assert micro_main(["run", "--k0", "0.3", "--V", "2", "--duration", "5", "--eps", "0.025",
                       "--out", str(out)]) == 0
    run = pd.read_csv(out)
    assert run.w.iloc[-1] == pytest.approx(10.0)
    exact = float(micro.steady_sliding(micro.Model(k0=0.3), 2.0, growth_rate=False).sigma)
    late = run[run.t > 2.5]
    assert abs(late.sigma.mean() - exact) < 5e-4


@pytest.mark.parametrize("argv, match", [
    (["sweep", "--k0", "0.1", "--V", "0.5,,2"], r"--V item 2 of 3 must be a number"),
    (["sweep", "--k0", "0.1", "--V", "5,nan"], r"--V item 2 must be in \[1e-06, 1e\+07\]"),
    (["critical", "--k0", "0.1,1e400"], r"--k0 item 2 must be in \[0, 1000\]"),
    (["steady", "--k0", "1e300", "--V", "1"], r"--k0 must be in \(0, 1000\]"),
    (["steady", "--k0", "0.1", "--V", "1", "--out", ""], "--out must name a CSV file"),
    (["steady", "--k0", "0.1", "--V", "1", "--out", "/proc/x.csv"], "cannot write in '/proc'"),
    (["steady", "--k0", "0.1", "--V", "1", "--out", "/"], "is a directory"),
    (["steady", "--k0", "0.1", "--V", "1", "--out", "/nonexistent-dir/x.csv"], "does not exist"),
    # run: each of these was accepted and ran for ever (a simulated time of 1e12)
    (["run", "--k0", "0.3", "--V", "1", "--duration", "1e12"], r"--duration must be in \(0, 1e\+08\]"),
    (["run", "--k0", "0.3", "--V", "1e9", "--duration", "1"], r"--V must be in \[1e-06, 1e\+07\]"),
    (["run", "--k0", "0.3", "--shs", "1", "1e12", "10", "20"], r"--shs SLIDE must be in \(0, 1e\+08\]"),
    (["run", "--k0", "0.3", "--schedule", "1:1e12"], r"--schedule item 1 duration must be in \(0, 1e\+08\]"),
    (["run", "--k0", "0.3", "--schedule", "1:10,nan:5"], r"--schedule item 2 velocity must be in \[0, 1e\+07\]"),
    (["sweep", "--k0", "0.1", "--V", "1", "--method", "fp", "--t-max", "1e300"], r"--t-max must be in \(0, 1e\+08\]"),
])
def test_every_input_is_checked_before_computing(argv, match, tmp_path, capsys):
    # each of these used to compute first (sweep --V 5,nan: 228 s) and fail on writing or on
    # the bad item; now one line names the option, in well under a second
    from micro.cli import main as micro_main

    if "--out" not in argv:
        argv = [*argv, "--out", str(tmp_path / "x.csv")]
    assert micro_main(argv) == 2
    assert re.search(match, capsys.readouterr().err)
    assert not (tmp_path / "x.csv").exists()


def test_critical_with_the_fp_answers_k0_above_k2_at_once(tmp_path):
    # k0 >= k2: steady sliding is stable at every V (closed form); the bisection used to run 9+ min
    from micro.cli import main as micro_main

    out = tmp_path / "vc.csv"
    assert micro_main(["critical", "--k0", "1.0", "--method", "fp", "--out", str(out), "-v"]) == 0
    row = pd.read_csv(out).iloc[0]
    assert row.status == "no stick-slip" and math.isnan(row.Vc) and "k2" in row.message


def test_run_progress_bar_does_not_change_the_run(capsys):
    # issue 18 item 6: `micro run` was silent for minutes; its bar is drawn by a thread that
    # only reads the simulated time while the kernel (which releases the GIL) runs
    model, drive = micro.Model(k0=0.3), micro.Drive.slide_hold_slide(0.05, 20.0, 10.0, 5.0)
    plain = micro.simulate(model, drive, numerics=micro.Numerics(eps=0.025)).records
    shown = micro.simulate(model, drive, numerics=micro.Numerics(eps=0.025), progress=True).records
    pd.testing.assert_frame_equal(plain, shown)
    assert "micro run" in capsys.readouterr().err
