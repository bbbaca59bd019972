"""FCL (IEC 61131-7) in the format registry: :mod:`.reader` and :mod:`.writer` adapt
:mod:`fuzzyctl.fcl`'s parser and writer to it, :mod:`.names` is what both use.  The reader
and writer load on first use."""

from __future__ import annotations

from fuzzyctl.formats import Format, on_use
from fuzzyctl.formats.fcl.names import fcl_api
from fuzzyctl.formatspec import SPECS

_read = on_use("fuzzyctl.formats.fcl.reader", "read")
# (through .type2: interval type-2 terms, docs/fcl.md; type-1 models as .writer writes them)
_write = on_use("fuzzyctl.formats.fcl.type2", "write")
_adapt = on_use("fuzzyctl.formats.fcl.type2", "adapt")
_notes = on_use("fuzzyctl.formats.fcl.writer", "notes")

_available = fcl_api() is not None
FORMAT = Format.builtin(
    SPECS["fcl"],
    read=_read if _available else None,
    write=_write if _available else None,
    adapt=_adapt,
    notes=_notes,
    validates=True,
    type2=True,
)
