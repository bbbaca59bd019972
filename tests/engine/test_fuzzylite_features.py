"""What the MATLAB / fuzzylite readers put in the model, evaluated by the engine: rule weights
(``Rule.weight``), lock-range on inputs and outputs (``clamp``), disabled rule blocks, rule
activation methods (``RuleBlock.rule_activation``), defaults with lock-previous, and
``FunctionMF.argument``.

Random systems are built twice from the same draws - as a model in Python and as FLL text
that pyfuzzylite 8 parses itself (in its own venv: tests/peers) - and evaluated on the same
input sequence (the state of lock-previous carries from one sample to the next).
Takagi-Sugeno outputs agree to 1e-9, Mamdani centroids within pyfuzzylite's resolution
(2e5 divisions: 1e-5 of the range).  The same systems check that the interpreter, the
specialised scalar path and the numpy batch path agree to 1e-9.
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

import fuzzyctl
from fuzzyctl import model as m
from fuzzyctl.diagnostics import DiagnosticError, InputError
from fuzzyctl.engine.support import unsupported
from tests import peers
from tests.engine.randsys import sorted_floats

RES = 200_000
LO, HI = 0.0, 10.0
IN_RANGE = (1.0, 9.0)  # inputs are drawn in [-1, 11]: lock-range matters
ACTIVATIONS = [
    None,
    "First 2",
    "First 1 0.3",
    "Last 1",
    "Last 2 0.2",
    "Highest 1",
    "Highest 2",
    "Lowest 1",
    "Lowest 2",
    "Proportional",
    "Threshold >= 0.4",
    "Threshold < 0.6",
]
TNORM = {"MIN": "Minimum", "PROD": "AlgebraicProduct"}
SNORM = {"MAX": "Maximum", "ASUM": "AlgebraicSum"}


def _num(x: float) -> str:
    return "nan" if math.isnan(x) else repr(float(x))


@st.composite
def fuzzy_set(draw: Any, output: bool) -> tuple[m.MembershipFunction, str]:
    kind = draw(st.sampled_from(["triangle", "trapezoid"] + ([] if output else ["gaussian"])))
    if kind == "triangle":
        a, b, c = draw(sorted_floats(3).filter(lambda v: v[0] < v[1] < v[2]))
        return m.ShapeMF(kind, (a, b, c)), f"Triangle {a} {b} {c}"
    if kind == "trapezoid":
        a, b, c, d = draw(sorted_floats(4).filter(lambda v: v[0] < v[1] <= v[2] < v[3]))
        return m.ShapeMF(kind, (a, b, c, d)), f"Trapezoid {a} {b} {c} {d}"
    mean, sd = round(draw(st.floats(LO, HI)), 3), round(draw(st.floats(0.5, 3.0)), 3)
    return m.ShapeMF(kind, (mean, sd)), f"Gaussian {mean} {sd}"


@st.composite
def condition(draw: Any, inputs: dict[str, int], depth: int = 0) -> tuple[m.Condition, str]:
    if depth >= 2 or draw(st.booleans()):
        var = draw(st.sampled_from(sorted(inputs)))
        t = f"t{draw(st.integers(0, inputs[var] - 1))}"
        neg = draw(st.booleans())
        return m.Is(var, t, neg), f"{var} is {'not ' if neg else ''}{t}"
    kids = [draw(condition(inputs, depth + 1)) for _ in range(2)]
    is_and = draw(st.booleans())
    node = m.And(tuple(k[0] for k in kids)) if is_and else m.Or(tuple(k[0] for k in kids))
    return node, "(" + (" and " if is_and else " or ").join(k[1] for k in kids) + ")"


@st.composite
def case(draw: Any) -> tuple[m.FunctionBlock, str]:
    """A random system as a model and as FLL text for pyfuzzylite."""
    ts = draw(st.booleans())
    inputs = {f"x{i}": draw(st.integers(2, 3)) for i in range(draw(st.integers(1, 2)))}
    fll = ["Engine: random"]
    fuzz = []
    for v, k in inputs.items():
        lock = draw(st.booleans())
        sets = [draw(fuzzy_set(False)) for _ in range(k)]
        fuzz.append(
            m.FuzzifyBlock(
                v, tuple(m.Term(f"t{j}", s[0]) for j, s in enumerate(sets)), m.Range(*IN_RANGE), clamp=lock
            )
        )
        fll += [
            f"InputVariable: {v}",
            f"  range: {IN_RANGE[0]} {IN_RANGE[1]}",
            f"  lock-range: {lock}".lower(),
        ]
        fll += [f"  term: t{j} {s[1]}" for j, s in enumerate(sets)]
    k_out = draw(st.integers(2, 4))
    out_terms: list[m.Term] = []
    out_text: list[str] = []
    for j in range(k_out):
        if ts and draw(st.booleans()):
            cs = [round(draw(st.floats(-2, 2)), 3) for _ in range(len(inputs) + 1)]
            out_terms.append(m.Term(f"o{j}", m.ShapeMF("linear", tuple(cs))))
            out_text.append(f"o{j} Linear {' '.join(map(str, cs))}")
        elif ts:
            c = round(draw(st.floats(LO, HI)), 3)
            out_terms.append(m.Term(f"o{j}", m.ShapeMF("constant", (c,))))
            out_text.append(f"o{j} Constant {c}")
        else:
            mf, text = draw(fuzzy_set(True))
            out_terms.append(m.Term(f"o{j}", mf))
            out_text.append(f"o{j} {text}")
    default = draw(st.sampled_from([math.nan, 5.5, -3.0, 12.0]))  # outside: lock-range limits it
    lock_previous, lock_range = draw(st.booleans()), draw(st.booleans())
    method = "WTAVER" if ts else "COG"
    fll += [
        "OutputVariable: y",
        f"  range: {LO} {HI}",
        f"  lock-range: {str(lock_range).lower()}",
        f"  aggregation: {'none' if ts else 'Maximum'}",
        f"  defuzzifier: {'WeightedAverage TakagiSugeno' if ts else f'Centroid {RES}'}",
        f"  default: {_num(default)}",
        f"  lock-previous: {str(lock_previous).lower()}",
    ]
    fll += [f"  term: {t}" for t in out_text]
    and_op = draw(st.sampled_from(["MIN", "PROD"]))
    or_op = {"MIN": "MAX", "PROD": "ASUM"}[and_op]
    act = draw(st.sampled_from(["MIN", "PROD"]))
    activation = draw(st.sampled_from(ACTIVATIONS))
    rules, texts = [], []
    for r in range(draw(st.integers(1, 6))):
        cond, text = draw(condition(inputs))
        o = f"o{draw(st.integers(0, k_out - 1))}"
        w = round(draw(st.floats(0.1, 1.0)), 2) if draw(st.booleans()) else None
        rules.append(m.Rule(str(r + 1), cond, (m.Conclusion("y", o),), weight=w))
        texts.append(f"if {text} then y is {o}" + (f" with {w}" if w is not None else ""))
    blocks = [
        m.RuleBlock("rb", tuple(rules), and_op, or_op, act, None if ts else "MAX", rule_activation=activation)
    ]
    fll += [
        "RuleBlock: rb",
        "  enabled: true",
        f"  conjunction: {TNORM[and_op]}",
        f"  disjunction: {SNORM[or_op]}",
        f"  implication: {TNORM[act]}",
        f"  activation: {_pyfuzzylite_activation(activation)}",
    ]
    fll += [f"  rule: {t}" for t in texts]
    if draw(st.booleans()):  # a disabled block that would fire everywhere
        blocks.append(
            m.RuleBlock("off", (m.Rule("1", None, (m.Conclusion("y", "o0"),)),), act=act, enabled=False)
        )
        first = next(iter(inputs))
        fll += ["RuleBlock: off", "  enabled: false", f"  implication: {TNORM[act]}"]
        fll += [f"  rule: if {first} is any then y is o0"]
    fb = m.FunctionBlock(
        "random",
        variables=(
            *tuple(m.Variable(v, m.VarKind.INPUT, range=m.Range(*IN_RANGE)) for v in inputs),
            m.Variable("y", m.VarKind.OUTPUT, range=m.Range(LO, HI)),
        ),
        fuzzify=tuple(fuzz),
        defuzzify=(
            m.DefuzzifyBlock(
                "y",
                tuple(out_terms),
                m.Range(LO, HI),
                method,
                m.Default(default, lock_previous),
                clamp=lock_range,
            ),
        ),
        rule_blocks=tuple(blocks),
    )
    return fb, "\n".join(fll) + "\n"


def _pyfuzzylite_activation(activation: str | None) -> str:
    """pyfuzzylite needs both parameters of First/Last (fuzzylite C++ and we default the threshold to 0)."""
    if activation is None:
        return "General"
    words = activation.split()
    return f"{activation} 0" if words[0] in ("First", "Last") and len(words) == 2 else activation


def _pyfuzzylite(text: str, names: list[str], rows: list[list[float]]) -> list[float]:
    return [r[0] for r in peers.pyfuzzylite_fll(text, names, rows, ["y"])]


def _three_paths(
    fb: m.FunctionBlock, rows: list[list[float]]
) -> tuple[list[float], list[float], list[float]]:
    names = [v.name for v in fb.inputs]
    fast = fuzzyctl.compile(fb)
    reference = fuzzyctl.compile(fb, backend="interpreted")
    batch = fuzzyctl.compile(fb)
    got_fast = [fast.evaluate(dict(zip(names, r, strict=True)))["y"] for r in rows]
    got_ref = [reference.evaluate(dict(zip(names, r, strict=True)))["y"] for r in rows]
    got_batch = batch.evaluate_batch({n: np.array([r[i] for r in rows]) for i, n in enumerate(names)})["y"]
    return got_fast, got_ref, [float(v) for v in got_batch]


# inputs beyond every term (nothing fires unless lock-range pulls them in) are frequent
SAMPLE = st.one_of(st.floats(-1.0, 11.0), st.sampled_from([-1.0, 11.0]))


def _same(a: float, b: float, tol: float) -> bool:
    return (math.isnan(a) and math.isnan(b)) or abs(a - b) <= tol


@settings(
    max_examples=100, deadline=None, suppress_health_check=[HealthCheck.too_slow, HealthCheck.filter_too_much]
)
@given(case(), st.lists(st.lists(SAMPLE, min_size=2, max_size=2), min_size=6, max_size=6))
def test_agrees_with_pyfuzzylite_and_the_three_paths_agree(
    drawn: tuple[m.FunctionBlock, str], xs: Any
) -> None:
    fb, text = drawn
    names = [v.name for v in fb.inputs]
    rows = [[round(x[i], 4) for i in range(len(names))] for x in xs]
    fast, ref, batch = _three_paths(fb, rows)
    for f, r, b in zip(fast, ref, batch, strict=True):
        assert _same(f, r, 1e-9 * (HI - LO)) and _same(b, r, 1e-9 * (HI - LO)), (f, r, b, text)
    want = _pyfuzzylite(text, names, rows)
    tol = 1e-9 if fb.defuzzify[0].method == "WTAVER" else 1e-5 * (HI - LO)
    for got, expected, row in zip(ref, want, rows, strict=True):
        assert _same(got, expected, tol) or _knife_edge(fb, row), (got, expected, row, text)


def _knife_edge(fb: m.FunctionBlock, row: list[float]) -> bool:
    """Whether the rule selection of ``row`` is decided by the last bit of a degree: two
    degrees (or a degree and a threshold, or 0) within a few ulps.  pyfuzzylite computes exp
    with numpy's vector code, we with libm on every path (one answer); they differ in the last
    bit on a few percent of arguments, which can flip such a tie (not an error of either)."""
    block = fb.rule_blocks[0]
    if block.rule_activation is None:
        return False
    words = block.rule_activation.split()
    marks = [0.0] + ([float(words[-1])] if words[0] == "Threshold" or len(words) == 3 else [])
    weights = {r.label: float(r.weight) if isinstance(r.weight, float) else 1.0 for r in block.rules}
    names = [v.name for v in fb.inputs]
    explained = fuzzyctl.compile(fb, backend="interpreted").explain(dict(zip(names, row, strict=True)))
    degrees = [(t.condition or 0.0) * weights[t.label] for t in explained.rules if t.block == block.name]
    values = degrees + marks
    return any(
        abs(a - b) <= 8 * math.ulp(max(abs(a), abs(b), 1e-300))
        for i, a in enumerate(values)
        for b in values[i + 1 :]
    )


# --------------------------------------------------------------------------- closed forms


def _one_rule(
    weight: float | None = None, with_weight: float | None = None, method: str = "RM", **block: Any
) -> m.FunctionBlock:
    """x in [0, 1] is ``high`` with degree x; y's only term is the triangle 0-5-10."""
    return m.FunctionBlock(
        "one",
        variables=(m.Variable("x", m.VarKind.INPUT), m.Variable("y", m.VarKind.OUTPUT)),
        fuzzify=(m.FuzzifyBlock("x", (m.Term("high", m.ShapeMF("ramp", (0.0, 1.0))),), m.Range(0.0, 1.0)),),
        defuzzify=(
            m.DefuzzifyBlock(
                "y",
                (m.Term("t", m.ShapeMF("triangle", (0.0, 5.0, 10.0))),),
                m.Range(0.0, 10.0),
                method,
                m.Default(-1.0),
            ),
        ),
        rule_blocks=(
            m.RuleBlock(
                "rb",
                (m.Rule("1", m.Is("x", "high"), (m.Conclusion("y", "t", with_weight),), weight=weight),),
                act="MIN",
                accu="MAX",
                **block,
            ),
        ),
    )


