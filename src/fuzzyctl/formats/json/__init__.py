"""fuzzyctl's own JSON form of the model (lossless): :mod:`.reader`, :mod:`.writer`, and the
tags, version and schema both use in :mod:`.names`.  The reader and writer load on first
use."""

from __future__ import annotations

from fuzzyctl.formats import Format, Loaded
from fuzzyctl.formatspec import SPECS
from fuzzyctl.model import Document
from fuzzyctl.validation import at_json_paths


def _read(text: str, path: str | None) -> Loaded:
    from fuzzyctl.formats.json.reader import read

    return read(text, path)


def _write(document: Document) -> str:
    from fuzzyctl.formats.json.writer import dumps

    return dumps(document)


FORMAT = Format.builtin(
    SPECS["json"],
    read=_read,
    write=_write,
    place=at_json_paths,
)
