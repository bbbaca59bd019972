"""docs/notebooks: every notebook runs headless in a fresh kernel (nbclient), its asserts hold
and the rich displays of fuzzyctl.display reach the notebook as HTML."""

from __future__ import annotations

import time

import pytest

from tests.conftest import ROOT

nbformat = pytest.importorskip("nbformat")
nbclient = pytest.importorskip("nbclient")
pytest.importorskip("ipykernel")


def run(name: str) -> list[dict[str, object]]:
    nb = nbformat.read(ROOT / "docs" / "notebooks" / name, as_version=4)
    start = time.monotonic()
    nbclient.NotebookClient(
        nb, timeout=60, kernel_name="python3", resources={"metadata": {"path": str(ROOT)}}
    ).execute()
    assert time.monotonic() - start < 30  # the tour stays small
    return [cell for cell in nb.cells if cell.cell_type == "code"]


def html_of(cell: dict[str, object]) -> str:
    outputs = [o for o in cell["outputs"] if o.get("output_type") == "execute_result"]  # type: ignore[attr-defined]
    assert outputs, cell["source"]
    return str(outputs[-1]["data"].get("text/html", ""))


def test_tour_runs_and_displays() -> None:
    cells = run("tour.ipynb")
    controller, variable, _, explanation, analysis, loop = cells
    assert "FUNCTION_BLOCK" in html_of(controller) and "<code>RULE 1" in html_of(controller)
    assert html_of(controller).count("data:image/png;base64,") == 3  # error, rate, dheat plotted
    assert "<td>pos_big</td>" in html_of(variable) and "data:image/png" in html_of(variable)
    assert "rules fired</b> (1 of 25)" in html_of(explanation)
    assert "<td>gaps</td><td>0</td>" in html_of(analysis)
    assert "60" in str(loop["outputs"][-1]["data"]["text/plain"])  # type: ignore[index]


def test_jupyter_page_examples() -> None:
    import doctest
    import os

    cwd = os.getcwd()
    os.chdir(ROOT)
    try:
        result = doctest.testfile(str(ROOT / "docs" / "jupyter.md"), module_relative=False)
    finally:
        os.chdir(cwd)
    assert result.attempted >= 5 and result.failed == 0