def test_rule_weight_scales_the_degree_before_activation_unlike_with() -> None:
    # a = 1, w = 0.5: MIN(0.5, triangle) is a trapezoid whose right end of the plateau is 7.5;
    # WITH 0.5 halves the whole triangle, whose maximum stays at 5.
    rule_weight = fuzzyctl.compile(_one_rule(weight=0.5))
    with_weight = fuzzyctl.compile(_one_rule(with_weight=0.5))
    assert rule_weight.evaluate({"x": 1.0})["y"] == pytest.approx(7.5, abs=1e-12)
    assert with_weight.evaluate({"x": 1.0})["y"] == pytest.approx(5.0, abs=1e-12)
    e = rule_weight.explain({"x": 0.8})
    assert e.rule("1").condition == pytest.approx(0.8)
    assert e.rule("1").degree == pytest.approx(0.4)  # the degree the rule fires with


def test_rule_weight_given_by_an_input_is_read_at_each_evaluation() -> None:
    fb = _one_rule(weight=m.Ref("w"))
    fb = m.FunctionBlock(
        fb.name, (*fb.variables, m.Variable("w", m.VarKind.INPUT)), fb.fuzzify, fb.defuzzify, fb.rule_blocks
    )
    c = fuzzyctl.compile(fb)
    assert c.evaluate({"x": 1.0, "w": 0.2})["y"] == pytest.approx(9.0, abs=1e-12)  # MIN(0.2, tri) ends at 9
    batch = c.evaluate_batch({"x": [1.0, 1.0], "w": [0.2, 0.6]})["y"]
    assert batch == pytest.approx([9.0, 7.0], abs=1e-12)
    with pytest.raises(InputError):
        c.evaluate({"x": 1.0, "w": 1.5})  # a weight given by an input is a degree


