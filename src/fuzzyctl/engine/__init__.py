"""The inference engine: IEC 61131-7 semantics, exact defuzzification, scalar and batch
evaluation, explanations.

Layers (each consumes the one above it):

* :mod:`~fuzzyctl.engine.shapes`, :mod:`~fuzzyctl.engine.operators` - the formulas, once.
* :mod:`~fuzzyctl.engine.lower` - FunctionBlock -> :class:`~fuzzyctl.engine.plan.Plan`.
* :mod:`~fuzzyctl.engine.interp` (reference scalar interpreter, explanations),
  :mod:`~fuzzyctl.engine.specialise` (straight-line Python generated from the plan),
  :mod:`~fuzzyctl.engine.batch` (numpy) - the evaluators.
* :mod:`~fuzzyctl.engine.controller` - the public :class:`Controller`.
"""

from __future__ import annotations

from fuzzyctl.engine.compile import COMPAT_PROFILES, compile_block
from fuzzyctl.engine.controller import Controller
from fuzzyctl.engine.explain import Explanation

__all__ = ["COMPAT_PROFILES", "Controller", "Explanation", "compile_block"]
