"""The semantic decisions of docs/engine.md, one test each."""

from __future__ import annotations

import dataclasses
import math

import numpy as np
import pytest

import fuzzyctl
from fuzzyctl import model as m
from fuzzyctl.diagnostics import DiagnosticError, InputError
from fuzzyctl.engine.lowering.lower import lower
from fuzzyctl.engine.support import unsupported
from tests.engine.builders import (
    and_,
    is_,
    mamdani,
    or_,
    pts,
    rule,
    shape,
    single,
    terms,
    then,
    var_in,
    var_out,
)

RAMP_UP = pts((0, 0), (10, 1))
RAMP_DOWN = pts((0, 1), (10, 0))


def _one_input(
    out_terms: dict[str, m.MembershipFunction], rules: list[m.Rule], **kw: object
) -> m.FunctionBlock:
    return mamdani({"x": {"up": RAMP_UP, "down": RAMP_DOWN}}, out_terms, rules, **kw)  # type: ignore[arg-type]


def test_no_accu_means_max() -> None:
    fb = _one_input(
        {"a": single(0.0), "b": single(10.0)},
        [
            rule("1", is_("x", "up"), then("y", "a")),
            rule("2", is_("x", "up"), then("y", "a")),
            rule("3", is_("x", "down"), then("y", "b")),
        ],
    )
    # x=5: a gets max(.5, .5) = .5 (SUM would give 1.0), b .5
    assert fuzzyctl.compile(fb).evaluate({"x": 5.0})["y"] == pytest.approx(5.0)
    summed = _one_input(
        fb.defuzzify[0].terms and {"a": single(0.0), "b": single(10.0)},
        list(fb.rule_blocks[0].rules),
        accu="SUM",
    )
    assert fuzzyctl.compile(summed).evaluate({"x": 5.0})["y"] == pytest.approx(10.0 / 3.0)


@pytest.mark.parametrize(
    ("and_op", "or_op", "expect_and", "expect_or"),
    [
        (None, None, min(0.3, 0.6), max(0.3, 0.6)),
        ("PROD", None, 0.3 * 0.6, 0.3 + 0.6 - 0.18),
        (None, "ASUM", 0.3 * 0.6, 0.3 + 0.6 - 0.18),
        ("BDIF", None, 0.0, 0.9),
        (None, "BSUM", 0.0, 0.9),
    ],
)
def test_and_or_pairs(and_op: str | None, or_op: str | None, expect_and: float, expect_or: float) -> None:
    fb = mamdani(
        {"x": {"p": pts((0, 0.3), (1, 0.3))}, "z": {"q": pts((0, 0.6), (1, 0.6))}},
        {"a": single(0.0), "b": single(1.0)},
        [
            rule("and", and_(is_("x", "p"), is_("z", "q")), then("y", "a")),
            rule("or", or_(is_("x", "p"), is_("z", "q")), then("y", "b")),
        ],
        and_op=and_op,
        or_op=or_op,
    )
    e = fuzzyctl.compile(fb).explain({"x": 0.5, "z": 0.5})
    assert e.rule("and").degree == pytest.approx(expect_and)
    assert e.rule("or").degree == pytest.approx(expect_or)


def test_not_and_negated_is() -> None:
    fb = _one_input(
        {"a": single(0.0), "b": single(1.0)},
        [
            rule("1", m.Not(is_("x", "up")), then("y", "a")),
            rule("2", is_("x", "up", negated=True), then("y", "b")),
        ],
    )
    e = fuzzyctl.compile(fb).explain({"x": 2.0})
    assert e.rule("1").degree == pytest.approx(0.8)
    assert e.rule("2").degree == pytest.approx(0.8)


def test_with_scales_the_activated_set_iec_and_the_degree_in_compat_mode() -> None:
    fb = _one_input(
        {"t": shape("triangle", 0, 5, 10)}, [rule("1", is_("x", "up"), then("y", "t", 0.5))], rng=(0, 10)
    )
    iec = fuzzyctl.compile(fb).explain({"x": 10.0}).output("y")
    # mu = 0.5 * min(1, tri): a triangle of height 0.5
    assert max(v for _x, v in iec.breakpoints) == pytest.approx(0.5)
    assert [x for x, v in iec.breakpoints if v == pytest.approx(0.5)] == [5.0]
    jfl = fuzzyctl.compile(fb, compat="jfuzzylogic").explain({"x": 10.0}).output("y")
    # min(0.5 * 1, tri): a trapezoid with a plateau from 2.5 to 7.5, drawn at jFuzzyLogic's
    # samples (x += 0.01 drifts by a few ulps)
    plateau = [x for x, v in jfl.breakpoints if v == pytest.approx(0.5)]
    assert (plateau[0], plateau[-1]) == (pytest.approx(2.5, abs=1e-12), pytest.approx(7.5, abs=1e-12))


