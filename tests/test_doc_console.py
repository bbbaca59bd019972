"""Every ```console example in README.md and docs/*.md runs as written and prints what the page
shows (how they run: tests/doc_console.py)."""

from __future__ import annotations

from pathlib import Path

import pytest

from tests.doc_console import ALL, PAGES, matches, normalised, run, scratch_dir


@pytest.fixture(scope="module")
def scratch(tmp_path_factory: pytest.TempPathFactory) -> dict[Path, Path]:
    return {page: scratch_dir(tmp_path_factory.mktemp(page.stem)) for page in PAGES}


def test_the_pages_have_examples() -> None:
    assert len(ALL) >= 25
    assert {e.page.name for e in ALL} >= {"README.md", "engine.md", "sim.md", "codegen.md"}


@pytest.mark.parametrize("page", [p for p in PAGES if any(e.page == p for e in ALL)], ids=lambda p: p.name)
def test_console_examples_run_as_written(page: Path, scratch: dict[Path, Path]) -> None:
    for example in (e for e in ALL if e.page == page):
        got = run(example, scratch[page])
        if not matches(example, got):
            pytest.fail(
                f"{page.name}:{example.line}: $ {example.command}\n--- the page shows:\n"
                f"{normalised(example.expected)}\n--- the command printed:\n{got}\n"
                "(python -m tests.doc_console PAGE rewrites the page; read the diff)"
            )
