"""A page that uses its space, in the real browser: resizable panes and a check panel that
can be hidden, the block diagram with ranges, term counts and the terms drawn, a busy
indicator while the server works, numbers formatted for engineers, line numbers and a
diagnostic gutter in the FCL text, and every part of the model the editors do not edit
shown (and what FCL cannot write listed), never silently dropped."""

from __future__ import annotations

import shutil
from pathlib import Path
from typing import Any

from tests.conftest import EXAMPLES, data_path
from tests.studio.browser import fcl_text, open_file, settle, shot, tab

TWO_BLOCKS = """FUNCTION_BLOCK first
    VAR_INPUT x : REAL; END_VAR
    VAR_OUTPUT y : REAL; END_VAR
    FUZZIFY x TERM low := (0, 1) (10, 0); TERM high := (0, 0) (10, 1); END_FUZZIFY
    DEFUZZIFY y TERM a := 0; TERM b := 1; METHOD : CoGS; DEFAULT := 0; END_DEFUZZIFY
    RULEBLOCK r RULE 1 : IF x IS low THEN y IS a; END_RULEBLOCK
END_FUNCTION_BLOCK
FUNCTION_BLOCK second
    VAR_INPUT p : REAL; q : REAL; END_VAR
    VAR_OUTPUT z : REAL; END_VAR
    FUZZIFY p TERM low := (0, 1) (1, 0); END_FUZZIFY
    FUZZIFY q TERM low := (0, 1) (1, 0); END_FUZZIFY
    DEFUZZIFY z TERM a := 0; METHOD : CoGS; DEFAULT := 0; END_DEFUZZIFY
    RULEBLOCK r RULE 1 : IF p IS low AND q IS low THEN z IS a; END_RULEBLOCK
END_FUNCTION_BLOCK
"""


def width(pg: Any, selector: str) -> float:
    box = pg.locator(selector).bounding_box()
    assert box is not None
    return float(box["width"])


def test_panes_diagram_busy_numbers_gutter(page: Any) -> None:
    pg = page
    assert pg.is_hidden("#loading")  # the loading indicator is gone once the studio is ready
    # ... and shows while the project is read (the server's answer is held back here)
    waiting: list[Any] = []
    pg.route("**/api/info", lambda route: waiting.append(route))
    pg.reload(wait_until="domcontentloaded")
    pg.wait_for_function("document.querySelector('#loading-text').textContent.includes('Reading')")
    assert pg.is_visible("#loading") and pg.is_visible("#loading .spinner")
    for route in waiting:
        route.continue_()
    pg.unroute("**/api/info")
    pg.wait_for_selector("body[data-ready=true]")
    assert pg.is_hidden("#loading")
    # the busy bar shows while a request is under way (the check is held back here)
    held: list[Any] = []
    hold = [True]
    pg.route("**/api/check", lambda route: held.append(route) if hold[0] else route.continue_())
    pg.click("#btn-new")
    pg.click("#new-ok")
    pg.wait_for_function("document.body.dataset.busy === 'true'")
    assert pg.is_visible("#busy")
    hold[0] = False
    for route in held:
        route.continue_()
    pg.wait_for_function("document.body.dataset.busy === 'false'")
    open_file(pg, "crane.fcl", discard=True)  # the new project is not saved

    # the block diagram: each variable with its term count, its range and its terms drawn
    tab(pg, "project")
    distance = pg.text_content('#diagram [data-id="var:distance"]') or ""
    assert "5 term(s) · -4 … 20" in distance
    assert pg.locator('#diagram [data-id="var:distance"] polyline.spark').count() == 5
    assert pg.locator('#diagram [data-id="var:power"] line.spark').count() == 5  # singletons
    assert "25 rule(s)" in (pg.text_content('#diagram [data-id="ruleblock:0"]') or "")
    size = pg.evaluate("parseFloat(getComputedStyle(document.querySelector('#diagram .sub')).fontSize)")
    assert size >= 13
    assert width(pg, "#diagram svg") >= 600  # drawn at the size of the view
    shot(pg, "24-project", doc=True)

    # resizable panes: the term panel grows when its splitter moves left, the chart follows
    tab(pg, "variable")
    chart, pane = width(pg, "#mf-chart"), width(pg, "#view-variable .term-pane")
    splitter = pg.locator("#view-variable .splitter").bounding_box()
    assert splitter is not None
    x, y = splitter["x"] + 3, splitter["y"] + 50
    pg.mouse.move(x, y)
    pg.mouse.down()
    pg.mouse.move(x - 60, y)
    pg.mouse.move(x - 120, y)
    pg.mouse.up()
    pg.wait_for_timeout(300)
    assert width(pg, "#view-variable .term-pane") == pane + 120
    assert width(pg, "#mf-chart") < chart - 100
    # the check panel hides, and the chart takes its place
    chart = width(pg, "#mf-chart")
    pg.click("#side-toggle")
    pg.wait_for_function(f"document.querySelector('#mf-chart').getBoundingClientRect().width > {chart + 200}")
    assert pg.is_hidden("#side")
    pg.click("#side-toggle")
    assert pg.is_visible("#side")

    # numbers as engineers read them (the studio's own formatting function)
    formatted = pg.evaluate(
        "import('/static/js/state.js').then((m) => [m.fmt(4.476e-13), m.fmt(29.99312), m.fmt(0.0071784),"
        " m.fmt(12.5, 4, 200), m.fmt(-0.00001, 4, 200), m.fmt(123456789), m.num(-4), m.num(0.1 + 0.2)])"
    )
    assert formatted == ["0.000", "29.99", "0.007178", "12.5", "0.0", "1.235e+8", "-4", "0.3"]

    # the FCL text: line numbers, and the line of a diagnostic marked in the gutter
    text = fcl_text(pg)
    lines = text.split("\n")
    at = next(i for i, line in enumerate(lines) if "RULE 3 :" in line)
    lines[at] = lines[at].replace("angle IS zero", "angle IS level")
    pg.fill("#code-input", "\n".join(lines))
    pg.wait_for_selector(f'#code-gutter div[data-line="{at + 1}"].error')
    assert pg.locator("#code-gutter div").count() == len(lines)
    assert "level" in (pg.get_attribute(f'#code-gutter div[data-line="{at + 1}"]', "title") or "")
    assert pg.get_attribute(f'#code-gutter div[data-line="{at}"]', "class") is None
    shot(pg, "25-fcl-gutter", doc=True)


