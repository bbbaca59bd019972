"""``fuzzyctl eval`` and ``fuzzyctl explain``."""

from __future__ import annotations

import csv
import json
from pathlib import Path

import pytest

from fuzzyctl.cli import main
from tests.conftest import EXAMPLES

FIG7 = str(EXAMPLES / "figure7.fcl")
# figure 7 at temp=10, pressure=60, computed by hand in tests/engine/test_standard_examples.py
FIG7_10_60 = (100 * 17 / 24 - 100 / 8) / (17 / 24 + 7 / 24 + 1 / 8)


def test_eval_set_json(capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["eval", FIG7, "--set", "temp=10", "--set", "pressure=60", "--json"]) == 0
    assert json.loads(capsys.readouterr().out)["valve"] == pytest.approx(FIG7_10_60, abs=1e-12)


def test_eval_set_table(capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["eval", FIG7, "-s", "temp=10", "-s", "pressure=60"]) == 0
    assert "51.85185185" in capsys.readouterr().out


def test_eval_errors_name_the_input(capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["eval", FIG7, "--set", "temp=10"]) == 1
    assert "missing input 'pressure'" in capsys.readouterr().err
    assert main(["eval", FIG7, "--set", "temp=hot", "--set", "pressure=1"]) == 1
    assert "'temp'" in capsys.readouterr().err
    assert main(["eval", FIG7, "--set", "tmp=1", "--set", "temp=1", "--set", "pressure=1"]) == 1
    assert "unknown input 'tmp'" in capsys.readouterr().err


def test_eval_csv_keeps_inputs_and_adds_outputs(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    src = tmp_path / "in.csv"
    src.write_text("pressure,temp\n60,10\n75,15\n")
    out = tmp_path / "out.csv"
    assert main(["eval", FIG7, "--csv", str(src), "-o", str(out)]) == 0
    rows = list(csv.reader(out.open()))
    assert rows[0] == ["pressure", "temp", "valve"]
    assert rows[1][:2] == ["60", "10"]
    assert float(rows[1][2]) == pytest.approx(FIG7_10_60, abs=1e-12)
    assert float(rows[2][2]) == pytest.approx(0.0, abs=1e-12)
    assert sorted(p.name for p in tmp_path.iterdir()) == ["in.csv", "out.csv"]  # no temp file left


def test_eval_csv_bad_cell_names_row_and_column(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    src = tmp_path / "in.csv"
    src.write_text("temp,pressure\n10,60\n12,high\n")
    out = tmp_path / "out.csv"
    assert main(["eval", FIG7, "--csv", str(src), "-o", str(out)]) == 1
    err = capsys.readouterr().err
    assert "in.csv:3" in err and "'pressure'" in err and "'high'" in err
    assert not out.exists()  # nothing half-written


def test_explain_tables_and_plot(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    png = tmp_path / "sets.png"
    tipper = str(Path(__file__).resolve().parents[2] / "benchmarks" / "tipper.fcl")
    assert main(["explain", tipper, "--set", "service=3", "--set", "food=8", "--png", str(png)]) == 0
    text = capsys.readouterr().out
    assert "tip IS generous" in text and "accumulated set" in text and "^ tip = " in text
    assert png.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"


def test_explain_json(capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["explain", FIG7, "--set", "temp=6", "--set", "pressure=85", "--json"]) == 0
    e = json.loads(capsys.readouterr().out)
    assert e["outputs"][0]["value"] == pytest.approx(12.5 / 0.975)
    rule2 = next(r for r in e["rules"] if r["label"] == "2")
    assert rule2["degree"] == pytest.approx(0.75)
    assert rule2["conclusions"][0]["weight"] == 0.8


NO_RULE_FIRES = """FUNCTION_BLOCK t
VAR_INPUT x : REAL; END_VAR
VAR_OUTPUT y : REAL; END_VAR
FUZZIFY x TERM low := (0, 1) (5, 0); RANGE := (0 .. 10); END_FUZZIFY
DEFUZZIFY y TERM a := (0, 0) (5, 1) (10, 0); METHOD : COG; DEFAULT := NAN; RANGE := (0 .. 10);
END_DEFUZZIFY
RULEBLOCK r AND : MIN; ACCU : MAX; RULE 1 : IF x IS low THEN y IS a; END_RULEBLOCK
END_FUNCTION_BLOCK
"""


@pytest.mark.parametrize("form", [[], ["--json"]])
def test_eval_without_a_value_exits_1_and_says_why(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], form: list[str]
) -> None:
    """Issue 14.6: NaN is never printed as a result with exit 0."""
    src = tmp_path / "nan.fcl"
    src.write_text(NO_RULE_FIRES)
    assert main(["eval", str(src), "--set", "x=8", *form]) == 1
    err = capsys.readouterr().err
    assert "output 'y' has no value" in err and "DEFAULT is NaN" in err
    assert main(["eval", str(src), "--set", "x=2", *form]) == 0  # the rule fires: y = 5
    assert "5" in capsys.readouterr().out
