"""Membership functions: evaluation of the shape registry's formulas.

Every shape kind of :data:`fuzzyctl.model.SHAPES` is an entry of :mod:`fuzzyctl.kinds.shapes`
whose formula is written once; here it is compiled for a Python float (``math``) and for
numpy arrays (:data:`NUMPY`: the C library's functions element by element) from the same
syntax tree, so the scalar and the batch evaluators agree to the last bit (and
:mod:`fuzzyctl.ir.builders.terms` translates the same tree to the IR of the generated code).

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
from fuzzyctl.kinds import formula
from fuzzyctl.kinds import shapes as registry

FloatArray = npt.NDArray[np.float64]
Points = tuple[tuple[float, float], ...]

#: Shapes that are piecewise linear and become breakpoint lists (and IEC points).
PWL_KINDS = frozenset({"points"}) | registry.kinds_where(lambda s: s.piecewise_linear)
#: Takagi-Sugeno output terms: a value, not a fuzzy set (and function terms).
TS_KINDS = frozenset({"function"}) | registry.kinds_where(lambda s: s.takagi_sugeno)
#: Monotonic shapes a weighted average can invert (Tsukamoto outputs, fuzzylite; monotonic
#: ``points`` under COGS: jfuzzyqt's Tsukamoto).
TSUKAMOTO_KINDS = frozenset({"points"}) | registry.kinds_where(lambda s: s.tsukamoto_invertible)
#: Smooth parametric shapes (integrated by adaptive quadrature on outputs).
SMOOTH_KINDS = registry.kinds_where(lambda s: s.smooth)

#: What the numpy forms of the registry's formulas call: the C library's transcendental
#: functions element by element (libm_np), numpy's exact operations.
NUMPY: dict[str, Any] = {
    "exp": libm_np.exp,
    "cos": libm_np.cos,
    "pow": libm_np.pow_,
    "log": np.log,
    "sqrt": np.sqrt,
    "abs": np.abs,
    "min": np.minimum,
    "max": np.maximum,
    "isnan": np.isnan,
    "where": np.where,
    "pi": np.pi,
    "nan": np.nan,
}


def _compiled(kind: str, which: str) -> Callable[..., Any]:
    """The registry formula of ``kind`` (``which``: "float", "np", "tsu", "tsu_np"),
    compiled once."""
    shape = registry.SHAPES.get(kind)
    if shape is None:
        raise ValueError(f"unknown shape kind {kind!r}")
    fn = shape.compiled.get(which)
    if fn is None:
        if which in ("float", "np") and not shape.smooth:
            raise ValueError(f"{kind} has no formula ({shape.formula})")
        if which in ("tsu", "tsu_np") and not shape.tsukamoto_invertible:
            raise ValueError(f"{kind} is not monotonic")
        f = shape.parsed() if which in ("float", "np") else shape.parsed_tsukamoto()
        if which in ("float", "tsu"):
            fn = formula.scalar(f, registry.HELPERS)
        else:
            fn = formula.vectorised(f, NUMPY, registry.HELPERS)
        shape.compiled[which] = fn
    return fn


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
    shape = registry.SHAPES.get(kind)
    if shape is None or isinstance(shape.breakpoints, registry.NA):
        return None
    return shape.breakpoints(p, h)


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


#: kind -> the float form of its formula (filled on first use: the hot path of membership)
_FLOAT: dict[str, Callable[..., float]] = {}


def smooth(kind: str, p: Sequence[float], x: float) -> float:
    """A smooth shape's formula (the registry's, compiled for floats) at ``x``, height 1."""
    fn = _FLOAT.get(kind)
    if fn is None:
        fn = _FLOAT[kind] = _compiled(kind, "float")
    return fn(x, *p)


def smooth_np(kind: str, p: Sequence[Any], x: Any) -> Any:
    """:func:`smooth` on numpy arrays (the same formula, compiled for numpy)."""
    with np.errstate(all="ignore"):
        return _compiled(kind, "np")(x, *p)


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
        return float(height) * smooth(kind, params, x)
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
    return np.asarray(height * smooth_np(kind, p64, x), dtype=np.float64)


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
    elif (vertices := registry.vertices(kind)) is not None:  # the parameters are the x
        xs = np.stack(flat, axis=1)
        ys = np.stack([zero if v == 0.0 else hh if v == 1.0 else v * hh for v in vertices], axis=1)
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
    shape = registry.SHAPES.get(kind)
    if shape is not None and not isinstance(shape.support, registry.NA):
        return shape.support([float(v) for v in params])
    return (-inf, inf)


def characteristic_points(kind: str, params: Sequence[float]) -> tuple[float, ...]:
    """Points where a smooth shape changes character (peaks, joins, support ends): the
    adaptive quadrature splits there first so that it never misses a narrow peak."""
    shape = registry.SHAPES.get(kind)
    if shape is not None and not isinstance(shape.characteristic, registry.NA):
        return shape.characteristic([float(v) for v in params])
    pts = pwl_points(kind, params)
    if pts is not None:
        return tuple(x for x, _y in pts)
    if kind == "singleton":
        return (float(params[0]),)
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
    fn = _compiled(kind, "tsu")
    try:
        return float(fn(y, h, *p))
    except (ArithmeticError, ValueError):
        # log(0), a division by zero: the IEEE value of the numpy path (whose sign follows the
        # slope), so that every backend agrees
        return float(tsukamoto_np(kind, params, height, np.float64(y)))


def tsukamoto_np(kind: str, params: Sequence[Any], height: Any, y: Any) -> Any:
    """Vectorised :func:`tsukamoto`."""
    h = height
    if kind == "points":
        return _monotone_inverse([float(v) for v in params], float(h), y)
    fn = _compiled(kind, "tsu_np")
    with np.errstate(all="ignore"):
        return fn(y, h, *params)


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
