"""The lookup-table block (:mod:`fuzzyctl.codegen.lookup`) in Structured Text and PLCopen
XML, and its test bench PROGRAM.  The block is the IR program of
:mod:`fuzzyctl.ir.programs.table_block`, printed by the ST renderers (REAL/LREAL:
:mod:`fuzzyctl.ir.render.st`; integers: :mod:`fuzzyctl.ir.render.fixed`)."""

from __future__ import annotations

import math
from typing import Any

from fuzzyctl.codegen.lookup import LookupReport, expected, header, sample_rows, table_block, tables
from fuzzyctl.codegen.testbench import st_bench_tail
from fuzzyctl.engine.plan import Plan
from fuzzyctl.engine.table import DEFAULT_MAX_BYTES, DEFAULT_TOLERANCE, Table
from fuzzyctl.ir.nodes import Decl, Program
from fuzzyctl.ir.programs.fixed_block import FixedDecl, FixedProgram
from fuzzyctl.ir.render.fixed import fixed_st_parts
from fuzzyctl.ir.render.st import STParts, format_st
from fuzzyctl.ir.render.st import st_parts as program_st_parts
from fuzzyctl.ir.state import CodegenError
from fuzzyctl.kinds import arith as arith_kinds
from fuzzyctl.kinds import targets
from fuzzyctl.model import Document, FunctionBlock


def st_parts(table: Table, dialect: str, lreal: bool, arith: str) -> STParts:
    """The FUNCTION_BLOCK of ``table`` as parts (for ST and PLCopen XML): its IR program
    (:func:`fuzzyctl.codegen.lookup.table_block`) printed by the ST renderer of its
    arithmetic, under the table's header."""
    record = targets.dialect(dialect)
    kind = arith_kinds.get(arith)
    real = record.real_type(not lreal)
    head = header(table, real, f"{record.label}, {'int' + str(table.bits) if table.bits else real}")
    block = table_block(table)
    if kind.integer:
        decls = [
            FixedDecl(
                d.name,
                {"value": "narrow"}.get(d.kind, d.kind),
                d.storage,
                comment=d.comment,
                size=d.size,
                values=None if d.init is None else tuple(int(v) for v in d.init),
            )
            for d in block.decls
        ]
        fixed = FixedProgram(block.name, kind, [], [], decls, block.body, list(head))
        return fixed_st_parts(fixed, record)
    types = {"value": "REAL", "wide": "REAL", "index": "DINT", "byte": "BYTE"}
    prog = Program(
        block.name,
        [Decl(d.name, types[d.kind], d.storage, d.size, d.init, d.comment) for d in block.decls],  # type: ignore[arg-type]
        block.body,
        list(head),
    )
    return program_st_parts(prog, dialect=record, lreal=lreal)


def _real_of(lreal: bool) -> str:
    return "LREAL" if lreal else "REAL"


def generate_lookup_st(
    model: Document | FunctionBlock | Plan,
    *,
    block: str | None = None,
    dialect: str = "codesys",
    lreal: bool = False,
    testbench: int = 0,
    arith: str = arith_kinds.DEFAULT,
    tolerance: float = DEFAULT_TOLERANCE,
    max_bytes: int = DEFAULT_MAX_BYTES,
    report: list[Any] | None = None,
    default: Any = None,
    **options: Any,
) -> str:
    """Structured Text: each function block as a lookup table (and its test bench)."""
    dialect = targets.dialect(dialect).name
    parts = []
    for plan, table in tables(
        model,
        block=block,
        real=_real_of(lreal),
        arith=arith,
        tolerance=tolerance,
        max_bytes=max_bytes,
        **options,
    ):
        if report is not None:
            report.append(LookupReport(table, _real_of(lreal)))
        parts.append(format_st(st_parts(table, dialect, lreal, arith), targets.dialect(dialect)))
        if testbench:
            parts.append(st_bench(plan, table, testbench, dialect, lreal))
    return "\n".join(parts)


