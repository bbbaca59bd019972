"""Writing FCL from another format: names FCL cannot read back are renamed so that
write -> parse always works and the system evaluates the same."""

from __future__ import annotations

import numpy as np
import pytest

import fuzzyctl
from fuzzyctl import model as m
from fuzzyctl.fcl.identifiers import fcl_keywords
from fuzzyctl.formats import convert, read_text

# IEC 61131-7 Table 7 keywords and the dialect words fcl.lark adds; written out here so a
# broken keyword extraction cannot pass by testing an empty set.
IEC_WORDS = [
    "FUNCTION_BLOCK",
    "END_FUNCTION_BLOCK",
    "VAR_INPUT",
    "VAR_OUTPUT",
    "VAR",
    "END_VAR",
    "FUZZIFY",
    "END_FUZZIFY",
    "DEFUZZIFY",
    "END_DEFUZZIFY",
    "RULEBLOCK",
    "END_RULEBLOCK",
    "OPTION",
    "END_OPTION",
    "OPTIONS",
    "END_OPTIONS",
    "TERM",
    "RANGE",
    "METHOD",
    "DEFAULT",
    "NC",
    "ACCU",
    "ACT",
    "AND",
    "OR",
    "NOT",
    "RULE",
    "IF",
    "THEN",
    "IS",
    "WITH",
    "FUNCTION",
]

FIS = """[System]
Name='if-then system'
Type='mamdani'
Version=2.0
NumInputs=2
NumOutputs=1
NumRules=4
AndMethod='min'
OrMethod='max'
ImpMethod='prod'
AggMethod='max'
DefuzzMethod='centroid'

[Input1]
Name='if'
Range=[0 10]
NumMFs=2
MF1='rule':'trimf',[-10 0 10]
MF2='Then':'trimf',[0 10 20]

[Input2]
Name='Is'
Range=[0 10]
NumMFs=2
MF1='not':'gaussmf',[2 0]
MF2='with':'gaussmf',[2 10]

[Output1]
Name='RANGE'
Range=[0 30]
NumMFs=3
MF1='term':'trimf',[0 5 10]
MF2='inf':'trimf',[5 15 25]
MF3='end_var':'trapmf',[20 25 30 35]

[Rules]
1 1, 1 (1) : 1
1 2, 2 (0.5) : 1
2 -1, 3 (1) : 2
2 2, 2 (1) : 1
"""


def test_the_keyword_set_is_the_grammars() -> None:
    assert set(IEC_WORDS) <= fcl_keywords()
    # numbers the grammar reads where a name could stand
    assert {"NAN", "INF", "INFINITY"} <= fcl_keywords()
    # operator names and hedges are not keywords: they stay usable as names
    assert not {"MIN", "MAX", "VERY", "X"} & fcl_keywords()


def test_fis_with_keyword_names_converts_to_fcl_that_reads_back_the_same() -> None:
    source = read_text(FIS, "fis").document
    text, losses = convert(source, "fcl")
    assert not losses
    again = read_text(text, "fcl").document
    fb = again.main
    names = [v.name for v in fb.variables] + [t.name for b in (*fb.fuzzify, *fb.defuzzify) for t in b.terms]
    assert not [n for n in names if n.upper() in fcl_keywords()], names
    rng = np.random.default_rng(5)
    rows = {"if": list(rng.uniform(-1, 11, 400)), "Is": list(rng.uniform(-1, 11, 400))}
    want = fuzzyctl.compile(source).evaluate_batch(rows)["RANGE"]
    inputs = [v.name for v in fb.inputs]
    renamed = dict(zip(inputs, rows.values(), strict=True))
    got = fuzzyctl.compile(again).evaluate_batch(renamed)[fb.outputs[0].name]
    assert np.allclose(want, got, rtol=0.0, atol=1e-9, equal_nan=True)
    # a real output, not all defaults: every output term fires somewhere on the grid
    assert np.ptp(np.asarray(want)) > 5


def _keyword_block(word: str) -> m.FunctionBlock:
    """A variable and a term both called ``word``, plus a term ``word word`` (several words)."""
    tri = m.ShapeMF("triangle", (0.0, 5.0, 10.0))
    return m.FunctionBlock(
        word,
        variables=(m.Variable(word, m.VarKind.INPUT), m.Variable("y", m.VarKind.OUTPUT)),
        fuzzify=(m.FuzzifyBlock(word, (m.Term(word, tri), m.Term(f"{word} {word}", tri)), m.Range(0, 10)),),
        defuzzify=(
            m.DefuzzifyBlock(
                "y",
                (m.Term(word, m.SingletonMF(2.0)), m.Term("b", m.SingletonMF(8.0))),
                m.Range(0, 10),
                "COGS",
            ),
        ),
        rule_blocks=(
            m.RuleBlock(
                word,
                (
                    m.Rule("1", m.Is(word, word), (m.Conclusion("y", word),)),
                    m.Rule("2", m.Is(word, f"{word} {word}", negated=True), (m.Conclusion("y", "b"),)),
                ),
                "MIN",
                None,
                "MIN",
                "MAX",
            ),
        ),
    )


