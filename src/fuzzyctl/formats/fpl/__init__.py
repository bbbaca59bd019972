"""FPL of Siemens S7 Fuzzy Control (the Togai InfraLogic subset, Siemens manual 1.3):
:mod:`.reader` (with the lexer and parser in :mod:`.parse`), :mod:`.writer`, and the names
both use in :mod:`.names`.  The reader and writer load on first use."""

from __future__ import annotations

from fuzzyctl.formats import Format, Loaded, Loss
from fuzzyctl.formatspec import SPECS
from fuzzyctl.model import Document


def _read(text: str, path: str | None) -> Loaded:
    from fuzzyctl.formats.fpl.reader import read

    return read(text, path)


def _write(document: Document) -> str:
    from fuzzyctl.formats.fpl.writer import write_fpl

    return write_fpl(document)


def _adapt(document: Document) -> tuple[Document, list[Loss]]:
    from fuzzyctl.formats.fpl.writer import adapt_fpl

    adapted, losses = adapt_fpl(document)
    return adapted, [Loss(element, reason) for element, reason in losses]


FORMAT = Format.builtin(
    SPECS["fpl"],
    read=_read,
    write=_write,
    adapt=_adapt,
)
