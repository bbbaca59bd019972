"""Interval type-2 systems through the studio's API (docs/type2.md, "Studio"): the lower
curve of every term (closed forms of MATLAB's scale/lag form), lower <= upper checked as a
diagnostic on the term, the evaluation views through the type-2 engine, FCL saved with
the lower functions, and the launch no longer refusing a type-2 file."""

from __future__ import annotations

import shutil
from pathlib import Path
from typing import Any

import numpy as np
import pytest
from fastapi.testclient import TestClient

import fuzzyctl
from fuzzyctl.studio import create_app
from fuzzyctl.studio.launch import prepare
from tests.conftest import EXAMPLES

FIS = EXAMPLES / "tipper_type2.fis"


@pytest.fixture
def client(tmp_path: Path) -> TestClient:
    shutil.copy(FIS, tmp_path / FIS.name)
    return TestClient(create_app(tmp_path, token=None), base_url="http://127.0.0.1:8770")


def opened(client: TestClient) -> dict[str, Any]:
    r = client.post("/api/open", json={"path": FIS.name})
    assert r.status_code == 200, r.text
    data: dict[str, Any] = r.json()
    return data


def body(data: dict[str, Any], **extra: Any) -> dict[str, Any]:
    return {"document": data["document"], "block": 0, "settings": data.get("settings") or {}, **extra}


def interp(points: list[list[float]], x: float) -> float:
    return float(np.interp(x, [p[0] for p in points], [p[1] for p in points]))


def test_lower_curves_are_matlabs_form(client: TestClient) -> None:
    data = opened(client)
    curves = data["curves"]
    # food.rancid: trapezoid -2 0 1 3, scale 1, lags 0.1 (rising) and 0.3 (falling)
    rancid = curves["food"]["rancid"]
    assert rancid["lower_kind"] == "scale_lag" and rancid["lower_fcl"] == "LOWER SCALE 1 LAG 0.1 0.3"
    for x in np.linspace(0, 10, 41):
        up = max(0.0, min((x + 2) / 2, 1.0, (3 - x) / 2))
        lag = 0.1 if x < 0 else 0.3
        assert interp(rancid["lower"], x) == pytest.approx(max(0.0, (up - lag) / (1 - lag)), abs=1e-12)
    # tip.average: triangle 10 15 20, scale 0.7, lag 0.1
    average = curves["tip"]["average"]
    for x in np.linspace(0, 30, 61):
        up = max(0.0, min((x - 10) / 5, (20 - x) / 5))
        assert interp(average["lower"], x) == pytest.approx(0.7 * max(0.0, (up - 0.1) / 0.9), abs=1e-12)
    assert data["ok"] and "LOWER SCALE 0.7 LAG 0.1" in data["text"]


def test_lower_above_upper_is_an_error_on_the_term(client: TestClient) -> None:
    data = opened(client)
    term = data["document"]["blocks"][0]["fuzzify"][0]["terms"][0]  # service.poor: TRIAN -5 0 5
    term["lower"] = {
        "type": "lower",
        "mf": {"type": "shape", "kind": "triangle", "params": [-6, 0, 6], "height": 1},
    }
    report = client.post("/api/check", json=body(data)).json()
    assert not report["ok"]
    [d] = [d for d in report["diagnostics"] if d["code"] == "type2-lower"]
    # at x = -5 the upper is 0 and the lower (x + 6) / 6 = 1/6
    assert d["element"] == "term:service:poor" and d["severity"] == "error"
    assert "service.poor" in d["message"] and "(0.166667)" in d["message"] and "at -5" in d["message"]
    # a scale outside (0, 1] is refused when the model is read, naming the term
    term["lower"] = {"type": "lower", "mf": None, "scale": 1.5, "lag": [0.2]}
    r = client.post("/api/check", json=body(data))
    assert r.status_code in (400, 422) or not r.json()["ok"]
    assert "scale" in r.text.lower() and "poor" in r.text


