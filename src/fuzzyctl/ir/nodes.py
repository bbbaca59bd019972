"""A small imperative IR that every generated evaluator is printed from.

Two programs are built from a :class:`~fuzzyctl.engine.plan.Plan` (their rule evaluation is
one piece of code, :mod:`fuzzyctl.ir.builders.rules`):

* :mod:`fuzzyctl.ir.programs.plc_block` - the PLC function block, printed as Structured Text
  (:mod:`~fuzzyctl.ir.render.st`) and C (:mod:`~fuzzyctl.ir.render.c`);
* :mod:`fuzzyctl.ir.programs.evaluator` - the evaluator of ``compile()``, printed as Python
  (:mod:`~fuzzyctl.ir.render.pysrc`), numpy (:mod:`~fuzzyctl.ir.render.npsrc`) and the
  native backend's C.

So the C file, the ST block, the native backend and the Python paths run the same algorithm,
and the tests that check one check the others' code too.

The IR is deliberately the intersection of what portable Structured Text and C99 can say:
scalar and one-dimensional array variables (0-based, literal sizes), assignments, IF/ELSIF/ELSE,
counted FOR loops with unit step, WHILE loops, arithmetic, comparisons, AND/OR/NOT and a few
intrinsic functions (EXP, SQRT, LN, ...).  MIN/MAX are spelled out as IFs by the program
builder, powers as products.
"""

from __future__ import annotations

import math
from collections.abc import Iterator, Sequence
from contextlib import contextmanager
from dataclasses import dataclass, field
from typing import Any, ClassVar, Literal

#: DINT: 32-bit integers (table indices of large rule bases; INT is 16-bit in Structured Text)
Type = Literal["REAL", "INT", "DINT", "BOOL", "BYTE"]
#: Storage classes: instance inputs/outputs, tunable parameters (static, initialised, meant to
#: be changed online), internal state (static), constants (static, initialised, not to be
#: changed) and temporaries (per evaluation).
Storage = Literal["input", "output", "param", "state", "const", "temp"]


# --------------------------------------------------------------------------- expressions


class Ex:
    """An expression.  Arithmetic operators build new nodes; comparisons are methods (``==``
    keeps its Python meaning so that nodes stay hashable)."""

    def __add__(self, o: ExLike) -> Ex:
        return _arith("+", self, ex(o))

    def __radd__(self, o: ExLike) -> Ex:
        return _arith("+", ex(o), self)

    def __sub__(self, o: ExLike) -> Ex:
        return _arith("-", self, ex(o))

    def __rsub__(self, o: ExLike) -> Ex:
        return _arith("-", ex(o), self)

    def __mul__(self, o: ExLike) -> Ex:
        return Bin("*", self, ex(o))

    def __rmul__(self, o: ExLike) -> Ex:
        return Bin("*", ex(o), self)

    def __truediv__(self, o: ExLike) -> Ex:
        return Bin("/", self, ex(o))

    def __rtruediv__(self, o: ExLike) -> Ex:
        return Bin("/", ex(o), self)

    def __neg__(self) -> Ex:
        return Neg(self)

    def lt(self, o: ExLike) -> Ex:
        return Bin("<", self, ex(o))

    def le(self, o: ExLike) -> Ex:
        return Bin("<=", self, ex(o))

    def gt(self, o: ExLike) -> Ex:
        return Bin(">", self, ex(o))

    def ge(self, o: ExLike) -> Ex:
        return Bin(">=", self, ex(o))

    def eq(self, o: ExLike) -> Ex:
        return Bin("=", self, ex(o))

    def ne(self, o: ExLike) -> Ex:
        return Bin("<>", self, ex(o))

    def and_(self, o: Ex) -> Ex:
        return Bin("AND", self, o)

    def or_(self, o: Ex) -> Ex:
        return Bin("OR", self, o)


ExLike = Ex | float | int | bool


def _arith(op: str, a: Ex, b: Ex) -> Ex:
    """Fold integer index arithmetic (``0 + 1`` -> ``1``, ``k + 0`` -> ``k``) so that
    generated array indices stay readable; REAL arithmetic is never folded (it would change
    rounding)."""
    if isinstance(a, Int) and isinstance(b, Int):
        return Int(a.value + b.value if op == "+" else a.value - b.value)
    if isinstance(b, Int) and b.value == 0:
        return a
    if isinstance(a, Int) and a.value == 0 and op == "+":
        return b
    if isinstance(b, Int) and b.value < 0:
        return Bin("-" if op == "+" else "+", a, Int(-b.value))
    return Bin(op, a, b)


@dataclass(frozen=True, eq=False)
class Num(Ex):
    """A REAL literal."""

    value: float


@dataclass(frozen=True, eq=False)
class Int(Ex):
    """An INT literal."""

    value: int


@dataclass(frozen=True, eq=False)
class Bool(Ex):
    value: bool


