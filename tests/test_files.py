"""fuzzyctl.files: every file fuzzyctl writes for a user is replaced whole or not at all, a
read-only file is refused unless forced, a symbolic link stays a link (its target is
written), a hard link stays a link (written in place), and a failed write - at any step,
in either way of writing - leaves the old content and no stray file."""

from __future__ import annotations

import errno
import os
import shutil
import stat
from pathlib import Path
from typing import Any

import pytest

from fuzzyctl.diagnostics import FuzzyctlError
from fuzzyctl.files import ReadOnlyError, atomic_writer, write_atomic

OLD = "old content\n" * 1000
NEW = "new content\n" * 3000  # longer: the in-place copy has to grow the file


def names(directory: Path) -> list[str]:
    return sorted(p.name for p in directory.iterdir())


def test_a_new_file_gets_the_umask_default_and_a_replaced_one_keeps_its_mode(tmp_path: Path) -> None:
    umask = os.umask(0o027)
    try:
        write_atomic(tmp_path / "new.txt", "x")
    finally:
        os.umask(umask)
    assert stat.S_IMODE((tmp_path / "new.txt").stat().st_mode) == 0o640
    (tmp_path / "new.txt").chmod(0o604)
    write_atomic(tmp_path / "new.txt", "y")
    assert stat.S_IMODE((tmp_path / "new.txt").stat().st_mode) == 0o604


def test_a_read_only_file_is_refused_and_force_replaces_it_keeping_its_mode(tmp_path: Path) -> None:
    target = tmp_path / "model.fcl"
    target.write_text(OLD)
    target.chmod(0o444)
    with pytest.raises(ReadOnlyError, match=r"model\.fcl is read-only: not replaced \(--force replaces it\)"):
        write_atomic(target, NEW, hint="--force replaces it")
    assert target.read_text() == OLD and names(tmp_path) == ["model.fcl"]
    write_atomic(target, NEW, force=True)
    assert target.read_text() == NEW and stat.S_IMODE(target.stat().st_mode) == 0o444
    assert names(tmp_path) == ["model.fcl"]


def test_a_symlink_stays_a_link_and_its_target_is_written(tmp_path: Path) -> None:
    (tmp_path / "real").mkdir()
    real = tmp_path / "real" / "model.fcl"
    real.write_text(OLD)
    (tmp_path / "hop.fcl").symlink_to("real/model.fcl")
    (tmp_path / "link.fcl").symlink_to("hop.fcl")  # a chain of two links
    write_atomic(tmp_path / "link.fcl", NEW)
    assert os.readlink(tmp_path / "link.fcl") == "hop.fcl"
    assert os.readlink(tmp_path / "hop.fcl") == "real/model.fcl"
    assert real.read_text() == NEW
    assert names(tmp_path / "real") == ["model.fcl"] and names(tmp_path) == ["hop.fcl", "link.fcl", "real"]
    # A dangling link: its target is created, as `echo > link` would.
    (tmp_path / "dangling.fcl").symlink_to("real/later.fcl")
    write_atomic(tmp_path / "dangling.fcl", "x")
    assert (tmp_path / "dangling.fcl").is_symlink() and (tmp_path / "real" / "later.fcl").read_text() == "x"
    # A read-only target behind a link is refused like the file itself.
    real.chmod(0o444)
    with pytest.raises(ReadOnlyError):
        write_atomic(tmp_path / "link.fcl", OLD)
    assert real.read_text() == NEW


def test_a_hard_link_stays_a_link(tmp_path: Path) -> None:
    first, second = tmp_path / "a.fcl", tmp_path / "b.fcl"
    first.write_text(OLD)
    first.chmod(0o640)
    os.link(first, second)
    inode = first.stat().st_ino
    write_atomic(first, NEW)
    assert second.read_text() == NEW and first.read_text() == NEW
    assert first.stat().st_ino == second.stat().st_ino == inode and first.stat().st_nlink == 2
    assert stat.S_IMODE(first.stat().st_mode) == 0o640
    write_atomic(second, "short\n")  # shrinking: the old tail is cut
    assert first.read_text() == "short\n"
    assert names(tmp_path) == ["a.fcl", "b.fcl"]
    first.chmod(0o444)
    with pytest.raises(ReadOnlyError):
        write_atomic(first, NEW)
    write_atomic(first, NEW, force=True)
    assert second.read_text() == NEW and stat.S_IMODE(second.stat().st_mode) == 0o444


def _hard_linked(tmp_path: Path) -> tuple[Path, Path]:
    first, second = tmp_path / "a.fcl", tmp_path / "b.fcl"
    first.write_text(OLD)
    os.link(first, second)
    return first, second


def test_a_full_disk_while_backing_up_a_hard_link_leaves_it_untouched(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    first, second = _hard_linked(tmp_path)

    def full(*_args: Any, **_kwargs: Any) -> None:
        raise OSError(errno.ENOSPC, "No space left on device")

    monkeypatch.setattr(shutil, "copyfile", full)
    with pytest.raises(OSError) as failed:
        write_atomic(first, NEW)
    assert failed.value.errno == errno.ENOSPC
    assert second.read_text() == OLD and first.stat().st_nlink == 2
    assert names(tmp_path) == ["a.fcl", "b.fcl"]


def test_a_failed_in_place_write_puts_the_old_content_back(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    first, second = _hard_linked(tmp_path)
    copy = shutil.copyfileobj
    calls = []

    def half_then_full(source: Any, out: Any, *args: Any) -> None:
        calls.append(source)
        if len(calls) == 1:  # the new content: a part written, then the disk is full
            out.write(b"partial")
            raise OSError(errno.ENOSPC, "No space left on device")
        copy(source, out, *args)  # the restore

    monkeypatch.setattr(shutil, "copyfileobj", half_then_full)
    with pytest.raises(OSError):
        write_atomic(first, NEW)
    assert len(calls) == 2
    assert second.read_text() == OLD and first.stat().st_nlink == 2
    assert names(tmp_path) == ["a.fcl", "b.fcl"]


def test_when_the_restore_fails_too_the_backup_is_kept_and_named(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    first, _second = _hard_linked(tmp_path)

    def broken(_source: Any, out: Any, *_args: Any) -> None:
        out.write(b"partial")
        raise OSError(errno.EIO, "Input/output error")

    monkeypatch.setattr(shutil, "copyfileobj", broken)
    with pytest.raises(FuzzyctlError, match="its previous content is in") as failed:
        write_atomic(first, NEW)
    backup = Path(str(failed.value).rsplit(" ", 1)[1])
    assert backup.parent == tmp_path and backup.name.startswith(".a.fcl.") and backup.read_text() == OLD


@pytest.mark.parametrize("links", [1, 2])
def test_an_exception_while_writing_leaves_the_file(tmp_path: Path, links: int) -> None:
    target = tmp_path / "a.fcl"
    target.write_text(OLD)
    if links == 2:
        os.link(target, tmp_path / "b.fcl")
    with pytest.raises(RuntimeError), atomic_writer(target) as handle:
        handle.write(NEW)
        raise RuntimeError("the generator failed half-way")
    assert target.read_text() == OLD and target.stat().st_nlink == links
    assert len(names(tmp_path)) == links


def test_a_name_at_the_file_system_s_limit_is_written(tmp_path: Path) -> None:
    name = "n" * 251 + ".fcl"  # 255 bytes: the temporary file cannot carry the whole name
    (tmp_path / name).write_text(OLD)  # the reference: the OS takes this name
    write_atomic(tmp_path / name, NEW)
    assert (tmp_path / name).read_text() == NEW and names(tmp_path) == [name]
