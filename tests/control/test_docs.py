"""The examples in docs/control.md run and print what the page says."""

from __future__ import annotations

import doctest
import os

import pytest

from tests.conftest import ROOT

pytest.importorskip("control")


def test_control_doc_examples() -> None:
    cwd = os.getcwd()
    os.chdir(ROOT)  # the examples use paths relative to the repository
    try:
        result = doctest.testfile(
            str(ROOT / "docs" / "control.md"),
            module_relative=False,
            optionflags=doctest.ELLIPSIS | doctest.NORMALIZE_WHITESPACE,
        )
    finally:
        os.chdir(cwd)
    assert result.attempted >= 10 and result.failed == 0
