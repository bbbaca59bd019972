"""fuzzylite language (FLL) files: :mod:`.reader` (with the rule lines in :mod:`.rules`),
:mod:`.writer`, and the names both use in :mod:`.names`.  The reader and writer load on
first use."""

from __future__ import annotations

from fuzzyctl.formats import Format, on_use
from fuzzyctl.formatspec import SPECS

_read = on_use("fuzzyctl.formats.fll.reader", "read")
_write = on_use("fuzzyctl.formats.fll.writer", "write")
_adapt = on_use("fuzzyctl.formats.fll.writer", "adapt")

FORMAT = Format.builtin(
    SPECS["fll"],
    read=_read,
    write=_write,
    adapt=_adapt,
)
