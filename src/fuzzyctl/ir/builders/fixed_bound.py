"""Bounds of an output's total weight over the whole input domain (branch and bound).

A weighted average (COGS, WTAVER) computed in integers is off by at most
``sum of the weights' errors * spread / total weight``: its worst-case error needs a lower
bound of the exact total weight (the denominator) over every input the block can be given.
:func:`weight_bounds` finds one by interval arithmetic on boxes of the input domain: a
piecewise-linear degree over an interval lies in the hull of its values at the ends and at
the breakpoints inside, the operators are monotone, so each box gets a rigorous interval of
the total weight; boxes whose lower end is far below the smallest value seen at a box centre
are bisected (at most ``budget`` boxes).  The result is rigorous whatever the budget, only
less tight when it runs out.

Degrees here are floats: the lower bound is lowered by a relative margin far above their
rounding."""

from __future__ import annotations

import heapq
import itertools
from collections.abc import Callable, Sequence
from dataclasses import dataclass

from fuzzyctl.engine.lowering.grid import left_limit, right_limit
from fuzzyctl.engine.plan import CAnd, CNot, CondPlan, COr, CTerm, CTrue, Plan
from fuzzyctl.engine.semantics.shapes import pwl_value
from fuzzyctl.ir.builders.fixed_smooth import SmoothTerm
from fuzzyctl.ir.builders.fixed_smooth import hull as smooth_hull
from fuzzyctl.kinds import norms

__all__ = ["Group", "WeightBounds", "input_cells", "rule_intervals", "weight_bounds"]

Iv = tuple[float, float]
Points = tuple[tuple[float, float], ...]
#: one item of a denominator: ``(accu, ((rule, weight), ...))`` - the accumulation (MAX or
#: SUM) of ``weight * rule degree`` over the contributions
Group = tuple[str, tuple[tuple[int, float], ...]]


@dataclass(frozen=True)
class WeightBounds:
    low: float  # rigorous lower bound of the total weight
    high: float  # rigorous upper bound
    witness: dict[int, float]  # input slot -> value where the smallest total was seen
    witness_total: float


def _hull(points: Points, a: float, b: float) -> Iv:
    vals = [pwl_value(points, a), pwl_value(points, b), right_limit(points, a), left_limit(points, b)]
    vals += [y for x, y in points if a < x < b]
    return min(vals), max(vals)


def _and(op: str, p: Iv, q: Iv) -> Iv:
    """``p AND q`` on intervals: a t-norm is monotone in each argument, so the images of the
    bounds, in the operator's fixed-point form (the integer code computes only those)."""
    match norms.TNORMS[op].fixed:
        case "min":
            return min(p[0], q[0]), min(p[1], q[1])
        case "product":
            return p[0] * q[0], p[1] * q[1]
        case "bounded_difference":
            return max(0.0, p[0] + q[0] - 1.0), max(0.0, p[1] + q[1] - 1.0)
    raise AssertionError(op)


def _or(op: str, p: Iv, q: Iv) -> Iv:
    """``p OR q`` on intervals (monotone, as :func:`_and`)."""
    match norms.SNORMS[op].fixed:
        case "max":
            return max(p[0], q[0]), max(p[1], q[1])
        case "probabilistic_sum":
            return p[0] + q[0] - p[0] * q[0], p[1] + q[1] - p[1] * q[1]
        case "bounded_sum":
            return min(1.0, p[0] + q[0]), min(1.0, p[1] + q[1])
    raise AssertionError(op)


def _cond(c: CondPlan, deg: Callable[[int, int], Iv]) -> Iv:
    if isinstance(c, CTerm):
        lo, hi = deg(c.var, c.term)
        return (1.0 - hi, 1.0 - lo) if c.negated else (lo, hi)
    if isinstance(c, CNot):
        lo, hi = _cond(c.operand, deg)
        return 1.0 - hi, 1.0 - lo
    if isinstance(c, CAnd | COr):
        combine = _and if isinstance(c, CAnd) else _or
        v = _cond(c.operands[0], deg)
        for o in c.operands[1:]:
            v = combine(c.op, v, _cond(o, deg))
        return v
    assert isinstance(c, CTrue)
    return 1.0, 1.0


def _degrees(plan: Plan, box: dict[int, Iv]) -> Callable[[int, int], Iv]:
    """The interval of each input term's degree over ``box`` (cached)."""
    slots = [fi.slot for fi in plan.fuzzy_inputs]
    cache: dict[tuple[int, int], Iv] = {}

    def deg(var: int, term: int) -> Iv:
        key = (var, term)
        if key not in cache:
            t = plan.fuzzy_inputs[var].terms[term]
            a, b = box[slots[var]]
            if isinstance(t, SmoothTerm):  # chords standing for a smooth term: their deviation too
                cache[key] = smooth_hull(t, a, b)
            else:
                assert t.pwl is not None
                cache[key] = _hull(t.pwl, a, b)
        return cache[key]

    return deg


