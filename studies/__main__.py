"""``python -m studies NAME [options]``: run one study; ``python -m studies`` alone (or
``--help``, ``list``) prints the index, one line per study (its docstring's first
sentence).  The index is read from the modules' source, so listing imports nothing."""
from __future__ import annotations

import ast
import re
import importlib
import sys
from pathlib import Path

HERE = Path(__file__).resolve().parent


def names() -> list[str]:
    """Every study: the modules of this folder that do not start with an underscore."""
    return sorted(p.stem for p in HERE.glob("*.py") if not p.stem.startswith("_"))


def summary(name: str) -> str:
    """The first sentence of a study's docstring, on one line (cut at 110 characters)."""
    doc = ast.get_docstring(ast.parse((HERE / f"{name}.py").read_text())) or ""
    first = " ".join(doc.split("\n\n")[0].split())
    end = re.search(r"(?<!Fig)(?<!Figs)[.?](?=\s+[A-Z])", first)
    first = first if end is None else first[:end.end()]
    return first if len(first) <= 110 else first[:109].rstrip() + "…"


def index() -> str:
    """The index printed by ``python -m studies``."""
    width = max(len(n) for n in names())
    rows = [f"  {n:<{width}}  {summary(n)}" for n in names()]
    return ("usage: python -m studies NAME [options]   (NAME --help: its options)\n\n"
            "studies (studies/README.md has commands, run times, CSVs, citing pages):\n"
            + "\n".join(rows))


def main(argv: list[str] | None = None) -> int:
    args = sys.argv[1:] if argv is None else list(argv)
    if not args or args[0] in ("-h", "--help", "list"):
        print(index())
        return 0
    name, rest = args[0], args[1:]
    if name not in names():
        print(f"python -m studies: unknown study {name!r}; "
              "`python -m studies` lists them", file=sys.stderr)
        return 2
    module = importlib.import_module(f"studies.{name}")
    sys.argv = [f"python -m studies {name}", *rest]  # the study's argparse reads sys.argv
    module.main()
    return 0


if __name__ == "__main__":
    sys.exit(main())
