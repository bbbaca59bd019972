"""``--strict`` and ``--compat jfuzzylogic`` on check, eval and codegen (issue 15)."""

from pathlib import Path

import pytest

import fuzzyctl
from fuzzyctl.cli import main
from fuzzyctl.diagnostics import DiagnosticError

# A gaussian output without RANGE (the universe is the span of the terms: -8..18), a term
# called MIN (a Table 7 keyword), a RANGE inside FUZZIFY (jFuzzyLogic rejects it).
FILE = """\
FUNCTION_BLOCK f
VAR_INPUT x : REAL; END_VAR
VAR_OUTPUT y : REAL; END_VAR
FUZZIFY x
  RANGE := (0 .. 10);
  TERM MIN := (0, 1) (10, 0);
  TERM high := (0, 0) (10, 1);
END_FUZZIFY
DEFUZZIFY y
  TERM low := GAUSS 0 2;
  TERM big := GAUSS 10 2;
  METHOD : COG;
  DEFAULT := 0;
END_DEFUZZIFY
RULEBLOCK r
  AND : MIN; ACCU : MAX;
  RULE 1 : IF x IS MIN THEN y IS low;
  RULE 2 : IF x IS high THEN y IS big;
END_RULEBLOCK
END_FUNCTION_BLOCK
"""


@pytest.fixture
def path(tmp_path: Path) -> Path:
    p = tmp_path / "f.fcl"
    p.write_text(FILE)
    return p


def test_lenient_check_and_eval_warn(path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["check", str(path)]) == 0
    err = capsys.readouterr().err
    assert f"{path}:6:3: warning: term MIN of x (line 6): MIN is a keyword IEC 61131-7 reserves" in err
    assert "term low (gaussian) is not 0 outside a finite interval" in err and "[-8, 18]" in err
    assert main(["eval", str(path), "--set", "x=3", "--json"]) == 0
    out, err = capsys.readouterr()
    assert "[-8, 18]" in err  # eval shows the universe it took
    # 0.7 low, 0.3 big, symmetric gaussians clipped: closer to 0 than the plain mean 3
    assert 0.0 < float(out.split(":")[1].strip(" }\n")) < 5.0


@pytest.mark.parametrize(
    "command", [["check"], ["eval", "--set", "x=3"], ["codegen", "--lang", "c", "-o", "out"]]
)
def test_strict_refuses(path: Path, command: list[str], capsys: pytest.CaptureFixture[str]) -> None:
    args = [command[0], str(path), *command[1:], "--strict"]
    assert main(args) == 1
    assert "MIN is a keyword IEC 61131-7 reserves" in capsys.readouterr().err
    renamed = path.with_name("g.fcl")
    renamed.write_text(FILE.replace("MIN := (0", "cold := (0").replace("x IS MIN", "x IS cold"))
    assert main([command[0], str(renamed), *command[1:], "--strict"]) == 1
    assert "give a RANGE" in capsys.readouterr().err
    renamed.write_text(
        FILE.replace("MIN := (0", "cold := (0")
        .replace("x IS MIN", "x IS cold")
        .replace("METHOD : COG;", "METHOD : COG;\n  RANGE := (-8 .. 18);")
    )
    assert main(["check", str(renamed), "--strict"]) == 0


def test_api_strict(path: Path) -> None:
    with pytest.raises(DiagnosticError, match="MIN is a keyword"):
        fuzzyctl.load(path, strict=True)
    doc = fuzzyctl.load(path)
    with pytest.raises(DiagnosticError, match="MIN is a keyword"):
        fuzzyctl.compile(doc, strict=True)
    ctl = fuzzyctl.compile(doc)
    assert [w.code for w in ctl.warnings] == ["universe-from-terms"]


def test_check_compat_jfuzzylogic_warns_what_jfuzzylogic_rejects(
    path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    assert main(["check", str(path), "--compat", "jfuzzylogic"]) == 0
    err = capsys.readouterr().err
    assert "jFuzzyLogic 3.3 would reject this file: its grammar has no RANGE in FUZZIFY" in err
    assert main(["check", str(path)]) == 0
    assert "jFuzzyLogic" not in capsys.readouterr().err.replace("as jFuzzyLogic computes it", "")
    assert main(["check", str(path), "--compat", "nonsense"]) == 2
