"""Smooth input terms in integer arithmetic: a piecewise-linear stand-in with a proven
maximum deviation (``codegen --arith int16|int32``).

The integer block reads each input as a stored integer ``k`` (``value = k * scale +
offset``, ``k`` limited to the input's stored range), so a term is only ever evaluated at
those values.  A smooth term (a registry shape with a formula: Gaussian, bell, sigmoid, ...)
is replaced there by chords between breakpoints at stored values ``k_0 < ... < k_n`` (the
first and last the range's ends: no tail is left outside), each chord through the engine's
degrees at its ends.

*Placement* (not part of the proof): the degrees are sampled, the samples refined where the
curve bends until neighbouring samples' chords are close, then each chord is made as long as
the samples allow (greedy, half the tolerance): breakpoints are dense where the curvature is.

*Proof*: on each chord's stored values, the deviation ``|f - chord|`` is bounded by interval
arithmetic over the shape's own formula (:mod:`fuzzyctl.kinds.enclose`): on a sub-interval,
the smaller of the enclosure of ``f`` against the chord's range there and the mean value form
``g(centre) + g'(interval) * radius`` (``g = f - chord``; the enclosure of ``f'`` comes from
the same formula).  A sub-interval whose bound exceeds the tolerance is halved, down to a
single stored value (an enclosure one float step wide); a chord that fails at a stored value
is split there.  The proven deviation is the largest bound of the accepted sub-intervals, plus
a margin for the engine's own float rounding of the formula."""

from __future__ import annotations

import bisect
import math
from collections.abc import Callable
from dataclasses import dataclass
from fractions import Fraction
from typing import Any

import numpy as np
import numpy.typing as npt

from fuzzyctl.engine.plan import TermPlan
from fuzzyctl.engine.semantics.shapes import NUMPY
from fuzzyctl.escape import CodegenError
from fuzzyctl.kinds import formula as fm
from fuzzyctl.kinds import shapes as registry
from fuzzyctl.kinds.arith import Arith
from fuzzyctl.kinds.enclose import enclose

__all__ = ["MAX_PIECES", "SmoothTerm", "approximate", "default_tolerance", "hull", "parse_term_tolerance"]

#: the most chords one term may take (a bisection over them is at most 10 comparisons deep)
MAX_PIECES = 1024
#: the engine's float evaluation of a formula against its real value (degrees are <= 1)
_FLOAT_MARGIN = 4e-15
_SUB = 8  # sub-intervals a chord's proof starts from
_FAST = {**NUMPY, "exp": np.exp, "cos": np.cos, "pow": np.power}
_Ints = npt.NDArray[np.int64]
_Arr = npt.NDArray[np.float64]


@dataclass(frozen=True)
class SmoothTerm(TermPlan):
    """A smooth term and its stand-in: ``knots`` (stored input values) with ``degrees`` there,
    ``pwl`` the same points in the input's unit, ``deviation`` the proven largest
    ``|term - chords|`` over the stored input range, ``tolerance`` the one asked for."""

    knots: tuple[int, ...] = ()
    degrees: tuple[float, ...] = ()
    deviation: float = 0.0
    tolerance: float = 0.0
    xs: tuple[float, ...] = ()  # the breakpoints in the input's unit (``pwl``'s x)


def default_tolerance(arith: Arith) -> float:
    """The deviation allowed by default.  int16: 2.5e-4, four units of the stored degree
    (2**-14), so the chords add about as much to an output's bound as the block's own
    roundings do (a Gaussian takes about 55 chords, 6 comparisons).  int32: 1e-5; the
    degree's own unit there (2**-30) is out of reach at any affordable size (a Gaussian
    takes about 300-560 chords, 9-10 comparisons), so the chords set the int32 bound."""
    return 2.5e-4 if arith.bits <= 16 else 1e-5


