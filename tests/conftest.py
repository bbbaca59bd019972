"""Shared test configuration: where the project's reference data lives.

``../shared`` (next to the checkout) holds the seeds, the real-world corpus and the
conformance data of other implementations.  ``FUZZYCTL_SHARED`` overrides the location.
A missing data directory is an error, never a silent skip."""

from __future__ import annotations

import os
from pathlib import Path

import pytest
from hypothesis import settings

# `make test` must give the same verdict on every run, so property tests replay a fixed
# sequence of examples there; `make fuzz` draws fresh ones (and more of them) to hunt bugs.
settings.register_profile("ci", derandomize=True, print_blob=True)
settings.register_profile("fuzz", max_examples=1000, print_blob=True)
settings.load_profile(os.environ.get("HYPOTHESIS_PROFILE", "ci"))

ROOT = Path(__file__).resolve().parent.parent
SHARED = Path(os.environ.get("FUZZYCTL_SHARED", ROOT.parent / "shared")).resolve()
EXAMPLES = ROOT / "examples"


def shared_path(*parts: str) -> Path:
    """A path inside the shared data directory; fails the test when it is missing."""
    path = SHARED.joinpath(*parts)
    if not path.exists():
        pytest.fail(f"reference data missing: {path} (set FUZZYCTL_SHARED to the shared directory)")
    return path


@pytest.fixture(scope="session")
def shared() -> Path:
    return shared_path()
