"""Helpers for the studio's browser tests: switch views, wait for the check, read the
recorder's reading line, open files, fill rule cells, read the 3D display and the FCL
text, and take the screenshots docs/studio.md shows."""

from __future__ import annotations

import os
from typing import Any

from tests.conftest import ROOT

CHROMIUM = "/usr/bin/chromium"
ARTIFACTS = ROOT / "test-artifacts" / "studio"
DOCS_IMG = ROOT / "docs" / "img" / "studio"
ARGS = [
    "--headless",
    "--no-sandbox",
    "--disable-gpu",
    "--disable-background-networking",
    "--disable-component-update",
    "--no-first-run",
]
# the recorder chart holds at least that many samples
RECORDED = (
    "(() => { const d = document.querySelector('#rec-chart').data; return d && d[0].x.length >= %s })()"
)


def shot(pg: Any, name: str, *, doc: bool = False) -> None:
    """A screenshot in test-artifacts/studio/; ``doc``: one of docs/studio.md's pictures,
    also written to docs/img/studio/ when FUZZYCTL_STUDIO_DOCS is set (`make docs-img`)."""
    ARTIFACTS.mkdir(parents=True, exist_ok=True)
    pg.screenshot(path=str(ARTIFACTS / f"{name}.png"))
    if doc and os.environ.get("FUZZYCTL_STUDIO_DOCS"):
        DOCS_IMG.mkdir(parents=True, exist_ok=True)
        pg.screenshot(path=str(DOCS_IMG / f"{name}.png"))


def rule_mode(pg: Any, mode: str) -> None:
    """The rule view as matrix, rows (Table), columns (Siemens) or text."""
    tab(pg, "rules")
    pg.click(f'#view-rules .segmented [data-mode="{mode}"]')
    pg.wait_for_function(f"document.querySelector('#view-rules').dataset.mode === '{mode}'")


def set_cell(pg: Any, rule: int, var: str, term: str) -> None:
    """Pick ``term`` in the rule table's cell of rule index ``rule`` and ``var``."""
    pg.click(f'#rule-table td.cell[data-rule="{rule}"][data-var="{var}"]')
    pg.select_option(f'#rule-table select[data-rule="{rule}"][data-var="{var}"]', term)
    pg.wait_for_selector(f'#rule-table td.cell[data-rule="{rule}"][data-var="{var}"]:not(:has(select))')


def cell_text(pg: Any, rule: int, var: str) -> str:
    text: str = pg.inner_text(f'#rule-table td.cell[data-rule="{rule}"][data-var="{var}"]')
    return text.strip()


def tab(pg: Any, view: str) -> None:
    pg.click(f'[role=tab][data-view="{view}"]')
    pg.wait_for_selector(f"#view-{view}:not([hidden])")


def checks(pg: Any) -> int:
    """How many checks of the model have come back so far."""
    return int(pg.get_attribute("body", "data-checks") or "0")


def checked(pg: Any) -> None:
    """Wait until the check of the model has seen every change made so far."""
    pg.wait_for_function(
        "document.body.dataset.changes === undefined"
        " || document.body.dataset.changes === document.body.dataset.checkedChanges",
        timeout=60000,
    )


def settle(pg: Any) -> None:
    """Wait for the pending check of the model (an edit that reaches the server first, as
    the rule and term fields do, has 300 ms to come back and make its change)."""
    pg.wait_for_timeout(300)
    checked(pg)


def reading(pg: Any, index: int) -> dict[str, float]:
    """Put the reading line on sample ``index`` and read every value at once."""
    pg.wait_for_function("document.querySelector('#view-recorder').dataset.running === 'false'")
    pg.wait_for_timeout(300)  # a request under way when Stop was pressed is dropped
    pg.eval_on_selector("#rec-read", f"(e) => {{ e.value = {index}; e.dispatchEvent(new Event('input')); }}")
    values: dict[str, float] = pg.evaluate(
        "Object.fromEntries([...document.querySelectorAll('#rec-values td[data-value]')]"
        ".map((td) => [td.id.slice(8), parseFloat(td.dataset.value)]))"
    )
    return values


def open_file(pg: Any, path: str, *, discard: bool = False) -> None:
    """File > Open; ``discard``: the project open has unsaved changes, answer Discard."""
    pg.click("#btn-open")
    if discard:
        pg.click("#confirm-discard")
    pg.select_option("#open-list", path)
    pg.click("#open-ok")
    pg.wait_for_function(f"document.querySelector('#project-name').textContent.includes('{path}')")
    settle(pg)


def new_project(pg: Any, name: str, inputs: int, outputs: int) -> None:
    """File > New: the manual's "Define Project" dialog."""
    pg.click("#btn-new")
    pg.fill("#new-name", name)
    pg.fill("#new-inputs", str(inputs))
    pg.fill("#new-outputs", str(outputs))
    pg.click("#new-ok")
    pg.wait_for_selector("#diagram svg")
    settle(pg)


def surface_z(pg: Any) -> list[list[float]]:
    pg.wait_for_function(
        "document.querySelector('#sf-chart').data && document.querySelector('#sf-chart').data.length"
    )
    z: list[list[float]] = pg.evaluate("document.querySelector('#sf-chart').data[0].z")
    return z


def fcl_text(pg: Any) -> str:
    tab(pg, "text")
    pg.wait_for_function("document.querySelector('#code-input').value.includes('FUNCTION_BLOCK')")
    text: str = pg.input_value("#code-input")
    return text
