"""Interval type-2 in FCL (the Open-level form of docs/fcl.md) and on the command line:
eval/explain/check, conversions, and the consumers that refuse type-2 systems (exit 1, a
message; never the internal-error exit 3)."""

from __future__ import annotations

import json
from pathlib import Path

import pytest

import fuzzyctl
from fuzzyctl import formats
from fuzzyctl import model as m
from fuzzyctl.cli.app import main
from fuzzyctl.diagnostics import DiagnosticError
from fuzzyctl.engine.type2 import Type2Controller
from fuzzyctl.fcl import conformance
from tests.engine.type2_systems import random_it2

EXAMPLE = "examples/tipper_type2.fis"

FCL = """FUNCTION_BLOCK t2
VAR_INPUT x : REAL; END_VAR
VAR_OUTPUT y : REAL; END_VAR
FUZZIFY x
    RANGE(0..10);
    TERM low := (0, 1) (10, 0) LOWER SCALE 0.8 LAG 0.1;   (* LOWER in a comment is text *)
    TERM high := (0, 0) (10, 1) LOWER (2, 0) (10, 0.9);
END_FUZZIFY
DEFUZZIFY y
    RANGE(0..1);
    TERM a := (0, 0) (0.3, 1) (0.6, 0) LOWER SCALE 0.6 LAG 0.2 0.1;
    TERM b := (0.4, 0) (0.7, 1) (1, 0);
    METHOD : COG;
    TYPE_REDUCTION : EKM;
END_DEFUZZIFY
RULEBLOCK r
    RULE 1 : IF x IS low THEN y IS a;
    RULE 2 : IF x IS high THEN y IS b;
END_RULEBLOCK
END_FUNCTION_BLOCK
"""


def test_fcl_form_reads_every_part() -> None:
    fb = fuzzyctl.load(FCL).main
    x, y = fb.fuzzify_block("x"), fb.defuzzify_block("y")
    assert x is not None and y is not None
    assert x.terms[0].lower == m.LowerMF(scale=0.8, lag=(0.1,))
    assert x.terms[1].lower == m.LowerMF(mf=m.PointsMF((m.Point(2.0, 0.0), m.Point(10.0, 0.9))))
    assert y.terms[0].lower == m.LowerMF(scale=0.6, lag=(0.2, 0.1))
    assert y.terms[1].lower is None and y.type_reduction == "EKM"


def test_fcl_form_round_trips_and_keeps_positions() -> None:
    doc = fuzzyctl.load(FCL)
    text, losses = formats.convert(doc, "fcl")
    assert not losses and "TYPE_REDUCTION : EKM;" in text and "LOWER SCALE 0.6 LAG 0.2 0.1" in text
    assert fuzzyctl.load(text).main == doc.main
    bad = FCL.replace("(0.4, 0) (0.7, 1) (1, 0);", "(0.4, 0) (0.7, 1) (1, 0) LOWER SCALE 2 LAG 0.1;")
    with pytest.raises(DiagnosticError) as info:
        fuzzyctl.load(bad)
    d = info.value.diagnostics[0]
    assert "LOWER SCALE must be in (0, 1]" in d.message
    assert d.span is not None and (d.span.line, d.span.column) == (12, 40)  # at LOWER


NAMES_SPELLED_LIKE_THE_WORDS = """FUNCTION_BLOCK names
VAR_INPUT lower : REAL; type_reduction : REAL; END_VAR
VAR_OUTPUT y : REAL; END_VAR
FUZZIFY lower
    TERM lower := (0, 1) (3, 0);
    TERM upper := (0, 0) (3, 1);
END_FUZZIFY
FUZZIFY type_reduction
    TERM lower := (0, 1) (3, 0);
END_FUZZIFY
DEFUZZIFY y
    TERM lower := (0, 1) (3, 0);   (* LOWER SCALE 0.5 LAG 0.1; in a comment *)
    TERM higher := (0, 0) (3, 1);
    METHOD : COG;
END_DEFUZZIFY
RULEBLOCK r
    RULE 1 : IF lower IS lower AND type_reduction IS lower THEN y IS lower WITH 0.3;
    RULE 2 : IF lower IS upper THEN y IS higher;
END_RULEBLOCK
END_FUNCTION_BLOCK
"""


