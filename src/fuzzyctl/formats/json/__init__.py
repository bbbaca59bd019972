"""fuzzyctl's own JSON form of the model (lossless): :mod:`.reader`, :mod:`.writer`, and the
tags, version and schema both use in :mod:`.names`.  The reader and writer load on first
use."""

from __future__ import annotations

from fuzzyctl.formats import Format
from fuzzyctl.formatspec import SPECS
from fuzzyctl.validation import at_json_paths

FORMAT = Format.lazy(SPECS["json"], read="reader:read", write="writer:dumps", place=at_json_paths, type2=True)