@dataclass(frozen=True, eq=False)
class Var(Ex):
    """A scalar variable, or a whole array when indexed."""

    name: str

    def __getitem__(self, index: ExLike) -> Index:
        return Index(self.name, ex(index))


@dataclass(frozen=True, eq=False)
class Index(Ex):
    name: str
    index: Ex


@dataclass(frozen=True, eq=False)
class Bin(Ex):
    op: str  # + - * / < <= > >= = <> AND OR
    left: Ex
    right: Ex


@dataclass(frozen=True, eq=False)
class Neg(Ex):
    operand: Ex


@dataclass(frozen=True, eq=False)
class Not(Ex):
    operand: Ex


@dataclass(frozen=True, eq=False)
class Call(Ex):
    """An intrinsic: EXP, LN, SQRT, ABS, COS, SIN, TAN, ACOS, ASIN, ATAN, LOG (base 10),
    and TO_REAL (INT -> REAL)."""

    function: str
    args: tuple[Ex, ...]


@dataclass(frozen=True, eq=False)
class Pwl(Ex):
    """The degree of a piecewise-linear membership function with constant breakpoints
    (``shapes.pwl_value``: constant beyond the ends, the upper value on a vertical edge).
    Only the evaluator of ``compile()`` uses it; each renderer writes it its own way (an
    if-chain, ``numpy.interp``)."""

    x: Ex
    points: tuple[tuple[float, float], ...]


def ex(v: ExLike) -> Ex:
    """Lift a Python number into the IR (``int`` -> INT literal, ``float`` -> REAL)."""
    if isinstance(v, Ex):
        return v
    if isinstance(v, bool):
        return Bool(v)
    if isinstance(v, int):
        return Int(v)
    if not math.isfinite(v):
        raise ValueError(f"non-finite literal {v}")
    return Num(float(v))


def call(function: str, *args: ExLike) -> Call:
    return Call(function, tuple(ex(a) for a in args))


def not_(e: Ex) -> Ex:
    return Not(e)


# --------------------------------------------------------------------------- statements


@dataclass
class Assign:
    target: Var | Index
    value: Ex


@dataclass
class If:
    branches: list[tuple[Ex, list[Stmt]]]
    orelse: list[Stmt] = field(default_factory=list)
    #: the first branch is taken only in a rare case (a point retuned out of order): the
    #: usual cost per cycle (:mod:`fuzzyctl.ir.cost`) leaves it out
    rare: bool = False


@dataclass
class For:
    """``FOR var := start TO stop BY step`` (both ends inclusive, ``step`` is +1 or -1)."""

    var: str
    start: Ex
    stop: Ex
    body: list[Stmt]
    step: int = 1
    #: most iterations, for bounds that are not literals (the cost per cycle needs it)
    bound: int | None = None


@dataclass
class While:
    cond: Ex
    body: list[Stmt]
    bound: int | None = None  # most iterations (for the cost per cycle)


@dataclass
class Comment:
    text: str


@dataclass
class Region:
    """A named group of statements (SCL REGION, a comment elsewhere)."""

    name: str
    body: list[Stmt]


@dataclass
class Kernel:
    """``outs := name(args)``: a routine each renderer provides in its own language (an
    exact integral, a quadrature, the NC fill of a batch), written once per target.
    ``data`` is constant (tables, the plan element the routine works on)."""

    name: str
    outs: tuple[Var | Index, ...]
    args: tuple[Ex, ...]
    data: Any = None


Stmt = Assign | If | For | While | Comment | Region | Kernel


class StmtVisitor:
    """The statement walk the printer and the cost share: :meth:`stmt` calls the method named
    for the statement's class (``assign``, ``if_``, ``for_``, ``while_``, ``note`` for a
    comment, ``region``, ``kernel``) with the extra arguments given; a subclass writes what each does."""

    #: The method for each statement class (the classes are final: an exact type lookup).
    METHODS: ClassVar[dict[type, str]] = {
        Assign: "assign",
        If: "if_",
        For: "for_",
        While: "while_",
        Comment: "note",
        Region: "region",
        Kernel: "kernel",
    }

    def stmt(self, s: Stmt, *args: Any) -> Any:
        return getattr(self, self.METHODS[type(s)])(s, *args)


# --------------------------------------------------------------------------- declarations


@dataclass
class Decl:
    """A variable.  ``size`` None is a scalar, else an array ``[0..size-1]``; ``init`` gives the
    initial values (params, consts, state); ``comment`` explains it to the PLC engineer."""

    name: str
    type: Type
    storage: Storage
    size: int | None = None
    init: tuple[float, ...] | float | bool | None = None
    comment: str = ""


@dataclass
class Program:
    """One function block: declarations and the statements of one evaluation."""

    name: str
    decls: list[Decl]
    body: list[Stmt]
    header: list[str] = field(default_factory=list)  # comment lines at the top
    uses: set[str] = field(default_factory=set)  # intrinsics the body calls

    def decl(self, name: str) -> Decl:
        for d in self.decls:
            if d.name == name:
                return d
        raise KeyError(name)

    def of(self, storage: Storage) -> list[Decl]:
        return [d for d in self.decls if d.storage == storage]


