"""The one expression/statement printer every renderer of the IR (:mod:`fuzzyctl.ir.nodes`)
is built on: Python (:mod:`~fuzzyctl.ir.render.pysrc`), numpy
(:mod:`~fuzzyctl.ir.render.npsrc`), C (:mod:`fuzzyctl.ir.render.c`) and Structured Text
(:mod:`fuzzyctl.ir.render.st`, which PLCopen XML wraps).

:class:`Printer` walks the nodes once.  What is lexical - literals, NaN and infinities,
operators, function spellings, comments - comes from the target's capabilities record
(:class:`fuzzyctl.kinds.targets.Target`); what is syntax - the statement forms - from the
class attributes a renderer sets (``ASSIGN``, ``IF``, ...).  A renderer overrides only what
differs: C names its block's fields ``fb->x``, SCL prefixes ``#``, numpy if-converts, the
native C calls its kernels.

Binary operations keep the IR's tree exactly (floating point is not associative): operands
are parenthesised by precedence where the target has it, always where the record says so.
"""

from __future__ import annotations

from collections.abc import Sequence

from fuzzyctl.escape import CodegenError
from fuzzyctl.ir.nodes import (
    Assign,
    Bin,
    Bool,
    Call,
    Comment,
    Ex,
    For,
    If,
    Index,
    Int,
    Kernel,
    Neg,
    Not,
    Num,
    Pwl,
    Region,
    Stmt,
    StmtVisitor,
    Var,
    While,
)
from fuzzyctl.kinds.targets import Target

#: Binding strength of the IR's binary operators (unary minus and NOT bind at UNARY).
PRECEDENCE = {
    "OR": 0,
    "AND": 1,
    "=": 2,
    "<>": 2,
    "<": 3,
    "<=": 3,
    ">": 3,
    ">=": 3,
    "+": 4,
    "-": 4,
    "*": 5,
    "/": 5,
}
UNARY = 6


