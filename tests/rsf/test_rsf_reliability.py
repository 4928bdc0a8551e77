"""Issue 39 (reliability, round two), rsf's rows: each call of the issue's table behaves as
its last column says."""
from __future__ import annotations

import io
import logging
import re
import sys
from pathlib import Path

import numpy as np
import pandas as pd
import pytest

import rsf
from rsf.cli import build_parser, main

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))
from _cli_checks import error_line as _error_line  # noqa: E402


# --- row 8: the same file twice ----------------------------------------------------------
def test_run_refuses_out_and_events_on_one_file(tmp_path, capsys, monkeypatch):
    out = tmp_path / "o.csv"
    argv = ["run", "--k0", "0.3", "--V", "0.05", "--t-end", "2"]
    assert main([*argv, "--out", str(out), "--events", str(out)]) == 2
    assert "--out and --events name the same file" in _error_line(capsys)
    assert not out.exists()                       # refused before anything was computed
    # the same file under another spelling: relative, or through a link
    monkeypatch.chdir(tmp_path)
    assert main([*argv, "--out", "o.csv", "--events", str(out)]) == 2
    link = tmp_path / "link.csv"
    link.symlink_to(out)
    assert main([*argv, "--out", str(link), "--events", "o.csv"]) == 2
    capsys.readouterr()
    assert main([*argv, "--out", "o.csv", "--events", "e.csv"]) == 0


# --- row 12: "wrote N rows" on stderr, stdout for data only ------------------------------
def test_wrote_rows_goes_to_stderr(tmp_path, capsys):
    out = tmp_path / "c.csv"
    assert main(["critical", "--k0", "0.1", "--out", str(out)]) == 0
    captured = capsys.readouterr()
    assert captured.out == ""
    assert f"wrote 1 rows to {out}" in captured.err
    assert main(["critical", "--k0", "0.1"]) == 0                 # to stdout: the CSV alone
    frame = pd.read_csv(io.StringIO(capsys.readouterr().out))
    assert list(frame.columns[:3]) == ["k0", "Dc", "Vc"]


# --- rows 2 and 3: the table law's file and --table-where ---------------------------------
@pytest.fixture
def table(tmp_path):
    path = tmp_path / "table.csv"
    V = [0.01, 0.1, 1.0, 10.0, 100.0]
    pd.DataFrame({"V": V, "sigma": rsf.HyperbolicLaw(mu_inf=0.9).mu_ss(V), "k0": [0.1, 0.1, 0.2, 0.1, 0.1],
                  "regime": ["steady", "stick-slip", "steady", "steady", "steady"]}).to_csv(path, index=False)
    return path


@pytest.mark.parametrize("extra, match", [
    (["--table", "/nope.csv"], r"--table '/nope.csv' cannot be read \(No such file"),
    (["--table", "{tmp}"], r"--table '.*' is a folder"),
    (["--table", "/dev/null"], r"--table '/dev/null' is not a readable CSV file"),
    (["--table", "{table}", "--table-where", "V >>> 1"], r"--table-where 'V >>> 1' is not a valid expression"),
    (["--table", "{table}", "--table-where", "V > 1e9"], r"has 0 row\(s\) after --table-where"),
    (["--table", "{table}", "--table-where", "W > 1"], r"--table-where 'W > 1': no column 'W'"),
    (["--table", "{table}", "--table-where", "regime > 1"], r"--table-where 'regime > 1' cannot be evaluated"),
    (["--table", "{table}", "--table-v-column", "W"], r"--table-v-column: column 'W' not in"),
    (["--table", "{table}", "--table-mu-column", "regime"], r"--table-mu-column: column 'regime' .* must hold numbers"),
])
def test_table_problems_are_one_line_and_exit_2(extra, match, table, tmp_path, capsys):
    extra = [x.format(tmp=tmp_path, table=table) for x in extra]
    assert main(["sweep", "--k0", "0.3", "--V", "1", "--law", "table", *extra]) == 2
    assert re.search(match, _error_line(capsys))


