"""``fuzzyctl studio FILE`` as `make run` starts it: prints its URL (with the token and the
view asked for), serves the page, the plotly.js of the plotly package and the API to the
browser that opened that URL, and listens on 127.0.0.1 only."""

from __future__ import annotations

import json
import re
import shutil
import socket
import subprocess
import sys
import urllib.request
from pathlib import Path

import pytest

from tests.conftest import EXAMPLES


def test_studio_command_serves_the_file_on_loopback_only(tmp_path: Path) -> None:
    shutil.copy(EXAMPLES / "crane.fcl", tmp_path / "crane.fcl")
    shutil.copy(EXAMPLES / "crane.toml", tmp_path / "crane.toml")
    exe = Path(sys.executable).parent / "fuzzyctl"
    proc = subprocess.Popen(
        [str(exe), "studio", str(tmp_path / "crane.fcl"), "--port", "0", "--view", "recorder"],
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
    )
    try:
        assert proc.stdout is not None
        line = proc.stdout.readline()
        match = re.search(r"(http://127\.0\.0\.1:(\d+)/)\?view=recorder&token=\S+", line)
        assert match, line
        base, port = match.group(1), int(match.group(2))
        browser = urllib.request.build_opener(urllib.request.HTTPCookieProcessor())
        with browser.open(match.group(0), timeout=10) as r:
            assert "fuzzyctl studio" in r.read().decode()
            assert r.url == base + "?view=recorder"  # the token went into a cookie
        with browser.open(f"{base}vendor/plotly.min.js", timeout=10) as r:
            assert len(r.read()) > 1_000_000  # the full plotly.js bundle of the plotly package
        with browser.open(f"{base}api/info", timeout=10) as r:
            info = json.loads(r.read())
        assert info["file"] == "crane.fcl"
        # bound to 127.0.0.1, not to every address: another loopback address is refused
        with pytest.raises(OSError), socket.create_connection(("127.0.0.2", port), timeout=2):
            pass
    finally:
        proc.terminate()
        proc.wait(10)