def parse_term_tolerance(value: object) -> float | None:
    """``--term-tolerance``: a deviation in degrees, 1e-9 <= t <= 0.1 (None: the default)."""
    if value is None:
        return None
    try:
        t = float(value)  # type: ignore[arg-type]
    except (TypeError, ValueError):
        raise CodegenError(f"--term-tolerance {value!r}: give a number of degrees, e.g. 1e-4") from None
    if not 1e-9 <= t <= 0.1:
        raise CodegenError(f"--term-tolerance {value!r}: give a deviation between 1e-09 and 0.1 degrees")
    return t


class _Grid:
    """Stored input values of one input and the term's degrees there."""

    def __init__(self, term: TermPlan, scale: Fraction, offset: Fraction) -> None:
        self.term = term
        self.s, self.o = float(scale), float(offset)
        self.exact = Fraction(self.s) == scale and Fraction(self.o) == offset
        self.params = tuple(float(p) for p in term.params)  # type: ignore[arg-type]
        self.h = float(term.height)  # type: ignore[arg-type]
        self.fast: Callable[..., Any] | None = None

    def x(self, k: npt.ArrayLike) -> _Arr:
        return np.asarray(k, dtype=np.float64) * self.s + self.o

    def degree(self, k: npt.ArrayLike) -> _Arr:
        """The degrees at stored values, by numpy's own functions (faster than the engine's
        C-library ones, which match the scalar engine to the last bit): they only place the
        breakpoints and give the chords' ends, and the proof covers whatever values these are."""
        fn = self.fast
        if fn is None:
            shape = registry.SHAPES[self.term.kind]
            fn = self.fast = fm.vectorised(shape.parsed(), _FAST, registry.HELPERS)
        with np.errstate(all="ignore"):
            return np.asarray(self.h * fn(self.x(k), *self.params), dtype=np.float64)

    def bounds(self, k0: _Arr, k1: _Arr) -> tuple[_Arr, _Arr]:
        """Float intervals holding the values of ``[k0, k1]``: their floats where
        ``k * scale + offset`` is exact (scale is a power of two: only the sum may round),
        else one step outward."""
        out = []
        for k, way in ((k0, -math.inf), (k1, math.inf)):
            a = np.asarray(k, dtype=np.float64) * self.s
            x = a + self.o
            bb = x - a
            err = (a - (x - bb)) + (self.o - bb)
            out.append(np.where(err == 0, x, np.nextafter(x, way)))
        return out[0], out[1]


def _samples(g: _Grid, low: int, high: int, target: float) -> tuple[_Ints, _Arr]:
    """Stored values and degrees, refined until each neighbouring pair's chord is within
    ``target / 4`` of the degree at its midpoint (or the pair is adjacent)."""
    ks = np.unique(np.linspace(low, high, min(high - low + 1, 2049)).round().astype(np.int64))
    ys = g.degree(ks)
    for _ in range(64):
        gap = np.diff(ks) > 1
        mid = (ks[:-1] + ks[1:]) // 2
        ym = g.degree(mid)
        bad = gap & ~(np.abs(ym - (ys[:-1] + ys[1:]) / 2) <= target / 4)
        # a pair whose midpoint is fine may still hide a bend between samples: also refine
        # where the slope changes (second difference) more than the target
        if len(ys) > 2:
            d2 = np.abs(np.diff(ys, 2))
            bend = np.zeros(len(gap), dtype=bool)
            bend[:-1] |= d2 > target
            bend[1:] |= d2 > target
            bad |= gap & bend & (np.diff(ks) > 1)
        if not bad.any():
            break
        ks = np.concatenate([ks, mid[bad]])
        ys = np.concatenate([ys, ym[bad]])
        order = np.argsort(ks, kind="stable")
        ks, ys = ks[order], ys[order]
        if len(ks) > 400_000:
            break
    return ks, ys


def _greedy(ks: _Ints, ys: _Arr, target: float) -> list[int]:
    """Indices of breakpoints: each chord as long as the samples under it stay within
    ``target`` (exponential then binary search on its far end)."""
    n = len(ks)

    def fits(i: int, j: int) -> bool:
        t = (ks[i : j + 1] - ks[i]) / (ks[j] - ks[i])
        chord = ys[i] + (ys[j] - ys[i]) * t
        return bool(np.max(np.abs(ys[i : j + 1] - chord)) <= target)

    out, i = [0], 0
    while i < n - 1:
        step, good = 1, i + 1
        while good + step < n and fits(i, good + step):
            good += step
            step *= 2
        lo, hi = good, min(good + step, n - 1)
        while hi - lo > 1:
            m = (lo + hi) // 2
            if fits(i, m):
                lo = m
            else:
                hi = m
        if hi > lo and fits(i, hi):
            lo = hi
        out.append(lo)
        i = lo
    return out