@pytest.mark.parametrize("where", [
    "@pd.io.common.os.system('touch {marker}')",
    "__import__('os').system('touch {marker}') == 0",
    "V.__class__.__init__.__globals__ > 1",
    "V[0] > 1",
    "V @ V > 1",
    "(lambda: open('{marker}', 'w'))() is None",
    "[c for c in V] == 1",
    "V",
])
def test_table_where_refuses_everything_but_column_comparisons(where, table, tmp_path, capsys):
    marker = tmp_path / "marker"
    where = where.format(marker=marker)
    assert main(["sweep", "--k0", "0.3", "--V", "1", "--law", "table", "--table", str(table),
                 "--table-where", where]) == 2
    assert _error_line(capsys).startswith("error: --table-where")
    assert not marker.exists()


def test_table_where_keeps_the_rows_of_column_comparisons(table, monkeypatch):
    # evaluated by rsf on the columns: neither pandas' query nor eval is ever called
    def forbidden(*args, **kwargs):
        raise AssertionError("pandas evaluated the expression")

    monkeypatch.setattr(pd.DataFrame, "query", forbidden)
    monkeypatch.setattr(pd.DataFrame, "eval", forbidden)
    monkeypatch.setattr(pd, "eval", forbidden)
    frame = pd.read_csv(table)
    keep = {
        "V > 1": [10.0, 100.0],
        "k0 == 0.1 and V < 3": [0.01, 0.1],
        "regime == 'steady'": [0.01, 1.0, 10.0, 100.0],
        "0.05 < V <= 10": [0.1, 1.0, 10.0],
        "not (V > 0.5) or k0 > 0.15": [0.01, 0.1, 1.0],
        "regime in ['stick-slip'] or V * 10 >= 1000": [0.1, 100.0],
        "-V < -50": [100.0],
    }
    for where, V in keep.items():
        assert list(rsf.laws.select_rows(frame, where).V) == V, where
    law = rsf.TabulatedLaw.from_csv(table, where="regime == 'steady'")
    assert list(law.V) == [0.01, 1.0, 10.0, 100.0]


def test_table_options_need_the_table_law(table, capsys):
    assert main(["sweep", "--k0", "0.3", "--V", "1", "--table", str(table)]) == 2
    assert "--table is for --law table" in _error_line(capsys)
    assert main(["sweep", "--k0", "0.3", "--V", "1", "--law", "log", "--table-where", "V > 1"]) == 2
    assert "--table-where is for --law table" in _error_line(capsys)


# --- row 10: physically meaningless input is refused, extrapolation is said -----------------
def test_default_mu_inf_refuses_a_negative_friction(capsys):
    # the call: sigma = -49 at k0 = 1e3, since 0.95 - 0.05 k0 < 0 for k0 > 19
    assert main(["sweep", "--k0", "1e3", "--V", "1"]) == 2
    line = _error_line(capsys)
    assert "--k0 must be < 19 with the default --mu-inf" in line and "got 1000" in line
    assert main(["sweep", "--k0", "1e3", "--V", "1", "--law", "viscoelastic"]) == 2
    assert "--k0 must be < 19" in _error_line(capsys)
    with pytest.raises(ValueError, match=r"k0 must be < 19 with the default mu_inf"):
        rsf.SpringSlider(k0=19.0)
    with pytest.raises(ValueError, match=r"k0 must be < 19 for this law"):
        rsf.SpringSlider(rsf.ViscoelasticLaw(), k0=25.0)
    # below the bound, or with mu_inf given, the model stands, and its friction is positive
    assert rsf.SpringSlider(k0=18.9).sigma_steady(1e7) > 0.0
    assert rsf.SpringSlider(rsf.HyperbolicLaw(mu_inf=0.5), k0=1e3).law.mu_inf == 0.5
    assert "< 19 with the default --mu-inf" in " ".join(build_parser()._subparsers._group_actions[0]
                                                        .choices["sweep"].format_help().split())


def test_table_law_outside_its_velocities_warns_once(table, tmp_path, caplog):
    out = tmp_path / "s.csv"
    with caplog.at_level(logging.WARNING, logger="rsf"):
        assert main(["sweep", "--k0", "0.3", "--law", "table", "--table", str(table),
                     "--V", "0.001,1,1000,5000", "--out", str(out)]) == 0
    flat = [r for r in caplog.records if "held flat" in r.getMessage()]
    assert len(flat) == 1 and r"--V = 0.001, 1000, 5000" in flat[0].getMessage()
    caplog.clear()
    with caplog.at_level(logging.WARNING, logger="rsf"):
        assert main(["sweep", "--k0", "0.3", "--law", "table", "--table", str(table),
                     "--V", "0.1,1", "--out", str(out)]) == 0
    assert not [r for r in caplog.records if "held flat" in r.getMessage()]


