"""FPL of Siemens S7 Fuzzy Control (the Togai InfraLogic subset, Siemens manual 1.3):
:mod:`.reader` (with the lexer and parser in :mod:`.parse`), :mod:`.writer`, and the names
both use in :mod:`.names`.  The reader and writer load on first use."""

from __future__ import annotations

from fuzzyctl.formats import Format, losses_of, on_use
from fuzzyctl.formatspec import SPECS

FORMAT = Format.lazy(
    SPECS["fpl"],
    read="reader:read",
    write="writer:write_fpl",
    adapt=losses_of(on_use("fuzzyctl.formats.fpl.writer", "adapt_fpl")),
)
