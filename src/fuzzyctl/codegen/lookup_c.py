"""The lookup-table block (:mod:`fuzzyctl.codegen.lookup`) in C99: ``NAME.h`` (the instance
struct, ``NAME_init``, ``NAME_step``) and ``NAME.c``, and its test bench ``NAME_testbench.c``
(``-DFUZZYCTL_TESTBENCH_MAIN`` makes it a program printing PASS or FAIL).  ``NAME_step`` is
the IR program of :mod:`fuzzyctl.ir.programs.table_block` printed by the IR's C printer."""

from __future__ import annotations

import math
from typing import Any

from fuzzyctl.codegen.lookup import LookupReport, expected, header, sample_rows, table_block, tables
from fuzzyctl.codegen.testbench import c_bench_driver
from fuzzyctl.engine.plan import Plan
from fuzzyctl.engine.table import DEFAULT_MAX_BYTES, DEFAULT_TOLERANCE, Table
from fuzzyctl.escape import c_ident
from fuzzyctl.ir.nodes import Call
from fuzzyctl.ir.programs.table_block import TableBlock
from fuzzyctl.ir.render.printer import Printer
from fuzzyctl.kinds import arith as arith_kinds
from fuzzyctl.kinds import targets


def _num(v: float) -> str:
    return repr(float(v)) if v >= 0 else f"({float(v)!r})"


class _CTable(Printer):
    """C99 statements of the table program: the block's inputs and outputs are the
    instance's fields, integer widening and narrowing are casts."""

    def __init__(self, block: TableBlock, real: str, num: str, wide: str, single: bool) -> None:
        super().__init__(targets.C, real=real, single=single)
        self.fields = {d.name for d in block.decls if d.storage in ("input", "output")}
        self.casts = {"WIDEN": wide, "NARROW": num}

    def name(self, n: str) -> str:
        return f"fb->{n}" if n in self.fields else n

    def call(self, e: Call) -> str:
        if e.function in self.casts:
            return f"(({self.casts[e.function]})({self.ex(e.args[0])}))"
        return super().call(e)


def c_files(table: Table, single: bool, arith: str) -> dict[str, str]:
    """``NAME.h`` and ``NAME.c`` of ``table``."""
    kind = arith_kinds.get(arith)
    name = c_ident(table.name or "FUZZY", "function block name")
    for v in table.inputs + table.outputs:
        c_ident(v, "variable")
    real = targets.C.real_type(single)
    num = kind.types["c"] if kind.integer else real
    wide = kind.wide_types["c"] if kind.integer else real
    com = targets.C.comment
    real_name = "REAL" if single else "LREAL"
    head = [com(line) for line in header(table, real_name, f"C99, {kind.name if kind.integer else real}")]
    guard = f"FUZZYCTL_LOOKUP_{name.upper()}_H"
    h = [*head, f"#ifndef {guard}", f"#define {guard}", ""]
    if kind.integer:
        h += ["#include <stdint.h>", ""]
    h += [f"typedef {num} {name}_real;", "", "typedef struct {"]
    h += [f"    {num} {v};" for v in table.inputs]
    h += [f"    {num} {v};" for v in table.outputs]
    h += [
        "    unsigned char INFO; /* always 0: rules fire everywhere in the input ranges */",
        f"}} {name};",
        "",
    ]
    h += [
        f"void {name}_init({name} *fb);",
        f"unsigned char {name}_step({name} *fb);",
        "",
        f"#endif /* {guard} */",
    ]
    axes = table.stored_axes() if kind.integer else table.axes
    vals = table.stored_values() if kind.integer else table.values

    def arr(values: Any) -> str:
        return (
            ", ".join(str(int(v)) for v in values)
            if kind.integer
            else ", ".join(_num(float(v)) for v in values)
        )

    c = [*head, f'#include "{name}.h"', ""]
    for i, a in enumerate(axes):
        c.append(f"static const {num} {name}_BP{i}[{len(a)}] = {{{arr(a)}}}; /* {table.inputs[i]} */")
    for k, entries in enumerate(vals):
        c.append(
            f"static const {num} {name}_TAB{k}[{entries.size}] = {{{arr(entries.ravel())}}}; "
            f"/* {table.outputs[k]} */"
        )
    c += ["", f"void {name}_init({name} *fb)", "{"]
    c += [f"    fb->{v} = 0;" for v in table.inputs + table.outputs]
    c += ["    fb->INFO = 0;", "}", "", f"unsigned char {name}_step({name} *fb)", "{"]
    arrays = ([f"{name}_BP{i}" for i in range(len(axes))], [f"{name}_TAB{k}" for k in range(len(vals))])
    block = table_block(table, arrays)
    types = {"value": num, "wide": wide, "index": "long"}
    c += [f"    {types[d.kind]} {d.name};" for d in block.decls if d.storage == "temp"]
    printer = _CTable(block, real, num, wide, single)
    printer.stmts(block.body, 1)
    c += printer.lines
    c += ["    return fb->INFO;", "}"]
    h_ext, c_ext = targets.C.extensions
    return {f"{name}{h_ext}": "\n".join(h) + "\n", f"{name}{c_ext}": "\n".join(c) + "\n"}