def test_weight_given_by_an_input_is_read_each_evaluation() -> None:
    fb = m.FunctionBlock(
        "w",
        variables=var_in("x", "w") + var_out("y"),
        fuzzify=(m.FuzzifyBlock("x", terms(up=RAMP_UP)),),
        defuzzify=(m.DefuzzifyBlock("y", terms(a=single(0.0), b=single(10.0)), method="COGS"),),
        rule_blocks=(
            m.RuleBlock(
                "r",
                (rule("1", is_("x", "up"), then("y", "b", m.Ref("w"))), rule("2", None, then("y", "a", 0.5))),
            ),
        ),
    )
    c = fuzzyctl.compile(fb)
    assert c.evaluate({"x": 10.0, "w": 0.5})["y"] == pytest.approx(5.0)
    assert c.evaluate({"x": 10.0, "w": 1.0})["y"] == pytest.approx(10 / 1.5)
    with pytest.raises(InputError, match="'w'"):
        c.evaluate({"x": 10.0, "w": 1.5})


def test_bare_variable_conclusion_and_degree_condition() -> None:
    fb = m.FunctionBlock(
        "bare",
        variables=var_in("x", "d") + var_out("alarm"),
        fuzzify=(m.FuzzifyBlock("x", terms(up=RAMP_UP)),),
        rule_blocks=(
            m.RuleBlock(
                "r",
                (
                    rule("1", and_(is_("x", "up"), m.Degree("d")), then("alarm", None, 0.5)),
                    rule("2", is_("x", "up"), then("alarm")),
                ),
                "PROD",
            ),
        ),
    )
    c = fuzzyctl.compile(fb)
    # rule 1: .4 * .5 = .2, times WITH .5 = .1; rule 2: .4; MAX
    assert c.evaluate({"x": 4.0, "d": 0.5})["alarm"] == pytest.approx(0.4)
    assert c.evaluate({"x": 4.0, "d": 0.5}) == c.evaluate_reference({"x": 4.0, "d": 0.5})


def _chained(reverse: bool = False) -> m.FunctionBlock:
    first = m.RuleBlock(
        "first",
        (
            rule("1", is_("x", "up"), then("flow", "big")),
            rule("2", is_("x", "down"), then("flow", "small", 0.5)),
        ),
    )
    second = m.RuleBlock(
        "second",
        (
            rule("3", is_("flow", "big"), then("valve", "open")),
            rule("4", is_("flow", "small"), then("valve", "shut")),
        ),
    )
    return m.FunctionBlock(
        "chain",
        variables=var_in("x") + var_out("valve") + (m.Variable("flow", m.VarKind.LOCAL),),
        fuzzify=(m.FuzzifyBlock("x", terms(up=RAMP_UP, down=RAMP_DOWN)),),
        defuzzify=(
            m.DefuzzifyBlock("flow", terms(small=single(0.0), big=single(1.0))),
            m.DefuzzifyBlock("valve", terms(shut=single(0.0), open=single(100.0)), method="COGS"),
        ),
        rule_blocks=(second, first) if reverse else (first, second),
    )


@pytest.mark.parametrize("reverse", [False, True])
def test_chained_inference_uses_accumulated_degrees(reverse: bool) -> None:
    c = fuzzyctl.compile(_chained(reverse))
    e = c.explain({"x": 2.0})
    chained = {(t.variable, t.term): t.degree for t in e.chained}
    assert chained[("flow", "big")] == pytest.approx(0.2)
    assert chained[("flow", "small")] == pytest.approx(0.4)  # 0.8 WITH 0.5
    assert e.values["valve"] == pytest.approx(100 * 0.2 / 0.6)
    assert c.evaluate({"x": 2.0})["valve"] == pytest.approx(100 * 0.2 / 0.6)
    assert c.evaluate_batch({"x": [2.0]})["valve"][0] == pytest.approx(100 * 0.2 / 0.6)


