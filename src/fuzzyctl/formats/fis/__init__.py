"""MATLAB / Octave FIS files and fuzzylite's FIS export: :mod:`.reader` (with the rule
lines in :mod:`.rules`), :mod:`.writer`, and the names both use in :mod:`.names`.  The
reader and writer load on first use."""

from __future__ import annotations

from fuzzyctl.formats import Format, Loaded, Loss
from fuzzyctl.limits import MiB
from fuzzyctl.model import Document


def _read(text: str, path: str | None) -> Loaded:
    from fuzzyctl.formats.fis.reader import read

    return read(text, path)


def _write(document: Document) -> str:
    from fuzzyctl.formats.fis.writer import write

    return write(document)


def _adapt(document: Document) -> tuple[Document, list[Loss]]:
    from fuzzyctl.formats.fis.writer import adapt

    return adapt(document)


FORMAT = Format(
    name="fis",
    extensions=(".fis",),
    description="MATLAB / Octave Fuzzy Logic Toolbox FIS (and fuzzylite's FIS export)",
    read=_read,
    write=_write,
    adapt=_adapt,
    # FIS rules are dense (8 bytes each): 512 KiB is 65,000 rules (a 10,000-rule 4-input
    # FIS file is 191 KB, the largest real one 179 KB)
    max_bytes=MiB // 2,
)
