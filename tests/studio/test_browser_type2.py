"""An interval type-2 system in the browser (docs/type2.md, "Studio"): the explain view and
the rule viewer with firing intervals and the type-reduced interval, the footprint of
uncertainty drawn between the upper and the lower curve, the scale and lags edited in
their fields and written back as FCL, an explicit lower function above the upper one
refused with the term's message.

Expected values are closed forms of MATLAB's lower function (scale * max(0, (upper - lag)
/ (1 - lag))) on examples/tipper_type2.fis, and the firing intervals worked by hand."""

from __future__ import annotations

import itertools
from typing import Any

import pytest

from tests.conftest import EXAMPLES
from tests.studio.browser import fcl_text, settle, shot, tab

FIS = EXAMPLES / "tipper_type2.fis"


def trace(pg: Any, name: str) -> dict[str, Any]:
    data: dict[str, Any] = pg.evaluate(
        f"(() => {{ const t = document.querySelector('#mf-chart').data.find((d) => d.name === '{name}');"
        " return t ? {x: [...t.x], y: [...t.y], fill: t.fill || null} : null; })()"
    )
    return data


def lower_at(tr: dict[str, Any], x: float) -> float:
    """The drawn lower curve at ``x`` (linear between its points)."""
    pts = list(zip(tr["x"], tr["y"], strict=True))
    for (x0, y0), (x1, y1) in itertools.pairwise(pts):
        if x0 <= x <= x1 and x1 > x0:
            return float(y0 + (y1 - y0) * (x - x0) / (x1 - x0))
    raise AssertionError(f"{x} outside the curve")


def rancid_upper(x: float) -> float:
    return max(0.0, min((x + 2) / 2, 1.0, (3 - x) / 2))


def test_footprint_drawn_edited_and_checked(page: Any) -> None:
    pg = page
    pg.set_input_files("#import-file", str(FIS))
    pg.wait_for_function("document.querySelector('#status').textContent.includes('imported')")
    settle(pg)

    # the check panel names the FIS as MATLAB does (mamfistype2: Type and TypeReductionMethod)
    system = pg.inner_text("#matlab-system")
    assert "'mamdanitype2'" in system and "'karnikmendel'" in system

    # explain at service 3, food 8: the firing intervals worked by hand (tests/engine)
    tab(pg, "explain")
    for name, value in (("service", "3"), ("food", "8")):
        pg.fill(f"#ex-in-{name}", value)
    pg.wait_for_function("(document.querySelector('#ex-chart').dataset.interval || '').length > 0")
    pg.wait_for_function(
        "(() => { const t = document.querySelector('#ex-rules tbody').textContent;"
        " return t.includes('0.250 … 0.400') && t.includes('0.300 … 0.500'); })()"
    )
    rules = pg.inner_text("#ex-rules tbody")
    assert "0.450 … 0.600" in rules and "0.300 … 0.500" in rules
    yl, yr = pg.evaluate("JSON.parse(document.querySelector('#ex-chart').dataset.interval)")
    value = float(pg.evaluate("document.querySelector('#ex-chart').dataset.value"))
    assert yl < value < yr and value == pytest.approx((yl + yr) / 2, rel=1e-12)

    # the rule viewer at the same point: firing intervals, lower activated sets, the interval
    tab(pg, "ruleviewer")
    for name, typed in (("service", "3"), ("food", "8")):
        pg.fill(f"#rv-in-{name}", typed)
        pg.press(f"#rv-in-{name}", "Enter")
    pg.wait_for_function(
        "document.querySelector('#rv-table tr[data-label=\"1\"] td.deg').textContent === '0.250 … 0.400'"
    )
    assert pg.locator("#rv-table .fill-out-lower").count() == 3  # one per fired rule
    assert pg.locator("#rv-table .fill-interval").count() == 1
    # both inputs applied (rule 1 reads service only: food may still be on its way)
    pg.wait_for_function(
        "v => { const o = document.querySelector('#view-ruleviewer').dataset.outputs;"
        " return !!o && Math.abs(JSON.parse(o).tip - v) <= 1e-9 * Math.abs(v); }",
        arg=value,
    )
    shown = pg.evaluate("JSON.parse(document.querySelector('#view-ruleviewer').dataset.outputs)")
    assert shown["tip"] == value
    shot(pg, "type2-ruleviewer")

    # the footprint of food.rancid: lower lags 0.1 (rising) and 0.3 (falling), scale 1
    tab(pg, "variable")
    pg.select_option("#var-select", "food")
    pg.select_option("#term-select", label="rancid")
    pg.wait_for_function(
        "(document.querySelector('#mf-chart').data || []).some((d) => d.name === 'rancid lower')"
    )
    assert trace(pg, "rancid footprint")["fill"] == "toself"
    lower = trace(pg, "rancid lower")
    for x in (-1.9, -1.5, -0.5, 0.5, 1.5, 2.0, 2.5, 2.9):
        lag = 0.1 if x < 0 else 0.3
        expected = max(0.0, (rancid_upper(x) - lag) / (1 - lag))
        assert lower_at(lower, x) == pytest.approx(expected, abs=1e-12)
    assert pg.input_value("#lower-kind") == "scale_lag"
    assert [pg.input_value(f"#lower-{k}") for k in ("scale", "lag-left", "lag-right")] == ["1", "0.1", "0.3"]

    # the scale edited: the lower curve's top follows, and the FCL says so
    pg.fill("#lower-scale", "0.5")
    pg.press("#lower-scale", "Enter")
    pg.wait_for_function(
        "Math.max(...document.querySelector('#mf-chart').data"
        ".find((d) => d.name === 'rancid lower').y) === 0.5"
    )
    lower = trace(pg, "rancid lower")
    assert lower_at(lower, -1.0) == pytest.approx(0.5 * (0.5 - 0.1) / 0.9, abs=1e-12)
    # a scale outside (0, 1] is refused in the field
    pg.fill("#lower-scale", "1.5")
    pg.press("#lower-scale", "Enter")
    pg.wait_for_function("document.querySelector('#status').textContent.includes('LowerScale is in (0, 1]')")
    assert "bad" in (pg.get_attribute("#lower-scale", "class") or "")
    assert "TRAPE -2 0 1 3 LOWER SCALE 0.5 LAG 0.1 0.3;" in fcl_text(pg)

    # an explicit lower function: the upper at half height, then widened past the upper
    tab(pg, "variable")
    pg.select_option("#var-select", "food")
    pg.select_option("#term-select", label="rancid")
    pg.select_option("#lower-kind", "mf")
    pg.wait_for_selector("#lower-param-0")
    assert [pg.input_value(f"#lower-param-{k}") for k in ("0", "1", "2", "3", "height")] == [
        "-2",
        "0",
        "1",
        "3",
        "0.5",
    ]
    pg.fill("#lower-param-0", "-3")
    pg.press("#lower-param-0", "Enter")
    # at x = -2 the upper is 0 and the lower 0.5 * 1/3: the term's message says where
    pg.wait_for_function("document.querySelector('#lower-diags').textContent.includes('exceeds the upper')")
    text = pg.inner_text("#lower-diags")
    assert "food.rancid" in text and "(0.166667)" in text and "at -2" in text
