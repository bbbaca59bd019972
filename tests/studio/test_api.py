"""The studio's HTTP API with FastAPI's TestClient: files stay inside the project
directory, requests are validated, saves are atomic, diagnostics are `fuzzyctl check`'s,
evaluations are the engine's, test signals follow the manual's definition, the simulated
process is fuzzyctl.sim's loop, and the on-line proxy reaches a real runtime."""

from __future__ import annotations

import base64
import errno
import json
import math
import os
import shutil
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import numpy as np
import pytest
from fastapi.testclient import TestClient

import fuzzyctl
from fuzzyctl.cli.app import main
from fuzzyctl.studio import create_app
from fuzzyctl.studio.analysis import test_signal as signal_at
from tests.conftest import EXAMPLES

BASE = "http://127.0.0.1:8770"
TOKEN = "studio-test-token-0123456789"


@pytest.fixture
def project(tmp_path: Path) -> Path:
    root = tmp_path / "project"
    root.mkdir()
    for name in ("crane.fcl", "crane.toml", "figure7.fcl", "xfuz_3_3.xfuz"):
        shutil.copy(EXAMPLES / name, root / name)
    (tmp_path / "secret.fcl").write_text("FUNCTION_BLOCK secret END_FUNCTION_BLOCK\n")
    return root


@pytest.fixture
def client(project: Path) -> TestClient:
    return TestClient(
        create_app(project, file="crane.fcl", token=TOKEN),
        base_url=BASE,
        headers={"Authorization": f"Bearer {TOKEN}"},
    )


def opened(client: TestClient, path: str) -> dict[str, Any]:
    r = client.post("/api/open", json={"path": path})
    assert r.status_code == 200, r.text
    data: dict[str, Any] = r.json()
    return data


# ---------------------------------------------------------------------------- files


@pytest.mark.parametrize(
    "path",
    [
        "../secret.fcl",
        "/etc/passwd",
        "sub/../../secret.fcl",
        "..",
        "link/secret.fcl",
        "outside.fcl",
        "a\x00b.fcl",
    ],
)
def test_no_path_leaves_the_project_directory(client: TestClient, project: Path, path: str) -> None:
    (project / "link").symlink_to(project.parent, target_is_directory=True)
    (project / "outside.fcl").symlink_to(project.parent / "secret.fcl")
    r = client.post("/api/open", json={"path": path})
    assert r.status_code in (403, 422), r.text
    crane = opened(client, "crane.fcl")["document"]
    target = path if path.endswith(".fcl") else path + "/x.fcl"
    r = client.post("/api/save", json={"path": target, "document": crane})
    assert r.status_code in (403, 422), r.text
    assert (project.parent / "secret.fcl").read_text() == "FUNCTION_BLOCK secret END_FUNCTION_BLOCK\n"
    listed = [f["path"] for f in client.get("/api/files").json()["files"]]
    assert "outside.fcl" not in listed and not any("secret" in p for p in listed)


def test_other_hosts_and_origins_and_non_json_are_refused(client: TestClient) -> None:
    assert client.get("/api/info", headers={"host": "evil.example:8770"}).status_code == 403
    r = client.post("/api/open", json={"path": "crane.fcl"}, headers={"origin": "http://evil.example"})
    assert r.status_code == 403
    r = client.post("/api/open", content=b'{"path": "crane.fcl"}', headers={"content-type": "text/plain"})
    assert r.status_code == 415
    assert client.post("/api/open", json={"path": "crane.fcl"}, headers={"origin": BASE}).status_code == 200


def test_requests_are_validated(client: TestClient) -> None:
    doc = opened(client, "crane.fcl")["document"]
    bad = [
        ("/api/open", {"path": "crane.fcl", "extra": 1}),
        ("/api/explain", {"document": doc, "inputs": {"distance": "NaN", "angle": 0}}),
        ("/api/record", {"document": doc, "times": [0], "length": 5}),
        (
            "/api/record",
            {"document": doc, "times": [0], "signals": {"angle": {"kind": "triangle", "duty": 101}}},
        ),
        ("/api/surface", {"document": doc, "x": "distance", "y": "angle", "z": "power", "points": 500}),
        ("/api/sim/step", {"id": "../../etc", "seconds": 1}),
        ("/api/save", {"path": "x.fcl", "document": doc, "settings": {"unknown": 1}}),
    ]
    for path, body in bad:
        text = json.dumps(body).replace('"NaN"', "NaN")
        r = client.post(path, content=text, headers={"content-type": "application/json"})
        assert r.status_code == 422, (path, r.text)
    r = client.post(
        "/api/check", json={"document": {"format": "fuzzyctl-model", "version": 1, "blocks": [{"nam": 1}]}}
    )
    assert r.status_code == 422 and "nam" in r.json()["detail"]


