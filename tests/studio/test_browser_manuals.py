"""The studio in a browser on what the manuals ask (issue 20, issue 15 point 5): the rule
bars of the Siemens block stack the rules of one singleton (S7 manual 1.4), a rule table
column with a THEN part only is a rule without an IF part (1.5), the dialogs check the
configuration tool's name limits (6.2, 6.4)."""

from __future__ import annotations

from typing import Any

import pytest

from tests.studio.browser import (
    RECORDED,
    cell_text,
    fcl_text,
    open_file,
    rule_mode,
    set_cell,
    settle,
    shot,
    tab,
)


def test_siemens_rule_bars_stack_the_rules_of_one_singleton(page: Any) -> None:
    pg = page
    open_file(pg, "siemens_fpltest.fcl")  # ACCU NSUM: the block's sum (1.4)
    tab(pg, "recorder")
    pg.select_option("#rec-source", "test")
    for name, value in (("Temp", 9), ("Pressure", 65)):
        pg.click(f"#rec-sig-{name}")
        pg.select_option("#sig-kind", "constant")
        pg.fill("#sig-value", str(value))
        pg.click("#sig-ok")
    pg.select_option("#rec-speed", "100")
    pg.click("#rec-start")
    pg.wait_for_function(RECORDED % 5, timeout=20000)
    pg.click("#rec-stop")
    # manual 1.4: inlet .75, closed .25 + .25, drainage .25 -> (75 - 25) / 1.5 = 100/3
    pg.wait_for_function(
        "Math.abs(parseFloat(document.querySelector('#rec-bars').dataset.value) - 100 / 3) < 1e-6"
    )
    bars = pg.evaluate(
        "(() => { const d = document.querySelector('#rec-bars').data[0];"
        " return d.x.map((x, i) => [x, d.y[i], d.base[i], d.text[i]]); })()"
    )
    by_rule = {label: (x, y, base) for x, y, base, label in bars}
    assert by_rule["Rule_01"] == (100, pytest.approx(0.75), 0)
    assert by_rule["Rule_04"] == (-100, pytest.approx(0.25), 0)
    # Rule_02 and Rule_03 both conclude "closed" (0): the second stands on the first
    closed = sorted((by_rule["Rule_02"], by_rule["Rule_03"]), key=lambda b: b[2])
    assert closed == [(0, pytest.approx(0.25), 0), (0, pytest.approx(0.25), pytest.approx(0.25))]
    shot(pg, "20-siemens-bars-stacked")


def test_rule_without_if_part_and_the_tool_s_name_limits(page: Any) -> None:
    pg = page
    # Define Project (6.2): at most 8 characters
    pg.click("#btn-new")
    pg.fill("#new-name", "")
    pg.locator("#new-name").press_sequentially("PROJECT_LONG")
    assert pg.input_value("#new-name") == "PROJECT_"
    pg.fill("#new-inputs", "1")
    pg.fill("#new-outputs", "1")
    pg.click("#new-ok")
    pg.wait_for_selector("#diagram svg")
    settle(pg)
    # a column with a THEN part only: a rule acting with degree 1 (1.5), part of the program
    rule_mode(pg, "columns")  # the manual's table, one column per rule
    pg.click("#rule-append")
    set_cell(pg, 0, "output1", "p_large")
    pg.wait_for_selector("#rule-diags [data-no-if]")
    assert "incomplete" not in pg.inner_text("#rule-diags")
    assert pg.get_attribute("#rule-diags [data-no-if]", "data-no-if") == "1"
    assert "(no IF part: degree 1) THEN output1 IS p_large" in (
        pg.get_attribute('#rule-table th[data-rule="0"]', "title") or ""
    )
    text = fcl_text(pg)
    assert "RULE 1 : IF ALWAYS THEN output1 IS p_large;" in text and "ALWAYS : REAL := 1;" in text
    # the text read back is the same column, not an input ALWAYS
    pg.fill("#code-input", text.replace("p_large;", "p_small;"))
    settle(pg)
    pg.wait_for_function("document.querySelector('#check-badge').textContent.startsWith('OK')")
    tab(pg, "rules")
    pg.wait_for_function(
        'document.querySelector(\'#rule-table td.cell[data-rule="0"][data-var="output1"]\')'
        ".textContent.trim() === 'p_small'"
    )
    assert cell_text(pg, 0, "output1") == "p_small"
    assert pg.locator('#rule-table td.cell[data-var="ALWAYS"]').count() == 0
    # the rules as text write it as FCL does, and read it back as a rule without an IF part
    rule_mode(pg, "text")
    assert pg.input_value("#rules-input") == "IF ALWAYS THEN output1 IS p_small;"
    parsed = int(pg.get_attribute("#rules-text", "data-parsed") or "0")
    pg.fill("#rules-input", "IF ALWAYS THEN output1 IS n_large;")
    pg.wait_for_function(f"+document.querySelector('#rules-text').dataset.parsed > {parsed}")
    assert pg.get_attribute("#rules-text", "data-ok") == "true"
    rule_mode(pg, "columns")
    assert cell_text(pg, 0, "output1") == "n_large"
    assert pg.locator('#rule-table td.cell[data-var="ALWAYS"]').count() == 0
    settle(pg)
    assert "RULE 1 : IF ALWAYS THEN output1 IS n_large;" in fcl_text(pg)
    # an IF part alone has no influence (1.5): incomplete
    rule_mode(pg, "columns")
    pg.click("#rule-append")
    set_cell(pg, 1, "input1", "zero")
    assert "1 incomplete rule(s) (no THEN part)" in pg.inner_text("#rule-diags")
    # names longer than the tool takes (6.4): accepted, with a warning
    tab(pg, "variable")
    pg.fill("#term-name", "very_negative")
    pg.press("#term-name", "Tab")
    warning = pg.inner_text("#status")
    assert "13 characters" in warning and "takes 7" in warning
    assert "warning" in (pg.get_attribute("#status", "class") or "")
    pg.fill("#var-name", "temperature1")
    pg.press("#var-name", "Tab")
    assert "takes 10" in pg.inner_text("#status")
    shot(pg, "21-rule-without-if-part")
