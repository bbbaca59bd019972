"""The FIS reader against MATLAB's definitions, and the FIS writer's round trip."""

from __future__ import annotations

import math
import re
from pathlib import Path

import numpy as np
import pytest

import fuzzyctl
from fuzzyctl import formats
from fuzzyctl.diagnostics import DiagnosticError
from fuzzyctl.formats import get
from fuzzyctl.formats.common.basics import unique_name
from fuzzyctl.formats.fis import reader as fis
from fuzzyctl.model import And, Conclusion, Is, Or, PointsMF, ShapeMF
from tests.conftest import DATA, EXAMPLES

HEADER = """[System]
Name='t'
Type='{type}'
Version=2.0
NumInputs=2
NumOutputs=1
NumRules={nrules}
AndMethod='min'
OrMethod='max'
ImpMethod='min'
AggMethod='max'
DefuzzMethod='{defuzz}'

[Input1]
Name='a'
Range=[0 10]
NumMFs=2
MF1='lo':'gaussmf',[1.5 0]
MF2='hi':'gbellmf',[2 4 10]

[Input2]
Name='b'
Range=[0 10]
NumMFs=2
MF1='lo':'sigmf',[-3 5]
MF2='hi':'dsigmf',[5 2 5 7]

[Output1]
Name='y'
Range=[0 30]
NumMFs=2
MF1='small':'trimf',[0 5 10]
MF2='big':'trapmf',[10 20 25 30]

[Rules]
"""


def doc(rules: str, *, type: str = "mamdani", defuzz: str = "centroid", nrules: int | None = None):
    count = nrules if nrules is not None else len([r for r in rules.splitlines() if r.strip()])
    return fis.read(HEADER.format(type=type, defuzz=defuzz, nrules=count) + rules, "t.fis")


def test_matlab_parameter_orders_map_onto_model_shapes() -> None:
    fb = doc("1 1, 1 (1) : 1\n").document.main
    a, b = fb.fuzzify
    # gaussmf [sigma c] -> gaussian(mean=c, sigma); gbellmf [a b c] -> bell(center=c, width=a, slope=b)
    assert a.terms[0].mf == ShapeMF("gaussian", (0.0, 1.5))
    assert a.terms[1].mf == ShapeMF("bell", (10.0, 2.0, 4.0))
    # sigmf [a c] -> sigmoid(center=c, slope=a); dsigmf [a1 c1 a2 c2] -> |s1 - s2| (MATLAB mf.c)
    assert b.terms[0].mf == ShapeMF("sigmoid", (5.0, -3.0))
    assert b.terms[1].mf == ShapeMF("dsigmoid", (2.0, 5.0, 7.0, 5.0))
    assert fb.defuzzify[0].terms[1].mf == ShapeMF("trapezoid", (10.0, 20.0, 25.0, 30.0))


def test_rule_codes_weights_not_dont_care_and_connection() -> None:
    rules = "1 -2, 2 (0.5) : 1\n0 1, 1 (1) : 2\n2.000 1.000 , 1.000 (1.000) : 2\n"
    fb = doc(rules).document.main
    r1, r2, r3 = fb.rule_blocks[0].rules
    assert r1.condition == And((Is("a", "lo"), Is("b", "hi", negated=True)))
    assert r1.weight == 0.5 and r1.conclusions == (Conclusion("y", "big"),)
    assert r2.condition == Is("b", "lo") and r2.weight is None  # 0 = don't care
    assert r3.condition == Or((Is("a", "hi"), Is("b", "lo")))


def test_comments_and_mismatched_numrules_warn() -> None:
    rules = "# a comment\n1 1, 1 (1) : 1 % trailing\n"
    loaded = doc(rules, nrules=5)
    assert len(loaded.document.main.rule_blocks[0].rules) == 1
    warning = next(d for d in loaded.diagnostics if d.code == "fis-count")
    assert "NumRules=5" in warning.message and warning.span is not None and warning.span.line == 1


def test_empty_antecedent_and_output_default_follow_matlab() -> None:
    loaded = doc("0 0, 1 (1) : 1\n")
    rule = loaded.document.main.rule_blocks[0].rules[0]
    assert rule.condition is None  # AND of don't-cares: degree 1 in MATLAB's fiscore.c
    assert any(d.code == "fis-empty-rule" for d in loaded.diagnostics)
    default = loaded.document.main.defuzzify[0].default
    assert default is not None and default.value == 15.0  # "set to its mean range value"


