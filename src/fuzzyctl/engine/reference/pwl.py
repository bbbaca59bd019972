"""Exact defuzzification of piecewise-linear accumulated sets (scalar).

On a grid interval every term is linear; MIN activation adds one kink where the term crosses
the rule's degree; MAX accumulation adds kinks where activated sets cross each other, BSUM
where the sum crosses 1.  Cutting at all of them leaves *pieces* on which the accumulated set
is linear (MAX, BSUM, SUM, NSUM) or a product of linear factors (PROBOR), integrated in closed
form (trapezoid moments; Gauss-Legendre with enough nodes to be exact for the polynomial).

A piece is ``(x0, x1, v0, v1, factors)``: the accumulated degree goes from ``v0`` (limit from
the right at ``x0``) to ``v1`` (limit from the left at ``x1``), linearly when ``factors`` is
None, else as ``1 - prod(1 - (c0 + (c1 - c0) s))`` over ``factors = ((c0, c1), ...)`` with
``s`` in [0, 1] (PROBOR).
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from functools import cache

import numpy as np

from fuzzyctl.engine.plan import GridPlan
from fuzzyctl.engine.semantics.operators import fsum
from fuzzyctl.kinds import norms
from fuzzyctl.kinds.methods import METHODS, implementation

#: Relative tolerance deciding that a computed vertex reaches the maximum (LM, RM, MoM).
MAX_TOL = 1e-12
#: Relative tolerance (of the whole area) within which CoA takes the area before a zero gap
#: as half: the bisector is then not unique and CoA answers the middle of the gap (rounding
#: in the running sums would otherwise pick one end of it).
COA_TOL = 1e-12

Piece = tuple[float, float, float, float, tuple[tuple[float, float], ...] | None]
#: One activated set on one grid interval: (L, R, a, w, is_min) - the term goes linearly from
#: L to R; the set is w*min(a, term) (is_min) or w*a*term.
Line = tuple[float, float, float, float, bool]


@cache
def gauss_legendre(n: int) -> tuple[tuple[float, ...], tuple[float, ...]]:
    """Nodes and weights on [0, 1]."""
    x, w = np.polynomial.legendre.leggauss(n)
    return tuple(float(v) for v in (x + 1.0) / 2.0), tuple(float(v) for v in w / 2.0)


def _value(line: Line, kink: float, t: float) -> float:
    L, R, a, w, is_min = line
    if is_min:
        if t == kink:
            return w * a
        y = L + (R - L) * t
        return w * (a if y >= a else y)
    return w * a * (L + (R - L) * t)


def interval_pieces(x0: float, x1: float, lines: Sequence[Line], accu: str, out: list[Piece]) -> None:
    """Append the pieces of the accumulated set on ``[x0, x1]``."""
    ts = [0.0, 1.0]
    kinks = []
    for L, R, a, _w, is_min in lines:
        k = -1.0
        if is_min and (L - a) * (R - a) < 0.0:
            k = (a - L) / (R - L)
            ts.append(k)
        kinks.append(k)
    ts = sorted(set(ts))
    dx = x1 - x0
    n = len(lines)
    prev = [_value(lines[i], kinks[i], 0.0) for i in range(n)]
    for idx in range(1, len(ts)):
        t0, t1 = ts[idx - 1], ts[idx]
        xa = x0 + t0 * dx if t0 > 0.0 else x0
        xb = x0 + t1 * dx if t1 < 1.0 else x1
        cur = [_value(lines[i], kinks[i], t1) for i in range(n)]
        _combine(xa, xb, prev, cur, accu, out)
        prev = cur


def _combine(xa: float, xb: float, p0: list[float], p1: list[float], accu: str, out: list[Piece]) -> None:
    n = len(p0)
    if n == 1:
        out.append((xa, xb, p0[0], p1[0], None))
        return
    if norms.is_max(accu):
        cuts: list[float] = []
        for i in range(n):
            for j in range(i + 1, n):
                d0 = p0[i] - p0[j]
                d1 = p1[i] - p1[j]
                if d0 * d1 < 0.0:
                    cuts.append(d0 / (d0 - d1))
        if not cuts:
            out.append((xa, xb, max(p0), max(p1), None))
            return
        cuts.sort()
        dx = xb - xa
        xp, vp = xa, max(p0)
        for s in cuts:
            xs = xa + s * dx
            vs = max(p0[k] + (p1[k] - p0[k]) * s for k in range(n))
            out.append((xp, xs, vp, vs, None))
            xp, vp = xs, vs
        out.append((xp, xb, vp, max(p1), None))
        return
    s0 = fsum(p0)
    s1 = fsum(p1)
    if norms.adds(accu):
        out.append((xa, xb, s0, s1, None))
    elif norms.bounded(accu):
        if (s0 - 1.0) * (s1 - 1.0) < 0.0:
            s = (1.0 - s0) / (s1 - s0)
            xm = xa + s * (xb - xa)
            out.append((xa, xm, min(1.0, s0), 1.0, None))
            out.append((xm, xb, 1.0, min(1.0, s1), None))
        else:
            out.append((xa, xb, min(1.0, s0), min(1.0, s1), None))
    elif norms.probabilistic(accu):
        factors = tuple(zip(p0, p1, strict=True))
        out.append((xa, xb, _poly_value(factors, 0.0), _poly_value(factors, 1.0), factors))
    else:  # pragma: no cover - lowering sends other accumulations to quadrature
        raise ValueError(f"accumulation {accu} is not piecewise linear")


def grid_pieces(grid: GridPlan, contribs: Sequence[tuple[int, float, float, bool]], accu: str) -> list[Piece]:
    """Pieces of the accumulated set over the whole grid; ``contribs`` are
    ``(term, a, w, is_min)`` with ``a * w > 0``."""
    out: list[Piece] = []
    xs = grid.xs
    left, right = grid.left, grid.right
    for j, act in enumerate(grid.active):
        lines: list[Line] = []
        for t, a, w, is_min in contribs:
            if t in act:
                lines.append((left[t][j], right[t][j], a, w, is_min))
        if lines:
            interval_pieces(xs[j], xs[j + 1], lines, accu, out)
    return out


def point_values(
    grid: GridPlan, contribs: Sequence[tuple[int, float, float, bool]], accu: str
) -> list[float]:
    """The accumulated degree exactly at each grid point (matters only at vertical edges)."""
    from fuzzyctl.engine.semantics.operators import accumulate

    vals = []
    for j in range(len(grid.xs)):
        v = 0.0
        for t, a, w, is_min in contribs:
            y = grid.point[t][j]
            c = w * (min(a, y) if is_min else a * y)
            v = accumulate(accu, v, c)
        vals.append(v)
    return vals


# --------------------------------------------------------------------------- integrals


def _poly_value(factors: tuple[tuple[float, float], ...], s: float) -> float:
    # folded as a + b - a*b (not 1 - prod(1 - c)) so that tiny degrees are not lost
    acc = 0.0
    for c0, c1 in factors:
        c = c0 + (c1 - c0) * s
        acc = acc + c - acc * c
    return acc


#: Scaling of tiny firing degrees (see :func:`tiny_degree_scale`): up to TINY_COUNT times,
#: while the largest degree is below TINY_BELOW, every degree is multiplied by TINY_FACTOR (a
#: power of two).  From any degree >= 2^-1074 the steps end in [2^-124, 2^-60); nothing at or
#: above 2^-124 moves.  Both constants are normal single-precision floats (REAL targets).
TINY_BELOW = 2.0**-124
TINY_FACTOR = 2.0**64
TINY_COUNT = 16


def tiny_degree_scale(top: float) -> float:
    """The power of two by which a Mamdani output whose largest firing degree is ``top``
    scales all its degrees (1.0 unless 0 < top < 2^-124): the steps of :data:`TINY_BELOW`.

    Areas and moments are products of degrees, widths and positions: at subnormal degrees
    they keep a few bits or underflow, and the paths split (1.0, 0.5 or 0.75 for a set that is
    a rectangle in effect).  Scaling every degree by the same power of two is exact and keeps
    each accumulated set's shape: only where a MIN-clipped edge crosses the level moves, by
    less than 2^-60 of that edge's run, far below 1e-9 of any range.  Every path (interpreter,
    numpy, the generated Python and C of the fast program) applies the same steps."""
    scale = 1.0
    if not top > 0.0:  # nothing fired (or NaN): nothing to scale
        return scale
    for _ in range(TINY_COUNT):
        if top < TINY_BELOW:
            top *= TINY_FACTOR
            scale *= TINY_FACTOR
    return scale


def piece_area_moment(p: Piece) -> tuple[float, float]:
    """Exact area and first moment of one piece."""
    x0, x1, v0, v1, factors = p
    dx = x1 - x0
    if factors is None:
        return 0.5 * dx * (v0 + v1), dx * (x0 * (2.0 * v0 + v1) + x1 * (v0 + 2.0 * v1)) / 6.0
    nodes, weights = gauss_legendre((len(factors) + 3) // 2 + 1)
    a = mo = 0.0
    for s, wt in zip(nodes, weights, strict=True):
        f = _poly_value(factors, s)
        a += wt * f
        mo += wt * f * (x0 + s * dx)
    return a * dx, mo * dx


def area_moment(pieces: Sequence[Piece]) -> tuple[float, float]:
    areas, moments = [], []
    for p in pieces:
        a, mo = piece_area_moment(p)
        areas.append(a)
        moments.append(mo)
    return fsum(areas), fsum(moments)


def _partial_area(p: Piece, s: float) -> float:
    """Area of piece ``p`` from its start to parameter ``s`` in [0, 1]."""
    x0, x1, v0, v1, factors = p
    dx = (x1 - x0) * s
    if factors is None:
        vs = v0 + (v1 - v0) * s
        return 0.5 * dx * (v0 + vs)
    nodes, weights = gauss_legendre((len(factors) + 3) // 2 + 1)
    return dx * sum(wt * _poly_value(factors, u * s) for u, wt in zip(nodes, weights, strict=True))


def _solve_in_piece(p: Piece, r: float) -> float:
    """The x in piece ``p`` where the area from the piece start equals ``r``."""
    x0, x1, v0, v1, factors = p
    dx = x1 - x0
    if factors is None:
        scale = max(abs(v0), abs(v1))  # the formula is scale-free; scaling avoids underflow
        if scale > 0.0:
            v0, v1, r = v0 / scale, v1 / scale, r / scale
        k = (v1 - v0) / dx if dx > 0.0 else 0.0
        disc = v0 * v0 + 2.0 * k * r
        den = v0 + math.sqrt(max(disc, 0.0))
        if den <= 0.0:
            return x0
        return min(x1, x0 + 2.0 * r / den)
    lo, hi = 0.0, 1.0  # the partial area is increasing in s: bisection to the last bit
    for _ in range(200):
        mid = 0.5 * (lo + hi)
        if mid in (lo, hi):
            break
        if _partial_area(p, mid) < r:
            lo = mid
        else:
            hi = mid
    return x0 + 0.5 * (lo + hi) * dx


def bisector(pieces: Sequence[Piece], total: float) -> float:
    """Centre of area: the x splitting the area in two equal halves.  When a whole interval
    of solutions exists (a gap where the set is 0), its midpoint."""
    half = 0.5 * total
    tol = COA_TOL * total
    areas = [piece_area_moment(p)[0] for p in pieces]
    # the whole piece within tol: its end, not the quadratic (whose root near a 0 end moves
    # by sqrt(rounding) there)
    cum = 0.0
    left = pieces[-1][1]
    for p, a in zip(pieces, areas, strict=True):
        if a > 0.0 and cum + a >= half - tol:
            left = p[1] if half - cum >= a - tol else _solve_in_piece(p, half - cum)
            break
        cum += a
    cum = 0.0
    right = pieces[0][0]
    for p, a in zip(reversed(pieces), reversed(areas), strict=True):
        if a > 0.0 and cum + a >= half - tol:
            right = p[0] if half - cum >= a - tol else _solve_in_piece(p, a - (half - cum))
            break
        cum += a
    return 0.5 * (left + right)


def maxima(
    pieces: Sequence[Piece], points: Sequence[tuple[float, float]]
) -> tuple[float, float, float, float]:
    """``(height, LM, RM, MoM)`` of the accumulated set: the supremum, the smallest and the
    largest u reaching it, and the mean of the maximising set (the centroid of its intervals,
    or the mean of its points when it has no length)."""
    sup = 0.0
    for _x0, _x1, v0, v1, _f in pieces:
        sup = max(sup, v0, v1)
    for _x, v in points:
        sup = max(sup, v)
    lm, rm = math.inf, -math.inf
    plateau_len = plateau_mom = 0.0
    isolated: set[float] = set()
    # crossing points are computed, not given: accept values within MAX_TOL of the supremum,
    # and take points within MAX_TOL of the range for one (a crossing rounded 1e-15 from a
    # vertex is no plateau and no second maximum)
    thr = sup * (1.0 - MAX_TOL)
    near = MAX_TOL * (points[-1][0] - points[0][0]) if points else 0.0
    for x0, x1, v0, v1, _f in pieces:
        if v0 >= thr:
            lm = min(lm, x0)
            rm = max(rm, x0)
            isolated.add(x0)
        if v1 >= thr:
            lm = min(lm, x1)
            rm = max(rm, x1)
            isolated.add(x1)
        if v0 >= thr and v1 >= thr and x1 > x0:
            plateau_len += x1 - x0
            plateau_mom += (x1 - x0) * 0.5 * (x0 + x1)
    for x, v in points:
        if v >= thr:
            lm = min(lm, x)
            rm = max(rm, x)
            isolated.add(x)
    distinct = distinct_points(sorted(isolated), near)
    mom = (
        plateau_mom / plateau_len
        if plateau_len > near
        else (fsum(distinct) / len(distinct) if distinct else math.nan)
    )
    return sup, lm, rm, mom


def distinct_points(xs: Sequence[float], near: float) -> list[float]:
    """Sorted ``xs`` without the points within ``near`` of the one before them."""
    return [x for i, x in enumerate(xs) if i == 0 or x - xs[i - 1] > near]


def defuzzify_pieces(
    method: str, pieces: Sequence[Piece], points: Sequence[tuple[float, float]]
) -> float | None:
    """The defuzzified value, or None when the set is empty (no rule fired)."""
    # "fired" means the set has area: a set that is 0 almost everywhere (a lone vertical edge
    # at the end of the range) has no centre and no meaningful maximum either
    area, moment = area_moment(pieces)
    if not area > 0.0:
        return None
    defuzzify = implementation(METHODS[method].reference)
    return float(defuzzify(pieces, points, area, moment))


# the methods on the pieces (kinds/methods.py names them as each entry's ``reference``)
Points = Sequence[tuple[float, float]]


def centroid(pieces: Sequence[Piece], points: Points, area: float, moment: float) -> float:
    """CoG: the first moment over the area."""
    return moment / area


def bisector_value(pieces: Sequence[Piece], points: Points, area: float, moment: float) -> float:
    """CoA: :func:`bisector` over the pieces with a width."""
    return bisector([p for p in pieces if p[1] > p[0]], area)


def leftmost(pieces: Sequence[Piece], points: Points, area: float, moment: float) -> float:
    """LM: the smallest point reaching the height (:func:`maxima`)."""
    return maxima(pieces, points)[1]


def rightmost(pieces: Sequence[Piece], points: Points, area: float, moment: float) -> float:
    """RM: the largest point reaching the height (:func:`maxima`)."""
    return maxima(pieces, points)[2]


def mean_of_maximum(pieces: Sequence[Piece], points: Points, area: float, moment: float) -> float:
    """MoM: the mean of the maximising set (:func:`maxima`)."""
    return maxima(pieces, points)[3]
