"""Every ``--help`` page reads as plain help: no ``<bool>`` after flags, no ``{file}`` tokens in
the usage line, no sentence broken in the middle of a line, and nothing that looked like an
HTML tag swallowed by the markdown rendering."""

from __future__ import annotations

import ast
import itertools
import re
from collections.abc import Iterator
from typing import Any

import pytest
import typer

from fuzzyctl.cli import main
from fuzzyctl.cli.app import _register_commands, app
from tests.conftest import EXAMPLES

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


# ------------------------------------------------------------------ the lazy command list


def test_the_command_table_is_what_the_modules_register() -> None:
    """``fuzzyctl --help`` lists :data:`COMMANDS` without importing the command modules: the
    table must name the commands the modules register, in their order, with their summaries
    and modules."""
    import inspect

    from fuzzyctl.cli import commands

    _register_commands()
    root = typer.main.get_command(app)
    real = getattr(root, "commands", {})
    assert list(real) == list(commands.COMMANDS)
    for name, command in real.items():
        listed = commands.COMMANDS[name]
        assert listed.summary == inspect.cleandoc(command.help or "").split("\n\n")[0], name
        where = command.callback.__module__ if command.callback else f"fuzzyctl.cli.{name}"
        assert where == f"fuzzyctl.cli.{listed.module}", name
    assert set(commands.MODULES) == {c.module for c in commands.COMMANDS.values()}


def _fresh(code: str) -> str:
    import os
    import subprocess
    import sys

    env = {**os.environ, "COLUMNS": str(WIDTH)}
    done = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, env=env, check=True)
    return done.stdout


LOADED = (
    "import sys\nfrom fuzzyctl.cli import main\ncode = main({args!r})\n"
    "print('LOADED', code, sorted(m for m in sys.modules if m.startswith('fuzzyctl.cli.') "
    "or m in ('fuzzyctl.model', 'numpy')))"
)


def test_root_help_imports_no_command_and_reads_as_before(
    capsys: pytest.CaptureFixture[str], monkeypatch: pytest.MonkeyPatch
) -> None:
    out = _fresh(LOADED.format(args=["--help"]))
    text, _, loaded = out.rpartition("LOADED ")
    assert loaded.split(" ", 1)[0] == "0"
    assert ast.literal_eval(loaded.split(" ", 1)[1]) == ["fuzzyctl.cli.app", "fuzzyctl.cli.commands"]
    # the same page as with every command module imported (the real commands' help)
    monkeypatch.setenv("COLUMNS", str(WIDTH))
    _register_commands()
    assert main(["--help"]) == 0
    assert capsys.readouterr().out == text


def test_a_command_imports_its_own_module_only() -> None:
    out = _fresh(LOADED.format(args=["fmt", str(EXAMPLES / "figure7.fcl")]))
    code, loaded = out.rpartition("LOADED ")[2].split(" ", 1)
    assert code == "0"
    assert [m for m in ast.literal_eval(loaded) if m.startswith("fuzzyctl.cli.")] == [
        "fuzzyctl.cli.app",
        "fuzzyctl.cli.commands",
        "fuzzyctl.cli.lang",
    ]


def test_an_unknown_command_still_suggests_the_known_ones(capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["evl"]) == 2
    assert "eval" in capsys.readouterr().err
