"""FPL (Siemens manual 1.3): the FPLTEST example of the manual, tolerated elements, the
subset's limits, writing back."""

from __future__ import annotations

from dataclasses import replace

import numpy as np
import pytest

import fuzzyctl
from fuzzyctl import model as m
from fuzzyctl.diagnostics import DiagnosticError, Severity
from fuzzyctl.formats import convert, read_text
from fuzzyctl.formats.fpl.reader import parse_fpl, read_fpl
from fuzzyctl.formats.fpl.writer import check_fpl, write_fpl
from fuzzyctl.model import (
    And,
    Conclusion,
    Default,
    DefuzzifyBlock,
    FunctionBlock,
    FuzzifyBlock,
    Is,
    Point,
    PointsMF,
    Range,
    Rule,
    RuleBlock,
    ShapeMF,
    SingletonMF,
    Term,
    Variable,
    VarKind,
)
from tests.conftest import EXAMPLES, shared_path


def fpltest_from_manual() -> str:
    """The FPLTEST listing exactly as the Siemens manual prints it (section 1.3), minus the
    "STL / Explanation" table headers and the <pre> tags of the text extraction."""
    text = shared_path("seeds", "003_9b3af9c2802d2be3.txt").read_text(encoding="utf-8")
    start = text.index("/*Copyright (c) Siemens AG 1995*/")
    end = text.index("</pre>", start) + len("</pre>")
    lines = [ln for ln in text[start:end].splitlines() if not ln.startswith("STL\t")]
    return "\n".join(lines).replace("<pre>", "").replace("</pre>", "")


def pts(*xy: tuple[float, float]) -> PointsMF:
    return PointsMF(tuple(Point(x, y) for x, y in xy))


def rule(label: str, t: str, p: str, v: str) -> Rule:
    return Rule(label, And((Is("Temp", t), Is("Pressure", p))), (Conclusion("Valve", v),))


EXPECTED_FPLTEST = FunctionBlock(
    "FPLTEST",
    variables=(
        Variable("Temp", VarKind.INPUT, "REAL"),
        Variable("Pressure", VarKind.INPUT, "REAL"),
        Variable("Valve", VarKind.OUTPUT, "REAL"),
    ),
    fuzzify=(
        # MIN/MAX: the range of the FUZZIFY block; no clamp needed, all points are inside.
        FuzzifyBlock(
            "Temp",
            (Term("cold", pts((0, 1), (3, 1), (27, 0))), Term("hot", pts((3, 0), (27, 1), (30, 1)))),
            range=Range(0, 30),
        ),
        FuzzifyBlock(
            "Pressure",
            (Term("low", pts((50, 1), (55, 1), (95, 0))), Term("high", pts((55, 0), (95, 1), (100, 1)))),
            range=Range(50, 100),
        ),
    ),
    defuzzify=(
        DefuzzifyBlock(
            "Valve",
            (
                Term("drainage", SingletonMF(-100.0)),
                Term("closed", SingletonMF(0.0)),
                Term("inlet", SingletonMF(100.0)),
            ),
            range=Range(-101.0, 101.0),
            method="COGS",
            default=Default(no_change=True),
        ),
    ),
    rule_blocks=(
        RuleBlock(
            "ProFuzzy",
            (
                rule("Rule_01", "cold", "low", "inlet"),
                rule("Rule_02", "cold", "high", "closed"),
                rule("Rule_03", "hot", "low", "closed"),
                rule("Rule_04", "hot", "high", "drainage"),
            ),
            and_op="MIN",
            act="MIN",
            accu="NSUM",  # Fuzzy Control adds the rules of one term (1.4): Rule_02 + Rule_03
        ),
    ),
)


@pytest.mark.extra("seeds")
def test_siemens_1_3_fpltest_example_reads_as_printed() -> None:
    result = parse_fpl(fpltest_from_manual(), path="FPLTEST.fpl")
    assert result.document is not None
    assert result.document.main == EXPECTED_FPLTEST
    # The manual's "CONNECT FROM FROM ProFuzzy" is read, with a warning at that place.
    (warn,) = [d for d in result.diagnostics if d.severity is Severity.WARNING]
    assert warn.code == "fpl-repeated-keyword"
    assert warn.span is not None and warn.span.line == 41


def test_siemens_1_3_example_file_is_the_manual_listing() -> None:
    doc = read_fpl((EXAMPLES / "fpltest.fpl").read_text(encoding="utf-8"))
    assert doc.main == EXPECTED_FPLTEST


