"""Converters keep the operator pair a rule block implies (issue 15.4).

IEC 61131-7 Table 3 pairs the operators: a block declaring only ``AND : PROD`` evaluates
its ORs with ASUM (the engine, docs/engine.md).  FIS and FLL have no such rule, FPL and XFUZ
have one AND only, so each writer must state the implied operator - or report a loss.  On
random systems drawing every declaration (AND only, OR only, both, neither; every operator;
AND, OR, NOT and parentheses in the rules) every writer either gives a model that computes
the same to 1e-9, or refuses with a loss naming what it cannot say.  The FLL and FIS exports
are also run through Debian's ``fuzzylite`` (an outside engine).
"""

from __future__ import annotations

import shutil
import subprocess
from pathlib import Path

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

import fuzzyctl
from fuzzyctl import model as m
from fuzzyctl.diagnostics import FuzzyctlError
from fuzzyctl.formats import LossError, convert, read_text

# (XFUZ computes on integer words and Discr points, never the same numbers as the engine:
# its operators are checked on the tables below)
WRITERS = ["fcl", "json", "fis", "fll", "fpl"]
AND_OPS = ["MIN", "PROD", "BDIF", "DMIN", "NIPMIN", "HAMACHER", "EINSTEIN"]
OR_OPS = [m.OPERATOR_PAIRS[a] for a in AND_OPS]

REPRODUCER = """FUNCTION_BLOCK repro
VAR_INPUT x1 : REAL; x2 : REAL; END_VAR
VAR_OUTPUT y : REAL; END_VAR
FUZZIFY x1 TERM a := (0, 0) (10, 1); END_FUZZIFY
FUZZIFY x2 TERM b := (0, 0) (10, 1); END_FUZZIFY
DEFUZZIFY y TERM s := 1; TERM t := 0; METHOD : COGS; DEFAULT := 0; END_DEFUZZIFY
RULEBLOCK r
    AND : PROD;
    RULE 1 : IF x1 IS a OR x2 IS b THEN y IS s;
    RULE 2 : IF x1 IS NOT a THEN y IS t;
END_RULEBLOCK
END_FUNCTION_BLOCK
"""


@pytest.mark.parametrize("fmt", ["fcl", "json", "fis", "fll"])
def test_the_issue_reproducer(fmt: str) -> None:
    """OR = ASUM(0.5, 0.5) = 0.75 fires s, NOT a = 0.5 fires t: (0.75 * 1 + 0.5 * 0) / 1.25."""
    doc = fuzzyctl.load(REPRODUCER)
    assert fuzzyctl.compile(doc).evaluate({"x1": 5, "x2": 5})["y"] == pytest.approx(0.6, abs=1e-12)
    text, losses = convert(doc, fmt)
    assert not losses
    again = read_text(text, fmt).document
    assert fuzzyctl.compile(again).evaluate({"x1": 5, "x2": 5})["y"] == pytest.approx(0.6, abs=1e-12)


# ------------------------------------------------------------------ random systems

TERMS = {
    "x1": (("lo", (0.0, 0.0, 6.0)), ("hi", (4.0, 10.0, 10.0))),
    "x2": (("lo", (0.0, 0.0, 5.0)), ("hi", (3.0, 10.0, 10.0))),
    "x3": (("lo", (0.0, 0.0, 7.0)), ("hi", (2.0, 10.0, 10.0))),
}


@st.composite
def conditions(draw: st.DrawFn, depth: int = 0) -> m.Condition:
    if depth >= 2 or draw(st.booleans()):
        var = draw(st.sampled_from(sorted(TERMS)))
        term = draw(st.sampled_from([t for t, _ in TERMS[var]]))
        return m.Is(var, term, negated=draw(st.booleans()) and draw(st.booleans()))
    kind = draw(st.sampled_from([m.And, m.Or, m.Not]))
    if kind is m.Not:
        return m.Not(draw(conditions(depth + 1)))
    return kind(tuple(draw(st.lists(conditions(depth + 1), min_size=2, max_size=3))))


