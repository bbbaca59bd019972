"""Membership functions: the one place where shape formulas live.

Every shape kind of :data:`fuzzyctl.model.SHAPES` is defined here twice, once for a Python
float (``math``) and once for numpy arrays, with the same formula written the same way, so
the scalar and the batch evaluators agree to the last few ulps.

Piecewise-linear shapes (IEC points, triangle, trapezoid, rectangle, ramp, binary) are also
expressed as *breakpoint lists* (:func:`pwl_points`): ``((x0, y0), (x1, y1), ...)`` with
non-decreasing ``x``, linear between successive points and constant beyond the first and the
last point (IEC 61131-7 5.2.2).  Two points with the same ``x`` form a vertical edge; the
degree *at* that ``x`` is the upper of the two values (a rectangle includes its ends).  The
exact defuzzifiers integrate these lists in closed form.
"""

from __future__ import annotations

import itertools
import math
from collections.abc import Callable, Sequence
from typing import Any

import numpy as np
import numpy.typing as npt

from fuzzyctl.engine.semantics import libm_np

FloatArray = npt.NDArray[np.float64]
Points = tuple[tuple[float, float], ...]

#: Shapes that are piecewise linear and become breakpoint lists.
PWL_KINDS = frozenset({"points", "triangle", "trapezoid", "rectangle", "ramp", "binary"})
#: Takagi-Sugeno output terms: a value, not a fuzzy set.
TS_KINDS = frozenset({"constant", "linear", "function"})
#: Monotonic shapes a weighted average can invert (Tsukamoto outputs, fuzzylite; monotonic
#: ``points`` under COGS: jfuzzyqt's Tsukamoto).
TSUKAMOTO_KINDS = frozenset({"ramp", "sigmoid", "sshape", "zshape", "concave", "arc", "points"})
#: Smooth parametric shapes (integrated by adaptive quadrature on outputs).
SMOOTH_KINDS = frozenset(
    {
        "gaussian",
        "gaussian2",
        "bell",
        "sigmoid",
        "dsigmoid",
        "dsigmoid_pos",
        "psigmoid",
        "cosine",
        "sshape",
        "zshape",
        "pishape",
        "spike",
        "concave",
        "cosine_half",
        "arc",
        "semiellipse",
    }
)


# --------------------------------------------------------------------------- breakpoint lists


def sort_points(points: Sequence[tuple[float, float]]) -> Points:
    """Sort points by ``x`` keeping the written order of equal ``x`` (5.2.2 note: points given
    by variables may arrive out of order at run time)."""
    return tuple(sorted(((float(x), float(y)) for x, y in points), key=lambda p: p[0]))


def pwl_points(kind: str, params: Sequence[float], height: float = 1.0) -> Points | None:
    """The breakpoint list of a piecewise-linear shape, or ``None`` when ``kind`` is not one.

    ``points`` takes ``params`` as ``x0, y0, x1, y1, ...``."""
    h = float(height)
    p = [float(v) for v in params]
    if kind == "points":
        pts = sort_points(list(zip(p[0::2], p[1::2], strict=True)))
        return tuple((x, y * h) for x, y in pts)
    if kind == "triangle":
        a, b, c = p
        return _shoulders(((a, 0.0), (b, h), (c, 0.0)), h)
    if kind == "trapezoid":
        a, b, c, d = p
        return _shoulders(((a, 0.0), (b, h), (c, h), (d, 0.0)), h)
    if kind == "rectangle":
        s, e = min(p), max(p)
        return ((s, 0.0), (s, h), (e, h), (e, 0.0))
    if kind == "ramp":
        s, e = p
        if s == e:  # fuzzylite: a ramp without extent is 0 everywhere
            return ((s, 0.0),)
        return ((s, 0.0), (e, h)) if s < e else ((e, h), (s, 0.0))
    if kind == "binary":
        s, direction = p
        if direction > s:
            return ((s, 0.0), (s, h))
        if direction < s:
            return ((s, h), (s, 0.0))
        return ((s, 0.0),)
    return None


def _shoulders(points: Points, h: float) -> Points:
    """A triangle or trapezoid with vertices at -inf / +inf is a shoulder (MATLAB
    ``trapmf [-Inf -Inf 2 4]``; fuzzylite gives the height beyond a finite vertex whose
    neighbour is infinite): the infinite vertices are dropped and the ends continue flat."""
    if all(math.isfinite(x) for x, _y in points):
        return points
    finite = tuple((x, y) for x, y in points if math.isfinite(x))
    return finite or ((0.0, h),)


