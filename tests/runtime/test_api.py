"""The HTTP + WebSocket API: reading, token enforcement, request validation, writes that
reach the block, online download, the live stream, and the 127.0.0.1 binding with a
0600 token file."""

from __future__ import annotations

from collections.abc import Iterator
from pathlib import Path

import numpy as np
import pytest
from fastapi.testclient import TestClient
from starlette.websockets import WebSocketDisconnect

from fuzzyctl.runtime.api import ApiSettings, LocalBackend, create_app
from fuzzyctl.runtime.core import Runtime
from fuzzyctl.runtime.service import Service
from tests.conftest import EXAMPLES
from tests.io.plcs import wait_until
from tests.runtime.helpers import FPLTEST_FCL, make_runtime

TOKEN = "test-token-0123456789abcdef"
READ_TOKEN = "read-token-0123456789abcdef"
CONFIG = f"""
[instances.valve]
knowledge_base = "{FPLTEST_FCL}"
period = 0.01

[instances.debit]
style = "xfuz"
knowledge_base = "{EXAMPLES / "xfuz_3_3.xfuz"}"
span_rule = false
period = 0.01
params = {{ MAN_AUTO = 1, START = 1, CONT_ASK = 0, T_OFB = 0 }}
"""


@pytest.fixture
def runtime(tmp_path: Path) -> Iterator[Runtime]:
    rt = make_runtime(tmp_path, CONFIG)
    rt.token = TOKEN
    rt.start()
    try:
        wait_until(lambda: all(i.task.stats.count > 2 for i in rt.instances.values()))
        yield rt
    finally:
        rt.stop()


AUTH = {"Authorization": f"Bearer {TOKEN}"}
READ = {"Authorization": f"Bearer {READ_TOKEN}"}


@pytest.fixture
def client(runtime: Runtime) -> TestClient:
    settings = ApiSettings(token=TOKEN, read_token=READ_TOKEN, hosts=["testserver"])
    # TestClient's requests carry the read-only token unless a test gives another one.
    return TestClient(create_app(LocalBackend(Service(runtime)), settings), headers=READ)


def test_reading_with_the_read_only_token_shows_live_values(client: TestClient) -> None:
    assert client.get("/api/v1/health").json()["status"] == "ok"
    listing = client.get("/api/v1/instances").json()
    assert {i["name"] for i in listing} == {"valve", "debit"}
    valve = client.get("/api/v1/instances/valve").json()
    # Unbound inputs stay 0.0, clamped to Temp 0, Pressure 50: cold AND low -> inlet (100).
    assert valve["outputs"] == {"Valve": 100.0} and valve["status"] == {"INFO": 0}
    assert valve["state"] == "run" and valve["knowledge_base"]["inputs"] == ["Temp", "Pressure"]
    stats = client.get("/api/v1/instances/valve/statistics").json()
    assert stats["cycles"] > 0 and stats["period"] == 0.01 and "jitter_p99" in stats
    assert client.get("/api/v1/instances/nope").status_code == 404
    assert set(client.get("/api/v1/statistics").json()) == {"valve", "debit"}
    page = client.get("/api/v1/events", params={"after": 0, "limit": 2}).json()
    assert [e["seq"] for e in page["events"]] == [1, 2] and page["last_seq"] >= 2
    spec = client.get("/api/v1/openapi.json").json()
    assert "/api/v1/instances/{name}/knowledge_base" in spec["paths"]


