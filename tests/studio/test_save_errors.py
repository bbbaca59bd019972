"""The studio's Open and Save when the disk says no: a name over 255 bytes, a path through a
file, a read-only directory or file, a full disk, a file too big - each answers its status
and a message saying what happened (never a 500 with a traceback), and leaves the file on
disk as it was.  Save never writes into a hidden directory (``.git/``), and keeps symbolic
and hard links as links.  TestClient raises any exception the app did not answer, so a
status code here is also the proof that none escaped to the terminal."""

from __future__ import annotations

import errno
import os
import shutil
import tempfile
from pathlib import Path
from typing import Any

import pytest
from fastapi.testclient import TestClient

import fuzzyctl
from fuzzyctl.studio import create_app
from tests.conftest import EXAMPLES

TOKEN = "save-errors-token-0123456789"


@pytest.fixture
def project(tmp_path: Path) -> Path:
    root = tmp_path / "project"
    root.mkdir()
    shutil.copy(EXAMPLES / "crane.fcl", root / "crane.fcl")
    return root


@pytest.fixture
def client(project: Path) -> TestClient:
    app = create_app(project, token=TOKEN)
    return TestClient(app, base_url="http://127.0.0.1:8770", headers={"Authorization": f"Bearer {TOKEN}"})


@pytest.fixture
def document(client: TestClient) -> dict[str, Any]:
    doc: dict[str, Any] = client.post("/api/open", json={"path": "crane.fcl"}).json()["document"]
    return doc


def snapshot(root: Path) -> dict[str, bytes]:
    """Every file under ``root`` (hidden ones too) with its bytes: what a refused Save must
    leave exactly as it was (no temporary file left behind either)."""
    return {
        p.relative_to(root).as_posix(): p.read_bytes()
        for p in sorted(root.rglob("*"))
        if p.is_file() and not p.is_symlink()
    }


def save(client: TestClient, document: dict[str, Any], path: str, **extra: Any) -> Any:
    return client.post("/api/save", json={"path": path, "document": document, **extra})


def test_a_name_over_255_bytes_is_a_400_and_one_just_under_is_saved(
    client: TestClient, project: Path, document: dict[str, Any]
) -> None:
    before = snapshot(project)
    r = save(client, document, "n" * 252 + ".fcl")  # 256 bytes
    assert r.status_code == 400
    assert "too long: at most 255 bytes per name" in r.json()["detail"]
    r = save(client, document, "é" * 126 + ".fcl")  # 256 bytes in UTF-8, 130 characters
    assert r.status_code == 400
    assert snapshot(project) == before
    # 255 bytes: the file system takes it (as it takes it from open()), so must Save, even
    # though the temporary file beside it could not carry the whole name.
    name = "n" * 251 + ".fcl"
    with open(project.parent / name, "w") as probe:  # the reference: the OS accepts this name
        probe.write("")
    r = save(client, document, name)
    assert r.status_code == 200, r.text
    assert fuzzyctl.load(project / name).main.name == "crane"
    assert sorted(p.name for p in project.iterdir()) == sorted(["crane.fcl", name])


@pytest.mark.parametrize("path", ["crane.fcl/x.fcl", "crane.fcl/sub/x.fcl"])
def test_a_path_through_a_file_is_a_400(
    client: TestClient, project: Path, document: dict[str, Any], path: str
) -> None:
    before = snapshot(project)
    r = save(client, document, path)
    assert r.status_code == 400
    reason = "a part of the path is a file, not a directory"
    assert r.json()["detail"] == f"cannot save {path!r}: {reason}; the file on disk is unchanged"
    assert snapshot(project) == before


@pytest.mark.parametrize(
    ("code", "status", "reason"),
    [
        (errno.EACCES, 403, "permission denied"),
        (errno.EROFS, 403, "the file system is read-only"),
        (errno.ENOSPC, 507, "the disk is full"),
        (errno.EDQUOT, 507, "the disk quota is exhausted"),
        (errno.EFBIG, 413, "the file is too big for the file system"),
        (errno.EIO, 500, os.strerror(errno.EIO)),
    ],
)
@pytest.mark.parametrize("where", ["mkstemp", "fsync", "replace"])
def test_a_failing_disk_answers_its_status_and_keeps_the_file(
    client: TestClient,
    project: Path,
    document: dict[str, Any],
    monkeypatch: pytest.MonkeyPatch,
    code: int,
    status: int,
    reason: str,
    where: str,
) -> None:
    """Root writes into a 0555 directory, so a read-only directory is simulated like a full
    disk: the call that fails in real life raises the errno it raises there."""
    document["blocks"][0]["name"] = "changed"
    before = snapshot(project)

    def fail(*_args: Any, **_kwargs: Any) -> Any:
        raise OSError(code, os.strerror(code))

    target = tempfile if where == "mkstemp" else os
    monkeypatch.setattr(target, where, fail)
    r = save(client, document, "crane.fcl", overwrite=True)
    assert r.status_code == status
    assert r.json() == {"detail": f"cannot save 'crane.fcl': {reason}; the file on disk is unchanged"}
    monkeypatch.undo()
    assert snapshot(project) == before


