"""The examples in docs/formats.md run and print what the page says."""

from __future__ import annotations

import doctest

import pytest

from tests.conftest import ROOT


def test_formats_doc_examples(monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.chdir(ROOT)  # the page names files relative to the checkout
    result = doctest.testfile(
        str(ROOT / "docs" / "formats.md"), module_relative=False, optionflags=doctest.ELLIPSIS
    )
    assert result.attempted >= 2 and result.failed == 0
