"""fuzzylite language (FLL) files: :mod:`.reader` (with the rule lines in :mod:`.rules`),
:mod:`.writer`, and the names both use in :mod:`.names`.  The reader and writer load on
first use."""

from __future__ import annotations

from fuzzyctl.formats import Format
from fuzzyctl.formatspec import SPECS

FORMAT = Format.lazy(SPECS["fll"], read="reader:read", write="writer:write", adapt="writer:adapt")
