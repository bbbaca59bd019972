"""The output grid: the defuzzification interval cut at every breakpoint of every term, so
that every term is linear on every grid interval (see :class:`~fuzzyctl.engine.plan.GridPlan`)."""

from __future__ import annotations

from collections.abc import Sequence

from fuzzyctl.engine.plan import GridPlan
from fuzzyctl.engine.shapes import Points, pwl_value


def right_limit(points: Points, x: float) -> float:
    """lim_{u -> x+} of a breakpoint list."""
    n = len(points)
    if x < points[0][0]:
        return points[0][1]
    if x >= points[n - 1][0]:
        return points[n - 1][1]
    for i in range(n - 1, -1, -1):
        if points[i][0] == x:
            return points[i][1]
    return _interp(points, x)


def left_limit(points: Points, x: float) -> float:
    """lim_{u -> x-} of a breakpoint list."""
    n = len(points)
    if x <= points[0][0]:
        return points[0][1]
    if x > points[n - 1][0]:
        return points[n - 1][1]
    for i in range(n):
        if points[i][0] == x:
            return points[i][1]
    return _interp(points, x)


def _interp(points: Points, x: float) -> float:
    for i in range(1, len(points)):
        x1, y1 = points[i]
        if x1 > x:
            x0, y0 = points[i - 1]
            return y0 + (y1 - y0) * ((x - x0) / (x1 - x0))
    return points[-1][1]


def build_grid(terms: Sequence[Points], low: float, high: float) -> GridPlan:
    """Cut ``[low, high]`` at every breakpoint of ``terms``."""
    cuts = {low, high}
    for pts in terms:
        for x, _y in pts:
            if low < x < high:
                cuts.add(x)
    xs = tuple(sorted(cuts))
    left = tuple(tuple(right_limit(p, xs[j]) for j in range(len(xs) - 1)) for p in terms)
    right = tuple(tuple(left_limit(p, xs[j + 1]) for j in range(len(xs) - 1)) for p in terms)
    point = tuple(tuple(pwl_value(p, x) for x in xs) for p in terms)
    active = tuple(
        tuple(t for t in range(len(terms)) if left[t][j] != 0.0 or right[t][j] != 0.0) for j in range(len(xs) - 1)
    )
    return GridPlan(xs, left, right, point, active)
