"""The siemens profile (manual 1.3, 3.1, 3.4): limits of the S7 FUZZY block, reported at
the element that exceeds them."""

from __future__ import annotations

from dataclasses import replace

from fuzzyctl.blocks.siemens import LIMITS, check_siemens
from fuzzyctl.blocks.siemens.profile import input_shape
from fuzzyctl.diagnostics import Severity
from fuzzyctl.formats.fpl.reader import read_fpl
from fuzzyctl.model import (
    And,
    Conclusion,
    Default,
    DefuzzifyBlock,
    FunctionBlock,
    FuzzifyBlock,
    Is,
    Not,
    Or,
    Point,
    PointsMF,
    Range,
    Rule,
    RuleBlock,
    ShapeMF,
    SingletonMF,
    Span,
    Term,
    Variable,
    VarKind,
)
from tests.conftest import EXAMPLES


def pts(*xy: tuple[float, float]) -> PointsMF:
    return PointsMF(tuple(Point(float(x), float(y)) for x, y in xy))


def small(
    n_inputs: int = 2,
    n_terms: int = 2,
    n_outputs: int = 1,
    n_out_terms: int = 2,
    n_rules: int = 2,
    **changes: object,
) -> FunctionBlock:
    inputs = tuple(Variable(f"in{i}", VarKind.INPUT, range=Range(0, 10)) for i in range(n_inputs))
    outputs = tuple(Variable(f"out{i}", VarKind.OUTPUT, range=Range(0, 10)) for i in range(n_outputs))
    fuzzify = tuple(
        FuzzifyBlock(
            v.name,
            tuple(
                Term(f"t{k}", ShapeMF("triangle", (k, k + 1.0, k + 2.0)), span=Span(10 + k, 5))
                for k in range(n_terms)
            ),
        )
        for v in inputs
    )
    defuzzify = tuple(
        DefuzzifyBlock(
            v.name,
            tuple(Term(f"s{k}", SingletonMF(float(k)), span=Span(30 + k, 5)) for k in range(n_out_terms)),
            range=Range(0, 10),
        )
        for v in outputs
    )
    rules = tuple(
        Rule(
            str(r), And((Is("in0", "t0"), Is("in1", "t1"))), (Conclusion("out0", "s0"),), span=Span(50 + r, 9)
        )
        for r in range(n_rules)
    )
    block = RuleBlock("rb", rules, accu="NSUM", span=Span(49, 1))  # the block's sum (1.4)
    fb = FunctionBlock("p", inputs + outputs, fuzzify, defuzzify, (block,))
    return replace(fb, **changes) if changes else fb


def codes(fb: FunctionBlock) -> list[str]:
    return sorted(d.code for d in check_siemens(fb) if d.is_error)


def test_siemens_1_3_fpltest_fits_the_block() -> None:
    # Only a warning: "drainage" has 8 characters where the term dialog takes 7 (6.4); 7 are
    # significant ("drainag", 1.3) and still unique.
    (w,) = check_siemens(read_fpl((EXAMPLES / "fpltest.fpl").read_text()))
    assert w.severity is Severity.WARNING and w.code == "siemens-name" and "drainag" in w.message
    assert not w.is_error


def test_siemens_3_1_at_most_8_inputs_with_7_terms_and_4_outputs_with_9_terms() -> None:
    assert codes(small(n_inputs=8, n_terms=7, n_outputs=4, n_out_terms=9)) == []
    diags = check_siemens(small(n_inputs=9))
    (d,) = [d for d in diags if d.is_error]
    assert d.code == "siemens-too-many-inputs" and "in8 cannot be connected" in d.message
    assert codes(small(n_outputs=5)) == ["siemens-too-many-outputs"]
    (d,) = check_siemens(small(n_terms=8))[:1]
    assert d.code == "siemens-too-many-terms" and d.span == Span(17, 5)  # the 8th term
    assert codes(small(n_out_terms=10)) == ["siemens-too-many-terms"]


