"""``python -m rsf``: the sweep, critical and run commands, their columns, and bad input."""
from __future__ import annotations

import re
import subprocess
import sys
from pathlib import Path

import numpy as np
import pandas as pd
import pytest

import rsf
from rsf.cli import main

ROOT = Path(__file__).resolve().parents[2]


def test_sweep_writes_one_row_per_V(tmp_path):
    out = tmp_path / "sweep.csv"
    assert main(["sweep", "--k0", "0.01", "--Dc", "0.06", "--V", "0.1,1,20", "--out", str(out)]) == 0
    df = pd.read_csv(out)
    assert list(df.columns[:8]) == ["k0", "Dc", "V", "regime", "sigma_max", "sigma_min",
                                    "sigma_mean", "period"]
    assert list(df.V) == [0.1, 1.0, 20.0]
    assert list(df.regime) == ["stick-slip", "stick-slip", "steady"]
    direct = rsf.limit_cycle(rsf.SpringSlider(k0=0.01), 1.0)
    assert df.sigma_max[1] == pytest.approx(direct.sigma_max, abs=1e-15)


def test_sweep_law_options(tmp_path):
    out = tmp_path / "sweep.csv"
    assert main(["sweep", "--k0", "0.3", "--V", "0.1", "--A", "0.007", "--B", "0.078",
                 "--mu-inf", "0.9", "--out", str(out)]) == 0
    got = pd.read_csv(out)
    direct = rsf.limit_cycle(rsf.SpringSlider(rsf.HyperbolicLaw(mu_inf=0.9), k0=0.3), 0.1)
    assert got.sigma_min[0] == pytest.approx(direct.sigma_min, abs=1e-15)
    # a table written by another tool
    table = tmp_path / "micro.csv"
    V = [0.01, 0.1, 1.0, 10.0, 100.0]
    pd.DataFrame({"V": V, "sigma": rsf.HyperbolicLaw(mu_inf=0.9).mu_ss(V)}).to_csv(table, index=False)
    assert main(["sweep", "--k0", "0.3", "--law", "table", "--table", str(table), "--V-range",
                 "0.05", "1", "3", "--out", str(out)]) == 0
    assert len(pd.read_csv(out)) == 3


def test_critical_writes_k0_Dc_Vc(tmp_path):
    out = tmp_path / "critical.csv"
    assert main(["critical", "--k0", "0.3,0.01", "--Dc", "0.06", "--out", str(out)]) == 0
    df = pd.read_csv(out)
    assert list(df.columns[:3]) == ["k0", "Dc", "Vc"]
    assert df.Vc[1] == pytest.approx(rsf.critical_velocity(rsf.HyperbolicLaw(), 0.01, 0.06).Vc, rel=1e-14)


def test_run_writes_series_and_events(tmp_path):
    out, ev = tmp_path / "run.csv", tmp_path / "events.csv"
    assert main(["run", "--k0", "0.3", "--V", "0.05", "--t-end", "20", "--out", str(out),
                 "--events", str(ev)]) == 0
    series, events = pd.read_csv(out), pd.read_csv(ev)
    assert list(series.columns) == ["t", "x", "sigma", "theta", "v"]
    assert list(events.columns) == ["t", "kind", "sigma", "theta", "x"]
    assert "slide->slip" in set(events.kind)
    # values: the series is the Python API's, and every switch sits on the threshold
    # phi(theta) = A / (D_c / theta + B) + mu_inf of the paper's law (a = 0)
    api = rsf.simulate(rsf.SpringSlider(k0=0.3), V=0.05, t_end=20.0)
    assert len(series) == len(api.t) and np.abs(series.sigma.to_numpy() - api.sigma).max() < 1e-12
    law = rsf.SpringSlider(k0=0.3).law
    switches = events[events.kind.str.contains("->")]
    phi = law.mu_ss(rsf.params.PAPER_DC / switches.theta.to_numpy())
    assert len(switches) >= 3 and np.abs(switches.sigma.to_numpy() - phi).max() < 1e-10
    assert main(["run", "--k0", "0.3", "--shs", "1", "5", "2", "--t-end", "12", "--out", str(out)]) == 0
    assert main(["run", "--k0", "0.3", "--steps", "1:5,3", "--t-end", "12", "--out", str(out)]) == 0


