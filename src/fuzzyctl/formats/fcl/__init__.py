"""FCL (IEC 61131-7) in the format registry: :mod:`.reader` and :mod:`.writer` adapt
:mod:`fuzzyctl.fcl`'s parser and writer to it, :mod:`.names` is what both use.  The reader
and writer load on first use."""

from __future__ import annotations

from fuzzyctl.formats import Format, Loaded, Loss
from fuzzyctl.formats.fcl.names import fcl_api
from fuzzyctl.formatspec import SPECS
from fuzzyctl.model import Document


def _read(text: str, path: str | None) -> Loaded:
    from fuzzyctl.formats.fcl.reader import read

    return read(text, path)


def _write(document: Document) -> str:
    from fuzzyctl.formats.fcl.writer import write

    return write(document)


def _adapt(document: Document) -> tuple[Document, list[Loss]]:
    from fuzzyctl.formats.fcl.writer import adapt

    return adapt(document)


def _notes(document: Document) -> list[Loss]:
    from fuzzyctl.formats.fcl.writer import notes

    return notes(document)


_available = fcl_api() is not None
FORMAT = Format.builtin(
    SPECS["fcl"],
    read=_read if _available else None,
    write=_write if _available else None,
    adapt=_adapt,
    notes=_notes,
    validates=True,
)
