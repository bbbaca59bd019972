"""The rest of the studio in a real browser: the input/output editor (the manual's two
range questions, terms inserted, renamed and deleted, zoom, singletons dragged as lines,
keyboard moves, diagnostics next to the term), the rule table's insert/delete/compress
and the FCL text editor on the same model (highlighting, live diagnostics), the 3D
display's family sliders, rotation and 4D animation, explain, the recorder's test
signals, display length limits, archive scroll bar and rule-effectiveness bars, import
and export from the browser, and keyboard shortcuts.

Expected values come from the engine on the text the studio shows, or closed forms."""

from __future__ import annotations

import json
from pathlib import Path
from typing import Any

import pytest

import fuzzyctl
from tests.conftest import data_path, shared_path
from tests.studio.browser import (
    cell_text,
    fcl_text,
    new_project,
    open_file,
    reading,
    rule_mode,
    set_cell,
    settle,
    shot,
    surface_z,
    tab,
)


def points(pg: Any) -> list[float]:
    """The x column of the points table (the selected term)."""
    xs: list[float] = pg.evaluate(
        "[...document.querySelectorAll('#points-table input[aria-label$=\" x\"]')].map((e) => +e.value)"
    )
    return xs


def term_names(pg: Any) -> list[str]:
    names: list[str] = pg.locator("#term-select option").all_inner_texts()
    return names


def set_range(pg: Any, lo: float, hi: float) -> None:
    pg.fill("#var-min", str(lo))
    pg.fill("#var-max", str(hi))
    pg.click("#var-range-apply")


def x_span(pg: Any) -> float:
    span: float = pg.evaluate(
        "(() => { const r = document.querySelector('#mf-chart')._fullLayout.xaxis.range;"
        " return r[1] - r[0]; })()"
    )
    return span