def rule_intervals(plan: Plan, box: dict[int, Iv], weights: Sequence[float]) -> list[Iv]:
    """A rigorous interval of each rule's weighted degree over ``box`` (input slot ->
    interval)."""
    deg = _degrees(plan, box)
    out = []
    for ri, rule in enumerate(plan.rules):
        r = _cond(rule.condition, deg)
        out.append((r[0] * weights[ri], r[1] * weights[ri]))
    return out


def _total(plan: Plan, groups: Sequence[Group], box: dict[int, Iv], weights: Sequence[float]) -> Iv:
    deg = _degrees(plan, box)
    rules: dict[int, Iv] = {}
    lo = hi = 0.0
    for accu, items in groups:
        glo = ghi = 0.0
        for ri, w in items:
            if ri not in rules:
                r = _cond(plan.rules[ri].condition, deg)
                rules[ri] = (r[0] * weights[ri], r[1] * weights[ri])
            rlo, rhi = rules[ri]
            if norms.is_max(accu):
                glo, ghi = max(glo, w * rlo), max(ghi, w * rhi)
            else:
                glo, ghi = glo + w * rlo, ghi + w * rhi
        lo, hi = lo + glo, hi + ghi
    return lo, hi


def _cuts(plan: Plan, slot: int, a: float, b: float) -> list[float]:
    xs = {a, b}
    for fi in plan.fuzzy_inputs:
        if fi.slot == slot:
            for t in fi.terms:
                if not isinstance(t, SmoothTerm):  # (its many chords bend little: no cells)
                    xs.update(x for x, _y in t.pwl or () if a < x < b)
    return sorted(xs)


def input_cells(plan: Plan, domain: dict[int, Iv], budget: int) -> list[dict[int, Iv]]:
    """The boxes of ``domain`` between the input terms' breakpoints, where every degree is
    linear (an input whose cells would pass ``budget`` boxes stays whole)."""
    boxes: list[dict[int, Iv]] = [{}]
    for s in sorted(domain):
        cuts = _cuts(plan, s, *domain[s])
        pieces = list(itertools.pairwise(cuts)) or [(cuts[0], cuts[0])]
        if len(boxes) * len(pieces) > budget:
            pieces = [domain[s]]
        boxes = [{**bx, s: p} for bx in boxes for p in pieces]
    return boxes


def weight_bounds(
    plan: Plan,
    groups: Sequence[Group],
    weights: Sequence[float],
    domain: dict[int, Iv],
    budget: int = 6000,
    enough: float = 0.9,
) -> WeightBounds:
    """Bounds of ``sum over groups`` on ``domain`` (input slot -> interval of the values the
    block can be given); ``weights[r]`` is rule ``r``'s constant weight.  The search stops
    when the lower bound reaches ``enough`` times the smallest total seen."""
    slots = sorted(domain)
    boxes = input_cells(plan, domain, budget)
    heap: list[tuple[float, int, dict[int, Iv]]] = []
    high = 0.0
    best, witness = float("inf"), {s: domain[s][0] for s in slots}
    count = 0

    def push(bx: dict[int, Iv]) -> None:
        nonlocal high, best, witness, count
        lo, hi = _total(plan, groups, bx, weights)
        high = max(high, hi)
        centre = {s: (a + b) / 2 for s, (a, b) in bx.items()}
        v = _total(plan, groups, {s: (c, c) for s, c in centre.items()}, weights)[0]
        if v < best:
            best, witness = v, centre
        count += 1
        heapq.heappush(heap, (lo, count, bx))

    for bx in boxes:
        push(bx)
    while heap and count < budget:
        lo, _n, bx = heap[0]
        if lo >= enough * best or best <= 0.0:
            break
        heapq.heappop(heap)
        s = max(slots, key=lambda k: (bx[k][1] - bx[k][0]) / max(domain[k][1] - domain[k][0], 1e-300))
        a, b = bx[s]
        m = (a + b) / 2
        if not a < m < b:  # cannot split further: keep its bound
            heapq.heappush(heap, (lo, _n, {**bx, s: (a, a)}))
            break
        push({**bx, s: (a, m)})
        push({**bx, s: (m, b)})
    low = min((h[0] for h in heap), default=0.0)
    low = max(0.0, low * (1 - 1e-9) - 1e-12)
    return WeightBounds(low, high * (1 + 1e-9) + 1e-12, witness, best)