def pwl_value(points: Points, x: float) -> float:
    """Degree of a breakpoint list at ``x`` (upper value on a vertical edge)."""
    n = len(points)
    if x < points[0][0]:
        return points[0][1]
    if x > points[n - 1][0]:
        return points[n - 1][1]
    best = -math.inf
    for i in range(n):
        xi, yi = points[i]
        if xi == x:
            if yi > best:
                best = yi
        elif xi > x:
            if best > -math.inf:
                return best
            x0, y0 = points[i - 1]
            return y0 + (yi - y0) * ((x - x0) / (xi - x0))
    return best


def pwl_value_np(points: Points, x: FloatArray) -> FloatArray:
    """Vectorised :func:`pwl_value` for a constant breakpoint list."""
    xs = np.array([p[0] for p in points])
    ys = np.array([p[1] for p in points])
    # np.interp takes the last of equal xs for x exactly on an edge; the upper value is
    # imposed afterwards.
    out = np.interp(x, xs, ys)
    for i in range(len(points) - 1):
        if xs[i] == xs[i + 1]:
            out = np.where(x == xs[i], np.maximum(np.maximum(ys[i], ys[i + 1]), out), out)
    return np.asarray(out, dtype=np.float64)


def pwl_value_dynamic_np(xs: FloatArray, ys: FloatArray, x: FloatArray) -> FloatArray:
    """Breakpoint lists that differ per sample: ``xs``/``ys`` are ``(N, P)`` (already sorted
    along axis 1, stably), ``x`` is ``(N,)``."""
    n, p = xs.shape
    out = np.where(x < xs[:, 0], ys[:, 0], ys[:, p - 1])
    done = (x < xs[:, 0]) | (x > xs[:, p - 1])
    on_point = np.full(n, -np.inf)
    for i in range(p):
        on_point = np.where(xs[:, i] == x, np.maximum(on_point, ys[:, i]), on_point)
    has_point = on_point > -np.inf
    for i in range(p - 1):
        x0, x1 = xs[:, i], xs[:, i + 1]
        inside = (~done) & (~has_point) & (x0 < x) & (x < x1)
        with np.errstate(invalid="ignore", divide="ignore"):
            val = ys[:, i] + (ys[:, i + 1] - ys[:, i]) * ((x - x0) / (x1 - x0))
        out = np.where(inside, val, out)
    out = np.where((~done) & has_point, on_point, out)
    return np.asarray(out, dtype=np.float64)


# --------------------------------------------------------------------------- smooth shapes


def _sig(x: float, c: float, s: float) -> float:
    z = -s * (x - c)
    if z > 700.0:  # exp overflow: the sigmoid is 0 to double precision
        return 0.0
    return 1.0 / (1.0 + math.exp(z))


def _sshape(x: float, s: float, e: float) -> float:
    if x <= s:
        return 0.0
    if x <= 0.5 * (s + e):
        t = (x - s) / (e - s)
        return 2.0 * t * t
    if x < e:
        t = (x - e) / (e - s)
        return 1.0 - 2.0 * t * t
    return 1.0


def _zshape(x: float, s: float, e: float) -> float:
    if x <= s:
        return 1.0
    if x <= 0.5 * (s + e):
        t = (x - s) / (e - s)
        return 1.0 - 2.0 * t * t
    if x < e:
        t = (x - e) / (e - s)
        return 2.0 * t * t
    return 0.0


def _gauss(x: float, m: float, sd: float) -> float:
    d = x - m
    return math.exp(-(d * d) / (2.0 * sd * sd))


