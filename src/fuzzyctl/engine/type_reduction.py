"""Type reduction of a discrete interval type-2 set: the centroid interval ``[yl, yr]`` of
points ``x`` with membership intervals ``[lower, upper]`` (the entries of
:mod:`fuzzyctl.kinds.type_reduction`).

``yl`` is the least weighted mean ``sum(x w) / sum(w)`` over the weights ``lower <= w <=
upper``; it takes the upper weights left of a switch point and the lower ones right of it
(``yr``: the other way round).  Each method finds that switch point exactly (they differ in
the search only), so all four give the same end points up to rounding; a set whose weights
are all zero gives NaN.
"""

from __future__ import annotations

import math
from collections.abc import Sequence

Interval = tuple[float, float]


def _sorted(
    x: Sequence[float], lower: Sequence[float], upper: Sequence[float]
) -> tuple[list[float], list[float], list[float]]:
    order = sorted(range(len(x)), key=lambda i: x[i])
    return [float(x[i]) for i in order], [float(lower[i]) for i in order], [float(upper[i]) for i in order]


def _mean(x: list[float], w: list[float]) -> float:
    total = math.fsum(w)
    return math.fsum(a * b for a, b in zip(x, w, strict=True)) / total if total > 0.0 else math.nan


def _switched(x: list[float], lo: list[float], up: list[float], k: int, left_upper: bool) -> float:
    """The weighted mean with the first ``k`` points at one bound and the rest at the other."""
    first, rest = (up, lo) if left_upper else (lo, up)
    return _mean(x, first[:k] + rest[k:])


def _km_end(x: list[float], lo: list[float], up: list[float], left_upper: bool) -> float:
    y = _mean(x, [(a + b) / 2.0 for a, b in zip(lo, up, strict=True)])
    if math.isnan(y):
        return _switched(x, lo, up, len(x) if left_upper else 0, left_upper)
    for _ in range(len(x) + 2):  # KM converges in at most n steps
        k = sum(1 for v in x if v <= y)
        y_next = _switched(x, lo, up, k, left_upper)
        if math.isnan(y_next) or y_next == y:
            return y_next if not math.isnan(y_next) else y
        y = y_next
    return y


def karnik_mendel(x: Sequence[float], lower: Sequence[float], upper: Sequence[float]) -> Interval:
    """Karnik-Mendel: start from the mean of the interval midpoints, move the switch point
    to where the current estimate falls, until it stays."""
    xs, lo, up = _sorted(x, lower, upper)
    if not xs:
        return math.nan, math.nan
    return _km_end(xs, lo, up, True), _km_end(xs, lo, up, False)


def _split_mean(x: list[float], first: list[float], rest: list[float], k: int) -> float | None:
    """The weighted mean with the first ``k`` points weighted by ``first`` and the others by
    ``rest``, each side summed exactly (None: every weight zero).  Updating the sums by the
    points that change side (Wu and Mendel's saving) cancels catastrophically when the
    weights left are small (lower weights of zero), giving a mean outside the points."""
    n = len(x)
    a = math.fsum(x[i] * first[i] for i in range(k)) + math.fsum(x[i] * rest[i] for i in range(k, n))
    b = math.fsum(first[:k]) + math.fsum(rest[k:])
    return a / b if b > 0.0 else None


def _ekm_end(x: list[float], lo: list[float], up: list[float], left_upper: bool) -> float:
    n = len(x)
    k = max(1, min(n - 1, round(n / 2.4 if left_upper else n / 1.7)))
    first, rest = (up, lo) if left_upper else (lo, up)
    y = _split_mean(x, first, rest, k)
    for _ in range(n + 2):
        if y is None:  # every weight on this side zero: KM's search handles it
            return _km_end(x, lo, up, left_upper)
        k2 = sum(1 for v in x if v <= y)
        if k2 == k:
            return y
        k = k2
        y = _split_mean(x, first, rest, k)
    return y if y is not None else _km_end(x, lo, up, left_upper)


def enhanced_karnik_mendel(x: Sequence[float], lower: Sequence[float], upper: Sequence[float]) -> Interval:
    """EKM (Wu and Mendel 2009): KM from the switch points n/2.4 and n/1.7 (the sums of each
    new switch point are summed exactly, not updated: see :func:`_split_mean`)."""
    xs, lo, up = _sorted(x, lower, upper)
    if not xs:
        return math.nan, math.nan
    if len(xs) == 1:
        return xs[0], xs[0]
    return _ekm_end(xs, lo, up, True), _ekm_end(xs, lo, up, False)


def _scan_left(x: list[float], lo: list[float], up: list[float], early: bool) -> float:
    """``yl`` by moving points from the lower to the upper weight, left to right."""
    a = math.fsum(v * w for v, w in zip(x, lo, strict=True))
    b = math.fsum(lo)
    best = a / b if b > 0.0 else math.inf
    for i in range(len(x)):
        d = up[i] - lo[i]
        a += x[i] * d
        b += d
        if b <= 0.0:
            continue
        y = a / b
        if early and i + 1 < len(x) and y <= x[i + 1]:
            return min(best, y)
        if not early and y > best:
            return best  # the mean rises again: the minimum is behind (IASC)
        best = min(best, y)
    return best if math.isfinite(best) else math.nan


def _scan_right(x: list[float], lo: list[float], up: list[float], early: bool) -> float:
    """``yr`` by moving points from the lower to the upper weight, right to left."""
    a = math.fsum(v * w for v, w in zip(x, lo, strict=True))
    b = math.fsum(lo)
    best = a / b if b > 0.0 else -math.inf
    for i in range(len(x) - 1, -1, -1):
        d = up[i] - lo[i]
        a += x[i] * d
        b += d
        if b <= 0.0:
            continue
        y = a / b
        if early and i > 0 and y >= x[i - 1]:
            return max(best, y)
        if not early and y < best:
            return best
        best = max(best, y)
    return best if math.isfinite(best) else math.nan


def iasc(x: Sequence[float], lower: Sequence[float], upper: Sequence[float]) -> Interval:
    """IASC (Duran, Bernal and Melgarejo 2008): scan the switch point from one end until the
    weighted mean stops improving."""
    xs, lo, up = _sorted(x, lower, upper)
    if not xs:
        return math.nan, math.nan
    return _scan_left(xs, lo, up, False), _scan_right(xs, lo, up, False)


def eiasc(x: Sequence[float], lower: Sequence[float], upper: Sequence[float]) -> Interval:
    """EIASC (Wu and Nie 2011): the same scan, stopped as soon as the mean falls before the
    next point (``yl``) or after the previous one (``yr``)."""
    xs, lo, up = _sorted(x, lower, upper)
    if not xs:
        return math.nan, math.nan
    return _scan_left(xs, lo, up, True), _scan_right(xs, lo, up, True)
