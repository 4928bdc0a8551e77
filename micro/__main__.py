"""``python -m micro``: see :mod:`micro.cli`."""
import os
import sys

from .cli import main

code = main()
if code == 130:
    # Ctrl-C: everything kept is written and closed; skip the interpreter's teardown of
    # numba, scipy and pandas (about a second), so that the process ends at once
    sys.stdout.flush()
    sys.stderr.flush()
    os._exit(code)
raise SystemExit(code)
