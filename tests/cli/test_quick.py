"""The quick start of ``fuzzyctl eval FILE --set ...`` (fuzzyctl/cli/quick.py): the same output
as the full command line, without importing the command framework, and every other
invocation or any error left to the full command line."""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

import pytest

from fuzzyctl.cli import main
from fuzzyctl.cli.quick import _parse, try_quick
from tests.conftest import EXAMPLES

FIG7 = str(EXAMPLES / "figure7.fcl")


@pytest.mark.parametrize(
    "args",
    [
        ["--set", "temp=10", "--set", "pressure=60", "--json"],
        ["-s", "temp=10", "-s", "pressure=60"],
        ["--set=temp=3", "--set=pressure=95", "--compat", "fuzzylite", "--json"],
        ["--set", "temp=27", "--block", "Fuzzy_FB", "--set", "pressure=55"],
    ],
)
def test_quick_path_prints_what_the_full_command_line_prints(
    args: list[str], capsys: pytest.CaptureFixture[str]
) -> None:
    assert main(["eval", FIG7, *args]) == 0
    full = capsys.readouterr().out
    assert try_quick(["eval", FIG7, *args]) == 0
    assert capsys.readouterr().out == full


@pytest.mark.parametrize(
    "argv",
    [
        ["eval", FIG7, "--set", "temp=10"],  # an error: the full command line reports it
        ["eval", FIG7, "--set", "temp=hot", "--set", "pressure=1"],
        ["eval", FIG7, "--csv", "x.csv"],  # not the simple form
        ["eval", FIG7],
        ["eval", "--help"],
        ["check", FIG7],
        ["eval", "missing.fcl", "--set", "a=1"],
    ],
)
def test_everything_else_goes_to_the_full_command_line(
    argv: list[str], capsys: pytest.CaptureFixture[str]
) -> None:
    assert try_quick(argv) is None
    assert capsys.readouterr().out == ""


def test_an_output_without_a_value_goes_to_the_full_command_line(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """Issue 14.6 (tests/cli/test_run.py): the full command line says why and exits 1."""
    from tests.cli.test_run import NO_RULE_FIRES

    src = tmp_path / "nan.fcl"
    src.write_text(NO_RULE_FIRES)
    for form in ([], ["--json"]):
        assert try_quick(["eval", str(src), "--set", "x=8", *form]) is None
        assert capsys.readouterr().out == ""
        assert try_quick(["eval", str(src), "--set", "x=2", *form]) == 0  # the rule fires
        assert "5" in capsys.readouterr().out


def test_parse_only_the_simple_form() -> None:
    assert _parse(["eval", "f.fcl", "-s", "a=1", "--json"]) is not None
    assert _parse(["eval", "f.fcl", "-s"]) is None
    assert _parse(["eval", "f.fcl", "g.fcl", "-s", "a=1"]) is None
    assert _parse(["eval", "f.fcl", "-s", "a=1", "--table"]) is None


def test_the_console_script_answers_without_importing_typer_or_numpy() -> None:
    code = (
        "import sys; from fuzzyctl.cli.quick import try_quick; "
        f"try_quick(['eval', {FIG7!r}, '--set', 'temp=10', '--set', 'pressure=60', '--json']); "
        "try_quick(['eval', "
        f"{FIG7!r}, '--set', 'temp=10', '--set', 'pressure=60', '--json']); "
        "print(sorted(m for m in ('typer', 'numpy', 'lark', 'rich') if m in sys.modules))"
    )
    env = dict(os.environ, FUZZYCTL_BACKEND="native")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, env=env, check=True)
    lines = out.stdout.strip().splitlines()
    assert lines[0] == lines[1] and '"valve": 51.85185185185' in lines[0]
    # the first call filled the caches (it may parse, lower, build); the second only read them
    code2 = code.replace(
        "try_quick(['eval', " + repr(FIG7) + ", '--set', 'temp=10', '--set', 'pressure=60', '--json']); ",
        "",
        1,
    )
    out = subprocess.run([sys.executable, "-c", code2], capture_output=True, text=True, env=env, check=True)
    assert out.stdout.strip().splitlines()[-1] == "[]", out.stdout
