"""Rules that scale, in the real browser: the matrix of two inputs, the Siemens columns and
the table with one row per rule all edit the one model; the text editor reads IF ... THEN
lines with the FCL parser (OR, NOT, parentheses, several conclusions, WITH) with live
diagnostics; a rule base of 500 rules opens and edits, with the times measured and written
to test-artifacts/studio/timings-500.json (never asserted: the machine is shared).

Expected rules come from the FCL files (fuzzyctl.load), never from the studio itself."""

from __future__ import annotations

import itertools
import json
import time
from pathlib import Path
from typing import Any

import fuzzyctl
from fuzzyctl.model import And, Conclusion, Is, Not, Or
from tests.studio.browser import (
    ARTIFACTS,
    cell_text,
    checked,
    fcl_text,
    new_project,
    open_file,
    rule_mode,
    set_cell,
    settle,
    shot,
    tab,
)


def matrix_cell(pg: Any, row: str, col: str) -> str:
    text: str = pg.inner_text(f'#rule-matrix td[data-row="{row}"][data-col="{col}"]')
    return text.strip()


def pick_in_matrix(pg: Any, row: str, col: str, term: str) -> None:
    pg.click(f'#rule-matrix td[data-row="{row}"][data-col="{col}"]')
    pg.select_option("#rule-matrix select", term)
    pg.wait_for_selector("#rule-matrix:not(:has(select))")


def cut_cells(pg: Any, selector: str) -> list[str]:
    """The cells whose text does not fit (names cut, as the old dropdowns did)."""
    cut: list[str] = pg.evaluate(
        f"[...document.querySelectorAll({selector!r})]"
        ".filter((e) => e.scrollWidth > e.clientWidth + 1).map((e) => e.textContent)"
    )
    return cut


def test_matrix_columns_and_table_edit_one_model(page: Any, browser_project: Path) -> None:
    pg = page
    open_file(pg, "crane.fcl")
    tab(pg, "rules")
    # two inputs: the matrix comes first; each cell is the conclusion of the file's rule
    assert pg.get_attribute("#view-rules", "data-mode") == "matrix"
    crane = fuzzyctl.load(browser_project / "crane.fcl").main
    for rule in crane.rule_blocks[0].rules:
        assert isinstance(rule.condition, And)
        a, b = rule.condition.operands
        assert isinstance(a, Is) and isinstance(b, Is)
        assert matrix_cell(pg, a.term, b.term) == rule.conclusions[0].term
    assert "25 of 25 rule(s) in this matrix" in pg.inner_text("#matrix-note")
    assert (
        pg.locator("#rule-matrix td").count() == 25
        and cut_cells(pg, "#rule-matrix td, #rule-matrix th") == []
    )
    # the whole matrix is in view: no horizontal scrolling
    pane = "document.querySelector('#rules-matrix')"
    assert pg.evaluate(f"{pane}.scrollWidth <= {pane}.clientWidth")
    shot(pg, "20-rule-matrix", doc=True)
    # a cell changes its rule; a blanked cell removes it; a pick in an empty cell adds one
    pick_in_matrix(pg, "far", "zero", "pos_high")
    settle(pg)
    assert "IF distance IS far AND angle IS zero THEN power IS pos_high;" in fcl_text(pg)
    tab(pg, "rules")
    pick_in_matrix(pg, "zero", "zero", "")
    assert matrix_cell(pg, "zero", "zero") == "·"
    settle(pg)
    assert "distance IS zero AND angle IS zero" not in fcl_text(pg)
    tab(pg, "rules")
    pick_in_matrix(pg, "zero", "zero", "neg_medium")
    settle(pg)
    text = fcl_text(pg)
    assert "RULE 26 : IF distance IS zero AND angle IS zero THEN power IS neg_medium;" in text
    assert text.count("RULE ") == 25

    # the Siemens rule table: one column per rule, the same rules
    rule_mode(pg, "columns")
    assert pg.locator("#rule-table th.rule-head").count() == 25
    assert cell_text(pg, 0, "distance") == "far" and cell_text(pg, 0, "power") == "pos_medium"
    assert cut_cells(pg, "#rule-table td.cell") == []
    shot(pg, "21-rule-columns", doc=True)
    # the table with one row per rule; an input cell offers NOT term
    rule_mode(pg, "rows")
    assert pg.locator("#rule-table tbody tr").count() == 25
    assert cut_cells(pg, "#rule-table td.cell") == []
    set_cell(pg, 0, "angle", "NOT neg_big")
    assert cell_text(pg, 0, "angle") == "NOT neg_big"
    settle(pg)
    assert "RULE 1 : IF distance IS far AND angle IS NOT neg_big THEN power IS pos_medium;" in fcl_text(pg)
    # keyboard: arrows move between cells, Enter opens the picker
    rule_mode(pg, "rows")
    pg.focus('#rule-table td.cell[data-rule="1"][data-var="distance"]')
    pg.keyboard.press("ArrowRight")
    pg.keyboard.press("ArrowDown")
    assert (
        pg.evaluate("document.activeElement.dataset.rule + ' ' + document.activeElement.dataset.var")
        == "2 angle"
    )
    pg.keyboard.press("Enter")
    pg.wait_for_selector('#rule-table select[data-rule="2"][data-var="angle"]')
    pg.keyboard.press("Escape")
    assert cell_text(pg, 2, "angle") == "zero"