def test_save_is_atomic_keeps_settings_beside_the_file_and_detects_changes(
    client: TestClient, project: Path
) -> None:
    first = opened(client, "crane.fcl")
    settings = {
        "ranges": {"distance": [-5.0, 25.0]},
        "recorder": {"curves": ["distance", "power"], "length": 30.0},
    }
    r = client.post(
        "/api/save", json={"path": "copy.fcl", "document": first["document"], "settings": settings}
    )
    assert r.status_code == 200, r.text
    saved = (project / "copy.fcl").read_text()
    assert "OPTIONS" not in saved and "STUDIO" not in saved  # the view settings: test_viewsettings.py
    assert not [p for p in project.iterdir() if p.name.startswith(".copy.fcl")]  # no temporary file left
    again = opened(client, "copy.fcl")
    assert again["settings"]["ranges"] == {"distance": [-5.0, 25.0]}
    assert again["settings"]["recorder"]["curves"] == ["distance", "power"]
    # the model read back is the crane (the studio block is not part of it)
    assert (
        fuzzyctl.load(project / "copy.fcl").main.rule_blocks
        == fuzzyctl.load(EXAMPLES / "crane.fcl").main.rule_blocks
    )
    assert again["document"] == first["document"] | {"blocks": again["document"]["blocks"]}
    assert again["document"]["blocks"][0]["options"] == []
    # a save over a file that changed on disk since it was opened is refused ...
    (project / "copy.fcl").write_text(saved + "\n(* edited elsewhere *)\n")
    body = {"path": "copy.fcl", "document": again["document"], "expected_sha256": again["sha256"]}
    assert client.post("/api/save", json=body).status_code == 409
    # ... and so is Save As onto an existing file, unless confirmed
    assert (
        client.post("/api/save", json={"path": "figure7.fcl", "document": first["document"]}).status_code
        == 409
    )
    assert client.post("/api/save", json={**body, "overwrite": True}).status_code == 200
    assert client.post("/api/save", json={"path": "x.txt", "document": first["document"]}).status_code == 403