def _smooth(kind: str, p: Sequence[float], x: float) -> float:
    if kind == "gaussian":
        return _gauss(x, p[0], p[1])
    if kind == "gaussian2":
        a = _gauss(x, p[0], p[1]) if x < p[0] else 1.0
        b = _gauss(x, p[2], p[3]) if x > p[2] else 1.0
        return a * b
    if kind == "bell":
        c, w, s = p
        return 1.0 / (1.0 + float(abs((x - c) / w) ** (2.0 * s)))
    if kind == "sigmoid":
        return _sig(x, p[0], p[1])
    if kind == "dsigmoid":
        return abs(_sig(x, p[0], p[1]) - _sig(x, p[2], p[3]))
    if kind == "dsigmoid_pos":
        return max(_sig(x, p[0], p[1]) - _sig(x, p[2], p[3]), 0.0)
    if kind == "psigmoid":
        return _sig(x, p[0], p[1]) * _sig(x, p[2], p[3])
    if kind == "cosine":
        c, w = p
        if x < c - 0.5 * w or x > c + 0.5 * w:
            return 0.0
        return 0.5 * (1.0 + math.cos(2.0 / w * math.pi * (x - c)))
    if kind == "sshape":
        return _sshape(x, p[0], p[1])
    if kind == "zshape":
        return _zshape(x, p[0], p[1])
    if kind == "pishape":
        return _sshape(x, p[0], p[1]) * _zshape(x, p[2], p[3])
    if kind == "spike":
        c, w = p
        return math.exp(-abs(10.0 / w * (x - c)))
    if kind == "concave":
        i, e = p
        if i <= e and x < e:
            return (e - i) / (2.0 * e - i - x)
        if i >= e and x > e:
            return (i - e) / (i - 2.0 * e + x)
        return 1.0
    if kind == "cosine_half":
        c, hw = p
        if x < c - abs(hw) or x > c + abs(hw):
            return 0.0
        return 0.5 * (1.0 + math.cos(math.pi * (x - c) / hw))
    if kind == "arc":
        s, e = p
        r = e - s
        if (s < e and s <= x <= e) or (s > e and e <= x <= s):
            t = (x - e) / r  # sqrt(r^2 - (x-e)^2) / |r| without squaring r (1e300 overflows)
            return math.sqrt(max(1.0 - t * t, 0.0))
        return 1.0 if (s < e and x > e) or (s > e and x < e) else 0.0
    if kind == "semiellipse":
        s, e = min(p), max(p)
        r = 0.5 * (e - s)
        c = s + r
        if s <= x <= e:
            t = (x - c) / r  # as arc: r^2 would overflow
            return math.sqrt(max(1.0 - t * t, 0.0))
        return 0.0
    raise ValueError(f"unknown shape kind {kind!r}")


def _sig_np(x: Any, c: Any, s: Any) -> Any:
    with np.errstate(over="ignore"):
        return 1.0 / (1.0 + libm_np.exp(-s * (x - c)))


def _sshape_np(x: Any, s: Any, e: Any) -> Any:
    with np.errstate(invalid="ignore", divide="ignore"):
        t1 = (x - s) / (e - s)
        t2 = (x - e) / (e - s)
    return np.where(
        x <= s, 0.0, np.where(x <= 0.5 * (s + e), 2.0 * t1 * t1, np.where(x < e, 1.0 - 2.0 * t2 * t2, 1.0))
    )


def _zshape_np(x: Any, s: Any, e: Any) -> Any:
    with np.errstate(invalid="ignore", divide="ignore"):
        t1 = (x - s) / (e - s)
        t2 = (x - e) / (e - s)
    return np.where(
        x <= s, 1.0, np.where(x <= 0.5 * (s + e), 1.0 - 2.0 * t1 * t1, np.where(x < e, 2.0 * t2 * t2, 0.0))
    )


def _gauss_np(x: Any, m: Any, sd: Any) -> Any:
    d = x - m
    return libm_np.exp(-(d * d) / (2.0 * sd * sd))