def test_disabled_rule_block_fires_nothing() -> None:
    c = fuzzyctl.compile(_one_rule(enabled=False))
    assert c.evaluate({"x": 1.0})["y"] == -1.0  # the DEFAULT: no rule fired


def test_lock_range_limits_inputs_before_fuzzification_and_outputs_after_default() -> None:
    fb = _one_rule(method="COG")
    fz = fb.fuzzify[0]
    d = fb.defuzzify[0]
    narrow = m.FuzzifyBlock("x", fz.terms, m.Range(0.0, 0.5), clamp=True)
    locked = m.DefuzzifyBlock("y", d.terms, d.range, "RM", m.Default(-1.0), clamp=True)
    c = fuzzyctl.compile(m.FunctionBlock("lock", fb.variables, (narrow,), (locked,), fb.rule_blocks))
    # x = 0.9 is read as 0.5: MIN(0.5, triangle) has its right plateau end at 7.5
    assert c.evaluate({"x": 0.9})["y"] == pytest.approx(7.5, abs=1e-12)
    # x = -3 is read as 0: nothing fires, DEFAULT -1 is limited to the output range
    assert c.evaluate({"x": -3.0})["y"] == 0.0
    assert list(c.evaluate_batch({"x": [0.9, -3.0]})["y"]) == pytest.approx([7.5, 0.0], abs=1e-12)


