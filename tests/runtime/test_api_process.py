"""The API as `fuzzyctl serve` runs it: in a process of its own, behind the front door.
Real clients only: raw sockets for oversized, chunked and unauthenticated bodies, httpx
for Host and Origin, the websockets client for the live stream (foreign origin, no
token, binary frames).  One runtime serves the whole module (starting the API process
takes seconds on a loaded machine)."""

from __future__ import annotations

import json
import os
import signal
import socket
import stat
import time
from collections.abc import Iterator
from pathlib import Path

import httpx
import pytest

from fuzzyctl.diagnostics import FuzzyctlError
from fuzzyctl.runtime.core import Runtime
from fuzzyctl.runtime.token import load_or_create_token
from tests.io.plcs import wait_until
from tests.runtime.helpers import make_runtime
from tests.runtime.test_api import CONFIG

MAX_BODY = 65536
JSON = {
    "Content-Type": "application/json"
}  # the smallest limit the configuration allows: over-limit tests stay quick


@pytest.fixture(scope="module")
def served(tmp_path_factory: pytest.TempPathFactory) -> Iterator[Runtime]:
    tmp = tmp_path_factory.mktemp("api")
    config = f'[runtime]\nstate_dir = "{tmp / "state"}"\n[api]\nport = 0\nmax_body = {MAX_BODY}\n' + CONFIG
    rt = make_runtime(tmp, config, api=True)
    rt.start()
    try:
        yield rt
    finally:
        rt.stop()


def base(rt: Runtime) -> str:
    host, port = rt.api_address  # type: ignore[misc]
    return f"http://{host}:{port}/api/v1"


def auth(token: str | None) -> dict[str, str]:
    return {"Authorization": f"Bearer {token}"}


def rss_kb(pid: int) -> int:
    for line in Path(f"/proc/{pid}/status").read_text().splitlines():
        if line.startswith("VmRSS:"):
            return int(line.split()[1])
    raise AssertionError("no VmRSS")


def raw_put(
    rt: Runtime, path: str, *, token: str | None, length: int | None, send: int, chunk: int = 16384
) -> tuple[str, int, bytes]:
    """PUT with a Content-Length of ``length`` (None: chunked), sending up to ``send``
    bytes of body and stopping as soon as the server answers.  Returns the status line,
    the body bytes sent and the whole answer."""
    host, port = rt.api_address  # type: ignore[misc]
    head = [f"PUT /api/v1{path} HTTP/1.1", f"Host: {host}:{port}", "Content-Type: application/json"]
    head.append(f"Content-Length: {length}" if length is not None else "Transfer-Encoding: chunked")
    if token:
        head.append(f"Authorization: Bearer {token}")
    sent = 0
    with socket.create_connection((host, port), timeout=10) as sock:
        sock.sendall(("\r\n".join(head) + "\r\n\r\n").encode())
        try:
            while sent < send:
                sock.setblocking(False)
                try:
                    if sock.recv(1, socket.MSG_PEEK):
                        break  # the server answered: stop sending
                except BlockingIOError:
                    pass
                finally:
                    sock.setblocking(True)
                data = b"{" * chunk
                sock.sendall(data if length is not None else f"{len(data):x}\r\n".encode() + data + b"\r\n")
                sent += len(data)
        except OSError:
            pass  # the server closed the connection on us: its answer is already here
        answer = b""
        sock.settimeout(10)
        try:
            while part := sock.recv(65536):
                answer += part
        except OSError:
            pass
    return answer.split(b"\r\n", 1)[0].decode(), sent, answer


def test_the_api_runs_in_its_own_process_with_0600_token_files(served: Runtime) -> None:
    proc = served.api_process.proc
    assert proc.pid != os.getpid() and proc.poll() is None
    assert b"fuzzyctl.runtime.apiserver" in Path(f"/proc/{proc.pid}/cmdline").read_bytes()
    assert served.api_address[0] == "127.0.0.1"  # type: ignore[index]
    for path, token in [(served.token_path, served.token), (served.read_token_path, served.read_token)]:
        assert path is not None and stat.S_IMODE(path.stat().st_mode) == 0o600
        assert path.read_text().strip() == token and len(token or "") >= 32
        assert load_or_create_token(path) == token  # the next start reuses it
    assert served.token != served.read_token
    r = httpx.get(f"{base(served)}/instances", headers=auth(served.read_token), timeout=10)
    assert {i["name"] for i in r.json()} == {"valve", "debit"}