@st.composite
def systems(draw: st.DrawFn) -> m.FunctionBlock:
    """One rule block: every way of declaring the operators, rules with AND/OR/NOT."""
    declared = draw(st.sampled_from(["and", "or", "both", "neither"]))
    and_op = draw(st.sampled_from(AND_OPS)) if declared in ("and", "both") else None
    or_op = draw(st.sampled_from(OR_OPS)) if declared in ("or", "both") else None
    if declared == "both" and draw(st.booleans()):
        or_op = m.OPERATOR_PAIRS[and_op]  # type: ignore[index]
    outs = (m.Term("s", m.SingletonMF(1.0)), m.Term("t", m.SingletonMF(0.0)), m.Term("u", m.SingletonMF(0.5)))
    rules = tuple(
        m.Rule(str(k + 1), draw(conditions()), (m.Conclusion("y", draw(st.sampled_from(["s", "t", "u"]))),))
        for k in range(draw(st.integers(1, 4)))
    )
    return m.FunctionBlock(
        "ops",
        variables=(*(m.Variable(v, m.VarKind.INPUT) for v in TERMS), m.Variable("y", m.VarKind.OUTPUT)),
        fuzzify=tuple(
            m.FuzzifyBlock(v, tuple(m.Term(t, m.ShapeMF("triangle", p)) for t, p in ts), m.Range(0.0, 10.0))
            for v, ts in TERMS.items()
        ),
        defuzzify=(m.DefuzzifyBlock("y", outs, m.Range(0.0, 1.0), "COGS", draw(st.sampled_from(DEFAULTS))),),
        rule_blocks=(m.RuleBlock("rb", rules, and_op, or_op, "MIN", "MAX"),),
    )


# a value, or NC (FPL has no DEFAULT: Fuzzy Control keeps the last value)
DEFAULTS = [m.Default(0.25), m.Default(None, no_change=True)]
ROWS = {name: list(np.random.default_rng(15).uniform(0.0, 10.0, 60)) for name in TERMS}


def _outputs(model: m.Document | m.FunctionBlock) -> np.ndarray:
    return fuzzyctl.compile(model).evaluate_batch(ROWS)["y"]


@pytest.mark.parametrize("fmt", WRITERS)
@settings(max_examples=25, deadline=None)
@given(fb=systems())
def test_every_writer_keeps_the_implied_operator_or_reports_a_loss(fmt: str, fb: m.FunctionBlock) -> None:
    doc = m.Document((fb,))
    try:
        text, _ = convert(doc, fmt)
    except LossError as exc:
        assert exc.losses  # refused, naming what it cannot say
        return
    except FuzzyctlError as exc:  # a writer's own refusal (FPL/XFUZ: diagnostics naming the element)
        assert str(exc)
        return
    again = read_text(text, fmt).document
    np.testing.assert_allclose(_outputs(again), _outputs(doc), rtol=0, atol=1e-9)


def test_fpl_writes_an_implied_min_and_refuses_an_implied_product() -> None:
    """FPL computes with MIN: a block declaring only ``OR : MAX`` (AND is MIN) is written and
    computes the same; only ``OR : ASUM`` (AND is PROD) is refused, naming the pair."""
    rules = (
        m.Rule("1", m.And((m.Is("x1", "hi"), m.Is("x2", "lo"))), (m.Conclusion("y", "s"),)),
        m.Rule("2", m.And((m.Is("x1", "lo"), m.Is("x3", "hi"))), (m.Conclusion("y", "t"),)),
    )
    fb = _fixed(rules, None, "MAX", DEFAULTS[1])
    text, _ = convert(m.Document((fb,)), "fpl")
    np.testing.assert_allclose(_outputs(read_text(text, "fpl").document), _outputs(fb), rtol=0, atol=1e-9)
    with pytest.raises(FuzzyctlError, match=r"AND : PROD \(the pair of OR : ASUM\)"):
        convert(m.Document((_fixed(rules, None, "ASUM", DEFAULTS[1]),)), "fpl")


@pytest.mark.parametrize(
    ("and_op", "or_op", "table_and"),
    [(None, None, "MIN"), ("MIN", None, "MIN"), ("PROD", None, "PROD"), (None, "MAX", "MIN"),
     (None, "ASUM", "PROD"), ("PROD", "ASUM", "PROD")],
)  # fmt: skip
def test_xfuz_states_the_implied_and(and_op: str | None, or_op: str | None, table_and: str) -> None:
    """XFUZ has one AND (MIN or PROD) and splits ORs into rules, exact only when OR is MAX:
    the implied AND is written, and an implied ASUM is reported, not split silently."""
    rules = (m.Rule("1", m.Or((m.Is("x1", "hi"), m.Is("x2", "lo"))), (m.Conclusion("y", "s"),)),)
    fb = _fixed(rules, and_op, or_op, m.Default(0.0))  # (XFUZ words are integers)
    text, losses = convert(m.Document((fb,)), "xfuz", lossy=True)
    again = read_text(text, "xfuz").document
    assert (again.main.rule_blocks[0].and_op or "MIN") == table_and
    or_lost = any("rule" in loss.element.lower() or "OR" in loss.reason for loss in losses)
    assert or_lost == (m.implied_operators(and_op, or_op)[1] != "MAX"), losses