def test_siemens_3_1_at_most_200_rules() -> None:
    assert codes(small(n_rules=LIMITS["rules"])) == []
    assert codes(small(n_rules=LIMITS["rules"] + 1)) == ["siemens-too-many-rules"]


def test_siemens_1_3_rules_are_and_only_without_weights() -> None:
    fb = small()
    rules = (
        Rule("or", Or((Is("in0", "t0"), Is("in1", "t0"))), (Conclusion("out0", "s0"),), span=Span(60, 1)),
        Rule("not", Not(Is("in0", "t0")), (Conclusion("out0", "s0"),)),
        Rule("isnot", Is("in0", "t0", negated=True), (Conclusion("out0", "s0"),)),
        Rule("w", Is("in0", "t0"), (Conclusion("out0", "s0", weight=0.5),)),
        Rule("on-out", Is("out0", "s0"), (Conclusion("out0", "s1"),)),
        Rule("empty-if", None, (Conclusion("out0", "s1"),)),  # allowed (1.5)
    )
    found = codes(replace(fb, rule_blocks=(RuleBlock("rb", rules),)))
    assert found == [
        "siemens-rule-operator",
        "siemens-rule-operator",
        "siemens-rule-operator",
        "siemens-rule-variable",
        "siemens-weight",
    ]


def test_siemens_1_3_input_terms_are_rectangles_triangles_trapezoids() -> None:
    assert input_shape(pts((0, 1), (3, 1), (27, 0))) == "trapezoid"  # FPLTEST's cold
    assert input_shape(pts((10, 0), (10, 1), (20, 1), (20, 0))) == "rectangle"
    assert input_shape(pts((1, 0), (2, 1), (3, 0))) == "triangle"
    assert input_shape(pts((1, 0), (2, 0.5), (3, 0))) is None
    assert input_shape(pts((1, 0), (2, 1), (3, 0), (4, 1))) is None
    assert input_shape(ShapeMF("gaussian", (1.0, 2.0))) is None
    gauss = FuzzifyBlock(
        "in0", (Term("t0", ShapeMF("gaussian", (1.0, 2.0))), Term("t1", ShapeMF("triangle", (0, 1, 2))))
    )
    fb = small()
    assert codes(replace(fb, fuzzify=(gauss, fb.fuzzify[1]))) == ["siemens-input-shape"]


def test_siemens_1_3_outputs_are_singletons_and_the_operators_are_the_block_s() -> None:
    fb = small()
    area = DefuzzifyBlock(
        "out0",
        (Term("s0", pts((0, 0), (1, 1), (2, 0))), Term("s1", SingletonMF(3.0))),
        range=Range(0, 10),
        method="COA",
        accu="BSUM",
    )
    found = codes(replace(fb, defuzzify=(area,), rule_blocks=(replace(fb.rule_blocks[0], and_op="PROD"),)))
    assert found == ["siemens-method", "siemens-operator", "siemens-output-shape"]  # BSUM: a warning
    local = replace(fb, variables=(*fb.variables, Variable("mid", VarKind.LOCAL)))
    assert codes(local) == ["siemens-intermediate"]


def test_siemens_1_3_significant_name_lengths() -> None:
    fb = small()
    long_in = replace(fb.variables[0], name="temperature_a")
    renamed = replace(
        fb,
        variables=(long_in, *fb.variables[1:]),
        fuzzify=(replace(fb.fuzzify[0], variable="temperature_a"), fb.fuzzify[1]),
    )
    warnings = [d for d in check_siemens(renamed) if not d.is_error]
    assert all(d.severity is Severity.WARNING for d in warnings)
    assert [d.code for d in warnings] == ["siemens-name"] and "temperatur" in warnings[0].message
    assert "13 characters, the configuration tool takes 10" in warnings[0].message
    twin = replace(fb.variables[1], name="temperature_b")
    clash = replace(renamed, variables=(long_in, twin, *fb.variables[2:]))
    assert "siemens-name-collision" in codes(clash)
    terms = (
        Term("verycold1", ShapeMF("triangle", (0, 1, 2))),
        Term("verycold2", ShapeMF("triangle", (1, 2, 3))),
    )
    assert codes(replace(fb, fuzzify=(FuzzifyBlock("in0", terms), fb.fuzzify[1]))) == [
        "siemens-name-collision"
    ]


