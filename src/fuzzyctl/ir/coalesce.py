"""Renaming a variable in statements already built, so that a temporary can take the name of
what it turned out to hold (``FZ_RULE_13`` instead of ``FZ_T12`` copied into ``FZ_R12``): one
variable and one assignment fewer per rule, and a name a reader can search for."""

from __future__ import annotations

from collections.abc import Sequence

from fuzzyctl.ir.nodes import (
    Assign,
    Bin,
    Call,
    Ex,
    For,
    If,
    Index,
    Kernel,
    Neg,
    Not,
    Pwl,
    Region,
    Stmt,
    Var,
    While,
)
from fuzzyctl.ir.state import Gen


def rename_ex(e: Ex, old: str, new: str) -> Ex:
    """``e`` with every use of variable (or array) ``old`` reading ``new``."""
    if isinstance(e, Var):
        return Var(new) if e.name == old else e
    if isinstance(e, Index):
        return Index(new if e.name == old else e.name, rename_ex(e.index, old, new))
    if isinstance(e, Bin):
        return Bin(e.op, rename_ex(e.left, old, new), rename_ex(e.right, old, new))
    if isinstance(e, Neg):
        return Neg(rename_ex(e.operand, old, new))
    if isinstance(e, Not):
        return Not(rename_ex(e.operand, old, new))
    if isinstance(e, Call):
        return Call(e.function, tuple(rename_ex(a, old, new) for a in e.args))
    if isinstance(e, Pwl):
        return Pwl(rename_ex(e.x, old, new), e.points)
    return e


def _target(t: Var | Index, old: str, new: str) -> Var | Index:
    out = rename_ex(t, old, new)
    assert isinstance(out, Var | Index)
    return out


def rename(stmts: Sequence[Stmt], old: str, new: str) -> None:
    """Rewrite ``stmts`` in place: variable ``old`` becomes ``new`` (the caller renames its
    declaration)."""
    for s in stmts:
        if isinstance(s, Assign):
            s.target = _target(s.target, old, new)
            s.value = rename_ex(s.value, old, new)
        elif isinstance(s, If):
            s.branches = [(rename_ex(c, old, new), body) for c, body in s.branches]
            for _c, body in s.branches:
                rename(body, old, new)
            rename(s.orelse, old, new)
        elif isinstance(s, For):
            s.start, s.stop = rename_ex(s.start, old, new), rename_ex(s.stop, old, new)
            rename(s.body, old, new)
        elif isinstance(s, While):
            s.cond = rename_ex(s.cond, old, new)
            rename(s.body, old, new)
        elif isinstance(s, Region):
            rename(s.body, old, new)
        elif isinstance(s, Kernel):
            s.outs = tuple(_target(o, old, new) for o in s.outs)
            s.args = tuple(rename_ex(a, old, new) for a in s.args)


def share_temps(
    g: Gen, decl_mark: int, stmts: Sequence[Stmt], pool: list[tuple[str, str]], what: str
) -> None:
    """The scalar temporaries declared since ``decl_mark`` and used only in ``stmts`` (one
    step whose value is consumed there: an activation, say) take the names of ``pool``, the
    temporaries of the previous such steps, one per position and type; the pool grows with
    new ones named ``what``.  Fewer temporaries: IEC 61131-3 initialises each VAR_TEMP on
    every call."""
    new = [d for d in g.decls[decl_mark:] if d.storage == "temp" and d.size is None]
    for k, d in enumerate(new):
        if k < len(pool) and pool[k][1] == d.type:
            rename(stmts, d.name, pool[k][0])
            g.decls.remove(d)
            g.names.discard(d.name.upper())
        elif k >= len(pool):
            name = g.named(what)
            rename(stmts, d.name, name)
            g.names.discard(d.name.upper())
            g.names.add(name.upper())
            d.name = name
            pool.append((name, d.type))