def test_chained_inference_cycle_is_an_error() -> None:
    fb = _chained()
    loop = m.RuleBlock("loop", (rule("5", is_("valve", "open"), then("flow", "big")),))
    fb = m.FunctionBlock(fb.name, fb.variables, fb.fuzzify, fb.defuzzify, (*fb.rule_blocks, loop))
    with pytest.raises(DiagnosticError) as exc:
        fuzzyctl.compile(fb)
    assert any(d.code == "dependency-cycle" for d in exc.value.diagnostics)
    assert any(d.code == "dependency-cycle" for d in unsupported(fb))


def test_output_read_in_a_condition_chains_like_fuzzylite_dimmer() -> None:
    tri = shape("triangle", 0.0, 0.25, 0.5)
    fb = m.FunctionBlock(
        "dimmer",
        variables=var_in("ambient") + var_out("power", "inverse"),
        fuzzify=(m.FuzzifyBlock("ambient", terms(dark=tri)),),
        defuzzify=(
            m.DefuzzifyBlock(
                "power",
                terms(low=shape("triangle", 0, 0.25, 0.5), high=shape("triangle", 0.5, 0.75, 1)),
                m.Range(0, 1),
            ),
            m.DefuzzifyBlock("inverse", terms(low=single(0.0), high=single(1.0))),
        ),
        rule_blocks=(
            m.RuleBlock(
                None,
                (
                    rule("1", is_("ambient", "dark"), then("power", "high")),
                    rule("2", is_("power", "high"), then("inverse", "low")),
                    rule("3", is_("power", "low"), then("inverse", "high")),
                ),
            ),
        ),
    )
    out = fuzzyctl.compile(fb).evaluate({"ambient": 0.2})
    assert out["power"] == pytest.approx(0.75)  # a symmetric triangle clipped at 0.8
    assert out["inverse"] == 0.0  # power IS high = 0.8, power IS low = 0


def test_variable_points_are_sorted_and_vertical_edges_take_the_upper_value() -> None:
    fb = m.FunctionBlock(
        "pts",
        variables=var_in("x", "p") + var_out("y"),
        fuzzify=(
            m.FuzzifyBlock(
                "x",
                terms(
                    a=m.PointsMF((m.Point(m.Ref("p"), 0.0), m.Point(5.0, 1.0))),
                    edge=pts((2, 0), (2, 1), (4, 1), (4, 0)),
                ),
            ),
        ),
        defuzzify=(m.DefuzzifyBlock("y", terms(lo=single(0.0), hi=single(1.0))),),
        rule_blocks=(
            m.RuleBlock(
                "r", (rule("1", is_("x", "a"), then("y", "hi")), rule("2", is_("x", "edge"), then("y", "lo")))
            ),
        ),
    )
    c = fuzzyctl.compile(fb)
    degrees = lambda x, p: {t.term: t.degree for t in c.explain({"x": x, "p": p}).terms}  # noqa: E731
    assert degrees(4.0, 0.0)["a"] == pytest.approx(0.8)
    assert degrees(8.0, 10.0)["a"] == pytest.approx(0.4)  # (10, 0) comes after (5, 1) at run time
    assert degrees(2.0, 0.0)["edge"] == 1.0
    assert degrees(4.0, 0.0)["edge"] == 1.0
    assert degrees(4.0 + 1e-12, 0.0)["edge"] == 0.0


def test_cog_with_singletons_is_cogs_and_coa_with_singletons_is_an_error() -> None:
    r = [rule("1", is_("x", "up"), then("y", "a")), rule("2", is_("x", "down"), then("y", "b"))]
    cog = fuzzyctl.compile(_one_input({"a": single(0.0), "b": single(10.0)}, r, method="COG"))
    assert cog.plan.outputs[0].method == "COGS"
    assert cog.evaluate({"x": 2.0})["y"] == pytest.approx(8.0)
    with pytest.raises(DiagnosticError, match="CoA is not applicable"):
        fuzzyctl.compile(_one_input({"a": single(0.0), "b": single(10.0)}, r, method="COA"))