@pytest.mark.parametrize("argv, match", [
    (["sweep", "--k0", "-1", "--V", "1"], "--k0 must be in \\(0, 1000\\]"),
    (["sweep", "--k0", "1e300", "--V", "1"], "--k0 must be in \\(0, 1000\\]"),
    (["sweep", "--k0", "0.1", "--V", "0"], "--V must be in \\(0, 1e\\+07\\]"),
    (["sweep", "--k0", "0.1", "--V-range", "0.1", "1", "1e9"], "--V-range needs .* integer N in \\[1, 10000\\]"),
    (["run", "--k0", "0.3", "--V", "1", "--t-end", "1e12", "--out", "-"], "--t-end must be in \\(0, 1e\\+08\\]"),
    (["sweep", "--k0", "0.1", "--V", "1", "--out", ""], "--out must name a CSV file"),
    (["sweep", "--k0", "0.1", "--V", "1", "--out", "/proc/x.csv"], "cannot write in '/proc'"),
    (["sweep", "--k0", "0.1", "--V", "1", "--out", "/"], "is a directory"),
    (["sweep", "--k0", "0.1", "--V", "1", "--out", "/nonexistent-dir/x.csv"], "does not exist"),
    (["sweep", "--k0", "0.1", "--Dc", "0", "--V", "1"], "Dc must be a finite number > 0"),
    (["sweep", "--k0", "0.1", "--V", "1", "--rtol", "5"], "rtol must lie in"),
    (["sweep", "--k0", "0.1", "--V", "1", "--B", "0"], "B must be a finite number > 0"),
    (["sweep", "--k0", "0.1"], "exactly one of --V and --V-range"),
    (["run", "--k0", "0.1", "--t-end", "1", "--out", "x.csv"], "exactly one of --V, --steps, --shs"),
    (["sweep", "--k0", "0.1", "--V", "1", "--law", "table"], "--law table needs --table"),
])
def test_bad_input_exit_code_and_message(argv, match, capsys):
    assert main(argv) == 2
    err = capsys.readouterr().err
    assert re.search(match, err)


@pytest.mark.parametrize("V, match", [("0.5,,2", "item 2 of 3 must be a number"), ("5,nan", "item 2 must be finite")])
def test_list_items_are_all_checked_before_computing(V, match, capsys):
    with pytest.raises(SystemExit) as exc:
        main(["sweep", "--k0", "0.1", "--V", V, "--out", "-"])
    assert exc.value.code == 2 and re.search(match, capsys.readouterr().err)


def test_critical_says_when_steady_sliding_is_stable_at_every_V(capsys):
    assert main(["critical", "--k0", "1.0,0.1"]) == 0
    captured = capsys.readouterr()
    assert "k0=1: stable at every V" in captured.err
    frame = pd.read_csv(__import__("io").StringIO(captured.out))
    assert list(frame.status) == ["stable at every V", "unstable band"] and np.isnan(frame.Vc[0])


def test_unconverged_sweep_exits_3(tmp_path, capsys):
    out = tmp_path / "s.csv"
    code = main(["sweep", "--k0", "0.3", "--V", "0.2029", "--max-cycles", "3", "--no-accelerate",
                 "--out", str(out)])
    assert code == 3
    assert "not converged" in capsys.readouterr().err
    assert pd.read_csv(out).converged[0] == False  # noqa: E712


def test_module_entry_point_help():
    res = subprocess.run([sys.executable, "-m", "rsf", "sweep", "--help"], cwd=ROOT,
                         capture_output=True, text=True, timeout=120)
    assert res.returncode == 0
    for option in ("--k0", "--Dc", "--V", "--A", "--B", "--mu-inf", "--out", "--law", "--cycle-rtol"):
        assert option in res.stdout