@pytest.mark.parametrize(
    ("activation", "expected"),
    [
        ("First 1", [0.6, 0.0, 0.0]),
        ("First 1 0.7", [0.0, 0.9, 0.0]),
        ("Last 1", [0.0, 0.0, 0.3]),
        ("Last 2 0.5", [0.6, 0.9, 0.0]),
        ("Highest 2", [0.6, 0.9, 0.0]),
        ("Lowest 1", [0.0, 0.0, 0.3]),
        ("Proportional", [0.6 / 1.8, 0.9 / 1.8, 0.3 / 1.8]),
        ("Threshold >= 0.6", [0.6, 0.9, 0.0]),
        ("Threshold < 0.6", [0.0, 0.0, 0.3]),
        ("General", [0.6, 0.9, 0.3]),
    ],
)
def test_rule_activation_methods(activation: str, expected: list[float]) -> None:
    """Three rules with degrees 0.6, 0.9, 0.3 on one Takagi-Sugeno output."""
    terms = tuple(m.Term(f"c{i}", m.ShapeMF("constant", (float(10**i),))) for i in range(3))
    rules = tuple(m.Rule(str(i + 1), m.Degree(f"d{i}"), (m.Conclusion("y", f"c{i}"),)) for i in range(3))
    fb = m.FunctionBlock(
        "sel",
        variables=(
            *(m.Variable(f"d{i}", m.VarKind.INPUT) for i in range(3)),
            m.Variable("y", m.VarKind.OUTPUT),
        ),
        defuzzify=(m.DefuzzifyBlock("y", terms, None, "WTSUM", m.Default(0.0)),),
        rule_blocks=(m.RuleBlock("rb", rules, rule_activation=activation),),
    )
    inputs = {"d0": 0.6, "d1": 0.9, "d2": 0.3}
    want = sum(w * 10**i for i, w in enumerate(expected))
    for backend in ("python", "interpreted"):
        c = fuzzyctl.compile(fb, backend=backend)
        assert c.evaluate(inputs)["y"] == pytest.approx(want, abs=1e-12)
        assert [r.degree for r in c.explain(inputs).rules] == pytest.approx(expected, abs=1e-12)
    batch = fuzzyctl.compile(fb).evaluate_batch({k: [v, v] for k, v in inputs.items()})["y"]
    assert list(batch) == pytest.approx([want, want], abs=1e-12)


