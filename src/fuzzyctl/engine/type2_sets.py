"""Interval type-2 sets for :mod:`fuzzyctl.engine.type2`: the upper and lower degree of a
term, the lower function of MATLAB's ``LowerScale`` / ``LowerLag`` form, the check that
lower <= upper, and the exact centroid interval of a piecewise-linear interval set.

The centroid interval of a continuous set with upper ``U`` and lower ``L`` is ``[yl, yr]``,
``yl = min_s c(s)`` where ``c(s)`` is the centroid of ``U`` left of ``s`` and ``L`` right of
it; ``c'(s) = (U(s) - L(s)) (s - c(s)) / area``, so the minimum is where ``s = c(s)``, the
one root of the decreasing ``G(s) = integral of (y - s) w_s(y) dy`` (the switch-point
argument of Karnik and Mendel taken to the continuum).  On piecewise-linear sets ``G`` is
a cubic on each piece: the piece is found from ``G`` at the breakpoints and the root by
bisection to the last bit, so the end points are exact up to rounding.
"""

from __future__ import annotations

import itertools
import math
from collections.abc import Sequence

from fuzzyctl.engine.semantics import shapes as sem
from fuzzyctl.model import LowerMF, MembershipFunction, PointsMF, Ref, ShapeMF, Term

Points = tuple[tuple[float, float], ...]
#: Points sampled per span when lower <= upper is checked on a smooth pair of functions.
CHECK_SAMPLES = 2001


class Type2Error(ValueError):
    """A type-2 term the engine cannot evaluate, or whose lower exceeds its upper."""


def floats(params: Sequence[object], where: str) -> list[float]:
    if any(isinstance(p, Ref) for p in params):
        raise Type2Error(f"{where}: parameters given by variables are not supported in type-2 terms")
    return [float(p) for p in params]  # type: ignore[arg-type]


def points_of(mf: MembershipFunction, where: str) -> Points | None:
    """The breakpoints of a piecewise-linear function, None for a smooth one."""
    if isinstance(mf, PointsMF):
        xs, ys = floats([p.x for p in mf.points], where), floats([p.y for p in mf.points], where)
        return sem.sort_points(list(zip(xs, ys, strict=True)))
    if isinstance(mf, ShapeMF):
        return sem.pwl_points(mf.kind, floats(mf.params, where), float(floats([mf.height], where)[0]))
    raise Type2Error(f"{where}: {type(mf).__name__} terms are not supported in type-2 systems")


def mf_value(mf: MembershipFunction, x: float, where: str) -> float:
    if isinstance(mf, ShapeMF):
        return sem.membership(mf.kind, floats(mf.params, where), float(floats([mf.height], where)[0]), x)
    pts = points_of(mf, where)
    assert pts is not None
    return sem.pwl_value(pts, x)


def lags(lower: LowerMF, where: str) -> tuple[float, float]:
    if not 0.0 < lower.scale <= 1.0:
        raise Type2Error(f"{where}: LowerScale must be in (0, 1], found {lower.scale:g}")
    if len(lower.lag) not in (1, 2) or not all(0.0 <= v < 1.0 for v in lower.lag):
        raise Type2Error(f"{where}: LowerLag must be one or two values in [0, 1), found {list(lower.lag)}")
    return (lower.lag[0], lower.lag[-1])


def _lagged(y: float, lag: float, scale: float) -> float:
    return scale * max(0.0, (y - lag) / (1.0 - lag)) if lag > 0.0 else scale * y


def lower_points(term: Term, where: str) -> Points | None:
    """The lower function of ``term`` as breakpoints (None: smooth).  The scale/lag form of
    a piecewise-linear upper is piecewise linear: each segment is cut where it crosses the
    lag, the left lag applying up to the first maximum, the right one after it."""
    lower = term.lower
    if lower is None:
        return points_of(term.mf, where)
    if lower.mf is not None:
        return points_of(lower.mf, where)
    left, right = lags(lower, where)
    up = points_of(term.mf, where)
    if up is None:
        return None
    top = max(y for _, y in up)
    peak = next(i for i, (_, y) in enumerate(up) if y == top)
    out: list[tuple[float, float]] = []
    for i, (x, y) in enumerate(up):
        lag = left if i <= peak else right
        if i > 0:
            x0, y0 = up[i - 1]
            if (y0 - lag) * (y - lag) < 0.0 and x != x0:  # crosses the lag inside the segment
                xc = x0 + (x - x0) * (lag - y0) / (y - y0)
                out.append((xc, 0.0))
        out.append((x, _lagged(y, lag, lower.scale)))
    return tuple(out)


def lower_value(term: Term, x: float, where: str) -> float:
    """The lower degree of ``term`` at ``x`` (a type-1 term: its only function)."""
    lower = term.lower
    if lower is None:
        return mf_value(term.mf, x, where)
    if lower.mf is not None:
        return mf_value(lower.mf, x, where)
    left, right = lags(lower, where)
    pts = lower_points(term, where)
    if pts is not None:
        return sem.pwl_value(pts, x)
    if left != right:
        raise Type2Error(f"{where}: two LowerLag values need a piecewise-linear upper function")
    return _lagged(mf_value(term.mf, x, where), left, lower.scale)