def test_variable_editor(page: Any) -> None:
    pg = page
    new_project(pg, "editor", 2, 1)
    # a click on the output in the block diagram opens its editor
    pg.click('#diagram [data-id="var:output1"]')
    pg.wait_for_selector("#view-variable:not([hidden])")
    assert pg.input_value("#var-name") == "output1"
    tab(pg, "variable")
    pg.select_option("#var-select", "input1")
    assert term_names(pg) == ["n_big", "n_small", "zero", "p_small", "p_big"]
    assert points(pg) == [-100, -50]

    # the range grows: "Should the membership functions be adjusted to the new range?"
    set_range(pg, -200, 200)
    pg.wait_for_selector("#dlg-confirm[open]")
    assert "adjusted to the new range" in pg.inner_text("#confirm-body")
    pg.click("#confirm-yes")
    settle(pg)
    assert points(pg) == [-200, -100]
    # it grows again, answered No: the points stay where they are
    set_range(pg, -400, 400)
    pg.click("#confirm-no")
    settle(pg)
    assert points(pg) == [-200, -100]
    assert pg.input_value("#var-min") == "-400"
    # it shrinks below the points: "There are some points outside the selected range"
    set_range(pg, -50, 50)
    pg.wait_for_selector("#dlg-confirm[open]")
    assert "points outside" in pg.inner_text("#confirm-body")
    pg.click("#confirm-ok")
    settle(pg)
    assert points(pg) == [-25, -12.5]  # x -> -50 + (x + 400) * 100 / 800
    # the range is saved with the project, and the engine sees the variable's range
    text = fcl_text(pg)
    assert fuzzyctl.compile(fuzzyctl.load(text)) is not None
    tab(pg, "variable")

    # zoom: each step halves the visible span; 1:1 shows the whole range
    assert x_span(pg) == pytest.approx(100)
    pg.click("#zoom-in")
    pg.click("#zoom-in")
    assert x_span(pg) == pytest.approx(25)
    pg.click("#zoom-reset")
    assert x_span(pg) == pytest.approx(100)

    # terms: insert one, rename it, delete it
    pg.click("#term-insert")
    settle(pg)
    assert term_names(pg)[-1] == "MBF_6"
    pg.fill("#term-name", "extra")
    pg.press("#term-name", "Tab")
    settle(pg)
    assert term_names(pg)[-1] == "extra"
    assert "TERM extra :=" in fcl_text(pg)
    tab(pg, "variable")
    pg.click("#term-delete")
    settle(pg)
    assert "extra" not in term_names(pg)

    # a rule uses zero; renaming the term renames it in the rule
    rule_mode(pg, "rows")
    pg.click("#rule-append")
    set_cell(pg, 0, "input1", "zero")
    set_cell(pg, 0, "output1", "p_large")
    settle(pg)
    tab(pg, "variable")
    pg.select_option("#var-select", "input1")
    pg.select_option("#term-select", label="zero")
    pg.fill("#term-name", "middle")
    pg.press("#term-name", "Tab")
    settle(pg)
    assert "IF input1 IS middle THEN output1 IS p_large" in fcl_text(pg)

    # a point moved past its neighbour: the check's error shows next to the term and
    # on its input in the diagram
    tab(pg, "variable")
    pg.select_option("#term-select", label="middle")
    assert points(pg) == [-12.5, 0, 12.5]
    pg.fill('#points-table [aria-label="point 1 x"]', "10")
    pg.press('#points-table [aria-label="point 1 x"]', "Enter")
    pg.wait_for_selector("#var-diags li.error")
    assert "ascending" in pg.inner_text("#var-diags")
    assert pg.inner_text("#check-badge") == "1 error(s)"
    shot(pg, "11-term-diagnostic")
    tab(pg, "project")
    assert pg.locator('#diagram [data-id="var:input1"] .mark-text').text_content() == "1"
    tab(pg, "variable")
    pg.select_option("#term-select", label="middle")
    pg.fill('#points-table [aria-label="point 1 x"]', "-12.5")
    pg.press('#points-table [aria-label="point 1 x"]', "Enter")
    pg.wait_for_function("document.querySelector('#check-badge').textContent.startsWith('OK')")

    # keyboard: focus the chart, Up selects the next point, Right moves it by 1 % of the view
    pg.focus("#mf-chart")
    pg.keyboard.press("ArrowUp")
    pg.keyboard.press("ArrowRight")
    settle(pg)
    assert points(pg) == [-12.5, 1, 12.5]

    # an output singleton is a line: grabbed low on the line and dragged to 40
    pg.select_option("#var-select", "output1")
    pg.select_option("#term-select", label="zero")
    line = pg.evaluate("document.querySelector('#mf-chart').data.find((t) => t.name === 'zero')")
    assert line["x"] == [0, 0] and line["y"] == [0, 1]
    box = pg.locator("#mf-chart").bounding_box()
    x0, x40, y = pg.evaluate(
        "(() => { const l = document.querySelector('#mf-chart')._fullLayout;"
        " return [l.xaxis.l2p(0) + l.xaxis._offset, l.xaxis.l2p(40) + l.xaxis._offset,"
        " l.yaxis.l2p(0.25) + l.yaxis._offset]; })()"
    )
    pg.mouse.move(box["x"] + x0, box["y"] + y)
    pg.mouse.down()
    for k in range(1, 9):
        pg.mouse.move(box["x"] + x0 + (x40 - x0) * k / 8, box["y"] + y)
    pg.mouse.up()
    settle(pg)
    moved = float(pg.input_value("#param-0"))
    assert 38 <= moved <= 42, moved
    assert f"TERM zero := {moved:g};" in fcl_text(pg).replace(".0;", ";")
    shot(pg, "12-singleton-dragged")


