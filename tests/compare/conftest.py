"""The quick report, computed once per session: its tables are checked by
test_compare_report.py, and its micro cache lets the docs examples run in seconds."""
from __future__ import annotations

import pytest

import compare


@pytest.fixture(scope="session")
def quick_report(tmp_path_factory):
    """(report, cache folder) of ``compare.report(Settings.quick())``, serial."""
    tmp = tmp_path_factory.mktemp("quick")
    rep = compare.report(compare.Settings.quick(), out=tmp / "report", cache_dir=tmp / "cache", workers=1,
                         progress=False)
    return rep, tmp / "cache"
