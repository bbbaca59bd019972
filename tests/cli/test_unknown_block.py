"""An unknown ``--block`` is bad input (exit 1 naming the blocks the file has), never an
internal error: eval, explain and codegen once ended in exit 3 on a KeyError."""

from __future__ import annotations

from pathlib import Path

import pytest

from fuzzyctl.cli.app import main

TWO = """FUNCTION_BLOCK a
VAR_INPUT x : REAL; END_VAR
VAR_OUTPUT y : REAL; END_VAR
FUZZIFY x TERM lo := (0, 1) (1, 0); TERM hi := (0, 0) (1, 1); END_FUZZIFY
DEFUZZIFY y TERM s := 0; TERM b := 1; METHOD : COGS; END_DEFUZZIFY
RULEBLOCK r AND : MIN; RULE 1 : IF x IS lo THEN y IS s; RULE 2 : IF x IS hi THEN y IS b; END_RULEBLOCK
END_FUNCTION_BLOCK
"""


@pytest.mark.parametrize(
    "args",
    [
        ["eval", "--set", "x=0.3"],
        ["eval", "--set", "x=0.3", "--samples", "5"],
        ["explain", "--set", "x=0.3"],
        ["codegen"],
        ["codegen", "--samples", "5"],
    ],
)
def test_an_unknown_block_is_bad_input(
    args: list[str], tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    path = tmp_path / "two.fcl"
    path.write_text(TWO + TWO.replace("FUNCTION_BLOCK a", "FUNCTION_BLOCK b"))
    code = main([args[0], str(path), *args[1:], "--block", "nope"])
    err = capsys.readouterr().err
    assert "internal error" not in err
    if "--samples" in args:  # a type-1 file: the option is refused first (usage error)
        assert code in (1, 2)
    else:
        assert code == 1
        assert "no function block 'nope'" in err and "'a', 'b'" in err


def test_a_known_block_still_evaluates(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    path = tmp_path / "two.fcl"
    path.write_text(TWO + TWO.replace("FUNCTION_BLOCK a", "FUNCTION_BLOCK b"))
    assert main(["eval", str(path), "--block", "b", "--set", "x=0.25"]) == 0
    assert "0.25" in capsys.readouterr().out
