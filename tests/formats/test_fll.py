"""The FLL reader against fuzzylite's semantics, and the FLL writer's round trip."""

from __future__ import annotations

import math

import pytest

import fuzzyctl
from fuzzyctl import model as m
from fuzzyctl.diagnostics import DiagnosticError
from fuzzyctl.formats import convert, get, read_text
from fuzzyctl.formats.fll import reader as fll
from fuzzyctl.model import And, Is, Or, PointsMF, ShapeMF

SYSTEM = """Engine: demo
InputVariable: a
  enabled: true
  range: 0.000 1.000
  lock-range: true
  term: lo Triangle 0.0 0.25 0.5
  term: hi SigmoidDifference 0.25 10 30 0.75 0.8
InputVariable: b
  enabled: true
  range: 0 1
  lock-range: false
  term: lo Discrete 0 1 0.5 0 2
  term: hi Ramp 0.5 1
  term: hi Gaussian 0.5 0.1
OutputVariable: y
  enabled: true
  range: 0 1
  lock-range: false
  {agg}: Maximum
  defuzzifier: Centroid 200
  default: nan
  {lock}: true
  term: small Triangle 0 0.25 0.5
  term: big Triangle 0.5 0.75 1
OutputVariable: z
  enabled: true
  range: 0 10
  lock-range: true
  aggregation: none
  defuzzifier: WeightedAverage TakagiSugeno
  default: 0
  lock-previous: false
  term: c Constant 5
  term: l Linear 1 2 3
RuleBlock: rb
  enabled: true
  conjunction: AlgebraicProduct
  disjunction: Maximum
  {imp}
  rule: if a is not very lo and (b is hi or b is somewhat lo) then y is small with 0.5
  rule: if a is any then z is c
  rule: if a is extremely hi then y is very big and z is seldom l
"""


def read(
    agg: str = "aggregation",
    lock: str = "lock-previous",
    imp: str = "implication: Minimum\n  activation: General",
):
    return fll.read(SYSTEM.format(agg=agg, lock=lock, imp=imp), "demo.fll")


def test_terms_map_with_fuzzylite_parameter_orders() -> None:
    fb = read().document.main
    a, b = fb.fuzzify
    assert a.clamp and not b.clamp
    # SigmoidDifference left rising falling right [height] -> dsigmoid(center1, slope1, center2, slope2)
    assert a.terms[1].mf == ShapeMF("dsigmoid", (0.25, 10.0, 0.75, 30.0), 0.8)
    # Discrete with an odd count: the last value is the height, applied to the points
    assert isinstance(b.terms[0].mf, PointsMF) and [float(p.y) for p in b.terms[0].mf.points] == [2.0, 0.0]
    z = fb.defuzzify[1]
    assert z.method == "WTAVER" and z.clamp and z.terms[1].mf == ShapeMF("linear", (1.0, 2.0, 3.0))


def test_duplicate_term_first_wins_and_warns() -> None:
    loaded = read()
    b = loaded.document.main.fuzzify[1]
    assert [t.name for t in b.terms] == ["lo", "hi", "hi_2"]
    assert b.terms[1].mf == ShapeMF("ramp", (0.5, 1.0))  # rules' "hi" is the first, as in fuzzylite C++
    assert any(d.code == "duplicate-term" and d.span and d.span.line == 14 for d in loaded.diagnostics)


def test_rules_hedges_any_weights() -> None:
    fb = read().document.main
    r1, r2, r3 = fb.rule_blocks[0].rules
    assert r1.condition == And(
        (
            Is("a", "lo", negated=True, hedges=("very",)),
            Or((Is("b", "hi"), Is("b", "lo", hedges=("somewhat",)))),
        )
    )
    assert r1.weight == 0.5
    assert r2.condition is None  # "a is any" always holds
    # fuzzylite hedges a running degree: z also receives y's "very"
    assert [c.hedges for c in r3.conclusions] == [("very",), ("seldom", "very")]
    block = fb.rule_blocks[0]
    assert (block.and_op, block.or_op, block.act) == ("PROD", "MAX", "MIN")


def test_version5_spellings() -> None:
    fb = read(agg="accumulation", lock="lock-valid", imp="activation: AlgebraicProduct").document.main
    assert fb.rule_blocks[0].act == "PROD" and fb.rule_blocks[0].rule_activation is None
    y = fb.defuzzify[0]
    assert (
        y.accu == "MAX" and y.default is not None and y.default.no_change and math.isnan(y.default.value or 0)
    )


def test_errors_point_at_line() -> None:
    with pytest.raises(DiagnosticError) as err:
        fll.read(
            SYSTEM.format(agg="aggregation", lock="lock-previous", imp="implication: Minimum").replace(
                "then y is small", "then y is smal"
            )
        )
    d = next(x for x in err.value.diagnostics if x.is_error)
    rule_line = (
        SYSTEM.splitlines().index(
            "  rule: if a is not very lo and (b is hi or b is somewhat lo) then y is small with 0.5"
        )
        + 1
    )
    assert d.span is not None and d.span.line == rule_line and "no term 'smal'" in d.message


def test_written_fll_reads_back_equal_and_undoes_running_hedges() -> None:
    original = read().document
    fmt = get("fll")
    adapted, losses = fmt.adapt(original)
    assert losses == []
    text = fmt.write(adapted)
    assert "then y is very big and z is seldom l" in text
    assert fll.read(text).document.main == adapted.main


def test_names_that_are_fll_hedges_or_keywords_are_renamed() -> None:
    """A term ``very`` or a variable ``then`` (fine in FCL) would read as a hedge or a keyword
    in a fuzzylite rule: the FLL writer renames them, and the system computes the same."""
    tri = m.ShapeMF("triangle", (0.0, 5.0, 10.0))
    fb = m.FunctionBlock(
        "f",
        variables=(m.Variable("then", m.VarKind.INPUT), m.Variable("y", m.VarKind.OUTPUT)),
        fuzzify=(m.FuzzifyBlock("then", (m.Term("very", tri), m.Term("any", tri)), m.Range(0, 10)),),
        defuzzify=(
            m.DefuzzifyBlock(
                "y",
                (m.Term("not", m.SingletonMF(2.0)), m.Term("b", m.SingletonMF(8.0))),
                m.Range(0, 10),
                "COGS",
            ),
        ),
        rule_blocks=(
            m.RuleBlock(
                "rb",
                (
                    m.Rule("1", m.Is("then", "very", hedges=("very",)), (m.Conclusion("y", "not"),)),
                    m.Rule("2", m.Is("then", "any", negated=True), (m.Conclusion("y", "b"),)),
                ),
                "MIN",
                None,
                "MIN",
                "MAX",
            ),
        ),
    )
    text, losses = convert(m.Document((fb,)), "fll")
    assert not losses
    again = read_text(text, "fll").document.main
    assert not {v.name for v in again.variables} & {"then", "very", "any", "not"}
    assert not {t.name for b in (*again.fuzzify, *again.defuzzify) for t in b.terms} & {"very", "any", "not"}
    xs = [0.5, 2.5, 5.0, 7.5, 9.5]
    want = fuzzyctl.compile(fb).evaluate_batch({"then": xs})["y"]
    got = fuzzyctl.compile(again).evaluate_batch({again.inputs[0].name: xs})["y"]
    assert list(want) == list(got)