def test_siemens_1_3_narrow_rectangles_are_singletons_at_their_centre() -> None:
    src = """PROJECT p VAR x TYPE float MIN 0 MAX 10 MEMBER a POINTS 0,0 10,1 END END
    VAR y TYPE float MIN 0 MAX 200 MEMBER s POINTS 49.5,1.0 50.5,1.0 END MEMBER t POINTS 120,1 END END
    FUZZY r RULE r1 IF (x is a) THEN y = s END END
    CONNECT FROM x TO r END CONNECT FROM r TO y END END"""
    y = read_fpl(src).main.defuzzify_block("y")
    assert y is not None
    assert [t.mf for t in y.terms] == [SingletonMF(50.0), SingletonMF(120.0)]


def test_siemens_1_3_vertical_edges_inside_the_range_get_their_foot() -> None:
    # "With vertical lines specifying the upper point is sufficient": a rectangle of two
    # points inside [MIN, MAX] is 0 outside; at MIN/MAX the edge stays a shoulder.
    src = """PROJECT p VAR x TYPE float MIN 0 MAX 30
      MEMBER mid POINTS 10,1 20,1 END
      MEMBER edge POINTS 0,1 5,1 8,0 END
      MEMBER right POINTS 22,0 25,1 END
    END END"""
    fz = read_fpl(src).main.fuzzify_block("x")
    assert fz is not None
    assert fz.term("mid") == Term("mid", pts((10, 0), (10, 1), (20, 1), (20, 0)))
    assert fz.term("edge") == Term("edge", pts((0, 1), (5, 1), (8, 0)))
    assert fz.term("right") == Term("right", pts((22, 0), (25, 1), (25, 0)))
    assert not fz.clamp
    wide = read_fpl("PROJECT p VAR x TYPE float MIN 0 MAX 30 MEMBER m POINTS -5,0 10,1 40,0 END END END")
    assert wide.main.fuzzify[0].clamp  # points outside [MIN, MAX]: the clamp of 1.5 matters


def test_siemens_1_3_tolerated_elements_warn_as_the_manual_lists() -> None:
    src = """/* header */
    PROJECT p
    OPTIONS something 1 2 END
    SOURCE "x.c" END
    FRAGMENT f #CODE int a = 1; END #END_CODE END
    VAR x TYPE float MIN 0 MAX 1 INITIALLY 0.5 MAP port 3
      MEMBER lo POINTS 0,1 1,0 END
    END
    VAR y TYPE float MIN 0 MAX 1 DEFAULT 0.5 MEMBER s POINTS 0.4,1 0.6,1 END END
    #CODE void f(void) {} #END_CODE
    FUZZY r RULE a IF x is lo THEN y = s END END
    END"""
    result = parse_fpl(src)
    assert result.document is not None
    warnings = sorted(d.message.split(":")[0] for d in result.diagnostics if d.severity is Severity.WARNING)
    assert warnings == ["DEFAULT ignored", "INITIALLY ignored", "MAP ignored"]
    notes = [d.message.split(" ")[0] for d in result.diagnostics if d.severity is Severity.NOTE]
    assert sorted(notes) == ["#CODE..#END_CODE", "FRAGMENT", "OPTIONS", "SOURCE"]
    fb = result.document.main
    assert [v.name for v in fb.inputs] == ["x"] and [v.name for v in fb.outputs] == ["y"]
    assert fb.defuzzify_block("y") is not None


@pytest.mark.parametrize(
    ("source", "message", "line", "column"),
    [
        (
            "PROJECT p\nFUZZY r RULE a IF (x is lo) OR (x is hi) THEN y = s END END END",
            "OR is not permissible",
            2,
            29,
        ),
        ("PROJECT p\nFUZZY r RULE a IF x is NOT lo THEN y = s END END END", "NOT is not permissible", 2, 24),
        ("PROJECT p\nPACKAGE q END END", "PACKAGE is not permissible", 2, 1),
        ("PROJECT p\nFUZZY a END\nFUZZY b END END", "only one set of rules", 3, 1),
        ("PROJECT p VAR x MEMBER m POINTS 1,0 0,1 END END END", "increasing x order", 1, 37),
        ("PROJECT p VAR x MEMBER m POINTS 1,0 2 END END END", "x,y pairs", 1, 37),
        ("PROJECT p VAR x MEMBER m POINTS 1,2 END END END", "outside [0, 1]", 1, 35),
        ("PROJECT p VAR x MEMBER m EQUATION x END END END", "expected POINTS or END", 1, 26),
        ("PROJECT p\nVAR x TYPE float MIN 5 MAX 1 END END", "MIN 5 must be below MAX 1", 2, 1),
        ("PROJECT p FUZZY r RULE a IF x is lo THEN y = s END END END", "x is not a VAR", 1, 29),
    ],
)
def test_siemens_1_3_errors_name_the_place(source: str, message: str, line: int, column: int) -> None:
    with pytest.raises(DiagnosticError) as info:
        read_fpl(source, path="bad.fpl")
    first = next(d for d in info.value.diagnostics if d.is_error)
    assert message in first.message
    assert first.span is not None and (first.span.line, first.span.column) == (line, column)
    assert first.file == "bad.fpl"


