"""``fmt -i``, ``convert``, ``codegen -o`` (ST, PLCopen, C) keep files as users keep them: a
read-only target is not replaced (exit 1, a message saying so and naming --force) and
``--force`` replaces it; a symbolic link stays a link and its target gets what the command
writes; a hard link stays one file under both names.  What "what the command writes" is
comes from the same command writing a fresh file (the reference), never from a copy of
our own output."""

from __future__ import annotations

import os
import shutil
import stat
from collections.abc import Callable
from pathlib import Path

import pytest

from fuzzyctl.cli.app import main
from tests.conftest import EXAMPLES

SOURCE = EXAMPLES / "figure7.fcl"


@pytest.fixture(autouse=True)
def fixed_creation_time(monkeypatch: pytest.MonkeyPatch) -> None:
    """PLCopen XML carries its creation time: the reference and the run under test would
    differ when a second passes between them (seen on a loaded machine)."""
    monkeypatch.setenv("SOURCE_DATE_EPOCH", "1700000000")


# name -> (the file the command writes, given a work directory; the arguments writing it)
Command = Callable[[Path, Path, Path], list[str]]
COMMANDS: dict[str, tuple[str, Command]] = {
    "fmt -i": ("model.fcl", lambda src, out, _d: ["fmt", "-i", str(out)]),
    "fmt -o": ("model.fcl", lambda src, out, _d: ["fmt", str(src), "-o", str(out)]),
    "convert": ("model.json", lambda src, out, _d: ["convert", str(src), str(out)]),
    "codegen st": ("model.st", lambda src, out, _d: ["codegen", str(src), "-o", str(out)]),
    "codegen plcopen": (
        "model.xml",
        lambda src, out, _d: ["codegen", str(src), "--lang", "plcopen", "-o", str(out)],
    ),
    "codegen c": ("Fuzzy_FB.c", lambda src, _out, d: ["codegen", str(src), "--lang", "c", "-o", str(d)]),
}


def reference(tmp_path: Path, name: str) -> bytes:
    """What the command writes to a fresh, ordinary file."""
    fresh = tmp_path / "fresh"
    fresh.mkdir()
    target, args = COMMANDS[name]
    src = fresh / "source.fcl"
    shutil.copy(SOURCE, src)
    out = fresh / target
    if name == "fmt -i":
        shutil.copy(SOURCE, out)
    assert main(args(src, out, fresh)) == 0
    data = out.read_bytes()
    assert data and data != SOURCE.read_bytes()  # the command does change something
    return data


def setup(tmp_path: Path, name: str) -> tuple[Path, Path, Path]:
    work = tmp_path / "work"
    work.mkdir()
    src = work / "source.fcl"
    shutil.copy(SOURCE, src)
    target = work / COMMANDS[name][0]
    return work, src, target


def old_content(name: str) -> bytes:
    # fmt -i rewrites the file it reads: its old content is the (unformatted) source
    return SOURCE.read_bytes() if name == "fmt -i" else b"the user's file\n"


@pytest.mark.parametrize("name", list(COMMANDS))
def test_a_read_only_target_is_refused_and_force_replaces_it(
    tmp_path: Path, name: str, capsys: pytest.CaptureFixture[str]
) -> None:
    expected = reference(tmp_path, name)
    work, src, target = setup(tmp_path, name)
    target.write_bytes(old_content(name))
    target.chmod(0o444)
    args = COMMANDS[name][1](src, target, work)
    capsys.readouterr()
    assert main(args) == 1
    err = capsys.readouterr().err
    assert f"{target.name} is read-only: not replaced (--force replaces it)" in err
    assert target.read_bytes() == old_content(name)
    assert main([*args, "--force"]) == 0
    assert target.read_bytes() == expected
    assert stat.S_IMODE(target.stat().st_mode) == 0o444  # still the user's read-only file
    assert not [p for p in work.iterdir() if p.name.startswith(".")]  # no temporary file left


def test_codegen_c_refuses_before_writing_any_file(tmp_path: Path) -> None:
    work, src, _ = setup(tmp_path, "codegen c")
    (work / "Fuzzy_FB.h").write_text("mine\n")
    (work / "Fuzzy_FB.h").chmod(0o444)
    assert main(["codegen", str(src), "--lang", "c", "-o", str(work)]) == 1
    assert not (work / "Fuzzy_FB.c").exists()  # the writable one was not written either
    assert (work / "Fuzzy_FB.h").read_text() == "mine\n"


@pytest.mark.parametrize("name", list(COMMANDS))
def test_a_symlink_stays_a_link_and_its_target_is_written(tmp_path: Path, name: str) -> None:
    expected = reference(tmp_path, name)
    work, src, target = setup(tmp_path, name)
    (work / "kept").mkdir()
    real = work / "kept" / target.name
    real.write_bytes(old_content(name))
    target.symlink_to(Path("kept") / target.name)
    assert main(COMMANDS[name][1](src, target, work)) == 0
    assert target.is_symlink() and os.readlink(target) == f"kept/{target.name}"
    assert real.read_bytes() == expected


@pytest.mark.parametrize("name", list(COMMANDS))
def test_a_hard_link_stays_one_file(tmp_path: Path, name: str) -> None:
    expected = reference(tmp_path, name)
    work, src, target = setup(tmp_path, name)
    target.write_bytes(old_content(name))
    other = tmp_path / "elsewhere"
    other.mkdir()
    os.link(target, other / "same-file")
    assert main(COMMANDS[name][1](src, target, work)) == 0
    assert (other / "same-file").read_bytes() == expected == target.read_bytes()
    assert target.stat().st_ino == (other / "same-file").stat().st_ino and target.stat().st_nlink == 2
    assert not [p for p in work.iterdir() if p.name.startswith(".")]
