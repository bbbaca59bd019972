"""Schneider XFUZ knowledge-base tables (ESV/FA/RG and the block constants) as JSON or CSV
files: :mod:`.reader`, :mod:`.writer`, the names both use in :mod:`.names`, and the table
layout the XFUZ block shares in :mod:`.tables`.  The reader and writer load on first use."""

from __future__ import annotations

from fuzzyctl.formats import Format, Loss, losses_of, on_use
from fuzzyctl.formatspec import SPECS
from fuzzyctl.model import Document


def _notes(document: Document) -> list[Loss]:
    from fuzzyctl.formats.xfuz.writer import notes

    return [Loss(element, reason) for element, reason in notes(document)]


FORMAT = Format.lazy(
    SPECS["xfuz"],
    read="reader:read",
    write="writer:write_xfuz",
    adapt=losses_of(on_use("fuzzyctl.formats.xfuz.writer", "adapt_xfuz")),
    notes=_notes,
)