@pytest.mark.extra("seeds")
def test_fpl_writer_round_trips_the_manual_example() -> None:
    doc = read_fpl(fpltest_from_manual())
    text = write_fpl(doc)
    assert read_fpl(text).main == EXPECTED_FPLTEST
    assert "POINTS -100.505,1.0 -99.495,1.0" in text  # 1/200 of the range, centred on -100


def test_fpl_writer_refuses_what_the_subset_cannot_say() -> None:
    fb = EXPECTED_FPLTEST
    weighted = RuleBlock(
        "r", (Rule("1", Is("Temp", "cold"), (Conclusion("Valve", "inlet", weight=0.8),)),), and_op="PROD"
    )
    gauss = FuzzifyBlock("Temp", (Term("warm", ShapeMF("gaussian", (15.0, 3.0))),))
    bad = FunctionBlock(fb.name, fb.variables, (gauss,), fb.defuzzify, (weighted,))
    codes = sorted(d.code for d in check_fpl(bad) if d.is_error)
    assert codes == ["fpl-expr-op", "fpl-expr-term", "fpl-expr-weight"]
    with pytest.raises(DiagnosticError):
        write_fpl(bad)


def test_fpl_writer_turns_triangles_and_trapezoids_into_points() -> None:
    fb = FunctionBlock(
        "shapes",
        variables=(
            Variable("x", VarKind.INPUT, range=Range(0, 10)),
            Variable("y", VarKind.OUTPUT, range=Range(0, 1)),
        ),
        fuzzify=(
            FuzzifyBlock(
                "x",
                (
                    Term("t", ShapeMF("triangle", (1.0, 2.0, 3.0))),
                    Term("z", ShapeMF("trapezoid", (4.0, 5.0, 6.0, 7.0))),
                ),
            ),
        ),
        defuzzify=(
            DefuzzifyBlock("y", (Term("one", SingletonMF(1.0)),), method="COGS", default=Default(0.0)),
        ),
        rule_blocks=(RuleBlock("r", (Rule("1", Is("x", "t"), (Conclusion("y", "one"),)),)),),
    )
    warnings = [d.code for d in check_fpl(fb)]
    assert warnings == ["fpl-expr-default"]
    back = read_fpl(write_fpl(fb)).main.fuzzify_block("x")
    assert back is not None
    assert back.term("t") == Term("t", pts((1, 0), (2, 1), (3, 0)))
    assert back.term("z") == Term("z", pts((4, 0), (5, 1), (6, 1), (7, 0)))


@pytest.mark.extra("seeds")
def test_siemens_1_3_fpltest_reads_like_the_fcl_transcription() -> None:
    # examples/siemens_fpltest.fcl was written by hand (FCL issue) from the same listing;
    # the FPL carries MIN/MAX, which that FCL leaves out.
    from fuzzyctl.fcl import parse_fcl

    fcl = parse_fcl((EXAMPLES / "siemens_fpltest.fcl").read_text(encoding="utf-8")).main
    fpl = read_fpl(fpltest_from_manual()).main
    no_ranges = replace(
        fpl,
        fuzzify=tuple(replace(f, range=None) for f in fpl.fuzzify),
        defuzzify=tuple(replace(d, range=None) for d in fpl.defuzzify),
        rule_blocks=tuple(replace(rb, act=None) for rb in fpl.rule_blocks),
    )
    assert no_ranges == fcl


