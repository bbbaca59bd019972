"""The studio's findings: a file with a planted gap (no rule for x hi AND y hi) and a dead
rule (its term lies outside the input's RANGE).  Expected values come from the engine
sampled point by point (explain() on a grid: where no rule fires, which terms are above 0
there) and from the FCL text the check returns (the line of each rule), never from
/api/findings itself."""

from __future__ import annotations

import json
from pathlib import Path
from typing import Any

import pytest
from fastapi.testclient import TestClient

import fuzzyctl
from fuzzyctl.studio import create_app

GAPDEMO = """\
FUNCTION_BLOCK gapdemo
VAR_INPUT
    x : REAL;
    y : REAL;
END_VAR
VAR_OUTPUT
    z : REAL;
END_VAR
FUZZIFY x
    TERM lo := (0, 1) (4, 1) (6, 0);
    TERM hi := (4, 0) (6, 1) (10, 1);
    TERM far := (20, 0) (25, 1) (30, 0);
    RANGE := (0 .. 10);
END_FUZZIFY
FUZZIFY y
    TERM lo := (0, 1) (4, 1) (6, 0);
    TERM hi := (4, 0) (6, 1) (10, 1);
    RANGE := (0 .. 10);
END_FUZZIFY
DEFUZZIFY z
    TERM a := 0;
    TERM b := 1;
    METHOD : CoGS;
    DEFAULT := 0;
    RANGE := (0 .. 1);
END_DEFUZZIFY
RULEBLOCK r
    AND : MIN;
    ACCU : MAX;
    RULE 1 : IF x IS lo AND y IS lo THEN z IS a;
    RULE 2 : IF x IS lo AND y IS hi THEN z IS b;
    RULE 3 : IF x IS hi AND y IS lo THEN z IS b;
    RULE 4 : IF x IS far AND y IS hi THEN z IS a;
END_RULEBLOCK
END_FUNCTION_BLOCK
"""
STEP = 0.05  # the brute-force grid: 201 x 201 points over [0, 10]^2


def brute_gap() -> tuple[dict[str, tuple[float, float]], dict[str, set[str]]]:
    """Over a grid: the bounding box of the points where no rule fires, and per input the
    terms above 0 at one of those points."""
    ctl = fuzzyctl.compile(fuzzyctl.load(GAPDEMO), backend="python")
    xs: list[float] = []
    ys: list[float] = []
    terms: dict[str, set[str]] = {"x": set(), "y": set()}
    for i in range(201):
        for j in range(201):
            p = {"x": i * STEP, "y": j * STEP}
            ex = ctl.explain(p)
            if all(r.degree == 0.0 for r in ex.rules):
                xs.append(p["x"])
                ys.append(p["y"])
                for t in ex.terms:
                    if t.degree > 0.0:
                        terms[t.variable].add(t.term)
    return {"x": (min(xs), max(xs)), "y": (min(ys), max(ys))}, terms


def line_of(text: str, needle: str) -> int:
    return next(i for i, line in enumerate(text.splitlines(), start=1) if needle in line)


@pytest.fixture(scope="module")
def reference() -> tuple[dict[str, tuple[float, float]], dict[str, set[str]]]:
    return brute_gap()


