"""The on-disk cache shared by the parser tables, parsed documents, lowered plans and native
libraries: where it is, atomic writes, a size bound, and a fingerprint of fuzzyctl's own code
(every key includes it, so a changed fuzzyctl never reads what an older one wrote).

Location: ``$FUZZYCTL_CACHE_DIR``, else ``$XDG_CACHE_HOME/fuzzyctl``, else
``~/.cache/fuzzyctl``.  ``FUZZYCTL_NO_CACHE=1`` turns the document and plan caches off (the
native libraries are always kept: a library is the result of a compiler run).  Each kind of
entry lives in its own subdirectory, kept under ``$FUZZYCTL_CACHE_MB`` megabytes (default
256) by removing the least recently used files.  A process that cannot write the cache
(read-only home, full disk) simply does not cache.
"""

from __future__ import annotations

import contextlib
import hashlib
import os
import tempfile
from functools import cache as _memo
from pathlib import Path

#: Files of the package whose content decides what the caches hold.
_CODE_SUFFIXES = (".py", ".lark")


def cache_dir() -> Path:
    env = os.environ.get("FUZZYCTL_CACHE_DIR")
    if env:
        return Path(env)
    base = os.environ.get("XDG_CACHE_HOME") or str(Path.home() / ".cache")
    return Path(base) / "fuzzyctl"


def enabled() -> bool:
    """Whether documents and plans are cached (``FUZZYCTL_NO_CACHE`` unset)."""
    return not os.environ.get("FUZZYCTL_NO_CACHE")


def limit_bytes() -> int:
    try:
        return int(float(os.environ.get("FUZZYCTL_CACHE_MB", "256")) * 1024 * 1024)
    except ValueError:
        return 256 * 1024 * 1024


@_memo
def code_fingerprint() -> str:
    """A hash of fuzzyctl's source files (names and contents)."""
    root = Path(__file__).resolve().parent
    h = hashlib.sha256()
    for path in sorted(p for p in root.rglob("*") if p.suffix in _CODE_SUFFIXES):
        h.update(str(path.relative_to(root)).encode() + b"\0")
        h.update(path.read_bytes())
    return h.hexdigest()[:24]


def write_atomic(path: Path, data: bytes) -> bool:
    """Write ``data`` to ``path`` through a temporary file and a rename (readers never see
    half a file); False when the cache cannot be written."""
    try:
        path.parent.mkdir(parents=True, exist_ok=True)
        fd, tmp = tempfile.mkstemp(dir=path.parent, prefix=f".{path.name}.", suffix=".tmp")
        try:
            with os.fdopen(fd, "wb") as fh:
                fh.write(data)
            os.replace(tmp, path)
        except BaseException:
            Path(tmp).unlink(missing_ok=True)
            raise
    except OSError:
        return False
    return True


def touch(path: Path) -> None:
    """Mark an entry as used (least recently used entries go first)."""
    with contextlib.suppress(OSError):
        os.utime(path)


def prune(directory: Path, limit: int, keep: Path | None = None) -> None:
    """Remove the least recently used files of ``directory`` until it holds at most
    ``limit`` bytes (``keep`` stays)."""
    try:
        entries = []
        for p in directory.iterdir():
            if p.is_file() and not p.name.startswith("."):
                st = p.stat()
                entries.append((st.st_mtime, st.st_size, p))
    except OSError:
        return
    total = sum(size for _t, size, _p in entries)
    for _t, size, p in sorted(entries, key=lambda e: e[0]):
        if total <= limit:
            break
        if keep is not None and p == keep:
            continue
        try:
            p.unlink()
            total -= size
        except OSError:
            pass