def test_table_law_queried_outside_its_velocities_during_a_run_warns_once(tmp_path, caplog):
    # the law is evaluated at the state velocity Dc/theta, which a stick takes below the
    # driving velocity: at V = 0.05 (inside [0.03, 100]) down to about 0.016, held flat there
    path = tmp_path / "t.csv"
    V = np.geomspace(0.03, 100.0, 9)
    pd.DataFrame({"V": V, "sigma": rsf.HyperbolicLaw(mu_inf=0.9).mu_ss(V)}).to_csv(path, index=False)
    table = ["--k0", "0.3", "--law", "table", "--table", str(path)]
    with caplog.at_level(logging.WARNING, logger="rsf"):
        assert main(["run", *table, "--V", "0.05", "--t-end", "30", "--out", str(tmp_path / "o.csv")]) == 0
    flat = [r.getMessage() for r in caplog.records if "held flat" in r.getMessage()]
    assert len(flat) == 1, flat
    assert re.match(r"simulate: the state velocity Dc/theta = 0\.01\d+ outside the table's velocities "
                    r"\[0\.03, 100\]", flat[0]), flat[0]
    caplog.clear()
    with caplog.at_level(logging.WARNING, logger="rsf"):
        assert main(["sweep", *table, "--V", "0.05,0.06", "--out", str(tmp_path / "s.csv")]) == 0
    flat = [r.getMessage() for r in caplog.records if "held flat" in r.getMessage()]
    assert len(flat) == 1 and flat[0].startswith("limit_cycle(V=0.05): the state velocity Dc/theta = 0.01"), flat
    # the API says it too; a run that stays inside the table says nothing
    caplog.clear()
    with caplog.at_level(logging.WARNING, logger="rsf"):
        law = rsf.TabulatedLaw(V, rsf.HyperbolicLaw(mu_inf=0.9).mu_ss(V))
        rsf.simulate(rsf.SpringSlider(law, k0=0.3), 0.05, t_end=30.0)
        assert len([r for r in caplog.records if "held flat" in r.getMessage()]) == 1
        law = rsf.TabulatedLaw(V, rsf.HyperbolicLaw(mu_inf=0.9).mu_ss(V))
        rsf.simulate(rsf.SpringSlider(law, k0=0.3), 1.0, t_end=30.0)
        assert len([r for r in caplog.records if "held flat" in r.getMessage()]) == 1


def test_history_shorter_than_t_end_warns(tmp_path, caplog):
    hist = tmp_path / "h.csv"
    pd.DataFrame({"t": [0.0, 10.0], "V": [1.0, 2.0]}).to_csv(hist, index=False)
    log = ["--law", "log", "--Dc", "10"]
    with caplog.at_level(logging.WARNING, logger="rsf"):
        assert main(["run", "--k0", "0.01", *log, "--history", str(hist), "--t-end", "20",
                     "--out", str(tmp_path / "o.csv")]) == 0
    held = [r.getMessage() for r in caplog.records if "holds its last" in r.getMessage()]
    assert held == ["--history ends at t = 10, before --t-end = 20: the driving holds its last "
                    "velocity, V = 2, from there on"]
    caplog.clear()
    with caplog.at_level(logging.WARNING, logger="rsf"):
        assert main(["run", "--k0", "0.01", *log, "--history", str(hist), "--t-end", "10",
                     "--out", str(tmp_path / "o.csv")]) == 0
    assert not [r for r in caplog.records if "holds its last" in r.getMessage()]


