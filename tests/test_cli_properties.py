"""Property-based tests (hypothesis) of the three command lines' validators: any bad value
of a numeric option exits with status 2 and one line on stderr naming the option, before
anything is computed or written; good values of micro's `steady` give finite rows inside
the model's analytic bounds.

The CLIs are called in-process (``main(argv)``), so an example costs milliseconds.  A few
dozen examples each in the default run; ``-m slow`` runs more.
"""
from __future__ import annotations

import contextlib
import io
import math

import pandas as pd
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

import compare.cli
import micro
import micro.cli
import rsf.cli

QUICK = settings(max_examples=30, deadline=None, suppress_health_check=[HealthCheck.too_slow,
                                                                         HealthCheck.function_scoped_fixture])
MORE = settings(max_examples=300, deadline=None, suppress_health_check=[HealthCheck.too_slow,
                                                                        HealthCheck.function_scoped_fixture])

#: text that no numeric option accepts
NOT_A_NUMBER = st.sampled_from(["nan", "inf", "-inf", "abc", "", "1e400", "0x1p3q", "1,2,x"])
NEGATIVE = st.floats(max_value=-1e-300, allow_nan=False, allow_infinity=False).map(repr)

#: (command line before the option, option): options whose every negative value is
#: refused, after a valid command line (a repeated option: argparse keeps the last)
MICRO = [(["steady", "--k0", "0.1", "--V", "1"], opt) for opt in ("--k0", "--k1", "--k2", "--zbar", "--eta-u",
                                                                   "--f-th")] + \
        [(["sweep", "--k0", "0.1"], "--V"), (["sweep", "--k0", "0.1", "--V", "0.3"], "--cohort-dt")]
RSF = [(["sweep", "--k0", "0.1", "--V", "1"], opt) for opt in ("--k0", "--Dc", "--B", "--zbar", "--k2", "--eta-u")] + \
      [(["run", "--k0", "0.1", "--V", "1"], "--t-end"), (["critical", "--k0", "0.1"], "--k0")]
COMPARE = [([], "--k0"), ([], "--eps"), ([], "--dc"), ([], "--workers")]


def _run(main, argv):
    """``main(argv)``'s exit status and stderr (argparse's errors exit through SystemExit)."""
    err = io.StringIO()
    with contextlib.redirect_stderr(err), contextlib.redirect_stdout(io.StringIO()):
        try:
            status = main(argv)
        except SystemExit as stop:
            status = stop.code
    return status, err.getvalue()


def _check_refused(main, argv, option, out):
    status, err = _run(main, argv)
    assert status == 2, (argv, status, err)
    last = err.strip().splitlines()[-1]
    # the last line names the option as typed (argparse adds its usage lines above its own errors)
    assert option in last, (argv, err)
    assert "np.float64" not in err and "Traceback" not in err
    assert not out.exists(), f"{argv}: wrote {out} although the input was refused"


@QUICK
@given(case=st.sampled_from(MICRO), value=st.one_of(NOT_A_NUMBER, NEGATIVE))
def test_micro_refuses_a_bad_option_at_once_naming_it(tmp_path_factory, case, value):
    out = tmp_path_factory.mktemp("micro") / "out.csv"
    head, option = case
    _check_refused(micro.cli.main, head + [option, value, "--out", str(out)], option, out)


@QUICK
@given(case=st.sampled_from(RSF), value=st.one_of(NOT_A_NUMBER, NEGATIVE))
def test_rsf_refuses_a_bad_option_at_once_naming_it(tmp_path_factory, case, value):
    out = tmp_path_factory.mktemp("rsf") / "out.csv"
    head, option = case
    _check_refused(rsf.cli.main, head + [option, value, "--out", str(out)], option, out)


@QUICK
@given(case=st.sampled_from(COMPARE), value=st.one_of(NOT_A_NUMBER, NEGATIVE, st.just("0")))
def test_compare_refuses_a_bad_option_at_once_naming_it(tmp_path_factory, case, value):
    out = tmp_path_factory.mktemp("compare") / "report"
    head, option = case
    _check_refused(compare.cli.main, head + [option, value, "--out", str(out), "--no-cache", "--no-progress"],
                   option, out)


def _steady_rows(tmp_path_factory, k0, V):
    out = tmp_path_factory.mktemp("steady") / "out.csv"
    status, err = _run(micro.cli.main, ["steady", "--k0", repr(k0), "--V", ",".join(map(repr, V)),
                                        "--no-growth-rate", "--out", str(out)])
    return status, err, out


@QUICK
@given(k0=st.floats(1e-3, 1.0), V=st.lists(st.floats(1e-2, 1e3), min_size=1, max_size=3))
def test_micro_steady_gives_rows_inside_the_analytic_bounds(tmp_path_factory, k0, V):
    status, err, out = _steady_rows(tmp_path_factory, k0, V)
    assert status == 0, err
    rows = pd.read_csv(out)
    assert len(rows) == len(V) and rows.converged.all()
    model = micro.Model(k0=k0)
    lo, hi = micro.sigma_slow_limit(model), micro.sigma_fast_limit(model)
    assert all(math.isfinite(s) and min(lo, hi) - 1e-9 <= s <= max(lo, hi) + 1e-9 for s in rows.sigma)
    assert {"method", "sigma_error"} <= set(rows.columns)


@pytest.mark.slow
@MORE
@given(case=st.sampled_from([(micro.cli.main, *c) for c in MICRO] + [(rsf.cli.main, *c) for c in RSF]),
       value=st.one_of(NOT_A_NUMBER, NEGATIVE))
def test_bad_options_many_examples(tmp_path_factory, case, value):
    main, head, option = case
    out = tmp_path_factory.mktemp("many") / "out.csv"
    _check_refused(main, head + [option, value, "--out", str(out)], option, out)


