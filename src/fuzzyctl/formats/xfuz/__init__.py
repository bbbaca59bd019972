"""Schneider XFUZ knowledge-base tables (ESV/FA/RG and the block constants) as JSON or CSV
files: :mod:`.reader`, :mod:`.writer`, the names both use in :mod:`.names`, and the table
layout the XFUZ block shares in :mod:`.tables`.  The reader and writer load on first use."""

from __future__ import annotations

from fuzzyctl.formats import Format, Loaded, Loss
from fuzzyctl.formatspec import SPECS
from fuzzyctl.model import Document


def _read(text: str, path: str | None) -> Loaded:
    from fuzzyctl.formats.xfuz.reader import read

    return read(text, path)


def _write(document: Document) -> str:
    from fuzzyctl.formats.xfuz.writer import write_xfuz

    return write_xfuz(document)


def _adapt(document: Document) -> tuple[Document, list[Loss]]:
    from fuzzyctl.formats.xfuz.writer import adapt_xfuz

    adapted, losses = adapt_xfuz(document)
    return adapted, [Loss(element, reason) for element, reason in losses]


def _notes(document: Document) -> list[Loss]:
    from fuzzyctl.formats.xfuz.writer import notes

    return [Loss(element, reason) for element, reason in notes(document)]


FORMAT = Format.builtin(
    SPECS["xfuz"],
    read=_read,
    write=_write,
    adapt=_adapt,
    notes=_notes,
)
