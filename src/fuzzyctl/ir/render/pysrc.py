"""Print the evaluator program (:mod:`fuzzyctl.ir.programs.evaluator`) as one straight-line Python
function, ``_fast(v, state) -> outputs``: inputs unpacked into locals, constants inlined as
exact float literals, IFs as Python ``if``, piecewise-linear memberships as if-chains over
their breakpoints, kernels as calls of :mod:`fuzzyctl.ir.kernels.scalar`.

The generated source is kept on the function (``__source__``) for inspection.  No name of the
model reaches the source: every variable is an ``FZ_`` identifier of the program (each one
checked by :func:`fuzzyctl.escape.py_ident`), and comments (which hold rule labels) are not
printed.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Sequence
from typing import Any

from fuzzyctl.escape import py_ident, py_str
from fuzzyctl.ir.kernels import scalar as kernels
from fuzzyctl.ir.nodes import (
    Assign,
    Bin,
    Bool,
    Ex,
    For,
    If,
    Index,
    Int,
    Kernel,
    Pwl,
    Region,
    Stmt,
    Var,
    While,
    identifiers,
)
from fuzzyctl.ir.programs.evaluator import FastProgram
from fuzzyctl.ir.render.printer import Printer
from fuzzyctl.kinds import targets

Fast = Callable[[list[float], list[float | None]], list[float]]


class PythonPrinter(Printer):
    """Python statement syntax (indentation blocks, ``pass``, ``range`` loops); no comments
    (they hold model text)."""

    ASSIGN = "{0} = {1}"
    IF = "if {0}:"
    ELIF = "elif {0}:"
    ELSE = "else:"
    END_IF = None
    WHILE = "while {0}:"
    END_WHILE = None
    EMPTY = "pass"

    def __init__(self, caps: targets.Target) -> None:
        super().__init__(caps, comments=False)

    def region(self, s: Region, ind: int) -> None:
        self.block(s.body, ind)  # a region that prints nothing holds a pass

    def for_(self, s: For, ind: int) -> None:
        stop = f"{self.ex(s.stop)} + 1" if s.step > 0 else f"{self.ex(s.stop)} - 1, -1"
        self.emit(f"for {s.var} in range({self.ex(s.start)}, {stop}):", ind)
        self.block(s.body, ind + 1)


class _Py(PythonPrinter):
    def __init__(self, fp: FastProgram, caps: targets.Target = targets.PY) -> None:
        super().__init__(caps)
        self.fp = fp
        self.env: dict[str, Any] = {"_NAN": math.nan, "_INF": math.inf, "_m": math}
        self.n_kernels = 0

    def bind(self, value: Any, prefix: str = "_k") -> str:
        name = f"{prefix}{self.n_kernels}"
        self.n_kernels += 1
        self.env[name] = value
        return name

    def pwl(self, e: Pwl) -> str:
        """Not at the top of an assignment: ``shapes.pwl_value`` bound as a function."""
        from fuzzyctl.engine.semantics.shapes import pwl_value

        return f"{self.bind(lambda x, pts=e.points: pwl_value(pts, x), '_p')}({self.ex(e.x)})"

    def assign(self, s: Assign, ind: int) -> None:
        if isinstance(s.value, Pwl):
            self.pwl_chain(s.value, self.ex(s.target), ind)
        else:
            super().assign(s, ind)

    def pwl_chain(self, p: Pwl, out: str, ind: int) -> None:
        """``shapes.pwl_value`` as an if-chain over the breakpoints."""
        from fuzzyctl.engine.lowering.grid import left_limit, right_limit
        from fuzzyctl.engine.semantics.shapes import pwl_value

        x = self.ex(p.x)
        if not isinstance(p.x, Var):
            self.emit(f"_x = {x}", ind)
            x = "_x"
        pts = p.points
        xs = sorted({q[0] for q in pts})
        self.emit(f"if {x} < {self.num(xs[0])}: {out} = {self.num(pts[0][1])}", ind)
        for k, u in enumerate(xs):
            pv = pwl_value(pts, u)
            jump = left_limit(pts, u) != right_limit(pts, u) or pv != left_limit(pts, u)
            if jump or k == 0:
                self.emit(f"elif {x} == {self.num(u)}: {out} = {self.num(pv)}", ind)
            if k + 1 < len(xs):
                u1 = xs[k + 1]
                r0, l1 = right_limit(pts, u), left_limit(pts, u1)
                if r0 == l1:
                    expr = self.num(r0)
                else:
                    base = f"({x} - {self.num(u)}) * {self.num((l1 - r0) / (u1 - u))}"
                    expr = base if r0 == 0.0 else f"{self.num(r0)} + {base}"
                self.emit(f"elif {x} < {self.num(u1)}: {out} = {expr}", ind)
        self.emit(f"elif {x} == {self.num(xs[-1])}: {out} = {self.num(pwl_value(pts, xs[-1]))}", ind)
        self.emit(f"else: {out} = {self.num(pts[-1][1])}", ind)

    # ------------------------------------------------------------------ kernels

    def kernel(self, k: Kernel, ind: int) -> None:
        outs = ", ".join(self.ex(o) for o in k.outs)
        args = ", ".join(self.ex(a) for a in k.args)
        if k.name == "HOLD":
            self.hold(k, ind)
            return
        fn = self.bind(kernels.make(k.name, k.data, self.fp.plan))
        self.emit(f"{outs}{',' if len(k.outs) == 1 and k.name == 'SELECT' else ''} = {fn}({args})", ind)

    def hold(self, k: Kernel, ind: int) -> None:
        """DEFAULT / NC / lock-range (``interp.run``)."""
        oi, default, no_change, clamp = k.data
        out = self.ex(k.outs[0])
        value, fired = k.args
        if not (isinstance(fired, Bool) and fired.value):
            self.emit(f"if {self.ex(fired)}:", ind)
            self.emit(f"{out} = {self.ex(value)}", ind + 1)
            self.emit("else:", ind)
            if no_change:
                self.emit(f"{out} = state[{oi}]", ind + 1)
                self.emit(f"if {out} is None: {out} = {self.num(default)}", ind + 1)
            else:
                self.emit(f"{out} = {self.num(default)}", ind + 1)
        elif self.ex(value) != out:
            self.emit(f"{out} = {self.ex(value)}", ind)
        if clamp is not None:
            lo, hi = clamp
            self.emit(f"if {out} < {self.num(lo)}: {out} = {self.num(lo)}", ind)
            self.emit(f"elif {out} > {self.num(hi)}: {out} = {self.num(hi)}", ind)
        self.emit(f"state[{oi}] = {out}", ind)


def render_py(fp: FastProgram, caps: targets.Target = targets.PY) -> tuple[str, dict[str, Any]]:
    """The source of ``_fast`` and the globals it needs; ``caps`` is the Python record
    (literals, functions, operators)."""
    r = _Py(fp, caps)
    prog = fp.program
    check_names(fp)
    for d in prog.of("const"):
        assert isinstance(d.init, tuple)
        r.env[d.name] = tuple(float(v) if d.type == "REAL" else int(v) for v in d.init)
    body_start = len(r.lines)
    r.block(prog.body, 1)
    body = r.lines[body_start:]
    head: list[str] = []
    for k, name in enumerate(fp.inputs):
        head.append(f"    {name} = v[{k}]")
    for d in prog.of("temp"):
        if d.size is not None:
            zero = "0.0" if d.type == "REAL" else ("0" if d.type == "INT" else "False")
            head.append(f"    {d.name} = [{zero}] * {d.size}")
    scalars = {d.name for d in prog.of("temp") + prog.of("output") if d.size is None}
    for name in needs_init(prog.body, scalars) + [
        o for o in fp.outputs if o in scalars and not _assigned(prog.body, o)
    ]:
        head.append(f"    {name} = 0.0")
    src = "def _fast(v, state):\n" + "\n".join(head + body) + f"\n    return [{', '.join(fp.outputs)}]\n"
    return src, r.env


def specialise(fp: FastProgram) -> Fast:
    """Compile the rendered source into the function."""
    src, env = render_py(fp)
    # no model text reaches the source (FZ_ names checked by py_ident, float literals;
    # kernels are bound objects)
    exec(compile(src, f"<fuzzyctl evaluator {py_str(fp.plan.name or '')}>", "exec"), env)
    fn: Fast = env["_fast"]
    fn.__source__ = src  # type: ignore[attr-defined]
    return fn


def check_names(fp: FastProgram) -> None:
    """Every name printed into the source passes :func:`fuzzyctl.escape.py_ident` (they are
    the program's ``FZ_`` names: a model name reaching here is refused, never printed)."""
    for name in sorted(identifiers(fp.program) | {*fp.inputs, *fp.outputs, fp.state}):
        py_ident(name, "generated name")


def _assigned(body: Sequence[Stmt], name: str) -> bool:
    return name not in needs_init([*body, Assign(Var("_probe"), Var(name))], {name})


def needs_init(body: Sequence[Stmt], scalars: set[str]) -> list[str]:
    """Scalar temporaries some path may read before assigning (they start at 0, as in C)."""
    out: set[str] = set()

    # The names defined on every path so far are a stack of sets, one per nesting level, so
    # that a branch does not copy all of them (linear, not quadratic, in long rule sections).
    def reads(e: Ex, defined: list[set[str]]) -> None:
        from fuzzyctl.ir.nodes import subexprs

        for sub in subexprs(e):
            if isinstance(sub, Var) and sub.name in scalars and not any(sub.name in d for d in defined):
                out.add(sub.name)

    def run(stmts: Sequence[Stmt], outer: list[set[str]]) -> set[str]:
        """The names ``stmts`` define on every path (beyond ``outer``)."""
        added: set[str] = set()
        defined = [*outer, added]
        for s in stmts:
            if isinstance(s, Assign):
                reads(s.value, defined)
                if isinstance(s.target, Index):
                    reads(s.target.index, defined)
                else:
                    added.add(s.target.name)
            elif isinstance(s, If):
                branch_sets = []
                for cond, b in s.branches:
                    reads(cond, defined)
                    branch_sets.append(run(b, defined))
                if s.orelse:  # without an else some path adds nothing
                    branch_sets.append(run(s.orelse, defined))
                    added |= set.intersection(*branch_sets)
            elif isinstance(s, For):
                reads(s.start, defined)
                reads(s.stop, defined)
                run(s.body, [*defined, {s.var}])
            elif isinstance(s, While):
                reads(s.cond, defined)
                run(s.body, defined)
            elif isinstance(s, Region):
                added |= run(s.body, defined)
            elif isinstance(s, Kernel):
                for a in s.args:
                    reads(a, defined)
                for o in s.outs:
                    if isinstance(o, Var):
                        added.add(o.name)
        return added

    run(body, [])
    return sorted(out)


class _PyTable(PythonPrinter):
    """The table block (:mod:`fuzzyctl.ir.programs.table_block`) in Python: a division of
    two index expressions is Python's integer division (``//``), as in ST and C."""

    def __init__(self, ints: set[str]) -> None:
        super().__init__(targets.PY)
        self.ints = ints

    def _integral(self, e: Ex) -> bool:
        if isinstance(e, Var):
            return e.name in self.ints
        if isinstance(e, Int):
            return True
        return (
            isinstance(e, Bin)
            and e.op in ("+", "-", "*")
            and self._integral(e.left)
            and self._integral(e.right)
        )

    def bin(self, e: Bin, parent: int, right: bool) -> str:
        if e.op == "/" and self._integral(e.left) and self._integral(e.right):
            return f"({self.ex(e.left, 5)} // {self.ex(e.right, 5, True)})"
        return super().bin(e, parent, right)


def table_function(block: Any, n_inputs: int, n_outputs: int) -> Callable[[Sequence[float]], list[float]]:
    """The table block as a Python function ``values -> outputs``.  ``block`` is built with
    the names ``FZ_IN<i>``, ``FZ_OUT<k>``, ``FZ_BP<i>``, ``FZ_TAB<k>`` (no model name reaches
    the source; every name is checked by :func:`fuzzyctl.escape.py_ident`)."""
    r = _PyTable({d.name for d in block.decls if d.kind == "index"})
    env: dict[str, Any] = {}
    for d in block.decls:
        py_ident(d.name, "generated name")
        if d.storage == "const":
            env[d.name] = tuple(float(v) for v in d.init)
    r.block(block.body, 1)
    head = [f"    FZ_IN{i} = v[{i}]" for i in range(n_inputs)]
    outs = ", ".join(f"FZ_OUT{k}" for k in range(n_outputs))
    src = "def _table(v):\n" + "\n".join(head + r.lines) + f"\n    return [{outs}]\n"
    exec(compile(src, "<fuzzyctl table>", "exec"), env)
    fn: Callable[[Sequence[float]], list[float]] = env["_table"]
    fn.__source__ = src  # type: ignore[attr-defined]
    return fn
