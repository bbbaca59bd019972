"""What the FIS and FLL writers must say so that a system computes the same after the trip:
defaults (no DEFAULT is NC), nested conditions, input singletons, weighted averages that
accumulate, Octave consequent hedges, fuzzylite's running conclusion hedges and hybrid FIS
aggregation.  Each check evaluates the model before and after with the engine."""

from __future__ import annotations

import math

import numpy as np
import pytest

import fuzzyctl
from fuzzyctl import model as m
from fuzzyctl.formats import get, read_text

T = m.ShapeMF


def _block(
    rules: tuple[m.Rule, ...],
    *,
    out_terms: tuple[m.Term, ...] | None = None,
    method: str = "COG",
    default: m.Default | None = None,
    and_op: str | None = "MIN",
    accu: str | None = "MAX",
    inputs: tuple[m.FuzzifyBlock, ...] | None = None,
) -> m.FunctionBlock:
    fuzz = inputs or (
        m.FuzzifyBlock(
            "a",
            (m.Term("lo", T("triangle", (0.0, 0.0, 6.0))), m.Term("hi", T("triangle", (4.0, 10.0, 10.0)))),
            m.Range(0.0, 10.0),
        ),
        m.FuzzifyBlock(
            "b",
            (
                m.Term("lo", T("trapezoid", (0.0, 0.0, 3.0, 7.0))),
                m.Term("hi", T("triangle", (3.0, 10.0, 10.0))),
            ),
            m.Range(0.0, 10.0),
        ),
    )
    terms = out_terms or (
        m.Term("small", T("triangle", (0.0, 5.0, 10.0))),
        m.Term("big", T("triangle", (5.0, 10.0, 15.0))),
    )
    return m.FunctionBlock(
        "w",
        variables=(
            *(m.Variable(f.variable, m.VarKind.INPUT) for f in fuzz),
            m.Variable("y", m.VarKind.OUTPUT),
        ),
        fuzzify=fuzz,
        defuzzify=(m.DefuzzifyBlock("y", terms, m.Range(0.0, 15.0), method, default),),
        rule_blocks=(m.RuleBlock("rb", rules, and_op, None, "MIN", accu),),
    )


def _through(fb: m.FunctionBlock, fmt: str) -> tuple[m.Document, str]:
    adapted, losses = get(fmt).adapt(m.Document((fb,)))
    assert not losses, losses
    text = get(fmt).write(adapted)
    return read_text(text, fmt).document, text


def _same(fb: m.FunctionBlock, again: m.Document, rows: dict[str, list[float]]) -> None:
    want = fuzzyctl.compile(fb).evaluate_batch(rows)["y"]
    got = fuzzyctl.compile(again).evaluate_batch(rows)["y"]
    assert np.allclose(want, got, rtol=0.0, atol=1e-9, equal_nan=True), (want, got)


def _grid() -> dict[str, list[float]]:
    xs = np.linspace(-1.0, 11.0, 25)
    a, b = np.meshgrid(xs, xs)
    return {"a": list(a.ravel()), "b": list(b.ravel())}


@pytest.mark.parametrize("fmt", ["fis", "fll"])
def test_no_default_keeps_the_previous_output_in_both_targets(fmt: str) -> None:
    """No DEFAULT: NC, 0 before the first firing (docs/engine.md); written Default=0 with
    LockPrevious / lock-previous, never a plain 0 or MATLAB's middle of the range."""
    fb = _block((m.Rule("1", m.Is("a", "hi"), (m.Conclusion("y", "big"),)),))
    again, text = _through(fb, fmt)
    assert ("LockPrevious=1" in text) if fmt == "fis" else ("lock-previous: true" in text)
    rows = {"a": [0.0, 8.0, 0.0, 2.0], "b": [0.0] * 4}  # nothing fires at a = 0
    got = fuzzyctl.compile(again).evaluate_batch(rows)["y"]
    assert got[0] == 0.0 and got[2] == got[1] == got[3] and got[1] > 5.0
    _same(fb, again, rows)


def test_matlab_default_is_the_middle_of_the_range_and_stays_matlab() -> None:
    fb = _block((m.Rule("1", m.Is("a", "hi"), (m.Conclusion("y", "big"),)),), default=m.Default(7.5))
    again, text = _through(fb, "fis")
    assert not text.startswith("%") and "Default" not in text  # plain MATLAB FIS
    assert fuzzyctl.compile(again).evaluate({"a": 0.0, "b": 0.0})["y"] == 7.5