def test_lower_and_type_reduction_stay_usable_as_names() -> None:
    # the words are keywords only where the type-2 form puts them (after a term's function;
    # at the start of a DEFUZZIFY statement): a type-1 file naming a term or a variable so
    # reads as before, as a type-1 system
    fb = fuzzyctl.load(NAMES_SPELLED_LIKE_THE_WORDS).main
    lower = fb.fuzzify_block("lower")
    assert lower is not None and [t.name for t in lower.terms] == ["lower", "upper"]
    assert all(t.lower is None for f in fb.fuzzify for t in f.terms)
    assert all(t.lower is None for d in fb.defuzzify for t in d.terms)
    y = fb.defuzzify_block("y")
    assert y is not None and y.type_reduction is None
    rules = [rule for _, rule in fb.rules()]
    assert len(rules) == 2 and rules[0].conclusions[0].weight == 0.3


def test_fis_to_fcl_to_fis_computes_the_same() -> None:
    doc = fuzzyctl.load(EXAMPLE)
    fcl = formats.convert(doc, "fcl")[0]
    back = fuzzyctl.load(formats.convert(fuzzyctl.load(fcl), "fis")[0], format="fis")
    a, b = Type2Controller(doc.main), Type2Controller(back.main)
    for s in (0.0, 2.5, 7.0):
        for f in (1.0, 8.5):
            assert a.evaluate(service=s, food=f) == b.evaluate(service=s, food=f)


def test_check_names_the_open_level() -> None:
    doc = fuzzyctl.load(FCL)
    feats = conformance.features(doc)
    assert conformance.level(feats) is conformance.Level.OPEN
    details = {f.detail for f in feats if f.level is conformance.Level.OPEN}
    assert "input: interval type-2 term (LOWER SCALE/LAG)" in details
    assert "TYPE_REDUCTION: EKM (interval type-2)" in details


def test_lower_equal_upper_type1_fcl_unchanged() -> None:
    # a type-1 FCL file is written exactly as before (no LOWER, no TYPE_REDUCTION)
    fb = m.FunctionBlock(
        "t1",
        (m.Variable("x", m.VarKind.INPUT), m.Variable("y", m.VarKind.OUTPUT)),
        (m.FuzzifyBlock("x", (m.Term("a", m.PointsMF((m.Point(0.0, 1.0), m.Point(1.0, 0.0)))),)),),
    )
    text = formats.convert(m.Document((fb,)), "fcl")[0]
    assert "LOWER" not in text and "TYPE_REDUCTION" not in text


def test_cli_eval_explain_check(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["eval", EXAMPLE, "-s", "service=3", "-s", "food=8", "--json"]) == 0
    value = json.loads(capsys.readouterr().out)["tip"]
    assert value == fuzzyctl.compile(EXAMPLE).evaluate(service=3, food=8)["tip"]
    assert main(["explain", EXAMPLE, "-s", "service=3", "-s", "food=8", "--json"]) == 0
    e = json.loads(capsys.readouterr().out)
    # by hand: poor(3) = 0.4, lower (0.4 - 0.2) / 0.8 = 0.25; good(3) = 0.6, lower
    # 0.9 (0.6 - 0.2) / 0.8 = 0.45; delicious(8) = 0.5, lower 0.8 (0.5 - 0.2) / 0.8 = 0.3
    firing = [v for r in e["rules"] for v in r["firing"]]
    assert firing == pytest.approx([0.25, 0.4, 0.45, 0.6, 0.3, 0.5], rel=1e-15)
    lo, hi = e["outputs"][0]["interval"]
    assert lo < value < hi
    fcl = tmp_path / "t2.fcl"
    fcl.write_text(FCL, encoding="utf-8")
    assert main(["check", str(fcl)]) == 0
    assert "Open" in capsys.readouterr().out