class Printer(StmtVisitor):
    """Prints IR expressions and statements as lines of one target's source.

    ``caps`` is the target's record, ``real`` the REAL type's name in the text (``TO_REAL``),
    ``single`` writes REAL literals of the single-precision build, ``comments`` False leaves
    comments (which hold model text) out."""

    INDENT = "    "
    #: Statement templates: {0} the target / condition, {1} the value.  None: no such line.
    ASSIGN = "{0} = {1};"
    IF = "if ({0}) {{"
    ELIF = "}} else if ({0}) {{"
    ELSE = "}} else {{"
    END_IF: str | None = "}"
    WHILE = "while ({0}) {{"
    END_WHILE: str | None = "}"
    #: The statement an empty block holds (Python ``pass``, ST ``;``); None: nothing.
    EMPTY: str | None = None
    #: An AND operand of an OR in parentheses although it binds tighter (gcc -Wall's
    #: -Wparentheses warns on ``a && b || c``, and -Werror makes that an error).
    GROUP_AND_IN_OR = False

    def __init__(self, caps: Target, real: str = "", single: bool = False, comments: bool = True) -> None:
        self.caps = caps
        self.real = real or caps.real_type(single)
        self.single = single
        self.comments = comments
        self.prefix = caps.var_prefix
        self.lines: list[str] = []

    # ------------------------------------------------------------------ expressions

    def num(self, v: float) -> str:
        return self.caps.real(v, self.single)

    def name(self, n: str) -> str:
        return self.prefix + n if self.prefix else n

    def ex(self, e: Ex, parent: int = -1, right: bool = False) -> str:
        """``e`` as text, parenthesised for a parent operator of precedence ``parent``
        (``right``: as its right operand)."""
        t = type(e)  # the node classes are final: an exact type test, most frequent first
        if t is Var:
            return self.name(e.name)  # type: ignore[attr-defined]
        if t is Num:
            return self.num(e.value)  # type: ignore[attr-defined]
        if t is Bin:
            return self.bin(e, parent, right)  # type: ignore[arg-type]
        if t is Index:
            return self.index(e)  # type: ignore[arg-type]
        if t is Int:
            return self.caps.integer(e.value)  # type: ignore[attr-defined]
        if t is Call:
            return self.call(e)  # type: ignore[arg-type]
        if t is Neg:
            return self.caps.neg.format(self.ex(e.operand, UNARY))  # type: ignore[attr-defined]
        if t is Not:
            return self.caps.not_.format(self.ex(e.operand, UNARY))  # type: ignore[attr-defined]
        if t is Bool:
            return self.caps.boolean(e.value)  # type: ignore[attr-defined]
        assert t is Pwl, e
        return self.pwl(e)  # type: ignore[arg-type]

    def index(self, e: Index) -> str:
        return f"{self.name(e.name)}[{self.ex(e.index)}]"

    def args(self, e: Call) -> list[str]:
        return [self.ex(a) for a in e.args]

    def call(self, e: Call) -> str:
        caps, fn = self.caps, e.function
        if fn == "NAN" and caps.numbers.nan is not None:
            return caps.numbers.nan
        if fn == "TO_REAL":
            return caps.to_real.format(*self.args(e), real=self.real)
        if fn == "IMOD" and caps.int_mod is not None:
            return caps.int_mod.format(*self.args(e))
        if fn not in caps.functions:
            raise CodegenError(f"function {fn} has no portable {caps.label} equivalent")
        return f"{caps.functions[fn]}({', '.join(self.args(e))})"

    def pwl(self, e: Pwl) -> str:
        raise CodegenError(f"a piecewise-linear degree has no {self.caps.label} form here")

    def bin(self, e: Bin, parent: int, right: bool) -> str:
        p = PRECEDENCE[e.op]
        op = self.caps.operators.get(e.op, e.op)
        left, rhs = self.ex(e.left, p), self.ex(e.right, p, True)
        if "{" in op:  # an operator the target writes as a call
            return op.format(left, rhs)
        s = f"{left} {op} {rhs}"
        if self.caps.parenthesise_all or p < parent or (right and p == parent):
            return f"({s})"
        if self.GROUP_AND_IN_OR and e.op == "AND" and parent == PRECEDENCE["OR"]:
            return f"({s})"
        return s

    # ------------------------------------------------------------------ statements

    def emit(self, s: str, ind: int) -> None:
        self.lines.append(self.INDENT * ind + s)

    def comment(self, text: str) -> str:
        """A comment line: every comment of the generated text is made here, from model
        text the record's escaping function makes inert."""
        return self.caps.comment(text)

    def stmts(self, body: Sequence[Stmt], ind: int) -> None:
        for s in body:
            self.stmt(s, ind)

    def block(self, body: Sequence[Stmt], ind: int) -> None:
        """A nested body; one that prints nothing gets :attr:`EMPTY`."""
        start = len(self.lines)
        self.stmts(body, ind)
        if len(self.lines) == start and self.EMPTY is not None:
            self.emit(self.EMPTY, ind)

    def note(self, s: Comment, ind: int) -> None:
        if self.comments:
            self.emit(self.comment(s.text), ind)

    def assign(self, s: Assign, ind: int) -> None:
        self.emit(self.ASSIGN.format(self.ex(s.target), self.ex(s.value)), ind)

    def if_(self, s: If, ind: int) -> None:
        for k, (cond, body) in enumerate(s.branches):
            self.emit((self.IF if k == 0 else self.ELIF).format(self.ex(cond)), ind)
            self.block(body, ind + 1)
        if s.orelse:
            self.emit(self.ELSE.format(), ind)
            self.block(s.orelse, ind + 1)
        if self.END_IF is not None:
            self.emit(self.END_IF, ind)

    def for_(self, s: For, ind: int) -> None:
        """C's ``for``; other syntaxes override."""
        v = self.name(s.var)
        cmp, inc = ("<=", "++") if s.step > 0 else (">=", "--")
        self.emit(f"for ({v} = {self.ex(s.start)}; {v} {cmp} {self.ex(s.stop)}; {v}{inc}) {{", ind)
        self.block(s.body, ind + 1)
        self.emit("}", ind)

    def while_(self, s: While, ind: int) -> None:
        self.emit(self.WHILE.format(self.ex(s.cond)), ind)
        self.block(s.body, ind + 1)
        if self.END_WHILE is not None:
            self.emit(self.END_WHILE, ind)

    def region(self, s: Region, ind: int) -> None:
        """A comment naming the region, then its statements at the same depth."""
        if self.comments:
            self.emit(self.comment(s.name), ind)
        self.stmts(s.body, ind)

    def kernel(self, k: Kernel, ind: int) -> None:
        """A routine the renderer provides (the record's ``kernels``); the PLC block has none."""
        raise CodegenError(f"the generated {self.caps.label} has no kernel {k.name}")
