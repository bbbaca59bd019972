"""The studio applies the validation every reader applies (issue 25, point 4): a model it is
sent with a degree of 1.5, points out of order or a number no float holds is refused with
its JSON path (a 4xx, not a 500), and never saved as an FCL that ``check`` refuses."""

from __future__ import annotations

import json
import shutil
from pathlib import Path
from typing import Any

import pytest
from fastapi.testclient import TestClient

import fuzzyctl
import fuzzyctl.diagnostics
from fuzzyctl.studio import create_app
from tests.conftest import EXAMPLES

BASE = "http://127.0.0.1:8770"


@pytest.fixture
def project(tmp_path: Path) -> Path:
    root = tmp_path / "project"
    root.mkdir()
    shutil.copy(EXAMPLES / "crane.fcl", root / "crane.fcl")
    return root


def _first_points(document: dict[str, Any]) -> list[dict[str, Any]]:
    for term in document["blocks"][0]["fuzzify"][0]["terms"]:
        if term["mf"]["type"] == "points" and len(term["mf"]["points"]) >= 2:
            points: list[dict[str, Any]] = term["mf"]["points"]
            return points
    raise AssertionError("crane.fcl has a points term")


@pytest.mark.parametrize("change", ["degree", "ascending", "huge"])
def test_an_invalid_model_is_refused_with_its_json_path_and_not_saved(project: Path, change: str) -> None:
    client = TestClient(create_app(project, file="crane.fcl", token=None), base_url=BASE)
    r = client.post("/api/open", json={"path": "crane.fcl"})
    assert r.status_code == 200, r.text
    document = r.json()["document"]
    points = _first_points(document)
    if change == "degree":
        points[0]["y"] = 1.5
    elif change == "ascending":
        points[0]["x"], points[1]["x"] = points[1]["x"] + 1.0, points[0]["x"]
    body = json.dumps({"path": "copy.fcl", "document": document})
    if change == "huge":
        body = body.replace(json.dumps(points[0]["x"]), "9" * 350, 1)
    r = client.post("/api/save", content=body, headers={"content-type": "application/json"})
    assert 400 <= r.status_code < 500, r.text
    assert "$.blocks[0].fuzzify[0].terms[" in r.text or "too large" in r.text, r.text
    assert not (project / "copy.fcl").exists()


@pytest.mark.parametrize("change", ["degree", "ascending"])
def test_check_answers_an_invalid_model_with_its_report(project: Path, change: str) -> None:
    # /api/check is how the editors learn what is wrong while the user edits: an invalid
    # model is its ordinary answer (200, ok false), the error tied to the term as the FCL
    # reader's validation reports it, so the page shows it next to the term (a 422 made the
    # browser log an error and the editor show nothing).  Saving it is still refused (above).
    client = TestClient(create_app(project, file="crane.fcl", token=None), base_url=BASE)
    document = client.post("/api/open", json={"path": "crane.fcl"}).json()["document"]
    variable = document["blocks"][0]["fuzzify"][0]["variable"]
    term = next(t for t in document["blocks"][0]["fuzzify"][0]["terms"] if t["mf"]["type"] == "points")
    points = _first_points(document)
    if change == "degree":
        points[0]["y"] = 1.5
    else:
        points[0]["x"], points[1]["x"] = points[1]["x"] + 1.0, points[0]["x"]
    r = client.post("/api/check", json={"document": document})
    assert r.status_code == 200, r.text
    report = r.json()
    assert report["ok"] is False
    errors = [d for d in report["diagnostics"] if d["severity"] == "error"]
    code = {"degree": "degree-out-of-range", "ascending": "points-not-ascending"}[change]
    assert [d["element"] for d in errors if d["code"] == code] == [f"term:{variable}:{term['name']}"], errors
    # the FCL text the check read is refused by the CLI's reader too: one validation
    with pytest.raises(fuzzyctl.diagnostics.DiagnosticError):
        fuzzyctl.load(report["text"])
