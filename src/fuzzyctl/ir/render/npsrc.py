"""Print the evaluator program (:mod:`fuzzyctl.ir.programs.evaluator`) as one numpy function,
``_batch(v, state, n) -> outputs``, evaluating whole columns of samples at once.

The program is written for one sample; printed for columns it is *if-converted*: a value that
differs between samples (anything computed from an input) is an array, a condition on such
values a mask, and an assignment under a mask ``x = where(mask, new, x)``.  Values that are the
same for every sample (constants, loop counters) stay Python numbers and their IFs and loops
stay Python control flow.  Two patterns the IR writes for MIN and MAX (``t := b; IF a < t THEN
t := a``) become ``numpy.minimum``/``numpy.maximum``.  Kernels are the vectorised routines of
:mod:`fuzzyctl.ir.kernels.columns`; DEFAULT := NC is a running fill along the batch (rows are
successive evaluations of one instance).

A WHILE loop whose end depends on the sample runs while some sample's condition holds, its
body masked to those samples (the type reduction of type-2 systems).  A FOR loop whose bounds
depend on the sample, or an array index that does, is refused
(:class:`~fuzzyctl.ir.state.CodegenError`) unless the program is printed with ``gather``:
then the loop runs from the smallest start to the largest stop of the samples, its body
masked to the samples inside their own bounds, an array read at a per-sample index is a
gather (``take_along_axis``) and a write a masked store into every element the index may
name (what :mod:`fuzzyctl.ir.kernels.rendered` prints a method's IR with).
"""

from __future__ import annotations

import math
from collections.abc import Callable, Sequence
from typing import Any

import numpy as np

from fuzzyctl.engine.semantics import libm_np
from fuzzyctl.escape import py_str
from fuzzyctl.ir.kernels import columns as kernels_np
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
    Neg,
    Not,
    Num,
    Program,
    Pwl,
    Region,
    Stmt,
    Var,
    While,
    subexprs,
)
from fuzzyctl.ir.programs.evaluator import FastProgram
from fuzzyctl.ir.render.pysrc import PythonPrinter, check_names
from fuzzyctl.ir.state import CodegenError
from fuzzyctl.kinds import targets

Batch = Callable[[list[Any], list[float | None], int], list[Any]]


def varying_names(prog: Program, inputs: Sequence[str]) -> set[str]:
    """Names whose value can differ between samples (fixpoint over the program)."""
    vary = set(inputs)

    def ex_varies(e: Ex) -> bool:
        return any(isinstance(s, Var | Index) and s.name in vary for s in subexprs(e))

    def run(stmts: Sequence[Stmt], masked: bool) -> bool:
        changed = False
        for s in stmts:
            if isinstance(s, Assign):
                index_varies = isinstance(s.target, Index) and ex_varies(s.target.index)
                if (masked or ex_varies(s.value) or index_varies) and s.target.name not in vary:
                    vary.add(s.target.name)
                    changed = True
            elif isinstance(s, If):
                m = masked
                for cond, body in s.branches:
                    m = m or ex_varies(cond)
                    changed |= run(body, m)
                changed |= run(s.orelse, m)
            elif isinstance(s, For):
                changed |= run(s.body, masked or ex_varies(s.start) or ex_varies(s.stop))
            elif isinstance(s, While):
                changed |= run(s.body, masked or ex_varies(s.cond))
            elif isinstance(s, Region):
                changed |= run(s.body, masked)
            elif isinstance(s, Kernel):
                for o in s.outs:
                    if o.name not in vary:
                        vary.add(o.name)
                        changed = True
        return changed

    while run(prog.body, False):
        pass
    return vary