# --- row 11: messages name the option, count from 1, show plain numbers ----------------------
@pytest.mark.parametrize("argv, message", [
    (["run", "--k0", "0.3", "--steps", "1:5,2:-1,3", "--t-end", "10", "--out", "{out}"],
     "error: --steps item 2 duration must be in (0, 1e+08], got -1"),
    (["run", "--k0", "0.3", "--steps", "1:5,2,3", "--t-end", "10", "--out", "{out}"],
     "error: --steps item 2 of 3 must be velocity:duration (only the last item may omit it), got '2'"),
    (["run", "--k0", "0.3", "--steps", "1:0,3", "--t-end", "10", "--out", "{out}"],
     "error: --steps item 1 duration must be in (0, 1e+08], got 0"),
    (["run", "--k0", "0.3", "--shs", "1", "0", "2", "--t-end", "10", "--out", "{out}"],
     "error: --shs SLIDE must be in (0, 1e+08], got 0"),
    (["run", "--k0", "0.3", "--law", "log", "--V", "1", "--t-end", "10", "--t-eval", "-1,2", "--out", "{out}"],
     "error: --t-eval item 1 of 2 must be in [0, --t-end = 10], got -1"),
    (["run", "--k0", "0.3", "--law", "log", "--V", "1", "--t-end", "10", "--t-eval", "0,2,2", "--out", "{out}"],
     "error: --t-eval must increase strictly: item 3 of 3 is 2, after 2"),
    (["sweep", "--k0", "0.3", "--V", "1", "--Dc", "-1e-3"], "error: --Dc must be a finite number > 0, got -0.001"),
    (["sweep", "--k0", "0.3", "--V", "1", "--law", "log", "--law-a", "-1"],
     "error: --law-a must be a finite number >= 0, got -1.0"),
    (["sweep", "--k0", "0.3", "--V", "1", "--a", "-1"], "error: --a must be a finite number >= 0, got -1.0"),
    (["sweep", "--k0", "0.3", "--V", "1", "--mu-inf", "-inf"], "error: --mu-inf must be a finite number, got -inf"),
    (["sweep", "--k0", "0.3", "--V", "1", "--rtol", "1"], "error: --rtol must lie in [1e-14, 0.01], got 1.0"),
    (["sweep", "--k0", "0.3", "--V", "1", "--max-cycles", "0"], "error: --max-cycles must be an integer >= 1, got 0"),
    (["sweep", "--k0", "0.3", "--V", "1", "--state-law", "nagata", "--a", "0.01"],
     "error: --state-law nagata takes b from the log law: give --law log, got --law hyperbolic"),
])
def test_messages_name_the_option(argv, message, tmp_path, capsys):
    argv = [x.format(out=tmp_path / "o.csv") for x in argv]
    assert main(argv) == 2
    line = _error_line(capsys)
    assert line == message
    assert "np." not in line and "[0]" not in line


def test_history_messages_count_rows_from_1(tmp_path, capsys):
    hist = tmp_path / "h.csv"
    pd.DataFrame({"t": [0.0, 10.0, 5.0], "V": [1.0, 2.0, 1.0]}).to_csv(hist, index=False)
    argv = ["run", "--k0", "0.01", "--law", "log", "--Dc", "10", "--history", str(hist), "--t-end", "20",
            "--out", str(tmp_path / "o.csv")]
    assert main(argv) == 2
    assert _error_line(capsys) == "error: --history times must increase strictly: row 3 has t = 5 after 10"
    pd.DataFrame({"t": [0.0, 10.0], "V": [1.0, -2.0]}).to_csv(hist, index=False)
    assert main(argv) == 2
    assert _error_line(capsys) == "error: --history velocities must be in [0, 1e+07]: row 2 has V = -2"


def test_a_list_starting_with_a_minus_is_a_value(tmp_path):
    # argparse took "-1,2" (and "-1e-3") for an option: "expected one argument"
    out = tmp_path / "o.csv"
    argv = ["run", "--k0", "0.3", "--law", "log", "--V", "1", "--t-end", "10", "--out", str(out)]
    assert main([*argv, "--t-eval", "-1,2"]) == 2                                  # checked, not misparsed
    # (a negative --mu-inf is refused since issue 54: the log law's --mu0 takes the minus instead)
    assert main(["sweep", "--k0", "0.3", "--law", "log", "--V", "1", "--mu0", "-1e-3", "--out", str(out)]) == 0
    assert pd.read_csv(out).sigma_mean[0] == pytest.approx(-1e-3, abs=1e-12)
    assert main([*argv, "--t-eval", "0,2.5"]) == 0 and list(pd.read_csv(out).t) == [0.0, 2.5]


