"""Issue 39, row 11, compare's part: the command line names the option the user typed and
documents its limits; compare's checks show plain numbers (no numpy reprs) and count items
from 1."""
from __future__ import annotations

import numpy as np
import pytest

from compare import _validation as v
from compare.cli import build_parser, main


@pytest.mark.parametrize("argv, message", [
    (["--k0", "0.1", "20"], "error: --k0 must be in (0, 10), got 20 (value 2 of 2)"),
    (["--k0", "0"], "error: --k0 must be in (0, 10), got 0"),
    (["--eps", "-1"], "error: --eps must be a finite number > 0, got -1"),
    (["--dc", "nan"], "error: --dc must be a finite number > 0, got nan"),
    (["--workers", "0"], "error: --workers must be an integer >= 1, got 0"),
])
def test_cli_names_the_option(argv, message, tmp_path, capsys):
    assert main([*argv, "--out", str(tmp_path / "report"), "--no-cache"]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert err == [message]
    assert not (tmp_path / "report").exists()


def test_cli_help_states_the_limits():
    text = " ".join(build_parser().format_help().split())
    assert "each in (0, 10)" in text and "Limits: --k0 in (0, 10)" in text


def test_messages_show_plain_numbers_and_count_from_1():
    checks = [
        (lambda: v.positive("eps", np.float64(-1.0)), "eps must be a finite number > 0, got -1.0"),
        (lambda: v.in_range("x", np.float64(5.0), 0.0, 1.0), "x must lie in [0, 1], got 5.0"),
        (lambda: v.positive_int("n", np.float64(1.5)), "n must be an integer >= 1, got 1.5"),
        (lambda: v.positive_array("k0", np.array([0.1, 20.0]), high=10.0),
         "k0 must hold finite values in (0, 10): item 2 of 2 is 20.0"),
        (lambda: v.positive("eps", True), "eps must be a real number, got True"),
        (lambda: v.positive("eps", "0.1"), "eps must be a real number, got '0.1'"),
        (lambda: v.positive_array("k0", [True, False]), "k0 must be a sequence of numbers, got [True, False]"),
    ]
    for make, message in checks:
        with pytest.raises(ValueError) as exc:
            make()
        assert str(exc.value) == message
