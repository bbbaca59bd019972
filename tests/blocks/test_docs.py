"""The examples in docs/blocks.md run and print what the page says."""

from __future__ import annotations

import doctest
import os

from tests.conftest import ROOT


def test_blocks_doc_examples() -> None:
    cwd = os.getcwd()
    os.chdir(ROOT)  # the examples open examples/...
    try:
        result = doctest.testfile(str(ROOT / "docs" / "blocks.md"), module_relative=False)
    finally:
        os.chdir(cwd)
    assert result.attempted >= 10 and result.failed == 0
