"""Syntax and semantic errors point at the real defect with a human message."""

from __future__ import annotations

import pytest

from fuzzyctl.fcl import load_text

HEAD = "FUNCTION_BLOCK f\nVAR_INPUT t : REAL; END_VAR\nVAR_OUTPUT v : REAL; END_VAR\n"
FUZZ = "FUZZIFY t\nTERM cold := (3, 1) (27, 0);\nEND_FUZZIFY\n"
DEFUZZ = "DEFUZZIFY v\nTERM on := 1;\nMETHOD : CoGS;\nDEFAULT := 0;\nEND_DEFUZZIFY\n"
RULES = "RULEBLOCK r\nAND : MIN;\nACCU : MAX;\nRULE 1 : IF t IS cold THEN v IS on;\nEND_RULEBLOCK\n"
TAIL = "END_FUNCTION_BLOCK\n"


def first_error(text: str):  # type: ignore[no-untyped-def]
    result = load_text(text, "x.fcl")
    assert not result.ok
    return next(d for d in result.diagnostics if d.is_error)


@pytest.mark.parametrize(
    ("text", "line", "words"),
    [
        (
            "FUNCTION_BLOCK f\nVAR_INPUT\nt : REAL;\nVAR_OUTPUT v : REAL; END_VAR\n" + TAIL,
            4,
            "missing END_VAR",
        ),
        (HEAD + "FUZZIFY t\nTERM hot := (3, 0 (27, 1);\nEND_FUZZIFY\n" + TAIL, 5, "missing ')'"),
        (
            HEAD + "FUZZIFY t\nTERM hot :=\nTERM cold := (3, 1) (27, 0);\nEND_FUZZIFY\n" + TAIL,
            5,
            "no membership",
        ),
        (
            "FUNCTION_BLOCK f\nVAR_INPUT\nt : REAL // ends here;\nq : REAL;\nEND_VAR\n" + TAIL,
            3,
            "missing ';'",
        ),
        (
            HEAD
            + "FUZZIFY t\nTERM hot := FUNCTION t * 2 // ends here;\nTERM c := (1, 0) (2, 1);\nEND_FUZZIFY\n"
            + TAIL,
            5,
            "missing ';'",
        ),
        (HEAD + FUZZ + DEFUZZ + RULES.replace("t IS cold", "t IS warm") + TAIL, 15, "no term warm"),
        (HEAD + FUZZ + DEFUZZ + RULES.replace("IF t", "IF q") + TAIL, 15, "undeclared variable q"),
        (HEAD + FUZZ + DEFUZZ.replace("CoGS", "CoA") + RULES + TAIL, 9, "CoA"),
        (HEAD + FUZZ.replace("(3, 1) (27, 0)", "(27, 1) (3, 0)") + DEFUZZ + RULES + TAIL, 5, "ascending"),
        (HEAD + FUZZ + DEFUZZ + RULES.replace("on;", "on WITH -0.5;") + TAIL, 15, "weight"),
        (
            HEAD.replace("VAR_INPUT t", "VAR_INPUT q : REAL; END_VAR VAR_OUTPUT t") + FUZZ + DEFUZZ + TAIL,
            4,
            "VAR_OUTPUT",
        ),
        (HEAD + "VAR_INPUT t : REAL; END_VAR\n" + TAIL, 4, "declared twice"),
        ("", 1, "no FUNCTION_BLOCK"),
        (HEAD + "FUZZIFY t (* never closed\n" + TAIL, 4, "comment"),
    ],
)
def test_diagnostic_points_at_the_defect(text: str, line: int, words: str) -> None:
    d = first_error(text)
    assert d.span is not None and d.span.line == line, d.render(text)
    assert words in d.message, d.message
    rendered = d.render(text)
    assert rendered.startswith(f"x.fcl:{line}:")
    assert "^" in rendered or not text


def test_warnings_for_missing_accu_default_and_act() -> None:
    text = (
        HEAD
        + FUZZ
        + DEFUZZ.replace("DEFAULT := 0;\n", "").replace("on := 1", "on := (0, 0) (1, 1)")
        + "RULEBLOCK r\nAND : MIN;\nOR : ASUM;\nRULE 1 : IF t IS cold THEN v IS on;\nEND_RULEBLOCK\n"
        + TAIL
    )
    result = load_text(text)
    assert result.ok
    by_code = {d.code: d for d in result.diagnostics}
    assert "MAX" in by_code["missing-accu"].message
    assert "NC is used" in by_code["missing-default"].message
    assert by_code["missing-act"].severity.value == "note"
    assert by_code["operator-pair"].severity.value == "warning"


def test_cycle_between_rule_blocks_through_locals() -> None:
    text = (
        "FUNCTION_BLOCK f\nVAR_INPUT t : REAL; END_VAR\nVAR a : REAL; b : REAL; END_VAR\n"
        "VAR_OUTPUT v : REAL; END_VAR\n"
        + FUZZ
        + DEFUZZ
        + "RULEBLOCK one ACCU : MAX; RULE 1 : IF b THEN a; END_RULEBLOCK\n"
        "RULEBLOCK two ACCU : MAX; RULE 1 : IF a THEN b; END_RULEBLOCK\n" + TAIL
    )
    d = first_error(text)
    assert d.code == "rule-block-cycle" and "one -> two -> one" in d.message


def test_a_term_without_semicolon_loads_with_a_warning() -> None:
    """scalablurry reads terms without ';' (and files written for it hide the ';' in a //
    comment): the term ends where the next item starts."""
    text = (
        HEAD
        + "FUZZIFY t\nTERM hot := triangular 0 1 3 // instead of (0, 1) (3, 0);\nTERM c := (1, 0) (2, 1);\n"
        + "END_FUZZIFY\n"
        + TAIL
    )
    result = load_text(text, "x.fcl")
    assert result.ok
    (w,) = [d for d in result.diagnostics if d.code == "missing-semicolon"]
    assert w.span is not None and w.span.line == 5 and "TERM hot" in w.message
    assert [t.name for t in result.document.main.fuzzify[0].terms] == ["hot", "c"]  # type: ignore[union-attr]