def test_a_token_file_others_can_read_is_refused(tmp_path: Path) -> None:
    config = f'[runtime]\nstate_dir = "{tmp_path / "state"}"\n[api]\nport = 0\n' + CONFIG
    (tmp_path / "state").mkdir()
    token_file = tmp_path / "state" / "api-token"
    load_or_create_token(token_file)
    os.chmod(token_file, 0o644)
    rt = make_runtime(tmp_path, config, api=True)
    with pytest.raises(FuzzyctlError, match="accessible to other users"):
        rt.start()
    rt.stop()


def test_bodies_without_the_token_or_over_the_limit_are_refused_unread(served: Runtime) -> None:
    child = served.api_process.proc.pid
    rss_before = rss_kb(child)
    kb = "/instances/valve/knowledge_base"
    huge = 500 * 1024 * 1024
    # 500 MB announced, no token: 401 on the headers alone, the connection closed.
    status, sent, answer = raw_put(served, kb, token=None, length=huge, send=0)
    assert status == "HTTP/1.1 401 Unauthorized" and b"connection: close" in answer.lower()
    # Chunked, no token: refused before the body is read.
    status, sent, _ = raw_put(served, kb, token=None, length=None, send=4 * MAX_BODY)
    assert status == "HTTP/1.1 401 Unauthorized"
    # With the token, announced over the limit: 413 unread.
    status, sent, _ = raw_put(served, kb, token=served.token, length=huge, send=0)
    assert status == "HTTP/1.1 413 Request Entity Too Large"
    # With the token, chunked without end: counted while read, 413 at the limit.  A server
    # that read the body first would take all 64 MB (and grow by as much).
    status, sent, _ = raw_put(served, kb, token=served.token, length=None, send=64 << 20)
    assert status == "HTTP/1.1 413 Request Entity Too Large" and sent < 64 << 20
    # Every other body is limited to 64 KiB.
    status, _, _ = raw_put(served, "/instances/valve/start_stop", token=served.token, length=70000, send=0)
    assert status == "HTTP/1.1 413 Request Entity Too Large"
    assert rss_kb(child) - rss_before < 20_000  # KiB: nothing of the uploads was kept
    # The runtime was not disturbed and the API still answers.
    assert httpx.get(f"{base(served)}/instances/valve", headers=auth(served.token), timeout=10).json()[
        "state"
    ]


def test_errors_name_the_field_and_never_echo_the_body(served: Runtime) -> None:
    marker = "ECHO" * 4000
    url, headers = f"{base(served)}/instances/valve", auth(served.token)
    for method, path, body in [
        ("PUT", "/force/Temp", {"value": marker}),
        ("PUT", "/start_stop", {"running": marker}),
        ("PATCH", "/parameters", {"values": {marker: 1}}),
        ("PUT", "/start_stop", {"running": True, marker: 1}),
    ]:
        r = httpx.request(method, url + path, json=body, headers=headers, timeout=10)
        assert r.status_code == 422 and r.json()["detail"], (method, path)
        assert marker[:200] not in r.text and len(r.text) < 2000, (method, path)
    broken = b'{"running": ' + marker.encode()  # not JSON
    r = httpx.put(url + "/start_stop", content=broken, headers=headers | JSON, timeout=10)
    assert r.status_code == 422 and "ECHOECHO" not in r.text
    r = httpx.get(f"{base(served)}/instances/{marker[:150]}", headers=headers, timeout=10)
    assert r.status_code in (404, 422) and len(r.text) < 1000
    # A refused download names places and quotes at most a short piece of the text.
    r = httpx.put(url + "/knowledge_base", json={"text": marker}, headers=headers, timeout=10)
    assert r.status_code == 422 and r.json()["diagnostics"][0]["line"] == 1 and len(r.text) < 2000


