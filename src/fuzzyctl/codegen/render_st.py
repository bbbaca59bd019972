"""Print a :class:`~fuzzyctl.codegen.ir.Program` as an IEC 61131-3 Structured Text
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

from fuzzyctl.codegen.context import CodegenError
from fuzzyctl.codegen.ir import (
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
from fuzzyctl.escape import st_comment, st_ident, st_ident_iec

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


def _type(d: Decl, real: str) -> str:
    base = {"REAL": real, "INT": "INT", "DINT": "DINT", "BOOL": "BOOL", "BYTE": "BYTE"}[d.type]
    return f"ARRAY[0..{d.size - 1}] OF {base}" if d.size is not None else base


def _init(d: Decl) -> str:
    def one(v: float | bool) -> str:
        if d.type == "BOOL":
            return "TRUE" if v else "FALSE"
        if d.type in ("INT", "DINT", "BYTE"):
            return str(int(v))
        return st_real(float(v))

    if d.init is None:
        return ""
    if isinstance(d.init, tuple):
        if d.storage != "param" and not any(d.init):
            # IEC 61131-3 initialises to 0 / FALSE anyway; long literal lists cost PLC
            # editors (and Earley parsers) dearly.  Parameters stay explicit for the tuner.
            return ""
        return " := [" + ", ".join(one(v) for v in d.init) + "]"
    return " := " + one(d.init)


def render_st(prog: Program, *, dialect: str = "codesys", lreal: bool = False) -> str:
    """One FUNCTION_BLOCK."""
    check = st_ident_iec if dialect == "iec" else st_ident
    check(prog.name, "function block name")
    for d in prog.decls:
        check(d.name, "variable" if d.storage in ("input", "output") else "identifier")
    r = _ST(prog, dialect, lreal)
    out: list[str] = []
    for line in prog.header:
        out.append(_comment(line))
    out.append(_comment(f"dialect: {dialect}; arithmetic in {r.real}"))
    if r.scl:
        out.append(f'FUNCTION_BLOCK "{prog.name}"')
        out.append("{ S7_Optimized_Access := 'TRUE' }")
        out.append("VERSION : 0.1")
    else:
        out.append(f"FUNCTION_BLOCK {prog.name}")

    def block(kw: str, decls: list[Decl], title: str | None = None) -> None:
        if not decls:
            return
        out.append(kw)
        if title:
            out.append(f"    {_comment(title)}")
        for d in decls:
            for line in d.comment.split("\n") if d.comment and d.size is not None else []:
                out.append(f"    {_comment(line)}")
            note = f" {_comment(d.comment)}" if d.comment and d.size is None else ""
            out.append(f"    {d.name} : {_type(d, r.real)}{_init(d)};{note}")
        out.append("END_VAR")

    block("VAR_INPUT", prog.of("input"))
    block("VAR_OUTPUT", prog.of("output"))
    block("VAR", prog.of("param"), "tunable parameters: may be changed online")
    block("VAR", prog.of("state") + prog.of("const"), "internal state and tables: do not change")
    # matiec (OpenPLC, Beremiz) turns a VAR_TEMP array without initial value into C that does
    # not compile, and IEC 61131-3 allows no initial value there: outside SCL the scratch
    # arrays live in the instance (written before read on every call, like the temporaries).
    scratch = [] if r.scl else [d for d in prog.of("temp") if d.size is not None]
    block("VAR", scratch, "scratch arrays of one call (no initial value needed)")
    block("VAR_TEMP", [d for d in prog.of("temp") if d not in scratch])
    if r.scl:
        out.append("BEGIN")
    r.stmts(prog.body, 1 if r.scl else 0)
    out += r.lines
    out.append("END_FUNCTION_BLOCK")
    return "\n".join(out) + "\n"