def test_mixed_and_or_under_min_max_becomes_one_rule_per_disjunct() -> None:
    cond = m.And((m.Or((m.Is("a", "lo"), m.Is("a", "hi", negated=True))), m.Is("b", "hi")))
    fb = _block((m.Rule("1", cond, (m.Conclusion("y", "small"),), weight=0.7),))
    again, _text = _through(fb, "fis")
    # (a lo AND b hi) OR (a not hi AND b hi): two rules, each an AND
    assert [type(r.condition) for r in again.main.rule_blocks[0].rules] == [m.And, m.And]
    _same(fb, again, _grid())


def test_mixed_and_or_under_prod_is_a_loss() -> None:
    cond = m.And((m.Or((m.Is("a", "lo"), m.Is("b", "hi"))), m.Is("a", "hi")))
    fb = _block((m.Rule("1", cond, (m.Conclusion("y", "small"),)),), and_op="PROD")
    _adapted, losses = get("fis").adapt(m.Document((fb,)))
    assert any("one AND or OR" in loss.reason for loss in losses)


def test_input_singleton_is_a_zero_width_triangle() -> None:
    inputs = (
        m.FuzzifyBlock("a", (m.Term("five", m.SingletonMF(5.0)), m.Term("hi", T("ramp", (0.0, 10.0))))),
    )
    rules = (
        m.Rule("1", m.Is("a", "five"), (m.Conclusion("y", "big"),)),
        m.Rule("2", m.Is("a", "hi"), (m.Conclusion("y", "small"),)),
    )
    fb = _block(rules, inputs=inputs, default=m.Default(1.0))
    for fmt in ("fis", "fll"):
        again, text = _through(fb, fmt)
        assert ("trimf',[5 5 5]" in text) if fmt == "fis" else ("Triangle 5 5 5" in text)
        _same(fb, again, {"a": [5.0, 4.999, 5.001, 7.0]})


def test_weighted_average_accumulating_with_max() -> None:
    """CoGS over singletons accumulates each term with MAX (IEC); a Sugeno FIS lets every rule
    count, so two rules on one term are a loss there, while FLL says it as aggregation."""
    terms = (m.Term("small", m.SingletonMF(2.0)), m.Term("big", m.SingletonMF(12.0)))
    rules = (
        m.Rule("1", m.Is("a", "hi"), (m.Conclusion("y", "big"),)),
        m.Rule("2", m.Is("b", "hi"), (m.Conclusion("y", "big"),)),
        m.Rule("3", m.Is("a", "lo"), (m.Conclusion("y", "small"),)),
    )
    fb = _block(rules, out_terms=terms, method="COGS", default=m.Default(0.0), accu=None)
    _adapted, losses = get("fis").adapt(m.Document((fb,)))
    assert any("accumulate with MAX" in loss.reason for loss in losses)
    again, text = _through(fb, "fll")
    assert "aggregation: Maximum" in text
    _same(fb, again, _grid())


def test_octave_consequent_hedge_is_written_as_octave_reads_it() -> None:
    """Octave raises a Sugeno rule's degree to 1/p for the code .p: degree^(1/3) is .30."""
    terms = (m.Term("c", T("constant", (10.0,))), m.Term("d", T("constant", (0.0,))))
    rules = (
        m.Rule(
            "1", m.Is("a", "hi", hedges=("pow:3",)), (m.Conclusion("y", "c", hedges=("pow:0.333333333333",)),)
        ),
        m.Rule("2", m.Is("a", "lo"), (m.Conclusion("y", "d"),)),
    )
    fb = _block(rules, out_terms=terms, method="WTAVER", default=m.Default(7.5), accu=None)
    adapted, losses = get("fis").adapt(m.Document((fb,)))
    assert not losses
    text = get("fis").write(adapted)
    assert not text.startswith("%") and "2.30, 1.30" in text.replace(" 0,", ",")
    again = read_text(text, "fis").document
    assert again.main.rule_blocks[0].rules[0].conclusions[0].hedges == ("pow:0.3333333333333333",)
    rows = _grid()
    want = fuzzyctl.compile(fb).evaluate_batch(rows)["y"]
    assert np.allclose(want, fuzzyctl.compile(again).evaluate_batch(rows)["y"], rtol=0.0, atol=1e-9)


def test_fuzzylite_fis_conclusions_without_hedges_get_the_running_ones() -> None:
    text = """% fuzzylite
[System]
Name='h'
Type='sugeno'
NumInputs=1
NumOutputs=2
NumRules=1
AndMethod='min'
OrMethod='max'
ImpMethod='min'
AggMethod='max'
DefuzzMethod='wtaver'

[Input1]
Name='a'
Range=[0 1]
NumMFs=1
MF1='hi':'rampmf',[0 1]

[Output1]
Name='y'
Range=[0 1]
NumMFs=1
MF1='c':'constant',[1]

[Output2]
Name='z'
Range=[0 1]
NumMFs=1
MF1='c':'constant',[1]

[Rules]
1, 1.20 1 (1) : 1
"""
    rule = read_text(text, "fis").document.main.rule_blocks[0].rules[0]
    assert [c.hedges for c in rule.conclusions] == [("very",), ("very",)]