def lower_problem(term: Term, span: tuple[float, float], where: str) -> str | None:
    """Why ``term``'s lower function is not below its upper one (None: it is).  Exact for
    piecewise-linear pairs (checked at every breakpoint of both, either side of a jump);
    a smooth pair is sampled at :data:`CHECK_SAMPLES` points of ``span``."""
    if term.lower is None:
        return None
    try:
        up, lo = points_of(term.mf, where), lower_points(term, where)
        if up is not None and lo is not None:
            xs = sorted({x for x, _ in up} | {x for x, _ in lo})
        else:
            a, b = span
            xs = [a + (b - a) * i / (CHECK_SAMPLES - 1) for i in range(CHECK_SAMPLES)]
        for x in xs:
            u, v = mf_value(term.mf, x, where), lower_value(term, x, where)
            if v > u + 1e-12:
                return _exceeds(where, v, u, x)
        if up is not None and lo is not None:
            for x in xs:  # the other side of a vertical edge
                u, v = _left_value(up, x), _left_value(lo, x)
                if v > u + 1e-12:
                    return _exceeds(where, v, u, x)
    except Type2Error as exc:
        return str(exc)
    return None


def _exceeds(where: str, lower: float, upper: float, x: float) -> str:
    return (
        f"{where}: the lower membership function ({lower:.6g}) exceeds the upper one ({upper:.6g}) at {x:.6g}"
    )


def _left_value(points: Points, x: float) -> float:
    """The left limit of a breakpoint list at ``x``."""
    for i, (px, py) in enumerate(points):
        if px >= x:
            if i == 0:
                return py
            x0, y0 = points[i - 1]
            return py if px == x0 else y0 + (py - y0) * (x - x0) / (px - x0)
    return points[-1][1]


# --------------------------------------------------------------------------- exact centroid


def segment_values(points: Points, a: float, b: float) -> tuple[float, float]:
    """The values at ``a`` and ``b`` of the linear piece of ``points`` over ``[a, b]`` (a
    piece that no breakpoint splits): limits from inside, so a vertical edge at ``a`` or
    ``b`` does not count."""
    m = 0.5 * (a + b)
    if m <= points[0][0]:
        return points[0][1], points[0][1]
    if m >= points[-1][0]:
        return points[-1][1], points[-1][1]
    for (x0, y0), (x1, y1) in itertools.pairwise(points):
        if x0 <= m <= x1 and x1 > x0:
            t = (y1 - y0) / (x1 - x0)
            return y0 + t * (a - x0), y0 + t * (b - x0)
    return points[-1][1], points[-1][1]


def _area_moment(a: float, b: float, ya: float, yb: float) -> tuple[float, float]:
    """Integral of the line through (a, ya), (b, yb) and of y times it, over [a, b]."""
    h = b - a
    return h * (ya + yb) / 2.0, h * (a * (2.0 * ya + yb) + b * (ya + 2.0 * yb)) / 6.0


def _partial(a: float, b: float, ya: float, yb: float, s: float, left: bool) -> tuple[float, float]:
    ys = ya + (yb - ya) * (s - a) / (b - a) if b > a else ya
    return _area_moment(a, s, ya, ys) if left else _area_moment(s, b, ys, yb)


def centroid_interval(
    xs: Sequence[float], upper: Sequence[tuple[float, float]], lower: Sequence[tuple[float, float]]
) -> tuple[float, float]:
    """``[yl, yr]`` of the interval set linear on each ``[xs[i], xs[i+1]]`` with values
    ``upper[i]`` / ``lower[i]`` (at the piece's two ends).  NaN when the upper area is 0."""
    n = len(xs) - 1
    am_u = [_area_moment(xs[i], xs[i + 1], *upper[i]) for i in range(n)]
    am_l = [_area_moment(xs[i], xs[i + 1], *lower[i]) for i in range(n)]
    if math.fsum(a for a, _ in am_u) <= 0.0:
        return math.nan, math.nan
    return (_end(xs, upper, lower, am_u, am_l, True), _end(xs, lower, upper, am_l, am_u, False))


def _end(
    xs: Sequence[float],
    left_f: Sequence[tuple[float, float]],
    right_f: Sequence[tuple[float, float]],
    am_left: list[tuple[float, float]],
    am_right: list[tuple[float, float]],
    low_end: bool,
) -> float:
    """The root of ``G(s)``: ``left_f`` left of ``s``, ``right_f`` right of it.  Where no
    mass is on either side ``G`` is 0 over an interval (a lower set of zero degree): the
    end point is that interval's edge next to the mass, right (``yl``) or left (``yr``)."""

    def right_of_root(g: float) -> bool:
        return g >= 0.0 if low_end else g > 0.0

    n = len(xs) - 1
    pre = [(0.0, 0.0)]
    for a, m in am_left:
        pre.append((pre[-1][0] + a, pre[-1][1] + m))
    suf = [(0.0, 0.0)] * (n + 1)
    for i in range(n - 1, -1, -1):
        suf[i] = (suf[i + 1][0] + am_right[i][0], suf[i + 1][1] + am_right[i][1])

    def g_at(k: int) -> float:
        area, moment = pre[k][0] + suf[k][0], pre[k][1] + suf[k][1]
        return moment - xs[k] * area

    k = 0
    while k < n and right_of_root(g_at(k + 1)):
        k += 1
    if k == n:
        return xs[n]
    a, b = xs[k], xs[k + 1]

    def g(s: float) -> float:
        al, ml = _partial(a, b, *left_f[k], s, True)
        ar, mr = _partial(a, b, *right_f[k], s, False)
        area = pre[k][0] + al + ar + suf[k + 1][0]
        return pre[k][1] + ml + mr + suf[k + 1][1] - s * area

    lo, hi = a, b
    for _ in range(200):
        mid = 0.5 * (lo + hi)
        if mid in (lo, hi):
            break
        if right_of_root(g(mid)):
            lo = mid
        else:
            hi = mid
    return lo if abs(g(lo)) < abs(g(hi)) else hi
