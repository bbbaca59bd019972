"""Issue 27 points 9-13 in the real browser: the recorder's axis is the selected curve's
(curves of one quantity on it, in its unit) and its values follow the running source; the
explain chart labels its singletons with their terms and has no line that reads as a fired
singleton; Save leaves the user's file as it was (level, `convert`), the view settings go
beside it; a MATLAB file opens on its rules with a [System] check panel; a malformed file
opens at its first error with the other views off; undo/redo for edits; readable rule
numbers over the effectiveness bars.  Expected values: the engine on the file, the loop
configuration, the file's own terms, the checker on the saved text."""

from __future__ import annotations

import json
import shutil
import tomllib
from pathlib import Path
from typing import Any

import pytest

import fuzzyctl
from fuzzyctl import formats
from fuzzyctl.studio.analysis import check_text
from tests.conftest import EXAMPLES
from tests.studio.browser import cell_text, open_file, rule_mode, set_cell, settle, shot, tab

CELL = 'document.querySelector(\'#rule-table td.cell[data-rule="0"][data-var="power"]\')'


def chart(pg: Any, selector: str) -> dict[str, Any]:
    data: dict[str, Any] = pg.evaluate(
        f"(() => {{ const c = document.querySelector({selector!r});"
        " return { data: c.data, layout: c.layout }; })()"
    )
    return data


def test_recorder_axis_is_the_selected_curves_and_values_follow_the_source(
    page: Any, browser_project: Path
) -> None:
    pg = page
    open_file(pg, "crane.fcl")
    tab(pg, "recorder")
    pg.wait_for_function("document.querySelector('#rec-source').value === 'sim'")
    pg.wait_for_selector("#rec-loop")
    pg.select_option("#rec-speed", "100")
    pg.click("#rec-start")
    pg.wait_for_function(
        "document.querySelector('#status').textContent.includes('run is complete')", timeout=60000
    )
    pg.click('#rec-curves input[type="radio"] >> nth=0')  # fb.distance: "target - position", metres
    axis = json.loads(pg.get_attribute("#rec-chart", "data-axis") or "{}")
    assert axis["curve"] == "fb.distance" and axis["unit"] == "m"
    assert {"fb.distance", "target", "position"} <= set(axis["curves"])
    # read off the shown axis, the target is the loop configuration's setpoint
    target = tomllib.loads((browser_project / "crane.toml").read_text())["setpoints"]["target"]
    traces = {t["name"]: t for t in chart(pg, "#rec-chart")["data"]}
    lo, hi = axis["lo"], axis["hi"]
    assert traces["target"]["y"][-1] * (hi - lo) + lo == pytest.approx(target, abs=1e-9)
    # curves of another quantity (degrees, percent) are dotted: the labels are not theirs
    assert traces["target"]["line"]["dash"] == "solid" and traces["fb.angle"]["line"]["dash"] == "dot"
    # and fb.distance is target - position at every sample, on that same axis
    for i in range(0, len(traces["position"]["y"]), 17):
        d, t, p = (traces[n]["y"][i] * (hi - lo) + lo for n in ("fb.distance", "target", "position"))
        assert d == pytest.approx(t - p, abs=1e-6 * (hi - lo))
    # the rule numbers above the bars: each label names the rules of its bar (or stack)
    pg.wait_for_function("document.querySelector('#rec-bars').dataset.labels")
    marks = json.loads(pg.get_attribute("#rec-bars", "data-labels") or "[]")
    rules = dict(json.loads(pg.get_attribute("#rec-bars", "data-rules") or "[]"))
    assert marks and all(all(rules[r] > 0 for r in m["text"].split(", ")) for m in marks)
    bars = chart(pg, "#rec-bars")["data"]
    numbers = next(t for t in bars if t.get("name") == "rules")
    assert (
        bars[0]["textposition"] == "none" and numbers["mode"] == "text" and numbers["textfont"]["size"] >= 11
    )
    shot(pg, "32-recorder-axis-per-quantity", doc=True)

    # test signals: the values shown are the running source's, never the finished crane run
    pg.select_option("#rec-source", "test")
    assert pg.eval_on_selector_all("#rec-values td[data-value]", "(x) => x.length") == 0
    pg.click("#rec-start")
    pg.wait_for_function("document.querySelectorAll('#rec-values td[data-value]').length >= 4")
    shown = pg.evaluate(
        "Object.fromEntries([...document.querySelectorAll('#rec-values td[data-value]')]"
        ".map((td) => [td.id.slice(8), parseFloat(td.dataset.value)]))"
    )
    pg.click("#rec-stop")
    assert "target" not in shown and "fb_distance" not in shown
    ctl = fuzzyctl.compile(fuzzyctl.load(browser_project / "crane.fcl"))
    expect = ctl.evaluate({"distance": shown["distance"], "angle": shown["angle"]})["power"]
    assert shown["power"] == pytest.approx(expect, abs=1e-9)
    assert shown["power"] != 0  # the inputs at the middle of their ranges, as the buttons say


