"""The lookup-table block as IR: each input limited to its breakpoints, its interval found by
binary search, the cell's corners interpolated multi-linearly (the last input first).

Built from plain numbers (breakpoints and entries, in engineering units or stored integers)
so that it depends on nothing above the IR; :mod:`fuzzyctl.codegen.lookup_st` and
:mod:`fuzzyctl.codegen.lookup_c` render it, and :mod:`fuzzyctl.ir.cost` counts it.

In integers (``integer=True``) the entries are read widened (``WIDEN``), each step is
``a + ((b - a) * D) / W`` with ``D`` the input's offset in its interval and ``W`` the
interval's width (one truncating division per input), and the result is narrowed back."""

from __future__ import annotations

import itertools
import math
from collections.abc import Sequence
from dataclasses import dataclass

from fuzzyctl.ir.nodes import Builder, Call, Ex, Stmt, Var, ex

#: the block's own names (inputs and outputs are the model's)
PREFIX = "LK_"


@dataclass(frozen=True)
class TableDecl:
    """A variable of the table block.  ``kind``: ``value`` (REAL, or the stored integer),
    ``wide`` (REAL, or the integer type of products), ``index`` (DINT), ``byte``."""

    name: str
    kind: str
    storage: str  # input, output, const, temp
    size: int | None = None
    init: tuple[float, ...] | None = None
    comment: str = ""


@dataclass
class TableBlock:
    name: str
    decls: list[TableDecl]
    body: list[Stmt]


def names(inputs: Sequence[str], outputs: Sequence[str]) -> tuple[list[str], list[str]]:
    """The breakpoint and entry arrays' names."""
    return [f"BP_{n}" for n in inputs], [f"TAB_{n}" for n in outputs]


def _widen(e: Ex, integer: bool) -> Ex:
    return Call("WIDEN", (e,)) if integer else e


def _interval(b: Builder, i: int, name: str, bp: str, n: int, integer: bool) -> None:
    x, lo, hi, mid = (Var(f"{PREFIX}{w}") for w in (f"X{i}", "LO", "HI", "MID"))
    arr = Var(bp)
    b.set(x, Var(name))
    with b.if_(x.lt(arr[0])):
        b.set(x, arr[0])
    with b.if_(x.gt(arr[n - 1])):
        b.set(x, arr[n - 1])
    b.set(lo, 0)
    b.set(hi, n - 1)
    with b.while_((hi - lo).gt(1), bound=max(1, math.ceil(math.log2(max(n - 1, 1))))):
        b.set(mid, (lo + hi) / 2)
        with b.if_(arr[mid].le(x)):
            b.set(lo, mid)
        with b.else_():
            b.set(hi, mid)
    b.set(Var(f"{PREFIX}I{i}"), lo)
    if integer:
        b.set(Var(f"{PREFIX}D{i}"), _widen(x - arr[lo], True))
        b.set(Var(f"{PREFIX}W{i}"), _widen(arr[lo + 1] - arr[lo], True))
    else:
        b.set(Var(f"{PREFIX}F{i}"), (x - arr[lo]) / (arr[lo + 1] - arr[lo]))


def build_table_block(
    name: str,
    inputs: Sequence[str],
    outputs: Sequence[str],
    axes: Sequence[Sequence[float]],
    values: Sequence[Sequence[float]],
    *,
    integer: bool,
    arrays: tuple[list[str], list[str]] | None = None,
) -> TableBlock:
    """The block of a table: ``axes[i]`` input ``i``'s breakpoints, ``values[k]`` output
    ``k``'s entries (last input fastest); stored integers when ``integer``; ``arrays``: the
    breakpoint and entry arrays' names (default :func:`names`)."""
    d = len(axes)
    shape = [len(a) for a in axes]
    bps, tabs = arrays or names(inputs, outputs)
    decls = [TableDecl(n, "value", "input") for n in inputs]
    decls += [TableDecl(n, "value", "output") for n in outputs]
    decls.append(
        TableDecl("INFO", "byte", "output", comment="always 16#00: rules fire everywhere in the input ranges")
    )
    decls += [
        TableDecl(bp, "value", "const", len(a), tuple(a), f"breakpoints of {n}")
        for bp, a, n in zip(bps, axes, inputs, strict=True)
    ]
    decls += [
        TableDecl(t, "value", "const", len(v), tuple(v), f"{n} at the breakpoints (last input fastest)")
        for t, v, n in zip(tabs, values, outputs, strict=True)
    ]
    decls += [TableDecl(f"{PREFIX}{w}", "index", "temp") for w in ("LO", "HI", "MID", "K")]
    decls += [TableDecl(f"{PREFIX}X{i}", "value", "temp") for i in range(d)]
    decls += [TableDecl(f"{PREFIX}I{i}", "index", "temp") for i in range(d)]
    if integer:
        decls += [TableDecl(f"{PREFIX}{w}{i}", "wide", "temp") for i in range(d) for w in ("D", "W")]
    else:
        decls += [TableDecl(f"{PREFIX}F{i}", "wide", "temp") for i in range(d)]
    b = Builder()
    b.comment("each input limited to its range; its interval found by binary search")
    for i, (inp, bp) in enumerate(zip(inputs, bps, strict=True)):
        _interval(b, i, inp, bp, shape[i], integer)
    strides = [math.prod(shape[i + 1 :]) for i in range(d)]
    k = Var(f"{PREFIX}K")
    total: Ex = ex(0)
    for i, s in enumerate(strides):
        total = total + Var(f"{PREFIX}I{i}") * s
    b.set(k, total)
    temps: set[str] = set()
    for out, tab in zip(outputs, tabs, strict=True):
        b.comment(f"{out}: the cell's corners interpolated, last input first")
        arr = Var(tab)
        corners: dict[tuple[int, ...], Ex] = {
            c: _widen(arr[k + sum(ci * s for ci, s in zip(c, strides, strict=True))], integer)
            for c in itertools.product((0, 1), repeat=d)
        }
        for axis in range(d - 1, -1, -1):
            reduced: dict[tuple[int, ...], Ex] = {}
            for prefix in itertools.product((0, 1), repeat=axis):
                lo_, hi_ = corners[(*prefix, 0)], corners[(*prefix, 1)]
                if integer:
                    step = lo_ + ((hi_ - lo_) * Var(f"{PREFIX}D{axis}")) / Var(f"{PREFIX}W{axis}")
                else:
                    step = lo_ + (hi_ - lo_) * Var(f"{PREFIX}F{axis}")
                if axis == 0:
                    reduced[prefix] = step
                    continue
                tmp = f"{PREFIX}V{''.join(map(str, prefix))}_{axis}"
                if tmp not in temps:
                    temps.add(tmp)
                    decls.append(TableDecl(tmp, "wide", "temp"))
                b.set(Var(tmp), step)
                reduced[prefix] = Var(tmp)
            corners = reduced
        final = corners[()]
        b.set(Var(out), Call("NARROW", (final,)) if integer else final)
    b.set(Var("INFO"), 0)
    return TableBlock(name, decls, b.root)