def test_rule_table_and_text_editor_share_the_model(page: Any) -> None:
    pg = page
    new_project(pg, "table", 2, 1)
    rule_mode(pg, "rows")
    for j, (a, y) in enumerate([("n_big", "n_large"), ("zero", "zero"), ("p_big", "p_large")]):
        pg.click("#rule-append")
        set_cell(pg, j, "input1", a)
        set_cell(pg, j, "output1", y)
    # insert a blank rule before the second one: an incomplete rule is not FCL yet
    pg.click('#rule-table th[data-rule="1"]')
    pg.click("#rule-insert")
    assert pg.locator("#rule-table th.rule-head").count() == 4
    assert "incomplete rule" in pg.inner_text("#rule-diags")
    settle(pg)
    text = fcl_text(pg)
    assert text.count("RULE ") == 3
    # delete the rule on "zero" (now the third column), then compress: renumbered 1, 2
    tab(pg, "rules")
    pg.click('#rule-table th[data-rule="2"]')
    pg.click("#rule-delete")
    pg.click("#rule-compress")
    settle(pg)
    assert pg.locator("#rule-table th.rule-head").all_inner_texts() == ["1", "2"]
    text = fcl_text(pg)
    assert "RULE 1 : IF input1 IS n_big THEN output1 IS n_large;" in text
    assert "RULE 2 : IF input1 IS p_big THEN output1 IS p_large;" in text
    assert "input1 IS zero" not in text
    assert pg.inner_text("#level-badge") == "level: Basic"
    # highlighting: keywords, names, numbers
    keywords = pg.locator("#code-highlight .tk-keyword").all_inner_texts()
    assert {"FUNCTION_BLOCK", "RULEBLOCK", "END_RULEBLOCK", "IF", "THEN"} <= set(keywords)
    assert pg.locator("#code-highlight .tk-number").count() > 10

    # a syntax error: the text keeps it, the diagnostic names its line, the model waits
    lines = text.split("\n")
    at = next(i for i, line in enumerate(lines) if "RULE 2 :" in line)
    broken = lines.copy()
    broken[at] = "        RULE 2 : IF input1 IS THEN output1 IS p_large;"
    pg.fill("#code-input", "\n".join(broken))
    pg.wait_for_selector("#text-diags li.error")
    assert f"error {at + 1}:" in pg.inner_text("#text-diags")
    assert pg.locator("#code-highlight .line-error").count() >= 1
    assert "error" in pg.inner_text("#check-badge")
    # an unknown term: a semantic error, also with its line
    broken[at] = "        RULE 2 : IF input1 IS huge THEN output1 IS p_large;"
    pg.fill("#code-input", "\n".join(broken))
    pg.wait_for_function("document.querySelector('#text-diags').textContent.includes('huge')")
    shot(pg, "13-text-diagnostic")
    # an AND rule and an OR rule written as text: the table shows the first in cells,
    # the second as text
    fixed = lines.copy()
    fixed[at] = (
        "        RULE 2 : IF input1 IS p_big AND input2 IS zero THEN output1 IS p_small;\n"
        "        RULE 3 : IF input1 IS zero OR input2 IS zero THEN output1 IS zero;"
    )
    pg.fill("#code-input", "\n".join(fixed))
    pg.wait_for_function("document.querySelector('#check-badge').textContent.startsWith('OK')")
    rule_mode(pg, "rows")
    assert cell_text(pg, 1, "input2") == "zero"
    assert cell_text(pg, 1, "output1") == "p_small"
    assert (
        pg.input_value('#rule-table input[data-rule="2"][data-part="if"]')
        == "input1 IS zero OR input2 IS zero"
    )
    assert cell_text(pg, 2, "output1") == "zero"  # its THEN part is still a cell
    # the conformance level follows the model: the OR rule (without an OR operator in its
    # rule block) lifts it above Basic, and the panel says why
    assert pg.inner_text("#level-badge") == "level: Extension"
    assert "operator OR in a condition" in pg.inner_text("#level-detail")
    # the ACCU left to its default: the check's warning shows under the rule table
    pg.select_option("#rb-accu", "")
    pg.wait_for_function("document.querySelector('#rule-diags').textContent.includes('no ACCU')")
    shot(pg, "14-rule-table")


