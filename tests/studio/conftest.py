"""Browser fixtures shared by the studio's Playwright tests: one studio server, one
chromium (Debian's, no browser download) and one browser context for the whole session,
a fresh page per test that fails the test on any console error and leaves a screenshot
in test-artifacts/."""

from __future__ import annotations

import shutil
import socket
import threading
import time
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import pytest

from fuzzyctl.studio import create_app
from tests.conftest import EXAMPLES
from tests.studio.browser import ARGS, ARTIFACTS, CHROMIUM


@pytest.fixture(scope="session")
def browser_project(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """The studio's project directory: a copy of some examples."""
    root = tmp_path_factory.mktemp("studio-project")
    for name in ("crane.fcl", "crane.toml", "siemens_fpltest.fcl"):
        shutil.copy(EXAMPLES / name, root / name)
    return root


STUDIO_TOKEN = "browser-test-token-0123456789"


@pytest.fixture(scope="session")
def studio(browser_project: Path) -> Iterator[str]:
    """The URL `fuzzyctl studio` would print: with its token, as users open it."""
    import uvicorn

    app = create_app(browser_project, token=STUDIO_TOKEN)
    sock = socket.socket()
    sock.bind(("127.0.0.1", 0))
    port = sock.getsockname()[1]
    server = uvicorn.Server(uvicorn.Config(app, log_level="warning", lifespan="off"))
    thread = threading.Thread(target=server.run, kwargs={"sockets": [sock]}, daemon=True)
    thread.start()
    deadline = time.monotonic() + 10
    while not server.started and time.monotonic() < deadline:
        time.sleep(0.05)
    yield f"http://127.0.0.1:{port}/?token={STUDIO_TOKEN}"
    server.should_exit = True
    thread.join(5)


@pytest.fixture(scope="session")
def browser() -> Iterator[Any]:
    import playwright.sync_api as sync_api  # a dev dependency: missing is a failure

    if not Path(CHROMIUM).exists():
        pytest.fail(f"{CHROMIUM} missing: `make test` installs Debian's chromium (scripts/system-deps.sh)")
    with sync_api.sync_playwright() as p:
        b = p.chromium.launch(executable_path=CHROMIUM, args=ARGS)
        yield b
        b.close()


@pytest.fixture(scope="session")
def browser_context(browser: Any) -> Iterator[Any]:
    """One context for the session: its HTTP cache keeps plotly.js (3.5 MB) parsed once,
    not once per test (each test still gets a fresh page; the studio's remembered pane
    sizes and rule view are cleared before every page)."""
    context = browser.new_context(viewport={"width": 1400, "height": 900}, accept_downloads=True)
    context.add_init_script("try { localStorage.clear(); } catch (e) {}")
    yield context
    context.close()


@pytest.fixture
def page(browser_context: Any, studio: str, request: pytest.FixtureRequest) -> Iterator[Any]:
    pg = browser_context.new_page()
    errors: list[str] = []
    pg.on("console", lambda m: m.type == "error" and errors.append(m.text))
    pg.on("pageerror", lambda e: errors.append(f"{e} {e.stack}"))
    request.node.console_errors = errors  # a test that provokes an error may take it off
    pg.goto(studio)
    pg.wait_for_selector("body[data-ready=true]")
    yield pg
    ARTIFACTS.mkdir(parents=True, exist_ok=True)
    pg.screenshot(path=str(ARTIFACTS / f"{request.node.name}-end.png"))
    pg.close()
    assert errors == [], f"console errors: {errors}"
