"""Shared test configuration: where the project's reference data lives.

Data we may redistribute (jFuzzyLogic's and fuzzylite's test files, with their licences)
is vendored under ``tests/data/`` (see its SOURCES.md).  What we may not (the real-world
corpus, the manuals' text) and the outside tools (live jFuzzyLogic, matiec, the PLCopen
schema) live in ``../shared`` (or ``FUZZYCTL_SHARED``) and run as extra suites
(tests/extras.py): deselected in a bare clone, always run in CI."""

from __future__ import annotations

import os
from pathlib import Path

import pytest
from hypothesis import settings

from tests.conformance.measurements import pytest_terminal_summary  # noqa: F401  (a pytest hook)
from tests.extras import (  # noqa: F401  (pytest hooks)
    SHARED,
    pytest_collection_modifyitems,
    pytest_configure,
    pytest_unconfigure,
)

# `make test` must give the same verdict on every run, so property tests replay a fixed
# sequence of examples there; `make fuzz` draws fresh ones (and more of them) to hunt bugs.
settings.register_profile("ci", derandomize=True, print_blob=True)
settings.register_profile("fuzz", max_examples=1000, print_blob=True)
settings.load_profile(os.environ.get("HYPOTHESIS_PROFILE", "ci"))

# compile() picks the native backend by default, which compiles C for every new system: the
# tests use the Python path unless they ask for native (tests/codegen/test_native.py and the
# default-backend tests do), and keep their caches (native libraries, plans, the parser
# tables) apart from the user's, across runs (keyed by content and fuzzyctl's code).
os.environ.setdefault("FUZZYCTL_BACKEND", "python")
os.environ.setdefault("FUZZYCTL_CACHE_DIR", str(Path.home() / ".cache" / "fuzzyctl-tests" / "cache"))
os.environ.setdefault("FUZZYCTL_QUIET", "1")

ROOT = Path(__file__).resolve().parent.parent
EXAMPLES = ROOT / "examples"
DATA = ROOT / "tests" / "data"


def data_path(*parts: str) -> Path:
    """A vendored file under tests/data/ (always present in a clone)."""
    path = DATA.joinpath(*parts)
    if not path.exists():
        pytest.fail(f"vendored test data missing: {path}")
    return path


def shared_path(*parts: str) -> Path:
    """A path inside the shared data directory, for tests of an extra suite (which only run
    when that suite's data is there); a missing file is then a failure, never a skip."""
    path = SHARED.joinpath(*parts)
    if not path.exists():
        pytest.fail(f"reference data missing: {path} (set FUZZYCTL_SHARED to the shared directory)")
    return path
