"""Values as JSON can carry them, for the studio's and the runtime's HTTP answers: NaN and
infinities become null (JSON has no such numbers), tuples become lists."""

from __future__ import annotations

import math
from typing import Any


def clean(obj: Any) -> Any:
    """``obj`` with every non-finite float replaced by None, in dicts, lists and tuples at
    any depth."""
    if isinstance(obj, float):
        return obj if math.isfinite(obj) else None
    if isinstance(obj, dict):
        return {k: clean(v) for k, v in obj.items()}
    if isinstance(obj, list | tuple):
        return [clean(v) for v in obj]
    return obj