class _Np(PythonPrinter):
    """The Python printer, if-converted: ``self.mask`` is the mask of the samples the
    statements being printed apply to (None: all)."""

    def __init__(self, fp: FastProgram, gather: bool = False) -> None:
        super().__init__(targets.NP)
        self.fp = fp
        self.gather = gather
        self.vary = varying_names(fp.program, fp.inputs)
        self.mask: str | None = None
        self.env: dict[str, Any] = {
            "_np": np,
            "_libm": libm_np,
            "_w": np.where,
            "_and": np.logical_and,
            "_or": np.logical_or,
            "_not": np.logical_not,
            "_real": lambda x: x * 1.0,
            "_NAN": math.nan,
            "_INF": math.inf,
            "_take": _take,
            "_span": _span,
        }
        self.n_bound = 0
        self.n_masks = 0

    def bind(self, value: Any, prefix: str = "_k") -> str:
        name = f"{prefix}{self.n_bound}"
        self.n_bound += 1
        self.env[name] = value
        return name

    def varies(self, e: Ex) -> bool:
        return any(isinstance(s, Var | Index) and s.name in self.vary for s in subexprs(e))

    # ------------------------------------------------------------------ expressions

    def index(self, e: Index) -> str:
        if self.varies(e.index):
            if not self.gather:
                raise CodegenError("an array index that differs between samples cannot be if-converted")
            return f"_take({self.name(e.name)}, {self.ex(e.index)})"
        return super().index(e)

    def pwl(self, e: Pwl) -> str:
        return f"{self.bind(e.points, '_p')}_v({self.ex(e.x)})"

    # ------------------------------------------------------------------ statements

    def masked(self, body: Sequence[Stmt], ind: int, mask: str | None) -> None:
        """``body`` under ``mask`` (at the same depth: an if-converted branch)."""
        outer, self.mask = self.mask, mask
        try:
            self.block(body, ind)
        finally:
            self.mask = outer

    def store(self, target: Ex, value: str, ind: int) -> None:
        if isinstance(target, Index) and self.varies(target.index):
            # every element the per-sample index may name, each where the index names it
            arr, k, v = self.name(target.name), self.mask_name(), self.mask_name()
            self.emit(f"{v} = {value}", ind)
            self.emit(f"{k} = {self.ex(target.index)}", ind)
            self.emit(f"for _j in range(len({arr})):", ind)
            hit = f"{k} == _j" if self.mask is None else f"_and({self.mask}, {k} == _j)"
            self.emit(f"{arr}[_j] = _w({hit}, {v}, {arr}[_j])", ind + 1)
            return
        t = self.ex(target)
        self.emit(f"{t} = {value}" if self.mask is None else f"{t} = _w({self.mask}, {value}, {t})", ind)

    def assign(self, s: Assign, ind: int) -> None:
        self.store(s.target, self.ex(s.value), ind)

    def for_(self, s: For, ind: int) -> None:
        if not (self.varies(s.start) or self.varies(s.stop)):
            super().for_(s, ind)
            return
        if not self.gather:
            raise CodegenError("a loop whose bounds differ between samples cannot be if-converted")
        lo, hi, m = self.mask_name(), self.mask_name(), self.mask_name()
        self.emit(f"{lo} = {self.ex(s.start)}", ind)
        self.emit(f"{hi} = {self.ex(s.stop)}", ind)
        self.emit(f"for {s.var} in _span({lo}, {hi}, {self.mask}, {s.step}):", ind)
        first, last = (lo, hi) if s.step > 0 else (hi, lo)
        inside = f"({first} <= {s.var}) & ({s.var} <= {last})"
        self.emit(f"{m} = {inside}" if self.mask is None else f"{m} = _and({self.mask}, {inside})", ind + 1)
        self.masked(s.body, ind + 1, m)

    def while_(self, s: While, ind: int) -> None:
        """A loop whose end differs between samples runs while some sample's condition
        holds, its body under the mask of those samples (each sample iterates exactly as
        often as alone)."""
        if not self.varies(s.cond):
            super().while_(s, ind)
            return
        m = self.mask_name()
        c = self.ex(s.cond)
        self.emit(f"{m} = {c}" if self.mask is None else f"{m} = _and({self.mask}, {c})", ind)
        self.emit(f"while _np.any({m}):", ind)
        self.masked(s.body, ind + 1, m)
        self.emit(f"{m} = _and({m}, {self.ex(s.cond)})", ind + 1)

    def if_(self, s: If, ind: int) -> None:
        if not any(self.varies(c) for c, _b in s.branches):
            super().if_(s, ind)
            return
        minmax = _minmax(s)
        if minmax is not None:
            fn, target, value = minmax
            self.store(target, f"_np.{fn}({self.ex(target)}, {self.ex(value)})", ind)
            return
        rest = self.mask
        for cond, body in s.branches:
            m = self.mask_name()
            c = self.ex(cond)
            self.emit(f"{m} = {c}" if rest is None else f"{m} = _and({rest}, {c})", ind)
            self.masked(body, ind, m)
            r = self.mask_name()
            self.emit(f"{r} = _not({m})" if rest is None else f"{r} = _and({rest}, _not({m}))", ind)
            rest = r
        if s.orelse:
            self.masked(s.orelse, ind, rest)

    def mask_name(self) -> str:
        self.n_masks += 1
        return f"_m{self.n_masks}"

    def kernel(self, k: Kernel, ind: int) -> None:
        mask = self.mask
        if k.name == "HOLD":
            if mask is not None:
                raise CodegenError("DEFAULT / NC under a condition")
            oi, default, no_change, clamp = k.data
            value, fired = (self.ex(a) for a in k.args)
            fn = self.bind(kernels_np.hold(oi, default, no_change, clamp))
            self.emit(f"{self.ex(k.outs[0])} = {fn}(n, state, {value}, {fired})", ind)
            return
        fn = self.bind(kernels_np.make(k.name, k.data, self.fp.plan))
        args = ", ".join(self.ex(a) for a in k.args)
        if mask is None:
            outs = ", ".join(self.ex(o) for o in k.outs)
            self.emit(f"{outs}{',' if _tuple1(k) else ''} = {fn}(n, {args})", ind)
            return
        tmp = [f"_r{i}" for i in range(len(k.outs))]
        self.emit(f"{', '.join(tmp)}{',' if _tuple1(k) else ''} = {fn}(n, {args})", ind)
        for o, t in zip(k.outs, tmp, strict=True):
            self.store(o, t, ind)


