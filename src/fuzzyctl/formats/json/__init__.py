"""fuzzyctl's own JSON form of the model (lossless): :mod:`.reader`, :mod:`.writer`, and the
tags, version and schema both use in :mod:`.names`.  The reader and writer load on first
use."""

from __future__ import annotations

from fuzzyctl.formats import Format, on_use
from fuzzyctl.formatspec import SPECS
from fuzzyctl.validation import at_json_paths

_read = on_use("fuzzyctl.formats.json.reader", "read")
_write = on_use("fuzzyctl.formats.json.writer", "dumps")

FORMAT = Format.builtin(
    SPECS["json"],
    read=_read,
    write=_write,
    place=at_json_paths,
    type2=True,
)