def applied(pg: Any, action: Any) -> None:
    """Do ``action`` (Enter in a rule's text field) and wait until the parser's rule is in
    the model and checked."""
    before = int(pg.get_attribute("#rule-table", "data-applied") or "0")
    action()
    pg.wait_for_function(f"+(document.querySelector('#rule-table').dataset.applied || 0) > {before}")
    checked(pg)


TYPED = """IF input1 IS n_big OR input2 IS p_big THEN output1 IS n_large, output2 IS zero
IF NOT (input1 IS zero AND input2 IS zero) THEN output1 IS p_small WITH 0.5
RULE 7 : IF (input1 IS p_big OR input1 IS p_small) AND input2 IS NOT n_big THEN output2 IS p_large
IF input1 IS zero THEN output1 IS zero"""


def test_text_editor_reads_rules_with_the_fcl_parser(page: Any) -> None:
    pg = page
    new_project(pg, "typed", 2, 2)
    rule_mode(pg, "text")
    pg.fill("#rules-input", TYPED)
    pg.wait_for_function("document.querySelector('#rules-text').dataset.ok === 'true'")
    checked(pg)  # the model's check follows a pause in typing
    rules = fuzzyctl.load(fcl_text(pg)).main.rule_blocks[0].rules
    assert [r.label for r in rules] == ["1", "2", "7", "4"]
    first, second, third, fourth = rules
    assert first.condition == Or((Is("input1", "n_big"), Is("input2", "p_big")))
    assert first.conclusions == (Conclusion("output1", "n_large"), Conclusion("output2", "zero"))
    assert second.condition == Not(And((Is("input1", "zero"), Is("input2", "zero"))))
    assert second.conclusions == (Conclusion("output1", "p_small", 0.5),)
    assert third.condition == And(
        (Or((Is("input1", "p_big"), Is("input1", "p_small"))), Is("input2", "n_big", negated=True))
    )
    assert fourth.conclusions == (Conclusion("output1", "zero"),)
    # an error: the diagnostic names the line and column of the typed text, the gutter
    # marks that line, and the model keeps the rules that checked
    tab(pg, "rules")
    pg.fill("#rules-input", TYPED.replace("input2 IS NOT n_big", "input2 IS NOT"))
    pg.wait_for_function("document.querySelector('#rules-text').dataset.ok === 'false'")
    diagnostics = pg.inner_text("#rule-diags")
    assert "error 3:" in diagnostics, diagnostics
    assert pg.get_attribute('#rules-gutter div[data-line="3"]', "class") == "error"
    assert pg.get_attribute('#rules-gutter div[data-line="1"]', "class") is None
    shot(pg, "22-rule-text", doc=True)
    assert "input2 IS NOT n_big" in fcl_text(pg)
    # an unknown term: the checks' error, on its line
    tab(pg, "rules")
    pg.fill("#rules-input", TYPED.replace("output1 IS zero", "output1 IS huge"))
    pg.wait_for_function("document.querySelector('#rule-diags').textContent.includes('huge')")
    assert "error 4:" in pg.inner_text("#rule-diags")
    pg.fill("#rules-input", TYPED)
    pg.wait_for_function("document.querySelector('#rules-text').dataset.ok === 'true'")
    checked(pg)

    # the table: the OR rule's IF part is a text field, its THEN part two cells
    rule_mode(pg, "rows")
    condition = '#rule-table input[data-rule="0"][data-part="if"]'
    assert pg.input_value(condition) == "input1 IS n_big OR input2 IS p_big"
    assert cell_text(pg, 0, "output1") == "n_large" and cell_text(pg, 0, "output2") == "zero"
    assert (
        pg.input_value('#rule-table input[data-rule="1"][data-part="then"]') == "output1 IS p_small WITH 0.5"
    )
    # edited there: read by the same parser; a mistake is refused with its message
    pg.fill(condition, "input1 IS n_big OR (input2 IS p_big AND NOT input1 IS zero)")
    applied(pg, lambda: pg.press(condition, "Enter"))
    rule = fuzzyctl.load(fcl_text(pg)).main.rule_blocks[0].rules[0]
    assert rule.condition == Or(
        (Is("input1", "n_big"), And((Is("input2", "p_big"), Not(Is("input1", "zero")))))
    )
    rule_mode(pg, "rows")
    pg.fill(condition, "input1 IS n_big OR")
    pg.press(condition, "Enter")
    pg.wait_for_selector(f"{condition}.bad")
    assert "unexpected" in (pg.get_attribute(condition, "title") or "")  # the parser's message
    # any rule can be written as text: ✎ turns its cells into fields
    pg.click('#rule-table button.as-text[data-rule="3"]')
    field = '#rule-table input[data-rule="3"][data-part="if"]'
    assert pg.input_value(field) == "input1 IS zero"
    pg.fill(field, "input1 IS zero OR input1 IS p_small")
    applied(pg, lambda: pg.press(field, "Enter"))
    assert "RULE 4 : IF input1 IS zero OR input1 IS p_small THEN output1 IS zero;" in fcl_text(pg)


