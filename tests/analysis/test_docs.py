"""The Python examples of docs/analyze.md run and print what the page says."""

from __future__ import annotations

import doctest
import os

from tests.conftest import ROOT


def test_analyze_doc_examples() -> None:
    cwd = os.getcwd()
    os.chdir(ROOT)  # the examples use paths relative to the repository
    try:
        result = doctest.testfile(
            str(ROOT / "docs" / "analyze.md"),
            module_relative=False,
            optionflags=doctest.ELLIPSIS | doctest.NORMALIZE_WHITESPACE,
        )
    finally:
        os.chdir(cwd)
    assert result.attempted >= 8 and result.failed == 0
