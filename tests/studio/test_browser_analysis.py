"""Recorder and analysis in the real browser, on the crane: the simulated run fills one
display and stops at its end (the transient stays in view), curves of one quantity on one
axis, the archive length of the manual, outputs "???" while a curve drives an input
(manual 6.7), the rotation step of the 3D display (5-45 degrees, manual 6.6), explain rows
labelled with the rule text under a chart above the fold, and the rule viewer driven by
its sliders.  Expected values: the engine (fuzzyctl.compile on the file), the file, or the
loop configuration."""

from __future__ import annotations

import tomllib
from pathlib import Path
from typing import Any

import pytest

import fuzzyctl
from tests.studio.browser import open_file, shot, tab


def trace(pg: Any, name: str) -> dict[str, Any]:
    data: dict[str, Any] = pg.evaluate(
        f"document.querySelector('#rec-chart').data.find((t) => t.name === {name!r})"
    )
    return data


def test_recorder_defaults_shared_axis_and_test_signals(page: Any, browser_project: Path) -> None:
    pg = page
    open_file(pg, "crane.fcl")
    tab(pg, "recorder")
    pg.wait_for_function("document.querySelector('#rec-source').value === 'sim'")
    pg.wait_for_selector("#rec-loop")
    # one display holds the whole run of the loop configuration; archive three displays
    duration = tomllib.loads((browser_project / "crane.toml").read_text())["duration"]
    assert float(pg.input_value("#rec-length")) == duration
    assert pg.input_value("#rec-speed") == "5"
    assert float(pg.input_value("#rec-archive")) == 3 * duration
    assert "archive 450 records" in pg.inner_text("#rec-sampling")
    pg.select_option("#rec-speed", "100")
    pg.click("#rec-start")
    # the recorder stops by itself at the end of the run, with all of it in view
    pg.wait_for_function(
        "document.querySelector('#status').textContent.includes('run is complete')", timeout=60000
    )
    assert pg.get_attribute("#view-recorder", "data-running") == "false"
    assert pg.evaluate("document.querySelector('#rec-chart').layout.xaxis.range") == [0, duration]
    position, target = trace(pg, "position"), trace(pg, "target")
    assert position["x"][0] == pytest.approx(0, abs=0.6) and position["x"][-1] == pytest.approx(
        duration, abs=0.6
    )
    # curves of one quantity (metres) share one axis by default: the target (30 m) and the
    # position at its end meet
    assert pg.is_checked("#rec-shared")
    assert abs(position["y"][-1] - target["y"][-1]) < 0.01
    pg.click('#rec-curves input[type="radio"] >> nth=4')  # the position's curve labels the axis
    assert "position" in pg.evaluate("document.querySelector('#rec-chart').layout.yaxis.title.text")
    assert "m" in pg.inner_text("#rec-cur-4")
    shot(pg, "27-recorder-shared-axis", doc=True)

    # test signals: the outputs are values while every input is a constant...
    pg.select_option("#rec-source", "test")
    pg.click("#rec-sig-distance")
    pg.select_option("#sig-kind", "constant")
    pg.fill("#sig-value", "8")
    pg.click("#sig-ok")
    pg.click("#rec-sig-angle")
    pg.select_option("#sig-kind", "zero")
    pg.click("#sig-ok")
    ctl = fuzzyctl.compile(fuzzyctl.load(browser_project / "crane.fcl"))
    expect = ctl.evaluate({"distance": 8, "angle": 0})["power"]
    pg.wait_for_selector('#rec-outputs-now [data-output="power"][data-value]')
    assert float(
        pg.get_attribute('#rec-outputs-now [data-output="power"]', "data-value") or "nan"
    ) == pytest.approx(expect)
    # ... and "???" as soon as a curve drives one (manual 6.7)
    pg.click("#rec-sig-distance")
    pg.select_option("#sig-kind", "triangle")
    pg.click("#sig-ok")
    pg.wait_for_function("document.querySelector('#rec-outputs-now').textContent.includes('power = ???')")
    # the archive length: 20 s of a 10 s display is 300 records of 1/15 s
    pg.fill("#rec-length", "10")
    pg.press("#rec-length", "Tab")
    pg.fill("#rec-archive", "20")
    pg.press("#rec-archive", "Tab")
    assert "archive 300 records" in pg.inner_text("#rec-sampling")
    pg.fill("#rec-archive", "100")  # at most about three displays
    pg.press("#rec-archive", "Tab")
    assert pg.input_value("#rec-archive") == "30"


