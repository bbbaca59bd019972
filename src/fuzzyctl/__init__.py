"""fuzzyctl: IEC 61131-7 fuzzy control for PLC engineers.

The public entry points are :func:`fuzzyctl.load` and :func:`fuzzyctl.compile`; see
``fuzzyctl.api``.
"""

from fuzzyctl.api import compile, load, plot_terms

__version__ = "0.1.0"
__all__ = ["__version__", "compile", "load", "plot_terms"]
