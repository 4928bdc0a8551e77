"""``python -m micro``: see :mod:`micro.cli`."""
import os
import sys

from .cli import main

code = main()
if code in (2, 130):
    # Ctrl-C (130): everything kept is written and closed; bad input (2): refused before
    # anything is computed or written.  Skip the interpreter's teardown of numba, scipy and
    # pandas (about a second after a computation; 0.35 s after `branch`'s check against V^c,
    # the error line's own time being 0.9 s), so that the process ends at once
    sys.stdout.flush()
    sys.stderr.flush()
    os._exit(code)
raise SystemExit(code)
