"""Invariants: outputs stay inside RANGE (or the singletons' hull), monotone systems stay
monotone, De Morgan holds for every AND/OR pair with real membership functions."""

from __future__ import annotations

import itertools

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

import fuzzyctl
from fuzzyctl import model as m
from fuzzyctl.engine.semantics.operators import AND_TO_OR
from tests.engine.builders import and_, is_, mamdani, or_, rule, shape, single, then
from tests.engine.randsys import HI, LO, input_values, system


@settings(max_examples=60, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(st.data())
def test_outputs_stay_inside_the_range(data: st.DataObject) -> None:
    fb = data.draw(system())
    c = fuzzyctl.compile(fb)
    for s in input_values(data.draw, fb, 5):
        y = c.evaluate(s)["y"]
        assert y == -1.0 or LO <= y <= HI  # -1 is the DEFAULT of these systems


@settings(max_examples=40, deadline=None)
@given(
    st.lists(st.floats(-50, 50), min_size=2, max_size=5, unique=True),
    st.lists(st.floats(0, 1), min_size=2, max_size=2),
    st.sampled_from(["MAX", "SUM", "BSUM"]),
)
def test_cogs_stays_inside_the_singletons_hull(positions: list[float], x: list[float], accu: str) -> None:
    outs = {f"s{i}": single(p) for i, p in enumerate(positions)}
    rules = [
        rule(str(i), is_("x", "lo" if i % 2 else "hi"), then("y", f"s{i}")) for i in range(len(positions))
    ]
    fb = mamdani(
        {"x": {"lo": shape("ramp", 1, 0), "hi": shape("ramp", 0, 1)}}, outs, rules, method="COGS", accu=accu
    )
    for v in x:
        y = fuzzyctl.compile(fb).evaluate({"x": v})["y"]
        assert min(positions) - 1e-12 <= y <= max(positions) + 1e-12


@st.composite
def ruspini(draw: st.DrawFn, n: int) -> list[float]:
    """n strictly increasing peaks in [0, 10]."""
    xs = sorted(set(round(v, 3) for v in draw(st.lists(st.floats(0, 10), min_size=n, max_size=n))))
    if len(xs) < n or min(b - a for a, b in itertools.pairwise(xs)) < 0.05:
        xs = [10.0 * i / (n - 1) for i in range(n)]
    return xs


def _partition(peaks: list[float]) -> dict[str, m.MembershipFunction]:
    """Triangles with neighbouring peaks as feet: degrees sum to 1 (a Ruspini partition)."""
    out: dict[str, m.MembershipFunction] = {}
    for i, p in enumerate(peaks):
        a = peaks[i - 1] if i > 0 else p - 1.0
        c = peaks[i + 1] if i + 1 < len(peaks) else p + 1.0
        out[f"a{i}"] = shape("triangle", a, p, c)
    return out


@settings(max_examples=30, deadline=None)
@given(
    st.integers(2, 5).flatmap(
        lambda n: st.tuples(ruspini(n), st.lists(st.floats(-20, 20), min_size=n, max_size=n))
    ),
    st.sampled_from(["singletons", "translated"]),
)
def test_monotone_rule_bases_give_monotone_controllers(
    spec: tuple[list[float], list[float]], outputs: str
) -> None:
    peaks, centres = spec
    centres = sorted(centres)
    n = len(peaks)
    rules = [rule(str(i), is_("x", f"a{i}"), then("y", f"b{i}")) for i in range(n)]
    if outputs == "singletons":
        fb = mamdani({"x": _partition(peaks)}, {f"b{i}": single(c) for i, c in enumerate(centres)}, rules)
    else:  # the same triangle translated, PROD activation and SUM: a weighted mean of centroids
        outs = {f"b{i}": shape("triangle", c - 3, c, c + 3) for i, c in enumerate(centres)}
        fb = mamdani({"x": _partition(peaks)}, outs, rules, act="PROD", accu="SUM", rng=(-30, 30))
    c = fuzzyctl.compile(fb)
    ys = c.evaluate_batch({"x": np.linspace(peaks[0], peaks[-1], 400)})["y"]
    assert np.all(np.diff(ys) >= -1e-9 * (1 + np.abs(ys[1:])))


@pytest.mark.parametrize("and_op", sorted(AND_TO_OR))
def test_de_morgan_for_every_operator_pair(and_op: str) -> None:
    terms = {
        "x": {"g": shape("gaussian", 4, 2), "t": shape("triangle", 0, 3, 9)},
        "z": {"b": shape("bell", 5, 2, 1.5), "s": shape("sigmoid", 5, -1.2)},
    }
    rules = [
        rule("lhs", m.Not(and_(is_("x", "g"), is_("z", "b"))), then("y", "o")),
        rule("rhs", or_(is_("x", "g", negated=True), is_("z", "b", negated=True)), then("y", "o")),
        rule("lhs2", m.Not(or_(is_("x", "t"), is_("z", "s"))), then("y", "o")),
        rule("rhs2", and_(m.Not(is_("x", "t")), m.Not(is_("z", "s"))), then("y", "o")),
    ]
    c = fuzzyctl.compile(mamdani(terms, {"o": single(1.0)}, rules, and_op=and_op))
    for x, z in np.random.default_rng(0).uniform(0, 10, (200, 2)):
        e = c.explain({"x": float(x), "z": float(z)})
        assert e.rule("lhs").degree == pytest.approx(e.rule("rhs").degree, abs=1e-12)
        assert e.rule("lhs2").degree == pytest.approx(e.rule("rhs2").degree, abs=1e-12)
    assert c.plan.rules[0].condition.operand.op == and_op  # type: ignore[union-attr]
    assert c.plan.rules[1].condition.op == AND_TO_OR[and_op]  # type: ignore[union-attr]
