"""``fuzzyctl check`` also shows what the engine refuses, so check never passes a file that
``fuzzyctl eval`` rejects."""

from pathlib import Path

from fuzzyctl.cli import main

# Syntactically and semantically valid FCL whose input term cannot be evaluated: a
# generalised bell of width 0 divides by zero.  Only the engine knows that.
ZERO_WIDTH_BELL = """\
FUNCTION_BLOCK f
VAR_INPUT x : REAL; END_VAR
VAR_OUTPUT y : REAL; END_VAR
FUZZIFY x
  TERM a := GBELL 0 2 5;
END_FUZZIFY
DEFUZZIFY y
  RANGE(0..1);
  TERM b := (0,0) (1,1);
  METHOD : COG;
  DEFAULT := 0;
END_DEFUZZIFY
RULEBLOCK r
  AND : MIN; ACT : MIN; ACCU : MAX;
  RULE 1 : IF x IS a THEN y IS b;
END_RULEBLOCK
END_FUNCTION_BLOCK
"""


def test_check_reports_engine_refusal_with_position(tmp_path: Path, capsys) -> None:  # type: ignore[no-untyped-def]
    path = tmp_path / "bell.fcl"
    path.write_text(ZERO_WIDTH_BELL)
    assert main(["check", str(path)]) == 1
    err = capsys.readouterr().err
    assert f"{path}:5:3: error:" in err
    assert "width" in err
    # eval refuses the same file with the same message
    assert main(["eval", str(path), "--set", "x=1"]) == 1
    assert "width" in capsys.readouterr().err


def test_check_passes_a_file_the_engine_evaluates(tmp_path: Path, capsys) -> None:  # type: ignore[no-untyped-def]
    path = tmp_path / "ok.fcl"
    path.write_text(ZERO_WIDTH_BELL.replace("GBELL 0 2 5", "GBELL 1 2 5"))
    assert main(["check", str(path)]) == 0
    assert main(["eval", str(path), "--set", "x=5"]) == 0
