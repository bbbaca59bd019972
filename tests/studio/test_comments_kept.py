"""The studio's Open -> Save keeps every comment where it was (issue 25, point 5): the
browser holds the model as JSON, and the comments' places travel with it."""

from __future__ import annotations

from pathlib import Path

from fastapi.testclient import TestClient

from fuzzyctl.studio import create_app
from tests.fcl.test_comments_kept import EVERYWHERE, EXPECTED, assert_in_place, formatted

BASE = "http://127.0.0.1:8770"


def test_open_then_save_keeps_every_comment_in_place(tmp_path: Path) -> None:
    (tmp_path / "everywhere.fcl").write_text(EVERYWHERE)
    client = TestClient(create_app(tmp_path, token=None), base_url=BASE)
    r = client.post("/api/open", json={"path": "everywhere.fcl"})
    assert r.status_code == 200, r.text
    opened = r.json()
    assert opened["document"] is not None
    body = {"document": opened["document"], "settings": opened.get("settings") or {}}
    # Save over the file it came from, and Save as another name
    r = client.post("/api/save", json={**body, "path": "everywhere.fcl", "expected_sha256": opened["sha256"]})
    assert r.status_code == 200, r.text
    r = client.post("/api/save", json={**body, "path": "copy.fcl"})
    assert r.status_code == 200, r.text
    for name in ("everywhere.fcl", "copy.fcl"):
        assert_in_place(EVERYWHERE, (tmp_path / name).read_text(), EXPECTED)
    # opened and saved again: the same text (the comments stay where the first Save put them)
    again = client.post("/api/open", json={"path": "copy.fcl"}).json()
    body = {"document": again["document"], "settings": again.get("settings") or {}}
    assert client.post("/api/save", json={**body, "path": "copy2.fcl"}).status_code == 200
    assert (tmp_path / "copy2.fcl").read_text() == (tmp_path / "copy.fcl").read_text()
    # the FCL part is what fmt writes
    assert (tmp_path / "copy.fcl").read_text().startswith(formatted(EVERYWHERE).split("    OPTIONS")[0])
