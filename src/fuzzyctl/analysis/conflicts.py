"""Conflicts (consistency): two rules that fire together above ``delta`` and conclude terms
of one output whose supports do not overlap.

"Fire together" is the joint degree ``min(degree 1, degree 2)``.  For conjunctive rules
(rows of :mod:`fuzzyctl.analysis.table`) its highest value is bounded by
``min over inputs of max_x min(leaf 1, leaf 2)`` (equal to it under AND = MIN, where the
maximum is separable); every pair above ``delta`` by that bound is evaluated by the engine
at the point reaching it, and reported only when the engine's joint degree exceeds delta.
Default ``delta = 0.5``, compared strictly: two rules that differ in the term of one input
whose terms form a partition (degrees summing to at most 1) never both exceed 0.5 there, so
the neighbouring cells of a rule table never count; rules whose premises overlap more (the
same premise, or one premise contained in the other) and that conclude far-apart terms do."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from fuzzyctl.analysis.cells import Axis
from fuzzyctl.analysis.context import Context, leaf_values
from fuzzyctl.analysis.table import AxisLeaves, Row, leaf_matrix
from fuzzyctl.engine.explain import Explanation
from fuzzyctl.engine.plan import TermPlan
from fuzzyctl.engine.semantics import shapes
from fuzzyctl.engine.semantics.operators import TNORMS
from fuzzyctl.kinds import shapes as registry

DEFAULT_DELTA = 0.5
#: conflicts reported at most (each is confirmed by an explanation of the whole block)
MAX_CONFLICTS = 100


@dataclass(frozen=True)
class Conflict:
    rules: tuple[str, str]
    where: tuple[str | None, str | None]
    output: str
    terms: tuple[str, str]
    box: dict[str, tuple[float, float]]
    joint_degree: float
    point: dict[str, float]


def term_support(t: TermPlan) -> tuple[float, float] | None:
    """The closed support of an output term (a point for singletons), None when unknown."""
    if not t.constant:
        return None
    if t.kind == "singleton" or registry.flag(t.kind, "ts_constant"):
        v = float(t.params[0])  # type: ignore[arg-type]
        return (v, v)
    if t.kind == "function" or registry.flag(t.kind, "ts_linear"):
        return None
    try:
        return shapes.support(t.kind, [float(p) for p in t.params], float(t.height))  # type: ignore[arg-type]
    except (ValueError, AssertionError):
        return None


def disjoint(a: tuple[float, float] | None, b: tuple[float, float] | None) -> bool:
    """No overlap of the open supports (two singletons: different positions)."""
    if a is None or b is None:
        return False
    if a[0] == a[1] and b[0] == b[1]:
        return a[0] != b[0]
    return max(a[0], b[0]) >= min(a[1], b[1])


def _concluded(ctx: Context, rows: list[Row], o: int) -> list[tuple[Row, int]]:
    out = []
    for row in rows:
        for cp in ctx.plan.rules[row.rule].conclusions:
            if o in cp.outputs and cp.term is not None:
                out.append((row, cp.term))
                break
    return out


def find_conflicts(
    ctx: Context, axes: list[Axis], rows: list[Row], tables: dict[int, AxisLeaves], delta: float
) -> list[Conflict]:
    found: list[Conflict] = []
    for o, op in enumerate(ctx.plan.outputs):
        if not op.is_output or op.kind == "degree":
            continue
        pairs = _concluded(ctx, rows, o)
        if len(pairs) < 2:
            continue
        sup = [term_support(t) for t in op.terms]
        apart = np.array([[disjoint(a, b) for b in sup] for a in sup], dtype=bool)
        found += _output_conflicts(ctx, axes, pairs, tables, apart, delta, o)
    return found


def _output_conflicts(
    ctx: Context,
    axes: list[Axis],
    pairs: list[tuple[Row, int]],
    tables: dict[int, AxisLeaves],
    apart: np.ndarray,
    delta: float,
    o: int,
) -> list[Conflict]:
    rows = [r for r, _t in pairs]
    terms = np.array([t for _r, t in pairs])
    weights = np.array([r.weight for r in rows])
    slots, mat = leaf_matrix(rows, tables)
    mm = [tables[s].max_min() for s in slots]
    out: list[Conflict] = []
    n = len(rows)
    for start in range(0, n, 256):
        i = np.arange(start, min(n, start + 256))
        ub = np.minimum(weights[i][:, None], weights[None, :])
        for k in range(len(slots)):
            ub = np.minimum(ub, mm[k][mat[i, k][:, None], mat[None, :, k]])
        # (1e-9: the bound comes from interpolated crossings; 0.5 + 1 ulp is 0.5)
        cand = (ub > delta + 1e-9) & apart[terms[i]][:, terms] & (i[:, None] < np.arange(n)[None, :])
        for a, b in zip(*np.nonzero(cand), strict=True):
            if len(out) >= MAX_CONFLICTS:
                return out
            c = _verify(ctx, axes, rows[i[a]], rows[b], terms[i[a]], terms[b], slots, mat, tables, delta, o)
            if c is not None:
                out.append(c)
    return out


def explained(ctx: Context, point: dict[str, float]) -> Explanation:
    """The engine's explanation at ``point`` (pairs meeting at one point share it)."""
    cache = ctx.explained
    key = tuple(point.values())
    got = cache.get(key)
    if got is None:
        if len(cache) > 256:
            cache.clear()
        got = cache[key] = ctx.controller.explain(point)
    assert isinstance(got, Explanation)
    return got


def _row_degree(ctx: Context, row: Row, point: dict[str, float]) -> float:
    """A conjunctive rule's degree at ``point`` with the engine's leaf and norm functions."""
    norm = TNORMS[row.op].scalar
    d: float | None = None
    for slot, leaf in row.leaves.items():
        v = float(leaf_values(ctx.plan, leaf, np.array([point[ctx.inputs[slot]]]))[0])  # type: ignore[arg-type]
        d = v if d is None else norm(d, v)
    return (1.0 if d is None else d) * row.weight


def _verify(
    ctx: Context,
    axes: list[Axis],
    r1: Row,
    r2: Row,
    t1: int,
    t2: int,
    slots: list[int],
    mat: np.ndarray,
    tables: dict[int, AxisLeaves],
    delta: float,
    o: int,
) -> Conflict | None:
    point = {a.name: 0.5 * (a.low + a.high) for a in axes}
    box = {a.name: (a.low, a.high) for a in axes}
    for s in slots:
        tab = tables[s]
        i, j = tab.of(r1.leaves.get(s)), tab.of(r2.leaves.get(s))
        point[axes[s].name] = tab.argmax_min(i, j)
        box[axes[s].name] = tab.above(i, j, delta)
    if min(_row_degree(ctx, r1, point), _row_degree(ctx, r2, point)) <= delta:
        return None  # (a cheap look first: the bound is loose under PROD)
    ex = explained(ctx, point)
    joint = min(ex.rules[r1.rule].degree, ex.rules[r2.rule].degree)
    if not joint > delta:
        return None
    op = ctx.plan.outputs[o]
    return Conflict(
        (ctx.rule_names[r1.rule], ctx.rule_names[r2.rule]),
        (ctx.rule_where[r1.rule], ctx.rule_where[r2.rule]),
        op.name,
        (op.terms[t1].name, op.terms[t2].name),
        box,
        float(joint),
        point,
    )
