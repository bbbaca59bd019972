"""A small on-disk cache for slow, deterministic test set-ups (a third-party parser's work on a
generated text, a compiler build): the value is recomputed whenever anything in its key
changes, and written atomically so that parallel test workers never read half a file.

Location: ``$FUZZYCTL_TEST_CACHE`` or ``~/.cache/fuzzyctl-tests``.  Deleting it only costs time."""

from __future__ import annotations

import hashlib
import os
import pickle
import tempfile
from collections.abc import Callable
from pathlib import Path
from typing import Any, TypeVar

T = TypeVar("T")

CACHE = Path(os.environ.get("FUZZYCTL_TEST_CACHE", Path.home() / ".cache" / "fuzzyctl-tests"))


def _digest(key: Any) -> str:
    return hashlib.sha256(pickle.dumps(key, protocol=4)).hexdigest()


def cache_dir(kind: str) -> Path:
    path = CACHE / kind
    path.mkdir(parents=True, exist_ok=True)
    return path


def cached(kind: str, key: Any, compute: Callable[[], T]) -> T:
    """``compute()``, or its pickled result from an earlier run with the same ``key``."""
    path = cache_dir(kind) / f"{_digest(key)}.pickle"
    try:
        with path.open("rb") as handle:
            value: T = pickle.load(handle)
            return value
    except (OSError, EOFError, pickle.UnpicklingError, AttributeError, ImportError):
        pass
    value = compute()
    fd, tmp = tempfile.mkstemp(dir=path.parent, suffix=".tmp")
    try:
        with os.fdopen(fd, "wb") as handle:
            pickle.dump(value, handle, protocol=4)
        os.replace(tmp, path)
    except BaseException:
        Path(tmp).unlink(missing_ok=True)
        raise
    return value


def cached_dir(kind: str, key: Any, build: Callable[[Path], None]) -> Path:
    """A directory filled by ``build(dir)`` once per ``key`` (a compiler's output, say): built in
    a temporary directory and renamed into place, so that a reader sees all of it or none."""
    import shutil

    final = cache_dir(kind) / _digest(key)
    if (final / ".complete").exists():
        return final
    tmp = Path(tempfile.mkdtemp(dir=final.parent, prefix=".build-"))
    try:
        build(tmp)
        (tmp / ".complete").touch()
        try:
            os.rename(tmp, final)
        except OSError:  # another worker got there first (or a stale partial dir is in the way)
            if not (final / ".complete").exists():
                shutil.rmtree(final, ignore_errors=True)
                os.rename(tmp, final)
    finally:
        shutil.rmtree(tmp, ignore_errors=True)
    return final