def test_law_options_reach_the_model(tmp_path):
    # every law option of the CLI against the Python API built by hand: a misrouted option
    # (--eta-u, --k2, --law-a, --b, --state-law) changes V^c or the cycle by O(1)
    out = tmp_path / "critical.csv"
    assert main(["critical", "--k0", "0.1", "--law", "viscoelastic", "--k1", "0.2", "--eta-u", "2",
                 "--zbar", "0.2", "--out", str(out)]) == 0
    law = rsf.ViscoelasticLaw(zbar=0.2, k1=0.2, eta_u=2.0, k0=0.1)
    got, want = pd.read_csv(out).Vc[0], rsf.critical_velocity(law, 0.1, rsf.params.PAPER_DC).Vc
    assert got == pytest.approx(want, rel=1e-12)
    assert abs(want / rsf.critical_velocity(rsf.ViscoelasticLaw(k0=0.1), 0.1, rsf.params.PAPER_DC).Vc - 1) > 0.1

    # log law above its critical stiffness (b - a)/Dc = 0.13: steady at mu0 + (a - b) ln(V/v0)
    out = tmp_path / "sweep.csv"
    log = ["--law", "log", "--b", "0.02", "--law-a", "0.012", "--a", "0.012", "--v0", "0.5"]
    assert main(["sweep", "--k0", "0.3", *log, "--V", "2", "--out", str(out)]) == 0
    got = pd.read_csv(out).iloc[0]
    assert got.regime == "steady"
    assert got.sigma_mean == pytest.approx(0.6 - 0.008 * np.log(4.0), abs=1e-9)
    # ... and a velocity step 1 -> 3 with the slip law, sample by sample against the API
    out = tmp_path / "run.csv"
    assert main(["run", "--k0", "0.3", *log, "--state-law", "slip", "--steps", "1:5,3", "--t-end", "10",
                 "--out", str(out)]) == 0
    series = pd.read_csv(out)
    model = rsf.SpringSlider(rsf.LogLaw(mu0=0.6, a=0.012, b=0.02, v0=0.5), k0=0.3, a=0.012, state_law="slip")
    api = rsf.simulate(model, t_end=10.0, protocol=rsf.Protocol.velocity_steps([1.0, 3.0], [5.0]))
    aging = rsf.simulate(rsf.SpringSlider(model.law, k0=0.3, a=0.012), t_end=10.0,
                         protocol=rsf.Protocol.velocity_steps([1.0, 3.0], [5.0]))
    assert len(series) == len(api.t) and np.abs(series.sigma.to_numpy() - api.sigma).max() < 1e-12
    t = np.linspace(5.0, 5.2, 41)  # the transient after the step (slip ~ D_c): the two laws differ
    assert np.abs(np.interp(t, aging.t, aging.sigma) - np.interp(t, api.t, api.sigma)).max() > 1e-4


def test_run_slide_hold_slide_and_steps_match_the_api(tmp_path):
    out = tmp_path / "run.csv"
    assert main(["run", "--k0", "0.3", "--shs", "1", "5", "2", "--t-end", "12", "--out", str(out)]) == 0
    series = pd.read_csv(out)
    api = rsf.simulate(rsf.SpringSlider(k0=0.3), t_end=12.0,
                       protocol=rsf.Protocol.slide_hold_slide(1.0, 5.0, 2.0))
    assert series.t.iloc[-1] == pytest.approx(12.0)
    assert len(series) == len(api.t) and abs(series.sigma.to_numpy() - api.sigma).max() < 1e-12
    # the hold (t in [5, 7]): with the load point at rest the stress cannot rise
    hold = series[(series.t > 5.0 + 1e-9) & (series.t < 7.0 - 1e-9)]
    assert len(hold) > 1 and np.all(np.diff(hold.sigma) <= 1e-12)