def test_evaluation_views_use_the_type2_engine(client: TestClient) -> None:
    data = opened(client)
    controller = fuzzyctl.compile(fuzzyctl.load(FIS).main)
    e = client.post("/api/explain", json=body(data, inputs={"service": 3, "food": 8})).json()
    # by hand: poor(3) = 0.4, lower 0.25; good(3) = 0.6, lower 0.45; delicious(8) 0.5, lower 0.3
    firing = [v for r in e["rules"] for v in (r["lower"], r["degree"])]
    assert firing == pytest.approx([0.25, 0.4, 0.45, 0.6, 0.3, 0.5], rel=1e-15)
    terms = {(t["variable"], t["term"]): (t["lower"], t["degree"]) for t in e["terms"]}
    assert terms[("service", "good")] == pytest.approx((0.45, 0.6), rel=1e-15)
    [out] = e["outputs"]
    yl, yr = out["interval"]
    assert yl < out["value"] < yr and out["value"] == controller.evaluate(service=3, food=8)["tip"]
    s = client.post("/api/surface", json=body(data, x="service", y="food", z="tip", points=5)).json()
    z = s["frames"][0]["z"]
    for j, fy in enumerate(s["y"]):
        for i, sx in enumerate(s["x"]):
            assert z[j][i] == controller.evaluate(service=sx, food=fy)["tip"]
    view = client.post("/api/ruleview", json=body(data, inputs={"service": 3, "food": 8})).json()
    first = view["rules"][0]  # IF service IS poor OR food IS rancid THEN tip IS cheap
    assert (first["lower"], first["degree"]) == pytest.approx((0.25, 0.4), rel=1e-15)
    poor = first["literals"][0]
    assert (poor["term"], poor["lower"], poor["degree"]) == ("poor", pytest.approx(0.25), pytest.approx(0.4))
    [cheap] = first["conclusions"]

    # upper: min(0.4, cheap(x)); lower: min(0.25, (cheap(x) - 0.2) / 0.8), cheap = TRIAN 0 5 10
    def cheap_at(x: float) -> float:
        return max(0.0, min(x / 5, (10 - x) / 5))

    for x, y in zip(cheap["set"]["x"], cheap["set"]["y"], strict=True):
        assert y == pytest.approx(min(0.4, cheap_at(x)), abs=1e-12)
    for x, y in zip(cheap["lower_set"]["x"], cheap["lower_set"]["y"], strict=True):
        assert y == pytest.approx(min(0.25, max(0.0, (cheap_at(x) - 0.2) / 0.8)), abs=1e-12)
    assert len(cheap["lower_set"]["x"]) > 50
    assert view["outputs"][0]["interval"] == [yl, yr]


def test_saved_fcl_keeps_the_lower_functions(client: TestClient, tmp_path: Path) -> None:
    data = opened(client)
    r = client.post("/api/save", json={**body(data), "path": "t2.fcl"})
    assert r.status_code == 200, r.text
    saved = fuzzyctl.load(tmp_path / "t2.fcl").main
    original = fuzzyctl.load(FIS).main
    assert [t.lower for f in saved.fuzzify for t in f.terms] == [
        t.lower for f in original.fuzzify for t in f.terms
    ]
    assert [t.lower for d in saved.defuzzify for t in d.terms] == [
        t.lower for d in original.defuzzify for t in d.terms
    ]


def test_launch_opens_a_type2_file(tmp_path: Path) -> None:
    shutil.copy(FIS, tmp_path / FIS.name)
    launch = prepare(tmp_path / FIS.name, no_token=True)
    try:
        assert launch.url.startswith("http://127.0.0.1:")
    finally:
        launch.sock.close()


@pytest.mark.parametrize(("sugeno", "explicit"), [(True, False), (False, True), (True, True)])
def test_sugeno_and_explicit_systems(client: TestClient, sugeno: bool, explicit: bool) -> None:
    from fuzzyctl.engine.type2 import Type2Controller
    from fuzzyctl.model import Document
    from fuzzyctl.studio.analysis import document_to_json
    from tests.engine.type2_systems import random_it2

    fb = random_it2(7, sugeno=sugeno, explicit=explicit)
    data = {"document": document_to_json(Document((fb,))), "settings": {}}
    report = client.post("/api/check", json=body(data)).json()
    assert report["ok"], report["diagnostics"]
    x0 = report["curves"]["x0"]
    assert all("lower" in c for c in x0.values())
    if explicit:
        assert {c["lower_kind"] for c in x0.values()} == {"mf"}
    point = {v.name: 3.7 for v in fb.inputs}
    e = client.post("/api/explain", json=body(data, inputs=point)).json()
    expected = Type2Controller(fb).explain(point)
    assert e["outputs"][0]["value"] == expected.outputs[0].value
    assert e["outputs"][0]["interval"] == [expected.outputs[0].yl, expected.outputs[0].yr]
    view = client.post("/api/ruleview", json=body(data, inputs=point)).json()
    assert [(r["lower"], r["degree"]) for r in view["rules"]] == [(r.lower, r.upper) for r in expected.rules]
