"""Writing files atomically: readers (and a crash) see the old content or the new one, never a
part, and the file keeps the permissions a user expects.

Every file fuzzyctl writes for a user (``fmt -i``, ``convert``, ``codegen``, ``eval -o``,
``explain --png``, ``simulate``, the studio's Save) goes through :func:`atomic_writer`: a
temporary file in the same directory, flushed and fsynced, then renamed over the target.
The result keeps the mode of the file it replaces, or gets the umask's default (0666 &
~umask) when it is new - a temporary file alone would be 0600."""

from __future__ import annotations

import contextlib
import os
import tempfile
from collections.abc import Iterator
from pathlib import Path
from typing import IO, Any


def _mode_for(target: Path) -> int:
    try:
        return target.stat().st_mode & 0o7777
    except FileNotFoundError:
        umask = os.umask(0)
        os.umask(umask)
        return 0o666 & ~umask


@contextlib.contextmanager
def atomic_writer(path: str | Path, mode: str = "w", *, durable: bool = False) -> Iterator[IO[Any]]:
    """A file object to write ``path`` through; on success it replaces ``path`` in one rename,
    on an exception ``path`` is left as it was.  ``durable`` also fsyncs the directory, so that
    the rename itself survives a power loss (the studio's Save)."""
    target = Path(path)
    directory = target.parent if str(target.parent) else Path(".")
    directory.mkdir(parents=True, exist_ok=True)
    fd, tmp = tempfile.mkstemp(prefix=f".{target.name}.", suffix=".tmp", dir=directory)
    try:
        opened = os.fdopen(fd, "wb") if mode == "wb" else os.fdopen(fd, "w", encoding="utf-8", newline="\n")
        with opened as handle:
            yield handle
            handle.flush()
            os.fsync(handle.fileno())
        os.chmod(tmp, _mode_for(target))
        os.replace(tmp, target)
        if durable:
            dir_fd = os.open(directory, os.O_RDONLY)
            try:
                os.fsync(dir_fd)
            finally:
                os.close(dir_fd)
    except BaseException:
        Path(tmp).unlink(missing_ok=True)
        raise


def write_atomic(path: str | Path, content: str | bytes, *, durable: bool = False) -> None:
    """Write ``content`` (text as UTF-8 with ``\\n`` line ends, or bytes) to ``path`` atomically."""
    if isinstance(content, bytes):
        with atomic_writer(path, "wb", durable=durable) as handle:
            handle.write(content)
    else:
        with atomic_writer(path, "w", durable=durable) as handle:
            handle.write(content)
