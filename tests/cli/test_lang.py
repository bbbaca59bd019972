"""fuzzyctl check / fmt: exit codes, JSON, and no traceback on garbage input."""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from fuzzyctl.cli import main
from fuzzyctl.fcl import load_file
from tests.conftest import EXAMPLES

FIG7 = EXAMPLES / "figure7.fcl"


def test_check_ok_reports_level(capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["check", str(FIG7)]) == 0
    out = capsys.readouterr().out
    assert "Conformance level needed: Extension" in out and "WITH constant" in out


def test_checklist(capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["check", "--checklist", str(FIG7)]) == 0
    out = capsys.readouterr().out
    assert "Data check list (Table 11)" in out and "number of all rules" in out


def test_check_json(capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["check", "--json", "--checklist", str(FIG7)]) == 0
    report = json.loads(capsys.readouterr().out)
    assert report["level"] == "Extension" and report["ok"] is True
    assert report["checklist"]["Fuzzy_FB"]["number of all rules"] == "4"


def test_check_errors_exit_1_with_json(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    bad = tmp_path / "bad.fcl"
    bad.write_text("FUNCTION_BLOCK f\nVAR_INPUT\nt : REAL;\nFUZZIFY t\nEND_FUZZIFY\nEND_FUNCTION_BLOCK\n")
    assert main(["check", "--json", str(bad)]) == 1
    report = json.loads(capsys.readouterr().out)
    assert report["ok"] is False and report["diagnostics"][0]["line"] == 4


@pytest.mark.parametrize("kind", ["binary", "empty", "directory", "missing"])
def test_garbage_input_gives_a_message_not_a_traceback(
    kind: str, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    path = tmp_path / "x.fcl"
    if kind == "binary":
        path.write_bytes(b"\x00\x01\x02FUNCTION_BLOCK")
    elif kind == "empty":
        path.write_bytes(b"")
    elif kind == "directory":
        path.mkdir()
    assert main(["check", str(path)]) == 1
    err = capsys.readouterr().err
    assert "Traceback" not in err and "x.fcl" in err


def test_usage_error_exit_2(capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["check"]) == 2


def test_fmt_prints_canonical_text_and_writes_in_place(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    assert main(["fmt", str(FIG7)]) == 0
    out = capsys.readouterr().out
    assert (
        "METHOD : CoGS;" in out
        and "RULE 2 : IF temp IS cold AND pressure IS high THEN valve IS closed WITH 0.8;" in out
    )
    copy = tmp_path / "f.fcl"
    copy.write_text(FIG7.read_text().lower().replace("fuzzy_fb", "fb"))
    assert main(["fmt", "--in-place", str(copy)]) == 0
    assert copy.read_text().startswith("(*") and "END_FUNCTION_BLOCK" in copy.read_text()
    assert load_file(copy).raise_for_errors().main.name == "fb"
    assert not list(tmp_path.glob(".*tmp"))
