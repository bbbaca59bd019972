"""The example in docs/studio.md runs and prints what the page says."""

from __future__ import annotations

import doctest
import os

from tests.conftest import ROOT


def test_studio_doc_examples() -> None:
    cwd = os.getcwd()
    os.chdir(ROOT)  # the example uses paths relative to the repository
    try:
        result = doctest.testfile(
            str(ROOT / "docs" / "studio.md"),
            module_relative=False,
            optionflags=doctest.ELLIPSIS | doctest.NORMALIZE_WHITESPACE,
        )
    finally:
        os.chdir(cwd)
    assert result.attempted >= 5 and result.failed == 0
