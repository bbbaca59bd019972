"""fuzzyctl: IEC 61131-7 fuzzy control for PLC engineers.

The public entry points are :func:`fuzzyctl.load` and :func:`fuzzyctl.compile`; see
``fuzzyctl.api``.  Importing the package is cheap: everything is imported when first used.
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Any

if TYPE_CHECKING:
    from fuzzyctl.api import compile, load

__version__ = "0.1.0"
__all__ = ["__version__", "compile", "load"]


def __getattr__(name: str) -> Any:
    if name in ("compile", "load"):
        from fuzzyctl import api

        return getattr(api, name)
    if not name.startswith("_"):  # a subpackage not imported yet (fuzzyctl.engine, ...)
        import importlib

        try:
            return importlib.import_module(f"fuzzyctl.{name}")
        except ModuleNotFoundError:
            pass
    raise AttributeError(f"module 'fuzzyctl' has no attribute {name!r}")