def test_range_defaults_to_the_hull_of_the_supports_and_unbounded_takes_the_span_of_the_terms() -> None:
    r = [rule("1", is_("x", "up"), then("y", "b"))]
    c = fuzzyctl.compile(
        _one_input({"a": shape("triangle", 2, 4, 6), "b": shape("trapezoid", 5, 7, 8, 12)}, r)
    )
    assert (c.plan.outputs[0].low, c.plan.outputs[0].high) == (2.0, 12.0)
    # a gaussian never reaches 0: jFuzzyLogic's universe, mean +- 4 sigma (1..9) joined with
    # the triangle's a..c (2..6), with a warning that names the term and the universe
    fb = _one_input({"a": shape("triangle", 2, 4, 6), "b": shape("gaussian", 5, 1)}, r)
    plan, diags = lower(fb)
    assert plan is not None and (plan.outputs[0].low, plan.outputs[0].high) == (1.0, 9.0)
    (w,) = [d for d in diags if d.code == "universe-from-terms"]
    assert not w.is_error and "term b" in w.message and "[1, 9]" in w.message and "4 sigma" in w.message
    # symmetric set, clipped at 1 over [1, 9]: the centroid is the mean
    assert fuzzyctl.compile(fb).evaluate({"x": 10.0})["y"] == pytest.approx(5.0, abs=1e-12)
    with pytest.raises(DiagnosticError, match=r"term b \(gaussian\).*give a RANGE"):
        fuzzyctl.compile(fb, strict=True)


def test_terms_spanning_one_point_give_that_point_when_a_rule_fires() -> None:
    # jFuzzyLogic's DeMorgan tests: TERM v := (0, 1) (0, 1); and no RANGE
    flat = m.PointsMF((m.Point(3.0, 1.0), m.Point(3.0, 1.0)))
    fb = _one_input({"a": flat}, [rule("1", is_("x", "up"), then("y", "a"))], default=m.Default(-1.0))
    c = fuzzyctl.compile(fb)
    assert c.evaluate({"x": 5.0})["y"] == 3.0
    assert c.evaluate({"x": 0.0})["y"] == -1.0  # nothing fired: DEFAULT
    with pytest.raises(DiagnosticError, match="give a RANGE"):
        fuzzyctl.compile(fb, strict=True)


def test_an_output_no_rule_concludes_is_its_default_whatever_its_terms() -> None:
    # jFuzzyLogic's noRules test: a DEFUZZIFY block without terms; or terms whose parameters
    # are variables and no RANGE - neither universe is ever needed
    fb = _one_input({}, [rule("1", is_("x", "up"), then("y2", "a"))], default=m.Default(4.0))
    fb = dataclasses.replace(
        fb,
        variables=(*fb.variables, m.Variable("y2", m.VarKind.OUTPUT)),
        defuzzify=(
            *fb.defuzzify,
            m.DefuzzifyBlock("y2", (m.Term("a", m.SingletonMF(1.0)),), method="COGS", default=m.Default(0.0)),
        ),
    )
    plan, diags = lower(fb)
    assert plan is not None
    assert any(d.code == "output-unused" and "y" in d.message for d in diags)
    assert fuzzyctl.compile(fb).evaluate({"x": 10.0}) == {"y": 4.0, "y2": 1.0}


def test_terms_are_limited_to_the_range() -> None:
    # a ramp that keeps rising beyond RANGE: only its part inside [0, 10] counts
    fb = _one_input({"a": shape("ramp", 0, 20)}, [rule("1", is_("x", "up"), then("y", "a"))], rng=(0, 10))
    assert fuzzyctl.compile(fb).evaluate({"x": 10.0})["y"] == pytest.approx(20.0 / 3.0)


def test_default_value_and_nc() -> None:
    r = [rule("1", is_("x", "up"), then("y", "a"))]
    with_default = fuzzyctl.compile(_one_input({"a": single(3.0)}, r, default=m.Default(-7.0)))
    assert with_default.evaluate({"x": 0.0})["y"] == -7.0
    assert with_default.evaluate({"x": 5.0})["y"] == 3.0
    assert with_default.evaluate({"x": 0.0})["y"] == -7.0
    nan_nc = fuzzyctl.compile(_one_input({"a": single(3.0)}, r, default=m.Default(math.nan, True)))
    assert math.isnan(nan_nc.evaluate({"x": 0.0})["y"])  # before any firing: the given value
    assert nan_nc.evaluate({"x": 5.0})["y"] == 3.0
    assert nan_nc.evaluate({"x": 0.0})["y"] == 3.0
    nc = fuzzyctl.compile(_one_input({"a": single(3.0)}, r))
    out = nc.evaluate_batch({"x": np.array([0.0, 5.0, 0.0, 0.0])})["y"]
    assert out.tolist() == [0.0, 3.0, 3.0, 3.0]  # batch rows are successive cycles
    assert nc.evaluate({"x": 0.0})["y"] == 3.0  # and the instance remembers