def test_siemens_1_5_default_value_is_reported_as_not_used() -> None:
    fb = small()
    with_default = replace(fb, defuzzify=(replace(fb.defuzzify[0], default=Default(5.0)),))
    (d,) = check_siemens(with_default)
    assert d.code == "siemens-default" and not d.is_error and "keeps the last value" in d.message


def test_siemens_6_2_6_4_names_the_configuration_tool_takes() -> None:
    # Project <= 8 characters (6.2 "Define Project"), inputs and outputs <= 10 (6.4), terms
    # <= 7 (6.4); letters, digits and "_", not starting with a digit (6.4).
    fb = small()
    assert check_siemens(replace(fb, name="PROJECT8")) == []
    (d,) = check_siemens(replace(fb, name="PROJECT_9"))
    assert (d.code, d.severity) == ("siemens-name", Severity.WARNING) and "9 characters" in d.message
    (d,) = check_siemens(replace(fb, name="1st"))
    assert "first character may not be a number" in d.message
    three = small(n_inputs=3)  # in2 is in no rule: rename it freely

    def named(name: str) -> FunctionBlock:
        var = replace(three.variables[2], name=name)
        fz = replace(three.fuzzify[2], variable=name)
        return replace(
            three,
            variables=(*three.variables[:2], var, *three.variables[3:]),
            fuzzify=(*three.fuzzify[:2], fz),
        )

    assert check_siemens(named("abcdefghij")) == []
    (d,) = check_siemens(named("débit"))
    assert d.code == "siemens-name" and "only '_'" in d.message
    seven = FuzzifyBlock(
        "in0", (Term("abcdefg", ShapeMF("triangle", (0, 1, 2))), Term("t-1", ShapeMF("triangle", (1, 2, 3))))
    )
    (d,) = check_siemens(replace(fb, fuzzify=(seven, fb.fuzzify[1])))
    assert d.code == "siemens-name" and "in0.t-1" in d.message


def test_siemens_3_2_3_3_bipolar_needs_symmetric_limits() -> None:
    fb = read_fpl((EXAMPLES / "fpltest.fpl").read_text())  # Temp 0..30, Pressure 50..100, Valve -101..101
    bipolar = [
        d for d in check_siemens(fb, bipolar=["Valve", "INPUT1"]) if d.code.startswith("siemens-bipolar")
    ]
    (d,) = bipolar
    assert d.severity is Severity.WARNING and d.message.startswith("Temp: MIN 0 and MAX 30 are not symmetric")
    assert "FUZZY_AI" in d.message
    assert [d.code for d in check_siemens(fb, bipolar=["Flow"]) if d.is_error] == ["siemens-bipolar"]
    assert not [d for d in check_siemens(fb, bipolar=["OUTPUT1"]) if d.code.startswith("siemens-bipolar")]


def test_siemens_1_4_accumulation_other_than_a_sum_is_a_warning_where_terms_are_shared() -> None:
    fb = small()  # both rules conclude out0 IS s0
    (d,) = check_siemens(replace(fb, rule_blocks=(replace(fb.rule_blocks[0], accu="MAX"),)))
    assert (d.code, d.severity) == ("siemens-accumulation", Severity.WARNING) and "rules 0, 1" in d.message
    (d,) = check_siemens(replace(fb, rule_blocks=(replace(fb.rule_blocks[0], accu=None),)))
    assert "MAX (the default)" in d.message
    assert check_siemens(replace(fb, rule_blocks=(replace(fb.rule_blocks[0], accu="SUM"),))) == []
    # one rule per term: every accumulation is the same sum
    one = small(n_rules=1)
    assert check_siemens(replace(one, rule_blocks=(replace(one.rule_blocks[0], accu="MAX"),))) == []
