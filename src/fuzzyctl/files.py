"""Writing files as users keep them: readers (and a crash) see the old content or the new one,
never a part; a read-only file is not replaced; a symbolic link stays a link and a hard link
stays a link.

Every file fuzzyctl writes for a user (``fmt -i``, ``convert``, ``codegen``, ``eval -o``,
``explain --png``, ``simulate``, the studio's Save) goes through :func:`atomic_writer`.  The
new content is always written to a temporary file in the target's directory first, flushed
and fsynced; then, by what the target is:

* an ordinary file (or a new one): the temporary file is renamed over it (atomic).  The result
  keeps the mode of the file it replaces, or gets the umask's default (0666 & ~umask) when it
  is new - a temporary file alone would be 0600.
* a symbolic link: the file it points to (at the end of the chain) is written, by the rules
  here; the link itself is left as it is.
* a file with other hard links (``st_nlink > 1``): a rename would detach this name from the
  others, so the new content is copied *into* the file.  The old content is first copied to a
  backup beside it (``.NAME.XXXX.orig``); if the copy into the file fails (disk full), the
  old content is put back from the backup, so no original is lost on a failed write.  The
  trade-off: this is not atomic for a reader that looks while it is written, the backup costs
  the file's size on disk while it exists, and after a power loss during the copy the old
  content is in the backup file (which is then left behind).
* a read-only file (no write permission for us, or no write bit at all - which also holds for
  root): refused with :class:`ReadOnlyError` unless ``force`` is given (``--force`` in the
  commands that have it).
"""

from __future__ import annotations

import contextlib
import os
import shutil
import stat
import tempfile
from collections.abc import Iterator
from pathlib import Path
from typing import IO, Any

from fuzzyctl.diagnostics import FuzzyctlError

__all__ = ["ReadOnlyError", "atomic_writer", "check_writable", "write_atomic", "write_target"]

# A temporary name is ".NAME.XXXXXXXX.tmp": 14 bytes more than NAME, which may already be at the
# file system's limit of 255 bytes; past this length the temporary file takes a short stem.
_STEM_MAX = 200


class ReadOnlyError(FuzzyctlError):
    """The file to write is read-only: it was not replaced."""

    def __init__(self, path: Path, hint: str) -> None:
        self.path = path
        super().__init__(f"{path} is read-only: not replaced ({hint})")


def write_target(path: str | Path) -> Path:
    """The file a write to ``path`` changes: the end of the chain when ``path`` is a symbolic
    link (which may not exist yet: a dangling link creates it), else ``path`` itself."""
    given = Path(path)
    return Path(os.path.realpath(given)) if given.is_symlink() else given


def _read_only(st: os.stat_result, target: Path) -> bool:
    # os.access says yes to root for every file: a file without any write bit counts as
    # read-only too (what `chmod a-w` means to its owner).
    return not (st.st_mode & 0o222) or not os.access(target, os.W_OK)


def check_writable(path: str | Path, *, hint: str = "make it writable to replace it") -> None:
    """Raise :class:`ReadOnlyError` when ``path`` (or what its link points to) is an existing
    read-only file; ``hint`` says how to override (e.g. ``"--force replaces it"``)."""
    target = write_target(path)
    try:
        st = target.stat()
    except (FileNotFoundError, NotADirectoryError):
        return
    if stat.S_ISREG(st.st_mode) and _read_only(st, target):
        raise ReadOnlyError(Path(path), hint)


def _mode_for(target: Path) -> int:
    try:
        return target.stat().st_mode & 0o7777
    except FileNotFoundError:
        umask = os.umask(0)
        os.umask(umask)
        return 0o666 & ~umask


def _fsync_dir(directory: Path) -> None:
    dir_fd = os.open(directory, os.O_RDONLY)
    try:
        os.fsync(dir_fd)
    finally:
        os.close(dir_fd)


def _copy_into(source: Path, target: Path) -> None:
    """``source``'s bytes into the file ``target`` (same inode), its end cut at their length."""
    with open(source, "rb") as src, open(target, "r+b") as out:
        shutil.copyfileobj(src, out, 1 << 20)
        out.truncate()
        out.flush()
        os.fsync(out.fileno())


