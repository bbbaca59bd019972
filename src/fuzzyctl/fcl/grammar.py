"""The FCL grammar (``fcl.lark``, the grammar of record) and lark parsers of it whose analysed
tables are kept in the on-disk cache, so that a process only loads them."""

from __future__ import annotations

import os
import threading
from functools import cache
from importlib import resources
from typing import Any

from lark import Lark

__all__ = ["cached_lark", "grammar", "terminal_names"]


@cache
def grammar() -> str:
    """The text of fcl.lark."""
    return resources.files("fuzzyctl.fcl").joinpath("fcl.lark").read_text(encoding="utf-8")


def terminal_names() -> list[str]:
    """The grammar's terminal names (for the lexer callbacks), kept beside the tables."""
    import hashlib
    import json

    from lark import __version__ as lark_version

    from fuzzyctl import cache as disk

    key = hashlib.sha256((grammar() + lark_version).encode()).hexdigest()[:24]
    path = disk.cache_dir() / "lark" / f"fcl-terminals-{key}.json"
    try:
        names = json.loads(path.read_text())
        if isinstance(names, list) and all(isinstance(n, str) for n in names):
            return names
    except (OSError, ValueError):
        pass
    names = [t.name for t in cached_lark().terminals]
    disk.write_atomic(path, json.dumps(names).encode())
    return names


def cached_lark(**options: Any) -> Lark:
    """A Lark parser of the FCL grammar, its analysed tables loaded from (or written to) the
    on-disk cache; without a writable cache directory they are computed in memory."""
    import hashlib

    from lark import __version__ as lark_version

    from fuzzyctl import cache as disk

    text = grammar()
    opts: dict[str, Any] = {"parser": "lalr", "lexer": "contextual", **options}
    spec = repr((sorted(options), options.get("maybe_placeholders")))
    key = hashlib.sha256((text + lark_version + spec).encode()).hexdigest()[:24]
    path = disk.cache_dir() / "lark" / f"fcl-{key}.cache"
    if not path.exists():
        # lark writes its cache file in place: write it elsewhere and rename it, so that
        # another process never reads half a file
        try:
            path.parent.mkdir(parents=True, exist_ok=True)
            tmp = path.with_name(f".{path.name}.{os.getpid()}.{threading.get_ident()}.tmp")
            Lark(text, cache=str(tmp), **opts)
            os.replace(tmp, path)
        except OSError:
            return Lark(text, **opts)
    return Lark(text, cache=str(path), **opts)
