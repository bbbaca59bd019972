"""The cost of one evaluation of a program, counted on its IR: additions (and subtractions,
negations), multiplications, divisions, comparisons, logic operations, calls of each
intrinsic (EXP, LN, SQRT, ...), array reads and assignments.

Two bounds are given, each count a bound on its own (an IF costs its conditions up to the
branch taken plus the dearest branch, category by category; a loop its most iterations times
its body plus the counter's test and increment):

* ``worst``: every branch may be taken;
* ``usual``: the branches marked rare (:attr:`fuzzyctl.ir.nodes.If.rare`: a term's points
  retuned out of order, degrees so small they are rescaled) are not taken.

A loop whose iteration count is not a literal and carries no bound makes the program's cost
unbounded (``bounded`` False); its body is then counted once.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass, field
from typing import Any

from fuzzyctl.ir.nodes import (
    Assign,
    Bin,
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
    Program,
    Pwl,
    Region,
    Stmt,
    StmtVisitor,
    While,
    subexprs,
)

#: The counted categories, in the order they are printed.
KINDS = ("add", "mul", "div", "compare", "logic", "array_reads", "assignments")
_OPS = {"+": "add", "-": "add", "*": "mul", "/": "div", "AND": "logic", "OR": "logic"}
_OPS.update({op: "compare" for op in ("<", "<=", ">", ">=", "=", "<>")})


@dataclass
class Counts:
    """Operation counts of one path (or a bound over paths)."""

    n: dict[str, int] = field(default_factory=dict)  # KINDS and "call:NAME"
    bounded: bool = True

    def add(self, kind: str, k: int = 1) -> None:
        self.n[kind] = self.n.get(kind, 0) + k

    def plus(self, o: Counts, times: int = 1) -> None:
        for k, v in o.n.items():
            self.add(k, v * times)
        self.bounded = self.bounded and o.bounded

    def copy(self) -> Counts:
        return Counts(dict(self.n), self.bounded)

    @staticmethod
    def most(paths: Sequence[Counts]) -> Counts:
        """The category-by-category maximum of ``paths``."""
        out = Counts()
        for p in paths:
            for k, v in p.n.items():
                out.n[k] = max(out.n.get(k, 0), v)
            out.bounded = out.bounded and p.bounded
        return out

    @property
    def calls(self) -> dict[str, int]:
        return {k[5:]: v for k, v in sorted(self.n.items()) if k.startswith("call:") and v}

    @property
    def operations(self) -> int:
        """Arithmetic, comparisons, logic and calls (not reads and assignments)."""
        return sum(self.n.get(k, 0) for k in KINDS[:5]) + sum(self.calls.values())

    def to_dict(self) -> dict[str, Any]:
        out: dict[str, Any] = {k: self.n.get(k, 0) for k in KINDS}
        out["calls"] = self.calls
        out["operations"] = self.operations
        out["bounded"] = self.bounded
        return out

    def summary(self) -> str:
        parts = [f"{self.n.get(k, 0)} {k.replace('_', ' ')}" for k in KINDS]
        parts += [f"{v} {name}" for name, v in self.calls.items()]
        text = f"{self.operations} operations ({', '.join(parts)})"
        return text if self.bounded else text + "; loops without a static bound counted once"


@dataclass
class Cost:
    """The usual and worst cost of one evaluation."""

    usual: Counts
    worst: Counts

    def to_dict(self) -> dict[str, Any]:
        return {"usual": self.usual.to_dict(), "worst": self.worst.to_dict()}

    def header(self) -> list[str]:
        return [
            "cost per cycle, usual (no retuned point out of order, no tiny degrees): " + self.usual.summary(),
            "cost per cycle, worst case: " + self.worst.summary(),
        ]


def expr(e: Ex, c: Counts) -> None:
    """Count the operations of evaluating ``e`` into ``c``."""
    for x in subexprs(e):
        t = type(x)
        if t is Index:
            c.add("array_reads")
        elif t is Bin:
            c.add(_OPS[x.op])  # type: ignore[attr-defined]
        elif t is Neg:
            c.add("add")
        elif t is Not:
            c.add("logic")
        elif t is Call:
            c.add(f"call:{x.function}")  # type: ignore[attr-defined]
        elif t is Pwl:
            c.add("call:PWL")


def _trips(s: For) -> int | None:
    if isinstance(s.start, Int) and isinstance(s.stop, Int):
        return max(0, (s.stop.value - s.start.value) * s.step + 1)
    return s.bound


class _Walk(StmtVisitor):
    """The bound on one execution of each statement (``usual``: rare branches left out)."""

    def __init__(self, usual: bool) -> None:
        self.usual = usual

    def stmts(self, body: Sequence[Stmt]) -> Counts:
        c = Counts()
        for s in body:
            c.plus(self.stmt(s))
        return c

    def assign(self, s: Assign) -> Counts:
        c = Counts()
        c.add("assignments")
        if isinstance(s.target, Index):
            expr(s.target.index, c)
        expr(s.value, c)
        return c

    def if_(self, s: If) -> Counts:
        paths: list[Counts] = []
        tested = Counts()
        for k, (cond, body) in enumerate(s.branches):
            expr(cond, tested)
            if not (self.usual and s.rare and k == 0):
                taken = tested.copy()
                taken.plus(self.stmts(body))
                paths.append(taken)
        last = tested.copy()
        last.plus(self.stmts(s.orelse))
        paths.append(last)
        return Counts.most(paths)

    def for_(self, s: For) -> Counts:
        c = Counts()
        expr(s.start, c)
        expr(s.stop, c)
        trips = _trips(s)
        step = self.stmts(s.body)
        step.add("compare")  # the counter's test
        step.add("add")  # and increment
        c.plus(step, 1 if trips is None else trips)
        c.add("compare")  # the test that ends the loop
        c.bounded = c.bounded and trips is not None
        return c

    def while_(self, s: While) -> Counts:
        c = Counts()
        step = self.stmts(s.body)
        expr(s.cond, step)
        c.plus(step, 1 if s.bound is None else s.bound)
        expr(s.cond, c)
        c.bounded = c.bounded and s.bound is not None
        return c

    def note(self, s: Comment) -> Counts:
        return Counts()

    def region(self, s: Region) -> Counts:
        return self.stmts(s.body)

    def kernel(self, s: Kernel) -> Counts:
        c = Counts()
        c.add(f"call:{s.name}")
        c.add("assignments", len(s.outs))
        for a in s.args:
            expr(a, c)
        return c


def stmts(body: Sequence[Stmt], usual: bool) -> Counts:
    """The bound on one execution of ``body`` (``usual``: rare branches left out)."""
    return _Walk(usual).stmts(body)


def cost(prog: Program) -> Cost:
    """The usual and worst cost of one evaluation of ``prog``."""
    return Cost(stmts(prog.body, True), stmts(prog.body, False))