@pytest.mark.parametrize(
    ("argv", "words"),
    [
        (["codegen", EXAMPLE, "--lang", "fmu"], "code generation is not available"),
        (["codegen", EXAMPLE, "--lookup"], "--lookup is not available"),
        (["codegen", EXAMPLE, "--arith", "int32"], "--arith int32 is not available"),
    ],
)
def test_consumers_refuse_with_a_message(
    argv: list[str], words: str, capsys: pytest.CaptureFixture[str]
) -> None:
    assert main(argv) == 1
    assert words in capsys.readouterr().err.replace("\n", " ")


def test_tune_writes_the_lower_functions(tmp_path: Path) -> None:
    data = tmp_path / "d.csv"
    data.write_text("service,food,tip\n3,8,15\n5,5,15\n1,2,6\n9,9,24\n", encoding="utf-8")
    out = tmp_path / "o.fcl"
    argv = ["tune", EXAMPLE, "--data", str(data), "-o", str(out), "--budget", "5", "--workers", "0"]
    assert main([*argv, "--validation", "0"]) == 0
    tuned = fuzzyctl.load(out).main
    assert tuned.is_type2 and all(t.lower is not None for f in tuned.fuzzify for t in f.terms)


def test_convert_type1_option(tmp_path: Path) -> None:
    out = tmp_path / "t1.fll"
    assert main(["convert", EXAMPLE, str(out)]) != 0  # fll cannot express type-2: a loss, refused
    assert main(["convert", EXAMPLE, str(out), "--type1"]) == 0
    assert not fuzzyctl.load(out).main.is_type2


def test_random_systems_round_trip_through_fcl_and_json() -> None:
    for seed in range(4):
        doc = m.Document((random_it2(seed, explicit=seed % 2 == 0, sugeno=seed == 3),))
        for fmt in ("fcl", "json"):
            text, losses = formats.convert(doc, fmt)
            assert not losses
            again = fuzzyctl.load(text, format=fmt).main
            a, b = Type2Controller(doc.main), Type2Controller(again)
            assert a.evaluate(x0=3.0, x1=6.0) == b.evaluate(x0=3.0, x1=6.0)


def test_type1_lowering_and_its_consumers_refuse(capsys: pytest.CaptureFixture[str]) -> None:
    from fuzzyctl.codegen.api import generate_st, lower_block
    from fuzzyctl.sim.runtimes import make_runtime
    from fuzzyctl.type2 import Type2NotSupported

    doc = fuzzyctl.load(EXAMPLE)
    with pytest.raises(Type2NotSupported, match="type-1 lowering"):
        lower_block(doc)
    assert "FUNCTION_BLOCK tipper_type2" in generate_st(doc)  # the type-2 generator
    for kind in ("siemens", "xfuz"):
        with pytest.raises(Type2NotSupported, match="interval type-2 system"):
            make_runtime(doc, kind)
    from fuzzyctl.engine.native import compiler

    if compiler() is not None:  # the native runtime runs the type-2 IR program in C
        native = make_runtime(doc, "native")
        got = native.evaluate({"service": 3.0, "food": 8.0})["tip"]
        assert got == fuzzyctl.compile(doc, backend="native").evaluate(service=3, food=8)["tip"]
    engine = make_runtime(doc, "engine")  # the loop runs on the type-2 engine
    assert engine.evaluate({"service": 3.0, "food": 8.0}) == fuzzyctl.compile(doc).evaluate(service=3, food=8)
    assert main(["analyze", EXAMPLE]) == 1
    assert "analysis (coverage, cells, surface) reads the type-1 plan" in capsys.readouterr().err.replace(
        "\n", " "
    )
