"""fuzzylite language (FLL) files: :mod:`.reader` (with the rule lines in :mod:`.rules`),
:mod:`.writer`, and the names both use in :mod:`.names`.  The reader and writer load on
first use."""

from __future__ import annotations

from fuzzyctl.formats import Format, Loaded, Loss
from fuzzyctl.formatspec import SPECS
from fuzzyctl.model import Document


def _read(text: str, path: str | None) -> Loaded:
    from fuzzyctl.formats.fll.reader import read

    return read(text, path)


def _write(document: Document) -> str:
    from fuzzyctl.formats.fll.writer import write

    return write(document)


def _adapt(document: Document) -> tuple[Document, list[Loss]]:
    from fuzzyctl.formats.fll.writer import adapt

    return adapt(document)


FORMAT = Format.builtin(
    SPECS["fll"],
    read=_read,
    write=_write,
    adapt=_adapt,
)