def test_save_survives_a_failed_write(
    client: TestClient, project: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    before = (project / "crane.fcl").read_text()
    doc = opened(client, "crane.fcl")

    def boom(*_args: Any) -> None:
        raise OSError(errno.ENOSPC, "No space left on device")

    monkeypatch.setattr(os, "replace", boom)
    r = client.post(
        "/api/save",
        json={"path": "crane.fcl", "document": doc["document"], "expected_sha256": doc["sha256"]},
    )
    assert r.status_code == 507
    assert r.json()["detail"] == "cannot save 'crane.fcl': the disk is full; the file on disk is unchanged"
    assert (project / "crane.fcl").read_text() == before
    assert sorted(p.name for p in project.iterdir()) == sorted(
        ["crane.fcl", "crane.toml", "figure7.fcl", "xfuz_3_3.xfuz"]
    )


# ---------------------------------------------------------------------------- checking


def check_json(path: Path, capsys: pytest.CaptureFixture[str]) -> dict[str, Any]:
    main(["check", "--json", str(path)])
    out = capsys.readouterr().out
    data: dict[str, Any] = json.loads(out)
    return data


BROKEN = """FUNCTION_BLOCK b
VAR_INPUT x : REAL; END_VAR
VAR_OUTPUT y : REAL; END_VAR
FUZZIFY x TERM lo := (0, 1) (1, 0); TERM lo := (0, 0) (1, 1); END_FUZZIFY
DEFUZZIFY y TERM a := 0; TERM b := 1; METHOD : CoA; END_DEFUZZIFY
RULEBLOCK r AND : MIN; ACCU : MAX;
RULE 1 : IF x IS lo THEN y IS a;
RULE 2 : IF x IS hi THEN y IS b;
END_RULEBLOCK
END_FUNCTION_BLOCK
"""

ENGINE_WARNS = """FUNCTION_BLOCK w
VAR_INPUT x : REAL; END_VAR
VAR_OUTPUT y : REAL; z : REAL; END_VAR
FUZZIFY x TERM lo := (0, 1) (1, 0); TERM lo := (0, 0) (1, 1); END_FUZZIFY
DEFUZZIFY y TERM a := 0; TERM b := 1; METHOD : CoGS; END_DEFUZZIFY
DEFUZZIFY z TERM a := 0; METHOD : CoGS; END_DEFUZZIFY
RULEBLOCK r AND : MIN;
RULE 1 : IF x IS lo THEN y IS a;
END_RULEBLOCK
END_FUNCTION_BLOCK
"""


@pytest.mark.parametrize("name", ["crane.fcl", "figure7.fcl", "broken.fcl", "warns.fcl"])
def test_diagnostics_are_those_of_fuzzyctl_check(
    client: TestClient, project: Path, capsys: pytest.CaptureFixture[str], name: str
) -> None:
    (project / "broken.fcl").write_text(BROKEN)
    (project / "warns.fcl").write_text(ENGINE_WARNS)
    expected = check_json(project / name, capsys)
    got = client.post("/api/parse", json={"text": (project / name).read_text()}).json()
    key = lambda d: (d["line"], d["column"], d["severity"], d["code"], d["message"])  # noqa: E731
    assert sorted(map(key, got["diagnostics"])) == sorted(map(key, expected["diagnostics"]))
    assert got["ok"] == expected["ok"]
    assert got["level"] == expected.get("level")
    if name == "warns.fcl":
        # every diagnostic of the engine's is tied to the element it concerns
        elements = sorted((d["code"], d["element"]) for d in got["diagnostics"])
        assert elements == [
            ("duplicate-term", "term:x:lo"),
            ("missing-accu", "ruleblock:0"),
            ("missing-default", "var:y"),
            ("missing-default", "var:z"),
            ("output-unused", "var:z"),  # no rule concludes z: it is its DEFAULT
        ]


def test_diagnostics_name_their_rule(client: TestClient) -> None:
    doc = opened(client, "crane.fcl")["document"]
    doc["blocks"][0]["rule_blocks"][0]["rules"][6]["conclusions"][0]["term"] = "nowhere"
    report = client.post("/api/check", json={"document": doc}).json()
    errors = [d for d in report["diagnostics"] if d["severity"] == "error"]
    assert errors and all(d["element"] == "rule:0:6" for d in errors)
    assert "RULE 7 : IF distance IS medium AND angle IS neg_small THEN power IS nowhere" in report["text"]


# ---------------------------------------------------------------------------- analysis


def test_surface_is_the_engine_over_the_grid(client: TestClient) -> None:
    doc = opened(client, "figure7.fcl")["document"]
    r = client.post(
        "/api/surface", json={"document": doc, "x": "temp", "y": "pressure", "z": "valve", "points": 7}
    )
    data = r.json()
    ctl = fuzzyctl.compile(fuzzyctl.load(EXAMPLES / "figure7.fcl"))
    # the ranges come from the terms: temp 3..27, pressure 55..95
    assert data["x"][0] == 3 and data["x"][-1] == 27 and data["y"][0] == 55 and data["y"][-1] == 95
    z = data["frames"][0]["z"]
    for j, p in enumerate(data["y"]):
        for i, t in enumerate(data["x"]):
            assert z[j][i] == pytest.approx(ctl.evaluate({"temp": t, "pressure": p})["valve"], abs=1e-9)


GAP = """FUNCTION_BLOCK gap
VAR_INPUT x : REAL; w : REAL; END_VAR
VAR_OUTPUT y : REAL; END_VAR
FUZZIFY x TERM lo := (0, 1) (4, 0); TERM hi := (6, 0) (10, 1); END_FUZZIFY
FUZZIFY w TERM any := (0, 1) (10, 1); END_FUZZIFY
DEFUZZIFY y TERM a := 5; TERM b := 10; METHOD : CoGS; DEFAULT := NC; END_DEFUZZIFY
RULEBLOCK r AND : MIN; ACCU : MAX;
RULE 1 : IF x IS lo AND w IS any THEN y IS a;
RULE 2 : IF x IS hi AND w IS any THEN y IS b;
END_RULEBLOCK
END_FUNCTION_BLOCK
"""


def test_surface_points_are_fresh_evaluations_where_no_rule_fires(client: TestClient, project: Path) -> None:
    # DEFAULT := NC and a gap between 4 and 6 where no rule fires: each grid point shows
    # what one evaluation after a reset gives (0), not the previous grid point's value
    (project / "gap.fcl").write_text(GAP)
    doc = opened(client, "gap.fcl")["document"]
    data = client.post(
        "/api/surface", json={"document": doc, "x": "x", "y": "w", "z": "y", "points": 11}
    ).json()
    z = data["frames"][0]["z"]
    ctl = fuzzyctl.compile(fuzzyctl.load(GAP))
    for j, w in enumerate(data["y"]):
        for i, x in enumerate(data["x"]):
            ctl.reset()
            assert z[j][i] == pytest.approx(ctl.evaluate({"x": x, "w": w})["y"], abs=1e-9)
    assert z[3][5] == 0 and z[3][3] == 5 and z[3][7] == 10


def test_4d_frames_step_the_third_input(client: TestClient, project: Path) -> None:
    (project / "three.fcl").write_text(
        """FUNCTION_BLOCK three
VAR_INPUT a : REAL; b : REAL; c : REAL; END_VAR
VAR_OUTPUT y : REAL; END_VAR
FUZZIFY a TERM lo := (0, 1) (10, 0); TERM hi := (0, 0) (10, 1); END_FUZZIFY
FUZZIFY b TERM lo := (0, 1) (10, 0); TERM hi := (0, 0) (10, 1); END_FUZZIFY
FUZZIFY c TERM lo := (0, 1) (10, 0); TERM hi := (0, 0) (10, 1); END_FUZZIFY
DEFUZZIFY y TERM n := 0; TERM p := 100; METHOD : CoGS; DEFAULT := 0; END_DEFUZZIFY
RULEBLOCK r AND : MIN; ACCU : MAX;
RULE 1 : IF a IS hi AND c IS hi THEN y IS p;
RULE 2 : IF b IS lo THEN y IS n;
END_RULEBLOCK
END_FUNCTION_BLOCK
"""
    )
    doc = opened(client, "three.fcl")["document"]
    body = {"document": doc, "x": "a", "y": "b", "z": "y", "points": 5, "animate": "c", "step_percent": 25}
    data = client.post("/api/surface", json=body).json()
    assert [f["value"] for f in data["frames"]] == [0, 2.5, 5, 7.5, 10]
    ctl = fuzzyctl.compile(fuzzyctl.load(project / "three.fcl"))
    for frame in data["frames"]:
        assert frame["z"][2][4] == pytest.approx(ctl.evaluate({"a": 10, "b": 5, "c": frame["value"]})["y"])


def test_explain_matches_the_engine(client: TestClient) -> None:
    doc = opened(client, "figure7.fcl")["document"]
    e = client.post("/api/explain", json={"document": doc, "inputs": {"temp": 6, "pressure": 85}}).json()
    # docs/engine.md: temp 6 is cold 0.875, hot 0.125; rule 2 has degree 0.75
    degrees = {(t["variable"], t["term"]): t["degree"] for t in e["terms"]}
    assert degrees[("temp", "cold")] == pytest.approx(0.875) and degrees[
        ("pressure", "high")
    ] == pytest.approx(0.75)
    assert next(r for r in e["rules"] if r["label"] == "2")["degree"] == pytest.approx(0.75)
    assert e["outputs"][0]["singletons"] == [[-100.0, 0.125], [0.0, pytest.approx(0.6)], [100.0, 0.25]]


def triangle_closed_form(t: float, lo: float, hi: float, period: float, duty: float, shift: float) -> float:
    """Written from the manual's words: a rise over duty of the period from lo to hi, a
    fall over the rest, starting at lo at the phase shift."""
    tau = ((t - shift) % period) / period
    if duty == 0:
        return hi - (hi - lo) * tau
    if duty == 1:
        return lo + (hi - lo) * tau
    return lo + (hi - lo) * tau / duty if tau < duty else hi - (hi - lo) * (tau - duty) / (1 - duty)


@pytest.mark.parametrize("duty", [0.0, 25.0, 50.0, 100.0])
def test_triangle_test_signal(duty: float) -> None:
    spec = {"kind": "triangle", "min": -10.0, "max": 30.0, "periods": 3, "duty": duty, "phase": 20.0}
    t = np.linspace(0, 60, 601)
    got = signal_at(spec, t, 60.0, -100, 100)
    expected = [triangle_closed_form(x, -10, 30, 20, duty / 100, 12) for x in t]
    assert got == pytest.approx(expected, abs=1e-9)
    # values at known points: a period starts at the phase shift (12 s) at the minimum
    assert got[120] == pytest.approx(30.0 if duty == 0 else -10.0)
    if duty == 50.0:
        assert got[220] == pytest.approx(30.0)  # half a period later: the top
    assert signal_at({"kind": "maximum"}, t, 60, -4, 20)[5] == 20
    assert signal_at({"kind": "minimum"}, t, 60, -4, 20)[5] == -4
    assert signal_at({"kind": "zero"}, t, 60, -4, 20)[5] == 0


def test_recorder_evaluates_successive_cycles(client: TestClient) -> None:
    doc = opened(client, "crane.fcl")["document"]
    signals = {
        "distance": {"kind": "triangle", "min": -4, "max": 20, "periods": 2},
        "angle": {"kind": "constant", "value": 3},
    }
    times = [i * 0.4 for i in range(150)]
    data = client.post(
        "/api/record", json={"document": doc, "signals": signals, "times": times, "length": 60, "reset": True}
    ).json()
    ctl = fuzzyctl.compile(fuzzyctl.load(EXAMPLES / "crane.fcl"))
    for i in (0, 17, 40, 75, 149):
        d = triangle_closed_form(times[i], -4, 20, 30, 0.5, 0)
        assert data["values"]["distance"][i] == pytest.approx(d)
        assert data["values"]["angle"][i] == 3
        assert data["values"]["power"][i] == pytest.approx(ctl.evaluate({"distance": d, "angle": 3})["power"])


# ---------------------------------------------------------------------------- formats


def test_import_and_export_every_format(client: TestClient) -> None:
    raw = (EXAMPLES / "xfuz_3_3.xfuz").read_bytes()
    r = client.post(
        "/api/import", json={"filename": "xfuz_3_3.xfuz", "data_base64": base64.b64encode(raw).decode()}
    )
    assert r.status_code == 200, r.text
    imported = r.json()
    assert imported["format"] == "xfuz" and imported["document"]["blocks"][0]["name"] == "xfuz_3_3"
    doc = opened(client, "crane.fcl")["document"]
    formats = {f["name"] for f in client.get("/api/info").json()["formats"] if f["write"]}
    assert {"fcl", "fis", "fll", "json"} <= formats
    for fmt in sorted(formats):
        out = client.post("/api/export", json={"document": doc, "format": fmt, "lossy": True}).json()
        assert out["text"], fmt
        if fmt in ("fcl", "fll", "json", "fpl"):  # fis writes the shoulders as -inf (formats issue)
            back = fuzzyctl.load(out["text"], format=fmt)
            ctl = fuzzyctl.compile(back)
            assert ctl.evaluate({"distance": 7, "angle": -3})["power"] == pytest.approx(
                fuzzyctl.compile(fuzzyctl.load(EXAMPLES / "crane.fcl")).evaluate(
                    {"distance": 7, "angle": -3}
                )["power"]
            )


def test_a_lossy_export_lists_the_losses_first(client: TestClient) -> None:
    doc = opened(client, "figure7.fcl")["document"]
    rule = doc["blocks"][0]["rule_blocks"][0]["rules"][0]
    rule["condition"] = {
        "type": "or",
        "operands": [rule["condition"], {"type": "is", "variable": "temp", "term": "hot"}],
    }
    first = client.post("/api/export", json={"document": doc, "format": "fis"}).json()
    assert first["text"] is None and first["losses"]
    assert any("rule '1'" in loss for loss in first["losses"])  # FIS has no nested AND/OR
    second = client.post("/api/export", json={"document": doc, "format": "fis", "lossy": True}).json()
    assert second["text"].startswith("[System]") and second["losses"] == first["losses"]


# ---------------------------------------------------------------------------- simulation


def test_simulated_process_is_the_sim_loop_with_the_edited_controller(
    client: TestClient, project: Path
) -> None:
    configs = client.get("/api/sim/configs", params={"current": "crane.fcl"}).json()["configs"]
    crane = next(c for c in configs if c["path"] == "crane.toml")
    assert crane["matches"] and crane["plant"] == "crane"
    doc = opened(client, "crane.fcl")["document"]
    # the edited controller, not the file's: rule 3 says pos_high instead of pos_medium
    doc["blocks"][0]["rule_blocks"][0]["rules"][2]["conclusions"][0]["term"] = "pos_high"
    info = client.post(
        "/api/sim/start",
        json={
            "document": doc,
            "config": "crane.toml",
            "parameters": {"load_mass": 20000},
            "setpoints": {"target": 15},
        },
    ).json()
    rows = client.post("/api/sim/step", json={"id": info["id"], "seconds": 5.0}).json()["rows"]
    from fuzzyctl import sim
    from fuzzyctl.sim.config import build_loop, load_config

    config = load_config(project / "crane.toml")
    edited = (
        (project / "crane.fcl")
        .read_text()
        .replace(
            "RULE 3 : IF distance IS far AND angle IS zero THEN power IS pos_medium",
            "RULE 3 : IF distance IS far AND angle IS zero THEN power IS pos_high",
        )
    )
    model = fuzzyctl.load(edited)
    from dataclasses import replace

    config = replace(
        config, plant_parameters={**config.plant_parameters, "load_mass": 20000}, setpoints={"target": 15}
    )
    reference = build_loop(config, model=model).run(5.0)
    assert isinstance(reference, sim.Trace)
    n = len(rows["t"])
    assert n == 100
    assert rows["position"] == pytest.approx(list(reference["position"][:n]), abs=1e-12)
    assert rows["fb.power"] == pytest.approx(list(reference["fb.power"][:n]), abs=1e-12)
    assert rows["target"][0] == 15
    assert client.delete(f"/api/sim/{info['id']}", headers={"content-type": "application/json"}).json() == {
        "stopped": True
    }
    assert client.post("/api/sim/step", json={"id": info["id"], "seconds": 1}).status_code == 404


# ---------------------------------------------------------------------------- on line

SERVE = """
[runtime]
state_dir = "{state}"
event_log = ""
[api]
port = 0
[instances.valve]
knowledge_base = "{kb}"
period = 0.02
"""


@pytest.fixture
def runtime(tmp_path: Path) -> Iterator[Any]:
    from fuzzyctl.runtime import Runtime, parse_config

    cfg = tmp_path / "serve.toml"
    text = SERVE.format(state=tmp_path / "state", kb=EXAMPLES / "siemens_fpltest.fcl")
    cfg.write_text(text)
    rt = Runtime(parse_config(text, cfg), api=True)
    rt.start()
    try:
        yield rt
    finally:
        rt.stop()


def test_online_proxy_reads_commands_and_downloads(client: TestClient, runtime: Any, project: Path) -> None:
    host, port = runtime.api_address
    url = f"http://{host}:{port}"
    # The runtime wants a token for reading too: the read-only one is enough to watch.
    refused = client.post("/api/online/instances", json={"url": url})
    assert refused.status_code == 502 and refused.json()["status"] == 401
    listing = client.post("/api/online/instances", json={"url": url, "token": runtime.read_token}).json()
    assert [i["name"] for i in listing["instances"]] == ["valve"]
    creds = {"url": url, "instance": "valve", "token": runtime.token}
    r = client.post("/api/online/command", json={**creds, "action": "force", "target": "Temp", "value": 20})
    assert r.status_code == 200 and list(r.json().values()) == [20.0]  # keyed by the block's INPUTn
    assert list(client.post("/api/online/read", json=creds).json()["forced"].values()) == [20.0]
    wrong = client.post("/api/online/command", json={**creds, "token": "nope", "action": "stop"})
    assert wrong.status_code == 502 and wrong.json()["status"] == 401
    # the diff shows the running knowledge base next to the edited one
    (project / "fpl.fcl").write_text((EXAMPLES / "siemens_fpltest.fcl").read_text())
    doc = opened(client, "fpl.fcl")["document"]
    doc["blocks"][0]["defuzzify"][0]["terms"][2]["mf"]["value"] = 80.0
    diff = client.post("/api/online/diff", json={**creds, "document": doc}).json()
    assert diff["running"]["fcl"] == (EXAMPLES / "siemens_fpltest.fcl").read_text()
    assert "TERM inlet := 80;" in diff["edited"] and "TERM inlet := 100;" in diff["running"]["fcl"]
    r = client.post("/api/online/download", json={**creds, "document": doc})
    assert r.status_code == 200, r.text
    assert runtime.instances["valve"].knowledge_base_source().text == diff["edited"]
    # what runs now is the edited base: inlet at 80
    assert (
        fuzzyctl.load(runtime.instances["valve"].knowledge_base_source().text)
        .main.defuzzify[0]
        .terms[2]
        .mf.value
        == 80
    )
    detail = client.post("/api/online/read", json=creds).json()
    assert detail["downloads"] == 1
    unreachable = client.post("/api/online/instances", json={"url": "http://127.0.0.1:9"})
    assert unreachable.status_code == 502
    assert client.post("/api/online/instances", json={"url": "file:///etc/passwd"}).status_code == 422
    assert math.isfinite(detail["period"])