# --- issue 54: ranges that exclude degenerate physics, and truthful statuses ------------------
def _log_floats(lo: float, hi: float):
    """Floats spread over the decades from ``lo`` to ``hi`` (as text)."""
    return st.floats(math.log10(lo), math.log10(hi)).map(lambda e: repr(10.0 ** e))


#: (command, command line before the option, option, values that must be refused): each
#: refused at once, naming the option, whatever the other options (the defaults here).
DEGENERATE = [
    (rsf.cli.main, ["sweep", "--k0", "0.1", "--V", "0.5"], "--Dc", _log_floats(1e-300, 1e-17)),
    (rsf.cli.main, ["sweep", "--k0", "0.1", "--V", "0.5"], "--A", _log_floats(1e15, 1e300)),
    (rsf.cli.main, ["sweep", "--k0", "0.1", "--V", "0.5"], "--B", _log_floats(1e-300, 1e-60)),
    (rsf.cli.main, ["sweep", "--k0", "0.1", "--V", "0.5"], "--mu-inf", _log_floats(1e15, 1e300)),
    (rsf.cli.main, ["sweep", "--k0", "0.1", "--V", "0.5"], "--mu-inf",
     st.floats(-1e300, -1e-300).map(repr)),
    (rsf.cli.main, ["run", "--k0", "0.1", "--V", "0.5", "--t-end", "5"], "--Dc", _log_floats(1e-300, 1e-17)),
    (rsf.cli.main, ["sweep", "--law", "viscoelastic", "--k0", "0.1", "--V", "0.5"], "--zbar",
     _log_floats(2.0, 1e300)),
    (micro.cli.main, ["steady", "--V", "1", "--k0", "0.1"], "--k0", st.floats(9.0, 1000.0).map(repr)),
    (micro.cli.main, ["steady", "--k0", "0.1", "--V", "1"], "--zbar", st.floats(0.381, 9.99).map(repr)),
    (micro.cli.main, ["critical", "--k0", "0.1"], "--V-min",
     st.one_of(_log_floats(1e-300, 9e-7), _log_floats(1.1e7, 1e300), st.just("0"))),
    (micro.cli.main, ["critical", "--k0", "0.1"], "--V-max", _log_floats(1.1e7, 1e300)),
    (micro.cli.main, ["sweep", "--k0", "0.1", "--V", "0.5"], "--cohort-dt", _log_floats(1e-300, 1e-10)),
    (micro.cli.main, ["sweep", "--k0", "0.1", "--V", "0.5"], "--cohort-h", _log_floats(1e-300, 8e-7)),
    (micro.cli.main, ["run", "--k0", "0.1", "--shs", "1", "1", "1", "1"], "--duration",
     st.floats(1e-3, 1e8).map(repr)),
    (compare.cli.main, ["--quick", "--no-cache", "--no-progress"], "--dc",
     st.one_of(_log_floats(1e-300, 4.9e-3), _log_floats(0.51, 1e300))),
]


@QUICK
@given(case=st.sampled_from(range(len(DEGENERATE))), data=st.data())
def test_degenerate_physics_is_refused_at_once_naming_the_option(tmp_path_factory, case, data):
    main, head, option, values = DEGENERATE[case]
    value = data.draw(values)
    out = tmp_path_factory.mktemp("degenerate") / ("report" if main is compare.cli.main else "out.csv")
    _check_refused(main, head + [option, value, "--out", str(out)], option, out)


@settings(max_examples=8, deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture])
@given(V_min=_log_floats(1e-4, 1e3))
def test_micro_critical_says_where_vc_lies_against_the_range(tmp_path_factory, V_min):
    # k0 = 0.1: V^c = 0.7275; a range that starts above it says so, never 'no stick-slip'
    out = tmp_path_factory.mktemp("critical") / "out.csv"
    status, err = _run(micro.cli.main, ["critical", "--k0", "0.1", "--V-min", V_min, "--out", str(out)])
    assert status == 0, err
    row = pd.read_csv(out).iloc[0]
    if float(V_min) < 0.727:
        assert row.status == "converged" and row.Vc == pytest.approx(0.72750434, rel=1e-6)
    elif float(V_min) > 0.728:
        assert row.status == "V^c below --V-min" and math.isnan(row.Vc)


@settings(max_examples=4, deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture])
@given(k0=_log_floats(1e-9, 7e-9))
def test_micro_critical_above_the_range_is_a_status_and_keeps_the_rows(tmp_path_factory, k0):
    out = tmp_path_factory.mktemp("critical") / "out.csv"
    status, err = _run(micro.cli.main, ["critical", "--k0", f"0.1,{k0}", "--out", str(out)])
    assert status == 0, err
    frame = pd.read_csv(out)
    assert list(frame.status) == ["converged", "V^c above --V-max"] and math.isinf(frame.Vc[1])


@QUICK
@given(spelling=st.sampled_from(["same", "relative", "dot", "link"]))
def test_rsf_run_refuses_out_and_events_on_one_file(tmp_path_factory, spelling, monkeypatch):
    folder = tmp_path_factory.mktemp("same")
    out = folder / "o.csv"
    other = {"same": str(out), "relative": "o.csv", "dot": "./o.csv", "link": str(folder / "l.csv")}[spelling]
    if spelling == "link":
        (folder / "l.csv").symlink_to(out)
    monkeypatch.chdir(folder)
    status, err = _run(rsf.cli.main, ["run", "--k0", "0.3", "--V", "0.05", "--t-end", "2", "--out", str(out),
                                      "--events", other])
    assert status == 2 and "--out and --events name the same file" in err and not out.exists()
