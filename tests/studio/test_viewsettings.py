"""Issue 27 point 11: Save keeps the user's file theirs.  The studio's view settings go to a
sidecar (.fuzzyctl-studio/<file>.json), so a Basic-level file stays Basic (the level the
checker gives the file as the user wrote it), `convert` to FLL takes it as it takes the
original, and a file written by an earlier studio (OPTIONS STUDIO block) still opens with
its settings and loses the block on the next Save."""

from __future__ import annotations

import json
import shutil
from pathlib import Path
from typing import Any

import pytest
from fastapi.testclient import TestClient

import fuzzyctl
from fuzzyctl import formats
from fuzzyctl.studio import create_app
from fuzzyctl.studio.analysis import check_text
from fuzzyctl.studio.viewsettings import SIDECAR_DIR, sidecar
from tests.conftest import EXAMPLES

TOKEN = "view-settings-token-0123456789"
SETTINGS = {
    "ranges": {"distance": [-5.0, 25.0]},
    "recorder": {"curves": ["distance", "power"], "length": 30.0},
}


@pytest.fixture
def project(tmp_path: Path) -> Path:
    shutil.copy(EXAMPLES / "crane.fcl", tmp_path / "crane.fcl")
    return tmp_path


@pytest.fixture
def client(project: Path) -> TestClient:
    return TestClient(
        create_app(project, token=TOKEN),
        base_url="http://127.0.0.1",
        headers={"Authorization": f"Bearer {TOKEN}"},
    )


def post(client: TestClient, path: str, body: dict[str, Any]) -> dict[str, Any]:
    r = client.post(path, json=body)
    assert r.status_code == 200, r.text
    data: dict[str, Any] = r.json()
    return data


def test_save_keeps_level_and_convert_and_settings_beside(client: TestClient, project: Path) -> None:
    original = (project / "crane.fcl").read_text()
    level = check_text(original, "crane.fcl").level
    assert level == "Basic"
    opened = post(client, "/api/open", {"path": "crane.fcl"})
    body = {"path": "crane.fcl", "document": opened["document"], "settings": SETTINGS}
    saved = post(client, "/api/save", {**body, "expected_sha256": opened["sha256"]})
    text = (project / "crane.fcl").read_text()
    assert "OPTIONS" not in text and "STUDIO" not in text
    assert saved["level"] == level == check_text(text, "crane.fcl").level
    # convert takes the saved file as it takes the original: same FLL (no "vendor options")
    fll_saved, losses_saved = formats.convert(fuzzyctl.load(project / "crane.fcl"), "fll")
    fll_original, losses_original = formats.convert(fuzzyctl.load(EXAMPLES / "crane.fcl"), "fll")
    assert fll_saved == fll_original and losses_saved == losses_original
    # the settings: in the hidden sidecar, not listed, read back on Open
    kept = json.loads(sidecar(project, "crane.fcl").read_text())
    assert kept["ranges"] == SETTINGS["ranges"] and kept["recorder"]["curves"] == ["distance", "power"]
    assert all(not f["path"].startswith(SIDECAR_DIR) for f in post_files(client))
    assert post(client, "/api/open", {"path": "crane.fcl"})["settings"] == kept
    # no settings: no sidecar left behind
    post(client, "/api/save", {**body, "settings": {}, "overwrite": True})
    assert not sidecar(project, "crane.fcl").exists()


def post_files(client: TestClient) -> list[dict[str, Any]]:
    r = client.get("/api/files")
    assert r.status_code == 200
    files: list[dict[str, Any]] = r.json()["files"]
    return files


def test_a_file_with_an_options_studio_block_still_opens_and_loses_it_on_save(
    client: TestClient, project: Path
) -> None:
    old = (
        (EXAMPLES / "crane.fcl")
        .read_text()
        .replace(
            "END_FUNCTION_BLOCK",
            'OPTIONS\n    STUDIO {"ranges":{"distance":[-5.0,25.0]}};\nEND_OPTIONS\nEND_FUNCTION_BLOCK',
            1,
        )
    )
    (project / "old.fcl").write_text(old)
    assert check_text(old, "old.fcl").level == "Open"  # what the block did to the file
    opened = post(client, "/api/open", {"path": "old.fcl"})
    assert opened["settings"] == {"ranges": {"distance": [-5.0, 25.0]}}
    assert opened["document"]["blocks"][0]["options"] == []
    post(
        client,
        "/api/save",
        {
            "path": "old.fcl",
            "document": opened["document"],
            "settings": opened["settings"],
            "expected_sha256": opened["sha256"],
        },
    )
    text = (project / "old.fcl").read_text()
    assert "STUDIO" not in text and check_text(text, "old.fcl").level == "Basic"
    assert post(client, "/api/open", {"path": "old.fcl"})["settings"] == {
        "ranges": {"distance": [-5.0, 25.0]}
    }


def test_a_broken_sidecar_never_keeps_a_file_from_opening(client: TestClient, project: Path) -> None:
    path = sidecar(project, "crane.fcl")
    path.parent.mkdir()
    path.write_text("{not json")
    assert post(client, "/api/open", {"path": "crane.fcl"})["settings"] == {}
