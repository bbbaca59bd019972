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


def test_every_picture_of_the_guide_is_taken_by_a_browser_test() -> None:
    """docs/studio.md shows only screenshots the browser tests take (`make studio-img`
    writes them again), and docs/img/studio holds no other picture."""
    import re

    guide = (ROOT / "docs" / "studio.md").read_text()
    pictures = set(re.findall(r"img/studio/([\w-]+)\.png", guide))
    taken: set[str] = set()
    for test in (ROOT / "tests" / "studio").glob("test_*.py"):
        taken |= set(re.findall(r'shot\(pg, "([\w-]+)", doc=True\)', test.read_text()))
    assert pictures == taken
    assert {p.stem for p in (ROOT / "docs" / "img" / "studio").glob("*.png")} == pictures
