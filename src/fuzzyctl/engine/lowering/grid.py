"""The output grid: the defuzzification interval cut at every breakpoint of every term, so
that every term is linear on every grid interval (see :class:`~fuzzyctl.engine.plan.GridPlan`),
and the closed forms of the intervals that belong to a single term."""

from __future__ import annotations

from collections.abc import Collection, Sequence

from numpy.polynomial import Polynomial as P

from fuzzyctl.engine.plan import GridPlan
from fuzzyctl.engine.semantics.shapes import Points, pwl_value


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


def build_grid(
    terms: Sequence[Points], low: float, high: float, used: Collection[int] | None = None
) -> GridPlan:
    """Cut ``[low, high]`` at every breakpoint of ``terms``.  ``used`` are the terms some rule
    concludes (the others never contribute; default: all)."""
    cuts = {low, high}
    for pts in terms:
        for x, _y in pts:
            if low < x < high:
                cuts.add(x)
    xs = tuple(sorted(cuts))
    nint = len(xs) - 1
    left = tuple(tuple(right_limit(p, xs[j]) for j in range(nint)) for p in terms)
    right = tuple(tuple(left_limit(p, xs[j + 1]) for j in range(nint)) for p in terms)
    point = tuple(tuple(pwl_value(p, x) for x in xs) for p in terms)
    use = set(range(len(terms))) if used is None else set(used)
    active = tuple(
        tuple(t for t in range(len(terms)) if t in use and (left[t][j] != 0.0 or right[t][j] != 0.0))
        for j in range(nint)
    )
    shared = tuple(j for j in range(nint) if len(active[j]) > 1)
    solo = tuple(tuple(j for j in range(nint) if active[j] == (t,)) for t in range(len(terms)))
    bands = tuple(_min_bands(xs, left[t], right[t], solo[t]) for t in range(len(terms)))
    full = tuple(_full(xs, left[t], right[t], solo[t]) for t in range(len(terms)))
    return GridPlan(xs, left, right, point, active, shared, solo, bands, full)


def _full(
    xs: Sequence[float], left: Sequence[float], right: Sequence[float], js: Sequence[int]
) -> tuple[float, float]:
    area = moment = 0.0
    for j in js:
        x0, x1, v0, v1 = xs[j], xs[j + 1], left[j], right[j]
        dx = x1 - x0
        area += 0.5 * dx * (v0 + v1)
        moment += dx * (x0 * (2.0 * v0 + v1) + x1 * (v0 + 2.0 * v1)) / 6.0
    return area, moment


def _segment_polys(x0: float, x1: float, lo: float, hi: float, h_mid: float) -> tuple[P, P]:
    """Area and moment of min(h, segment) on [x0, x1] as polynomials in h, valid for h in the
    band containing ``h_mid`` (the band never crosses the segment's end values)."""
    dx = x1 - x0
    h = P([0.0, 1.0])
    if h_mid >= max(lo, hi):
        a = 0.5 * dx * (lo + hi)
        mo = dx * (x0 * (2.0 * lo + hi) + x1 * (lo + 2.0 * hi)) / 6.0
        return P([a]), P([mo])
    if h_mid <= min(lo, hi):
        return dx * h, dx * 0.5 * (x0 + x1) * h
    # the segment crosses h: t_k is where it reaches h (t from the low end)
    rising = hi > lo
    L, D = (lo, hi - lo) if rising else (hi, lo - hi)  # measured from the lower end
    tk = (h - L) / D
    area_unit = L * tk + 0.5 * D * tk**2 + h * (1.0 - tk)  # integral over t in [0, 1]
    tmom_unit = 0.5 * L * tk**2 + D * tk**3 / 3.0 + 0.5 * h * (1.0 - tk**2)  # integral of t * c(t)
    area = dx * area_unit
    # a falling segment is mirrored: t' = 1 - t measured from x1 going left
    moment = x0 * area + dx * dx * tmom_unit if rising else x1 * area - dx * dx * tmom_unit
    return area, moment


def _min_bands(
    xs: Sequence[float], left: Sequence[float], right: Sequence[float], js: Sequence[int]
) -> tuple[tuple[float, float, tuple[float, ...], tuple[float, ...]], ...]:
    levels = sorted({0.0, *(left[j] for j in js), *(right[j] for j in js)})
    bands = []
    tops = [*levels[1:], float("inf")]
    for lo_h, hi_h in zip(levels, tops, strict=True):
        mid = lo_h + 1.0 if hi_h == float("inf") else 0.5 * (lo_h + hi_h)
        area, moment = P([0.0]), P([0.0])
        for j in js:
            a, mo = _segment_polys(xs[j], xs[j + 1], left[j], right[j], mid)
            area = area + a
            moment = moment + mo
        ac = [*area.coef.tolist(), 0.0, 0.0, 0.0][:3]
        mc = [*moment.coef.tolist(), 0.0, 0.0, 0.0, 0.0][:4]
        bands.append((lo_h, hi_h, tuple(float(c) for c in ac), tuple(float(c) for c in mc)))
    return tuple(bands)