@contextlib.contextmanager
def _writable_for_now(target: Path, force: bool) -> Iterator[None]:
    """With ``force``, a read-only file we own gets its owner's write bit while it is written."""
    st = target.stat()
    lend = force and not os.access(target, os.W_OK) and st.st_uid == os.geteuid()
    if lend:
        os.chmod(target, stat.S_IMODE(st.st_mode) | stat.S_IWUSR)
    try:
        yield
    finally:
        if lend:
            os.chmod(target, stat.S_IMODE(st.st_mode))


def _write_in_place(new: Path, target: Path, force: bool) -> None:
    """Copy ``new`` into the hard-linked ``target``, its old content backed up beside it and
    put back if the copy fails."""
    fd, name = tempfile.mkstemp(prefix=f".{_stem(target)}.", suffix=".orig", dir=target.parent)
    os.close(fd)
    backup = Path(name)
    try:
        shutil.copyfile(target, backup)  # disk full here: the target is not touched yet
        with open(backup, "rb+") as handle:
            os.fsync(handle.fileno())
    except BaseException:
        backup.unlink(missing_ok=True)
        raise
    with _writable_for_now(target, force):
        try:
            _copy_into(new, target)
        except BaseException as exc:
            try:
                _copy_into(backup, target)
            except OSError as again:
                raise FuzzyctlError(
                    f"{target}: writing it failed ({exc}) and so did restoring it ({again}); "
                    f"its previous content is in {backup}"
                ) from exc
            backup.unlink(missing_ok=True)
            raise
    backup.unlink(missing_ok=True)


def _stem(target: Path) -> str:
    return target.name if len(os.fsencode(target.name)) <= _STEM_MAX else "fuzzyctl"


@contextlib.contextmanager
def atomic_writer(
    path: str | Path,
    mode: str = "w",
    *,
    durable: bool = False,
    force: bool = False,
    hint: str = "make it writable to replace it",
) -> Iterator[IO[Any]]:
    """A file object to write ``path`` through; on success it replaces ``path``'s content (see
    the module: rename, or in place for a hard link; a symbolic link's target), on an
    exception ``path`` is left as it was.  A read-only ``path`` raises :class:`ReadOnlyError`
    (``hint`` says how to override) unless ``force``.  ``durable`` also fsyncs the directory,
    so that a rename itself survives a power loss (the studio's Save)."""
    given = Path(path)
    target = write_target(given)
    if not force:
        check_writable(given, hint=hint)
    directory = target.parent if str(target.parent) else Path(".")
    if not given.is_symlink():
        directory.mkdir(parents=True, exist_ok=True)
    fd, tmp = tempfile.mkstemp(prefix=f".{_stem(target)}.", suffix=".tmp", dir=directory)
    try:
        opened = os.fdopen(fd, "wb") if mode == "wb" else os.fdopen(fd, "w", encoding="utf-8", newline="\n")
        with opened as handle:
            yield handle
            handle.flush()
            os.fsync(handle.fileno())
        try:
            links = target.stat().st_nlink if target.is_file() else 1
        except FileNotFoundError:
            links = 1
        if links > 1:
            _write_in_place(Path(tmp), target, force)
            Path(tmp).unlink()
            return
        os.chmod(tmp, _mode_for(target))
        os.replace(tmp, target)
        if durable:
            _fsync_dir(directory)
    except BaseException:
        Path(tmp).unlink(missing_ok=True)
        raise


def write_atomic(
    path: str | Path,
    content: str | bytes,
    *,
    durable: bool = False,
    force: bool = False,
    hint: str = "make it writable to replace it",
) -> None:
    """Write ``content`` (text as UTF-8 with ``\\n`` line ends, or bytes) to ``path`` by
    :func:`atomic_writer`'s rules."""
    if isinstance(content, bytes):
        with atomic_writer(path, "wb", durable=durable, force=force, hint=hint) as handle:
            handle.write(content)
    else:
        with atomic_writer(path, "w", durable=durable, force=force, hint=hint) as handle:
            handle.write(content)