def test_explain_labels_singletons_by_term_and_draws_no_zero_line(page: Any, browser_project: Path) -> None:
    pg = page
    open_file(pg, "crane.fcl")
    tab(pg, "explain")
    pg.fill("#ex-in-distance", "8")
    pg.fill("#ex-in-angle", "2")
    doc = fuzzyctl.load(browser_project / "crane.fcl")
    expect = fuzzyctl.compile(doc).evaluate({"distance": 8, "angle": 2})["power"]
    pg.wait_for_function(
        f"Math.abs(parseFloat(document.querySelector('#ex-chart').dataset.value) - {expect}) < 1e-9"
    )
    pg.wait_for_function("(document.querySelector('#ex-chart').layout || {}).annotations")
    c = chart(pg, "#ex-chart")
    assert c["layout"]["xaxis"]["zeroline"] is False
    # no trace stands at degree 0 only (an unfired singleton drawn as a line at 0)
    assert all(any(y and y > 0 for y in t["y"]) for t in c["data"] if t["name"] not in ("result",))
    terms = {t.name: t.mf.value for t in doc.main.defuzzify_block("power").terms}  # type: ignore[union-attr]
    labels = json.loads(pg.get_attribute("#ex-chart", "data-labels") or "[]")
    assert labels
    for mark in labels:
        name = mark["text"].split(" ")[0]
        assert terms[name] == pytest.approx(mark["x"])
    assert f"power = {expect:.1f}" in c["layout"]["annotations"][0]["text"]
    shot(pg, "33-explain-singletons", doc=True)


def test_save_keeps_the_file_basic_and_convertible(page: Any, browser_project: Path) -> None:
    pg = page
    open_file(pg, "crane.fcl")
    tab(pg, "recorder")
    pg.uncheck("#rec-shared")  # a view setting
    pg.click("#btn-saveas")
    pg.fill("#saveas-path", "kept.fcl")
    pg.click("#saveas-ok")
    pg.wait_for_function("document.querySelector('#status').textContent.includes('saved kept.fcl')")
    text = (browser_project / "kept.fcl").read_text()
    original = (browser_project / "crane.fcl").read_text()
    assert "OPTIONS" not in text
    assert check_text(text, "kept.fcl").level == check_text(original, "crane.fcl").level == "Basic"
    assert formats.convert(fuzzyctl.load(browser_project / "kept.fcl"), "fll") == formats.convert(
        fuzzyctl.load(browser_project / "crane.fcl"), "fll"
    )
    side = json.loads((browser_project / ".fuzzyctl-studio" / "kept.fcl.json").read_text())
    assert side["recorder"]["shared"] is False
    pg.reload()
    pg.wait_for_selector("body[data-ready=true]")
    open_file(pg, "kept.fcl")
    tab(pg, "recorder")
    assert not pg.is_checked("#rec-shared")


def test_matlab_file_opens_on_its_rules(page: Any, browser_project: Path) -> None:
    pg = page
    shutil.copy(EXAMPLES / "tipper.fis", browser_project / "tipper.fis")
    pg.click("#btn-open")
    pg.select_option("#open-list", "tipper.fis")
    pg.click("#open-ok")
    pg.wait_for_function("document.querySelector('#status').textContent.includes('imported tipper.fis')")
    settle(pg)
    tab(pg, "rules")
    rules = fuzzyctl.load(browser_project / "tipper.fis").main.rule_blocks[0].rules
    assert pg.get_attribute("#view-rules", "data-mode") == "rows"  # the matrix holds 0 of 3
    assert pg.eval_on_selector_all("#rule-table tbody tr", "(x) => x.length") == len(rules) == 3
    system = pg.inner_text("#matlab-system")
    for key, value in (("AndMethod", "'min'"), ("OrMethod", "'max'"), ("DefuzzMethod", "'centroid'")):
        assert key in system and value in system
    assert "gaussmf" in pg.inner_text("#level-detail") and "trapmf" in pg.inner_text("#level-detail")
    assert not pg.is_visible("#level-detail ul.features")  # the conformance items: one click away
    shot(pg, "30-matlab-rules", doc=True)


def test_malformed_file_opens_at_its_first_error_then_undo_redo(
    page: Any, browser_project: Path, request: Any
) -> None:
    pg = page
    bad = (EXAMPLES / "crane.fcl").read_text().replace("TERM zero :=", "TERM zero = ", 1)
    (browser_project / "bad.fcl").write_text(bad)
    first = next(d for d in check_text(bad, "bad.fcl").to_dict()["diagnostics"] if d["severity"] == "error")
    pg.click("#btn-open")
    pg.select_option("#open-list", "bad.fcl")
    pg.click("#open-ok")
    pg.wait_for_function("document.querySelector('#status').textContent.includes('bad.fcl has errors')")
    assert not pg.is_hidden("#view-text")
    start = pg.eval_on_selector("#code-input", "(e) => e.selectionStart")
    assert bad[:start].count("\n") + 1 == first["line"]
    for view in ("project", "rules", "surface", "recorder", "explain"):
        assert pg.is_disabled(f'[role=tab][data-view="{view}"]')
        assert "errors" in (pg.get_attribute(f'[role=tab][data-view="{view}"]', "title") or "")
    assert "1 error" in pg.inner_text("#check-badge")
    shot(pg, "31-malformed-file", doc=True)

    # undo / redo of an edit (a rule cell), by the keys
    open_file(pg, "crane.fcl")  # nothing was edited: no "discard?"
    assert not pg.is_disabled('[role=tab][data-view="rules"]')
    rule_mode(pg, "rows")
    before = fuzzyctl.load(browser_project / "crane.fcl").main.rule_blocks[0].rules[0].conclusions[0].term
    changed = "zero" if before != "zero" else "pos_high"
    set_cell(pg, 0, "power", changed)
    settle(pg)
    pg.click("#rule-count")  # focus off the cell's field: the keys go to the studio
    pg.keyboard.press("Control+z")
    pg.wait_for_function(f"!{CELL}.textContent.includes('{changed}')")
    assert cell_text(pg, 0, "power") == before
    pg.keyboard.press("Control+y")
    pg.wait_for_function(f"{CELL}.textContent.includes('{changed}')")
    assert cell_text(pg, 0, "power") == changed
    pg.click("#btn-undo")
    pg.wait_for_function(f"!{CELL}.textContent.includes('{changed}')")
    settle(pg)
    assert pg.is_enabled("#btn-redo")
