"""``fuzzyctl blocks`` and the FPL/XFUZ formats through ``fuzzyctl convert``."""

from __future__ import annotations

import csv
import io
import json
from pathlib import Path

import pytest

from fuzzyctl import formats, load
from fuzzyctl.cli.app import main
from fuzzyctl.formats.xfuz.reader import read_tables
from tests.conftest import EXAMPLES


def run(args: list[str], capsys: pytest.CaptureFixture[str]) -> tuple[int, str, str]:
    code = main(args)
    out, err = capsys.readouterr()
    return code, out, err


def rows(text: str) -> list[dict[str, str]]:
    return list(csv.DictReader(io.StringIO(text)))


def test_blocks_help_documents_the_csv_runs(capsys: pytest.CaptureFixture[str]) -> None:
    code, out, _ = run(["blocks", "--help"], capsys)
    assert code == 0
    for word in ("siemens", "xfuz", "check", "CSV", "one row per", "INFO", "STATUS", "empty cell"):
        assert word in out
    code, out, _ = run(["blocks", "xfuz", "--help"], capsys)
    assert code == 0 and "MAN_AUTO" in out and "--period" in out and "--relaxed-span" in out


def test_xfuz_3_3_tables_convert_to_fcl_and_back(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    for source in ("xfuz_3_3.xfuz", "xfuz_3_3.csv.xfuz"):
        fcl, back = tmp_path / "debit.fcl", tmp_path / "back.xfuz"
        code, _, err = run(["convert", str(EXAMPLES / source), str(fcl)], capsys)
        assert code == 0, err
        assert "STATUS bit 9" in err  # the manual's Discr 20 on a 0..10 output, reported
        assert "RULE 4 : IF Débit IS fort THEN OUT3 IS grande;" in fcl.read_text(encoding="utf-8")
        code, _, err = run(["convert", str(fcl), str(back)], capsys)
        assert code == 0, err
        original = read_tables((EXAMPLES / source).read_text(encoding="utf-8"))
        assert read_tables(back.read_text(encoding="utf-8")) == original


def test_xfuz_convert_lists_what_the_tables_cannot_hold(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    out = tmp_path / "figure7.xfuz"
    code, _, err = run(["convert", str(EXAMPLES / "figure7.fcl"), str(out)], capsys)
    assert code == 1 and not out.exists()
    assert "rule '2': XFUZ rules have no weight" in err and "16-bit integers" in err
    code, _, err = run(["convert", str(EXAMPLES / "figure7.fcl"), str(out), "--lossy"], capsys)
    assert code == 0 and "dropped: rule '2'" in err
    c = read_tables(out.read_text())
    assert c.out_pt and c.rg[:6] == (0, 2, 999, 999, 6, 999)  # cold AND low -> inlet


def test_fpl_through_the_registry(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    doc = load(EXAMPLES / "fpltest.fpl")
    assert doc.main.name == "FPLTEST"
    assert formats.for_path("x.fpl").name == "fpl" and formats.for_path("x.xfuz").name == "xfuz"
    fcl = tmp_path / "fpltest.fcl"
    code, _, err = run(["convert", str(EXAMPLES / "fpltest.fpl"), str(fcl)], capsys)
    assert code == 0 and "repeated FROM" in err
    back = tmp_path / "back.fpl"
    code, _, err = run(["convert", str(fcl), str(back)], capsys)
    assert code == 0, err
    assert load(back).main == doc.main
    code, _, err = run(["convert", str(EXAMPLES / "figure7.fcl"), str(tmp_path / "f7.fpl")], capsys)
    assert code == 1 and "WITH weights cannot be written in FPL" in err and "DEFAULT := 0.0" in err


def samples(tmp_path: Path, text: str) -> Path:
    path = tmp_path / "samples.csv"
    path.write_text(text)
    return path


def test_blocks_xfuz_runs_one_row_per_cycle(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    path = samples(tmp_path, "INP1,INP4,MAN_AUTO,START\n0,-50,1,0\n,,,1\n20,10,,0\n,,,1\n,,0,\n")
    code, out, err = run(
        ["blocks", "xfuz", str(EXAMPLES / "xfuz_3_3.xfuz"), str(path), "--relaxed-span"], capsys
    )
    assert code == 0, err
    got = rows(out)
    assert [r["INFERRED"] for r in got] == ["0", "1", "0", "1", "0"]
    # 8 from (0, -50) and 4 from (20, 10) on the printed 20 points (7.50 and 3.58, see
    # tests/blocks/test_xfuz_block.py for the hand computation); the last row goes back to
    # MANUAL (O3_MAN = O3_DEF$ = 0).
    assert [r["OUT3"] for r in got] == ["0", "8", "8", "4", "0"]
    assert [r["O3_CALC"] for r in got] == ["0", "8", "8", "4", "4"]
    assert {r["STATUS"] for r in got} == {"0"} and [r["time"] for r in got][:2] == ["0.0", "0.01"]
    code, out, err = run(["blocks", "xfuz", str(EXAMPLES / "xfuz_3_3.xfuz"), str(path), "--json"], capsys)
    assert code == 1  # the run ends in the block's error state: said, and not exit 0
    assert "ERROR = 1, STATUS bits 9" in err
    first = json.loads(out)[1]
    assert first["STATUS"] == 512 and first["STATUS_BITS"] == "9" and first["ERROR"] == 1  # as printed


def test_the_bundled_xfuz_example_runs_without_options(capsys: pytest.CaptureFixture[str]) -> None:
    """examples/xfuz_debit.xfuz is the manual's 3.3 example with Ouverture on 6 points, which
    its span rule allows: Pression 0, Température -50 gives 8 (7.83 by hand); 20, 10 gives 3
    (3.38) - tests/blocks/test_xfuz_block.py computes both from the manual's formulas."""
    code, out, err = run(
        ["blocks", "xfuz", str(EXAMPLES / "xfuz_debit.xfuz"), str(EXAMPLES / "xfuz.csv")], capsys
    )
    assert code == 0, err
    got = rows(out)
    assert [r["OUT3"] for r in got] == ["8", "8", "3", "3"]
    assert {r["ERROR"] for r in got} == {"0"}


def test_siemens_run_ending_in_an_error_state_exits_non_zero(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    from fuzzyctl.blocks.siemens import FuzzyFB

    path = samples(tmp_path, "Temp,Pressure\n9,65\n")
    original = FuzzyFB.execute

    def failing(self: FuzzyFB) -> int:  # INFO 11: no valid application (manual, Table 3-7)
        original(self)
        self.INFO = 0x11
        return 0x11

    FuzzyFB.execute = failing  # type: ignore[method-assign]
    try:
        code, out, err = run(["blocks", "siemens", str(EXAMPLES / "fpltest.fpl"), str(path)], capsys)
    finally:
        FuzzyFB.execute = original  # type: ignore[method-assign]
    assert code == 1 and "INFO 11" in err and "cycle,Valve,INFO,ENO" in out


def test_blocks_xfuz_from_fcl_accepts_variable_names(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    fcl = tmp_path / "tank.fcl"
    fcl.write_text(
        "FUNCTION_BLOCK tank VAR_INPUT level : INT; END_VAR VAR_OUTPUT pump : INT; END_VAR\n"
        "FUZZIFY level TERM low := (20, 1) (60, 0); TERM high := (40, 0) (80, 1); END_FUZZIFY\n"
        "DEFUZZIFY pump RANGE(0..1000); TERM off := 0; TERM full := 1000; METHOD : CoGS; DEFAULT := 0;\n"
        "END_DEFUZZIFY RULEBLOCK r RULE 1 : IF level IS low THEN pump IS full;\n"
        "RULE 2 : IF level IS high THEN pump IS off; END_RULEBLOCK END_FUNCTION_BLOCK\n"
    )
    path = samples(tmp_path, "level,MAN_AUTO,START\n50,1,1\n45,,0\n45,,1\n")
    code, out, err = run(["blocks", "xfuz", str(fcl), str(path)], capsys)
    assert code == 0, err
    # On demand (CONTASK$ = 1): a rising edge of START runs the rules.  Level 50: low .25,
    # high .25 -> 500; level 45: low .375, high .125 -> (.375 * 1000) / .5 = 750.
    assert [r["OUT1"] for r in rows(out)] == ["500", "500", "750"]


def test_blocks_xfuz_rejects_unknown_columns(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    path = samples(tmp_path, "INP1,SPEED\n1,2\n")
    code, _, err = run(["blocks", "xfuz", str(EXAMPLES / "xfuz_3_3.xfuz"), str(path)], capsys)
    assert code == 1 and "unknown column 'SPEED'" in err
    path = samples(tmp_path, "INP1\n40000\n")
    code, _, err = run(["blocks", "xfuz", str(EXAMPLES / "xfuz_3_3.xfuz"), str(path)], capsys)
    assert code == 1 and "16-bit" in err and "INP1" in err


def test_blocks_siemens_runs_one_row_per_cycle(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    path = samples(tmp_path, "Temp,Pressure,START_STOP\n9,65,\n20,60,0\n30,100,\n,,16#FFFF\n-5,200,\n")
    code, out, err = run(["blocks", "siemens", str(EXAMPLES / "fpltest.fpl"), str(path)], capsys)
    assert code == 0, err
    got = rows(out)
    # 100/3 (the sum of manual 1.4, hand computation in tests/blocks/test_siemens_fb.py),
    # printed as the REAL holds it; START_STOP 0: INFO 01 and the value kept; back on at
    # (30, 100): drainage -100; (-5, 200) is clamped to (0, 100): cold 1, high 1 -> closed 0.
    third = "33.33333206176758"
    assert [(r["Valve"], r["INFO"], r["ENO"]) for r in got] == [
        (third, "00", "1"),
        (third, "01", "0"),
        (third, "01", "0"),
        ("-100.0", "00", "1"),
        ("0.0", "00", "1"),
    ]
    code, out, err = run(["blocks", "siemens", str(EXAMPLES / "fpltest.fpl"), str(path), "--json"], capsys)
    assert code == 0 and json.loads(out)[0] == {"cycle": 0, "Valve": float(third), "INFO": "00", "ENO": 1}


def test_blocks_siemens_and_check_report_what_does_not_fit(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    path = samples(tmp_path, "temp,pressure\n9,65\n")
    code, _, err = run(["blocks", "siemens", str(EXAMPLES / "figure7.fcl"), str(path)], capsys)
    assert code == 1 and "figure7.fcl:36" in err and "no rule weights" in err
    code, out, _ = run(
        ["blocks", "siemens", str(EXAMPLES / "figure7.fcl"), str(path), "--no-profile"], capsys
    )
    # the block's sum (1.4) with the program's WITH 0.8: inlet .75, closed .8 * .25 + .25,
    # drainage .25 -> 50 / 1.45, as a REAL
    assert code == 0 and rows(out)[0]["valve"] == "34.482757568359375"
    code, _, err = run(["blocks", "check", str(EXAMPLES / "figure7.fcl")], capsys)
    assert code == 1 and "siemens-weight" not in err and "WITH 0.8" in err
    code, out, _ = run(["blocks", "check", str(EXAMPLES / "fpltest.fpl"), "--json"], capsys)
    assert code == 0 and [d["code"] for d in json.loads(out)] == ["siemens-name"]  # "drainage"
    code, out, _ = run(
        [
            "blocks",
            "check",
            str(EXAMPLES / "fpltest.fpl"),
            "--json",
            "--bipolar",
            "Valve",
            "--bipolar",
            "Temp",
        ],
        capsys,
    )
    found = json.loads(out)
    assert code == 0 and [d["code"] for d in found] == ["siemens-name", "siemens-bipolar-asymmetric"]
    assert found[1]["message"].startswith("Temp: MIN 0 and MAX 30")
    bad = samples(tmp_path, "Temp,Flow\n1,2\n")
    code, _, err = run(["blocks", "siemens", str(EXAMPLES / "fpltest.fpl"), str(bad)], capsys)
    assert code == 1 and "unknown column 'Flow'" in err