@pytest.mark.parametrize("word", sorted({*IEC_WORDS, *fcl_keywords()}))
def test_every_keyword_as_a_name_survives_write_then_parse(word: str) -> None:
    for spelling in (word.lower(), word.title()):
        fb = _keyword_block(spelling)
        text, losses = convert(m.Document((fb,)), "fcl")
        assert not losses
        loaded = read_text(text, "fcl")
        again = loaded.document.main
        assert [v.kind for v in again.variables] == [m.VarKind.INPUT, m.VarKind.OUTPUT]
        xs = [0.5, 2.5, 5.0, 7.5, 9.5]
        want = fuzzyctl.compile(fb).evaluate_batch({spelling: xs})["y"]
        got = fuzzyctl.compile(again).evaluate_batch({again.inputs[0].name: xs})["y"]
        assert np.allclose(want, got, rtol=0.0, atol=1e-12), (spelling, text)


def test_names_fcl_reads_are_kept() -> None:
    fb = _keyword_block("Température")
    text, _ = convert(m.Document((fb,)), "fcl")
    again = read_text(text, "fcl").document.main
    assert [v.name for v in again.variables] == ["Température", "y"]
    assert [t.name for t in again.fuzzify[0].terms] == ["Température", "Température Température"]


def test_variable_references_follow_a_renamed_variable() -> None:
    """A FUNCTION term and a WITH weight that name a renamed variable name the new one."""
    fb = _keyword_block("then")
    out = fb.defuzzify[0]
    fb = m.FunctionBlock(
        fb.name,
        variables=(*fb.variables, m.Variable("or", m.VarKind.INPUT)),
        fuzzify=(*fb.fuzzify, m.FuzzifyBlock("or", (m.Term("t", m.ShapeMF("triangle", (0.0, 5.0, 10.0))),))),
        defuzzify=(
            m.DefuzzifyBlock(
                "y",
                (*out.terms, m.Term("f", m.FunctionMF(m.Binary("*", m.Name("then"), m.Num(2.0))))),
                out.range,
                "WTSUM",
            ),
        ),
        rule_blocks=(
            m.RuleBlock(
                "rb",
                (m.Rule("1", m.Is("or", "t"), (m.Conclusion("y", "f", m.Ref("then")),)),),
                "MIN",
                None,
                "MIN",
                None,
            ),
        ),
    )
    text, losses = convert(m.Document((fb,)), "fcl")
    assert not losses
    again = read_text(text, "fcl").document.main
    new = {v.name for v in again.variables} - {"y"}
    assert not {n.upper() for n in new} & fcl_keywords()
    term = again.defuzzify[0].terms[-1].mf
    assert isinstance(term, m.FunctionMF)
    assert isinstance(term.expr, m.Binary) and isinstance(term.expr.left, m.Name)
    assert term.expr.left.name in new
    weight = again.rule_blocks[0].rules[0].conclusions[0].weight
    assert isinstance(weight, m.Ref) and weight.name in new


def test_octave_power_hedges_become_very_and_somewhat_or_a_loss() -> None:
    """Octave's hedge codes raise a degree to a power (``2.4``: term 2, d^4): FCL says d^4 as
    ``very very`` (d^2 twice) and has no word for d^3."""
    rules = "1 1, 1 (1) : 1\n2.4 -2, 2 (1) : 1\n1 2, 3 (1) : 2\n"
    source = read_text(
        FIS.replace("NumRules=4", "NumRules=3").split("[Rules]")[0] + "[Rules]\n" + rules, "fis"
    )
    text, losses = convert(source.document, "fcl")
    assert not losses and "IS very very Then" in text
    again = read_text(text, "fcl").document
    rng = np.random.default_rng(9)
    xs, ys = list(rng.uniform(0, 10, 300)), list(rng.uniform(0, 10, 300))
    want = fuzzyctl.compile(source.document).evaluate_batch({"if": xs, "Is": ys})["RANGE"]
    names = [v.name for v in again.main.inputs]
    got = fuzzyctl.compile(again).evaluate_batch(dict(zip(names, (xs, ys), strict=True)))
    assert np.allclose(want, got[again.main.outputs[0].name], rtol=0.0, atol=1e-9, equal_nan=True)
    cubed = read_text(FIS.replace("2 2, 2 (1) : 1", "2.3 2, 2 (1) : 1"), "fis").document
    _text, losses = convert(cubed, "fcl", lossy=True)
    assert [loss.reason for loss in losses] == ["FCL has no hedge for pow:3; dropped"]
