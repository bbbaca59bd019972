"""The writer never produces FCL the parser rejects: names it cannot write are errors."""

from __future__ import annotations

from dataclasses import replace

import pytest

from fuzzyctl.diagnostics import DiagnosticError
from fuzzyctl.fcl import parse_fcl, write
from fuzzyctl.model import FunctionBlock

TEXT = """FUNCTION_BLOCK demo
VAR_INPUT level : REAL; END_VAR
VAR_OUTPUT valve : REAL; END_VAR
FUZZIFY level TERM low := (0, 1) (5, 0); TERM high := (5, 0) (10, 1); END_FUZZIFY
DEFUZZIFY valve TERM shut := 0; TERM open := 100; METHOD : CoGS; END_DEFUZZIFY
RULEBLOCK rules
RULE 1 : IF level IS low THEN valve IS open;
RULE 2 : IF level IS high THEN valve IS shut;
END_RULEBLOCK
END_FUNCTION_BLOCK
"""


def _block() -> FunctionBlock:
    return parse_fcl(TEXT).blocks[0]


def test_written_text_reads_back() -> None:
    fb = _block()
    assert parse_fcl(write(fb)).blocks[0] == fb


@pytest.mark.parametrize("bad", ["if", "Rule", "END_VAR", "nan", "two words", "a/b", "3x"])
def test_unwritable_variable_or_term_names_are_errors_naming_them(bad: str) -> None:
    fb = _block()
    terms = (replace(fb.fuzzify[0].terms[0], name=bad), fb.fuzzify[0].terms[1])
    renamed_term = replace(fb, fuzzify=(replace(fb.fuzzify[0], terms=terms),))
    renamed_var = replace(fb, variables=(replace(fb.variables[0], name=bad), *fb.variables[1:]))
    for model, what in ((renamed_var, "variable"), (renamed_term, "term of level")):
        if " " in bad:
            continue  # several words are a valid name (ridderware's "Rear Left", "Amplitude Slope")
        with pytest.raises(DiagnosticError) as info:
            write(model)
        messages = [d.message for d in info.value.diagnostics]
        assert any(m.startswith(f"{what} {bad!r}") for m in messages), messages
        assert all(d.code == "fcl-write-name" for d in info.value.diagnostics)


def test_multi_word_term_names_are_written() -> None:
    fb = _block()
    terms = (replace(fb.fuzzify[0].terms[0], name="Rear Left"), fb.fuzzify[0].terms[1])
    fb = replace(fb, fuzzify=(replace(fb.fuzzify[0], terms=terms),), rule_blocks=())
    assert "TERM Rear Left :=" in write(fb)
    assert parse_fcl(write(fb)).blocks[0] == fb
