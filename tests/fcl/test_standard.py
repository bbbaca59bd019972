"""IEC 61131-7 clause 5 examples, the Siemens example system, and the rule semantics the
standard prescribes (5.2.4, Table 6)."""

from __future__ import annotations

import math

import pytest

from fuzzyctl.fcl import conformance, load_file, load_text, parse_fcl, write
from fuzzyctl.model import (
    And,
    Conclusion,
    Degree,
    Is,
    Not,
    Or,
    Point,
    PointsMF,
    Ref,
    ShapeMF,
    SingletonMF,
    VarKind,
    comments_at,
)
from tests.conftest import EXAMPLES

FIG3 = """FUNCTION_BLOCK Fuzzy_FB
    VAR_INPUT
        Temp: REAL;
        Pressure: REAL;
    END_VAR
    VAR_OUTPUT
        Valve: REAL;
    END_VAR
END_FUNCTION_BLOCK"""


def _wrap(
    body: str, decls: str = "VAR_INPUT temp : REAL; pressure : REAL; END_VAR VAR_OUTPUT valve : REAL; END_VAR"
) -> str:
    return f"FUNCTION_BLOCK fb {decls}\n{body}\nEND_FUNCTION_BLOCK\n"


FIG4 = """FUZZIFY temp;
TERM cold:= (3, 1) (27, 0);
TERM warm:= (3, 0) (27, 1);
END_FUZZIFY"""

FIG5_DECLS = """VAR_INPUT
temp: REAL; (* this input shall be fuzzified *)
pressure: REAL; (* this input shall be fuzzified *)
bp_warm1, bp_warm2: REAL; (* these inputs are for on-line adaptation *)
END_VAR VAR_OUTPUT valve : REAL; END_VAR"""
FIG5 = """FUZZIFY temp
TERM warm:= (bp_warm1, 0.0), (21.0, 1.0), (bp_warm2, 0.0);
END_FUZZIFY"""

FIG6 = """DEFUZZIFY valve
RANGE(-100,100);
TERM drainage := -100;
TERM closed := 0;
TERM inlet := 100;
METHOD: CoGS;
DEFAULT := NC;
END_DEFUZZIFY"""

WEIGHT_CONSTANT = """FUZZIFY temp TERM cold := (3, 1) (27, 0); END_FUZZIFY
FUZZIFY pressure TERM low := (55, 1) (95, 0); END_FUZZIFY
DEFUZZIFY valve1 TERM inlet := 100; METHOD : CoGS; DEFAULT := 0; END_DEFUZZIFY
DEFUZZIFY valve2 TERM closed := 0; METHOD : CoGS; DEFAULT := 0; END_DEFUZZIFY
RULEBLOCK b AND : MIN; ACCU : MAX;
RULE 1 : IF temp IS cold AND pressure IS low THEN valve1 IS inlet WITH 0.5,
valve2 IS closed;
END_RULEBLOCK"""

WEIGHT_VARIABLE_DECLS = """VAR_INPUT temp : REAL; pressure : REAL; w_myrule1: REAL:= 0.8; END_VAR
VAR_OUTPUT valve : REAL; END_VAR"""
WEIGHT_VARIABLE = """FUZZIFY temp TERM cold := (3, 1) (27, 0); END_FUZZIFY
FUZZIFY pressure TERM low := (55, 1) (95, 0); END_FUZZIFY
DEFUZZIFY valve TERM inlet := 100; METHOD : CoGS; DEFAULT := 0; END_DEFUZZIFY
RULEBLOCK temp_rule AND : MIN; ACCU : MAX;
RULE 1: IF temp IS cold AND pressure IS low
THEN valve IS inlet WITH w_myrule1;
END_RULEBLOCK"""


def _round_trip(text: str) -> None:
    doc = parse_fcl(text)
    assert parse_fcl(write(doc)) == doc


def test_figure3_interface() -> None:
    fb = parse_fcl(FIG3).main
    assert [v.name for v in fb.inputs] == ["Temp", "Pressure"]
    assert [v.name for v in fb.outputs] == ["Valve"]
    _round_trip(FIG3)


def test_figure4_ramps_and_fuzzify_semicolon() -> None:
    doc = load_text(_wrap(FIG4, "VAR_INPUT temp : REAL; END_VAR")).raise_for_errors()
    cold = doc.main.fuzzify[0].terms[0]
    assert cold.mf == PointsMF((Point(3.0, 1.0), Point(27.0, 0.0)))
    _round_trip(_wrap(FIG4, "VAR_INPUT temp : REAL; END_VAR"))


