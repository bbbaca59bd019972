"""The editing endpoints: rule lines and terms read by the FCL parser with diagnostics at the
typed line and column, the line cache giving what a fresh read gives, the rule viewer's
activated sets against closed forms, the shape catalogue, and what FCL cannot write."""

from __future__ import annotations

import shutil
from pathlib import Path
from typing import Any

import pytest
from fastapi.testclient import TestClient

import fuzzyctl
from fuzzyctl.formats.json.writer import encode, to_dict
from fuzzyctl.model import SHAPES, Document, ShapeMF
from fuzzyctl.studio import create_app
from tests.conftest import EXAMPLES, data_path

BASE = "http://127.0.0.1:8770"


@pytest.fixture
def client(tmp_path: Path) -> TestClient:
    shutil.copy(EXAMPLES / "crane.fcl", tmp_path / "crane.fcl")
    return TestClient(create_app(tmp_path, token=None), base_url=BASE)


def crane(client: TestClient) -> dict[str, Any]:
    doc: dict[str, Any] = client.post("/api/open", json={"path": "crane.fcl"}).json()["document"]
    return doc


def strip(data: Any) -> Any:
    if isinstance(data, dict):
        return {k: strip(v) for k, v in data.items() if k not in ("span", "comments", "placed_comments")}
    if isinstance(data, list):
        return [strip(v) for v in data]
    return data


def parse(client: TestClient, doc: dict[str, Any], text: str) -> dict[str, Any]:
    r = client.post("/api/rules/parse", json={"document": doc, "text": text})
    assert r.status_code == 200, r.text
    out: dict[str, Any] = r.json()
    return out


def test_rule_lines_are_read_by_the_fcl_parser(client: TestClient) -> None:
    doc = crane(client)
    text = (
        "IF distance IS far OR NOT angle IS zero THEN power IS zero WITH 0.5\n\n// a comment\n"
        "RULE 1 : IF angle IS zero THEN power IS pos_high"
    )
    out = parse(client, doc, text)
    assert out["ok"] and out["lines"] == [1, 4]
    first, second = out["rules"]
    # the line without a label takes its position, or the next free number
    assert (first["label"], second["label"]) == ("2", "1")
    assert first["condition"]["type"] == "or" and first["conclusions"][0]["weight"] == 0.5
    # the same rules as the FCL text gives for these lines in the function block
    source = (EXAMPLES / "crane.fcl").read_text()
    start = source.index("RULE 1 :")
    end = source.index("END_RULEBLOCK")
    fcl = (
        source[:start]
        + "RULE 2 : "
        + text.split("\n")[0]
        + ";\n"
        + text.split("\n")[3]
        + ";\n"
        + source[end:]
    )
    expected = fuzzyctl.load(fcl).main.rule_blocks[0].rules
    assert strip(out["rules"]) == [strip(encode(r)) for r in expected]
    assert out["rules"][1]["comments"] == ["// a comment"]
    # an unknown term: the check's error, at its line and column of the typed text
    bad = "IF distance IS far THEN power IS zero\nIF distance IS farr THEN power IS zero"
    out = parse(client, doc, bad)
    assert not out["ok"] and out["rules"] is None
    [error] = [d for d in out["diagnostics"] if d["severity"] == "error"]
    assert "farr" in error["message"]
    # the subcondition's column in the typed line (the "RULE 2 : " put in front is not counted)
    assert (error["line"], error["column"]) == (2, bad.split("\n")[1].index("distance") + 1)
    # a syntax error: its line and column too
    out = parse(client, doc, "IF distance IS far THEN power IS zero\nIF distance IS THEN power IS zero")
    [error] = out["diagnostics"]
    assert (error["line"], error["column"]) == (2, 16)