def test_octave_hedges_and_fuzzylite_dialect() -> None:
    fb = doc("1.2 -2.3, 1 (1) : 1\n").document.main
    a, b = fb.rule_blocks[0].rules[0].condition.operands  # type: ignore[union-attr]
    assert a.hedges == ("very",) and b.hedges == ("pow:3",) and b.negated
    text = (
        "# generated with fuzzylite\n"
        + HEADER.format(type="mamdani", defuzz="centroid", nrules=1)
        + "1.3 0.99, 1 (1) : 1\n"
    )
    rule = fis.read(text).document.main.rule_blocks[0].rules[0]
    assert rule.condition == Is(
        "a", "lo", hedges=("extremely",)
    )  # ".99" is fuzzylite's "any": dropped from AND
    assert math.isnan(fis.read(text).document.main.defuzzify[0].default.value)  # type: ignore[union-attr]


def test_errors_name_line_and_problem() -> None:
    with pytest.raises(DiagnosticError) as err:
        doc("1 3, 1 (1) : 1\n")
    d = err.value.diagnostics[0]
    rule_line = HEADER.count("\n") + 1
    assert d.code == "fis-rule-index" and d.span is not None and d.span.line == rule_line
    assert "MF3 of 'b'" in d.message
    bad = HEADER.replace("[0 5 10]", "[0 5 1x0]").format(type="mamdani", defuzz="centroid", nrules=0)
    with pytest.raises(DiagnosticError) as err2:
        fis.read(bad)
    mf_line = HEADER.splitlines().index("MF1='small':'trimf',[0 5 10]") + 1
    assert err2.value.diagnostics[0].span.line == mf_line  # type: ignore[union-attr]
    assert "1x0" in err2.value.diagnostics[0].message


def test_sugeno_linear_needs_one_coefficient_per_input_and_a_constant() -> None:
    text = HEADER.replace("MF1='small':'trimf',[0 5 10]", "MF1='small':'linear',[1 2 3]").replace(
        "MF2='big':'trapmf',[10 20 25 30]", "MF2='big':'constant',[7]"
    )
    fb = fis.read(text.format(type="sugeno", defuzz="wtaver", nrules=1) + "1 1, 1 (1) : 1\n").document.main
    out = fb.defuzzify[0]
    assert out.method == "WTAVER" and out.terms[0].mf == ShapeMF("linear", (1.0, 2.0, 3.0))
    with pytest.raises(DiagnosticError, match="needs 3 parameters"):
        fis.read(text.replace("[1 2 3]", "[1 2 3 4]").format(type="sugeno", defuzz="wtaver", nrules=0))


def test_duplicate_term_names_stay_reachable_by_index() -> None:
    text = HEADER.replace("MF2='big'", "MF2='small'").format(type="mamdani", defuzz="centroid", nrules=2)
    loaded = fis.read(text + "1 1, 1 (1) : 1\n2 2, 2 (1) : 1\n")
    out = loaded.document.main.defuzzify[0]
    assert [t.name for t in out.terms] == ["small", "small_2"]
    assert loaded.document.main.rule_blocks[0].rules[1].conclusions[0].term == "small_2"
    assert any(d.code == "duplicate-term" for d in loaded.diagnostics)


def test_many_terms_of_one_name_are_numbered_as_unique_name_numbers_them() -> None:
    # t, t, t_3 (written), t, t: the renaming skips the written t_3, as _common.unique_name does
    names = ["t", "t", "t_3", "t", "t"]
    mfs = "".join(f"MF{i}='{n}':'trimf',[0 5 10]\n" for i, n in enumerate(names, start=1))
    text = HEADER.replace("MF1='small':'trimf',[0 5 10]\nMF2='big':'trapmf',[10 20 25 30]\n", mfs)
    loaded = fis.read(
        text.replace("NumMFs=2\n" + mfs, f"NumMFs=5\n{mfs}").format(
            type="mamdani", defuzz="centroid", nrules=1
        )
        + "1 1, 5 (1) : 1\n"
    )
    out = loaded.document.main.defuzzify[0]
    taken: set[str] = set()
    assert (
        [t.name for t in out.terms]
        == [unique_name(n, taken) for n in names]
        == ["t", "t_2", "t_3", "t_4", "t_5"]
    )
    assert loaded.document.main.rule_blocks[0].rules[0].conclusions[0].term == "t_5"


