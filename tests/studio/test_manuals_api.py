"""The studio's API on what the manuals ask (issue 20): a rule without an IF part (Siemens
1.5) is checked, saved as FCL and opened again as the same rule; the name limits the
dialogs use are the siemens profile's."""

from __future__ import annotations

import shutil
from pathlib import Path

from fastapi.testclient import TestClient

from fuzzyctl.blocks.siemens import LIMITS
from fuzzyctl.studio import create_app
from tests.conftest import EXAMPLES

BASE = "http://127.0.0.1:8770"


def client_for(tmp_path: Path) -> TestClient:
    root = tmp_path / "project"
    root.mkdir()
    shutil.copy(EXAMPLES / "siemens_fpltest.fcl", root / "siemens_fpltest.fcl")
    return TestClient(create_app(root, file="siemens_fpltest.fcl", token=None), base_url=BASE)


def test_siemens_1_5_rule_without_if_part_is_checked_saved_and_opened_again(tmp_path: Path) -> None:
    client = client_for(tmp_path)
    doc = client.post("/api/open", json={"path": "siemens_fpltest.fcl"}).json()["document"]
    bias = {
        "label": "5",
        "condition": None,
        "conclusions": [{"variable": "Valve", "term": "closed", "weight": None, "hedges": []}],
        "weight": None,
    }
    doc["blocks"][0]["rule_blocks"][0]["rules"].append(bias)
    checked = client.post("/api/check", json={"document": doc}).json()
    assert checked["ok"] and "RULE 5 : IF ALWAYS THEN Valve IS closed;" in checked["text"]
    assert not [d for d in checked["diagnostics"] if d["severity"] == "error"]
    # Temp 9, Pressure 65 (manual 1.4, rules of one term added): inlet .75, closed .25 + .25
    # + 1, drainage .25 -> (75 - 25) / 2.5 = 20; the bias rule has degree 1.
    e = client.post("/api/explain", json={"document": doc, "inputs": {"Temp": 9, "Pressure": 65}}).json()
    assert next(r for r in e["rules"] if r["label"] == "5")["degree"] == 1.0
    assert abs(e["outputs"][0]["value"] - 20.0) < 1e-9
    saved = client.post("/api/save", json={"path": "bias.fcl", "document": doc})
    assert saved.status_code == 200, saved.text
    again = client.post("/api/open", json={"path": "bias.fcl"}).json()["document"]
    rules = again["blocks"][0]["rule_blocks"][0]["rules"]
    assert rules[-1]["condition"] is None and rules[-1]["conclusions"][0]["term"] == "closed"
    assert [v["name"] for v in again["blocks"][0]["variables"]] == ["Temp", "Pressure", "Valve"]


def test_the_dialogs_limits_are_the_siemens_profile_s(tmp_path: Path) -> None:
    info = client_for(tmp_path).get("/api/info").json()
    # manual 6.2 (project 8), 6.4 (inputs/outputs 10, terms 7)
    assert info["siemens_limits"] == {"project_name": 8, "variable_name": 10, "term_name": 7}
    assert all(LIMITS[k] == v for k, v in info["siemens_limits"].items())
