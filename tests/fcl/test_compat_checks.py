"""Reserved words (IEC 61131-7 Table 7) and what jFuzzyLogic would reject (issue 15.3, 15.6)."""

from __future__ import annotations

import pytest

from fuzzyctl.fcl import load_text
from fuzzyctl.fcl.reserved import TABLE7

BASE = """FUNCTION_BLOCK f
VAR_INPUT
    x : REAL;
END_VAR
VAR_OUTPUT
    y : REAL;
END_VAR
FUZZIFY x
    TERM lo := (0, 1) (10, 0);
    TERM hi := (0, 0) (10, 1);
END_FUZZIFY
DEFUZZIFY y
    TERM a := TRIAN 0 5 10;
    METHOD : COG;
    DEFAULT := 0;
    RANGE := (0 .. 10);
END_DEFUZZIFY
RULEBLOCK r
    AND : MIN;
    ACCU : MAX;
    RULE 1 : IF x IS lo THEN y IS a;
END_RULEBLOCK
END_FUNCTION_BLOCK
"""


def _codes(text: str, **kw: object) -> list[tuple[str, int | None, str]]:
    result = load_text(text, "t.fcl", **kw)  # type: ignore[arg-type]
    return [(d.code or "", d.span.line if d.span else None, d.message) for d in result.diagnostics]


def test_table7_is_the_standards_list() -> None:
    assert len(TABLE7) == 41
    assert {"NC", "WITH", "LM", "COGS", "BSUM", "MIN", "RANGE", "END_OPTIONS"} <= set(TABLE7)
    assert TABLE7["COGS"] == "CoGS"


@pytest.mark.parametrize(
    ("old", "new", "line", "what"),
    [
        ("TERM lo :=", "TERM MIN :=", 9, "term MIN of x"),
        ("TERM a :=", "TERM Nc :=", 13, "term Nc of y"),
        ("RULEBLOCK r", "RULEBLOCK bsum", 18, "rule block bsum"),
        ("FUNCTION_BLOCK f", "FUNCTION_BLOCK CoG", 1, "function block CoG"),
    ],
)
def test_reserved_words_warn_with_keyword_and_line(old: str, new: str, line: int, what: str) -> None:
    text = BASE.replace(old, new).replace("x IS lo", "x IS MIN" if "MIN" in new else "x IS lo")
    text = text.replace("y IS a", "y IS Nc" if "Nc" in new else "y IS a")
    hits = [c for c in _codes(text) if c[0] == "reserved-word"]
    assert len(hits) == 1 and hits[0][1] == line and hits[0][2].startswith(f"{what} (line {line}): ")
    result = load_text(text, "t.fcl", strict=True)
    assert not result.ok
    assert [d.code for d in result.diagnostics if d.is_error] == ["reserved-word"]


def test_no_reserved_words_no_warning() -> None:
    assert not [c for c in _codes(BASE) if c[0] == "reserved-word"]
    assert load_text(BASE, strict=True).ok


@pytest.mark.parametrize(
    ("old", "new", "code", "words"),
    [
        ("FUZZIFY x\n", "FUZZIFY x\n    RANGE := (0 .. 10);\n", "jfl-rejects", "no RANGE in FUZZIFY"),
        (
            "    METHOD : COG;",
            "    METHOD : COG;\n    ACCU : MAX;",
            "jfl-rejects",
            "ACCU belongs in the RULEBLOCK",
        ),
        ("RULEBLOCK r", "RULEBLOCK", "jfl-rejects", "needs a name"),
        ("DEFAULT := 0;", "DEFAULT := nan;", "jfl-rejects", "not nan"),
        ("TRIAN 0 5 10", "Triangle 0 5 10", "jfl-rejects", "no shape Triangle"),
        ("TRIAN 0 5 10", "SINGLETONS (1, 1)", "jfl-rejects", "SINGLETONS"),
        ("ACCU : MAX;", "ACCU : ASUM;", "jfl-rejects", "no ACCU : ASUM"),
        ("IF x IS lo", "IF X IS lo", "jfl-fails", "case-sensitive"),
        ("    x : REAL;", "    x : REAL; RANGE := (0 .. 10);", "jfl-differs", "declaration of x is ignored"),
        ("(0, 1) (10, 0)", "(0, 1) (10., 0)", "jfl-rejects", "digits before '.'"),
    ],
)
def test_what_jfuzzylogic_would_reject(old: str, new: str, code: str, words: str) -> None:
    text = BASE.replace(old, new)
    assert text != BASE
    plain = [c for c in _codes(text) if c[0].startswith("jfl-")]
    assert not plain  # only under --compat jfuzzylogic
    found = [c for c in _codes(text, compat="jfuzzylogic") if c[0].startswith("jfl-")]
    assert [c[0] for c in found] == [code], found
    assert words in found[0][2]


def test_a_file_jfuzzylogic_reads_gets_no_jfl_warning() -> None:
    assert not [c for c in _codes(BASE, compat="jfuzzylogic") if c[0].startswith("jfl-")]


def test_text_after_the_last_function_block_is_not_lexed() -> None:
    # jFuzzyLogic stops there: a file name pasted after it (corpus: "configuration1.txt")
    # loads cleanly in the live jFuzzyLogic
    text = BASE + "\nconfiguration1.txt\n"
    assert not [c for c in _codes(text, compat="jfuzzylogic") if c[0] == "jfl-rejects"]