def test_api_messages_show_plain_numbers():
    checks = [
        (lambda: rsf.SpringSlider(k0=np.float64(-1.0)), "k0 must be a finite number > 0, got -1.0"),
        (lambda: rsf.SolverOptions(rtol=np.float64(1.0)), "rtol must lie in [1e-14, 0.01], got 1.0"),
        (lambda: rsf.Protocol(np.array([0.5, 1.0]), np.array([1.0, 1.0])), "times[0] must be 0, got 0.5"),
        (lambda: rsf.Protocol(np.array([0.0, 1.0, 1.0]), np.array([1.0, 1.0, 1.0])),
         "times must be finite and strictly increasing: item 3 of 3 is 1.0, after 1.0"),
        (lambda: rsf.Protocol(np.array([0.0, 1.0]), np.array([1.0, -1.0])),
         "velocities must be finite and >= 0: item 2 of 2 is -1.0"),
        (lambda: rsf.InitialState(perturbation=np.float64(-2.0)),
         "perturbation must be a finite number > -1, got -2.0"),
    ]
    for make, message in checks:
        with pytest.raises(ValueError) as exc:
            make()
        assert str(exc.value) == message and "np." not in str(exc.value)


# --- row 12: strict types in the API ----------------------------------------------------------
@pytest.mark.parametrize("make", [
    lambda: rsf.SpringSlider(k0=True),
    lambda: rsf.SpringSlider(k0="0.1"),
    lambda: rsf.SpringSlider(k0=0.1, Dc=np.bool_(True)),
    lambda: rsf.HyperbolicLaw(A=True),
    lambda: rsf.LogLaw(b="0.01"),
    lambda: rsf.SecondState(True, 1.0),
    lambda: rsf.NagataLaw(c=False),
    lambda: rsf.InitialState(theta=True),
    lambda: rsf.InitialState(sigma="1"),
    lambda: rsf.InitialState(perturbation=False),
    lambda: rsf.SolverOptions(rtol=True),
    lambda: rsf.SolverOptions(max_cycles=True),
    lambda: rsf.SolverOptions(v_max=True),
    lambda: rsf.limit_cycle(rsf.SpringSlider(k0=0.1), True),
    lambda: rsf.simulate(rsf.SpringSlider(k0=0.1), V="1", t_end=1.0),
    lambda: rsf.simulate(rsf.SpringSlider(k0=0.1), V=1.0, t_end=True),
])
def test_api_rejects_bools_and_strings_for_numbers(make):
    with pytest.raises(ValueError) as exc:
        make()
    message = str(exc.value)
    assert "\n" not in message and ("real number" in message or "integer" in message or "> 0" in message)


# --- row 5: next to the critical stiffness a sweep reports progress and ends in a status -----
def test_slow_limit_cycle_reports_progress_and_ends_in_a_status(tmp_path, caplog, capsys, monkeypatch):
    # the call (log law, k0 = 0.08333 next to k_c = (b - a)/Dc = 0.08333...): the cycle
    # changes by ~1e-4 per cycle and never meets cycle_rtol; a progress line every
    # _PROGRESS_CYCLES cycles (1000; 10 here to keep the test short), a row that says why
    monkeypatch.setattr(rsf.solver, "_PROGRESS_CYCLES", 10)
    out = tmp_path / "s.csv"
    with caplog.at_level(logging.INFO, logger="rsf"):
        code = main(["sweep", "--law", "log", "--k0", "0.08333", "--V", "1", "--max-cycles", "35",
                     "--out", str(out)])
    assert code == 3
    progress = [r.getMessage() for r in caplog.records if "of at most 35 cycles" in r.getMessage()]
    assert [m.split(": ")[1].split(" of")[0] for m in progress] == ["10", "20", "30"]
    row = pd.read_csv(out).iloc[0]
    assert (not row.converged) and row.status == rsf.Status.MAX_CYCLES
    assert "not converged within max_cycles (35 cycles; the last relative change" in row.message
    assert "not converged" in capsys.readouterr().err
    helptext = " ".join(build_parser()._subparsers._group_actions[0].choices["sweep"].format_help().split())
    assert "give up after this many cycles (default 20000)" in helptext