# --------------------------------------------------------------------------- building


class Builder:
    """Collects statements with ``with`` blocks for nesting::

    b = Builder()
    with b.if_(x.lt(0.0)):
        b.set(y, 0.0)
    with b.else_():
        b.set(y, x)
    """

    def __init__(self) -> None:
        self.root: list[Stmt] = []
        self._stack: list[list[Stmt]] = [self.root]
        self._last_if: If | None = None

    @property
    def cur(self) -> list[Stmt]:
        return self._stack[-1]

    def add(self, s: Stmt) -> None:
        self.cur.append(s)
        self._last_if = s if isinstance(s, If) else None

    def set(self, target: Var | Index, value: ExLike) -> None:
        self.add(Assign(target, ex(value)))

    def comment(self, text: str) -> None:
        self.add(Comment(text))

    @contextmanager
    def _body(self, body: list[Stmt]) -> Iterator[None]:
        self._stack.append(body)
        self._last_if = None
        try:
            yield
        finally:
            self._stack.pop()

    @contextmanager
    def if_(self, cond: Ex, rare: bool = False) -> Iterator[None]:
        node = If([(cond, [])], rare=rare)
        self.add(node)
        with self._body(node.branches[0][1]):
            yield
        self._last_if = node

    @contextmanager
    def elif_(self, cond: Ex) -> Iterator[None]:
        node = self._last_if
        assert node is not None and not node.orelse, "elif_ must follow if_"
        node.branches.append((cond, []))
        with self._body(node.branches[-1][1]):
            yield
        self._last_if = node

    @contextmanager
    def else_(self) -> Iterator[None]:
        node = self._last_if
        assert node is not None and not node.orelse, "else_ must follow if_"
        body: list[Stmt] = []
        node.orelse = body
        with self._body(body):
            yield
        self._last_if = None

    @contextmanager
    def for_(
        self, var: str, start: ExLike, stop: ExLike, step: int = 1, bound: int | None = None
    ) -> Iterator[Var]:
        node = For(var, ex(start), ex(stop), [], step, bound)
        self.add(node)
        with self._body(node.body):
            yield Var(var)
        self._last_if = None

    @contextmanager
    def while_(self, cond: Ex, bound: int | None = None) -> Iterator[None]:
        node = While(cond, [], bound)
        self.add(node)
        with self._body(node.body):
            yield
        self._last_if = None

    @contextmanager
    def region(self, name: str) -> Iterator[None]:
        node = Region(name, [])
        self.add(node)
        with self._body(node.body):
            yield
        self._last_if = None


def walk_exprs(stmts: Sequence[Stmt]) -> Iterator[Ex]:
    """Every expression in ``stmts`` (top-level expressions only; use :func:`subexprs`)."""
    for s in stmts:
        if isinstance(s, Assign):
            yield s.target
            yield s.value
        elif isinstance(s, If):
            for c, body in s.branches:
                yield c
                yield from walk_exprs(body)
            yield from walk_exprs(s.orelse)
        elif isinstance(s, For):
            yield s.start
            yield s.stop
            yield from walk_exprs(s.body)
        elif isinstance(s, While):
            yield s.cond
            yield from walk_exprs(s.body)
        elif isinstance(s, Region):
            yield from walk_exprs(s.body)
        elif isinstance(s, Kernel):
            yield from s.outs
            yield from s.args


def _loop_vars(stmts: Sequence[Stmt]) -> Iterator[str]:
    for s in stmts:
        if isinstance(s, For):
            yield s.var
            yield from _loop_vars(s.body)
        elif isinstance(s, If):
            for _c, body in s.branches:
                yield from _loop_vars(body)
            yield from _loop_vars(s.orelse)
        elif isinstance(s, While | Region):
            yield from _loop_vars(s.body)


def identifiers(prog: Program) -> set[str]:
    """Every identifier of ``prog`` a renderer prints: declarations, loop variables and the
    variables the statements use (each renderer passes them through its target's escaping
    function, :mod:`fuzzyctl.escape`)."""
    out = {d.name for d in prog.decls} | set(_loop_vars(prog.body))
    for top in walk_exprs(prog.body):
        out.update(e.name for e in subexprs(top) if isinstance(e, Var | Index))
    return out


def subexprs(e: Ex) -> Iterator[Ex]:
    yield e
    if isinstance(e, Index):
        yield from subexprs(e.index)
    elif isinstance(e, Bin):
        yield from subexprs(e.left)
        yield from subexprs(e.right)
    elif isinstance(e, Neg | Not):
        yield from subexprs(e.operand)
    elif isinstance(e, Call):
        for a in e.args:
            yield from subexprs(a)
    elif isinstance(e, Pwl):
        yield from subexprs(e.x)
