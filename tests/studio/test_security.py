"""The studio's front door: the 16 MB limit holds for chunked bodies too (counted while
read, on a real uvicorn server and a raw socket), and a studio with a token refuses
everything without it; `fuzzyctl studio` makes one by default, on loopback too (another
user of the machine must not read or write your files through it), prints it in its URL,
and serves without one only with --no-token, with a warning."""

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
from fuzzyctl.studio.app import MAX_BODY, cookie_name
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
    app = create_app(project, token=TOKEN)
    srv = uvicorn.Server(uvicorn.Config(app, log_level="warning", lifespan="off"))
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
            f"Authorization: Bearer {TOKEN}\r\nTransfer-Encoding: chunked\r\n\r\n".encode()
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
    assert f"{cookie_name(TOKEN)}={TOKEN}" in cookie and "HttpOnly" in cookie and "SameSite=strict" in cookie
    browser = TestClient(app, base_url="http://plant-pc:8770", cookies={cookie_name(TOKEN): TOKEN})
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


def _url(proc: subprocess.Popen[str]) -> str:
    assert proc.stdout is not None
    line = proc.stdout.readline()
    url = re.search(r"http://127\.0\.0\.1:\d+/\S*", line)
    assert url, line
    return url.group(0)


def _refused(url: str) -> int:
    with pytest.raises(urllib.error.HTTPError) as refused:
        urllib.request.urlopen(url, timeout=20)
    return refused.value.code


@pytest.mark.parametrize("host", ["127.0.0.1", "0.0.0.0"])
def test_the_studio_command_requires_its_token_on_loopback_too(project: Path, host: str) -> None:
    proc = _studio(["crane.fcl", "--host", host, "--port", "0"], project)
    try:
        url = _url(proc)
        assert "?token=" in url
        plain = url.split("?")[0]
        # Another user of the machine: no token, no file read, no file written.
        assert _refused(plain + "api/info") == 401
        assert _refused(plain) == 401
        opening = urllib.request.Request(
            plain + "api/open", data=b'{"path": "crane.fcl"}', headers={"Content-Type": "application/json"}
        )
        with pytest.raises(urllib.error.HTTPError) as refused:
            urllib.request.urlopen(opening, timeout=20)
        assert refused.value.code == 401
        # The user clicking the printed URL: the redirect sets the cookie, the page works.
        browser = urllib.request.build_opener(urllib.request.HTTPCookieProcessor())
        with browser.open(url, timeout=20) as r:
            assert "fuzzyctl studio" in r.read().decode()
        with browser.open(plain + "api/info", timeout=20) as r:
            assert b"crane.fcl" in r.read()
        # The API description (Swagger UI from a CDN) is off unless --api-docs.
        with pytest.raises(urllib.error.HTTPError) as missing:
            browser.open(plain + "api/docs", timeout=20)
        assert missing.value.code == 404
    finally:
        err = _stop(proc)
    assert ("whoever has the URL" in err) == (host == "0.0.0.0")
    assert "--no-token" not in err


def test_no_token_is_an_explicit_choice_with_a_warning(project: Path) -> None:
    proc = _studio(["crane.fcl", "--port", "0", "--no-token"], project)
    try:
        url = _url(proc)
        assert "token" not in url
        with urllib.request.urlopen(url + "api/info", timeout=20) as r:
            assert b"crane.fcl" in r.read()
    finally:
        err = _stop(proc)
    assert "warning: --no-token: any program or user on this machine can read and write" in err
    proc = _studio(["crane.fcl", "--port", "0", "--no-token", "--token", TOKEN], project)
    err = proc.communicate(timeout=60)[1]
    assert proc.returncode == 2 and "either --token or --no-token" in err


def test_two_studios_on_one_host_keep_their_own_cookie(project: Path) -> None:
    first, second = "first-token-0123456789", "second-token-0123456789"
    assert cookie_name(first) != cookie_name(second)
    app = create_app(project, token=first)
    client = TestClient(app, base_url="http://127.0.0.1:8770")
    client.cookies.set(cookie_name(second), second)  # the other studio's, sent along by the browser
    assert client.get("/api/info").status_code == 401
    client.cookies.set(cookie_name(first), first)
    assert client.get("/api/info").status_code == 200


@pytest.mark.parametrize("api_docs", [False, True])
def test_the_api_docs_are_off_unless_asked_for(project: Path, api_docs: bool) -> None:
    """Swagger UI comes from a CDN (no installed package ships it): third-party code in a
    page holding the token, so /api/docs is served only with --api-docs."""
    app = create_app(project, token=TOKEN, api_docs=api_docs)
    client = TestClient(app, base_url="http://127.0.0.1:8770", headers={"Authorization": f"Bearer {TOKEN}"})
    assert client.get("/api/docs").status_code == (200 if api_docs else 404)
    assert client.get("/api/redoc").status_code == 404
    assert client.get("/api/openapi.json").status_code == 200  # the description itself is ours
    page = client.get("/")
    foreign = re.findall(r"(?:src|href)=[\"'](?:https?:)?//[^\"']+", page.text)
    assert foreign == []  # the studio's own page loads nothing from elsewhere
