"""Code generation from the lowered plan: IEC 61131-3 Structured Text for PLCs, PLCopen XML,
C99 for embedded targets, and what goes with them (test benches, renaming, DEFAULT choices).

* :func:`generate_st` - one FUNCTION_BLOCK per FCL function block (CODESYS, TwinCAT, SCL).
* :func:`generate_plcopen` - the same blocks as PLCopen TC6 XML 2.01 (one project).
* :func:`generate_c` - a header and a source file per function block.

Everything is generated from :class:`~fuzzyctl.engine.plan.Plan` through target-neutral
programs in one IR (:mod:`fuzzyctl.ir`: the PLC block :mod:`fuzzyctl.ir.programs.plc_block`,
printed by :mod:`fuzzyctl.ir.render`; the native backend of ``compile()`` is
:mod:`fuzzyctl.engine.native`), so they agree with the engine by construction
and the tests check that they do.  Importing the package is cheap (the generators load on
first use).
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Any

if TYPE_CHECKING:
    from fuzzyctl.codegen.api import generate_c, generate_st, lower_block
    from fuzzyctl.codegen.plcopen import generate_plcopen
    from fuzzyctl.ir.state import CodegenError

__all__ = ["CodegenError", "generate_c", "generate_plcopen", "generate_st", "lower_block"]


def __getattr__(name: str) -> Any:
    if name == "CodegenError":
        from fuzzyctl.ir.state import CodegenError

        return CodegenError
    if name == "generate_plcopen":
        from fuzzyctl.codegen import plcopen

        return plcopen.generate_plcopen
    if name in ("generate_c", "generate_st", "lower_block"):
        from fuzzyctl.codegen import api

        return getattr(api, name)
    raise AttributeError(f"module 'fuzzyctl.codegen' has no attribute {name!r}")
