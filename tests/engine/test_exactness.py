"""Closed-form cases: the exact defuzzifiers reproduce results computed by hand, to rounding."""

from __future__ import annotations

import math

import numpy as np
import pytest

import fuzzyctl
from tests.engine.builders import is_, mamdani, pts, rule, shape, then

ONE = pts((0, 1), (1, 1))  # degree 1 everywhere


def _controller(out_terms: dict, rules: list, **kw: object) -> fuzzyctl.engine.Controller:  # type: ignore[type-arg]
    ins = {"x": {"one": ONE, "h": pts((0, 0), (1, 1))}}
    return fuzzyctl.compile(mamdani(ins, out_terms, rules, **kw))  # type: ignore[arg-type]


def _trapezoid_centroid(a: float, b: float, c: float, d: float, h: float) -> float:
    """Centroid of the clipped triangle/trapezoid from the three elementary pieces."""
    parts = [
        ((b - a) * h / 2, a + 2 * (b - a) / 3),
        ((c - b) * h, (b + c) / 2),
        ((d - c) * h / 2, c + (d - c) / 3),
    ]
    area = sum(p[0] for p in parts)
    return sum(p[0] * p[1] for p in parts) / area


@pytest.mark.parametrize("h", [0.1, 0.35, 0.8, 1.0])
def test_clipped_triangle(h: float) -> None:
    a, b, c = 1.0, 2.0, 6.0
    for method, want in [
        ("COG", _trapezoid_centroid(a, a + h * (b - a), c - h * (c - b), c, h)),
        ("LM", a + h * (b - a)),
        ("RM", c - h * (c - b)),
        ("MOM", (a + h * (b - a) + c - h * (c - b)) / 2),
    ]:
        ctl = _controller(
            {"t": shape("triangle", a, b, c)},
            [rule("1", is_("x", "h"), then("y", "t"))],
            method=method,
            rng=(0, 10),
        )
        assert ctl.evaluate({"x": h})["y"] == pytest.approx(want, rel=1e-13, abs=1e-13), method
        assert ctl.evaluate_batch({"x": [h]})["y"][0] == pytest.approx(want, rel=1e-13, abs=1e-13), method


def test_coa_of_a_falling_triangle() -> None:
    ctl = _controller(
        {"t": shape("triangle", 0, 0, 1)}, [rule("1", is_("x", "one"), then("y", "t"))], method="COA"
    )
    assert ctl.evaluate({"x": 0.5})["y"] == pytest.approx(1 - 1 / math.sqrt(2), rel=1e-14)
    assert ctl.evaluate_batch({"x": [0.5]})["y"][0] == pytest.approx(1 - 1 / math.sqrt(2), rel=1e-14)


def test_max_of_overlapping_triangles() -> None:
    terms = {"p": shape("triangle", 0, 1, 2), "q": shape("triangle", 1, 2, 4)}
    rules = [rule("1", is_("x", "one"), then("y", "p")), rule("2", is_("x", "one"), then("y", "q"))]
    # mu: up on [0,1]; max(2-x, x-1) on [1,2] (V with its bottom 0.5 at 1.5); down on [2,4]
    area = 0.5 + 0.75 + 1.0
    left_v = (1.5 - 1) * (1 + 0.5) / 2  # area of 2 - x on [1, 1.5]
    right_v = left_v  # x - 1 on [1.5, 2]
    m_left = (1.5 - 1) * (1 * (2 * 1 + 0.5) + 1.5 * (1 + 2 * 0.5)) / 6
    m_right = (2 - 1.5) * (1.5 * (2 * 0.5 + 1) + 2 * (0.5 + 2 * 1)) / 6
    moment = 2 / 3 * 0.5 + m_left + m_right + 1.0 * (2 + 2 / 3)
    assert left_v + right_v == pytest.approx(0.75)
    for method, want in [("COG", moment / area), ("LM", 1.0), ("RM", 2.0), ("MOM", 1.5)]:
        ctl = _controller(terms, rules, method=method, rng=(0, 4))
        assert ctl.evaluate({"x": 0.5})["y"] == pytest.approx(want, rel=1e-13), method


def test_bsum_clipped_at_one() -> None:
    # two unit plateaus overlapping on [2, 3]: the bounded sum is 1 there, not 2
    terms = {"p": shape("trapezoid", 0, 0, 3, 3), "q": shape("trapezoid", 2, 2, 6, 6)}
    rules = [rule("1", is_("x", "one"), then("y", "p")), rule("2", is_("x", "one"), then("y", "q"))]
    ctl = _controller(terms, rules, accu="BSUM", rng=(0, 6))
    assert ctl.evaluate({"x": 0.5})["y"] == pytest.approx(3.0, rel=1e-14)
    summed = _controller(terms, rules, accu="SUM", rng=(0, 6))
    assert summed.evaluate({"x": 0.5})["y"] == pytest.approx((4.5 + 16) / 7, rel=1e-14)


def test_probor_is_integrated_exactly() -> None:
    # f1 = x/2 and f2 = 0.5 (1 - x/2) on [0, 2]: probor = 0.5 + x^2/8
    terms = {"up": shape("triangle", 0, 2, 2), "down": shape("triangle", 0, 0, 2)}
    rules = [rule("1", is_("x", "one"), then("y", "up")), rule("2", is_("x", "h"), then("y", "down"))]
    cog = _controller(terms, rules, accu="PROBOR", act="PROD", rng=(0, 2))
    assert cog.evaluate({"x": 0.5})["y"] == pytest.approx(1.5 / (4 / 3), rel=1e-13)
    assert cog.evaluate_batch({"x": [0.5]})["y"][0] == pytest.approx(1.125, rel=1e-13)
    coa = _controller(terms, rules, accu="PROBOR", act="PROD", rng=(0, 2), method="COA")
    # s/2 + s^3/24 = 2/3  <=>  s^3 + 12 s - 16 = 0
    root = next(r.real for r in np.roots([1, 0, 12, -16]) if abs(r.imag) < 1e-12)
    assert coa.evaluate({"x": 0.5})["y"] == pytest.approx(root, rel=1e-12)


def test_smooth_centroid_within_quadrature_tolerance() -> None:
    # a Gaussian on [m - s, m + 5 s]: the mean of a truncated normal
    m_, s = 3.0, 0.7
    lo, hi = m_ - s, m_ + 5 * s
    ctl = _controller(
        {"g": shape("gaussian", m_, s)}, [rule("1", is_("x", "one"), then("y", "g"))], rng=(lo, hi)
    )

    def phi(z: float) -> float:
        return math.exp(-z * z / 2) / math.sqrt(2 * math.pi)

    def cdf(z: float) -> float:
        return 0.5 * (1 + math.erf(z / math.sqrt(2)))

    want = m_ + s * (phi(-1) - phi(5)) / (cdf(5) - cdf(-1))
    assert ctl.evaluate({"x": 0.5})["y"] == pytest.approx(want, rel=1e-10)


def test_clipped_smooth_plateau_edges() -> None:
    # min(h, gaussian): LM/RM where the Gaussian crosses h
    m_, s, h = 5.0, 1.0, 0.4
    for method, sign in [("LM", -1), ("RM", 1)]:
        ctl = _controller(
            {"g": shape("gaussian", m_, s)},
            [rule("1", is_("x", "h"), then("y", "g"))],
            rng=(0, 10),
            method=method,
        )
        want = m_ + sign * s * math.sqrt(-2 * math.log(h))
        assert ctl.evaluate({"x": h})["y"] == pytest.approx(want, abs=1e-9)
