"""``python -m rsf``: see :mod:`rsf.cli`."""
from __future__ import annotations

from .cli import main

raise SystemExit(main())
