"""Every readable file of the corpus (extra suite) and of the vendored conformance data (FCL,
FIS, FLL; identical files once) converted to every format that can be both written and read, the way
``fuzzyctl convert`` does it (``formats.convert``).

* A conversion without losses always writes a file that our reader of the target reads.
* FCL, FIS, FLL and JSON files written with ``--lossy`` (what the target cannot express
  left out) read back too; FPL and XFUZ may instead refuse with a diagnostic naming the
  problem (a PLC format of 16-bit words cannot take every system), never with an internal
  error.

Counts per target are printed in the "conformance measurements" section."""

from __future__ import annotations

from functools import cache
from pathlib import Path

import pytest

from fuzzyctl.diagnostics import DiagnosticError
from fuzzyctl.formats import available, convert, decode, get, read_text
from fuzzyctl.model import Document
from tests.extras import ROOT, SOURCE_SETS, source_files

TARGETS = [f.name for f in available() if f.write is not None and f.read is not None]
LOSSY_MUST_READ = {"fcl", "fis", "fll", "json"}


KINDS = ("fcl", "fis", "fll")


@cache
def _documents(source: str) -> list[tuple[Path, Document]]:
    """The readable files of a source set, parsed once for all targets (the unreadable ones
    are the business of tests/formats/rejected.tsv and the FCL corpus test)."""
    out = []
    for path in source_files(source, KINDS):
        try:
            out.append((path, get(path.suffix[1:]).read(decode(path.read_bytes()), str(path)).document))
        except DiagnosticError:
            continue
    return out


def _listed_as_defective() -> set[str]:
    """Names of the corpus files whose defects tests/fcl/rejected.tsv and
    tests/formats/rejected.tsv record (each checked there: line, diagnostic, why no engine
    runs it)."""
    names = set()
    for tsv in (ROOT / "tests" / "fcl" / "rejected.tsv", ROOT / "tests" / "formats" / "rejected.tsv"):
        for line in tsv.read_text(encoding="utf-8").splitlines():
            if line and not line.startswith(("#", "file\t")):
                names.add(Path(line.split("\t", 1)[0]).name)
    return names


@pytest.mark.parametrize("source", SOURCE_SETS)
def test_the_issue_formats_are_all_converted(source: str) -> None:
    """Every file is converted but those a rejected.tsv lists as defective (a rate would let
    a newly unreadable file pass unnoticed)."""
    assert {"fcl", "fis", "fll", "json", "fpl", "xfuz"} <= set(TARGETS)
    files = source_files(source, KINDS)
    assert len(files) > {"corpus": 240, "vendored": 230}[source]
    read = {path for path, _ in _documents(source)}
    unreadable = sorted(p.name for p in files if p not in read)
    assert not set(unreadable) - _listed_as_defective(), unreadable
    assert len(read) >= 0.94 * len(files)


@pytest.mark.parametrize("source", SOURCE_SETS)
@pytest.mark.parametrize("target", TARGETS)
def test_every_conversion_reads_back(
    target: str, source: str, record_property: pytest.RecordProperty
) -> None:
    problems = []
    for path, document in _documents(source):
        label = f"convert {source} -> {target}, files"
        try:
            text, losses = convert(document, target, lossy=True)
        except DiagnosticError as exc:
            if target in LOSSY_MUST_READ or not get(target).adapt(document)[1]:
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
