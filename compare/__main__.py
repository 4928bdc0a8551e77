"""``python -m compare`` (see :mod:`compare.cli`)."""
import sys

from .cli import main

if __name__ == "__main__":
    sys.exit(main())