def test_foreign_hosts_and_origins_are_refused(served: Runtime) -> None:
    host, port = served.api_address  # type: ignore[misc]
    url, token = f"{base(served)}/instances/valve", auth(served.token)
    # DNS rebinding: a page of attacker.example whose name now points to 127.0.0.1.
    assert httpx.get(url, headers=token | {"Host": "attacker.example"}, timeout=10).status_code == 403
    assert httpx.get(url, headers=token | {"Host": "attacker.example:80"}, timeout=10).status_code == 403
    evil = token | {"Origin": "http://evil.example"}
    assert httpx.get(url, headers=evil, timeout=10).status_code == 403
    assert httpx.put(url + "/start_stop", json={"running": True}, headers=evil, timeout=10).status_code == 403
    same = token | {"Origin": f"http://{host}:{port}"}  # the API's own page (/api/v1/docs)
    assert httpx.get(url, headers=same, timeout=10).status_code == 200
    assert httpx.get(url, headers=token | {"Host": f"localhost:{port}"}, timeout=10).status_code == 200


def test_the_live_stream_checks_origin_and_token_and_ignores_what_clients_send(served: Runtime) -> None:
    from websockets.exceptions import InvalidStatus
    from websockets.sync.client import connect

    host, port = served.api_address  # type: ignore[misc]
    live = f"ws://{host}:{port}/api/v1/live?rate=20&instances=valve"
    with pytest.raises(InvalidStatus) as refused:
        connect(live, origin="http://evil.example", additional_headers=auth(served.read_token))  # type: ignore[arg-type]
    assert refused.value.response.status_code == 403
    with pytest.raises(InvalidStatus) as refused:
        connect(live)
    assert refused.value.response.status_code == 403
    # DNS rebinding on the WebSocket: a raw handshake with the token but a foreign Host.
    with socket.create_connection((host, port), timeout=10) as sock:
        sock.sendall(
            f"GET /api/v1/live HTTP/1.1\r\nHost: attacker.example\r\nUpgrade: websocket\r\n"
            "Connection: Upgrade\r\nSec-WebSocket-Key: dGhlIHNhbXBsZSBub25jZQ==\r\n"
            f"Sec-WebSocket-Version: 13\r\nAuthorization: Bearer {served.token}\r\n\r\n".encode()
        )
        assert sock.recv(100).startswith(b"HTTP/1.1 403")
    # A browser page cannot set headers: the token in the query does; binary and text
    # frames from the client are ignored and the stream goes on.
    with connect(f"{live}&token={served.read_token}", origin=f"http://{host}:{port}") as ws:  # type: ignore[arg-type]
        first = json.loads(ws.recv(timeout=10))
        ws.send(b"\x00\xff binary")
        ws.send("text")
        second = json.loads(ws.recv(timeout=10))
        third = json.loads(ws.recv(timeout=10))
    assert first["type"] == second["type"] == third["type"] == "snapshot"
    assert third["instances"]["valve"]["cycles"] > first["instances"]["valve"]["cycles"]


def test_the_read_only_token_reads_but_changes_nothing(served: Runtime) -> None:
    url, read = f"{base(served)}/instances/valve", auth(served.read_token)
    assert httpx.get(url + "/knowledge_base", headers=read, timeout=10).json()["format"] == "fcl"
    r = httpx.put(url + "/start_stop", json={"running": False}, headers=read, timeout=10)
    assert r.status_code == 403
    assert served.instances["valve"].adapter.block.START_STOP == 0xFFFF


def test_a_killed_api_process_is_restarted(served: Runtime) -> None:
    old = served.api_process.proc
    os.kill(old.pid, signal.SIGKILL)
    wait_until(lambda: served.api_process.proc is not old and served.api_process.ready, 60, 0.1)
    r = httpx.get(f"{base(served)}/health", timeout=10)
    assert r.json()["status"] == "ok"
    assert any(e.kind == "api" and e.level == "error" for e in served.events.since(0))
    assert served.instances["valve"].task.stats.count > 0 and served.scheduler.alive
    deadline = time.monotonic() + 5
    while old.poll() is None and time.monotonic() < deadline:
        time.sleep(0.05)
    assert old.poll() is not None  # reaped, no zombie left behind