def test_highest_breaks_ties_by_rule_order() -> None:
    fb = m.FunctionBlock(
        "tie",
        variables=(m.Variable("d", m.VarKind.INPUT), m.Variable("y", m.VarKind.OUTPUT)),
        defuzzify=(
            m.DefuzzifyBlock(
                "y",
                (m.Term("a", m.ShapeMF("constant", (1.0,))), m.Term("b", m.ShapeMF("constant", (2.0,)))),
                None,
                "WTAVER",
                m.Default(0.0),
            ),
        ),
        rule_blocks=(
            m.RuleBlock(
                "rb",
                (
                    m.Rule("1", m.Degree("d"), (m.Conclusion("y", "a"),)),
                    m.Rule("2", m.Degree("d"), (m.Conclusion("y", "b"),)),
                ),
                rule_activation="Highest 1",
            ),
        ),
    )
    c = fuzzyctl.compile(fb)
    assert c.evaluate({"d": 0.5})["y"] == 1.0
    assert float(c.evaluate_batch({"d": [0.5]})["y"][0]) == 1.0


def test_function_argument_names_the_point() -> None:
    """``u`` is the point of the output universe: mu(u) = u / 10, so RM is 10 and CoG 20/3."""
    fb = _one_rule(method="COG")
    d = fb.defuzzify[0]
    expr = m.Binary("/", m.Name("u"), m.Num(10.0))
    ramp = m.Term("t", m.FunctionMF(expr, "u / 10", argument="u"))
    fb = m.FunctionBlock(
        fb.name, fb.variables, fb.fuzzify, (m.DefuzzifyBlock("y", (ramp,), d.range, "COG"),), fb.rule_blocks
    )
    assert fuzzyctl.compile(fb).evaluate({"x": 1.0})["y"] == pytest.approx(20.0 / 3.0, abs=1e-8)


@pytest.mark.parametrize(
    ("change", "code"),
    [
        ({"rule_activation": "Probabilistic"}, "rule-activation"),
        ({"rule_activation": "Highest two"}, "rule-activation"),
        ({"rule_activation": "Threshold 0.5"}, "rule-activation"),
    ],
)
def test_what_the_engine_refuses_is_reported(change: dict[str, Any], code: str) -> None:
    fb = _one_rule(**change)
    assert any(d.code == code and d.is_error for d in unsupported(fb))
    with pytest.raises(DiagnosticError):
        fuzzyctl.compile(fb)


