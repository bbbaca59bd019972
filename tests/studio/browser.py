"""Helpers for the studio's browser tests: switch views, wait for the check, read the
recorder's reading line, open files, read the 3D display and the FCL text."""

from __future__ import annotations

from typing import Any

from tests.conftest import ROOT

CHROMIUM = "/usr/bin/chromium"
ARTIFACTS = ROOT / "test-artifacts" / "studio"
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


def shot(pg: Any, name: str) -> None:
    ARTIFACTS.mkdir(parents=True, exist_ok=True)
    pg.screenshot(path=str(ARTIFACTS / f"{name}.png"))


def tab(pg: Any, view: str) -> None:
    pg.click(f'[role=tab][data-view="{view}"]')
    pg.wait_for_selector(f"#view-{view}:not([hidden])")


def settle(pg: Any) -> None:
    """Wait for the pending check of the model."""
    pg.wait_for_timeout(400)


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


def open_file(pg: Any, path: str) -> None:
    pg.click("#btn-open")
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
