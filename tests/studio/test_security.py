"""The studio's front door: the 16 MB limit holds for chunked bodies too (counted while
read, on a real uvicorn server and a raw socket), and a studio with a token refuses
everything without it; `fuzzyctl studio` makes one when it listens beyond loopback and
warns when it has none."""

from __future__ import annotations

import re
import shutil
import socket
import subprocess
import sys
import threading
import time
import urllib.error
import urllib.request
from collections.abc import Iterator
from pathlib import Path

import pytest
from fastapi.testclient import TestClient

from fuzzyctl.studio import create_app
from fuzzyctl.studio.app import COOKIE, MAX_BODY
from tests.conftest import EXAMPLES

TOKEN = "studio-token-0123456789"


@pytest.fixture(scope="module")
def project(tmp_path_factory: pytest.TempPathFactory) -> Path:
    root = tmp_path_factory.mktemp("studio-security")
    shutil.copy(EXAMPLES / "crane.fcl", root / "crane.fcl")
    return root


@pytest.fixture(scope="module")
def server(project: Path) -> Iterator[tuple[str, int]]:
    import uvicorn

    sock = socket.socket()
    sock.bind(("127.0.0.1", 0))
    port = sock.getsockname()[1]
    srv = uvicorn.Server(uvicorn.Config(create_app(project), log_level="warning", lifespan="off"))
    thread = threading.Thread(target=srv.run, kwargs={"sockets": [sock]}, daemon=True)
    thread.start()
    deadline = time.monotonic() + 20
    while not srv.started and time.monotonic() < deadline:
        time.sleep(0.05)
    yield "127.0.0.1", port
    srv.should_exit = True
    thread.join(5)


def rss_kb() -> int:
    for line in Path("/proc/self/status").read_text().splitlines():
        if line.startswith("VmRSS:"):
            return int(line.split()[1])
    raise AssertionError("no VmRSS")


def test_a_chunked_body_over_16_mb_is_refused_while_it_is_read(server: tuple[str, int]) -> None:
    host, port = server
    before = rss_kb()
    chunk = b"x" * (1 << 20)
    sent = 0
    with socket.create_connection((host, port), timeout=20) as sock:
        sock.sendall(
            f"POST /api/open HTTP/1.1\r\nHost: {host}:{port}\r\nContent-Type: application/json\r\n"
            "Transfer-Encoding: chunked\r\n\r\n".encode()
        )
        try:
            while sent < 200 * len(chunk):  # the 200 MB that used to be accepted
                sock.sendall(f"{len(chunk):x}\r\n".encode() + chunk + b"\r\n")
                sent += len(chunk)
        except OSError:
            pass  # closed by the server after its answer
        sock.settimeout(20)
        answer = b""
        try:
            while part := sock.recv(65536):
                answer += part
        except OSError:
            pass
    assert answer.startswith(b"HTTP/1.1 413"), answer[:100]
    assert sent < 200 * len(chunk)  # refused mid-way, not after taking it all
    assert rss_kb() - before < 6 * MAX_BODY // 1024  # KiB: at most the limit was ever held


def test_a_studio_with_a_token_refuses_everything_without_it(project: Path) -> None:
    app = create_app(project, host="0.0.0.0", token=TOKEN)
    anonymous = TestClient(app, base_url="http://plant-pc:8770")
    for path in ("/", "/api/info", "/api/files", "/static/studio.css", "/vendor/plotly.min.js"):
        assert anonymous.get(path).status_code == 401, path
    assert anonymous.post("/api/open", json={"path": "crane.fcl"}).status_code == 401
    assert anonymous.get("/?token=wrong-token-0123456789").status_code == 401
    # The printed URL: the token moves into an HttpOnly, SameSite=Strict cookie and out of
    # the address bar (other query parameters are kept).
    r = anonymous.get(f"/?view=recorder&token={TOKEN}", follow_redirects=False)
    assert r.status_code == 303 and r.headers["location"] == "/?view=recorder"
    cookie = r.headers["set-cookie"]
    assert f"{COOKIE}={TOKEN}" in cookie and "HttpOnly" in cookie and "SameSite=strict" in cookie
    browser = TestClient(app, base_url="http://plant-pc:8770", cookies={COOKIE: TOKEN})
    assert browser.get("/api/info").json()["file"] is None
    assert browser.post("/api/open", json={"path": "crane.fcl"}).status_code == 200
    script = TestClient(app, base_url="http://plant-pc:8770", headers={"Authorization": f"Bearer {TOKEN}"})
    assert script.get("/api/files").status_code == 200


def _studio(args: list[str], cwd: Path) -> subprocess.Popen[str]:
    exe = Path(sys.executable).parent / "fuzzyctl"
    return subprocess.Popen(
        [str(exe), "studio", *args], cwd=cwd, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True
    )


def _stop(proc: subprocess.Popen[str]) -> str:
    proc.terminate()
    return proc.communicate(timeout=20)[1]


def test_the_studio_command_makes_a_token_beyond_loopback_and_warns_without_one(project: Path) -> None:
    proc = _studio(["crane.fcl", "--host", "0.0.0.0", "--port", "0"], project)
    try:
        assert proc.stdout is not None
        line = proc.stdout.readline()
        url = re.search(r"http://127\.0\.0\.1:\d+/\?token=\S+", line)
        assert url, line
        plain = url.group(0).split("?")[0]
        with pytest.raises(urllib.error.HTTPError) as refused:
            urllib.request.urlopen(plain + "api/info", timeout=20)
        assert refused.value.code == 401
        browser = urllib.request.build_opener(urllib.request.HTTPCookieProcessor())
        with browser.open(url.group(0), timeout=20) as r:  # the redirect sets the cookie
            assert "fuzzyctl studio" in r.read().decode()
        with browser.open(plain + "api/info", timeout=20) as r:
            assert b"crane.fcl" in r.read()
    finally:
        err = _stop(proc)
    assert "whoever has the URL" in err
    proc = _studio(["crane.fcl", "--port", "0"], project)
    try:
        assert proc.stdout is not None
        line = proc.stdout.readline()
    finally:
        err = _stop(proc)
    assert "http://127.0.0.1:" in line and "?token=" not in line and "has no token" in err