def test_run_t_eval_and_runaway_on_the_command_line(tmp_path, capsys):
    out = tmp_path / "run.csv"
    log = ["--law", "log", "--b", "0.01", "--law-a", "0.005", "--a", "0.005", "--v0", "1",
           "--Dc", "10", "--mu0", "0.6"]
    assert main(["run", "--k0", "0.01", *log, "--steps", "1:10,10", "--t-end", "60",
                 "--t-eval-n", "61", "--out", str(out)]) == 0
    series = pd.read_csv(out)
    model = rsf.standard_rs(mu0=0.6, a=0.005, b=0.01, Dc=10.0, k0=0.01, v0=1.0)
    api = rsf.simulate(model, t_end=60.0, protocol=rsf.Protocol.velocity_steps([1.0, 10.0], [10.0]),
                       t_eval=np.linspace(0.0, 60.0, 61))
    assert np.array_equal(series.t.to_numpy(), np.linspace(0.0, 60.0, 61))
    assert np.abs(series.sigma.to_numpy() - api.sigma).max() < 1e-14
    assert main(["run", "--k0", "0.01", *log, "--steps", "1:10,10", "--t-end", "60",
                 "--t-eval", "0,1,2.5", "--out", str(out)]) == 0
    assert list(pd.read_csv(out).t) == [0.0, 1.0, 2.5]
    # the runaway (k0 = 0.8 k_c): exit status 3, a message with the time
    assert main(["run", "--k0", "0.0004", *log, "--steps", "1:10,10", "--t-end", "60",
                 "--out", str(out)]) == 3
    assert "runaway" in capsys.readouterr().err
    assert main(["run", "--k0", "0.01", *log, "--steps", "1:10,10", "--t-end", "60",
                 "--t-eval", "0,70", "--out", str(out)]) == 2
    assert main(["run", "--k0", "0.01", *log, "--V", "1", "--t-end", "60",
                 "--t-eval-n", "1", "--out", str(out)]) == 2


def test_run_history_state_laws_and_damping_on_the_command_line(tmp_path):
    hist = tmp_path / "history.csv"
    ts = np.linspace(0.0, 30.0, 31)
    pd.DataFrame({"t": ts, "V": 1.0 + 0.5 * np.sin(ts) ** 2}).to_csv(hist, index=False)
    out = tmp_path / "run.csv"
    log = ["--law", "log", "--b", "0.01", "--law-a", "0.005", "--a", "0.005", "--v0", "1",
           "--Dc", "10", "--mu0", "0.6"]
    extra = ["--state-law", "nagata", "--nagata-c", "1.5", "--b2", "0.003", "--Dc2", "30"]
    # Nagata with a second state is refused by the model (exit status 2)
    assert main(["run", "--k0", "0.01", *log, *extra, "--history", str(hist),
                 "--t-end", "40", "--out", str(out)]) == 2
    assert main(["run", "--k0", "0.01", *log, "--state-law", "prz", "--b2", "0.003", "--Dc2", "30",
                 "--eta-rad", "0.001", "--history", str(hist), "--t-end", "40", "--t-eval-n", "41",
                 "--out", str(out)]) == 0
    series = pd.read_csv(out)
    model = rsf.standard_rs(mu0=0.6, a=0.005, b=0.01, Dc=10.0, k0=0.01, v0=1.0, state_law="prz",
                            second_state=rsf.SecondState(0.003, 30.0), eta_rad=0.001)
    api = rsf.simulate(model, protocol=rsf.Protocol.sampled(ts, 1.0 + 0.5 * np.sin(ts) ** 2),
                       t_end=40.0, t_eval=np.linspace(0.0, 40.0, 41))
    assert np.abs(series.sigma.to_numpy() - api.sigma).max() < 1e-14
    assert main(["run", "--k0", "0.01", *log, "--b2", "0.003", "--V", "1", "--t-end", "4",
                 "--out", str(out)]) == 2                                  # --Dc2 missing
    assert main(["run", "--k0", "0.01", *log, "--history", str(tmp_path / "nope.csv"),
                 "--t-end", "4", "--out", str(out)]) == 2


def test_critical_and_sweep_with_radiation_damping(tmp_path):
    out = tmp_path / "vc.csv"
    log = ["--law", "log", "--b", "0.01", "--law-a", "0.005", "--a", "0.005", "--v0", "1",
           "--Dc", "10", "--eta-rad", "1e-4"]
    assert main(["critical", "--k0", "0.0004", *log, "--out", str(out)]) == 0
    assert pd.read_csv(out).Vc[0] == pytest.approx(10.0, rel=1e-13)     # (b - a - k0 Dc)/eta
    assert main(["sweep", "--k0", "0.0004", *log, "--V", "5,20", "--out", str(out)]) == 0
    assert list(pd.read_csv(out).regime) == ["stick-slip", "steady"]