def test_figure5_variable_points_need_extension() -> None:
    result = load_text(_wrap(FIG5, FIG5_DECLS))
    doc = result.raise_for_errors()
    warm = doc.main.fuzzify[0].terms[0]
    assert isinstance(warm.mf, PointsMF)
    assert warm.mf.points[0].x == Ref("bp_warm1") and warm.mf.points[2].x == Ref("bp_warm2")
    assert [v.name for v in doc.main.inputs] == ["temp", "pressure", "bp_warm1", "bp_warm2"]
    assert conformance.level(conformance.features(doc)) is conformance.Level.EXTENSION
    _round_trip(_wrap(FIG5, FIG5_DECLS))


def test_figure6_singletons_and_comma_range() -> None:
    doc = parse_fcl(_wrap(FIG6))
    d = doc.main.defuzzify[0]
    assert [t.mf for t in d.terms] == [SingletonMF(-100.0), SingletonMF(0.0), SingletonMF(100.0)]
    assert (d.range.low, d.range.high) == (-100.0, 100.0)  # type: ignore[union-attr]
    assert d.method == "COGS" and d.default is not None and d.default.no_change
    _round_trip(_wrap(FIG6))


def test_figure7_needs_extension_because_of_with() -> None:
    result = load_file(EXAMPLES / "figure7.fcl")
    doc = result.raise_for_errors()
    feats = conformance.features(doc)
    assert conformance.level(feats) is conformance.Level.EXTENSION
    assert [f.element for f in feats] == ["weighting factor"]
    rule2 = doc.main.rule_blocks[0].rules[1]
    assert rule2.conclusions == (Conclusion("valve", "closed", 0.8),)
    assert not [d for d in result.diagnostics if d.severity.value != "note"]
    assert parse_fcl(write(doc)) == doc


def test_siemens_example_needs_extension_only_for_the_sum() -> None:
    # The S7 block adds the rules of one output term (Siemens manual 1.4): ACCU NSUM, a
    # Table 9 accumulation; everything else in FPLTEST is Basic level.
    doc = load_file(EXAMPLES / "siemens_fpltest.fcl").raise_for_errors()
    feats = conformance.features(doc)
    assert conformance.level(feats) is conformance.Level.EXTENSION
    assert [(f.element, f.detail) for f in feats] == [("accumulation", "ACCU: NSUM")]
    assert [r.label for r in doc.main.rule_blocks[0].rules] == ["Rule_01", "Rule_02", "Rule_03", "Rule_04"]
    assert parse_fcl(write(doc)) == doc


def test_weight_attaches_to_the_subconclusion_it_follows() -> None:
    doc = parse_fcl(
        _wrap(
            WEIGHT_CONSTANT,
            "VAR_INPUT temp : REAL; pressure : REAL; END_VAR "
            "VAR_OUTPUT valve1 : REAL; valve2 : REAL; END_VAR",
        )
    )
    (rule,) = doc.main.rule_blocks[0].rules
    assert rule.conclusions == (Conclusion("valve1", "inlet", 0.5), Conclusion("valve2", "closed", None))


def test_variable_weight() -> None:
    doc = parse_fcl(_wrap(WEIGHT_VARIABLE, WEIGHT_VARIABLE_DECLS))
    w = doc.main.variable("w_myrule1")
    assert w is not None and w.initial == 0.8 and w.kind is VarKind.INPUT
    (rule,) = doc.main.rule_blocks[0].rules
    assert rule.conclusions[0].weight == Ref("w_myrule1")
    _round_trip(_wrap(WEIGHT_VARIABLE, WEIGHT_VARIABLE_DECLS))


RULES_DECLS = "VAR_INPUT a : REAL; b : REAL; c : REAL; temp : REAL; END_VAR VAR_OUTPUT v : REAL; END_VAR"
RULES_TERMS = """FUZZIFY a TERM x := (0, 0) (1, 1); END_FUZZIFY
FUZZIFY b TERM x := (0, 0) (1, 1); END_FUZZIFY
FUZZIFY c TERM x := (0, 0) (1, 1); END_FUZZIFY
FUZZIFY temp TERM hot := (0, 0) (1, 1); END_FUZZIFY
DEFUZZIFY v TERM on := 1; METHOD : CoGS; DEFAULT := 0; END_DEFUZZIFY
RULEBLOCK r AND : MIN; OR : MAX; ACCU : MAX;
RULE 1 : IF {cond} THEN v IS on;
END_RULEBLOCK"""