def test_surface_family_parameter_rotation_animation_and_explain(page: Any) -> None:
    pg = page
    new_project(pg, "three", 3, 1)
    rule_mode(pg, "rows")
    table = [
        ("n_big", "n_big", "n_big", "n_large"),
        ("p_big", "zero", "zero", "p_small"),
        ("zero", "zero", "p_big", "p_large"),
        ("zero", "p_big", "n_big", "n_small"),
    ]
    for j, (a, b, c, y) in enumerate(table):
        pg.click("#rule-append")
        for var, term in (("input1", a), ("input2", b), ("input3", c), ("output1", y)):
            set_cell(pg, j, var, term)
    settle(pg)
    ctl = fuzzyctl.compile(fuzzyctl.load(fcl_text(pg)))

    def engine_agrees(fixed: float) -> None:
        z = surface_z(pg)
        xs = pg.evaluate("document.querySelector('#sf-chart').data[0].x")
        ys = pg.evaluate("document.querySelector('#sf-chart').data[0].y")
        for j in (0, 9, 15, 24):
            for i in (0, 5, 15, 30):
                ctl.reset()
                expect = ctl.evaluate({"input1": xs[i], "input2": ys[j], "input3": fixed})["output1"]
                assert z[j][i] == pytest.approx(expect, abs=1e-9), (i, j, fixed)

    tab(pg, "surface")
    # input3 is the family parameter: a slider with its value, at mid-range first
    assert pg.input_value('[aria-label="input3 value"]') == "0"
    engine_agrees(0)
    before = surface_z(pg)
    pg.fill('[aria-label="input3 value"]', "80")
    pg.press('[aria-label="input3 value"]', "Enter")
    pg.wait_for_function("document.querySelector('#sf-chart').dataset.fixed === '{\"input3\":80}'")
    assert surface_z(pg) != before
    assert pg.input_value('[aria-label="family parameter input3"]') == "80"
    engine_agrees(80)
    # rotation turns the camera round the vertical axis
    eye = pg.evaluate("document.querySelector('#sf-chart')._fullLayout.scene.camera.eye")
    pg.click("#sf-rotate")
    pg.wait_for_timeout(700)
    pg.click("#sf-rotate")
    turned = pg.evaluate("document.querySelector('#sf-chart')._fullLayout.scene.camera.eye")
    assert pg.input_value("#sf-rot") != "45"
    assert (turned["x"], turned["y"]) != pytest.approx((eye["x"], eye["y"]))
    assert turned["z"] == pytest.approx(eye["z"])
    # 4D: input3 animated over its range in steps of 20 %: -100, -60, ..., 100
    pg.select_option("#sf-anim", "input3")
    pg.select_option("#sf-step", "20")
    pg.click("#sf-animate")
    seen: dict[float, Any] = {}
    for _ in range(60):
        title, z = pg.evaluate(
            "(() => { const c = document.querySelector('#sf-chart');"
            " return [c._fullLayout.title.text, c.data[0].z]; })()"
        )
        if title.startswith("input3 = "):
            seen[float(title.split("= ")[1])] = z
        if len(seen) >= 6:
            break
        pg.wait_for_timeout(120)
    pg.click("#sf-animate")
    assert sorted(seen) == pytest.approx([-100, -60, -20, 20, 60, 100])
    shot(pg, "15-surface-4d")
    xs = pg.evaluate("document.querySelector('#sf-chart').data[0].x")
    ys = pg.evaluate("document.querySelector('#sf-chart').data[0].y")
    for value, z in seen.items():
        ctl.reset()
        assert z[3][7] == pytest.approx(
            ctl.evaluate({"input1": xs[7], "input2": ys[3], "input3": value})["output1"], abs=1e-9
        )

    # explain a point: term degrees (closed form of the evenly spread triangles), rule
    # degrees and the value (the engine)
    tab(pg, "explain")
    for name, value in (("input1", -75), ("input2", -90), ("input3", -80)):
        pg.fill(f"#ex-in-{name}", str(value))
    pg.wait_for_function("document.querySelector('#ex-terms').textContent.includes('0.6')")
    rows = pg.evaluate(
        "[...document.querySelectorAll('#ex-terms tbody tr')]"
        ".map((r) => [...r.cells].slice(0, 3).map((c) => c.textContent))"
    )
    degrees = {(v, t): float(d) for v, t, d in rows}
    assert degrees[("input1", "n_big")] == pytest.approx(0.5)  # (-100, 1) (-50, 0) at -75
    assert degrees[("input1", "n_small")] == pytest.approx(0.5)
    assert degrees[("input2", "n_big")] == pytest.approx(0.8)
    assert degrees[("input3", "n_big")] == pytest.approx(0.6)
    assert degrees[("input3", "zero")] == 0
    rules = pg.evaluate(
        "[...document.querySelectorAll('#ex-rules tbody tr')].map((r) => +r.cells[1].textContent)"
    )
    assert rules[0] == pytest.approx(0.5)  # MIN(0.5, 0.8, 0.6)
    ctl.reset()
    expect = ctl.evaluate({"input1": -75, "input2": -90, "input3": -80})["output1"]
    assert float(pg.get_attribute("#ex-chart", "data-value") or "nan") == pytest.approx(expect, abs=1e-9)
    shot(pg, "16-explain")