# ------------------------------------------------------------------ fuzzylite, an outside engine

FUZZYLITE = shutil.which("fuzzylite")


@pytest.mark.parametrize("fmt", ["fll", "fis"])
def test_fuzzylite_runs_the_exports_as_the_engine_does(fmt: str, tmp_path: Path) -> None:
    """Every declaration with every pair, rules with AND, OR and NOT: fuzzylite (Debian's
    command) evaluates our export as our engine evaluates the model."""
    if FUZZYLITE is None:
        pytest.fail("the fuzzylite command is missing: `make test` installs the apt package fuzzylite")
    rules = (
        m.Rule("1", m.Or((m.Is("x1", "hi"), m.Is("x2", "hi"))), (m.Conclusion("y", "s"),)),
        m.Rule("2", m.And((m.Is("x1", "lo"), m.Is("x3", "hi"))), (m.Conclusion("y", "t"),)),
        m.Rule(
            "3", m.Or((m.Is("x2", "lo"), m.Is("x3", "lo"), m.Is("x1", "hi", True))), (m.Conclusion("y", "u"),)
        ),
    )
    rng = np.random.default_rng(4)
    data = rng.uniform(0.0, 10.0, (40, 3))
    for k, (and_op, or_op) in enumerate([(a, None) for a in AND_OPS] + [(None, o) for o in OR_OPS]):
        fb = _fixed(rules, and_op, or_op)
        text, _ = convert(m.Document((fb,)), fmt)
        path = tmp_path / f"s{k}.{fmt}"
        path.write_text(text)
        # fuzzylite 6 fires a rule only above 1e-6: its profile
        ctl = fuzzyctl.compile(fb, compat="fuzzylite")
        want = ctl.evaluate_batch({n: data[:, i] for i, n in enumerate(TERMS)})["y"]
        got = _fuzzylite(path, fmt, data, tmp_path)
        np.testing.assert_allclose(got, want, rtol=0, atol=1e-9, err_msg=f"{and_op} {or_op}")


def _fixed(
    rules: tuple[m.Rule, ...], and_op: str | None, or_op: str | None, default: m.Default = DEFAULTS[0]
) -> m.FunctionBlock:
    outs = (m.Term("s", m.SingletonMF(1.0)), m.Term("t", m.SingletonMF(0.0)), m.Term("u", m.SingletonMF(0.5)))
    return m.FunctionBlock(
        "ops",
        variables=(*(m.Variable(v, m.VarKind.INPUT) for v in TERMS), m.Variable("y", m.VarKind.OUTPUT)),
        fuzzify=tuple(
            m.FuzzifyBlock(v, tuple(m.Term(t, m.ShapeMF("triangle", p)) for t, p in ts), m.Range(0.0, 10.0))
            for v, ts in TERMS.items()
        ),
        defuzzify=(m.DefuzzifyBlock("y", outs, m.Range(0.0, 1.0), "COGS", default),),
        rule_blocks=(m.RuleBlock("rb", rules, and_op, or_op, "MIN", "MAX"),),
    )


def _fuzzylite(path: Path, fmt: str, data: np.ndarray, work: Path) -> np.ndarray:
    inputs = work / "in.fld"
    inputs.write_text(
        " ".join(TERMS) + "\n" + "\n".join(" ".join(repr(float(v)) for v in r) for r in data) + "\n"
    )
    out = work / "out.fld"
    subprocess.run(
        [FUZZYLITE or "fuzzylite", "-i", str(path), "-if", fmt, "-of", "fld", "-d", str(inputs),
         "-o", str(out), "-decimals", "12"],
        check=True, capture_output=True, timeout=60,
    )  # fmt: skip
    rows = [ln.split() for ln in out.read_text().splitlines()[1:] if ln.strip()]
    return np.array([float(r[-1]) for r in rows])