def test_comments_stay_with_their_rules(client: TestClient) -> None:
    doc = crane(client)
    text = (
        "(* the first rule,\n   two lines of comment *)\nIF angle IS zero THEN power IS zero\n"
        "// the second\nIF angle IS neg_big THEN power IS neg_high"
    )
    out = parse(client, doc, text)
    assert out["lines"] == [3, 5]
    assert [r["label"] for r in out["rules"]] == ["1", "2"]
    assert out["rules"][0]["comments"] == ["(* the first rule,\n   two lines of comment *)"]
    assert out["rules"][1]["comments"] == ["// the second"]


def test_the_line_cache_gives_what_a_fresh_read_gives(client: TestClient) -> None:
    doc = crane(client)
    fb = fuzzyctl.load(EXAMPLES / "crane.fcl").main
    from fuzzyctl.fcl.writer import rule_text

    lines = [rule_text(r).split(" : ", 1)[1] for r in fb.rule_blocks[0].rules]
    parse(client, doc, "\n".join(lines))  # every line read, then cached
    lines.insert(3, "IF distance IS zero OR angle IS pos_big THEN power IS neg_high")
    lines[10] = lines[10].replace("THEN power IS", "THEN power IS pos_high, power IS")
    cached = parse(client, doc, "\n".join(lines))
    # the same lines read afresh (a comment makes each line new to the cache): the same
    # rules and labels
    fresh = parse(client, doc, "\n".join(f"{line} (* fresh *)" for line in lines))
    assert cached["ok"] and fresh["ok"]
    assert strip(cached["rules"]) == strip(fresh["rules"])
    assert [r["label"] for r in cached["rules"]] == [str(i + 1) for i in range(26)]


@pytest.mark.parametrize(
    ("text", "kind", "params"),
    [
        ("GAUSS 3 0.5", "gaussian", [3.0, 0.5]),
        ("Gaussian 3 0.5 0.8", "gaussian", [3.0, 0.5]),
        ("GBELL 2 4 6", "bell", [6.0, 2.0, 4.0]),
        ("TRIAN 0 5 10", "triangle", [0.0, 5.0, 10.0]),
        ("SIGM 2 5", "sigmoid", [5.0, 2.0]),
    ],
)
def test_a_term_typed_as_fcl(client: TestClient, text: str, kind: str, params: list[float]) -> None:
    doc = crane(client)
    r = client.post("/api/term/parse", json={"document": doc, "variable": "angle", "text": text}).json()
    assert r["ok"] and r["mf"]["type"] == "shape"
    assert (r["mf"]["kind"], r["mf"]["params"]) == (kind, params)


def test_a_wrong_term_names_its_column(client: TestClient) -> None:
    doc = crane(client)
    r = client.post(
        "/api/term/parse", json={"document": doc, "variable": "angle", "text": "(0, 0) (5, 1) (3"}
    ).json()
    assert not r["ok"] and r["mf"] is None
    assert r["diagnostics"][0]["line"] == 1 and r["diagnostics"][0]["column"] >= 15
    r = client.post("/api/term/parse", json={"document": doc, "variable": "power", "text": "12.5"}).json()
    assert r["ok"] and r["mf"] == {"type": "singleton", "value": 12.5}


def test_shape_catalogue_is_the_models(client: TestClient) -> None:
    shapes = client.get("/api/shapes").json()
    assert {k: v["params"] for k, v in shapes.items()} == {k: list(s.params) for k, s in SHAPES.items()}


def triangle(x: float, a: float, b: float, c: float) -> float:
    if x <= a or x >= c:
        return 0.0
    return (x - a) / (b - a) if x <= b else (c - x) / (c - b)


