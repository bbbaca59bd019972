"""Rules as a table: a rule whose condition is one leaf or an AND of leaves on distinct
inputs (the shape of almost every rule base) is a row ``input slot -> leaf``.  Comparisons
between two rows reduce to comparisons of one-input functions, computed here once per
pair of leaves of an axis on a fine abscissa: every cut of the axis (breakpoints, supports,
level crossings), ``cells.SAMPLES`` evenly spaced points, and where two piecewise-linear
leaves cross between two of them (exact for piecewise-linear leaves)."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from fuzzyctl.analysis.cells import SAMPLES, Axis
from fuzzyctl.analysis.context import Context, FloatArray, constant, leaf_axis, leaf_values
from fuzzyctl.engine.plan import CAnd, CDegree, CondPlan, CTerm, CTrue


@dataclass(frozen=True)
class Row:
    """A conjunctive rule: ``leaves[slot]`` is its leaf on that input."""

    rule: int
    op: str  # its AND (MIN when it has one leaf)
    leaves: dict[int, CondPlan]
    weight: float


def as_row(ctx: Context, ri: int) -> Row | None:
    r = ctx.plan.rules[ri]
    w = constant(r.weight)
    if w is None:
        return None
    c = r.condition
    items = list(c.operands) if isinstance(c, CAnd) else ([] if isinstance(c, CTrue) else [c])
    leaves: dict[int, CondPlan] = {}
    for leaf in items:
        if not isinstance(leaf, CTerm | CDegree):
            return None
        slot = leaf_axis(ctx.plan, leaf)
        if slot is None or slot in leaves:
            return None
        leaves[slot] = leaf
    return Row(ri, c.op if isinstance(c, CAnd) else "MIN", leaves, w)


class AxisLeaves:
    """Every leaf of one axis on a fine abscissa; index ``len(leaves)`` is "no leaf" (1)."""

    def __init__(self, ctx: Context, axis: Axis, slot: int, leaves: list[CondPlan]) -> None:
        self.axis = axis
        self.index = {leaf: k for k, leaf in enumerate(leaves)}
        xs = np.unique(np.concatenate([axis.cuts, np.linspace(axis.low, axis.high, SAMPLES)]))
        self.xs = xs
        vals = [leaf_values(ctx.plan, leaf, xs) for leaf in leaves]  # type: ignore[arg-type]
        vals.append(np.ones_like(xs))
        self.values: FloatArray = np.array(vals)

    def of(self, leaf: CondPlan | None) -> int:
        return len(self.index) if leaf is None else self.index[leaf]

    def max_min(self) -> FloatArray:
        """``M[i, j]``: the highest value of min(leaf i, leaf j) on the axis."""
        v = self.values
        n = len(v)
        out = np.zeros((n, n))
        for i in range(n):
            lo = np.minimum(v[i][None, :], v)
            best = lo.max(axis=1)
            d = v[i][None, :] - v  # crossings between samples: both lines meet there
            s = d[:, :-1] * d[:, 1:] < 0
            if s.any():
                t = np.where(s, d[:, :-1] / np.where(s, d[:, :-1] - d[:, 1:], 1.0), 0.0)
                y = v[i][:-1] + (v[i][1:] - v[i][:-1]) * t
                best = np.maximum(best, np.where(s, y, 0.0).max(axis=1))
            out[i] = best
        return out

    def dominates(self) -> np.ndarray:
        """``D[i, j]``: leaf i >= leaf j everywhere on the axis (1e-12 slack)."""
        v = self.values
        return np.asarray(np.all(v[:, None, :] >= v[None, :, :] - 1e-12, axis=2))

    def above(self, i: int, j: int, delta: float) -> tuple[float, float]:
        """The hull of where min(leaf i, leaf j) > delta (the whole axis when empty)."""
        v = np.minimum(self.values[i], self.values[j]) - delta
        idx = np.nonzero(v > 0)[0]
        if not len(idx):
            return (self.axis.low, self.axis.high)
        xs = self.xs
        a, b = int(idx[0]), int(idx[-1])
        lo, hi = float(xs[a]), float(xs[b])
        # the crossing between the last sample below and the first above (linear there)
        if a > 0:
            lo = float(xs[a - 1] + (xs[a] - xs[a - 1]) * v[a - 1] / (v[a - 1] - v[a]))
        if b + 1 < len(xs):
            hi = float(xs[b] + (xs[b + 1] - xs[b]) * v[b] / (v[b] - v[b + 1]))
        return (lo, hi)

    def argmax_min(self, i: int, j: int) -> float:
        m = np.minimum(self.values[i], self.values[j])
        return float(self.xs[int(np.argmax(m))])


def axis_leaves(ctx: Context, axes: list[Axis], rows: list[Row]) -> dict[int, AxisLeaves]:
    per: dict[int, dict[CondPlan, None]] = {}
    for row in rows:
        for slot, leaf in row.leaves.items():
            per.setdefault(slot, {})[leaf] = None
    return {slot: AxisLeaves(ctx, axes[slot], slot, list(ls)) for slot, ls in per.items()}


def leaf_matrix(rows: list[Row], tables: dict[int, AxisLeaves]) -> tuple[list[int], np.ndarray]:
    """``L[r, k]``: the leaf index of row r on the k-th table axis."""
    slots = sorted(tables)
    mat = np.array([[tables[s].of(row.leaves.get(s)) for s in slots] for row in rows], dtype=np.int64)
    return slots, mat.reshape(len(rows), len(slots))