NO_TOKEN = {"Authorization": ""}
WRITES = [
    ("put", "/api/v1/instances/valve/start_stop", {"running": False}),
    ("patch", "/api/v1/instances/valve/parameters", {"values": {"START_STOP": 0}}),
    ("put", "/api/v1/instances/debit/mode", {"mode": "manual"}),
    ("put", "/api/v1/instances/valve/force/Temp", {"value": 3}),
    ("delete", "/api/v1/instances/valve/force/Temp", None),
    ("put", "/api/v1/instances/debit/manual/OUT3", {"value": 3}),
    ("put", "/api/v1/instances/valve/knowledge_base", {"text": "x", "format": "fcl"}),
]
READS = [
    "/api/v1/instances",
    "/api/v1/instances/valve",
    "/api/v1/instances/valve/statistics",
    "/api/v1/statistics",
    "/api/v1/instances/valve/knowledge_base",
    "/api/v1/links",
    "/api/v1/events",
    "/api/v1/nowhere",  # no probing of paths without a token either
]


def test_every_write_needs_the_write_token_and_every_read_a_token(
    client: TestClient, runtime: Runtime
) -> None:
    before = runtime.events.last_seq
    for method, url, payload in WRITES:
        for headers, status in [(NO_TOKEN, 401), ({"Authorization": "Bearer nope"}, 401), (READ, 403)]:
            r = client.request(method.upper(), url, json=payload, headers=headers)
            assert r.status_code == status, (method, url, headers)
            if status == 401:
                assert r.headers["www-authenticate"] == "Bearer"
    # Nothing was changed, nothing logged (cycle overruns of a loaded test machine aside).
    assert [e.kind for e in runtime.events.since(before) if e.kind != "overrun"] == []
    for url in READS:
        assert client.get(url, headers=NO_TOKEN).status_code == 401, url
        assert client.get(url, headers={"Authorization": "Bearer nope"}).status_code == 401, url
    assert client.get("/api/v1/instances/valve", headers=AUTH).status_code == 200  # the write token reads too
    # Liveness and the API description stay open (they tell nothing about the process).
    assert client.get("/api/v1/health", headers=NO_TOKEN).status_code == 200
    assert client.get("/api/v1/openapi.json", headers=NO_TOKEN).status_code == 200


def test_the_docs_page_is_off_unless_the_configuration_asks(client: TestClient, runtime: Runtime) -> None:
    """Swagger UI would come from a CDN into the page where the token is typed (no installed
    package ships its assets): off by default, on only with ``[api] docs = true``."""
    from fuzzyctl.runtime.config import ApiConfig

    assert ApiConfig().docs is False
    for headers in (NO_TOKEN, AUTH):
        assert client.get("/api/v1/docs", headers=headers).status_code == 404
    assert client.get("/api/v1/redoc", headers=AUTH).status_code == 404
    settings = ApiSettings(token=TOKEN, read_token=READ_TOKEN, hosts=["testserver"], docs=True)
    with TestClient(create_app(LocalBackend(Service(runtime)), settings)) as documented:
        page = documented.get("/api/v1/docs")
        assert page.status_code == 200 and "swagger-ui" in page.text


def test_without_a_token_only_when_asked_for(runtime: Runtime) -> None:
    """``serve --no-token`` (ApiSettings(token=None)): every request passes without one;
    the other checks of the front door stay."""
    settings = ApiSettings(token=None, hosts=["testserver"])
    with TestClient(create_app(LocalBackend(Service(runtime)), settings)) as open_api:
        assert open_api.get("/api/v1/instances/valve").status_code == 200
        r = open_api.put("/api/v1/instances/valve/start_stop", json={"running": True})
        assert r.status_code == 200
        assert open_api.get("/api/v1/instances", headers={"Host": "evil.example"}).status_code == 403


