"""fuzzyctl: IEC 61131-7 fuzzy control for PLC engineers.

The public entry points are :func:`fuzzyctl.load` and :func:`fuzzyctl.compile`; see
``fuzzyctl.api``.  ``fuzzyctl.tune(...)``, ``fuzzyctl.learn(...)`` and
``fuzzyctl.evaluate_dataframe(...)`` (docs/tune.md) are imported on first use.
"""

from typing import Any

from fuzzyctl.api import compile, load, plot_terms

__version__ = "0.1.0"
__all__ = ["__version__", "compile", "evaluate_dataframe", "learn", "load", "plot_terms", "tune"]


def __getattr__(name: str) -> Any:
    # Lazy: tuning pulls in scipy, cma and Dask, which plain evaluation does not need.
    if name in ("tune", "learn", "evaluate_dataframe"):
        import importlib

        module = importlib.import_module("fuzzyctl.tune")
        return module if name == "tune" else getattr(module, name)
    raise AttributeError(f"module 'fuzzyctl' has no attribute {name!r}")