def c_bench(plan: Plan, table: Table, n: int, single: bool) -> str:
    """``int NAME_testbench(int *first_fail)`` returning FAIL_COUNT, and with
    ``-DFUZZYCTL_TESTBENCH_MAIN`` a ``main`` printing ``PASS``/``FAIL FAIL_COUNT=.. FIRST_FAIL=..``."""
    name = c_ident(table.name or "FUZZY", "function block name")
    rows = sample_rows(table, n)
    exp = expected(plan, rows, single=single and not table.bits)
    lines = [targets.C.comment(f"test bench of {name}: {n} vectors, outputs within the stated bound"), ""]
    lines += ["#include <stdio.h>", f'#include "{name}.h"', ""]
    for i in range(len(table.inputs)):
        if table.bits:
            sc, off = table.in_scale[i]
            vals = ", ".join(str(round((r[i] - off) / sc)) for r in rows)
            lines.append(f"static const long {name}_TB_X{i}[{n}] = {{{vals}}};")
        else:
            lines.append(
                f"static const double {name}_TB_X{i}[{n}] = {{{', '.join(_num(r[i]) for r in rows)}}};"
            )
    for k in range(len(table.outputs)):
        if table.bits:
            sc, off = table.out_scale[k]
            vals = ", ".join(str(round((e[k] - off) / sc)) for e in exp)
            lines.append(f"static const long {name}_TB_Y{k}[{n}] = {{{vals}}};")
            lines.append(f"static const long {name}_TB_TOL{k} = {math.ceil(table.bound[k] / sc + 0.5)};")
        else:
            lines.append(
                f"static const double {name}_TB_Y{k}[{n}] = {{{', '.join(_num(e[k]) for e in exp)}}};"
            )
            lines.append(f"static const double {name}_TB_TOL{k} = {_num(table.bound[k] * (1 + 1e-6))};")
    diff = "long" if table.bits else "double"
    body = [f"fb.{v} = ({name}_real){name}_TB_X{i}[k];" for i, v in enumerate(table.inputs)]
    body.append(f"bad = {name}_step(&fb) != 0;")
    for k, v in enumerate(table.outputs):
        body.append(f"d = ({diff})fb.{v} - {name}_TB_Y{k}[k];")
        body.append(f"if (!((d < 0 ? -d : d) <= {name}_TB_TOL{k})) bad = 1;")
    lines += c_bench_driver(name, n, diff, body)
    return "\n".join(lines) + "\n"


def generate_lookup_c(
    model: Any,
    *,
    block: str | None = None,
    single: bool = False,
    testbench: int = 0,
    arith: str = arith_kinds.DEFAULT,
    tolerance: float = DEFAULT_TOLERANCE,
    max_bytes: int = DEFAULT_MAX_BYTES,
    report: list[Any] | None = None,
    default: Any = None,
    **options: Any,
) -> dict[str, str]:
    """C99 files: each function block as a lookup table (and its test bench)."""
    real = "REAL" if single else "LREAL"
    files: dict[str, str] = {}
    for plan, table in tables(
        model, block=block, real=real, arith=arith, tolerance=tolerance, max_bytes=max_bytes, **options
    ):
        if report is not None:
            report.append(LookupReport(table, real))
        files.update(c_files(table, single, arith))
        if testbench:
            files[f"{table.name}_testbench.c"] = c_bench(plan, table, testbench, single)
    return files
