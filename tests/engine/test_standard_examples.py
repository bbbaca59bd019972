"""The worked examples of the seeds: IEC 61131-7 figure 7 (computed by hand) and the
Siemens S7 Fuzzy Control manual, sections 1.4 and 1.5."""

from __future__ import annotations

import pytest

import fuzzyctl
from fuzzyctl import model as m
from tests.engine.builders import and_, figure7, is_, mamdani, pts, rule, shape, single, then


@pytest.mark.parametrize(
    ("temp", "pressure", "expected"),
    [
        # cold=1/2 hot=1/2 low=1/2 high=1/2: inlet .5, closed max(.8*.5, .5), drainage .5
        (15.0, 75.0, 0.0),
        # cold=17/24 hot=7/24 low=7/8 high=1/8: inlet 17/24, closed max(.8/8, 7/24), drainage 1/8
        (10.0, 60.0, (100 * 17 / 24 - 100 / 8) / (17 / 24 + 7 / 24 + 1 / 8)),
        # cold=7/8 hot=1/8 low=1/4 high=3/4: inlet 1/4, closed max(.8*3/4, 1/8), drainage 1/8;
        # without the WITH 0.8 the result would be 12.5/1.125
        (6.0, 85.0, (25.0 - 12.5) / (0.25 + 0.6 + 0.125)),
        # beyond the points the degrees stay constant (5.2.2): cold=1, high=1: only rule 2
        (0.0, 100.0, 0.0),
        (3.0, 55.0, 100.0),
        (27.0, 95.0, -100.0),
    ],
)
def test_figure7_by_hand(temp: float, pressure: float, expected: float) -> None:
    c = fuzzyctl.compile(figure7())
    assert c.evaluate({"temp": temp, "pressure": pressure})["valve"] == pytest.approx(expected, abs=1e-12)
    assert c.evaluate_batch({"temp": [temp], "pressure": [pressure]})["valve"][0] == pytest.approx(
        expected, abs=1e-12
    )


def test_figure7_explanation() -> None:
    e = fuzzyctl.compile(figure7()).explain({"temp": 6.0, "pressure": 85.0})
    degrees = {(t.variable, t.term): t.degree for t in e.terms}
    assert degrees[("temp", "cold")] == pytest.approx(7 / 8)
    assert degrees[("pressure", "high")] == pytest.approx(3 / 4)
    r2 = e.rule("2")
    assert r2.degree == pytest.approx(0.75)
    assert r2.conclusions[0].weight == 0.8
    assert dict(e.output("valve").singletons) == pytest.approx({-100.0: 0.125, 0.0: 0.6, 100.0: 0.25})


def _siemens(
    method: str = "COGS",
    valve: dict[str, m.MembershipFunction] | None = None,
    act: str | None = None,
    accu: str | None = None,
) -> m.FunctionBlock:
    # Terms chosen so that temperature 50 and pressure 2.0 give the manual's degrees (its
    # figure 1-7 is lost in the text): cold 0, warm .95, hot .35; low .25, medium .85, high 0.
    return mamdani(
        {
            "temperature": {
                "cold": pts((20, 1), (40, 0)),
                "warm": shape("triangle", 30, 49, 69),
                "hot": pts((43, 0), (63, 1)),
            },
            "pressure": {
                "low": pts((1.25, 1), (2.25, 0)),
                "medium": shape("triangle", 1, 1.85, 2.85),
                "high": pts((2.5, 0), (3.5, 1)),
            },
        },
        valve or {"closed": single(0.0), "half_open": single(50.0), "open": single(100.0)},
        [
            rule(
                "01", and_(is_("temperature", "warm"), is_("pressure", "medium")), then("valve", "half_open")
            ),
            rule("02", and_(is_("temperature", "hot"), is_("pressure", "low")), then("valve", "open")),
        ],
        out="valve",
        method=method,
        act=act,
        accu=accu,
        rng=(0, 100) if valve else None,
    )


def test_siemens_1_4_rule_degrees_and_singletons() -> None:
    c = fuzzyctl.compile(_siemens())
    e = c.explain({"temperature": 50.0, "pressure": 2.0})
    assert e.rule("01").degree == pytest.approx(0.85)  # warm .95 AND medium .85
    assert e.rule("02").degree == pytest.approx(0.25)  # hot .35 AND low .25
    # x_S' = (mu_A x_A + mu_B x_B) / (mu_A + mu_B)
    assert e.values["valve"] == pytest.approx((0.85 * 50 + 0.25 * 100) / (0.85 + 0.25))


def _trap_area_moment(a: float, b: float, c: float, d: float) -> tuple[float, float]:
    """Area and first moment of a trapezoid by elementary geometry (three pieces)."""
    pieces = [((a, b), "up"), ((b, c), "flat"), ((c, d), "down")]
    area = moment = 0.0
    for (x0, x1), kind in pieces:
        w = x1 - x0
        if w == 0:
            continue
        if kind == "flat":
            area += w
            moment += w * (x0 + x1) / 2
        else:
            area += w / 2
            cx = x0 + 2 * w / 3 if kind == "up" else x0 + w / 3
            moment += w / 2 * cx
    return area, moment


def test_siemens_1_4_weighting_by_multiplication() -> None:
    """PROD activation with summed areas: x_S = (mu_A M_A0 + mu_B M_B0) / (mu_A A_A0 + mu_B A_B0)."""
    half = (25.0, 45.0, 55.0, 75.0)
    full = (60.0, 80.0, 100.0, 100.0)
    fb = _siemens(
        "COG",
        {"half_open": shape("trapezoid", *half), "open": shape("trapezoid", *full)},
        act="PROD",
        accu="SUM",
    )
    value = fuzzyctl.compile(fb).evaluate({"temperature": 50.0, "pressure": 2.0})["valve"]
    (a1, m1), (a2, m2) = _trap_area_moment(*half), _trap_area_moment(*full)
    assert value == pytest.approx((0.85 * m1 + 0.25 * m2) / (0.85 * a1 + 0.25 * a2), rel=1e-12)


def test_siemens_1_5_rule_without_if_part_acts_with_degree_1() -> None:
    fb = mamdani(
        {"x": {"a": pts((0, 1), (10, 0))}},
        {"lo": single(10.0), "hi": single(90.0)},
        [rule("1", is_("x", "a"), then("y", "lo")), rule("2", None, then("y", "hi"))],
    )
    c = fuzzyctl.compile(fb)
    assert c.evaluate({"x": 10.0})["y"] == 90.0  # rule 1 is 0, rule 2 always 1
    assert c.evaluate({"x": 0.0})["y"] == pytest.approx(50.0)


def test_siemens_1_5_no_rule_active_keeps_the_last_value_starting_at_zero() -> None:
    fb = mamdani(
        {"x": {"a": pts((0, 1), (10, 0))}}, {"lo": single(10.0)}, [rule("1", is_("x", "a"), then("y", "lo"))]
    )
    c = fuzzyctl.compile(fb)  # no DEFAULT: NC
    assert c.evaluate({"x": 20.0})["y"] == 0.0  # nothing fired yet
    assert c.evaluate({"x": 5.0})["y"] == 10.0
    assert c.evaluate({"x": 20.0})["y"] == 10.0  # kept
    c.reset()
    assert c.evaluate({"x": 20.0})["y"] == 0.0