def _smooth_np(kind: str, p: Sequence[Any], x: Any) -> Any:
    if kind == "gaussian":
        return _gauss_np(x, p[0], p[1])
    if kind == "gaussian2":
        a = np.where(x < p[0], _gauss_np(x, p[0], p[1]), 1.0)
        b = np.where(x > p[2], _gauss_np(x, p[2], p[3]), 1.0)
        return a * b
    if kind == "bell":
        c, w, s = p
        return 1.0 / (1.0 + libm_np.pow_(np.abs((x - c) / w), 2.0 * s))
    if kind == "sigmoid":
        return _sig_np(x, p[0], p[1])
    if kind == "dsigmoid":
        return np.abs(_sig_np(x, p[0], p[1]) - _sig_np(x, p[2], p[3]))
    if kind == "dsigmoid_pos":
        return np.maximum(_sig_np(x, p[0], p[1]) - _sig_np(x, p[2], p[3]), 0.0)
    if kind == "psigmoid":
        return _sig_np(x, p[0], p[1]) * _sig_np(x, p[2], p[3])
    if kind == "cosine":
        c, w = p
        inside = (x >= c - 0.5 * w) & (x <= c + 0.5 * w)
        return np.where(inside, 0.5 * (1.0 + libm_np.cos(2.0 / w * np.pi * (x - c))), 0.0)
    if kind == "sshape":
        return _sshape_np(x, p[0], p[1])
    if kind == "zshape":
        return _zshape_np(x, p[0], p[1])
    if kind == "pishape":
        return _sshape_np(x, p[0], p[1]) * _zshape_np(x, p[2], p[3])
    if kind == "spike":
        c, w = p
        return libm_np.exp(-np.abs(10.0 / w * (x - c)))
    if kind == "concave":
        i, e = p
        with np.errstate(invalid="ignore", divide="ignore"):
            inc = (e - i) / (2.0 * e - i - x)
            dec = (i - e) / (i - 2.0 * e + x)
        return np.where((i <= e) & (x < e), inc, np.where((i >= e) & (x > e), dec, 1.0))
    if kind == "cosine_half":
        c, hw = p
        inside = (x >= c - np.abs(hw)) & (x <= c + np.abs(hw))
        return np.where(inside, 0.5 * (1.0 + libm_np.cos(np.pi * (x - c) / hw)), 0.0)
    if kind == "arc":
        s, e = p
        r = e - s
        inside = ((s < e) & (s <= x) & (x <= e)) | ((s > e) & (e <= x) & (x <= s))
        t = (x - e) / r  # as _smooth
        arc = np.sqrt(np.maximum(1.0 - t * t, 0.0))
        beyond = ((s < e) & (x > e)) | ((s > e) & (x < e))
        return np.where(inside, arc, np.where(beyond, 1.0, 0.0))
    if kind == "semiellipse":
        s, e = np.minimum(p[0], p[1]), np.maximum(p[0], p[1])
        r = 0.5 * (e - s)
        c = s + r
        inside = (x >= s) & (x <= e)
        t = (x - c) / r  # as _smooth
        return np.where(inside, np.sqrt(np.maximum(1.0 - t * t, 0.0)), 0.0)
    raise ValueError(f"unknown shape kind {kind!r}")


# --------------------------------------------------------------------------- public evaluation


def membership(kind: str, params: Sequence[float], height: float, x: float) -> float:
    """Degree of membership of ``x`` in a fuzzy-set term (not for Takagi-Sugeno kinds)."""
    if kind in PWL_KINDS:
        pts = pwl_points(kind, params, height)
        assert pts is not None
        return pwl_value(pts, x)
    if kind == "singleton":
        return float(height) if x == params[0] else 0.0
    if kind == "singletons":
        best = 0.0
        for xi, yi in zip(params[0::2], params[1::2], strict=True):
            if xi == x and yi > best:
                best = yi
        return best * float(height)
    try:
        return float(height) * _smooth(kind, params, x)
    except (ArithmeticError, ValueError):
        if kind not in SMOOTH_KINDS:
            raise
        # Python raises where IEEE arithmetic (numpy, the generated C) gives inf or NaN
        # (a power or an exponential overflowing at x = 1e20, a zero width): take the numpy
        # value, so that every backend gives the same degree.
        return float(membership_np(kind, params, height, np.array([x]))[0])


def membership_np(kind: str, params: Sequence[Any], height: Any, x: FloatArray) -> FloatArray:
    """Vectorised :func:`membership`; every parameter may be a float or an array broadcasting
    against ``x`` (parameters given by input variables)."""
    x = np.asarray(x, dtype=np.float64)
    with np.errstate(all="ignore"):  # overflow gives inf, 0/0 NaN: the IEEE values, no warning
        return _membership_np(kind, params, height, x)


