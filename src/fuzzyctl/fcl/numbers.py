"""How FCL files write numbers (shared by every text format's writer; no parser needed)."""

from __future__ import annotations

import math


def number_text(value: float) -> str:
    """A float written the way FCL files write numbers (``3``, ``0.5``, ``nan``, ``-inf``)."""
    if math.isnan(value):
        return "nan"
    if math.isinf(value):
        return "inf" if value > 0 else "-inf"
    if value == int(value) and abs(value) < 1e15:
        return str(int(value))
    return repr(value)