def test_requests_are_validated(client: TestClient) -> None:
    url = "/api/v1/instances/valve/parameters"
    assert client.patch(url, json={"values": {}}, headers=AUTH).status_code == 422
    assert client.patch(url, json={"values": {"START_STOP": "x"}}, headers=AUTH).status_code == 422
    assert client.patch(url, json={"vals": {"START_STOP": 0}}, headers=AUTH).status_code == 422
    r = client.patch(url, json={"values": {"START_STOP": 70000}}, headers=AUTH)
    assert r.status_code == 400 and "START_STOP" in r.json()["detail"]
    r = client.patch(url, json={"values": {"MAN_AUTO": 1}}, headers=AUTH)
    assert r.status_code == 400 and "not a parameter" in r.json()["detail"]
    # All or nothing: T_OFB out of range, so MAN_AUTO is not written either.
    r = client.patch(
        "/api/v1/instances/debit/parameters", json={"values": {"MAN_AUTO": 0, "T_OFB": 99999}}, headers=AUTH
    )
    assert r.status_code == 400 and "T_OFB" in r.json()["detail"]
    assert client.get("/api/v1/instances/debit").json()["parameters"]["MAN_AUTO"] == 1
    assert client.put("/api/v1/instances/valve/mode", json={"mode": "auto"}, headers=AUTH).status_code == 409
    r = client.put("/api/v1/instances/debit/mode", json={"mode": "semi"}, headers=AUTH)
    assert r.status_code == 422
    r = client.put("/api/v1/instances/valve/force/Nope", json={"value": 1}, headers=AUTH)
    assert r.status_code == 400 and "Temp, Pressure" in r.json()["detail"]
    body = '{"value": NaN}'
    headers = AUTH | {"content-type": "application/json"}
    r = client.put("/api/v1/instances/valve/force/Temp", content=body, headers=headers)
    assert r.status_code == 422
    assert client.get("/api/v1/events", params={"limit": 0}).status_code == 422


def test_writes_reach_the_block(client: TestClient, runtime: Runtime) -> None:
    valve = runtime.instances["valve"]
    r = client.put("/api/v1/instances/valve/start_stop", json={"running": False}, headers=AUTH)
    assert r.json() == {"START_STOP": 0}
    wait_until(lambda: client.get("/api/v1/instances/valve").json()["status"]["INFO"] == 1)
    client.patch("/api/v1/instances/valve/parameters", json={"values": {"START_STOP": 65535}}, headers=AUTH)
    # Force Temp to 27 (hot) with Pressure 50 (low): hot AND low -> closed (0).
    r = client.put("/api/v1/instances/valve/force/Temp", json={"value": 27}, headers=AUTH)
    assert r.json() == {"INPUT1": 27.0}
    wait_until(lambda: client.get("/api/v1/instances/valve").json()["outputs"]["Valve"] == 0.0)
    assert client.delete("/api/v1/instances/valve/force/Temp", headers=AUTH).json() == {}
    assert valve.adapter.forced() == {}  # released; an unbound input keeps its last value, as in a DB

    # XFUZ: manual mode puts O3_MAN on OUT3; forcing INP4 goes through I4_SIM and COMMAND bit 3.
    client.put("/api/v1/instances/debit/manual/OUT3", json={"value": 7}, headers=AUTH)
    client.put("/api/v1/instances/debit/mode", json={"mode": "manual"}, headers=AUTH)
    wait_until(lambda: client.get("/api/v1/instances/debit").json()["outputs"]["OUT3"] == 7)
    client.put("/api/v1/instances/debit/mode", json={"mode": "auto"}, headers=AUTH)
    r = client.put("/api/v1/instances/debit/force/INP4", json={"value": -50}, headers=AUTH)
    assert r.json() == {"INP4": -50.0}
    wait_until(lambda: client.get("/api/v1/instances/debit").json()["outputs"]["OUT3"] == 8)  # manual 3.3
    assert runtime.instances["debit"].adapter.block.COMMAND == 0b1000
    kinds = [e["kind"] for e in client.get("/api/v1/events").json()["events"]]
    assert kinds.count("parameter") >= 4 and kinds.count("force") == 3


