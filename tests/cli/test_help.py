"""Every ``--help`` page reads as plain help: no ``<bool>`` after flags, no ``{file}`` tokens in
the usage line, no sentence broken in the middle of a line, and nothing that looked like an
HTML tag swallowed by the markdown rendering."""

from __future__ import annotations

import itertools
import re
from collections.abc import Iterator
from typing import Any

import pytest
import typer

from fuzzyctl.cli import main
from fuzzyctl.cli.app import _register_commands, app

WIDTH = 100


def _commands() -> Iterator[tuple[str, ...]]:
    _register_commands()
    root = typer.main.get_command(app)

    def walk(command: Any, path: tuple[str, ...]) -> Iterator[tuple[str, ...]]:
        yield path
        for name, sub in getattr(command, "commands", {}).items():
            yield from walk(sub, (*path, name))

    yield from walk(root, ())


COMMANDS = list(_commands())


def test_every_command_is_covered() -> None:
    names = {c[0] for c in COMMANDS if c}
    assert {
        "check",
        "fmt",
        "eval",
        "explain",
        "convert",
        "codegen",
        "simulate",
        "serve",
        "studio",
        "blocks",
    } <= names


@pytest.mark.parametrize("command", COMMANDS, ids=lambda c: " ".join(c) or "fuzzyctl")
def test_help_page_is_plain(
    command: tuple[str, ...], capsys: pytest.CaptureFixture[str], monkeypatch: pytest.MonkeyPatch
) -> None:
    monkeypatch.setenv("COLUMNS", str(WIDTH))
    assert main([*command, "--help"]) == 0
    text = capsys.readouterr().out
    assert "<bool>" not in text
    usage = next(line for line in text.splitlines() if "Usage:" in line)
    assert "{" not in usage and "}" not in usage, usage
    assert not re.search(r"/\.(csv|png|html)\b", text), "a <placeholder> was eaten by the markdown rendering"
    prose = [
        line.strip()
        for line in text.splitlines()
        if line.strip() and not line.lstrip().startswith(("│", "╭", "╰", "Usage:"))
    ]
    for a, b in itertools.pairwise(prose):
        broken = len(a) < WIDTH * 0.6 and a[-1].isalnum() and b[0].islower()
        assert not broken, f"sentence broken mid-line:\n  {a}\n  {b}"
