"""The FLL reader on pathological input (issue 14, point 4): what it refuses, and where, and
that the shortcuts that keep it linear read what the plain reading would.  Timings are in
benchmarks/large_inputs.py."""

from __future__ import annotations

import pytest

from fuzzyctl.diagnostics import DiagnosticError
from fuzzyctl.formats import read_text
from fuzzyctl.formats.common.expr import ExprError, parse_expr
from fuzzyctl.formats.fll import reader as fll
from fuzzyctl.limits import MAX_NESTING
from fuzzyctl.model import And, Call, Is, Name, Num, Or

HEAD = """Engine: e
InputVariable: a
  range: 0 1
  term: lo Triangle 0 0 1
OutputVariable: y
  range: 0 1
  defuzzifier: Centroid 100
  term: small Triangle 0 0 1
RuleBlock: r
"""
RULE_LINE = HEAD.count("\n") + 1


def _refusal(text: str) -> tuple[str, int, int]:
    with pytest.raises(DiagnosticError) as info:
        read_text(text, "fll", path="x.fll")
    d = next(d for d in info.value.diagnostics if d.is_error)
    assert d.span is not None and d.file == "x.fll"
    return d.message, d.span.line, d.span.column


def test_a_hedge_chain_longer_than_the_nesting_limit_is_refused_at_its_rule() -> None:
    ok = HEAD + "  rule: if a is " + "very " * MAX_NESTING + "lo then y is small\n"
    rule = read_text(ok, "fll").document.main.rule_blocks[0].rules[0]
    assert rule.condition == Is("a", "lo", hedges=("very",) * MAX_NESTING)
    too_long = ok.replace("very lo", "very very lo")
    message, line, column = _refusal(too_long)
    assert message == f"rule: {MAX_NESTING + 1} hedges on 'a' is 'lo': the limit is {MAX_NESTING}"
    assert (line, column) == (RULE_LINE, 3)


def test_running_conclusion_hedges_are_bounded_as_a_chain() -> None:
    # fuzzylite hedges a running degree, so conclusion k carries the hedges of all before it:
    # without a bound, n conclusions would hold n * n / 2 hedges
    ok = HEAD + "  rule: if a is lo then " + " and ".join(["y is very small"] * MAX_NESTING) + "\n"
    rule = read_text(ok, "fll").document.main.rule_blocks[0].rules[0]
    assert [len(c.hedges) for c in rule.conclusions] == list(range(1, MAX_NESTING + 1))
    message, line, _ = _refusal(ok.replace("small\n", "small and y is very small\n"))
    assert message.startswith(f"rule: {MAX_NESTING + 1} hedges apply to 'y' is 'small'")
    assert line == RULE_LINE


@pytest.mark.parametrize(
    ("condition", "refused"),
    [
        ("(" * MAX_NESTING + "a is lo" + ")" * MAX_NESTING, False),
        ("(" * (MAX_NESTING + 1) + "a is lo" + ")" * (MAX_NESTING + 1), True),
        ("(" * 100_000 + "a is lo", True),  # refused at the 101st, the rest never read
    ],
)
def test_rule_parentheses_are_bounded(condition: str, refused: bool) -> None:
    text = HEAD + f"  rule: if {condition} then y is small\n"
    if not refused:
        assert read_text(text, "fll").document.main.rule_blocks[0].rules[0].condition == Is("a", "lo")
        return
    message, line, _ = _refusal(text)
    assert message == f"rule: the condition nests more than {MAX_NESTING} parentheses deep"
    assert line == RULE_LINE


def test_a_long_and_or_rule_groups_as_written() -> None:
    # "and" binds tighter than "or": 3000 words, one Or of 500 Ands of two
    rule = "  rule: if " + " or ".join(["a is lo and a is very lo"] * 500) + " then y is small\n"
    cond = read_text(HEAD + rule, "fll").document.main.rule_blocks[0].rules[0].condition
    assert isinstance(cond, Or) and len(cond.operands) == 500
    assert all(o == And((Is("a", "lo"), Is("a", "lo", hedges=("very",)))) for o in cond.operands)


def test_many_duplicate_terms_take_the_first_free_suffix() -> None:
    terms = ["lo", "lo_3", "lo", "lo", "lo", "hi", "hi"]
    text = HEAD.replace(
        "  term: lo Triangle 0 0 1\n", "".join(f"  term: {t} Triangle 0 0 1\n" for t in terms)
    )
    loaded = fll.read(text)
    names = [t.name for t in loaded.document.main.fuzzify[0].terms]
    assert names == ["lo", "lo_3", "lo_2", "lo_4", "lo_5", "hi", "hi_2"]
    assert sum(d.code == "duplicate-term" for d in loaded.diagnostics) == 4


def test_an_operator_chain_over_the_limit_is_refused_as_soon_as_it_is_too_deep() -> None:
    # x + x + ... is a tree as deep as the chain is long; refused while it is read, so a
    # syntax error further on is not reached (the message is the depth, not the ')')
    assert parse_expr(" + ".join(["x"] * MAX_NESTING)) is not None
    for text in (" + ".join(["x"] * (MAX_NESTING + 1)), "x + " * 100_000 + "x )"):
        with pytest.raises(ExprError, match=f"nests more than {MAX_NESTING} levels deep"):
            parse_expr(text)
    message, line, _ = _refusal(HEAD.replace("Triangle 0 0 1", "Function " + "(" * 50_000 + "x", 1))
    assert message == f"Function 'lo': the expression nests more than {MAX_NESTING} levels deep"
    assert line == 4
    # a stray character is still found first, wherever it is
    with pytest.raises(ExprError, match="unexpected character '\\$'") as info:
        parse_expr("(" * 200 + "x $")
    assert info.value.position == 202


def test_a_call_with_thousands_of_arguments_reads_every_one() -> None:
    # longer than the tokenizer's chunk: arguments on both sides of a cut, numbers with signs
    args = ["x", "1e-5", "a.b", "2.5e+3"] * 3000
    expr = parse_expr("max(" + ", ".join(args) + ")")
    leaves = {"x": Name("x"), "1e-5": Num(1e-5), "a.b": Name("a.b"), "2.5e+3": Num(2500.0)}
    assert expr == Call("max", tuple(leaves[a] for a in args))
    with pytest.raises(ExprError, match="expected '\\)' but found 'z'"):
        parse_expr("max(" + ", ".join(args) + " z)")