def test_a_read_only_directory_really_refuses_when_not_root(
    client: TestClient, project: Path, document: dict[str, Any]
) -> None:
    if os.geteuid() == 0:
        pytest.skip("root writes into read-only directories (the errno case is simulated above)")
    (project / "locked").mkdir()
    (project / "locked").chmod(0o555)
    try:
        r = save(client, document, "locked/x.fcl")
    finally:
        (project / "locked").chmod(0o755)
    assert r.status_code == 403 and "permission denied" in r.json()["detail"]


def test_a_read_only_file_is_not_replaced_even_when_confirmed(
    client: TestClient, project: Path, document: dict[str, Any]
) -> None:
    (project / "crane.fcl").chmod(0o444)
    before = snapshot(project)
    for extra in ({}, {"overwrite": True}):
        r = save(client, document, "crane.fcl", **extra)
        assert r.status_code == 403
        assert r.json()["readonly"] is True
        assert r.json()["detail"].startswith("crane.fcl is read-only: not saved")
    assert snapshot(project) == before
    assert (project / "crane.fcl").stat().st_mode & 0o777 == 0o444


def test_open_refuses_a_file_too_big_and_answers_a_read_error(
    client: TestClient, project: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    with open(project / "huge.fcl", "wb") as f:
        f.truncate(16 * 2**20 + 1)  # sparse: 16 MB + 1 byte
    r = client.post("/api/open", json={"path": "huge.fcl"})
    assert r.status_code == 413
    assert r.json()["detail"] == "huge.fcl is too big: 16.0 MB, the studio opens files of up to 16 MB"

    def denied(*_args: Any) -> bytes:
        raise PermissionError(errno.EACCES, "Permission denied")

    monkeypatch.setattr(Path, "read_bytes", denied)
    r = client.post("/api/open", json={"path": "crane.fcl"})
    assert r.status_code == 403
    assert r.json()["detail"] == "cannot open 'crane.fcl': permission denied"


@pytest.mark.parametrize(
    "path", [".git/config.fcl", ".hidden.fcl", "sub/.cache/x.fcl", ".git/hooks/pre-commit.fcl"]
)
def test_save_never_writes_into_hidden_directories(
    client: TestClient, project: Path, document: dict[str, Any], path: str
) -> None:
    (project / ".git" / "hooks").mkdir(parents=True)
    (project / ".git" / "config.fcl").write_text("keep")
    before = snapshot(project)
    r = save(client, document, path, overwrite=True)
    assert r.status_code == 403
    assert "hidden" in r.json()["detail"]
    assert snapshot(project) == before
    assert not (project / "sub").exists()


def test_save_through_a_link_into_a_hidden_directory_is_refused(
    client: TestClient, project: Path, document: dict[str, Any]
) -> None:
    (project / ".git").mkdir()
    (project / ".git" / "config.fcl").write_text("keep")
    (project / "innocent.fcl").symlink_to(project / ".git" / "config.fcl")
    r = save(client, document, "innocent.fcl", overwrite=True)
    assert r.status_code == 403
    assert (project / ".git" / "config.fcl").read_text() == "keep"


def test_save_writes_a_symlink_s_target_and_keeps_hard_links(
    client: TestClient, project: Path, document: dict[str, Any]
) -> None:
    (project / "models").mkdir()
    shutil.move(project / "crane.fcl", project / "models" / "crane.fcl")
    (project / "crane.fcl").symlink_to("models/crane.fcl")
    os.link(project / "models" / "crane.fcl", project / "twin.fcl")
    document["blocks"][0]["name"] = "renamed"
    opened = client.post("/api/open", json={"path": "crane.fcl"}).json()
    r = save(client, document, "crane.fcl", expected_sha256=opened["sha256"])
    assert r.status_code == 200, r.text
    assert (project / "crane.fcl").is_symlink()
    assert os.readlink(project / "crane.fcl") == "models/crane.fcl"
    real = project / "models" / "crane.fcl"
    assert real.stat().st_nlink == 2 and real.stat().st_ino == (project / "twin.fcl").stat().st_ino
    assert fuzzyctl.load(project / "twin.fcl").main.name == "renamed"
    assert (project / "twin.fcl").read_text() == r.json()["text"]