def _bounds(g: _Grid, ka: _Arr, ya: _Arr, kb: _Arr, yb: _Arr, k0: _Arr, k1: _Arr) -> _Arr:
    """A proven bound of ``|f - chord|`` on the stored values of each ``[k0, k1]``."""
    shape = registry.SHAPES[g.term.kind]
    n = len(k0)
    kc = (k0 + k1) / 2
    x0, x1 = g.bounds(k0, k1)
    xc0, xc1 = g.bounds(kc, kc)
    e = enclose(
        shape.parsed(), registry.HELPERS, np.concatenate([x0, xc0]), np.concatenate([x1, xc1]), g.params
    )
    h = g.h  # a height in [0, 1] scales values and derivatives (one more rounding each)
    lo, hi = np.nextafter(e.lo * h, -math.inf), np.nextafter(e.hi * h, math.inf)
    dlo, dhi = np.nextafter(e.dlo * h, -math.inf), np.nextafter(e.dhi * h, math.inf)
    span = kb - ka

    def chord(k: _Arr) -> _Arr:
        return ya + (yb - ya) * ((k - ka) / np.where(span > 0, span, 1.0))

    c0, c1, cc = chord(k0), chord(k1), chord(kc)
    clo, chi = np.minimum(c0, c1) - 1e-15, np.maximum(c0, c1) + 1e-15
    with np.errstate(all="ignore"):
        naive = np.maximum(hi[:n] - clo, chi - lo[:n])
        slope = (yb - ya) / (np.where(span > 0, span, 1.0) * g.s)
        gd = np.maximum(np.abs(dlo[:n] - slope), np.abs(dhi[:n] - slope)) * (1 + 1e-12)
        radius = np.maximum(xc1 - x0, x1 - xc0) * (1 + 1e-12)
        centre = np.maximum(np.abs(lo[n:] - cc), np.abs(hi[n:] - cc)) + 1e-15
        mvf = centre + gd * radius
        out = np.fmin(naive, mvf)
    return np.where(np.isnan(out), math.inf, out)


