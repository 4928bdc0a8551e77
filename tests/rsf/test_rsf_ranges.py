"""Issue 54 (reliability, round three), rsf's range rows: D8, D9, D22 and the two left from
round two.  Each bad value fails at once with one line naming the option (CLI) or the
parameter (API) and its range; a "cycle" double precision cannot resolve is never reported
as converged."""
from __future__ import annotations

import math
import sys
from pathlib import Path

import pytest

import rsf
from rsf.cli import main
from rsf.results import Status

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))
from _cli_checks import error_line as _error_line  # noqa: E402


# --- D8: values that divided by zero -------------------------------------------------------
@pytest.mark.parametrize("command", ["sweep", "run"])
def test_tiny_dc_is_refused_naming_dc(command, tmp_path, capsys):
    extra = ["--t-end", "5", "--out", str(tmp_path / "r.csv")] if command == "run" else []
    assert main([command, "--k0", "0.1", "--V", "0.5", "--Dc", "1e-300", *extra]) == 2
    line = _error_line(capsys)
    assert line.startswith("error: --Dc must be >= 2.23e-58")
    assert not (tmp_path / "r.csv").exists()


def test_tiny_b_is_refused_naming_a_and_b(capsys):
    assert main(["sweep", "--k0", "0.1", "--V", "0.5", "--B", "1e-300"]) == 2
    line = _error_line(capsys)
    assert "--A/--B = 0.007/1e-300" in line and "--Dc = 0.06" in line and "--V = 0.5" in line


def test_api_dc_below_the_floor():
    with pytest.raises(ValueError, match=r"^Dc must be >= 2.23e-58"):
        rsf.SpringSlider(k0=0.1, Dc=1e-300)
    from rsf.params import DC_MIN
    assert rsf.SpringSlider(k0=0.1, Dc=DC_MIN).Dc == DC_MIN     # the bound itself is accepted


# --- D9: a period-0 "cycle" -----------------------------------------------------------------
@pytest.mark.parametrize("option, value, culprit", [("--Dc", "1e-20", "--Dc = 1e-20"),
                                                    ("--A", "1e300", "--A/--B = 1e+300/0.078"),
                                                    ("--mu-inf", "1e300", "--mu-inf = 1e+300")])
def test_unresolvable_cycles_are_refused(option, value, culprit, capsys):
    assert main(["sweep", "--k0", "0.1", "--V", "0.5", option, value]) == 2
    line = _error_line(capsys)
    assert culprit in line and "--k0 = 0.1" in line and "--V = 0.5" in line


def test_api_limit_cycle_refuses_an_unresolvable_cycle():
    model = rsf.SpringSlider(k0=0.1, Dc=1e-20)
    with pytest.raises(ValueError, match=r"^Dc = 1e-20 with k0 = 0.1, V = 0.5, A = 0.007"):
        rsf.limit_cycle(model, 0.5)
    with pytest.raises(ValueError, match=r"V = 0.5"):
        rsf.sweep(model, [0.5])
    with pytest.raises(ValueError, match=r"V = 0.5"):
        rsf.simulate(model, 0.5, t_end=1.0)


def test_small_dc_that_resolves_still_runs():
    # k0 Dc V = 5e-17 is above the bound (3.6e-17): a true cycle, the a = 0 limit of small K
    result = rsf.limit_cycle(rsf.SpringSlider(k0=0.1, Dc=1e-15), 0.5)
    assert result.converged and result.period > 1.0
    assert result.sigma_max - result.sigma_min == pytest.approx(0.007 / 0.078, rel=1e-6)


def test_a_period_zero_cycle_is_degenerate_not_converged():
    # the viscoelastic law has no onset check: its period-0 "cycle" must get an honest status
    model = rsf.SpringSlider(law=rsf.ViscoelasticLaw(), k0=0.1, Dc=1e-20)
    result = rsf.limit_cycle(model, 0.5)
    assert result.status == Status.DEGENERATE
    assert not result.converged and result.regime == "unknown"
    assert "not resolved in double precision" in result.message


# --- left from round two: a negative mu_inf -------------------------------------------------
def test_negative_mu_inf_is_refused(capsys):
    assert main(["sweep", "--k0", "0.1", "--V", "0.5", "--mu-inf", "-0.5"]) == 2
    assert _error_line(capsys).startswith("error: --mu-inf must be >= 0")
    with pytest.raises(ValueError, match=r"^mu_inf must be >= 0"):
        rsf.HyperbolicLaw(mu_inf=-0.5)
    assert rsf.HyperbolicLaw(mu_inf=0.0).mu_inf == 0.0


# --- D22: the viscoelastic law blames zbar, not k0 -----------------------------------------
def test_viscoelastic_huge_zbar_names_zbar(capsys):
    assert main(["sweep", "--law", "viscoelastic", "--zbar", "1e300", "--k0", "0.1", "--V", "0.5"]) == 2
    line = _error_line(capsys)
    assert line.startswith("error: --zbar must be < 2 f_th / (k0 + k1 + k2) = 1.81818")
    assert "k0 = 0.1" in line and "--k0 must be" not in line
    with pytest.raises(ValueError, match=r"^zbar must be <"):
        rsf.ViscoelasticLaw(zbar=1e300, k0=0.1)
    with pytest.raises(ValueError, match=r"^k0 must be < 19 "):   # k0 still blamed where it helps
        rsf.ViscoelasticLaw(k0=30.0)


# --- left from round two: a run beyond the event budget -------------------------------------
def test_run_beyond_the_event_budget_is_refused_with_the_bound(tmp_path, capsys):
    out = tmp_path / "r.csv"
    assert main(["run", "--k0", "0.1", "--V", "0.1", "--t-end", "1e8", "--out", str(out)]) == 2
    line = _error_line(capsys)
    assert line.startswith("error: --t-end 1e+08 is beyond the event budget")
    bound = float(line.rsplit("<= ", 1)[1])
    assert 5e6 < bound < 1e7       # the run stopped at t = 8.2e6 with "too many events"
    assert not out.exists()


def test_run_within_the_probe_is_the_whole_run(tmp_path, capsys):
    out = tmp_path / "r.csv"
    assert main(["run", "--k0", "0.1", "--V", "0.1", "--t-end", "100", "--out", str(out)]) == 0
    assert "too many events" not in capsys.readouterr().err
    import pandas as pd
    assert math.isclose(pd.read_csv(out).t.iloc[-1], 100.0)


# --- D25: an argument of another type ------------------------------------------------------
def test_rsf_options_of_another_type_are_refused():
    model = rsf.SpringSlider(k0=0.1)
    with pytest.raises(ValueError, match=r"^options must be an rsf.SolverOptions \(or None\), got 'fast'"):
        rsf.simulate(model, 0.5, t_end=1.0, options="fast")
    with pytest.raises(ValueError, match=r"^initial must be an rsf.InitialState"):
        rsf.limit_cycle(model, 0.5, initial=3)