def _membership_np(kind: str, params: Sequence[Any], height: Any, x: FloatArray) -> FloatArray:
    if kind in PWL_KINDS:
        if all(np.ndim(p) == 0 for p in params) and np.ndim(height) == 0:
            pts = pwl_points(kind, [float(p) for p in params], float(height))
            assert pts is not None
            return pwl_value_np(pts, x)
        return _pwl_dynamic(kind, params, height, x)
    if kind == "singleton":
        return np.asarray(np.where(x == params[0], 1.0, 0.0) * height, dtype=np.float64)
    if kind == "singletons":
        best = np.zeros(np.broadcast(x, *params).shape)
        for xi, yi in zip(params[0::2], params[1::2], strict=True):
            best = np.where(x == xi, np.maximum(best, yi), best)
        return np.asarray(best * height, dtype=np.float64)
    # numpy scalars: a Python float operand would raise where IEEE gives inf (2 / w, w = 0)
    p64 = [np.float64(p) if np.ndim(p) == 0 else p for p in params]
    return np.asarray(height * _smooth_np(kind, p64, x), dtype=np.float64)


def _pwl_dynamic(kind: str, params: Sequence[Any], height: Any, x: FloatArray) -> FloatArray:
    """Piecewise-linear shapes whose parameters differ per sample: build ``(N, P)`` point
    arrays, sort each row stably by ``x`` and interpolate."""
    shape = np.broadcast(x, height, *params).shape
    bp = [np.broadcast_to(np.asarray(p, dtype=np.float64), shape) for p in params]
    h = np.broadcast_to(np.asarray(height, dtype=np.float64), shape)
    xx = np.broadcast_to(x, shape).ravel()
    flat = [p.ravel() for p in bp]
    hh = h.ravel()
    zero = np.zeros_like(xx)
    if kind == "points":
        xs = np.stack(flat[0::2], axis=1)
        ys = np.stack(flat[1::2], axis=1) * hh[:, None]
    elif kind == "triangle":
        xs = np.stack(flat, axis=1)
        ys = np.stack([zero, hh, zero], axis=1)
    elif kind == "trapezoid":
        xs = np.stack(flat, axis=1)
        ys = np.stack([zero, hh, hh, zero], axis=1)
    else:
        # rectangle, ramp and binary change form with the order of their parameters: evaluate
        # each sample through the scalar definition (rare: variable points on such shapes).
        out = np.array(
            [
                membership(kind, [float(f[i]) for f in flat], float(hh[i]), float(xx[i]))
                for i in range(xx.size)
            ]
        )
        return out.reshape(shape)
    order = np.argsort(xs, axis=1, kind="stable")
    xs = np.take_along_axis(xs, order, axis=1)
    ys = np.take_along_axis(ys, order, axis=1)
    return pwl_value_dynamic_np(xs, ys, xx).reshape(shape)


# --------------------------------------------------------------------------- geometry for integration


def support(kind: str, params: Sequence[float], height: float = 1.0) -> tuple[float, float]:
    """The closed interval outside which the term is 0 (may be infinite)."""
    inf = math.inf
    if float(height) == 0.0:
        return (0.0, 0.0)
    if kind in PWL_KINDS:
        pts = pwl_points(kind, params, height)
        assert pts is not None
        lo = -inf if pts[0][1] != 0.0 else next((x for x, y in pts if y != 0.0), inf)
        hi = inf if pts[-1][1] != 0.0 else next((x for x, y in reversed(pts) if y != 0.0), -inf)
        if lo == inf:  # identically zero
            return (0.0, 0.0)
        # the support is bounded by the zero points next to the first/last nonzero point
        if lo != -inf:
            idx = next(i for i, (_x, y) in enumerate(pts) if y != 0.0)
            lo = pts[idx - 1][0] if idx > 0 else lo
        if hi != inf:
            idx = max(i for i, (_x, y) in enumerate(pts) if y != 0.0)
            hi = pts[idx + 1][0] if idx + 1 < len(pts) else hi
        return (lo, hi)
    if kind == "singleton":
        return (params[0], params[0])
    if kind == "singletons":
        xs = [x for x, y in zip(params[0::2], params[1::2], strict=True) if y != 0.0]
        return (min(xs), max(xs)) if xs else (0.0, 0.0)
    if kind == "cosine":
        c, w = params
        return (c - 0.5 * abs(w), c + 0.5 * abs(w))
    if kind == "sshape":
        return (params[0], inf)
    if kind == "zshape":
        return (-inf, params[1])
    if kind == "pishape":
        return (params[0], params[3])
    if kind == "cosine_half":
        c, hw = params
        return (c - abs(hw), c + abs(hw))
    if kind == "semiellipse":
        return (min(params), max(params))
    if kind == "arc":
        s, e = params
        return (s, inf) if s < e else (-inf, s)
    return (-inf, inf)


