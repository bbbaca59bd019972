"""MATLAB / Octave FIS files and fuzzylite's FIS export: :mod:`.reader` (with the rule
lines in :mod:`.rules`), :mod:`.writer`, and the names both use in :mod:`.names`.  The
reader and writer load on first use."""

from __future__ import annotations

from fuzzyctl.formats import Format, Loaded, Loss
from fuzzyctl.formatspec import SPECS
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


FORMAT = Format.builtin(
    SPECS["fis"],
    read=_read,
    write=_write,
    adapt=_adapt,
)
