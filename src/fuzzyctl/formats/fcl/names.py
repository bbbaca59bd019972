"""What the FCL reader and writer share: the FCL package they both call
(:mod:`fuzzyctl.fcl`, with ``load_text`` and ``write``), when it is installed."""

from __future__ import annotations

import importlib
import importlib.util
from typing import Any


def fcl_api() -> Any | None:
    """:mod:`fuzzyctl.fcl`, or None when this installation has no FCL reader and writer."""
    if importlib.util.find_spec("fuzzyctl.fcl") is None:
        return None
    module = importlib.import_module("fuzzyctl.fcl")
    if not (hasattr(module, "load_text") and hasattr(module, "write")):
        return None
    return module