def test_rule_viewer_sets_are_the_activated_terms() -> None:
    fis = data_path("fuzzylite", "mamdani", "matlab", "tipper.fis")
    document = fuzzyctl.load(fis)
    client = TestClient(create_app(EXAMPLES, token=None), base_url=BASE)
    point = {"service": 3.0, "food": 7.5}
    view = client.post("/api/ruleview", json={"document": to_dict(document), "inputs": point}).json()
    ctl = fuzzyctl.compile(document)
    explanation = ctl.explain(point)
    tip = document.main.defuzzify_block("tip")
    assert tip is not None
    assert [r["degree"] for r in view["rules"]] == pytest.approx([r.degree for r in explanation.rules])
    checked = 0
    for row in view["rules"]:
        for c in row["conclusions"]:
            term = tip.term(c["term"])
            assert term is not None and isinstance(term.mf, ShapeMF) and term.mf.kind == "triangle"
            a, b, cc = (float(p) for p in term.mf.params)  # type: ignore[arg-type]
            for x, y in zip(c["set"]["x"], c["set"]["y"], strict=True):
                assert y == pytest.approx(c["weight"] * min(row["degree"], triangle(x, a, b, cc)), abs=1e-12)
                checked += 1
        # the literals carry the term degrees the engine explains
        for lit in row["literals"]:
            assert lit["degree"] == pytest.approx(
                next(
                    t.degree
                    for t in explanation.terms
                    if (t.variable, t.term) == (lit["variable"], lit["term"])
                )
            )
    assert checked > 100
    ctl.reset()
    assert view["outputs"][0]["value"] == pytest.approx(ctl.evaluate(point)["tip"], abs=1e-12)


def test_what_fcl_cannot_write_is_listed(client: TestClient) -> None:
    document = fuzzyctl.load(data_path("fuzzylite", "hybrid", "tipper.fll"))
    r = client.post("/api/check", json={"document": to_dict(Document(document.blocks))}).json()
    assert any("rule weight" in loss for loss in r["fcl_losses"])
    assert any("lock-range" in loss for loss in r["fcl_losses"])
    opened = client.post("/api/open", json={"path": "crane.fcl"}).json()
    assert opened["fcl_losses"] == [] and set(opened["curves"]) == {"distance", "angle", "power"}


def test_an_expression_term_is_read_too(client: TestClient) -> None:
    """A term given by an expression (jFuzzyLogic FUNCTION, a Takagi-Sugeno output) has no
    parameter fields: it is written and read as FCL."""
    doc = crane(client)
    r = client.post(
        "/api/term/parse", json={"document": doc, "variable": "power", "text": "FUNCTION 2 * distance + 1"}
    ).json()
    assert r["ok"] and r["mf"]["type"] == "function"
    assert r["mf"]["expr"]["type"] == "binary" and r["mf"]["expr"]["op"] == "+"


def test_a_rule_without_if_part_is_typed_as_fcl_writes_it(client: TestClient, tmp_path: Path) -> None:
    """IF ALWAYS THEN (fcl/no_if.py, Siemens 1.5) reads back as a rule without an IF part,
    as the FCL text of a whole block does; ALWAYS inside a condition is refused (it is no
    variable of the model)."""
    doc = crane(client)
    out = parse(client, doc, "IF ALWAYS THEN power IS zero\nIF angle IS zero THEN power IS zero")
    assert out["ok"], out["diagnostics"]
    assert out["rules"][0]["condition"] is None and out["rules"][1]["condition"]["type"] == "is"
    # the FCL text of the whole block reads the same line the same way
    text = (EXAMPLES / "crane.fcl").read_text()
    text = text.replace("VAR_INPUT", "VAR_INPUT\n    ALWAYS : REAL := 1.0;", 1)
    text = text.replace("END_RULEBLOCK", "RULE 99 : IF ALWAYS THEN power IS zero;\nEND_RULEBLOCK", 1)
    (tmp_path / "always.fcl").write_text(text)
    rules = fuzzyctl.load(tmp_path / "always.fcl").main.rule_blocks[0].rules
    assert rules[-1].label == "99" and rules[-1].condition is None
    bad = parse(client, doc, "IF ALWAYS AND angle IS zero THEN power IS zero")
    assert not bad["ok"] and "ALWAYS stands alone" in bad["diagnostics"][0]["message"]
