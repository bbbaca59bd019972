"""Every term kind the engine reads is editable in the browser: fields named after the
kind's parameters (fuzzyctl.model.SHAPES) holding the file's values, every kind reachable
from the Shape picker and written back as FCL the parser reads, the term typed as FCL,
handles dragged on the chart, and every curve labelled.

The file is fuzzylite's AllTerms.fis (vendored in tests/data); expected values come from
the file, the model's catalogue of shapes, or closed forms."""

from __future__ import annotations

import math
from typing import Any

import pytest

import fuzzyctl
from fuzzyctl.model import SHAPES, PointsMF, ShapeMF
from tests.conftest import data_path
from tests.studio.browser import checked, fcl_text, settle, shot, tab

# cosine_half is only a kind of its own with a variable half-width (else FCL writes a cosine)
# (points and singletons first: they go to input terms; an output cannot mix singletons with
# fuzzy sets)
FUZZY_KINDS = ["points", "singleton"] + [k for k in SHAPES if k not in ("constant", "linear", "cosine_half")]


def import_allterms(pg: Any) -> Any:
    fis = data_path("fuzzylite", "mamdani", "AllTerms.fis")
    pg.set_input_files("#import-file", str(fis))
    pg.wait_for_function("document.querySelector('#status').textContent.includes('imported')")
    settle(pg)
    return fuzzyctl.load(fis).main


def params(pg: Any) -> list[str]:
    values: list[str] = pg.evaluate(
        "[...document.querySelectorAll('#term-params input')].map((e) => e.value)"
    )
    return values


def test_every_term_kind_is_editable(page: Any) -> None:
    pg = page
    fb = import_allterms(pg)
    tab(pg, "variable")
    pg.select_option("#var-select", "AllInputTerms")
    # every term: its kind, and one field per parameter (and the height) with its value
    for term in fb.fuzzify[0].terms:
        pg.select_option("#term-select", label=term.name)
        mf = term.mf
        if isinstance(mf, ShapeMF):
            assert pg.input_value("#term-kind") == mf.kind
            names = pg.evaluate(
                "[...document.querySelectorAll('#term-params label')].map((e) => e.textContent)"
            )
            assert names == [*SHAPES[mf.kind].params, "height"]
            assert [float(v) for v in params(pg)] == [*mf.params, mf.height]
        else:
            assert isinstance(mf, PointsMF) and pg.input_value("#term-kind") == "points"
            xs = pg.evaluate(
                "[...document.querySelectorAll('#points-table input[aria-label$=\" x\"]')]"
                ".map((e) => +e.value)"
            )
            assert xs == [p.x for p in mf.points]
    # every curve carries its name
    pg.wait_for_function("document.querySelector('#mf-chart').layout")
    labels = pg.evaluate("document.querySelector('#mf-chart').layout.annotations.map((a) => a.text)")
    assert sorted(labels) == sorted(t.name for t in fb.fuzzify[0].terms)
    shot(pg, "23-every-shape", doc=True)

    # a Gaussian's sigma typed: the engine's curve is the closed form of the new sigma
    pg.select_option("#term-select", label="I")
    pg.fill("#param-1", "0.4")
    pg.press("#param-1", "Enter")
    pg.wait_for_function(
        "(() => { const c = document.querySelector('#mf-chart').data.find((t) => t.name === 'I');"
        " const i = c.x.findIndex((x) => x > 3.3);"
        " return Math.abs(c.y[i] - Math.exp(-((c.x[i] - 3) ** 2) / 0.32)) < 1e-9; })()"
    )
    # the bell's centre dragged from 4 to 5 along the axis
    pg.select_option("#term-select", label="M")
    box = pg.locator("#mf-chart").bounding_box()
    x4, x5, y1 = pg.evaluate(
        "(() => { const l = document.querySelector('#mf-chart')._fullLayout;"
        " return [l.xaxis.l2p(4) + l.xaxis._offset, l.xaxis.l2p(5) + l.xaxis._offset,"
        " l.yaxis.l2p(1) + l.yaxis._offset]; })()"
    )
    pg.mouse.move(box["x"] + x4, box["y"] + y1)
    pg.mouse.down()
    for k in range(1, 9):
        pg.mouse.move(box["x"] + x4 + (x5 - x4) * k / 8, box["y"] + y1)
    pg.mouse.up()
    settle(pg)
    centre = float(pg.input_value("#param-0"))
    assert centre == pytest.approx(5, abs=0.05)
    assert float(pg.input_value("#param-1")) == 0.25  # the width stays
    # a term typed as FCL, in any spelling the parser reads; a wrong one is refused
    pg.select_option("#term-select", label="E")
    pg.fill("#term-fcl", "TRAPE 1 1.5 2 2.5")
    pg.press("#term-fcl", "Enter")
    pg.wait_for_function(
        "document.querySelector('#param-1') && document.querySelector('#param-1').value === '1.5'"
    )
    assert params(pg) == ["1", "1.5", "2", "2.5", "1"]
    pg.fill("#term-fcl", "TRAPE 1 2")
    pg.press("#term-fcl", "Enter")
    pg.wait_for_selector("#term-fcl-diags li.error")
    assert "4 parameters" in pg.inner_text("#term-fcl-diags")
    assert params(pg) == ["1", "1.5", "2", "2.5", "1"]  # the term keeps its last good form

    # every kind from the Shape picker, each on its own term, placed where the term was
    terms = [t.name for t in fb.fuzzify[0].terms] + [t.name for t in fb.defuzzify[0].terms]
    wanted: dict[tuple[str, str], str] = {}
    for kind, name in zip(FUZZY_KINDS, terms, strict=False):
        variable = "AllInputTerms" if len(wanted) < len(fb.fuzzify[0].terms) else "AllOutputTerms"
        if pg.input_value("#var-select") != variable:
            pg.select_option("#var-select", variable)
        pg.select_option("#term-select", label=name)
        pg.select_option("#term-kind", kind)
        wanted[(variable, name)] = kind
    checked(pg)  # the check of the model after the last change
    assert len(wanted) == len(FUZZY_KINDS)
    assert pg.inner_text("#check-badge").startswith("OK")
    edited = fuzzyctl.load(fcl_text(pg)).main
    for (variable, name), kind in wanted.items():
        block = edited.fuzzify_block(variable) or edited.defuzzify_block(variable)
        assert block is not None
        term = block.term(name)
        assert term is not None
        got = term.mf.kind if isinstance(term.mf, ShapeMF) else type(term.mf).__name__
        assert got == {"points": "PointsMF", "singleton": "SingletonMF"}.get(kind, kind), (name, kind)
    # placed where the term was: the new shape's parameters lie in the variable's range
    for (variable, name), _kind in wanted.items():
        block = edited.fuzzify_block(variable) or edited.defuzzify_block(variable)
        assert block is not None
        term = block.term(name)
        assert term is not None
        if isinstance(term.mf, ShapeMF) and term.mf.kind in (
            "triangle",
            "trapezoid",
            "rectangle",
            "gaussian",
        ):
            assert all(
                -1 <= float(p) <= 7.5 for p in term.mf.params if isinstance(p, float) and math.isfinite(p)
            )
