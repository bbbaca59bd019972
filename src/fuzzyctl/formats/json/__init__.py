"""fuzzyctl's own JSON form of the model (lossless): :mod:`.reader`, :mod:`.writer`, and the
tags, version and schema both use in :mod:`.names`.  The reader and writer load on first
use."""

from __future__ import annotations

from fuzzyctl.formats import Format, Loaded
from fuzzyctl.formats.json.names import EXTENSIONS, NAME
from fuzzyctl.limits import DEFAULT_MAX_INPUT_BYTES
from fuzzyctl.model import Document
from fuzzyctl.validation import at_json_paths


def _read(text: str, path: str | None) -> Loaded:
    from fuzzyctl.formats.json.reader import read

    return read(text, path)


def _write(document: Document) -> str:
    from fuzzyctl.formats.json.writer import dumps

    return dumps(document)


FORMAT = Format(
    NAME,
    EXTENSIONS,
    "fuzzyctl model as JSON (lossless; schema in fuzzyctl/formats/json/fuzzyctl-model.schema.json)",
    read=_read,
    write=_write,
    place=at_json_paths,
    # JSON spells out every span (that 10,000-rule system is 43.5 MB) and is read by C
    max_bytes=12 * DEFAULT_MAX_INPUT_BYTES,
)