def test_download_through_the_api(client: TestClient, runtime: Runtime) -> None:
    text = FPLTEST_FCL.read_text(encoding="utf-8").replace("TERM inlet := 100;", "TERM inlet := 70;")
    url = "/api/v1/instances/valve/knowledge_base"
    r = client.put(url, json={"text": text, "format": "fcl"}, headers=AUTH)
    assert r.status_code == 200, r.text
    assert r.json()["procedure"].startswith("START_STOP = 0")
    wait_until(lambda: client.get("/api/v1/instances/valve").json()["outputs"]["Valve"] == 70.0)
    broken = text.replace("END_FUZZIFY", "END_FUZIFY", 1)
    r = client.put(url, json={"text": broken}, headers=AUTH)
    assert r.status_code == 422 and r.json()["diagnostics"][0]["line"] is not None
    renamed = text.replace("Temp", "Tmp")  # valid: this instance has no bindings that would miss Temp
    assert client.put(url, json={"text": renamed}, headers=AUTH).status_code == 200
    r = client.put(url, json={"text": text, "format": "docx"}, headers=AUTH)
    assert r.status_code == 422
    kinds = [e["kind"] for e in client.get("/api/v1/events").json()["events"]]
    assert kinds.count("download") == 2 and kinds.count("download-refused") == 2


def test_live_websocket_streams_snapshots_and_events(client: TestClient) -> None:
    with client.websocket_connect("/api/v1/live?rate=20&instances=valve") as ws:
        first = ws.receive_json()
        second = ws.receive_json()
    assert first["type"] == "snapshot" and set(first["instances"]) == {"valve"}
    assert second["instances"]["valve"]["cycles"] >= first["instances"]["valve"]["cycles"]
    assert first["instances"]["valve"]["outputs"] == {"Valve": 100.0}
    with client.websocket_connect("/api/v1/live?instances=ghost") as ws:
        assert ws.receive_json()["type"] == "error"
    # A rate above 20 Hz is refused at the handshake (policy violation).
    with (
        pytest.raises(WebSocketDisconnect) as refused,
        client.websocket_connect("/api/v1/live?rate=50") as ws,
    ):
        ws.receive_json()
    assert refused.value.code == 1008


def test_values_the_block_type_cannot_hold_and_loose_json_types_are_refused(
    client: TestClient, runtime: Runtime
) -> None:
    force = "/api/v1/instances/valve/force/Temp"
    for value in (1e308, -1e308, 3.5e38, -3.41e38):  # beyond a REAL: not clamped, refused
        r = client.put(force, json={"value": value}, headers=AUTH)
        assert r.status_code == 400 and "REAL" in r.json()["detail"], value
    assert runtime.instances["valve"].adapter.forced() == {}
    r = client.put(force, json={"value": 3.4e38}, headers=AUTH)  # the largest REALs are fine
    assert r.status_code == 200 and r.json() == {"INPUT1": float(np.float32(3.4e38))}
    client.delete(force, headers=AUTH)
    for url, value in [
        ("/api/v1/instances/debit/force/INP4", 40000),  # an XFUZ input is a 16-bit word
        ("/api/v1/instances/debit/force/INP4", 2.5),
        ("/api/v1/instances/debit/manual/OUT3", 1e308),
        ("/api/v1/instances/debit/manual/OUT3", -32769),
    ]:
        r = client.put(url, json={"value": value}, headers=AUTH)
        assert r.status_code == 400 and "16-bit" in r.json()["detail"], (url, value)
    assert runtime.instances["debit"].adapter.forced() == {}
    # JSON's own types only, as the docs say: "yes", 1 and "true" are not booleans.
    for running in ("yes", 1, "true", None):
        r = client.put("/api/v1/instances/valve/start_stop", json={"running": running}, headers=AUTH)
        assert r.status_code == 422, running
    for value in ("3", True, [3], {"v": 3}):
        assert client.put(force, json={"value": value}, headers=AUTH).status_code == 422, value
    assert (
        client.patch(
            "/api/v1/instances/valve/parameters", json={"values": {"START_STOP": "65535"}}, headers=AUTH
        ).status_code
        == 422
    )
    assert runtime.instances["valve"].adapter.block.START_STOP == 0xFFFF
