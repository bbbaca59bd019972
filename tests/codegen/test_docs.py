"""docs/codegen.md: the Python examples run as written, and the C program compiles with the
strict flags the page shows and prints what the page says."""

from __future__ import annotations

import doctest
import os
import re
from pathlib import Path

import pytest

import fuzzyctl
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


def test_the_calling_program_parses_with_the_block() -> None:
    """The CODESYS calling program of "Importing into ..." is IEC 61131-3 that the tree-sitter
    grammar accepts together with the block it calls, and uses the block's real interface."""
    from fuzzyctl.codegen import generate_st
    from tests.codegen.test_st import tree_sitter_errors

    text = DOC.read_text()
    (program,) = [b for b in re.findall(r"```st\n(.*?)```", text, flags=re.S) if b.startswith("PROGRAM")]
    block = generate_st(fuzzyctl.load(ROOT / "examples" / "heater_extension.fcl"))
    assert tree_sitter_errors(block + "\n" + program) == []
    for name in [*re.findall(r"(\w+) :=", program.split("END_VAR")[1]), "power", "INFO"]:
        if name not in ("rPower", "bBadEco"):
            assert re.search(rf"^\s+{name} : ", block, flags=re.M), name
