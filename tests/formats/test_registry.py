"""The format registry, atomic writing and ``fuzzyctl convert``."""

from __future__ import annotations

from pathlib import Path

import pytest

from fuzzyctl import formats
from fuzzyctl.cli.app import main
from fuzzyctl.diagnostics import FuzzyctlError
from tests.conftest import data_path


def test_builtin_formats_and_extensions() -> None:
    names = {f.name for f in formats.available()}
    assert {"fis", "fll", "json"} <= names
    assert formats.for_path("x.FIS").name == "fis"
    with pytest.raises(FuzzyctlError, match="unknown format 'abc'"):
        formats.get("abc")
    with pytest.raises(FuzzyctlError, match="cannot tell the format"):
        formats.for_path("x.txt")


def test_a_registered_format_is_used_by_convert(tmp_path: Path) -> None:
    seen = []
    fmt = formats.Format("demo", (".demo",), "test", write=lambda d: seen.append(d) or "ok\n")
    formats.register(fmt)
    try:
        src = data_path("fuzzylite", "mamdani", "SimpleDimmer.fll")
        assert main(["convert", str(src), str(tmp_path / "x.demo")]) == 0
        assert (tmp_path / "x.demo").read_text() == "ok\n" and seen
    finally:
        formats.REGISTRY.pop("demo")


def test_convert_refuses_losses_then_lists_them_with_lossy(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    src = data_path("fuzzylite", "mamdani", "SimpleDimmerChained.fll")
    out = tmp_path / "out.fis"
    out.write_text("previous content\n")
    assert main(["convert", str(src), str(out)]) == 1
    err = capsys.readouterr().err
    assert err.count("FIS cannot test an output variable") == 3 and "rule '4'" in err
    assert out.read_text() == "previous content\n"  # nothing half-written, old file kept
    assert main(["convert", str(src), str(out), "--lossy"]) == 0
    err = capsys.readouterr().err
    assert err.count("dropped: rule") == 3
    assert "[Rules]" in out.read_text()


def test_convert_between_formats_keeps_the_model(tmp_path: Path) -> None:
    src = data_path("fuzzylite", "takagi-sugeno", "octave", "linear_tip_calculator.fll")
    original = formats.read_path(src).document
    assert main(["convert", str(src), str(tmp_path / "a.json")]) == 0
    assert main(["convert", str(tmp_path / "a.json"), str(tmp_path / "b.txt"), "--to", "fll"]) == 0
    assert formats.read_path(tmp_path / "b.txt", "fll").document.main == original.main


def test_unavailable_and_bad_input_exit_codes(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    src = data_path("fuzzylite", "mamdani", "SimpleDimmer.fll")
    code = main(["convert", str(src), str(tmp_path / "x.xyz")])
    assert code == 1 and "cannot tell the format" in capsys.readouterr().err
    broken = tmp_path / "broken.fis"
    broken.write_text("[System]\nName='x'\nType='mamdani'\n[Input1]\nName='a'\nRange=[0 1 2]\n")
    assert main(["convert", str(broken), str(tmp_path / "y.fll")]) == 1
    assert "broken.fis:6:1: error: Range needs 2 numbers" in capsys.readouterr().err


def test_write_atomic_replaces_whole_file(tmp_path: Path) -> None:
    target = tmp_path / "t.txt"
    formats.write_atomic(target, "one\n")
    formats.write_atomic(target, "two\n")
    assert target.read_text() == "two\n" and [p.name for p in tmp_path.iterdir()] == ["t.txt"]


def test_convert_formats_by_option_whatever_the_extensions(tmp_path: Path) -> None:
    """--from and --to override the extensions (a MATLAB FIS saved as .txt)."""
    src = data_path("fuzzylite", "takagi-sugeno", "matlab", "tippersg.fis")
    renamed = tmp_path / "tipper.txt"
    renamed.write_bytes(src.read_bytes())
    assert main(["convert", str(renamed), str(tmp_path / "out.dat"), "--from", "fis", "--to", "fll"]) == 0
    again = formats.read_path(tmp_path / "out.dat", "fll").document.main
    original = formats.read_path(src).document.main
    assert [v.name for v in again.variables] == [v.name for v in original.variables]
    assert main(["convert", str(renamed), str(tmp_path / "out.fll")]) == 1  # .txt: format unknown