def test_negative_rule_weight_and_lock_range_without_range_are_reported() -> None:
    assert any(d.code == "weight-negative" for d in unsupported(_one_rule(weight=-0.5)))
    fb = _one_rule()
    d = fb.defuzzify[0]
    unbounded = m.DefuzzifyBlock("y", d.terms, None, "RM", clamp=True)
    fb = m.FunctionBlock(fb.name, fb.variables, fb.fuzzify, (unbounded,), fb.rule_blocks)
    assert any(x.code == "clamp-range" for x in unsupported(fb))


def test_rule_activation_with_chained_inference_is_reported() -> None:
    chained = m.FunctionBlock(
        "chain",
        variables=(
            m.Variable("x", m.VarKind.INPUT),
            m.Variable("y", m.VarKind.OUTPUT),
            m.Variable("z", m.VarKind.OUTPUT),
        ),
        fuzzify=(m.FuzzifyBlock("x", (m.Term("high", m.ShapeMF("ramp", (0.0, 1.0))),)),),
        defuzzify=(
            m.DefuzzifyBlock(
                "y", (m.Term("t", m.ShapeMF("triangle", (0.0, 5.0, 10.0))),), m.Range(0.0, 10.0), "COG"
            ),
            m.DefuzzifyBlock(
                "z", (m.Term("t", m.ShapeMF("triangle", (0.0, 5.0, 10.0))),), m.Range(0.0, 10.0), "COG"
            ),
        ),
        rule_blocks=(
            m.RuleBlock("a", (m.Rule("1", m.Is("x", "high"), (m.Conclusion("y", "t"),)),)),
            m.RuleBlock(
                "b", (m.Rule("1", m.Is("y", "t"), (m.Conclusion("z", "t"),)),), rule_activation="First 1"
            ),
        ),
    )
    assert any(d.code == "rule-activation-chained" for d in unsupported(chained))


def test_highest_tie_on_a_gaussians_last_bit_is_one_answer_on_every_path() -> None:
    # exp(-1/8) (Gaussian 1 2 at x = 0) is one ulp apart in libm and numpy's vector exp on
    # common CPUs; ASUM(1, g) = 1 + g - g is then 1.0 under libm and 0.999... under numpy, so
    # "Highest 1" against a rule of degree exactly 1 picked rule 1 (o1: 4/3) in the scalar
    # paths and rule 2 (o0: 1) in the batch path.  Brute force: the degrees as libm gives them.
    g = math.exp(-(1.0 * 1.0) / (2.0 * 2.0 * 2.0))
    rule1, rule2 = 1.0 + g - 1.0 * g, 1.0
    want = 4.0 / 3.0 if rule1 >= rule2 else 1.0  # the earlier rule on a tie
    fz = m.FuzzifyBlock(
        "x0",
        (
            m.Term("t0", m.ShapeMF("triangle", (0.0, 1.0, 2.0))),
            m.Term("t1", m.ShapeMF("gaussian", (1.0, 2.0))),
        ),
    )
    df = m.DefuzzifyBlock(
        "y",
        (
            m.Term("o0", m.ShapeMF("triangle", (0.0, 1.0, 2.0))),
            m.Term("o1", m.ShapeMF("triangle", (0.0, 1.0, 3.0))),
        ),
        m.Range(LO, HI),
        "COG",
        m.Default(math.nan),
    )
    rules = (
        m.Rule("1", m.Or((m.Is("x0", "t0", True), m.Is("x0", "t1"))), (m.Conclusion("y", "o1"),)),
        m.Rule("2", m.Is("x0", "t0", True), (m.Conclusion("y", "o0"),)),
    )
    fb = m.FunctionBlock(
        "tie",
        variables=(m.Variable("x0", m.VarKind.INPUT), m.Variable("y", m.VarKind.OUTPUT)),
        fuzzify=(fz,),
        defuzzify=(df,),
        rule_blocks=(m.RuleBlock("rb", rules, "PROD", "ASUM", "MIN", "MAX", rule_activation="Highest 1"),),
    )
    fast, ref, batch = _three_paths(fb, [[0.0]] * 6)
    assert fast == ref == batch == [pytest.approx(want, abs=1e-12)] * 6
    assert _knife_edge(fb, [0.0])  # pyfuzzylite (numpy's exp) may take the other rule here