def _condition(cond: str):  # type: ignore[no-untyped-def]
    doc = parse_fcl(_wrap(RULES_TERMS.replace("{cond}", cond), RULES_DECLS))
    assert parse_fcl(write(doc)) == doc
    return doc.main.rule_blocks[0].rules[0].condition


A, B, C = Is("a", "x"), Is("b", "x"), Is("c", "x")


@pytest.mark.parametrize(
    ("text", "expected"),
    [
        ("NOT temp IS hot", Not(Is("temp", "hot"))),
        ("NOT (temp IS hot)", Not(Is("temp", "hot"))),
        ("temp IS NOT hot", Is("temp", "hot", negated=True)),
        ("a IS x AND b IS x AND c IS x", And((A, B, C))),
        ("(a IS x AND b IS x) AND c IS x", And((And((A, B)), C))),
        ("a IS x OR b IS x AND c IS x", Or((A, And((B, C))))),
        ("(a IS x OR b IS x) AND c IS x", And((Or((A, B)), C))),
        ("NOT a IS x AND b IS x", And((Not(A), B))),
        ("a AND b IS x", And((Degree("a"), B))),
    ],
)
def test_condition_structure_and_precedence(text: str, expected: object) -> None:
    assert _condition(text) == expected


def test_lower_case_dialect_without_semicolons_and_fuzzylite_terms() -> None:
    text = """function_block
    var_input x : real; end_var var_output y : real; end_var
    fuzzify x range := (0.000 .. 1.000); term lo := Triangle 0 0.5 1 0.8; term hi := GBELL 2 4 6; end_fuzzify
    defuzzify y range := (0 .. 1); term a := COSINE 2 5; term b := Cosine 5 4;
      method : MM; accu : ASUM; default := nan | NC; end_defuzzify
    ruleblock
      and : EPROD; or : ESUM; act : EPROD;
      rule 1 : if x is lo then y is a
      rule 2 : if x is very hi then y is b with 0.5
    end_ruleblock
    end_function_block"""
    result = load_text(text)
    doc = result.raise_for_errors()
    fb = doc.main
    assert fb.name is None and fb.rule_blocks[0].name is None
    lo, hi = fb.fuzzify[0].terms
    assert lo.mf == ShapeMF("triangle", (0.0, 0.5, 1.0), 0.8)
    assert hi.mf == ShapeMF("bell", (6.0, 2.0, 4.0))  # GBELL a b mean
    a, b = fb.defuzzify[0].terms
    assert a.mf == ShapeMF("cosine", (5.0, 4.0)) == b.mf  # COSINE net_max offset == Cosine center width
    d = fb.defuzzify[0]
    assert d.method == "MOM" and d.accu == "PROBOR"
    assert d.default is not None and math.isnan(d.default.value or 0.0) and d.default.no_change
    rb = fb.rule_blocks[0]
    assert (rb.and_op, rb.or_op, rb.act) == ("EINSTEIN", "EINSTEIN", "EINSTEIN")
    assert rb.rules[1].condition == Is("x", "hi", hedges=("very",))
    assert conformance.level(conformance.features(doc)) is conformance.Level.OPEN
    assert parse_fcl(write(doc)) == doc


def test_crlf_bom_latin1_comments_and_options(tmp_path) -> None:  # type: ignore[no-untyped-def]
    text = (
        "\ufeff// header\r\nFUNCTION_BLOCK t (* iec *)\r\nVAR_INPUT temp\u00e9 : REAL; END_VAR\r\n"
        "OPTIONS\r\n  vendor_param = 3; (* kept *)\r\nEND_OPTIONS\r\nEND_FUNCTION_BLOCK\r\n"
    )
    path = tmp_path / "latin.fcl"
    path.write_bytes(text.encode("utf-8")[3:].replace("\u00e9".encode(), b"\xe9"))
    result = load_file(path)
    doc = result.raise_for_errors()
    assert result.source.encoding == "latin-1"
    assert doc.main.inputs[0].name == "temp\u00e9"
    assert doc.main.options[0].text == "vendor_param = 3; (* kept *)"
    assert doc.main.comments == ("// header",)  # before the block; the other after its header
    assert comments_at(doc.main, "head") == ("(* iec *)",)
    bom = tmp_path / "bom.fcl"
    bom.write_bytes(text.encode("utf-8"))
    assert load_file(bom).raise_for_errors() == doc
    assert "(* header *)" in write(doc)