def test_what_the_editors_do_not_edit_is_shown_and_kept(page: Any, browser_project: Path) -> None:
    pg = page
    shutil.copy(EXAMPLES / "dryer_chained.fcl", browser_project / "dryer_chained.fcl")
    (browser_project / "two_blocks.fcl").write_text(TWO_BLOCKS)
    open_file(pg, "dryer_chained.fcl")
    tab(pg, "project")
    beyond = pg.inner_text("#beyond-list")
    assert "local variables (VAR): wetness" in beyond
    assert "hedge" in beyond
    assert "Conformance level Open" in pg.inner_text("#model-summary")
    assert "hedges" in pg.inner_text("#level-detail")  # among the features of that level
    # kept: an edit elsewhere and a save leave the local variable, its rules and hedges
    tab(pg, "variable")
    pg.select_option("#var-select", "load")
    pg.fill("#var-max", "12")
    pg.click("#var-range-apply")
    pg.click("#confirm-no")
    settle(pg)
    pg.click("#btn-save")
    pg.wait_for_function("document.querySelector('#status').textContent.includes('saved dryer_chained.fcl')")
    saved = (browser_project / "dryer_chained.fcl").read_text()
    original = (EXAMPLES / "dryer_chained.fcl").read_text()
    for part in ("wetness : REAL;", "IS very", "PROBOR"):
        assert part in original and part in saved, part

    # what FCL cannot write is listed before a save drops it (a fuzzylite file)
    pg.set_input_files("#import-file", str(data_path("fuzzylite", "hybrid", "tipper.fll")))
    pg.wait_for_function("document.querySelector('#status').textContent.includes('imported')")
    settle(pg)
    tab(pg, "project")
    losses = pg.inner_text("#fcl-losses")
    assert "lock-range" in losses and "rule weight" in losses
    assert "saving as FCL drops" in pg.inner_text("#all-diags")
    assert "clamped to its range" in pg.inner_text("#beyond-list")
    shot(pg, "26-kept-and-dropped", doc=True)

    # several function blocks: a picker, and each block's diagram
    open_file(pg, "two_blocks.fcl", discard=True)
    assert pg.is_visible("#fb-picker")
    assert "1 other function block(s): second" in pg.inner_text("#beyond-list")
    pg.select_option("#fb-select", "1")
    pg.wait_for_function("document.querySelectorAll('#diagram .node.input').length === 2")
    assert "FUNCTION_BLOCK second" in (pg.text_content("#diagram") or "")


def test_the_printed_url_opens_the_studio_and_nothing_else_does(browser: Any, studio: str) -> None:
    """Without the token the studio answers 401 also on loopback; the URL with it (as
    `fuzzyctl studio` prints it) opens a working page, and the token leaves the address bar
    into a cookie the page's scripts cannot read."""
    plain = studio.split("?")[0]
    context = browser.new_context()  # a fresh browser: no cookie yet
    try:
        pg = context.new_page()
        assert pg.goto(plain).status == 401
        assert pg.goto(plain + "api/files").status == 401
        pg.goto(studio.replace("?", "?view=recorder&"))
        pg.wait_for_selector("body[data-ready=true]")
        assert "token" not in pg.url and "view=recorder" in pg.url
        assert pg.evaluate("document.cookie") == ""  # HttpOnly
        files = pg.evaluate("fetch('/api/files').then((r) => r.json())")
        assert "crane.fcl" in [f["path"] for f in files["files"]]
        assert pg.is_visible("#view-recorder")
    finally:
        context.close()


def test_save_errors_are_said_in_the_status_line(page: Any, browser_project: Path, request: Any) -> None:
    """A read-only file, a path through a file and a hidden directory: the status line says
    why (no "Replace it?" question that could not help), and nothing is written."""
    pg = page
    open_file(pg, "crane.fcl")
    crane = browser_project / "crane.fcl"
    before = crane.read_bytes()
    crane.chmod(0o444)
    try:
        pg.keyboard.press("Control+s")
        pg.wait_for_function("document.querySelector('#status').textContent.includes('read-only')")
        assert pg.inner_text("#status").startswith("crane.fcl is read-only: not saved")
    finally:
        crane.chmod(0o644)
    assert crane.read_bytes() == before
    for path, said in [("crane.fcl/x.fcl", "is a file, not a directory"), (".git/x.fcl", "hidden")]:
        pg.click("#btn-saveas")
        pg.fill("#saveas-path", path)
        pg.click("#saveas-ok")
        pg.wait_for_function(f"document.querySelector('#status').textContent.includes({said!r})")
        assert not pg.evaluate("document.querySelector('#dlg-confirm').open")
    assert not (browser_project / ".git").exists()
    # the refused requests are the browser's console errors this test expects
    errors: list[str] = request.node.console_errors
    errors[:] = [e for e in errors if "403" not in e and "400" not in e]
