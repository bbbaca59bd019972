"""Redundancy: duplicate rules, rules subsumed by another with the same conclusion, rules
that never fire, input terms no rule reads and output terms no live rule concludes.

* duplicate: same rule block, same leaves (in any order), same AND, weight and conclusions.
* subsumed: same block and conclusions; the covering rule reads a subset of the inputs, its
  leaf on each is >= the other's leaf everywhere on the axis, its AND is the same t-norm or
  MIN (or it has one leaf), and its weight is not lower - so its degree is >= the other's
  everywhere (t-norms are monotone and T(a, 1) = a).  Reported only when every output it
  concludes accumulates with MAX: under a sum the covered rule still adds its share.
* dead: the rule's degree is 0 (at most the firing threshold) at every cell of the
  decomposition (:mod:`fuzzyctl.analysis.cells`)."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from fuzzyctl.analysis.context import Context
from fuzzyctl.analysis.table import AxisLeaves, Row, leaf_matrix
from fuzzyctl.kinds import norms


@dataclass(frozen=True)
class Redundant:
    rule: str
    covered_by: str
    kind: str  # "duplicate" | "subsumed"


@dataclass(frozen=True)
class UnusedTerm:
    variable: str
    term: str
    reason: str  # "never read" | "never concluded" | "concluded only by dead rules"


def _signature(ctx: Context, row: Row) -> tuple[object, ...]:
    r = ctx.plan.rules[row.rule]
    return (r.block, r.conclusions, r.act)


def _max_accumulation(ctx: Context, row: Row) -> bool:
    plan = ctx.plan
    for cp in plan.rules[row.rule].conclusions:
        for o in cp.outputs:
            op = plan.outputs[o]
            if op.kind == "ts" or not norms.accumulates_by_max(op.accu):
                return False
        if any(not norms.is_max(plan.chained[c].accu) for c in cp.chained):
            return False
    return True


def find_redundant(
    ctx: Context, rows: list[Row], tables: dict[int, AxisLeaves], dead: set[int]
) -> list[Redundant]:
    groups: dict[tuple[object, ...], list[Row]] = {}
    for row in rows:
        if row.rule not in dead:
            groups.setdefault(_signature(ctx, row), []).append(row)
    dom = {s: t.dominates() for s, t in tables.items()}
    out: list[Redundant] = []
    for group in groups.values():
        if len(group) > 1:
            out += _group(ctx, group, tables, dom)
    return sorted(out, key=lambda r: ctx.rule_names.index(r.rule))


def _group(
    ctx: Context, group: list[Row], tables: dict[int, AxisLeaves], dom: dict[int, np.ndarray]
) -> list[Redundant]:
    slots, mat = leaf_matrix(group, tables)
    n = len(group)
    absent = np.array([len(tables[s].index) for s in slots], dtype=np.int64)
    cover = np.ones((n, n), dtype=bool)  # cover[b, a]: b's degree >= a's everywhere
    for k, s in enumerate(slots):
        cover &= dom[s][mat[:, k][:, None], mat[None, :, k]]
    subset = np.all(
        (mat[:, None, :] == absent) | (mat[None, :, :] != absent), axis=2
    )  # b reads a subset of a
    weights = np.array([r.weight for r in group])
    ops = np.array([r.op for r in group])
    single = np.array([len(r.leaves) <= 1 or norms.is_min(r.op) for r in group])
    ops_ok = single[:, None] | (ops[:, None] == ops[None, :])
    cover &= subset & (weights[:, None] >= weights[None, :]) & ops_ok
    np.fill_diagonal(cover, False)
    same = np.all(mat[:, None, :] == mat[None, :, :], axis=2) & (weights[:, None] == weights[None, :])
    out = []
    for a in range(n):
        for b in np.nonzero(cover[:, a])[0]:
            if cover[a, b] and a < b:
                continue  # equivalent rules: the later one is the redundant one
            ra, rb = group[a], group[b]
            if same[a, b] and ra.op == rb.op:
                out.append(Redundant(ctx.rule_names[ra.rule], ctx.rule_names[rb.rule], "duplicate"))
            elif _max_accumulation(ctx, ra):
                out.append(Redundant(ctx.rule_names[ra.rule], ctx.rule_names[rb.rule], "subsumed"))
            else:
                continue
            break
    return out


def find_unused(ctx: Context, dead: set[int]) -> list[UnusedTerm]:
    from fuzzyctl.analysis.cells import leaves
    from fuzzyctl.engine.plan import CTerm

    plan = ctx.plan
    read = {
        (leaf.var, leaf.term) for r in plan.rules for leaf in leaves(r.condition) if isinstance(leaf, CTerm)
    }
    out = [
        UnusedTerm(fi.name, t.name, "never read")
        for v, fi in enumerate(plan.fuzzy_inputs)
        for k, t in enumerate(fi.terms)
        if (v, k) not in read
    ]
    live: set[tuple[int, int]] = set()
    any_rule: set[tuple[int, int]] = set()
    for ri, r in enumerate(plan.rules):
        for cp in r.conclusions:
            for o in cp.outputs:
                if cp.term is not None:
                    any_rule.add((o, cp.term))
                    if ri not in dead:
                        live.add((o, cp.term))
    for o, op in enumerate(plan.outputs):
        if op.kind == "degree":
            continue
        for k, t in enumerate(op.terms):
            if (o, k) not in any_rule:
                out.append(UnusedTerm(op.name, t.name, "never concluded"))
            elif (o, k) not in live:
                out.append(UnusedTerm(op.name, t.name, "concluded only by dead rules"))
    return out