def test_names_fpl_cannot_read_are_renamed() -> None:
    """MATLAB names such as ``dV*`` or ``Rear Left`` and FPL keywords (``If``, ``Min``) are no
    FPL words: the writer renames them and the project reads back and evaluates the same."""
    pts = m.PointsMF((m.Point(0.0, 0.0), m.Point(5.0, 1.0), m.Point(10.0, 0.0)))
    fb = m.FunctionBlock(
        "my project",
        variables=(
            m.Variable("dV*", m.VarKind.INPUT),
            m.Variable("If", m.VarKind.INPUT),
            m.Variable("Min", m.VarKind.OUTPUT),
        ),
        fuzzify=(
            m.FuzzifyBlock("dV*", (m.Term("Rear Left", pts),), m.Range(0, 10)),
            m.FuzzifyBlock("If", (m.Term("end", pts),), m.Range(0, 10)),
        ),
        defuzzify=(
            m.DefuzzifyBlock(
                "Min",
                (m.Term("is", m.SingletonMF(2.0)), m.Term("b", m.SingletonMF(8.0))),
                m.Range(0, 10),
                "COGS",
            ),
        ),
        rule_blocks=(
            m.RuleBlock(
                "rb",
                (
                    m.Rule("1", m.Is("dV*", "Rear Left"), (m.Conclusion("Min", "is"),)),
                    m.Rule("2", m.Is("If", "end"), (m.Conclusion("Min", "b"),)),
                ),
                "MIN",
                None,
                None,
                "MAX",
            ),
        ),
    )
    text, losses = convert(m.Document((fb,)), "fpl", lossy=True)
    assert not [loss for loss in losses if "name" in loss.reason]
    again = read_text(text, "fpl").document.main
    names = {v.name for v in again.variables} | {t.name for b in again.fuzzify for t in b.terms}
    assert not names & {"dV*", "If", "Min", "Rear Left", "end", "is"}
    xs = np.linspace(0.5, 9.5, 7)
    want = fuzzyctl.compile(fb).evaluate_batch({"dV*": xs, "If": xs[::-1]})["Min"]
    a, b = (v.name for v in again.inputs)
    got = fuzzyctl.compile(again).evaluate_batch({a: xs, b: xs[::-1]})[again.outputs[0].name]
    assert np.allclose(want, got, rtol=0.0, atol=1e-9)


def test_siemens_1_4_fpl_means_the_sum_of_the_rules_of_one_term() -> None:
    # An FPL file means what Fuzzy Control computes: x = sum(mu_rule x_rule) / sum(mu_rule)
    # (1.4).  FPLTEST at Temp 9, Pressure 65: inlet .75, closed .25 + .25, drainage .25 ->
    # (75 - 25) / 1.5 = 100/3 through the IEC engine too (ACCU NSUM).
    app = read_fpl((EXAMPLES / "fpltest.fpl").read_text())
    assert app.main.rule_blocks[0].accu == "NSUM"
    assert fuzzyctl.compile(app).evaluate({"Temp": 9.0, "Pressure": 65.0})["Valve"] == pytest.approx(100 / 3)
    # An FCL program with ACCU MAX (or none) whose term "closed" is concluded by two rules
    # computes 40 there: FPL cannot say it without changing the result.
    fcl = (EXAMPLES / "siemens_fpltest.fcl").read_text()
    as_max = read_text(fcl.replace("ACCU : NSUM;", "ACCU : MAX;"), "fcl").document
    with pytest.raises(fuzzyctl.formats.LossError, match=r"adds the degrees.*rules Rule_02, Rule_03"):
        convert(as_max, "fpl")
    text, losses = convert(as_max, "fpl", lossy=True)
    assert len(losses) == 1 and read_fpl(text).main.rule_blocks[0].accu == "NSUM"
    no_accu = read_text(fcl.replace("        ACCU : NSUM;\n", ""), "fcl").document
    assert any("MAX (the default)" in str(loss) for loss in fuzzyctl.formats.get("fpl").losses(no_accu))
    assert fuzzyctl.formats.get("fpl").losses(read_text(fcl, "fcl").document) == []
    # One rule per term: MAX and the sum agree, nothing is lost.
    rule_3 = "        RULE Rule_03 : IF Temp IS hot AND Pressure IS low THEN Valve IS closed;\n"
    assert rule_3 in fcl
    one = read_text(fcl.replace(rule_3, "").replace("ACCU : NSUM;", "ACCU : MAX;"), "fcl").document
    assert fuzzyctl.formats.get("fpl").losses(one) == []
