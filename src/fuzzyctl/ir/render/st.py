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

from dataclasses import dataclass

from fuzzyctl.ir.nodes import (
    Decl,
    For,
    Program,
    Region,
)
from fuzzyctl.ir.render.printer import Printer
from fuzzyctl.ir.state import CodegenError
from fuzzyctl.kinds import targets
from fuzzyctl.kinds.targets import st_real

__all__ = [
    "CodegenError",
    "STParts",
    "STSection",
    "STSyntax",
    "STVar",
    "format_st",
    "render_st",
    "st_parts",
    "st_real",
]


class STSyntax(Printer):
    """Structured Text's statement syntax, shared by the REAL block's printer and the
    integer block's (:mod:`fuzzyctl.ir.render.fixed`)."""

    ASSIGN = "{0} := {1};"
    IF = "IF {0} THEN"
    ELIF = "ELSIF {0} THEN"
    ELSE = "ELSE"
    END_IF = "END_IF;"
    WHILE = "WHILE {0} DO"
    END_WHILE = "END_WHILE;"
    EMPTY = ";"


class _ST(STSyntax):
    """Structured Text syntax; the dialect's record says how variables, regions, loops and
    the block are written."""

    def __init__(self, prog: Program, dialect: targets.Target, lreal: bool) -> None:
        super().__init__(dialect, real=dialect.real_type(not lreal))
        self.prog = prog

    def region(self, s: Region, ind: int) -> None:
        if not self.caps.regions:
            self.emit(self.comment(f"---- {s.name}"), ind)
            self.stmts(s.body, ind)
            return
        self.emit(f"REGION {self.caps.comments.escape(s.name)}", ind)  # the title runs to the line's end
        self.stmts(s.body, ind + 1)
        self.emit("END_REGION", ind)

    def for_(self, s: For, ind: int) -> None:
        var = self.name(s.var)
        if self.caps.for_as_while:
            # matiec (OpenPLC) runs FOR i := a TO a zero times: the same loop as WHILE
            step = "+" if s.step == 1 else "-"
            self.emit(f"{var} := {self.ex(s.start)};", ind)
            self.emit(f"WHILE {var} {'<=' if s.step == 1 else '>='} {self.ex(s.stop, 3)} DO", ind)
            self.stmts(s.body, ind + 1)
            self.emit(f"{var} := {var} {step} 1;", ind + 1)
            self.emit("END_WHILE;", ind)
            return
        by = "" if s.step == 1 else " BY -1"
        self.emit(f"FOR {var} := {self.ex(s.start)} TO {self.ex(s.stop)}{by} DO", ind)
        self.block(s.body, ind + 1)
        self.emit("END_FOR;", ind)


def _init_values(d: Decl, record: targets.Target) -> tuple[str, ...] | None:
    """The initial value of ``d`` as ST literals of the dialect's record (one for a scalar,
    one per element of an array); None when the declaration has none."""

    def one(v: float | bool) -> str:
        if d.type == "BOOL":
            return record.boolean(bool(v))
        if d.type in ("INT", "DINT", "BYTE"):
            return str(int(v))
        return record.real(float(v), parens=False)

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


def _record(dialect: str | targets.Target) -> targets.Target:
    return dialect if isinstance(dialect, targets.Target) else targets.dialect(dialect)


def st_parts(prog: Program, *, dialect: str | targets.Target = "codesys", lreal: bool = False) -> STParts:
    """The declarations and statements of one FUNCTION_BLOCK, before formatting; ``dialect``
    is a dialect's name or its record (:data:`fuzzyctl.kinds.targets.DIALECTS`)."""
    record = _record(dialect)
    name = dialect if isinstance(dialect, str) else record.name
    check = record.identifiers.check
    check(prog.name, "function block name")
    for d in prog.decls:
        check(d.name, "variable" if d.storage in ("input", "output") else "identifier")
    r = _ST(prog, record, lreal)
    r.stmts(prog.body, record.body_indent)

    def var(d: Decl) -> STVar:
        base = {"REAL": r.real, "INT": "INT", "DINT": "DINT", "BOOL": "BOOL", "BYTE": "BYTE"}[d.type]
        return STVar(d.name, base, d.size, _init_values(d, record), d.comment or "")

    # matiec (OpenPLC, Beremiz) turns a VAR_TEMP array without initial value into C that does
    # not compile, and IEC 61131-3 allows no initial value there: outside SCL the scratch
    # arrays live in the instance (written before read on every call, like the temporaries).
    scratch = [] if record.temp_arrays else [d for d in prog.of("temp") if d.size is not None]
    groups = (
        ("VAR_INPUT", prog.of("input"), ""),
        ("VAR_OUTPUT", prog.of("output"), ""),
        ("VAR", prog.of("param"), "tunable parameters: may be changed online"),
        ("VAR", prog.of("state") + prog.of("const"), "internal state and tables: do not change"),
        ("VAR", scratch, "scratch arrays of one call (no initial value needed)"),
        ("VAR_TEMP", [d for d in prog.of("temp") if d not in scratch], ""),
    )
    sections = tuple(STSection(kw, title, tuple(var(d) for d in ds)) for kw, ds, title in groups if ds)
    header = (*prog.header, f"dialect: {name}; arithmetic in {r.real}")
    return STParts(prog.name, name, r.real, header, sections, tuple(r.lines))


def render_st(prog: Program, *, dialect: str | targets.Target = "codesys", lreal: bool = False) -> str:
    """One FUNCTION_BLOCK."""
    return format_st(st_parts(prog, dialect=dialect, lreal=lreal), _record(dialect))


def format_st(parts: STParts, record: targets.Target | None = None) -> str:
    """The text of a FUNCTION_BLOCK from its parts: header comments, ``FUNCTION_BLOCK``,
    the sections, the body lines, ``END_FUNCTION_BLOCK``; ``record`` is the dialect's
    (default: the one ``parts.dialect`` names).  Every comment is made by the record, from
    model text its escaping function makes inert."""
    record = record or targets.dialect(parts.dialect)
    _comment = record.comment
    out = [_comment(line) for line in parts.header]
    quote = record.block_name_quote
    out.append(f"FUNCTION_BLOCK {quote}{parts.name}{quote}")
    out += record.block_head
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
    if record.body_keyword is not None:
        out.append(record.body_keyword)
    out += parts.body
    out.append("END_FUNCTION_BLOCK")
    return "\n".join(out) + "\n"
