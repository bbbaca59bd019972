"""docs/codegen.md: the Python examples run as written, and the C program compiles with the
strict flags the page shows and prints what the page says."""

from __future__ import annotations

import doctest
import os
import re
import shutil
import subprocess
from pathlib import Path

import pytest

from fuzzyctl.cli.app import main
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


def test_c_example_compiles_and_prints_what_the_page_says(tmp_path: Path) -> None:
    text = DOC.read_text()
    program = re.search(r"A complete program.*?```c\n(.*?)```", text, flags=re.S)
    console = re.search(r"```console\n\$ (cc .*?)\n(.*?)```", text, flags=re.S)
    assert program and console
    cc = shutil.which("cc")
    assert cc is not None, "the C example needs the system compiler"
    assert (
        main(["codegen", str(ROOT / "examples" / "figure7.fcl"), "--lang", "c", "-o", str(tmp_path / "gen")])
        == 0
    )
    (tmp_path / "main.c").write_text(program.group(1))
    command = console.group(1).split(" && ")[0].split()
    res = subprocess.run([cc, *command[1:]], cwd=tmp_path, capture_output=True, text=True)
    assert res.returncode == 0, res.stderr
    run = subprocess.run(["./fb"], cwd=tmp_path, capture_output=True, text=True)
    assert run.stdout == console.group(2)
