"""The quick start of ``fuzzyctl eval FILE --set ...`` (fuzzyctl/cli/quick.py): the same output
as the full command line, without importing the command framework, and every other
invocation or any error left to the full command line."""

from __future__ import annotations

import io
import os
import string
import subprocess
import sys
from pathlib import Path

import pytest
from hypothesis import given
from hypothesis import strategies as st

from fuzzyctl.cli import main
from fuzzyctl.cli.quick import _parse, plain_table, try_quick
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


# ----------------------------------------------------------------------------- quick record

# an output no rule concludes: the engine warns that it always gives its DEFAULT
WARNS = """FUNCTION_BLOCK span
VAR_INPUT x : REAL; END_VAR
VAR_OUTPUT y : REAL; z : REAL; END_VAR
FUZZIFY x
  TERM lo := (0, 1) (10, 0);
  TERM hi := (0, 0) (10, 1);
END_FUZZIFY
DEFUZZIFY y
  TERM s := (0, 0) (5, 1) (10, 0);
  TERM b := (10, 0) (15, 1) (20, 0);
  METHOD : COG;
  DEFAULT := 0;
  RANGE := (0, 20);
END_DEFUZZIFY
DEFUZZIFY z
  TERM t := (0, 0) (1, 1) (2, 0);
  METHOD : COG;
  DEFAULT := 1;
END_DEFUZZIFY
RULEBLOCK r
  RULE 1 : IF x IS lo THEN y IS s;
  RULE 2 : IF x IS hi THEN y IS b;
END_RULEBLOCK
END_FUNCTION_BLOCK
"""


def _console(argv: list[str], env: dict[str, str]) -> subprocess.CompletedProcess[str]:
    """The console script's entry (quick path first) in a process of its own, output to pipes."""
    code = f"import sys; sys.argv = ['fuzzyctl', *{argv!r}]; from fuzzyctl.cli.entry import run; run()"
    return subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, env=env)


def _full(argv: list[str], env: dict[str, str]) -> subprocess.CompletedProcess[str]:
    code = f"import sys; from fuzzyctl.cli.app import main; sys.exit(main({argv!r}))"
    return subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, env=env)


def _quick_env(tmp_path: Path) -> dict[str, str]:
    env = {k: v for k, v in os.environ.items() if k not in ("COLUMNS", "FORCE_COLOR")}
    return dict(env, FUZZYCTL_BACKEND="auto", FUZZYCTL_CACHE_DIR=str(tmp_path / "cache"))


@pytest.mark.parametrize("form", [[], ["--json"]])
def test_the_quick_record_prints_what_the_full_command_line_prints(tmp_path: Path, form: list[str]) -> None:
    """The first start records the native controller, the second answers from the record:
    both print what the full command line prints, the warnings included."""
    src = tmp_path / "warns.fcl"
    src.write_text(WARNS)
    env = _quick_env(tmp_path)
    for path, sets in ((FIG7, ["--set", "temp=10", "--set", "pressure=60"]), (str(src), ["--set", "x=3"])):
        argv = ["eval", path, *sets, *form]
        full = _full(argv, env)
        assert full.returncode == 0, full.stderr
        first, second = _console(argv, env), _console(argv, env)
        assert list((tmp_path / "cache" / "quick").glob("*.json")), "no record was written"
        assert path == FIG7 or "always gives its DEFAULT" in full.stderr
        for run in (first, second):
            assert (run.returncode, run.stdout, run.stderr) == (0, full.stdout, full.stderr)


def test_an_answer_from_the_record_imports_neither_model_nor_engine(tmp_path: Path) -> None:
    env = _quick_env(tmp_path)
    argv = ["eval", FIG7, "--set", "temp=10", "--set", "pressure=60"]
    assert _console(argv, env).returncode == 0  # records
    code = (
        "import sys; from fuzzyctl.cli.quick import try_quick; "
        f"code = try_quick({argv!r}); "
        "print(code, sorted(m for m in sys.modules if m.startswith(('fuzzyctl.model', "
        "'fuzzyctl.engine', 'numpy', 'rich', 'typer', 'lark'))))"
    )
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, env=env, check=True)
    assert out.stdout.strip().splitlines()[-1] == "0 []", out.stdout
    assert "51.85185185" in out.stdout


def test_what_the_record_cannot_answer_goes_the_full_way(tmp_path: Path) -> None:
    """A misspelt input, a missing one, a library removed from the cache: the record steps
    aside and the full command line answers as it always does."""
    env = _quick_env(tmp_path)
    good = ["eval", FIG7, "--set", "temp=10", "--set", "pressure=60"]
    assert _console(good, env).returncode == 0
    for argv in (
        ["eval", FIG7, "--set", "temp=10", "--set", "presure=60"],
        ["eval", FIG7, "--set", "temp=10"],
    ):
        quick, full = _console(argv, env), _full(argv, env)
        assert quick.returncode == full.returncode != 0
        assert quick.stderr == full.stderr and "pressure" in full.stderr
    for lib in (tmp_path / "cache").rglob("*.so"):
        lib.unlink()
    after = _console(good, env)
    assert after.returncode == 0 and after.stdout == _full(good, env).stdout


@given(
    title=st.text(alphabet=string.ascii_letters + "_. -", min_size=1, max_size=40),
    rows=st.lists(
        st.tuples(
            st.text(alphabet=string.ascii_letters + "_", min_size=1, max_size=30),
            st.floats(allow_nan=False, allow_infinity=False).map(lambda v: f"{v:.10g}"),
        ),
        min_size=1,
        max_size=6,
    ),
)
def test_the_plain_table_is_what_rich_draws_on_a_pipe(title: str, rows: list[tuple[str, str]]) -> None:
    from rich.console import Console
    from rich.table import Table

    mine = plain_table(title, rows)
    table = Table(title=title, show_lines=False)
    table.add_column("output", overflow="fold")
    table.add_column("value", justify="right", overflow="fold", no_wrap=False)
    for a, b in rows:
        table.add_row(a, b)
    buf = io.StringIO()
    Console(file=buf, width=80, highlight=False).print(table)
    assert mine is None or mine == buf.getvalue()
    if len(title.strip()) == len(title) and sum(max(len(r[k]) for r in rows) for k in (0, 1)) < 60:
        assert mine is not None  # the common case is drawn without rich