def test_nsum_normalises_only_what_is_shown() -> None:
    r = [rule("1", is_("x", "up"), then("y", "a")), rule("2", is_("x", "up"), then("y", "a"))]
    tri = {"a": shape("triangle", 0, 5, 10)}
    nsum = fuzzyctl.compile(_one_input(tri, r, accu="NSUM", act="PROD"))
    e = nsum.explain({"x": 8.0})
    assert max(v for _x, v in e.output("y").breakpoints) == pytest.approx(1.0)  # 1.6 / max(1, 1.6)
    assert e.values["y"] == pytest.approx(5.0)


def test_takagi_sugeno_linear_constant_function() -> None:
    fb = m.FunctionBlock(
        "ts",
        variables=var_in("x", "z") + var_out("y"),
        fuzzify=(m.FuzzifyBlock("x", terms(up=RAMP_UP, down=RAMP_DOWN)),),
        defuzzify=(
            m.DefuzzifyBlock(
                "y",
                terms(
                    lin=shape("linear", 2.0, -1.0, 3.0),
                    const=shape("constant", 7.0),
                    fn=m.FunctionMF(m.Binary("*", m.Name("x"), m.Name("z"))),
                ),
                method=None,
            ),
        ),
        rule_blocks=(
            m.RuleBlock(
                "r",
                (
                    rule("1", is_("x", "up"), then("y", "lin")),
                    rule("2", is_("x", "down"), then("y", "const")),
                    rule("3", is_("x", "down"), then("y", "fn", 0.5)),
                ),
            ),
        ),
    )
    c = fuzzyctl.compile(fb)
    x, z = 4.0, 2.0
    w1, w2, w3 = 0.4, 0.6, 0.3
    z1, z2, z3 = 2 * x - z + 3, 7.0, x * z
    assert c.evaluate({"x": x, "z": z})["y"] == pytest.approx((w1 * z1 + w2 * z2 + w3 * z3) / (w1 + w2 + w3))
    wtsum = m.FunctionBlock(
        fb.name,
        fb.variables,
        fb.fuzzify,
        (m.DefuzzifyBlock("y", fb.defuzzify[0].terms, method="WTSUM"),),
        fb.rule_blocks,
    )
    assert fuzzyctl.compile(wtsum).evaluate({"x": x, "z": z})["y"] == pytest.approx(
        w1 * z1 + w2 * z2 + w3 * z3
    )
    b = c.evaluate_batch({"x": [x], "z": [z]})["y"][0]
    assert b == pytest.approx((w1 * z1 + w2 * z2 + w3 * z3) / (w1 + w2 + w3))


@pytest.mark.parametrize(
    ("hedge", "f"),
    [
        ("very", lambda d: d * d),
        ("somewhat", math.sqrt),
        ("extremely", lambda d: 2 * d * d if d <= 0.5 else 1 - 2 * (1 - d) ** 2),
        ("seldom", lambda d: math.sqrt(d / 2) if d <= 0.5 else 1 - math.sqrt((1 - d) / 2)),
        ("any", lambda d: 1.0),
    ],
)
def test_hedges(hedge: str, f: object) -> None:
    fb = _one_input({"a": single(0.0)}, [rule("1", is_("x", "up", hedges=[hedge]), then("y", "a"))])
    for x in (2.0, 7.0):
        got = fuzzyctl.compile(fb).explain({"x": x}).rule("1").degree
        assert got == pytest.approx(f(x / 10.0))  # type: ignore[operator]


def test_input_errors_name_the_input() -> None:
    c = fuzzyctl.compile(_one_input({"a": single(0.0)}, [rule("1", is_("x", "up"), then("y", "a"))]))
    with pytest.raises(InputError, match="missing input 'x'"):
        c.evaluate({})
    with pytest.raises(InputError, match=r"'x'.*finite"):
        c.evaluate({"x": math.nan})
    with pytest.raises(InputError, match="'x' must be a number"):
        c.evaluate({"x": "20"})
    with pytest.raises(InputError, match="unknown input 'temp'"):
        c.evaluate({"x": 1.0, "temp": 3.0})
    with pytest.raises(InputError, match=r"'x'.*row 2"):
        c.evaluate_batch({"x": [1.0, 2.0, math.nan]})
    with pytest.raises(InputError, match=r"'x'.*row 1"):
        c.evaluate_batch({"x": np.array([1.0, "abc"], dtype=object)})