def test_recorder_signals_length_archive_and_bars(page: Any, browser_project: Path) -> None:
    pg = page
    open_file(pg, "siemens_fpltest.fcl")
    tab(pg, "recorder")
    pg.select_option("#rec-source", "test")
    # the display length stays within 10..9999 s; 150 values per display
    for typed, kept in (("5", "10"), ("20000", "9999"), ("15", "15")):
        pg.fill("#rec-length", typed)
        pg.press("#rec-length", "Tab")
        assert pg.input_value("#rec-length") == kept
    assert "sampling time 0.1 s" in pg.inner_text("#rec-sampling")
    # five curve selectors, no more
    assert pg.locator("#rec-curves select").count() == 5
    # Temp at its minimum, Pressure a triangle
    pg.click("#rec-sig-Temp")
    pg.select_option("#sig-kind", "minimum")
    pg.click("#sig-ok")
    pg.click("#rec-sig-Pressure")
    pg.select_option("#sig-kind", "triangle")
    pg.fill("#sig-min", "50")
    pg.fill("#sig-max", "100")
    pg.fill("#sig-periods", "3")
    pg.click("#sig-ok")
    assert pg.inner_text("#rec-sig-Temp") == "Temp: Minimum"
    pg.select_option("#rec-speed", "100")
    pg.click("#rec-start")
    # more than 450 samples: the archive is full and the oldest records are gone
    pg.wait_for_function(
        "(document.querySelector('#rec-chart').layout?.xaxis.range[0] ?? 0) >= 60", timeout=30000
    )
    pg.click("#rec-stop")
    values = reading(pg, 75)
    assert values["Temp"] == 0  # the range minimum
    scroll = pg.locator("#rec-scroll")
    # the archive: three display lengths (45 s) of 0.1 s records, 450 - 150 - 1 positions
    assert scroll.is_enabled() and scroll.get_attribute("max") == "299"
    # scroll to the oldest record of the archive
    pg.eval_on_selector("#rec-scroll", "(e) => { e.value = 0; e.dispatchEvent(new Event('input')); }")
    first = reading(pg, 0)
    newest = pg.evaluate("document.querySelector('#rec-chart').layout.xaxis.range[0]")
    assert first["t"] == pytest.approx(newest) and first["t"] > 0
    # the bars at the reading line: every rule's degree over its singleton, and the
    # centre of gravity, as the engine explains the same instant
    at = reading(pg, 40)
    ctl = fuzzyctl.compile(fuzzyctl.load(browser_project / "siemens_fpltest.fcl"))
    explanation = ctl.explain({"Temp": at["Temp"], "Pressure": at["Pressure"]})
    expect = {r.label: r.degree for r in explanation.rules}
    pg.wait_for_function(
        f"Math.abs(parseFloat(document.querySelector('#rec-bars').dataset.value) - {at['Valve']}) < 1e-9"
    )
    bars = dict(json.loads(pg.get_attribute("#rec-bars", "data-rules") or "[]"))
    assert bars == pytest.approx(expect, abs=1e-12)
    assert sum(1 for d in bars.values() if d > 0) >= 1
    bar_x = pg.evaluate("document.querySelector('#rec-bars').data[0].x")
    assert sorted(bar_x) == [-100, 0, 0, 100]  # the singletons drainage, closed, closed, inlet
    cog = pg.evaluate("document.querySelector('#rec-bars').data[1].x[0]")
    assert cog == pytest.approx(at["Valve"], abs=1e-12)
    shot(pg, "17-recorder-archive")