def generate_lookup_plcopen(
    model: Document | FunctionBlock | Plan,
    *,
    block: str | None = None,
    dialect: str = "codesys",
    lreal: bool = False,
    arith: str = arith_kinds.DEFAULT,
    tolerance: float = DEFAULT_TOLERANCE,
    max_bytes: int = DEFAULT_MAX_BYTES,
    project: str | None = None,
    default: Any = None,
    **options: Any,
) -> str:
    """PLCopen TC6 XML: the blocks :func:`generate_lookup_st` writes."""
    from fuzzyctl import __version__
    from fuzzyctl.codegen.plcopen import check_dialect, render_plcopen

    check_dialect(dialect)
    dialect = targets.dialect(dialect).name
    parts = [
        st_parts(table, dialect, lreal, arith)
        for _plan, table in tables(
            model,
            block=block,
            real=_real_of(lreal),
            arith=arith,
            tolerance=tolerance,
            max_bytes=max_bytes,
            **options,
        )
    ]
    return render_plcopen(parts, project=project or parts[0].name, version=__version__)


def st_bench(plan: Plan, table: Table, n: int, dialect: str, lreal: bool) -> str:
    """A PROGRAM ``TB_<block>`` feeding the block ``n`` vectors, one per cycle, checking each
    output against the engine within the stated bound; ``PASS`` / ``FAIL_COUNT`` /
    ``FIRST_FAIL`` / ``DONE``."""
    record = targets.dialect(dialect)
    if not record.testbench:
        raise CodegenError(f"the test bench is not written for --dialect {dialect}")
    real = _real_of(lreal)
    rows = sample_rows(table, n)
    exp = expected(plan, rows, single=not lreal and not table.bits)
    fb = table.name or "FUZZY"
    prog = f"TB_{fb}"[:24].rstrip("_")
    record.identifiers.check(prog, "test bench name")
    lines = [
        record.comment(f"test bench of {fb}: {n} vectors, outputs within the stated bound of the engine")
    ]
    lines += [f"PROGRAM {prog}", "VAR_OUTPUT", "    PASS : BOOL := FALSE;", "    FAIL_COUNT : INT := 0;"]
    lines += [
        "    FIRST_FAIL : INT := 0;",
        "    DONE : BOOL := FALSE;",
        "END_VAR",
        "VAR",
        f"    TB_FB : {fb};",
    ]
    num = ("DINT" if table.bits == 32 else "INT") if table.bits else real

    def array(name: str, typ: str, values: list[str]) -> str:
        return f"    {name} : ARRAY[0..{n - 1}] OF {typ} := [{', '.join(values)}];"

    for i in range(len(table.inputs)):
        if table.bits:
            sc, off = table.in_scale[i]
            lines.append(array(f"TB_X{i}", num, [str(round((r[i] - off) / sc)) for r in rows]))
        else:
            lines.append(array(f"TB_X{i}", real, [record.real(r[i], parens=False) for r in rows]))
    for k in range(len(table.outputs)):
        if table.bits:  # stored units: |out - round(E)| <= bound / scale + 1/2
            sc, off = table.out_scale[k]
            lines.append(array(f"TB_Y{k}", "LINT", [str(round((e[k] - off) / sc)) for e in exp]))
            lines.append(f"    TB_TOL{k} : LINT := {math.ceil(table.bound[k] / sc + 0.5)};")
        else:
            lines.append(array(f"TB_Y{k}", real, [record.real(e[k], parens=False) for e in exp]))
            lines.append(
                f"    TB_TOL{k} : {real} := {record.real(table.bound[k] * (1 + 1e-6), parens=False)};"
            )
    lines += ["    TB_K : INT := 0;", "    TB_BAD : BOOL;", "END_VAR"]
    args = ", ".join(f"{name} := TB_X{i}[TB_K]" for i, name in enumerate(table.inputs))
    lines += ["IF NOT DONE THEN", f"    TB_FB({args});", "    TB_BAD := FALSE;"]
    for k, name in enumerate(table.outputs):
        got = f"{num}_TO_LINT(TB_FB.{name})" if table.bits else f"TB_FB.{name}"
        lines.append(f"    IF NOT (ABS({got} - TB_Y{k}[TB_K]) <= TB_TOL{k}) THEN")
        lines += ["        TB_BAD := TRUE;", "    END_IF;"]
    lines += st_bench_tail(n)
    return "\n".join(lines) + "\n"
