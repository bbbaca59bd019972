"""Bounded reading (issue 14, point 4): a size limit per format with a clear message, at most
:data:`MAX_DIAGNOSTICS_SHOWN` diagnostics printed per file with an "N more" line, source
lines indexed once per file, and long lines shown as a window around the column.  The
timings on 10 MB inputs are in benchmarks/large_inputs.py (no wall clock here)."""

from __future__ import annotations

from pathlib import Path

import pytest

import fuzzyctl
from fuzzyctl.cli.app import main
from fuzzyctl.diagnostics import (
    MAX_DIAGNOSTICS_SHOWN,
    MAX_LINE_SHOWN,
    DiagnosticError,
    error,
    render_all,
    warning,
)
from fuzzyctl.limits import MAX_JSON_DEPTH, max_input_bytes, read_input
from fuzzyctl.model import Span

EXAMPLES = Path(__file__).resolve().parent.parent / "examples"


def _padded(path: Path, size: int) -> Path:
    """tank.fcl followed by a comment that brings it to ``size`` bytes."""
    text = (EXAMPLES / "tank.fcl").read_text()
    path.write_text(text + "(* " + "x" * (size - len(text) - 6) + " *)\n")
    return path


@pytest.mark.parametrize("suffix", [".fcl", ".fis", ".fll", ".fpl", ".xfuz", ".json"])
def test_a_file_over_the_limit_is_refused_before_it_is_read(tmp_path: Path, suffix: str) -> None:
    fmt = suffix.lstrip(".")
    path = tmp_path / f"big{suffix}"
    with path.open("wb") as f:  # sparse: the size is what is checked, before any reading
        f.truncate(max_input_bytes(fmt) + 1)
    with pytest.raises(DiagnosticError) as info:
        fuzzyctl.load(path)
    d = info.value.diagnostics[0]
    assert d.code == "too-large" and d.file == str(path)
    assert "over the" in d.message and "limit" in d.message
    limit = max_input_bytes(fmt)
    assert f"{limit / (1024 * 1024):.1f} MiB limit" in d.message or f"{limit} bytes limit" in d.message
    assert "FUZZYCTL_MAX_INPUT_BYTES" in (d.hint or "")


def test_the_10000_rule_system_fits_every_format_that_writes_it() -> None:
    """The limits leave room for the 10,000-rule 8-input system of issue 17 in FCL, FLL and
    JSON (which spells out every span), measured on the system itself."""
    import sys

    sys.path.insert(0, str(Path(__file__).resolve().parent.parent / "benchmarks"))
    import systems as S

    system = S.SYSTEMS["rules10k"]
    assert len(S.fcl(system).encode()) < max_input_bytes("fcl")
    assert len(S.fll(system).encode()) < max_input_bytes("fll")
    assert max_input_bytes("json") > 30 * max_input_bytes("fcl")


def test_the_limit_is_an_environment_setting(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    path = _padded(tmp_path / "tank.fcl", 20_000)
    assert fuzzyctl.load(path).main.name == "tank"
    monkeypatch.setenv("FUZZYCTL_MAX_INPUT_BYTES", "10000")
    with pytest.raises(DiagnosticError, match="over the 10000 bytes limit"):
        fuzzyctl.load(path)
    # source text given to the API is held to the same limit
    with pytest.raises(DiagnosticError, match="limit"):
        fuzzyctl.load(path.read_text())
    monkeypatch.setenv("FUZZYCTL_MAX_INPUT_BYTES", "nonsense")
    assert max_input_bytes("xfuz") == 1024 * 1024


def test_cli_refuses_a_large_file_with_exit_1(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]
) -> None:
    path = _padded(tmp_path / "tank.fcl", 20_000)
    monkeypatch.setenv("FUZZYCTL_MAX_INPUT_BYTES", "10000")
    assert main(["check", str(path)]) == 1
    assert main(["convert", str(path), str(tmp_path / "out.json")]) == 1
    err = capsys.readouterr().err
    assert err.count("over the 10000 bytes limit for FCL files") == 2
    assert not (tmp_path / "out.json").exists()


