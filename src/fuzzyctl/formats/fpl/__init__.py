"""FPL of Siemens S7 Fuzzy Control (the Togai InfraLogic subset, Siemens manual 1.3):
:mod:`.reader` (with the lexer and parser in :mod:`.parse`), :mod:`.writer`, and the names
both use in :mod:`.names`.  The reader and writer load on first use."""

from __future__ import annotations

from fuzzyctl.formats import Format, Loaded, Loss
from fuzzyctl.formats.fpl.names import EXTENSIONS, NAME
from fuzzyctl.limits import MiB
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


FORMAT = Format(
    NAME,
    EXTENSIONS,
    "FPL of Siemens S7 Fuzzy Control (Togai InfraLogic subset, Siemens manual 1.3)",
    read=_read,
    write=_write,
    adapt=_adapt,
    # the largest project S7 Fuzzy Control allows (8 inputs of 7 terms, 4 outputs of 9, 200
    # rules; Siemens manual 1.3) is a 77 KB FPL file, 346 KB with 56 conditions a rule
    max_bytes=MiB,
)
