"""MATLAB / Octave FIS files and fuzzylite's FIS export: :mod:`.reader` (with the rule
lines in :mod:`.rules`), :mod:`.writer`, and the names both use in :mod:`.names`.  The
reader and writer load on first use."""

from __future__ import annotations

from fuzzyctl.formats import Format
from fuzzyctl.formatspec import SPECS

# (through .type2: MATLAB's interval type-2 files; type-1 ones go on to .reader / .writer)
FORMAT = Format.lazy(SPECS["fis"], read="type2:read", write="type2:write", adapt="type2:adapt", type2=True)
