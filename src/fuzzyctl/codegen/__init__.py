"""Code generation from the lowered plan: IEC 61131-3 Structured Text for PLCs, C99 for
embedded targets, and the native evaluation backend built on the C.

* :func:`generate_st` - one FUNCTION_BLOCK per FCL function block (CODESYS, TwinCAT, SCL).
* :func:`generate_c` - a header and a source file per function block.
* :mod:`fuzzyctl.codegen.native` - ``compile(model, backend="native")``.

Everything is generated from :class:`~fuzzyctl.engine.plan.Plan` through one target-neutral
program (:mod:`fuzzyctl.codegen.program`), so the three agree with the engine by
construction and the tests check that they do.
"""

from __future__ import annotations

from fuzzyctl.codegen.api import generate_c, generate_st, lower_block
from fuzzyctl.codegen.context import CodegenError

__all__ = ["CodegenError", "generate_c", "generate_st", "lower_block"]
