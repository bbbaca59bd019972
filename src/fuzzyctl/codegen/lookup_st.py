"""The lookup-table block (:mod:`fuzzyctl.codegen.lookup`) in Structured Text and PLCopen
XML, and its test bench PROGRAM."""

from __future__ import annotations

import math
from typing import Any

from fuzzyctl.codegen.lookup import (
    LookupReport,
    expected,
    header,
    interpolation,
    lerp_text,
    sample_rows,
    tables,
)
from fuzzyctl.codegen.testbench import st_bench_tail
from fuzzyctl.engine.plan import Plan
from fuzzyctl.engine.table import DEFAULT_MAX_BYTES, DEFAULT_TOLERANCE, Table
from fuzzyctl.ir.render.st import STParts, STSection, STVar, format_st
from fuzzyctl.ir.state import CodegenError
from fuzzyctl.kinds import arith as arith_kinds
from fuzzyctl.kinds import targets
from fuzzyctl.model import Document, FunctionBlock

#: the block's own names (inputs and outputs are the model's; these cannot clash with them
#: since model names are checked identifiers without this prefix's double meaning)
_P = "LK_"


def _names(table: Table) -> tuple[list[str], list[str]]:
    return [f"BP_{n}" for n in table.inputs], [f"TAB_{n}" for n in table.outputs]


def st_parts(table: Table, dialect: str, lreal: bool, arith: str) -> STParts:
    """The FUNCTION_BLOCK of ``table`` as parts (for ST and PLCopen XML)."""
    record = targets.dialect(dialect)
    check = record.identifiers.check
    kind = arith_kinds.get(arith)
    real = record.real_type(not lreal)
    num = kind.types["st"] if kind.integer else real
    wide = kind.wide_types["st"] if kind.integer else real
    bps, tabs = _names(table)
    check(table.name or "FUZZY", "function block name")
    for name in (*table.inputs, *table.outputs, *bps, *tabs):
        check(name, "variable")
    p = record.var_prefix

    def lit(v: float) -> str:
        return record.real(v, parens=False)

    def arr(values: Any) -> tuple[str, ...]:
        return tuple(str(int(v)) for v in values) if kind.integer else tuple(lit(float(v)) for v in values)

    axes = table.stored_axes() if kind.integer else table.axes
    vals = table.stored_values() if kind.integer else table.values
    d = len(table.axes)
    inputs = STSection("VAR_INPUT", "", tuple(STVar(n, num, None, None, "") for n in table.inputs))
    outputs = STSection(
        "VAR_OUTPUT",
        "",
        (
            *(STVar(n, num, None, None, "") for n in table.outputs),
            STVar("INFO", "BYTE", None, None, "always 16#00: rules fire everywhere in the input ranges"),
        ),
    )
    consts = [
        STVar(b, num, len(a), arr(a), f"breakpoints of {n}")
        for b, a, n in zip(bps, axes, table.inputs, strict=True)
    ]
    consts += [
        STVar(t, num, v.size, arr(v.ravel()), f"{n} at the breakpoints (last input fastest)")
        for t, v, n in zip(tabs, vals, table.outputs, strict=True)
    ]
    temps = [STVar(f"{_P}{w}", "DINT", None, None, "") for w in ("LO", "HI", "MID", "K")]
    temps += [STVar(f"{_P}X{i}", num, None, None, "") for i in range(d)]
    temps += [STVar(f"{_P}I{i}", "DINT", None, None, "") for i in range(d)]
    if kind.integer:
        temps += [STVar(f"{_P}{w}{i}", wide, None, None, "") for i in range(d) for w in ("D", "W")]
    else:
        temps += [STVar(f"{_P}F{i}", real, None, None, "") for i in range(d)]
    body = ["    (* each input limited to its range; its interval found by binary search *)"]
    for i, (name, bp) in enumerate(zip(table.inputs, bps, strict=True)):
        body += _interval(p, i, name, bp, len(table.axes[i]), f"{num}_TO_{wide}" if kind.integer else None)
    strides = [math.prod(table.shape[i + 1 :]) for i in range(d)]
    body.append(f"    {p}{_P}K := " + " + ".join(f"{p}{_P}I{i} * {s}" for i, s in enumerate(strides)) + ";")
    for name, tab in zip(table.outputs, tabs, strict=True):
        body.append(f"    (* {name}: the cell's corners interpolated, last input first *)")

        def read(off: int, tab: str = tab) -> str:
            at = f"{p}{tab}[{p}{_P}K + {off}]" if off else f"{p}{tab}[{p}{_P}K]"
            return f"{num}_TO_{wide}({at})" if kind.integer else at

        def lerp(a: str, b: str, axis: int) -> str:
            if kind.integer:
                return lerp_text(a, b, f"{p}{_P}D{axis}", f"{p}{_P}W{axis}")
            return lerp_text(a, b, f"{p}{_P}F{axis}")

        steps, final = interpolation(table.shape, read, lerp, lambda s: f"{p}{_P}V{s}")
        for tmp, expr in steps:
            decl = tmp[len(p) :]
            if all(t.name != decl for t in temps):
                temps.append(STVar(decl, wide, None, None, ""))
            body.append(f"    {tmp} := {expr};")
        body.append(
            f"    {p}{name} := {wide}_TO_{num}({final});" if kind.integer else f"    {p}{name} := {final};"
        )
    body.append(f"    {p}INFO := 0;")
    for t in temps:
        check(t.name, "identifier")
    return STParts(
        table.name or "FUZZY",
        record.name,
        real,
        tuple(header(table, real, f"{record.label}, {'int' + str(table.bits) if table.bits else real}")),
        (inputs, outputs, STSection("VAR", "", tuple(consts)), STSection("VAR_TEMP", "", tuple(temps))),
        tuple(body),
    )


def _interval(p: str, i: int, name: str, bp: str, n: int, widen: str | None) -> list[str]:
    """Input ``i`` limited to its breakpoints, its interval by binary search, and its
    fraction across it (REAL) or its offset and the interval's width (integers, widened)."""
    x, lo, hi, mid = f"{p}{_P}X{i}", f"{p}{_P}LO", f"{p}{_P}HI", f"{p}{_P}MID"
    lines = [
        f"    {x} := {p}{name};",
        f"    IF {x} < {p}{bp}[0] THEN {x} := {p}{bp}[0]; END_IF;",
        f"    IF {x} > {p}{bp}[{n - 1}] THEN {x} := {p}{bp}[{n - 1}]; END_IF;",
        f"    {lo} := 0;",
        f"    {hi} := {n - 1};",
        f"    WHILE {hi} - {lo} > 1 DO",
        f"        {mid} := ({lo} + {hi}) / 2;",
        f"        IF {p}{bp}[{mid}] <= {x} THEN {lo} := {mid}; ELSE {hi} := {mid}; END_IF;",
        "    END_WHILE;",
        f"    {p}{_P}I{i} := {lo};",
    ]
    if widen is not None:
        return [
            *lines,
            f"    {p}{_P}D{i} := {widen}({x} - {p}{bp}[{lo}]);",
            f"    {p}{_P}W{i} := {widen}({p}{bp}[{lo} + 1] - {p}{bp}[{lo}]);",
        ]
    return [*lines, f"    {p}{_P}F{i} := ({x} - {p}{bp}[{lo}]) / ({p}{bp}[{lo} + 1] - {p}{bp}[{lo}]);"]


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
        parts.append(format_st(st_parts(table, dialect, lreal, arith)))
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
