"""Print a :class:`~fuzzyctl.ir.nodes.Program` as an IEC 61131-3 Structured Text
FUNCTION_BLOCK in the portable subset: REAL (or LREAL), arrays with literal bounds, FOR loops
over INT counters, IF instead of MIN/MAX/LIMIT, no ``**``, ``(* *)`` comments, upper-case
keywords, identifiers of at most 24 characters checked against the reserved words of IEC,
TwinCAT and SCL.  ``dialect="scl"`` adds Siemens TIA Portal conventions: ``#`` before block
variables, ``REGION``, ``VERSION`` and ``BEGIN``.  ``dialect="iec"`` (OpenPLC, Beremiz: the
matiec compiler) writes FOR loops as WHILE loops, since matiec runs ``FOR i := a TO a`` zero
times.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass

from fuzzyctl.escape import st_comment, st_ident, st_ident_iec
from fuzzyctl.ir.nodes import (
    Assign,
    Bin,
    Bool,
    Call,
    Comment,
    Decl,
    Ex,
    For,
    If,
    Index,
    Int,
    Neg,
    Not,
    Num,
    Program,
    Region,
    Stmt,
    Var,
    While,
)
from fuzzyctl.ir.state import CodegenError

_PREC = {"OR": 0, "AND": 1, "=": 2, "<>": 2, "<": 3, "<=": 3, ">": 3, ">=": 3, "+": 4, "-": 4, "*": 5, "/": 5}
#: IEC 61131-3 standard functions (Table 22/23) the program may call.
_FUNCS = {"EXP", "LN", "LOG", "SQRT", "ABS", "SIN", "COS", "TAN", "ASIN", "ACOS", "ATAN"}


def st_real(v: float) -> str:
    """A REAL literal with the decimal point IEC requires (``1.0E-5``, never ``1e-05``)."""
    if not math.isfinite(v):
        raise CodegenError(f"the value {v} cannot be written in portable Structured Text")
    s = repr(float(v)).upper()
    mant, _, exp = s.partition("E")
    if "." not in mant:
        mant += ".0"
    return mant + ("E" + exp if exp else "")


class _ST:
    def __init__(self, prog: Program, dialect: str, lreal: bool) -> None:
        self.prog = prog
        self.scl = dialect == "scl"
        self.iec = dialect == "iec"
        self.real = "LREAL" if lreal else "REAL"
        self.lines: list[str] = []

    def name(self, n: str) -> str:
        return f"#{n}" if self.scl else n

    def num(self, v: float) -> str:
        s = st_real(v)
        return f"({s})" if v < 0 else s

    def ex(self, e: Ex, parent: int = -1, right: bool = False) -> str:
        if isinstance(e, Num):
            return self.num(e.value)
        if isinstance(e, Int):
            return str(e.value) if e.value >= 0 else f"({e.value})"
        if isinstance(e, Bool):
            return "TRUE" if e.value else "FALSE"
        if isinstance(e, Var):
            return self.name(e.name)
        if isinstance(e, Index):
            return f"{self.name(e.name)}[{self.ex(e.index)}]"
        if isinstance(e, Neg):
            return f"-{self.ex(e.operand, 6)}"
        if isinstance(e, Not):
            return f"NOT {self.ex(e.operand, 6)}"
        if isinstance(e, Call):
            if e.function == "TO_REAL":
                return f"INT_TO_{self.real}({self.ex(e.args[0])})"
            if e.function not in _FUNCS:
                raise CodegenError(f"function {e.function} has no portable Structured Text equivalent")
            return f"{e.function}({', '.join(self.ex(a) for a in e.args)})"
        assert isinstance(e, Bin)
        p = _PREC[e.op]
        s = f"{self.ex(e.left, p)} {e.op} {self.ex(e.right, p, True)}"
        return f"({s})" if p < parent or (right and p == parent) else s

    def emit(self, s: str, ind: int) -> None:
        self.lines.append("    " * ind + s)

    def stmts(self, body: Sequence[Stmt], ind: int) -> None:
        for s in body:
            if isinstance(s, Assign):
                self.emit(f"{self.ex(s.target)} := {self.ex(s.value)};", ind)
            elif isinstance(s, Comment):
                self.emit(_comment(s.text), ind)
            elif isinstance(s, Region):
                if self.scl:
                    self.emit(f"REGION {st_comment(s.name)}", ind)  # the title runs to the line's end
                    self.stmts(s.body, ind + 1)
                    self.emit("END_REGION", ind)
                else:
                    self.emit(_comment(f"---- {s.name}"), ind)
                    self.stmts(s.body, ind)
            elif isinstance(s, If):
                for k, (cond, b) in enumerate(s.branches):
                    self.emit(f"{'IF' if k == 0 else 'ELSIF'} {self.ex(cond)} THEN", ind)
                    self.stmts(b, ind + 1) if b else self.emit(";", ind + 1)
                if s.orelse:
                    self.emit("ELSE", ind)
                    self.stmts(s.orelse, ind + 1)
                self.emit("END_IF;", ind)
            elif isinstance(s, For) and self.iec:
                # matiec (OpenPLC) runs FOR i := a TO a zero times: the same loop as WHILE
                var, step = self.name(s.var), "+" if s.step == 1 else "-"
                self.emit(f"{var} := {self.ex(s.start)};", ind)
                self.emit(f"WHILE {var} {'<=' if s.step == 1 else '>='} {self.ex(s.stop, 3)} DO", ind)
                self.stmts(s.body, ind + 1)
                self.emit(f"{var} := {var} {step} 1;", ind + 1)
                self.emit("END_WHILE;", ind)
            elif isinstance(s, For):
                by = "" if s.step == 1 else " BY -1"
                self.emit(f"FOR {self.name(s.var)} := {self.ex(s.start)} TO {self.ex(s.stop)}{by} DO", ind)
                self.stmts(s.body, ind + 1) if s.body else self.emit(";", ind + 1)
                self.emit("END_FOR;", ind)
            elif isinstance(s, While):
                self.emit(f"WHILE {self.ex(s.cond)} DO", ind)
                self.stmts(s.body, ind + 1)
                self.emit("END_WHILE;", ind)


def _comment(text: str) -> str:
    """An ST comment: every comment of the generated block is made here, from model text
    escaped by :func:`fuzzyctl.escape.st_comment`."""
    return f"(* {st_comment(text)} *)"


def _init_values(d: Decl) -> tuple[str, ...] | None:
    """The initial value of ``d`` as ST literals (one for a scalar, one per element of an
    array); None when the declaration has none."""

    def one(v: float | bool) -> str:
        if d.type == "BOOL":
            return "TRUE" if v else "FALSE"
        if d.type in ("INT", "DINT", "BYTE"):
            return str(int(v))
        return st_real(float(v))

    if d.init is None:
        return None
    if isinstance(d.init, tuple):
        if d.storage != "param" and not any(d.init):
            # IEC 61131-3 initialises to 0 / FALSE anyway; long literal lists cost PLC
            # editors (and Earley parsers) dearly.  Parameters stay explicit for the tuner.
            return None
        return tuple(one(v) for v in d.init)
    return (one(d.init),)


@dataclass(frozen=True)
class STVar:
    """One declared variable: ``name : [ARRAY[0..size-1] OF] base [:= init];``."""

    name: str
    base: str  # elementary type as written: REAL/LREAL (by precision), INT, DINT, BOOL, BYTE
    size: int | None  # None: a scalar
    init: tuple[str, ...] | None  # ST literals (one for a scalar); None: no initial value
    comment: str  # the model's text, unescaped ("" for none; may hold newlines for arrays)

    @property
    def type(self) -> str:
        return f"ARRAY[0..{self.size - 1}] OF {self.base}" if self.size is not None else self.base

    @property
    def declaration(self) -> str:
        """``name : TYPE := init`` (no semicolon, no comment)."""
        if self.init is None:
            return f"{self.name} : {self.type}"
        value = f"[{', '.join(self.init)}]" if self.size is not None else self.init[0]
        return f"{self.name} : {self.type} := {value}"


@dataclass(frozen=True)
class STSection:
    keyword: str  # VAR_INPUT, VAR_OUTPUT, VAR, VAR_TEMP
    title: str  # the comment under the keyword ("" for none), unescaped
    variables: tuple[STVar, ...]


@dataclass(frozen=True)
class STParts:
    """A FUNCTION_BLOCK as parts (for :func:`render_st` and the PLCopen XML writer): the
    names are checked identifiers, the comment texts are the model's (escape them per target),
    the body is the statement lines exactly as ``render_st`` prints them."""

    name: str
    dialect: str
    real: str  # REAL or LREAL
    header: tuple[str, ...]  # comment lines above the block
    sections: tuple[STSection, ...]  # only the non-empty ones, in order
    body: tuple[str, ...]


def st_parts(prog: Program, *, dialect: str = "codesys", lreal: bool = False) -> STParts:
    """The declarations and statements of one FUNCTION_BLOCK, before formatting."""
    check = st_ident_iec if dialect == "iec" else st_ident
    check(prog.name, "function block name")
    for d in prog.decls:
        check(d.name, "variable" if d.storage in ("input", "output") else "identifier")
    r = _ST(prog, dialect, lreal)
    r.stmts(prog.body, 1 if r.scl else 0)

    def var(d: Decl) -> STVar:
        base = {"REAL": r.real, "INT": "INT", "DINT": "DINT", "BOOL": "BOOL", "BYTE": "BYTE"}[d.type]
        return STVar(d.name, base, d.size, _init_values(d), d.comment or "")

    # matiec (OpenPLC, Beremiz) turns a VAR_TEMP array without initial value into C that does
    # not compile, and IEC 61131-3 allows no initial value there: outside SCL the scratch
    # arrays live in the instance (written before read on every call, like the temporaries).
    scratch = [] if r.scl else [d for d in prog.of("temp") if d.size is not None]
    groups = (
        ("VAR_INPUT", prog.of("input"), ""),
        ("VAR_OUTPUT", prog.of("output"), ""),
        ("VAR", prog.of("param"), "tunable parameters: may be changed online"),
        ("VAR", prog.of("state") + prog.of("const"), "internal state and tables: do not change"),
        ("VAR", scratch, "scratch arrays of one call (no initial value needed)"),
        ("VAR_TEMP", [d for d in prog.of("temp") if d not in scratch], ""),
    )
    sections = tuple(STSection(kw, title, tuple(var(d) for d in ds)) for kw, ds, title in groups if ds)
    header = (*prog.header, f"dialect: {dialect}; arithmetic in {r.real}")
    return STParts(prog.name, dialect, r.real, header, sections, tuple(r.lines))


def render_st(prog: Program, *, dialect: str = "codesys", lreal: bool = False) -> str:
    """One FUNCTION_BLOCK."""
    return format_st(st_parts(prog, dialect=dialect, lreal=lreal))


def format_st(parts: STParts) -> str:
    """The text of a FUNCTION_BLOCK from its parts: header comments, ``FUNCTION_BLOCK``,
    the sections, the body lines, ``END_FUNCTION_BLOCK``."""
    scl = parts.dialect == "scl"
    out = [_comment(line) for line in parts.header]
    if scl:
        out.append(f'FUNCTION_BLOCK "{parts.name}"')
        out.append("{ S7_Optimized_Access := 'TRUE' }")
        out.append("VERSION : 0.1")
    else:
        out.append(f"FUNCTION_BLOCK {parts.name}")
    for sec in parts.sections:
        out.append(sec.keyword)
        if sec.title:
            out.append(f"    {_comment(sec.title)}")
        for v in sec.variables:
            for line in v.comment.split("\n") if v.comment and v.size is not None else []:
                out.append(f"    {_comment(line)}")
            note = f" {_comment(v.comment)}" if v.comment and v.size is None else ""
            out.append(f"    {v.declaration};{note}")
        out.append("END_VAR")
    if scl:
        out.append("BEGIN")
    out += parts.body
    out.append("END_FUNCTION_BLOCK")
    return "\n".join(out) + "\n"
