"""docs/codegen.md: the Python examples run as written, and the C program compiles with the
strict flags the page shows and prints what the page says."""

from __future__ import annotations

import doctest
import os
import re
from pathlib import Path

import pytest

from tests.conftest import ROOT

DOC = ROOT / "docs" / "codegen.md"


def test_python_examples(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setenv("FUZZYCTL_CACHE_DIR", str(tmp_path))
    cwd = os.getcwd()
    os.chdir(ROOT)
    try:
        result = doctest.testfile(
            str(DOC), module_relative=False, optionflags=doctest.ELLIPSIS | doctest.NORMALIZE_WHITESPACE
        )
    finally:
        os.chdir(cwd)
    assert result.attempted >= 4 and result.failed == 0


def test_c_example_is_the_shipped_program() -> None:
    """The page shows examples/codegen_main.c; tests/test_doc_console.py compiles it with the
    page's strict flags, runs it and compares what it prints with the page."""
    text = DOC.read_text()
    program = re.search(r"A complete program.*?```c\n(.*?)```", text, flags=re.S)
    assert program and program.group(1) == (ROOT / "examples" / "codegen_main.c").read_text()
    assert "examples/codegen_main.c" in re.search(r"```console\n\$ (cc .*?)\n", text).group(1)  # type: ignore[union-attr]