def characteristic_points(kind: str, params: Sequence[float]) -> tuple[float, ...]:
    """Points where a smooth shape changes character (peaks, joins, support ends): the
    adaptive quadrature splits there first so that it never misses a narrow peak."""
    p = list(params)
    if kind == "gaussian":
        m, s = p
        return tuple(m + k * abs(s) for k in (-8, -4, -2, -1, 0, 1, 2, 4, 8))
    if kind == "gaussian2":
        return tuple(
            [p[0] + k * abs(p[1]) for k in (-8, -4, -2, -1, 0)]
            + [p[2] + k * abs(p[3]) for k in (0, 1, 2, 4, 8)]
        )
    if kind == "bell":
        c, w, _s = p
        return tuple(c + k * abs(w) for k in (-16, -4, -2, -1, 0, 1, 2, 4, 16))
    if kind in ("sigmoid",):
        c, s = p
        d = 1.0 / abs(s) if s else 1.0
        return tuple(c + k * d for k in (-30, -8, -2, 0, 2, 8, 30))
    if kind in ("dsigmoid", "dsigmoid_pos", "psigmoid"):
        out: list[float] = []
        for c, s in ((p[0], p[1]), (p[2], p[3])):
            d = 1.0 / abs(s) if s else 1.0
            out += [c + k * d for k in (-30, -8, -2, 0, 2, 8, 30)]
        return tuple(out)
    if kind == "cosine":
        c, w = p
        return (c - 0.5 * abs(w), c - 0.25 * abs(w), c, c + 0.25 * abs(w), c + 0.5 * abs(w))
    if kind in ("sshape", "zshape"):
        return (p[0], 0.5 * (p[0] + p[1]), p[1])
    if kind == "pishape":
        return (p[0], 0.5 * (p[0] + p[1]), p[1], p[2], 0.5 * (p[2] + p[3]), p[3])
    if kind == "spike":
        c, w = p
        return tuple(c + k * abs(w) / 10.0 for k in (-40, -8, -2, 0, 2, 8, 40))
    if kind == "concave":
        return (p[0], p[1])
    if kind == "cosine_half":
        c, hw = p
        return (c - abs(hw), c - 0.5 * abs(hw), c, c + 0.5 * abs(hw), c + abs(hw))
    if kind in ("arc", "semiellipse"):
        return (p[0], 0.5 * (p[0] + p[1]), p[1])
    pts = pwl_points(kind, params)
    if pts is not None:
        return tuple(x for x, _y in pts)
    if kind == "singleton":
        return (p[0],)
    return ()


# --------------------------------------------------------------------------- hedges

HEDGES: dict[str, Callable[[float], float]] = {
    "not": lambda x: 1.0 - x,
    "very": lambda x: x * x,
    "somewhat": lambda x: math.sqrt(x) if x > 0.0 else 0.0,
    "extremely": lambda x: 2.0 * x * x if x <= 0.5 else 1.0 - 2.0 * (1.0 - x) * (1.0 - x),
    "seldom": lambda x: math.sqrt(0.5 * x) if x <= 0.5 else 1.0 - math.sqrt(0.5 * (1.0 - x)),
    "any": lambda x: 1.0,
}
"""fuzzylite's hedges (``Is.hedges``), applied innermost (closest to the term) first."""


def power_of(name: str) -> float | None:
    """The exponent of a power hedge ``"pow:p"`` (Octave FIS hedge codes), else None."""
    if not name.startswith("pow:"):
        return None
    try:
        return float(name[4:])
    except ValueError:
        return None


def hedge_function(name: str) -> Callable[[float], float]:
    """The scalar function of a hedge name (``HEDGES`` or ``"pow:p"``)."""
    p = power_of(name)
    f = (lambda x: float(max(x, 0.0) ** p)) if p is not None else HEDGES[name]

    def hedge(x: float) -> float:
        try:
            return f(x)
        except (ArithmeticError, ValueError):  # the IEEE value, as in hedge_np and the C
            with np.errstate(all="ignore"):
                return float(hedge_np(name, np.float64(x)))

    return hedge