def test_rotation_explain_and_rule_viewer(page: Any, browser_project: Path) -> None:
    pg = page
    open_file(pg, "crane.fcl")
    ctl = fuzzyctl.compile(fuzzyctl.load(browser_project / "crane.fcl"))
    # the rotation step of the manual: 5 to 45 degrees
    tab(pg, "surface")
    pg.wait_for_function("document.querySelector('#sf-chart').data")
    # tick labels of X and Y stay off the floor's corners, where they would stand on each other
    scene = pg.evaluate("document.querySelector('#sf-chart').layout.scene")
    for axis, name in (("xaxis", "distance"), ("yaxis", "angle")):
        lo, hi = scene[axis]["range"]
        ticks = scene[axis]["tickvals"]
        assert scene[axis]["title"]["text"] == name
        assert 2 <= len(ticks) <= 6
        assert all(lo + 0.04 * (hi - lo) < t < hi - 0.04 * (hi - lo) for t in ticks), (axis, lo, hi, ticks)
    pg.fill("#sf-rot-step", "60")
    pg.press("#sf-rot-step", "Tab")
    assert pg.input_value("#sf-rot-step") == "45"
    pg.click("#sf-rotate")
    pg.wait_for_function("document.querySelector('#sf-rot').value !== '45'")
    pg.click("#sf-rotate")
    assert (int(pg.input_value("#sf-rot")) - 45) % 45 == 0

    # explain: the chart first, in view; rows labelled with the rule's text
    tab(pg, "explain")
    pg.fill("#ex-in-distance", "8")
    pg.fill("#ex-in-angle", "2")
    expect = ctl.evaluate({"distance": 8, "angle": 2})["power"]
    pg.wait_for_function(f"Math.abs(+document.querySelector('#ex-chart').dataset.value - {expect}) < 1e-9")
    chart = pg.locator("#ex-chart").bounding_box()
    rules = pg.locator("#ex-rules").bounding_box()
    assert chart is not None and rules is not None
    assert chart["y"] + chart["height"] <= 900 and chart["y"] < rules["y"]
    first = pg.inner_text("#ex-rules tbody tr:first-child")
    assert "IF distance IS far AND angle IS neg_big THEN power IS pos_medium" in first
    shot(pg, "29-explain", doc=True)

    # the rule viewer: each rule's degree, the outputs at the bottom, moved by the sliders
    tab(pg, "ruleviewer")
    pg.wait_for_selector("#rv-table")
    assert pg.locator("#rv-table tbody tr").count() == 25 + 1
    pg.fill("#rv-in-distance", "5")
    pg.press("#rv-in-distance", "Enter")
    pg.fill("#rv-in-angle", "-3")
    pg.press("#rv-in-angle", "Enter")
    ctl.reset()
    expect = ctl.evaluate({"distance": 5, "angle": -3})["power"]
    pg.wait_for_function(
        "Math.abs(JSON.parse(document.querySelector('#view-ruleviewer').dataset.outputs || '{}').power"
        f" - {expect}) < 1e-9"
    )
    ctl.reset()
    explanation = ctl.explain({"distance": 5, "angle": -3})
    degrees = pg.evaluate(
        "[...document.querySelectorAll('#rv-table tbody tr:not(.total) td.deg')].map((e) => e.textContent)"
    )
    assert degrees == [f"{r.degree:.3f}" for r in explanation.rules]
    assert pg.locator("#rv-table tr.fired").count() == sum(1 for r in explanation.rules if r.degree > 0)
    # a click in the distance column moves the input there
    cell = pg.locator("#rv-table td.rv-in[data-var='distance'] svg >> nth=0").bounding_box()
    assert cell is not None
    pg.mouse.click(cell["x"] + cell["width"] * 0.75, cell["y"] + cell["height"] / 2)
    pg.wait_for_function("+document.querySelector('#rv-in-distance').value > 10")
    # ... to a value as an engineer writes it: a thousandth of the range (24 -> 0.01)
    clicked = pg.input_value("#rv-in-distance")
    assert len(clicked.partition(".")[2]) <= 2, clicked
    shot(pg, "28-rule-viewer", doc=True)