# A FIS file imported and exported, then the keyboard: the real-world one of the corpus (an
# extra suite) and MATLAB's tipper with its OR rules, vendored from fuzzylite (every clone).
IMPORTS = [
    pytest.param(
        ("corpus", "fis", "AlexMolio__nn_classification__fuzzy.fis"),
        {"len": 40.0, "wid": 20.0, "n": 30.0},
        "PL",
        marks=pytest.mark.extra("corpus"),
        id="corpus",
    ),
    pytest.param(
        ("data", "fuzzylite", "mamdani", "matlab", "tipper.fis"),
        {"service": 3.0, "food": 7.0},
        "tip",
        id="vendored",
    ),
]


@pytest.mark.parametrize(("where", "point", "output"), IMPORTS)
def test_import_export_and_keyboard(
    page: Any, browser_project: Path, where: tuple[str, ...], point: dict[str, float], output: str
) -> None:
    pg = page
    fis = shared_path(*where) if where[0] == "corpus" else data_path(*where[1:])
    pg.set_input_files("#import-file", str(fis))
    pg.wait_for_function("document.querySelector('#status').textContent.includes('imported')")
    assert "(fis)" in pg.inner_text("#status")
    settle(pg)
    assert pg.locator("#diagram .node.input").count() == len(point)
    ref = fuzzyctl.compile(fuzzyctl.load(fis))
    imported = fuzzyctl.compile(fuzzyctl.load(fcl_text(pg)))
    assert imported.evaluate(point) == pytest.approx(ref.evaluate(point))
    # the rules are editable: cells, and the OR rules text fields (not greyed-out text)
    rule_mode(pg, "rows")
    assert pg.locator("#rule-table tbody tr").count() == len(ref.plan.rules)
    conditions = pg.evaluate(
        "[...document.querySelectorAll('#rule-table input[data-part=\"if\"]')].map((e) => e.value)"
    )
    assert any(" OR " in c for c in conditions) == (where[0] == "data")  # the corpus file has none
    # export as FLL: the downloaded file computes the same
    pg.click("#btn-export")
    pg.select_option("#export-format", "fll")
    with pg.expect_download() as info:
        pg.click("#export-ok")
    path = info.value.path()
    exported = fuzzyctl.compile(fuzzyctl.load(Path(path).read_text(), format="fll"))
    assert exported.evaluate(point) == pytest.approx(ref.evaluate(point))
    assert info.value.suggested_filename.endswith(".fll")

    # keyboard: Alt+digit picks a view, arrows move along the tabs, Ctrl+S saves
    pg.keyboard.press("Alt+4")
    assert pg.is_visible("#view-ruleviewer")
    pg.keyboard.press("ArrowRight")
    assert pg.is_visible("#view-text")
    assert pg.evaluate("document.activeElement.dataset.view") == "text"
    pg.keyboard.press("Control+s")
    pg.wait_for_selector("#dlg-saveas[open]")
    name = f"imported-{where[0]}.fcl"
    pg.fill("#saveas-path", name)
    pg.keyboard.press("Enter")
    pg.wait_for_function(f"document.querySelector('#status').textContent.includes('saved {name}')")
    again = fuzzyctl.compile(fuzzyctl.load(browser_project / name))
    assert again.evaluate(point) == pytest.approx(ref.evaluate(point))
    # a change, then Save (no dialog: the project has its file now)
    tab(pg, "variable")
    pg.select_option("#var-select", output)
    pg.select_option("#out-method", "MOM")
    settle(pg)
    assert pg.inner_text("#project-name").startswith("●")  # unsaved changes
    pg.click("#btn-save")
    pg.wait_for_function("!document.querySelector('#project-name').textContent.startsWith('●')")
    block = fuzzyctl.load(browser_project / name).main.defuzzify_block(output)
    assert block is not None and block.method == "MOM"
    # Tab reaches the buttons of the menu bar in order
    pg.focus("#btn-new")
    pg.keyboard.press("Tab")
    assert pg.evaluate("document.activeElement.id") == "btn-open"
    shot(pg, f"18-imported-{where[0]}")