def test_hybrid_fis_aggregation_belongs_to_the_mamdani_outputs() -> None:
    text = """% fuzzylite
[System]
Name='h'
Type='hybrid'
NumInputs=1
NumOutputs=2
NumRules=2
AndMethod='min'
OrMethod='max'
ImpMethod='min'
AggMethod='max'
DefuzzMethod='centroid'

[Input1]
Name='a'
Range=[0 1]
NumMFs=2
MF1='hi':'rampmf',[0 1]
MF2='lo':'rampmf',[1 0]

[Output1]
Name='m'
Range=[0 1]
NumMFs=1
MF1='t':'trimf',[0 0.5 1]

[Output2]
Name='s'
Range=[0 10]
NumMFs=2
MF1='c':'constant',[10]
MF2='d':'constant',[0]

[Rules]
1, 1 1 (1) : 1
1, 1 1 (1) : 1
"""
    fb = read_text(text, "fis").document.main
    assert fb.rule_blocks[0].accu is None
    assert fb.defuzzify_block("m").accu == "MAX" and fb.defuzzify_block("s").accu is None
    # the Sugeno output weighs every rule: both rules count, 10 either way
    assert fuzzyctl.compile(fb).evaluate({"a": 0.4})["s"] == 10.0
    assert math.isfinite(fuzzyctl.compile(fb).evaluate({"a": 0.4})["m"])


def _fis_losses(fb: m.FunctionBlock) -> list[str]:
    adapted, losses = get("fis").adapt(m.Document((fb,)))
    if losses:  # what is written without them must still read back
        read_text(get("fis").write(adapted), "fis")
    return [f"{loss.element}: {loss.reason}" for loss in losses]


def test_fis_never_writes_a_shape_its_reader_refuses() -> None:
    """A trapezoid out of order (the FCL reader takes it, MATLAB's trapmf does not) and a
    zero-width Gaussian are losses, not files the FIS reader rejects."""
    bad = (
        m.FuzzifyBlock(
            "a",
            (m.Term("lo", T("trapezoid", (1.0, 0.0, 2.0, 3.0))), m.Term("hi", T("gaussian", (5.0, 0.0)))),
            m.Range(0.0, 10.0),
        ),
    )
    fb = _block((m.Rule("1", m.Is("a", "lo"), (m.Conclusion("y", "big"),)),), inputs=bad)
    losses = _fis_losses(fb)
    assert any("'lo' of 'a'" in x and "a <= b <= c <= d" in x for x in losses), losses
    assert any("'hi' of 'a'" in x and "sigma must not be 0" in x for x in losses), losses


def test_fis_weighted_average_output_of_fuzzy_sets_is_a_loss() -> None:
    """COGS over point-list terms (jfuzzyqt's Tsukamoto file): a Sugeno FIS output holds
    constants, linear functions or fuzzylite's monotonic shapes only."""
    terms = (
        m.Term("up", m.PointsMF((m.Point(0.0, 0.0), m.Point(5.0, 0.4), m.Point(10.0, 1.0)))),
        m.Term("down", m.PointsMF((m.Point(0.0, 1.0), m.Point(5.0, 0.6), m.Point(10.0, 0.0)))),
    )
    fb = _block((m.Rule("1", m.Is("a", "lo"), (m.Conclusion("y", "up"),)),), out_terms=terms, method="COGS")
    losses = _fis_losses(fb)
    assert any("'up' of 'y'" in x and "weighted-average output" in x for x in losses), losses


def test_tsukamoto_sigmoids_are_written_in_the_fuzzylite_dialect() -> None:
    """sigmf is a MATLAB type, but a Sugeno output of sigmoids only reads back as fuzzylite's
    Tsukamoto: the writer must say so (the dialect comment), or the reader refuses it."""
    terms = (m.Term("up", T("sigmoid", (5.0, 2.0))), m.Term("down", T("sigmoid", (5.0, -2.0))))
    rules = (
        m.Rule("1", m.Is("a", "lo"), (m.Conclusion("y", "up"),)),
        m.Rule("2", m.Is("a", "hi"), (m.Conclusion("y", "down"),)),
    )
    fb = _block(rules, out_terms=terms, method="WTAVER", accu=None)
    again, text = _through(fb, "fis")
    assert text.startswith("%")
    _same(fb, again, _grid())
