"""The inference engine: IEC 61131-7 semantics, exact defuzzification, scalar and batch
evaluation, explanations.

Layers, each importing only those before it (tests/test_layout.py keeps it so):

* :mod:`~fuzzyctl.engine.plan` - the lowered form, plain data every layer reads.
* :mod:`fuzzyctl.engine.semantics` - what the words mean: membership formulas, operators,
  function-term expressions, fuzzylite's rule activation, the C library as Java computes it.
* :mod:`fuzzyctl.engine.lowering` - FunctionBlock -> :class:`~fuzzyctl.engine.plan.Plan`,
  every decision the standard leaves open made once.
* :mod:`fuzzyctl.engine.reference` - the readable interpreter and exact defuzzifiers every
  other path is tested against (and explanations are read from).
* :mod:`fuzzyctl.engine.compat` - jFuzzyLogic 3.3 reproduced (``compat="jfuzzylogic"``).
* :mod:`fuzzyctl.ir` (a package of its own) - the plan as IR programs and their renderers.
* here, on top: :func:`~fuzzyctl.engine.compile.compile_block`, the public
  :class:`Controller`, the native backend (:mod:`~fuzzyctl.engine.native`), explanations.

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
