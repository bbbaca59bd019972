"""``fuzzyctl codegen``: files written atomically, options checked, refusals as messages."""

from __future__ import annotations

from pathlib import Path

import pytest

from fuzzyctl.cli.app import main
from tests.codegen import systems as S
from tests.conftest import data_path

FIG7 = str(S.EXAMPLES / "figure7.fcl")


def test_st_to_file_and_stdout(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    out = tmp_path / "fb.st"
    assert main(["codegen", FIG7, "--lang", "st", "--dialect", "twincat", "--lreal", "-o", str(out)]) == 0
    text = out.read_text()
    assert "FUNCTION_BLOCK Fuzzy_FB" in text and "temp : LREAL;" in text
    assert not list(tmp_path.glob(".*tmp"))
    assert main(["codegen", FIG7]) == 0
    assert "FUNCTION_BLOCK Fuzzy_FB" in capsys.readouterr().out


def test_c_to_directory(tmp_path: Path) -> None:
    assert main(["codegen", FIG7, "--lang", "c", "--float", "-o", str(tmp_path / "gen")]) == 0
    header = (tmp_path / "gen" / "Fuzzy_FB.h").read_text()
    assert "typedef float Fuzzy_FB_real;" in header
    assert "unsigned char Fuzzy_FB_step(Fuzzy_FB *fb);" in header
    assert (tmp_path / "gen" / "Fuzzy_FB.c").exists()


def test_option_mismatches_are_usage_errors(tmp_path: Path) -> None:
    assert main(["codegen", FIG7, "--lang", "c", "--dialect", "scl"]) == 2
    assert main(["codegen", FIG7, "--lang", "st", "--float"]) == 2
    assert main(["codegen", FIG7, "--lang", "cobol"]) == 2


def test_refusals_exit_1_naming_the_element(capsys: pytest.CaptureFixture[str]) -> None:
    dimmer = data_path("fuzzylite", "mamdani", "SimpleDimmer.fcl")
    assert main(["codegen", str(dimmer), "--lang", "st"]) == 1
    err = capsys.readouterr().err
    assert "output Power: DEFAULT := nan" in err and "--default" in err
    assert main(["codegen", str(dimmer), "--lang", "st", "--default", "hold"]) == 0
    assert "--default hold" in capsys.readouterr().out
    tsukamoto = data_path("fuzzylite", "tsukamoto", "tsukamoto.fcl")
    assert main(["codegen", str(tsukamoto), "--lang", "c"]) == 1
    assert "Tsukamoto" in capsys.readouterr().err


def test_one_function_block_per_fcl_block(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    """A file with two FUNCTION_BLOCKs gives two ST blocks (one text both parsers accept) and
    two C pairs; --block picks one."""
    from tests.codegen.test_st import tree_sitter_errors

    two = tmp_path / "two.fcl"
    two.write_text(
        (S.EXAMPLES / "figure7.fcl").read_text() + "\n" + (S.EXAMPLES / "heater_extension.fcl").read_text()
    )
    assert main(["codegen", str(two), "-o", str(tmp_path / "two.st")]) == 0
    text = (tmp_path / "two.st").read_text()
    assert [line for line in text.splitlines() if line.startswith("FUNCTION_BLOCK")] == [
        "FUNCTION_BLOCK Fuzzy_FB",
        "FUNCTION_BLOCK heater",
    ]
    assert text.count("END_FUNCTION_BLOCK") == 2 and tree_sitter_errors(text) == []
    assert main(["codegen", str(two), "--lang", "c", "-o", str(tmp_path / "c")]) == 0
    assert sorted(p.name for p in (tmp_path / "c").iterdir()) == [
        "Fuzzy_FB.c",
        "Fuzzy_FB.h",
        "heater.c",
        "heater.h",
    ]
    assert main(["codegen", str(two), "--block", "heater"]) == 0
    only = capsys.readouterr().out
    assert "FUNCTION_BLOCK heater" in only and "Fuzzy_FB" not in only
    assert main(["codegen", str(two), "--block", "nope"]) == 1
    assert "nope" in capsys.readouterr().err
