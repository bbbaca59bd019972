"""The inference engine: IEC 61131-7 semantics, exact defuzzification, scalar and batch
evaluation, explanations.

Layers (each consumes the one above it):

* :mod:`~fuzzyctl.engine.shapes`, :mod:`~fuzzyctl.engine.operators` - the formulas, once.
* :mod:`~fuzzyctl.engine.lower` - FunctionBlock -> :class:`~fuzzyctl.engine.plan.Plan`.
* :mod:`~fuzzyctl.engine.interp` - the reference interpreter (the readable statement of the
  semantics; explanations).
* :mod:`~fuzzyctl.engine.fastprog` - the plan as one IR program (:mod:`~fuzzyctl.engine.ir`,
  rule evaluation from :mod:`~fuzzyctl.engine.irrules`), printed as straight-line Python
  (:mod:`~fuzzyctl.engine.render_py`), as numpy (:mod:`~fuzzyctl.engine.render_np`) and, by
  :mod:`fuzzyctl.codegen`, as the native backend's C.
* :mod:`~fuzzyctl.engine.controller` - the public :class:`Controller`.

Importing the package is cheap; numpy and the generators are imported when first used.
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Any

if TYPE_CHECKING:
    from fuzzyctl.engine.compile import COMPAT_PROFILES, compile_block
    from fuzzyctl.engine.controller import Controller
    from fuzzyctl.engine.explain import Explanation

__all__ = ["COMPAT_PROFILES", "Controller", "Explanation", "compile_block"]
_WHERE = {
    "COMPAT_PROFILES": "fuzzyctl.engine.compile",
    "compile_block": "fuzzyctl.engine.compile",
    "Controller": "fuzzyctl.engine.controller",
    "Explanation": "fuzzyctl.engine.explain",
}


def __getattr__(name: str) -> Any:
    if name in _WHERE:
        import importlib

        return getattr(importlib.import_module(_WHERE[name]), name)
    raise AttributeError(f"module 'fuzzyctl.engine' has no attribute {name!r}")