# --- row 12: every state variable is written ---------------------------------------------------
def test_two_state_run_writes_theta2(tmp_path):
    out = tmp_path / "o.csv"
    log = ["--law", "log", "--b", "0.01", "--law-a", "0.005", "--a", "0.005", "--v0", "1", "--Dc", "10",
           "--mu0", "0.6"]
    assert main(["run", "--k0", "0.01", *log, "--b2", "0.003", "--Dc2", "30", "--steps", "1:10,3",
                 "--t-end", "60", "--t-eval-n", "7", "--out", str(out)]) == 0
    series = pd.read_csv(out)
    assert list(series.columns) == ["t", "x", "sigma", "theta", "v", "theta2"]
    # theta2 starts at steady state for V = 1 (Dc2 / V) and relaxes to Dc2 / 3 after the step
    assert series.theta2.iloc[0] == pytest.approx(30.0, rel=1e-12)
    assert series.theta2.iloc[-1] == pytest.approx(10.0, rel=2e-2)
    # the friction of Eq. (7) with both state variables is the column sigma
    sigma = (0.6 + 0.005 * np.log(series.v) + 0.01 * np.log(series.theta / 10.0)
             + 0.003 * np.log(series.theta2 / 30.0))
    assert np.abs(sigma - series.sigma).max() < 1e-13
    # one state variable: the columns are unchanged
    assert main(["run", "--k0", "0.01", *log, "--steps", "1:10,3", "--t-end", "60", "--out", str(out)]) == 0
    assert list(pd.read_csv(out).columns) == ["t", "x", "sigma", "theta", "v"]


# --- row 12: a run's rows are bounded (a 60-unit Nagata run wrote 170-183k rows) ----------------
NAGATA = ["--k0", "0.1", "--Dc", "0.006", "--V", "1", "--eta-rad", "1e-3", "--law", "log",
          "--state-law", "nagata"]


def test_a_long_run_writes_a_bounded_number_of_rows(tmp_path, monkeypatch, capsys):
    # at rtol 1e-10 each fast cycle takes ~700 integrator steps; by default rsf run writes every
    # step only while there are at most OUT_ROWS of them, else one row per t-end/OUT_ROWS
    # between events (made small here so that a short run shows it)
    import rsf.cli

    monkeypatch.setattr(rsf.cli, "OUT_ROWS", 100)
    out, events, every = tmp_path / "o.csv", tmp_path / "e.csv", tmp_path / "all.csv"
    assert main(["run", *NAGATA, "--t-end", "0.5", "--out", str(every), "--out-dt", "0"]) == 0
    assert main(["run", *NAGATA, "--t-end", "0.5", "--out", str(out), "--events", str(events)]) == 0
    steps, rows, ev = pd.read_csv(every), pd.read_csv(out), pd.read_csv(events)
    assert len(steps) > 1000                                      # the integrator's own steps
    assert f"wrote {len(rows)} rows to {out} (of {len(steps)} integrator steps: one row per --out-dt = " \
           f"0.005 between events" in capsys.readouterr().err
    assert len(rows) <= 100 + 1 + 2 * len(ev)
    # the rows kept are exact steps, every event's row among them (the spring force's extrema)
    model = rsf.SpringSlider(rsf.LogLaw(), k0=0.1, Dc=0.006, state_law=rsf.NagataLaw(2.0), eta_rad=1e-3)
    run = rsf.simulate(model, 1.0, t_end=0.5)
    thin = run.thinned(0.005)
    assert len(thin.t) == len(rows) and len(run.t) == len(steps)
    kept = np.isin(run.t, thin.t)
    assert np.array_equal(thin.sigma, run.sigma[kept]) and np.array_equal(thin.v, run.v[kept])
    at_events = np.isin(run.t, [e.t for e in run.events])
    assert at_events.sum() >= 5 and np.all(kept[at_events])
    force, thin_force = run.sigma + 1e-3 * run.v, thin.sigma + 1e-3 * thin.v     # the spring's force
    assert thin_force.max() == force.max() and thin_force.min() == force.min()
    assert np.all((np.diff(thin.t) >= 0.005) | np.isin(thin.t[1:], [e.t for e in run.events]) |
                  (thin.t[1:] == run.t[-1]))
    # a run of at most OUT_ROWS steps keeps them all; --out-dt thins any run
    assert main(["run", *NAGATA, "--t-end", "0.01", "--out", str(out)]) == 0
    assert len(pd.read_csv(out)) <= 100
    assert main(["run", *NAGATA, "--t-end", "0.5", "--out", str(out), "--out-dt", "0.1"]) == 0
    assert len(pd.read_csv(out)) <= 6 + 2 * len(ev)
    helptext = " ".join(build_parser()._subparsers._group_actions[0].choices["run"].format_help().split())
    assert "at most about t-end/OUT_DT + 2 per event" in helptext