def _take(arr: Sequence[Any], idx: Any) -> Any:
    """``arr[idx]`` per sample (a list of columns or numbers; indices out of range, which only
    masked-off samples can hold, are clipped)."""
    cols = np.broadcast_arrays(*(np.asarray(a) for a in arr), np.asarray(idx))
    at = np.clip(cols[-1].astype(np.intp), 0, len(arr) - 1)
    return np.take_along_axis(np.stack(cols[:-1]), at[None, ...], 0)[0]


def _span(lo: Any, hi: Any, mask: Any, step: int) -> range:
    """The counter values a loop from ``lo`` to ``hi`` takes in some sample under ``mask``."""
    lo, hi = np.broadcast_arrays(np.asarray(lo), np.asarray(hi))
    if mask is not None:
        sel = np.broadcast_to(mask, lo.shape)
        lo, hi = lo[sel], hi[sel]
    if lo.size == 0:
        return range(0)
    if step > 0:
        return range(int(lo.min()), int(hi.max()) + 1)
    return range(int(lo.max()), int(hi.min()) - 1, -1)


def _tuple1(k: Kernel) -> bool:
    """A kernel returning a tuple of one value (SELECT of a one-rule block)."""
    return len(k.outs) == 1 and k.name == "SELECT"


def _minmax(s: If) -> tuple[str, Var | Index, Ex] | None:
    """``IF a < t THEN t := a`` (``>``): the MIN (MAX) the IR spells with an IF."""
    if len(s.branches) != 1 or s.orelse:
        return None
    cond, body = s.branches[0]
    if len(body) != 1 or not isinstance(body[0], Assign) or not isinstance(cond, Bin):
        return None
    if cond.op not in ("<", ">"):
        return None
    target, value = body[0].target, body[0].value
    if not _same(cond.right, target):
        return None
    if not _same(cond.left, value):
        return None
    return ("minimum" if cond.op == "<" else "maximum"), target, value


def _same(a: Ex, b: Ex) -> bool:
    if type(a) is not type(b):
        return False
    if isinstance(a, Num | Int | Bool):
        return a.value == b.value  # type: ignore[attr-defined, no-any-return]
    if isinstance(a, Var):
        return a.name == b.name  # type: ignore[attr-defined, no-any-return]
    if isinstance(a, Index):
        return a.name == b.name and _same(a.index, b.index)  # type: ignore[attr-defined]
    if isinstance(a, Bin):
        return a.op == b.op and _same(a.left, b.left) and _same(a.right, b.right)  # type: ignore[attr-defined]
    if isinstance(a, Neg | Not):
        return _same(a.operand, b.operand)  # type: ignore[attr-defined]
    return a is b


def render_np(fp: FastProgram, gather: bool = False) -> tuple[str, dict[str, Any]]:
    """The source of ``_batch`` and the globals it needs (``gather``: see the module
    docstring)."""
    r = _Np(fp, gather)
    prog = fp.program
    check_names(fp)
    for d in prog.of("const"):
        assert isinstance(d.init, tuple)
        r.env[d.name] = tuple(float(v) if d.type == "REAL" else int(v) for v in d.init)
    r.block(prog.body, 2)
    body = r.lines
    head = [f"    {name} = v[{k}]" for k, name in enumerate(fp.inputs)]
    for d in prog.of("temp") + prog.of("output"):
        if d.size is not None:
            head.append(f"    {d.name} = [0.0] * {d.size}")
        else:
            head.append(f"    {d.name} = 0.0")
    for name, value in list(r.env.items()):
        if name.startswith("_p") and isinstance(value, tuple):
            r.env[name + "_v"] = lambda x, pts=value: kernels_np.pwl_membership(pts, x)
    outs = ", ".join(f"_full(n, {o})" for o in fp.outputs)
    r.env["_full"] = kernels_np.full
    src = (
        "def _batch(v, state, n):\n"
        + "\n".join(head)
        + "\n    with _np.errstate(all='ignore'):\n"
        + "\n".join(body)
        + f"\n    return [{outs}]\n"
    )
    return src, r.env


def vectorise(fp: FastProgram, gather: bool = False) -> Batch:
    """Compile the rendered source into the function."""
    src, env = render_np(fp, gather)
    exec(compile(src, f"<fuzzyctl batch evaluator {py_str(fp.plan.name or '')}>", "exec"), env)
    fn: Batch = env["_batch"]
    fn.__source__ = src  # type: ignore[attr-defined]
    return fn
