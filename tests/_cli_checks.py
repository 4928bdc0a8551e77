"""What the command-line tests of micro, rsf and compare check of a refused call: one line
on standard error, ``error: ...``, and no traceback (shared by their test files)."""
from __future__ import annotations


def error_line(capsys) -> str:
    """The one line of a refused call (and nothing else on stderr)."""
    err = capsys.readouterr().err
    lines = err.strip().splitlines()
    assert len(lines) == 1, err
    assert lines[0].startswith("error: ") and "Traceback" not in err
    return lines[0]
