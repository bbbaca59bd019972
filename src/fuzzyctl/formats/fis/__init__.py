"""MATLAB / Octave FIS files and fuzzylite's FIS export: :mod:`.reader` (with the rule
lines in :mod:`.rules`), :mod:`.writer`, and the names both use in :mod:`.names`.  The
reader and writer load on first use."""

from __future__ import annotations

from fuzzyctl.formats import Format, on_use
from fuzzyctl.formatspec import SPECS

# (through .type2: MATLAB's interval type-2 files; type-1 ones go on to .reader / .writer)
_read = on_use("fuzzyctl.formats.fis.type2", "read")
_write = on_use("fuzzyctl.formats.fis.type2", "write")
_adapt = on_use("fuzzyctl.formats.fis.type2", "adapt")

FORMAT = Format.builtin(
    SPECS["fis"],
    read=_read,
    write=_write,
    adapt=_adapt,
    type2=True,
)
