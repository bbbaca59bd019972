"""The API reference (issue 30.5): every public name of fuzzyctl's top level is documented
with an example, the examples in the docstrings run (doctest, from the repository root), and
the mkdocs site builds in strict mode (a broken link or reference fails)."""

from __future__ import annotations

import doctest
import importlib
import inspect
import os
import shutil
import subprocess
import sys
from pathlib import Path

import pytest

import fuzzyctl
from tests.conftest import ROOT

#: modules whose docstring examples are part of the reference (docs/api.md)
MODULES = ["fuzzyctl.api", "fuzzyctl.tune", "fuzzyctl.analysis", "fuzzyctl.control", "fuzzyctl.display"]


@pytest.fixture
def at_root() -> object:
    cwd = os.getcwd()
    os.chdir(ROOT)  # the examples use paths relative to the repository
    yield
    os.chdir(cwd)


def test_every_public_name_has_a_runnable_example() -> None:
    for name in fuzzyctl.__all__:
        if name == "__version__":
            continue
        obj = getattr(fuzzyctl, name)
        doc = inspect.getdoc(obj.tune if name == "tune" else obj) or ""
        assert ">>> " in doc, f"fuzzyctl.{name} has no example in its docstring"


@pytest.mark.parametrize("module", MODULES)
def test_docstring_examples_run(module: str, at_root: object) -> None:
    if module == "fuzzyctl.control":
        pytest.importorskip("control")
    if module == "fuzzyctl.tune":
        pytest.importorskip("dask")
    mod = importlib.import_module(module)
    result = doctest.testmod(mod, optionflags=doctest.ELLIPSIS | doctest.NORMALIZE_WHITESPACE)
    assert result.attempted > 0 and result.failed == 0


def mkdocs(args: list[str], cwd: Path) -> subprocess.CompletedProcess[str]:
    env = {**os.environ, "PYTHONPATH": os.pathsep.join([str(ROOT / "src"), os.environ.get("PYTHONPATH", "")])}
    return subprocess.run(
        [sys.executable, "-m", "mkdocs", "build", "--strict", *args],
        cwd=cwd,
        env=env,
        capture_output=True,
        text=True,
        timeout=120,
    )


def test_reference_builds_strict(tmp_path: Path) -> None:
    pytest.importorskip("mkdocs")
    pytest.importorskip("mkdocstrings_handlers.python")
    done = mkdocs(["-d", str(tmp_path / "site")], ROOT)
    assert done.returncode == 0, done.stderr
    page = (tmp_path / "site" / "api" / "index.html").read_text()
    # every public name of the top level has its section, its example rendered as code
    for name in [n for n in fuzzyctl.__all__ if n != "__version__"]:
        module = {"load": "api", "compile": "api", "plot_terms": "api", "analyze": "analysis"}.get(
            name, "tune"
        )
        assert f'id="fuzzyctl.{module}.{name}"' in page, name
    assert 'id="fuzzyctl.control.iosys"' in page and 'id="fuzzyctl.display.controller_html"' in page
    assert "&gt;&gt;&gt;" in page and "<blockquote>" not in page  # doctests as code, not quotes


def test_strict_build_fails_on_a_broken_reference(tmp_path: Path) -> None:
    # the same configuration on a one-page copy with a broken link and a broken
    # cross-reference: the strict build must refuse it
    pytest.importorskip("mkdocs")
    docs = tmp_path / "docs"
    docs.mkdir()
    (docs / "index.md").write_text("See [nowhere](missing.md) and [fuzzyctl.nothing][].\n")
    shutil.copy(ROOT / "mkdocs.yml", tmp_path / "mkdocs.yml")
    text = (tmp_path / "mkdocs.yml").read_text()
    start, end = text.index("nav:"), text.index("plugins:")
    (tmp_path / "mkdocs.yml").write_text(text[:start] + text[end:])
    done = mkdocs([], tmp_path)
    assert done.returncode != 0
    assert "missing.md" in done.stderr and "fuzzyctl.nothing" in done.stderr
