"""fuzzyctl: IEC 61131-7 fuzzy control for PLC engineers.

The public entry points are :func:`fuzzyctl.load` and :func:`fuzzyctl.compile`; see
``fuzzyctl.api``; :func:`fuzzyctl.analyze` checks a rule base (docs/analyze.md).
``fuzzyctl.tune(...)``, ``fuzzyctl.learn(...)`` and
``fuzzyctl.evaluate_dataframe(...)`` (docs/tune.md) are imported on first use.  Importing the
package is cheap: everything is imported when first used (the start of a command matters).
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Any

if TYPE_CHECKING:
    from fuzzyctl.analysis import analyze
    from fuzzyctl.api import compile, load, plot_terms

__version__ = "0.1.0"
__all__ = ["__version__", "analyze", "compile", "evaluate_dataframe", "learn", "load", "plot_terms", "tune"]


def __dir__() -> list[str]:
    """The lazy names too, so that ``dir(fuzzyctl)`` and tab completion show them."""
    return sorted({*__all__, *(n for n in globals() if n.startswith("__"))})


def __getattr__(name: str) -> Any:
    import importlib

    if name == "analyze":  # static analysis of a rule base (docs/analyze.md)
        return importlib.import_module("fuzzyctl.analysis").analyze
    if name in ("compile", "load", "plot_terms"):
        return getattr(importlib.import_module("fuzzyctl.api"), name)
    # Lazy: tuning pulls in scipy, cma and Dask, which plain evaluation does not need.
    if name in ("tune", "learn", "evaluate_dataframe"):
        module = importlib.import_module("fuzzyctl.tune")
        return module if name == "tune" else getattr(module, name)
    if not name.startswith("_"):  # a subpackage not imported yet (fuzzyctl.engine, ...)
        try:
            return importlib.import_module(f"fuzzyctl.{name}")
        except ModuleNotFoundError as exc:
            if exc.name != f"fuzzyctl.{name}":  # the module is there, a dependency is not:
                raise  # its message names the extra to install (fuzzyctl.control)
    raise AttributeError(f"module 'fuzzyctl' has no attribute {name!r}")


def _rich_display() -> None:
    # In a Jupyter kernel: controllers, variables, explanations and analyses display as HTML
    # (fuzzyctl.display; cheap: registered by name, nothing imported until shown).
    import sys

    if "IPython" in sys.modules:
        from fuzzyctl.display import register

        register()


_rich_display()
