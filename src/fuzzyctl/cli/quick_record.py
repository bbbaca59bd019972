"""The quick record of ``fuzzyctl eval FILE --set ...``: what one evaluation through a cached
native library needs (input names, defaults, output slots, the library, the warnings the
compiler gave), written as JSON beside the plan cache after a run of the full path, so the
next start with the same file, options and fuzzyctl imports neither the model nor the engine
nor numpy: it hashes the file, reads this record and calls the library through ctypes.

Only the native evaluator is recorded (the Python evaluators need the plan, which is the
import this avoids).  Anything the record cannot answer exactly as the full path would - an
unknown or missing input, a value out of a degree input's [0, 1], a library gone from the
cache - returns None, and the caller takes the full path, which reports it."""

from __future__ import annotations

import hashlib
import json
import math
import os
from pathlib import Path
from typing import Any

#: bump when the record's layout changes (old records are then never read)
_LAYOUT = 2
#: no format reads more (fuzzyctl.limits: JSON's limit, the largest), without importing it
_LARGEST_INPUT = 96 * 1024 * 1024


def _key(file: Path, data: bytes, block: str | None, compat: str) -> str | None:
    from fuzzyctl import cache

    if not cache.enabled():
        return None
    h = hashlib.sha256()
    spec = repr((_LAYOUT, cache.code_fingerprint(), file.suffix.lower(), block, compat))
    h.update(spec.encode() + b"\0")
    h.update(data)
    return h.hexdigest()[:32]


def _path(key: str) -> Path:
    from fuzzyctl import cache

    return cache.cache_dir() / "quick" / f"{key}.json"


def _native_wanted() -> bool:
    return os.environ.get("FUZZYCTL_BACKEND", "auto") in ("auto", "native")


def read_source(file: Path) -> bytes | None:
    """The file's bytes when it is a regular file of a size some format accepts (else None:
    the full path reads it and reports what is wrong).  A record is only ever written for a
    file the full path accepted, under limits that are part of fuzzyctl's code (so of the
    key); a limit set in the environment sends every start the full way."""
    if "FUZZYCTL_MAX_INPUT_BYTES" in os.environ:
        return None
    try:
        if not file.is_file() or file.stat().st_size > _LARGEST_INPUT:
            return None
        return file.read_bytes()
    except (OSError, ValueError):
        return None


class QuickRecord:
    """One recorded controller: evaluates through its library as NativeController does."""

    def __init__(self, data: dict[str, Any]) -> None:
        self.title: str = data["title"]
        self.inputs: list[tuple[str, float | None, bool]] = [
            (str(n), None if d is None else float(d), bool(g)) for n, d, g in data["inputs"]
        ]
        self.outputs: list[tuple[str, int]] = [(str(n), int(i)) for n, i in data["outputs"]]
        self.n_results: int = int(data["n_results"])
        self.library: str = data["library"]
        self.warnings: list[str] = [str(w) for w in data["warnings"]]
        #: input name -> (low, high): the ranges the full path warns about (engine/ranges.py)
        self.ranges: dict[str, tuple[float, float]] = {
            str(n): (float(lo), float(hi)) for n, (lo, hi) in data["ranges"].items()
        }

    def run(self, values: dict[str, float]) -> dict[str, float] | None:
        """The outputs for ``values``, or None where the full path must answer."""
        known = {n for n, _d, _g in self.inputs}
        if any(n not in known for n in values) or not os.path.isfile(self.library):
            return None
        row: list[float] = []
        for name, default, degree in self.inputs:
            v = values.get(name, default)
            if v is None or not math.isfinite(v) or (degree and not 0.0 <= v <= 1.0):
                return None
            row.append(v)
        import ctypes

        try:
            lib = ctypes.CDLL(self.library)
        except OSError:
            return None
        vp = ctypes.c_void_p
        lib.fz_state_size.restype = ctypes.c_size_t
        lib.fz_init.argtypes = [vp]
        lib.fz_eval.argtypes = [vp, vp, vp]
        inst = ctypes.create_string_buffer(int(lib.fz_state_size()))
        inst_p = ctypes.cast(inst, vp)
        lib.fz_init(inst_p)
        buf = (ctypes.c_double * max(1, len(row)))(*row)
        out = (ctypes.c_double * max(1, self.n_results))()
        lib.fz_eval(inst_p, buf, out)
        return {name: float(out[slot]) for name, slot in self.outputs}


def outside_lines(ranges: dict[str, tuple[float, float]], values: dict[str, float]) -> list[str]:
    """:func:`fuzzyctl.engine.ranges.outside_lines` without importing the engine package
    (tests/cli/test_quick.py holds the two to the same text)."""
    return [
        f"input {n!r} = {v:g} is outside its range {ranges[n][0]:g}..{ranges[n][1]:g}: "
        "the result is what the terms give there"
        for n, v in values.items()
        if n in ranges and not ranges[n][0] <= v <= ranges[n][1] and v == v
    ]


def lookup(file: Path, block: str | None, compat: str) -> tuple[QuickRecord | None, str | None]:
    """(the record for this file and these options or None, the key to save one under)."""
    if not _native_wanted():
        return None, None
    data = read_source(file)
    key = None if data is None else _key(file, data, block, compat)
    if key is None:
        return None, None
    try:
        with open(_path(key), encoding="utf-8") as fh:
            return QuickRecord(json.load(fh)), key
    except (OSError, ValueError, KeyError, TypeError):
        return None, key


def save(key: str, ctl: Any, title: str) -> None:
    """Record ``ctl`` when it evaluates through a native library (else nothing)."""
    from fuzzyctl.diagnostics import render_all
    from fuzzyctl.engine.native import NativeController

    if not isinstance(ctl, NativeController):
        return
    plan = ctl.plan
    slots, n_results = ctl.result_layout()
    record = {
        "title": title,
        "inputs": [[s.name, s.default, bool(s.degree)] for s in plan.inputs],
        "outputs": [[n, slot] for n, slot in slots],
        "n_results": n_results,
        "library": str(ctl.library),
        "warnings": render_all(ctl.warnings),
        "ranges": {n: list(r) for n, r in ctl.input_ranges.items()},
    }
    from fuzzyctl import cache

    cache.write_atomic(_path(key), json.dumps(record).encode())