def test_several_rule_blocks_accumulate_and_disagreeing_accu_warns() -> None:
    fb = _one_input(
        {"a": single(0.0), "b": single(10.0)}, [rule("1", is_("x", "up"), then("y", "a"))], accu="MAX"
    )
    other = m.RuleBlock(
        "more",
        (rule("2", is_("x", "up"), then("y", "a")), rule("3", is_("x", "down"), then("y", "b"))),
        accu="SUM",
    )
    fb = m.FunctionBlock(fb.name, fb.variables, fb.fuzzify, fb.defuzzify, (*fb.rule_blocks, other))
    assert any(d.code == "accu-disagree" and not d.is_error for d in unsupported(fb))
    # MAX (the first block's): a = max(.5, .5), b = .5
    assert fuzzyctl.compile(fb).evaluate({"x": 5.0})["y"] == pytest.approx(5.0)


def test_unsupported_reports_what_cannot_be_evaluated() -> None:
    bad = _one_input(
        {"a": shape("triangle", 0, 5, 10), "s": single(3.0)}, [rule("1", is_("x", "up"), then("y", "a"))]
    )
    codes = {d.code for d in unsupported(bad)}
    assert "mixed-terms" in codes
    unknown = _one_input({"a": shape("wiggle", 1, 2)}, [rule("1", is_("x", "up"), then("y", "a"))])
    assert "shape-unknown" in {d.code for d in unsupported(unknown)}
    assert unsupported(_one_input({"a": single(1.0)}, [rule("1", is_("x", "up"), then("y", "a"))])) == []


def test_duplicate_term_names_keep_the_first_and_warn() -> None:
    fb = m.FunctionBlock(
        "dup",
        variables=var_in("x") + var_out("y"),
        fuzzify=(m.FuzzifyBlock("x", (m.Term("t", RAMP_UP), m.Term("t", RAMP_DOWN))),),
        defuzzify=(m.DefuzzifyBlock("y", terms(a=single(1.0))),),
        rule_blocks=(m.RuleBlock("r", (rule("1", is_("x", "t"), then("y", "a")),)),),
    )
    assert [d.code for d in unsupported(fb)] == ["duplicate-term"]
    assert fuzzyctl.compile(fb).explain({"x": 2.0}).rule("1").degree == pytest.approx(
        0.2
    )  # the first: RAMP_UP


def test_power_hedges_and_comparison_functions() -> None:
    fb = _one_input({"a": single(0.0)}, [rule("1", is_("x", "up", hedges=["pow:3"]), then("y", "a"))])
    assert fuzzyctl.compile(fb).explain({"x": 5.0}).rule("1").degree == pytest.approx(0.125)
    # fuzzylite's Function as a fuzzy set of x: 1 on [0, 0.5), 0.5 at 0.5, 0 beyond (a step)
    step = m.FunctionMF(
        m.Binary(
            "+",
            m.Call("lt", (m.Name("x"), m.Num(0.5))),
            m.Binary("*", m.Num(0.5), m.Call("eq", (m.Name("x"), m.Num(0.5)))),
        )
    )
    fb = mamdani({"v": {"up": RAMP_UP}}, {"s": step}, [rule("1", is_("v", "up"), then("y", "s"))], rng=(0, 1))
    c = fuzzyctl.compile(fb)
    assert c.plan.outputs[0].kind == "mamdani" and not c.plan.outputs[0].exact  # quadrature
    assert c.evaluate({"v": 10.0})["y"] == pytest.approx(0.25, abs=1e-9)


def test_explained_set_keeps_vertical_edges_across_gaps() -> None:
    """Two sets apart, the right one starting with a vertical edge: the polyline must drop
    to 0 between them and rise vertically, so its centroid is the output's value."""
    fb = _one_input(
        {"lo": shape("trapezoid", 0, 1, 2, 3), "hi": shape("triangle", 6, 6, 9)},
        [rule("1", is_("x", "up"), then("y", "lo")), rule("2", is_("x", "down"), then("y", "hi"))],
        rng=(0, 10),
    )
    out = fuzzyctl.compile(fb).explain({"x": 5.0}).output("y")
    xs, ys = np.array(out.breakpoints).T
    assert (6.0, 0.0) in out.breakpoints and (6.0, 0.5) in out.breakpoints
    seg = np.diff(xs)
    area = float((seg * (ys[:-1] + ys[1:]) / 2).sum())
    moment = float((seg * (xs[:-1] * (2 * ys[:-1] + ys[1:]) + xs[1:] * (ys[:-1] + 2 * ys[1:])) / 6).sum())
    assert moment / area == pytest.approx(out.value, abs=1e-12)