def test_a_device_is_read_up_to_the_limit_and_no_further(monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setenv("FUZZYCTL_MAX_INPUT_BYTES", "4096")
    with pytest.raises(DiagnosticError) as info:
        read_input("/dev/zero", "fcl")  # endless: reading it all would never return
    assert info.value.diagnostics[0].code == "too-large"


def test_missing_and_directory_are_diagnostics(tmp_path: Path) -> None:
    for path, code in ((tmp_path / "none.fis", "no-file"), (tmp_path, "is-directory")):
        with pytest.raises(DiagnosticError) as info:
            read_input(path, "fis")
        assert info.value.diagnostics[0].code == code


def _many(n_errors: int, n_warnings: int) -> list:  # type: ignore[type-arg]
    out = [warning(f"w{k}", Span(k + 1, 1), code="w") for k in range(n_warnings)]
    out += [error(f"e{k}", Span(n_warnings + k + 1, 1), code="e") for k in range(n_errors)]
    return out


def test_at_most_max_shown_diagnostics_then_n_more() -> None:
    source = "\n".join(f"line {k}" for k in range(1, 400))
    diags = _many(150, 100)
    text = DiagnosticError(diags, source).render()
    lines = [ln for ln in text.splitlines() if ": error: " in ln or ": warning: " in ln]
    assert len(lines) == MAX_DIAGNOSTICS_SHOWN
    assert all(": error: " in ln for ln in lines)  # errors are chosen before warnings
    assert text.splitlines()[-1] == "... and 230 more diagnostic(s) not shown (130 error(s), 100 other)"
    assert len(render_all(diags[:5], source)) == 5  # few: all, no summary


def test_cli_check_caps_the_diagnostics(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    text = (EXAMPLES / "tank.fcl").read_text()
    bad = "".join(f"        RULE x{k} : IF error IS nothing{k} THEN dheat IS zero;\n" for k in range(300))
    path = tmp_path / "bad.fcl"
    path.write_text(text.replace("    END_RULEBLOCK", bad + "    END_RULEBLOCK"))
    assert main(["check", str(path)]) == 1
    err = capsys.readouterr().err
    assert err.count(": error: ") == MAX_DIAGNOSTICS_SHOWN
    assert "... and 280 more diagnostic(s) not shown (280 error(s), 0 other)" in err


class _CountingStr(str):
    splits = 0

    def split(self, *args, **kwargs):  # type: ignore[no-untyped-def,override]
        type(self).splits += 1
        return super().split(*args, **kwargs)


def test_source_lines_are_indexed_once_per_file() -> None:
    """The issue's 21 KB file took minutes: every diagnostic split the whole source again."""
    source = _CountingStr("\n".join(f"RULE {k} : IF a IS b THEN c IS d;" for k in range(3000)))
    diags = [error("bad", Span(k + 1, 6), code="x") for k in range(3000)]
    rendered = render_all(diags, source, limit=len(diags))
    assert _CountingStr.splits == 1
    assert rendered[2999].splitlines()[1].strip() == "RULE 2999 : IF a IS b THEN c IS d;"


def test_a_huge_line_is_shown_as_a_window_around_the_column() -> None:
    line = "a" * 500_000 + "XYZ" + "b" * 500_000
    d = error("here", Span(1, 500_001, 1, 500_004), code="x")
    text = d.render(line)
    shown, caret = text.splitlines()[1:3]
    assert len(shown) <= MAX_LINE_SHOWN + 12 and shown.strip().startswith("...")
    col = caret.index("^")
    assert shown[col : col + 3] == "XYZ" and caret[col:].rstrip() == "^~~"


def test_a_huge_run_of_unbalanced_parentheses_is_refused_at_its_first() -> None:
    """An unbalanced condition of 150,000 parentheses is not given to lark (whose error
    recovery over a million of them took 10 s): refused at the run's first parenthesis."""
    from fuzzyctl.diagnostics import DiagnosticError
    from fuzzyctl.fcl.parser import MAX_PAREN_RUN

    head = (
        "FUNCTION_BLOCK f\nVAR_INPUT a : REAL; END_VAR\nVAR_OUTPUT y : REAL; END_VAR\n"
        "FUZZIFY a TERM lo := (0, 1) (1, 0); END_FUZZIFY\n"
        "DEFUZZIFY y TERM lo := 0; METHOD : COGS; END_DEFUZZIFY\nRULEBLOCK r\n"
    )
    n = MAX_PAREN_RUN + 50_000
    rule = "RULE 1 : IF " + "(" * n + "a IS lo" + ")" * (n - 1) + " THEN y IS lo;\n"
    with pytest.raises(DiagnosticError) as err:
        fuzzyctl.load(head + rule + "END_RULEBLOCK\nEND_FUNCTION_BLOCK\n")
    first = err.value.diagnostics[0]
    assert f"{n:,} parentheses open in a row" in first.message
    assert first.span is not None and (first.span.line, first.span.column) == (7, 13)


@pytest.mark.parametrize(
    ("old", "new", "message"),
    [
        ("TYPE float", "TYPE " + "x" * 100_000, f"the name '{'x' * 20}... (100000 characters)' is longer"),
        ("MAX 30.00", "MAX " + "9" * 5001, f"the number {'9' * 20}... (5001 characters) is too large"),
        ("POINTS 0.00,1.0", "POINTS 1e400,1.0", "the number 1e400 is too large"),
    ],
)
def test_fpl_never_echoes_a_long_token_nor_reads_inf(
    tmp_path: Path, old: str, new: str, message: str
) -> None:
    """A megabyte-long name or a number beyond the double range in an FPL file: one short
    error at its place (the FPL reader quoted whole tokens, and read 5001 nines as inf)."""
    path = tmp_path / "big.fpl"
    path.write_text((EXAMPLES / "fpltest.fpl").read_text().replace(old, new, 1))
    with pytest.raises(DiagnosticError) as err:
        fuzzyctl.load(path)
    (diag,) = [d for d in err.value.diagnostics if d.is_error]
    assert diag.message.startswith(message) and len(diag.message) < 100
    assert diag.span is not None and diag.span.line == (7 if "TYPE" in old else 9 if "MAX" in old else 11)


def test_load_json_reads_spelt_non_numbers_and_refuses_overflowing_literals_at_their_place() -> None:
    """Every JSON reader goes through ``load_json`` (issue 25): NaN / Infinity spelt out are
    read as such; a literal beyond the double range is refused at its line and column, as the
    FCL reader refuses it, never read as an infinity or kept as an integer no float holds."""
    import math

    from fuzzyctl.limits import load_json

    data = load_json("[NaN, Infinity, -Infinity, 1.5, 7]")
    assert math.isnan(data[0]) and data[1:3] == [math.inf, -math.inf] and data[3:] == [1.5, 7]
    for literal in ("1e400", "-1e400", "9" * 309, "-" + "9" * 309, "9" * 5001):
        with pytest.raises(DiagnosticError) as caught:
            load_json(f'{{"a":\n  [0, {literal}]}}', "t.json")
        (found,) = caught.value.diagnostics
        assert found.code == "number-range" and found.span is not None
        assert (found.span.line, found.span.column) == (2, 7), found.render()
    assert load_json("[" + "9" * 308 + "]")[0] == int("9" * 308)  # below 1.8e308: a number
    text = "[" * (MAX_JSON_DEPTH + 1) + "]" * (MAX_JSON_DEPTH + 1)
    with pytest.raises(DiagnosticError) as caught:
        load_json(text, "t.json")
    (found,) = caught.value.diagnostics
    assert found.code == "json-depth" and found.span is not None and found.span.column == MAX_JSON_DEPTH + 1