def big_rule_base(path: Path, rules: int = 500) -> None:
    """Three inputs of eight triangles, one singleton output, ``rules`` AND rules."""
    names = ["nb", "nm", "ns", "ze", "ps", "pm", "pb", "px"]
    lines = [
        "FUNCTION_BLOCK big",
        "    VAR_INPUT",
        "        e : REAL;",
        "        de : REAL;",
        "        load : REAL;",
    ]
    lines += ["    END_VAR", "    VAR_OUTPUT", "        u : REAL;", "    END_VAR"]
    for v in ("e", "de", "load"):
        lines.append(f"    FUZZIFY {v}")
        for i, t in enumerate(names):
            c = -100 + 200 * i / 7
            lines.append(f"        TERM {t} := ({c - 200 / 7:.4f}, 0) ({c:.4f}, 1) ({c + 200 / 7:.4f}, 0);")
        lines.append("    END_FUZZIFY")
    lines.append("    DEFUZZIFY u")
    lines += [f"        TERM {t} := {-100 + 200 * i / 7:.4f};" for i, t in enumerate(names)]
    lines += ["        METHOD : COGS;", "        DEFAULT := 0;", "    END_DEFUZZIFY", "    RULEBLOCK rules"]
    lines += ["        AND : MIN;", "        ACCU : MAX;"]
    for k, (a, b, c) in enumerate(itertools.islice(itertools.product(range(8), repeat=3), rules)):
        out = names[min(7, (a + b + c) // 3)]
        lines.append(
            f"        RULE {k + 1} : IF e IS {names[a]} AND de IS {names[b]} AND load IS {names[c]}"
            f" THEN u IS {out};"
        )
    lines += ["    END_RULEBLOCK", "END_FUNCTION_BLOCK", ""]
    path.write_text("\n".join(lines))


def test_500_rules_open_and_edit(page: Any, browser_project: Path) -> None:
    pg = page
    big_rule_base(browser_project / "big500.fcl")
    timings: dict[str, float] = {}
    start = time.monotonic()
    open_file(pg, "big500.fcl")
    rule_mode(pg, "rows")
    pg.wait_for_function("document.querySelectorAll('#rule-table tbody tr').length === 500")
    timings["open_and_show_table_s"] = time.monotonic() - start
    timings["table_render_ms"] = float(pg.get_attribute("#view-rules", "data-render-ms") or "nan")
    pg.wait_for_function("document.querySelector('#check-badge').textContent.startsWith('OK')")
    # a cell edit: the table answers at once, the check of the whole model follows
    checks = int(pg.get_attribute("body", "data-checks") or "0")
    start = time.monotonic()
    set_cell(pg, 499, "load", "nb")
    timings["cell_edit_ui_s"] = time.monotonic() - start  # with Playwright's click and pick
    timings["cell_edit_browser_ms"] = float(pg.get_attribute("#rule-table", "data-edit-ms") or "nan")
    pg.wait_for_function(f"+document.body.dataset.checks > {checks}", timeout=60000)
    timings["cell_edit_checked_s"] = time.monotonic() - start
    pg.wait_for_function("document.querySelector('#check-badge').textContent.startsWith('OK')")
    for mode in ("columns", "matrix", "text"):
        rule_mode(pg, mode)
        timings[f"{mode}_render_ms"] = float(pg.get_attribute("#view-rules", "data-render-ms") or "nan")
    # a line of the text: read again alone (the others come from the cache)
    lines = pg.input_value("#rules-input").split("\n")
    assert len(lines) == 500 and lines[499].startswith("IF e IS px AND de IS pb AND load IS nb THEN")
    # typed as a user types: select the last term of line 1 and write another
    end = lines[0].index(";")
    pg.eval_on_selector("#rules-input", f"(e) => {{ e.focus(); e.setSelectionRange({end - 2}, {end}); }}")
    parsed = int(pg.get_attribute("#rules-text", "data-parsed") or "0")
    start = time.monotonic()
    pg.keyboard.insert_text("pb")
    pg.wait_for_function(f"+document.querySelector('#rules-text').dataset.parsed > {parsed}", timeout=60000)
    timings["text_first_read_s"] = time.monotonic() - start  # 500 lines; includes the 300 ms pause
    assert pg.get_attribute("#rules-text", "data-ok") == "true"
    # the next edit reads its one line (the 499 others come from the cache); measured once
    # the check of the whole model that the first edit started is back (both use the parser)
    pg.wait_for_function(f"+document.body.dataset.checks > {checks + 1}", timeout=60000)
    second = len(lines[0]) + 1 + lines[1].index(";")
    pg.eval_on_selector("#rules-input", f"(e) => {{ e.setSelectionRange({second - 2}, {second}); }}")
    start = time.monotonic()
    pg.keyboard.insert_text("px")
    pg.wait_for_function(
        f"+document.querySelector('#rules-text').dataset.parsed > {parsed + 1}", timeout=60000
    )
    timings["text_next_read_s"] = time.monotonic() - start
    assert pg.get_attribute("#rules-text", "data-ok") == "true"
    tab(pg, "text")  # the FCL text follows when the check of the whole model is back
    pg.wait_for_function(
        "document.querySelector('#code-input').value.includes('load IS nm THEN u IS px;')", timeout=60000
    )
    text = fcl_text(pg)
    rules = fuzzyctl.load(text).main.rule_blocks[0].rules
    assert len(rules) == 500
    assert rules[0].conclusions == (Conclusion("u", "pb"),)
    assert rules[1].conclusions == (Conclusion("u", "px"),)
    assert rules[499].condition == And((Is("e", "px"), Is("de", "pb"), Is("load", "nb")))
    ARTIFACTS.mkdir(parents=True, exist_ok=True)
    (ARTIFACTS / "timings-500.json").write_text(json.dumps(timings, indent=2) + "\n")
    print("500 rules:", json.dumps(timings))


COMMENTED = """FUNCTION_BLOCK commented
VAR_INPUT x : REAL; END_VAR
VAR_OUTPUT y : REAL; END_VAR
FUZZIFY x TERM lo := (0, 1) (10, 0); TERM hi := (0, 0) (10, 1); END_FUZZIFY
DEFUZZIFY y TERM a := 0; TERM b := 10; METHOD : COGS; DEFAULT := 0; END_DEFUZZIFY
RULEBLOCK r
    AND : MIN;
    ACCU : MAX;
    (* C01 before rule 1 *)
    RULE 1 : IF x IS lo THEN y IS a; // C02 after rule 1
    RULE 2 : IF x IS hi THEN y IS b; (* C03 after rule 2 *) (* C04 and another *)
END_RULEBLOCK
END_FUNCTION_BLOCK
"""


def test_text_editor_keeps_the_comments_of_the_rules(page: Any, browser_project: Path) -> None:
    # a rule's comments stand before it and after it on its line, as in the file; edited
    # as text, they are read again with the rules and written where they were
    from tests.fcl.test_comments_kept import places

    pg = page
    (browser_project / "commented_rules.fcl").write_text(COMMENTED)
    open_file(pg, "commented_rules.fcl")
    rule_mode(pg, "text")
    lines = pg.input_value("#rules-input").split("\n")
    assert lines[0] == "(* C01 before rule 1 *)"
    assert lines[1].endswith("THEN y IS a; // C02 after rule 1")
    assert lines[2].endswith("THEN y IS b; (* C03 after rule 2 *) (* C04 and another *)")
    pg.fill("#rules-input", "\n".join(lines).replace("THEN y IS b", "THEN y IS a"))
    pg.wait_for_function("document.querySelector('#rules-text').dataset.ok === 'true'")
    checked(pg)
    found = places(fcl_text(pg))
    assert found["C01"] == ("", "RULE 1 : IF x IS lo THEN y IS a;")
    assert found["C02"][0] == "RULE 1 : IF x IS lo THEN y IS a;"
    assert found["C03"][0] == found["C04"][0] == "RULE 2 : IF x IS hi THEN y IS a;"
