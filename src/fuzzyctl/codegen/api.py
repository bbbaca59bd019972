"""Entry points: model -> Structured Text or C source text."""

from __future__ import annotations

from typing import Any, Literal

from fuzzyctl.codegen.context import CodegenError
from fuzzyctl.codegen.program import build_program
from fuzzyctl.codegen.render_c import render_c
from fuzzyctl.codegen.render_st import render_st
from fuzzyctl.engine.plan import Plan
from fuzzyctl.model import Document, FunctionBlock

Dialect = Literal["codesys", "twincat", "scl", "iec", "openplc"]
DIALECTS: tuple[str, ...] = ("codesys", "twincat", "scl", "iec", "openplc")
#: Other names of a dialect: OpenPLC (and Beremiz) compile strict IEC 61131-3 with matiec.
DIALECT_ALIASES = {"openplc": "iec"}


def lower_block(model: Document | FunctionBlock, block: str | None = None, **options: Any) -> Plan:
    """The engine's plan of one function block (``compat=``/option keywords as for
    :func:`fuzzyctl.compile`); raises ``DiagnosticError`` for what the engine refuses."""
    from fuzzyctl.engine.compile import compile_block

    return compile_block(model, block=block, backend="interpreted", **options).plan


def _blocks(model: Document | FunctionBlock, block: str | None) -> list[str | None]:
    if isinstance(model, FunctionBlock) or block is not None:
        return [block]
    return [fb.name for fb in model.blocks]


def generate_st(
    model: Document | FunctionBlock,
    *,
    block: str | None = None,
    dialect: str = "codesys",
    lreal: bool = False,
    testbench: int = 0,
    **options: Any,
) -> str:
    """Structured Text for every function block of ``model`` (or just ``block``).

    ``dialect`` is ``codesys`` / ``twincat`` (IEC 61131-3 text both accept), ``iec`` (alias
    ``openplc``: strict IEC 61131-3 as matiec, the compiler of OpenPLC and Beremiz, accepts it)
    or ``scl`` (Siemens TIA Portal: ``#`` before block variables, ``REGION``, ``VERSION``); ``lreal``
    computes in LREAL instead of REAL; ``testbench`` > 0 adds after each block a PROGRAM that
    checks it on that many input vectors against the engine (:mod:`fuzzyctl.codegen.testbench`).
    Raises :class:`CodegenError` naming what cannot be expressed."""
    if dialect not in DIALECTS:
        raise CodegenError(f"unknown dialect {dialect!r} (known: {', '.join(DIALECTS)})")
    dialect = DIALECT_ALIASES.get(dialect, dialect)
    parts = []
    for name in _blocks(model, block):
        plan = lower_block(model, name, **options)
        parts.append(render_st(build_program(plan, "st"), dialect=dialect, lreal=lreal))
        if testbench:
            from fuzzyctl.codegen.testbench import choose, render_st_bench

            bench = choose(plan, testbench, single=not lreal)
            parts.append(render_st_bench(bench, dialect=dialect, lreal=lreal))
    return "\n".join(parts)


def generate_c(
    model: Document | FunctionBlock,
    *,
    block: str | None = None,
    single: bool = False,
    testbench: int = 0,
    **options: Any,
) -> dict[str, str]:
    """C99 files (``NAME.h``, ``NAME.c``) for every function block of ``model`` (or just
    ``block``); ``single`` computes in float instead of double; ``testbench`` > 0 adds
    ``NAME_testbench.c`` checking the block on that many input vectors against the engine."""
    files: dict[str, str] = {}
    for name in _blocks(model, block):
        plan = lower_block(model, name, **options)
        prog = build_program(plan, "c")
        header, source = render_c(prog, single=single)
        files[f"{prog.name}.h"] = header
        files[f"{prog.name}.c"] = source
        if testbench:
            from fuzzyctl.codegen.testbench import choose, render_c_bench

            bench = choose(plan, testbench, single=single)
            files[f"{prog.name}_testbench.c"] = render_c_bench(bench, single=single)
    return files