def hedge_np(name: str, x: Any) -> Any:
    """Vectorised hedge."""
    p = power_of(name)
    if p is not None:
        return np.maximum(x, 0.0) ** p
    if name == "not":
        return 1.0 - x
    if name == "very":
        return x * x
    if name == "somewhat":
        return np.sqrt(np.maximum(x, 0.0))
    if name == "extremely":
        return np.where(x <= 0.5, 2.0 * x * x, 1.0 - 2.0 * (1.0 - x) * (1.0 - x))
    if name == "seldom":
        return np.where(
            x <= 0.5, np.sqrt(0.5 * np.maximum(x, 0.0)), 1.0 - np.sqrt(0.5 * np.maximum(1.0 - x, 0.0))
        )
    if name == "any":
        return np.ones_like(x)
    raise ValueError(f"unknown hedge {name!r}")


# --------------------------------------------------------------------------- Tsukamoto


def tsukamoto(kind: str, params: Sequence[float], height: float, y: float) -> float:
    """The x at which a monotonic term reaches degree ``y`` (Tsukamoto inference)."""
    h = float(height)
    p = list(params)
    if kind == "points":
        return float(_monotone_inverse(p, h, y))
    try:
        if kind == "ramp":
            s, e = p
            return s + (e - s) * y / h
        if kind == "sigmoid":
            i, s = p
            return i + math.log(h / y - 1.0) / -s
        if kind == "sshape":
            s, e = p
            return (
                s + (e - s) * math.sqrt(y / (2.0 * h))
                if y <= 0.5 * h
                else e - (e - s) * math.sqrt((h - y) / (2.0 * h))
            )
        if kind == "zshape":
            s, e = p
            return (
                s + (e - s) * math.sqrt((h - y) / (2.0 * h))
                if y >= 0.5 * h
                else e - (e - s) * math.sqrt(y / (2.0 * h))
            )
        if kind == "concave":
            i, e = p
            return h * (i - e) / y + 2.0 * e - i
        if kind == "arc":
            s, e = p
            r = e - s
            return e + (-1.0 if s < e else 1.0) * math.sqrt(max(r * r - (y * r / h) ** 2, 0.0))
    except (ArithmeticError, ValueError):
        # log(0), a division by zero: the IEEE value of the numpy path (whose sign follows the
        # slope), so that every backend agrees
        return float(tsukamoto_np(kind, params, height, np.float64(y)))
    raise ValueError(f"{kind} is not monotonic")


def tsukamoto_np(kind: str, params: Sequence[Any], height: Any, y: Any) -> Any:
    """Vectorised :func:`tsukamoto`."""
    h = height
    if kind == "points":
        return _monotone_inverse([float(v) for v in params], float(h), y)
    with np.errstate(all="ignore"):
        if kind == "ramp":
            s, e = params
            return s + (e - s) * y / h
        if kind == "sigmoid":
            i, s = params
            return i + np.log(h / y - 1.0) / -s
        if kind == "sshape":
            s, e = params
            return np.where(
                y <= 0.5 * h, s + (e - s) * np.sqrt(y / (2.0 * h)), e - (e - s) * np.sqrt((h - y) / (2.0 * h))
            )
        if kind == "zshape":
            s, e = params
            return np.where(
                y >= 0.5 * h, s + (e - s) * np.sqrt((h - y) / (2.0 * h)), e - (e - s) * np.sqrt(y / (2.0 * h))
            )
        if kind == "concave":
            i, e = params
            return h * (i - e) / y + 2.0 * e - i
        if kind == "arc":
            s, e = params
            r = e - s
            return e + np.where(s < e, -1.0, 1.0) * np.sqrt(np.maximum(r * r - (y * r / h) ** 2, 0.0))
    raise ValueError(f"{kind} is not monotonic")


def monotone(points: Points) -> bool:
    """Whether a breakpoint list never falls or never rises (a Tsukamoto term)."""
    ys = [y for _x, y in points]
    return all(a <= b for a, b in itertools.pairwise(ys)) or all(a >= b for a, b in itertools.pairwise(ys))


def _monotone_inverse(params: Sequence[float], h: float, y: Any) -> Any:
    """Where monotonic points reach degree ``y`` (the nearest end beyond their values)."""
    pts = pwl_points("points", params, h)
    assert pts is not None
    xs, ys = [x for x, _y in pts], [v for _x, v in pts]
    if ys[0] > ys[-1]:
        xs, ys = xs[::-1], ys[::-1]
    return np.interp(y, ys, xs)