def test_api_findings_gap_terms_and_rule_lines(tmp_path: Path, reference: Any) -> None:
    (tmp_path / "gapdemo.fcl").write_text(GAPDEMO)
    client = TestClient(create_app(tmp_path, token=None), base_url="http://127.0.0.1:8770")
    opened = client.post("/api/open", json={"path": "gapdemo.fcl"}).json()
    doc = opened["document"]
    text = client.post("/api/check", json={"document": doc}).json()["text"]
    r = client.post("/api/findings", json={"document": doc})
    assert r.status_code == 200, r.text
    out = r.json()
    box, terms = reference
    (gap,) = out["gaps"]
    assert gap["output"] == "z"
    for k in ("x", "y"):
        lo, hi = gap["box"][k]
        assert lo == pytest.approx(box[k][0], abs=STEP) and hi == pytest.approx(box[k][1], abs=STEP)
        assert set(gap["terms"][k]) == terms[k]
    by_code = {f["code"]: f for f in out["findings"]}
    assert set(by_code) == {"analyze-gap", "analyze-dead"}
    dead = by_code["analyze-dead"]
    assert "rule 4" in dead["message"] and dead["line"] == line_of(text, "RULE 4 :")
    assert dead["element"] == "rule:0:3"
    assert by_code["analyze-gap"]["element"] == "var:z"
    # with the text the panel shows (the file as opened), the lines are the file's
    as_opened = client.post("/api/findings", json={"document": doc, "text": opened["text"]}).json()
    (dead_opened,) = [f for f in as_opened["findings"] if f["code"] == "analyze-dead"]
    assert dead_opened["line"] == line_of(GAPDEMO, "RULE 4 :") != dead["line"]
    # declared "z falls with x": rules 1 (x lo, y lo -> a = 0) and 3 (x hi, y lo -> b = 1)
    # conclude against it; the entries name the pairs fuzzyctl.analyze finds, at the lines
    mono = client.post("/api/findings", json={"document": doc, "monotone": ["z:-x"]}).json()
    expected = fuzzyctl.analyze(fuzzyctl.load(GAPDEMO), monotone=["z:-x"]).monotonicity[0].offending
    lines = [f for f in mono["findings"] if f["code"] == "analyze-monotone" and f["line"]]
    assert ("1", "3") in expected
    assert [(f["message"].split()[2], f["message"].split()[4]) for f in lines] == expected
    assert [f["line"] for f in lines] == [line_of(text, f"RULE {b} :") for _a, b in expected]
    # an invalid model (points out of order) is no request error: the check reports it
    broken = json.loads(json.dumps(doc))
    broken["blocks"][0]["fuzzify"][0]["terms"][0]["mf"]["points"].reverse()
    answer = client.post("/api/findings", json={"document": broken})
    assert answer.status_code == 200 and answer.json()["ok"] is False
    bad = client.post("/api/findings", json={"document": doc, "monotone": ["z:-nosuch"]})
    assert bad.status_code in (200, 400, 422) and "nosuch" in bad.text


def test_browser_matrix_surface_and_check_panel(page: Any, browser_project: Path, reference: Any) -> None:
    """In the real browser: the check panel lists the gap and the dead rule 4 at its line
    (a click goes to the rule), the matrix dashes the cells of the terms reaching into the
    gap, the 3D display draws the gap's footprint with the box's extent."""
    from tests.studio.browser import open_file, rule_mode, shot, tab

    pg = page
    box, terms = reference
    (browser_project / "gapdemo.fcl").write_text(GAPDEMO)
    open_file(pg, "gapdemo.fcl")
    pg.wait_for_selector('#findings-list li[data-code="analyze-dead"]', timeout=60000)
    tab(pg, "text")
    text = pg.input_value("#code-input")
    dead = pg.inner_text('#findings-list li[data-code="analyze-dead"]')
    assert f" {line_of(text, 'RULE 4 :')}:" in dead and "rule 4 can never fire" in dead
    gap = pg.inner_text('#findings-list li[data-code="analyze-gap"]')
    assert "no rule concluding z fires" in gap and f" {line_of(text, 'z : REAL')}:" in gap
    box_item = pg.inner_text('#findings-list li[data-code="analyze-gap-box"]')
    assert f"x in [{box['x'][0]:g}" in box_item or "x in [6, 10]" in box_item
    assert len(pg.query_selector_all("#findings-list li")) == 3  # gap, its box, the dead rule
    # a click on the dead rule goes to it in the rule editor
    pg.click('#findings-list li[data-code="analyze-dead"]')
    pg.wait_for_selector("#view-rules:not([hidden])")
    # the matrix: x down, y across; dashed where a term of each reaches into the gap
    rule_mode(pg, "matrix")
    pg.wait_for_selector("#rule-matrix td.gap")
    cells = {
        (td.get_attribute("data-row"), td.get_attribute("data-col"))
        for td in pg.query_selector_all("#rule-matrix td.gap")
    }
    assert cells == {(a, b) for a in terms["x"] for b in terms["y"]} == {("hi", "hi")}
    assert "gap of z" in pg.inner_text("#matrix-gaps")
    shot(pg, "34-findings-matrix", doc=True)
    # the 3D display: the footprint of the gap on the floor, with the box's extent
    tab(pg, "surface")
    has_gap = "c && c.data && c.data.some((t) => t.meta === 'gap')"
    pg.wait_for_function(
        f"(() => {{ const c = document.querySelector('#sf-chart'); return {has_gap} }})()", timeout=60000
    )
    trace = pg.evaluate("document.querySelector('#sf-chart').data.find((t) => t.meta === 'gap')")
    assert min(trace["x"]) == pytest.approx(box["x"][0], abs=STEP) and max(trace["x"]) == pytest.approx(
        box["x"][1], abs=STEP
    )
    assert min(trace["y"]) == pytest.approx(box["y"][0], abs=STEP) and max(trace["y"]) == pytest.approx(
        box["y"][1], abs=STEP
    )
    assert pg.evaluate("document.querySelector('#sf-chart').data.some((t) => t.meta === 'gap-area')")
    shot(pg, "35-findings-surface", doc=True)