@pytest.mark.parametrize("extra, message", [
    (["--out-dt", "-1"], "error: --out-dt must be in [0, 0.5], got -1"),
    (["--out-dt", "nan"], "error: --out-dt must be in [0, 0.5], got nan"),
    (["--out-dt", "0.1", "--t-eval-n", "3"], "error: give at most one of --t-eval, --t-eval-n and --out-dt"),
])
def test_out_dt_is_checked(extra, message, tmp_path, capsys):
    assert main(["run", *NAGATA, "--t-end", "0.5", "--out", str(tmp_path / "o.csv"), *extra]) == 2
    assert _error_line(capsys) == message
    assert not (tmp_path / "o.csv").exists()


def test_thinned_keeps_events_and_both_rows_of_a_slip():
    run = rsf.simulate(rsf.SpringSlider(k0=0.1), 0.05, t_end=30.0)         # a = 0: instantaneous slips
    thin = run.thinned(5.0)
    slips = [e.t for e in run.events if e.kind == "stick->slip"]
    assert slips and all(np.count_nonzero(thin.t == t) == 2 for t in slips)
    assert thin.t[0] == 0.0 and thin.t[-1] == run.t[-1] and thin.events == run.events
    assert run.thinned(0.0) is run and len(thin.t) < len(run.t)
    with pytest.raises(ValueError, match=r"^dt must be a finite number >= 0, got -1$"):
        run.thinned(-1.0)


# --- row 1: a long run over steady sliding finishes; one bound on t_end for API and CLI ------
class _CountingRuns:
    """Counts the CVODE runs (integrate / integrate_outputs calls) of the solver."""

    def __init__(self, monkeypatch):
        self.calls = 0
        for name in ("integrate", "integrate_outputs"):
            original = getattr(rsf._sundials, name)
            monkeypatch.setattr(rsf._sundials, name, self._wrap(original))

    def _wrap(self, original):
        def counted(*args, **kwargs):
            self.calls += 1
            return original(*args, **kwargs)
        return counted


@pytest.mark.parametrize("law, steady", [("hyperbolic", 0.95 - 0.025 + 0.007 / 1.078), ("log", 0.6)])
def test_long_run_across_steady_sliding_finishes(law, steady, tmp_path, monkeypatch):
    # the call: exit 3 after 20 s ("slide at t = 0 did not end", 100000 runs of CVODE)
    # with the paper's law; with the log law CVODE's steps shrank to the noise of the steady
    # state and the run did not end
    runs = _CountingRuns(monkeypatch)
    out = tmp_path / "o.csv"
    # (a budget of 1e5 right-hand-side evaluations: the work is counted, and a regression
    # fails in seconds with STEP_BUDGET instead of running for minutes)
    assert main(["run", "--k0", "0.5", "--V", "1", "--law", law, "--t-end", "1e8", "--max-rhs-evals", "100000",
                 "--out", str(out)]) == 0
    series = pd.read_csv(out)
    assert series.t.iloc[-1] == pytest.approx(1e8, rel=1e-12)
    assert series.sigma.iloc[-1] == pytest.approx(steady, abs=1e-12)
    assert runs.calls < 200 and len(series) < 5000


def test_t_end_has_one_bound_for_api_and_cli(capsys):
    from rsf import cli

    assert rsf.params.T_END_MAX == cli.T_END_MAX == 1e8
    model = rsf.SpringSlider(k0=0.5)
    for t_end in (1e300, 2e8):
        with pytest.raises(ValueError, match=r"t_end must be <= 1e\+08 \(rsf.params.T_END_MAX\), got"):
            rsf.simulate(model, V=1.0, t_end=t_end)
    with pytest.raises(ValueError, match=r"t_end must be a finite number > 0, got inf"):
        rsf.simulate(model, V=1.0, t_end=float("inf"))
    assert main(["run", "--k0", "0.5", "--V", "1", "--t-end", "2e8", "--out", "-"]) == 2
    assert "--t-end must be in (0, 1e+08], got 2e+08" in _error_line(capsys)
    assert "end time, in (0, 1e+08]" in " ".join(build_parser()._subparsers._group_actions[0]
                                                 .choices["run"].format_help().split())