def _prove(g: _Grid, knots: list[int], ys: list[float], tol: float) -> tuple[list[float], dict[int, int]]:
    """Each chord's proven deviation, and the chords that fail (chord -> a stored value where
    the bound exceeds ``tol`` at a single value: split there)."""
    npiece = len(knots) - 1
    ka_all, kb_all = np.array(knots[:-1], dtype=np.float64), np.array(knots[1:], dtype=np.float64)
    ya_all, yb_all = np.array(ys[:-1]), np.array(ys[1:])
    piece = np.repeat(np.arange(npiece), _SUB)
    frac = np.tile(np.arange(_SUB), npiece)
    length = (kb_all - ka_all)[piece]
    k0 = ka_all[piece] + np.floor(length * frac / _SUB)
    k1 = ka_all[piece] + np.floor(length * (frac + 1) / _SUB)
    best = [0.0] * npiece
    failed: dict[int, int] = {}
    for _ in range(80):
        if len(piece) == 0:
            break
        b = _bounds(g, ka_all[piece], ya_all[piece], kb_all[piece], yb_all[piece], k0, k1)
        ok = b <= tol
        for p, v in zip(piece[ok].tolist(), b[ok].tolist(), strict=True):
            best[p] = max(best[p], v)
        bad = ~ok & ~np.isin(piece, list(failed))
        point = bad & (k0 >= k1)
        for p, k in zip(piece[point].tolist(), k0[point].tolist(), strict=True):
            failed.setdefault(p, int(k))
        split = bad & (k0 < k1)
        p, a, z = piece[split], k0[split], k1[split]
        m = np.floor((a + z) / 2)
        piece, k0, k1 = np.concatenate([p, p]), np.concatenate([a, m + 1]), np.concatenate([m, z])
    for p in np.unique(piece).tolist():  # not settled (cannot happen within 80 halvings of 2**32)
        failed.setdefault(p, (knots[p] + knots[p + 1]) // 2)
    return best, failed


def _attempt(g: _Grid, low: int, high: int, tol: float) -> tuple[list[int], list[float], float] | str:
    """Breakpoints, degrees and the proven deviation; or why not."""
    ks, ys = _samples(g, low, high, tol)
    if not np.all(np.isfinite(ys)):
        k = int(ks[~np.isfinite(ys)][0])
        return f"its degree is not a number at {g.x(k):g}"
    idx = _greedy(ks, ys, 0.7 * tol)
    knots = [int(ks[i]) for i in idx]
    degs = [float(ys[i]) for i in idx]
    for _ in range(40):
        if len(knots) - 1 > MAX_PIECES:
            return f"more than {MAX_PIECES} chords are needed"
        if len(knots) == 1:
            return knots, degs, 0.0
        best, failed = _prove(g, knots, degs, tol)
        if not failed:
            return knots, degs, max(best) + _FLOAT_MARGIN
        for p in sorted(failed, reverse=True):
            a, b = knots[p], knots[p + 1]
            k = failed[p] if a < failed[p] < b else (a + b) // 2
            if not a < k < b:
                return f"its formula could not be bounded near {g.x(k):g}"
            knots.insert(p + 1, k)
            degs.insert(p + 1, float(g.degree([k])[0]))
    return "the proof did not settle"


def approximate(
    term: TermPlan,
    where: str,
    scale: Fraction,
    offset: Fraction,
    low: int,
    high: int,
    tolerance: float,
    loosen: bool,
) -> SmoothTerm:
    """``term`` (a smooth shape with constant parameters, height in 0..1) as chords over the
    stored values ``low..high`` of ``value = stored * scale + offset``, within ``tolerance``
    degrees (``loosen``: when that takes more than :data:`MAX_PIECES` chords, the tolerance is
    doubled until it does not, up to 0.01).  ``where`` names the term in a refusal."""
    g = _Grid(term, scale, offset)
    tol = tolerance
    while True:
        got = _attempt(g, low, high, tol)
        if not isinstance(got, str):
            break
        if not (loosen and got.startswith("more than") and tol * 2 <= 0.01):
            hint = " (give a larger --term-tolerance)" if got.startswith("more than") else ""
            raise CodegenError(
                f"{where}: a {term.kind} term within {tol:g} degrees in integer arithmetic: {got}{hint} "
                "(use --arith float)"
            )
        tol *= 2
    knots, degs, dev = got
    pwl = tuple((float(Fraction(k) * scale + offset), y) for k, y in zip(knots, degs, strict=True))
    return SmoothTerm(
        term.name,
        term.kind,
        term.params,
        term.height,
        term.expr,
        pwl,
        knots=tuple(knots),
        degrees=tuple(degs),
        deviation=dev,
        tolerance=tol,
        xs=tuple(x for x, _y in pwl),
    )


def hull(term: SmoothTerm, a: float, b: float) -> tuple[float, float]:
    """An interval holding the term's exact degree for every input in ``[a, b]``: the chords'
    hull there widened by the proven deviation (and a margin for this float arithmetic)."""
    xs, ys = term.xs, term.degrees

    def at(x: float) -> float:
        i = bisect.bisect_right(xs, x)
        if i == 0:
            return ys[0]
        if i == len(xs):
            return ys[-1]
        x0, x1 = xs[i - 1], xs[i]
        return ys[i - 1] + (ys[i] - ys[i - 1]) * ((x - x0) / (x1 - x0))

    i, j = bisect.bisect_right(xs, a), bisect.bisect_left(xs, b)
    vals = [at(a), at(b), *ys[i:j]]
    slack = term.deviation + 1e-12
    return max(0.0, min(vals) - slack), min(1.0, max(vals) + slack)
