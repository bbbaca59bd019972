"""Every readable file of ../shared/corpus and ../shared/conformance (FCL, FIS, FLL; identical
files once) converted to every format that can be both written and read, the way
``fuzzyctl convert`` does it (``formats.convert``).

* A conversion without losses always writes a file that our reader of the target reads.
* FCL, FIS, FLL and JSON files written with ``--lossy`` (what the target cannot express
  left out) read back too; FPL and XFUZ may instead refuse with a diagnostic naming the
  problem (a PLC format of 16-bit words cannot take every system), never with an internal
  error.

Counts per target are printed in the "conformance measurements" section."""

from __future__ import annotations

import hashlib
from functools import cache
from pathlib import Path

import pytest

from fuzzyctl.diagnostics import DiagnosticError
from fuzzyctl.formats import available, convert, decode, get, read_text
from fuzzyctl.model import Document
from tests.conftest import SHARED

TARGETS = [f.name for f in available() if f.write is not None and f.read is not None]
LOSSY_MUST_READ = {"fcl", "fis", "fll", "json"}


def _sources() -> list[Path]:
    seen: set[str] = set()
    out = []
    for kind in ("fcl", "fis", "fll"):
        for path in sorted((SHARED / "corpus" / kind).glob(f"*.{kind}")) + sorted(
            (SHARED / "conformance").rglob(f"*.{kind}")
        ):
            digest = hashlib.sha1(path.read_bytes()).hexdigest()
            if digest not in seen:
                seen.add(digest)
                out.append(path)
    return out


SOURCES = _sources()


@cache
def _documents() -> list[tuple[Path, Document]]:
    """The readable sources, parsed once for all targets (the unreadable ones are the
    business of tests/formats/rejected.tsv and the FCL corpus test)."""
    out = []
    for path in SOURCES:
        try:
            out.append((path, get(path.suffix[1:]).read(decode(path.read_bytes()), str(path)).document))
        except DiagnosticError:
            continue
    return out


def test_the_issue_formats_are_all_converted() -> None:
    assert {"fcl", "fis", "fll", "json", "fpl", "xfuz"} <= set(TARGETS)
    assert len(SOURCES) > 400 and len(_documents()) > 0.95 * len(SOURCES)


@pytest.mark.parametrize("target", TARGETS)
def test_every_conversion_reads_back(target: str, record_property: pytest.RecordProperty) -> None:
    problems = []
    for path, document in _documents():
        label = f"convert corpus -> {target}, files"
        try:
            text, losses = convert(document, target, lossy=True)
        except DiagnosticError as exc:
            if target in LOSSY_MUST_READ or not get(target).lower(document)[1]:
                problems.append(f"{path.name}: writing fails: {exc.diagnostics[0].message}")
            else:
                assert exc.diagnostics[0].message
                record_property("roundtrip", f"{label}\tlossy, refused with a diagnostic\t")
            continue
        try:
            read_text(text, target)
        except DiagnosticError as exc:
            if not losses or target in LOSSY_MUST_READ:
                problems.append(f"{path.name}: written with {len(losses)} losses, unreadable: {exc}")
            else:
                record_property("roundtrip", f"{label}\tlossy, written but not readable\t")
            continue
        category = "lossy, reads back" if losses else "lossless, reads back"
        record_property("roundtrip", f"{label}\t{category}\t")
    assert not problems, "\n".join(problems[:20])