@pytest.mark.parametrize(
    ("old", "new", "code", "words"),
    [
        # numbers Python will not convert (over 4300 digits) in a section header and an MF key
        ("[Input1]", "[Input" + "0" * 5000 + "1]", None, None),
        ("MF2='hi'", "MF" + "0" * 5000 + "3='hi'", "fis-mf-number", "membership function number 2"),
        ("MF2='hi'", "MF" + "7" * 5000 + "='hi'", "fis-mf-number", "membership function number 2"),
        # MATLAB's value of (-8)^0.5 is complex
        ("[1.5 0]", "[1.5 (-8)^0.5]", "fis-number", "not a real number"),
        ("NumMFs=2\nMF1='lo'", "Enabled=x\nNumMFs=2\nMF1='lo'", "fis-number", "Enabled must be 0 or 1"),
    ],
)
def test_hostile_numbers_get_a_diagnostic_not_a_traceback(
    old: str, new: str, code: str | None, words: str
) -> None:
    text = (
        HEADER.replace(old, new, 1).format(type="mamdani", defuzz="centroid", nrules=1) + "1 1, 1 (1) : 1\n"
    )
    if code is None:  # read as Input1
        assert [v.name for v in fis.read(text, "t.fis").document.main.variables] == ["a", "b", "y"]
        return
    place = next(i for i, line in enumerate(text.splitlines(), start=1) if new.splitlines()[0][:12] in line)
    try:
        found = list(fis.read(text, "t.fis").diagnostics)
    except DiagnosticError as exc:
        found = exc.diagnostics
    d = next(d for d in found if d.code == code)
    assert words in d.message and d.span is not None and d.span.line == place


def test_an_expression_nested_a_million_deep_is_refused_with_its_place() -> None:
    deep = "(" * 1_000_000 + "0" + ")" * 1_000_000
    text = HEADER.replace("[1.5 0]", f"[1.5 {deep}]").format(type="mamdani", defuzz="centroid", nrules=0)
    with pytest.raises(DiagnosticError) as err:
        fis.read(text, "t.fis")
    d = err.value.diagnostics[0]
    assert d.code == "fis-number" and "nests more than" in d.message and "2000001 characters" in d.message
    assert d.span is not None and d.span.line == HEADER.splitlines().index("MF1='lo':'gaussmf',[1.5 0]") + 1


def test_written_fis_reads_back_equal() -> None:
    original = doc("1 -2, 2 (0.5) : 1\n0 1, 1 (1) : 2\n1.2 2, 1 (1) : 1\n").document
    fmt = get("fis")
    adapted, losses = fmt.adapt(original)
    assert losses == []
    again = fis.read(fmt.write(adapted)).document
    assert again.main == original.main


def test_points_become_trimf_or_discretemf() -> None:
    from fuzzyctl.formats.fis.writer import _mf_text
    from fuzzyctl.model import Point, Term

    tri = Term("t", PointsMF((Point(0.0, 0.0), Point(1.0, 1.0), Point(3.0, 0.0))))
    odd = Term("o", PointsMF((Point(0.0, 0.2), Point(1.0, 1.0), Point(3.0, 0.0))))
    assert _mf_text(tri) == "'t':'trimf',[0 1 3]"
    assert _mf_text(odd) == "'o':'discretemf',[0 0.2 1 1 3 0]"


@pytest.mark.parametrize(
    "source",
    [*sorted((DATA / "fuzzylite").rglob("*.fis")), EXAMPLES / "tipper.fis"],
    ids=lambda p: p.name,
)
def test_fis_to_fcl_uses_basic_level_forms(source: Path) -> None:
    """Triangles and trapezoids become IEC point lists and ranges move into FUZZIFY/DEFUZZIFY
    (not jFuzzyLogic's declaration-line RANGE); the FCL computes what the FIS computes."""
    from fuzzyctl.formats import convert, read_text

    document = formats.read_path(source).document
    try:
        text, losses = convert(document, "fcl")
    except formats.LossError as exc:  # FCL cannot say it: reported, element by element
        assert exc.losses
        text, losses = convert(document, "fcl", lossy=True)
        assert not re.search(r"\b(TRIAN|TRAPE)\b", text)
        return
    assert not losses
    assert not re.search(r"\b(TRIAN|TRAPE|TRIANGLE|TRAPEZOID)\b", text), text
    assert not re.search(r":\s*REAL\s*;\s*RANGE", text), "RANGE on a declaration line is Open level"
    back = read_text(text, "fcl").document
    a, b = fuzzyctl.compile(document), fuzzyctl.compile(back)
    rng = np.random.default_rng(5)
    data = {}
    for name in a.inputs:
        info = a.inputs[name]
        low, high = info.range or (0.0, 1.0)
        data[name] = rng.uniform(low - 0.1 * (high - low), high + 0.1 * (high - low), 60)
    # FCL may rename what it cannot read (LDL-Level -> LDL_Level): match by position
    renamed = {new: data[old] for old, new in zip(a.inputs, b.inputs, strict=True)}
    got = b.evaluate_batch(renamed)
    for (name, want), other in zip(a.evaluate_batch(data).items(), b.outputs, strict=True):
        assert np.allclose(got[other], want, rtol=0, atol=1e-9, equal_nan=True), name
