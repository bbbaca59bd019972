"""Adaptive Gauss-Kronrod (7/15) quadrature for accumulated sets that are not piecewise
linear (smooth shapes, or operators such as Einstein/Hamacher that bend straight lines).

The integrand is evaluated with numpy on every node of every open interval at once.  An
interval is accepted when the Kronrod-Gauss difference of both the area and the first moment
is below ``rtol`` times the total (scaled by the interval's share of the range); the others
are halved.  The initial intervals are cut at every term's characteristic points (peaks,
joins, support ends), so narrow peaks are never missed, and kinks (clipping, crossings) are
isolated by the bisection.  With the default ``rtol = 1e-10`` the results agree with a
10^6-point reference to better than 1e-9 relative (tests/engine/test_exactness.py).
"""

from __future__ import annotations

import math
from collections.abc import Callable, Sequence
from typing import Any

import numpy as np

from fuzzyctl.engine.reference.pwl import COA_TOL
from fuzzyctl.engine.semantics.operators import fsum
from fuzzyctl.engine.semantics.shapes import FloatArray

_XGK = np.array(
    [
        0.991455371120812639206854697526329,
        0.949107912342758524526189684047851,
        0.864864423359769072789712788640926,
        0.741531185599394439863864773280788,
        0.586087235467691130294144845693013,
        0.405845151377397166906606412076961,
        0.207784955007898467600689403773245,
        0.0,
    ]
)
_WGK = np.array(
    [
        0.022935322010529224963732008058970,
        0.063092092629978553290700663189204,
        0.104790010322250183839876322541518,
        0.140653259715525918745189590510238,
        0.169004726639267902826583426598550,
        0.190350578064785409913256402421014,
        0.204432940075298892414161999234649,
        0.209482141084727828012999174891714,
    ]
)
_WG = np.array(
    [
        0.129484966168869693270611432679082,
        0.279705391489276667901467771423780,
        0.381830050505118944950369775488975,
        0.417959183673469387755102040816327,
    ]
)
# 15 nodes on [-1, 1] and their weights; the 7-point Gauss rule uses every other node.
NODES = np.concatenate([-_XGK[:-1], [0.0], _XGK[:-1][::-1]])
WK = np.concatenate([_WGK[:-1], [_WGK[-1]], _WGK[:-1][::-1]])
WG = np.zeros(15)
WG[1::2] = [_WG[0], _WG[1], _WG[2], _WG[3], _WG[2], _WG[1], _WG[0]]

Integrand = Callable[[FloatArray], FloatArray]
MAX_INTERVALS = 40_000


def _rule(
    f: Integrand, a: FloatArray, b: FloatArray
) -> tuple[FloatArray, FloatArray, FloatArray, FloatArray, FloatArray]:
    half = 0.5 * (b - a)
    mid = 0.5 * (a + b)
    x = mid[:, None] + half[:, None] * NODES[None, :]
    y = f(x.ravel()).reshape(x.shape)
    k = (y @ WK) * half
    g = (y @ WG) * half
    km = ((y * x) @ WK) * half
    gm = ((y * x) @ WG) * half
    return k, np.abs(k - g), km, np.abs(km - gm), y


def integrate(
    f: Integrand, cuts: Sequence[float], rtol: float = 1e-10
) -> tuple[FloatArray, FloatArray, FloatArray, FloatArray]:
    """Integrate ``f`` and ``x f`` over ``[cuts[0], cuts[-1]]``.  Returns the accepted
    intervals ``(a, b, area, moment)``, sorted by ``a``."""
    edges = np.array(sorted(set(cuts)), dtype=np.float64)
    a, b = edges[:-1], edges[1:]
    span = float(edges[-1] - edges[0])
    scale = max(abs(float(edges[0])), abs(float(edges[-1])), span)
    k, ek, km, ekm, _y = _rule(f, a, b)
    total = max(float(np.sum(np.abs(k))), 1e-300)
    done: list[tuple[FloatArray, FloatArray, FloatArray, FloatArray]] = []
    n_open = len(a)
    while True:
        share = (b - a) / span
        tol = rtol * total * np.maximum(share, 1e-6)
        ok = (ek <= tol) & (ekm <= tol * scale) | ((b - a) <= 1e-13 * scale)
        if not (np.isfinite(k).all() and np.isfinite(km).all()):
            ok = np.ones_like(ok)  # NaN/inf (a 0/0 in a function term): no halving makes it a number
        if n_open + len(done) > MAX_INTERVALS:  # give up refining: keep the best estimate
            ok = np.ones_like(ok)
        done.append((a[ok], b[ok], k[ok], km[ok]))
        if ok.all():
            break
        a, b = a[~ok], b[~ok]
        m = 0.5 * (a + b)
        a, b = np.concatenate([a, m]), np.concatenate([m, b])
        n_open += len(a)
        k, ek, km, ekm, _y = _rule(f, a, b)
    A = np.concatenate([d[0] for d in done])
    B = np.concatenate([d[1] for d in done])
    K = np.concatenate([d[2] for d in done])
    KM = np.concatenate([d[3] for d in done])
    order = np.argsort(A, kind="stable")
    return A[order], B[order], K[order], KM[order]


def kinks(branch: Callable[[FloatArray], list[Any]], cuts: Sequence[float], samples: int = 16) -> list[float]:
    """Points between ``cuts`` where ``branch(x)`` (which piece of a formula x falls in)
    changes: each interval sampled at ``samples`` points, every change located by bisection
    to the float (a kink inside an interval can fool the error estimate).  A gap between two
    samples may pass several pieces: one is found per round, four rounds at most."""
    edges = np.array(sorted(set(cuts)), dtype=np.float64)
    t = np.linspace(0.0, 1.0, samples)
    xs = (edges[:-1, None] + (edges[1:] - edges[:-1])[:, None] * t[None, :]).ravel()
    codes = branch(xs)
    gaps = [i for i in range(len(xs) - 1) if codes[i] != codes[i + 1] and xs[i] < xs[i + 1]]
    lo = np.array([xs[i] for i in gaps])
    hi = np.array([xs[i + 1] for i in gaps])
    c_lo = [codes[i] for i in gaps]
    c_end = [codes[i + 1] for i in gaps]
    out: list[float] = []
    for _round in range(4):
        if not len(lo):
            break
        end = hi.copy()
        while True:  # all gaps at once, to the last bit
            mid = 0.5 * (lo + hi)
            open_ = (mid != lo) & (mid != hi)
            if not open_.any():
                break
            same = np.array([c == c0 for c, c0 in zip(branch(mid), c_lo, strict=True)]) & open_
            lo = np.where(same, mid, lo)
            hi = np.where(same | ~open_, hi, mid)
        out += [float(v) for v in hi]
        c_hi = branch(hi)
        more = [k for k in range(len(hi)) if c_hi[k] != c_end[k] and hi[k] < end[k]]
        lo, hi = hi[more], end[more]
        c_lo, c_end = [c_hi[k] for k in more], [c_end[k] for k in more]
    return out


def partial(f: Integrand, a: float, x: float) -> float:
    """One 15-point Kronrod estimate of the integral of ``f`` over ``[a, x]`` (``x`` inside an
    accepted interval, where the rule is accurate)."""
    k, _e, _km, _em, _y = _rule(f, np.array([a]), np.array([x]))
    return float(k[0])


def bisector(f: Integrand, A: FloatArray, B: FloatArray, K: FloatArray, rtol: float = 1e-10) -> float:
    """Centre of area from accepted intervals: the middle of the points that halve the area -
    one point, or a whole gap where the set is 0 (``pwl.bisector``: an area within a tolerance
    of half counts as half - here ten times the quadrature's ``rtol``, what the areas are
    known to - and a whole interval within it answers its end)."""
    total = float(np.sum(K))
    half = 0.5 * total
    tol = max(COA_TOL, 10.0 * rtol) * total
    cum = np.cumsum(K)
    i = int(np.argmax((cum >= half - tol) & (K > 0.0)))
    before = float(cum[i - 1]) if i > 0 else 0.0
    left = float(B[i]) if half - before >= K[i] - tol else _solve(f, float(A[i]), float(B[i]), half - before)
    rcum = np.cumsum(K[::-1])[::-1]
    j = len(K) - 1 - int(np.argmax(((rcum >= half - tol) & (K > 0.0))[::-1]))
    after = float(rcum[j]) - float(K[j])
    if half - after >= K[j] - tol:
        right = float(A[j])
    else:
        right = _solve(f, float(A[j]), float(B[j]), float(K[j]) - (half - after))
    return 0.5 * (left + right)


def _solve(f: Integrand, a: float, b: float, target: float) -> float:
    """The x in [a, b] (an accepted interval) where the area from ``a`` reaches ``target``."""
    lo, hi = a, b
    for _ in range(100):
        mid = 0.5 * (lo + hi)
        if mid in (lo, hi):
            break
        if partial(f, a, mid) < target:
            lo = mid
        else:
            hi = mid
    return 0.5 * (lo + hi)


#: Nodes this close (relative) below the top of a smooth set count as at the top
#: (:func:`maxima`): about 45 ulps, the rounding of a few PROBOR/Einstein/Hamacher steps; a
#: smooth peak is that flat over 1e-7 of its width only (docs/engine.md allows 1.5e-6).
PLATEAU_TOL = 1e-14


def maxima(f: Integrand, A: FloatArray, B: FloatArray) -> tuple[float, float, float, float]:
    """``(height, LM, RM, MoM)`` of a smooth accumulated set.

    Plateaus (clipping makes the set constant) are runs of nodes at the largest value,
    their edges found by bisection; smooth peaks are local maxima of the nodes refined by
    golden-section search.  The maximising set is the plateaus when the largest
    value is reached on one (MoM: their centroid), else the peaks within 1e-12 of the
    height (MoM: their mean).

    A plateau is exactly constant in exact arithmetic only: PROBOR's ``a + b - a b`` (and
    Einstein, Hamacher) is not monotone in double, so the node at a clipping edge, where
    the term is a hair below the clip level, can come out an ulp above the plateau.  Nodes
    within :data:`PLATEAU_TOL` of the top therefore count as at the top (with an exact
    comparison that one node was the "maximum" and LM/RM/MoM jumped to the plateau's
    edge)."""
    half = 0.5 * (B - A)
    x = np.concatenate(
        [(0.5 * (A + B))[:, None] + half[:, None] * NODES[None, :], A[:, None], B[:, None]], axis=1
    )
    xs = np.unique(x.ravel())
    ys = f(xs)
    n = len(xs)
    top = float(np.max(ys))
    if not top > 0.0:
        return top, math.nan, math.nan, math.nan
    thr = top * (1.0 - PLATEAU_TOL)
    # smooth peaks between nodes
    peaks: list[tuple[float, float]] = []
    for index in np.flatnonzero(ys >= top * (1.0 - 1e-6)):
        i = int(index)
        if (i > 0 and ys[i - 1] > ys[i]) or (i + 1 < n and ys[i + 1] > ys[i]):
            continue
        level = min(ys[i], thr)  # equal neighbours, or both at the top
        if (i > 0 and ys[i - 1] >= level) or (i + 1 < n and ys[i + 1] >= level):
            continue  # a node of a plateau (below: its edges), not a peak between nodes
        peaks.append(
            _golden(f, float(xs[max(i - 1, 0)]), float(xs[min(i + 1, n - 1)]), float(xs[i]), float(ys[i]))
        )
    sup = max([top, *(v for _x, v in peaks)])
    # plateaus: runs of at least two nodes at the top value (to rounding)
    runs: list[tuple[float, float]] = []
    at_top = ys >= thr
    if top >= sup * (1.0 - 1e-12):
        j = 0
        while j < n:
            if not at_top[j]:
                j += 1
                continue
            k = j
            while k + 1 < n and at_top[k + 1]:
                k += 1
            if k > j:
                left = _edge(f, float(xs[j - 1]), float(xs[j]), thr) if j > 0 else float(xs[j])
                right = _edge(f, float(xs[k + 1]), float(xs[k]), thr) if k + 1 < n else float(xs[k])
                runs.append((left, right))
            j = k + 1
    points = sorted({px for px, pv in peaks if pv >= sup * (1.0 - 1e-12)})
    if runs:
        lm = min(runs[0][0], *points) if points else runs[0][0]
        rm = max(runs[-1][1], *points) if points else runs[-1][1]
        length = sum(r - l_ for l_, r in runs)
        mom = sum((r - l_) * 0.5 * (l_ + r) for l_, r in runs) / length if length > 0 else 0.5 * (lm + rm)
        return sup, lm, rm, mom
    if not points:  # pragma: no cover - the top node itself is always a candidate peak
        points = [float(xs[int(np.argmax(ys))])]
    return sup, points[0], points[-1], fsum(points) / len(points)


def _golden(f: Integrand, lo: float, hi: float, x0: float, y0: float) -> tuple[float, float]:
    g = (math.sqrt(5.0) - 1.0) / 2.0
    for _ in range(80):
        if hi - lo <= 1e-15 * max(1.0, abs(lo), abs(hi)):
            break
        c, d = hi - g * (hi - lo), lo + g * (hi - lo)
        fc, fd = f(np.array([c, d]))
        # A tie means both points sit on the flat top (in floating point): the peak lies
        # between them, so keep the middle; favouring one side would bias LM/RM by ~sqrt(eps).
        if fc == fd:
            lo, hi = c, d
        elif fc > fd:
            hi = d
        else:
            lo = c
    xm = 0.5 * (lo + hi)
    ym = float(f(np.array([xm]))[0])
    return (xm, ym) if ym > y0 else (x0, y0)


def _edge(f: Integrand, outside: float, inside: float, thr: float) -> float:
    """Bisection for the point between ``outside`` (below thr) and ``inside`` (above)."""
    for _ in range(100):
        mid = 0.5 * (outside + inside)
        if mid in (outside, inside):
            break
        if f(np.array([mid]))[0] >= thr:
            inside = mid
        else:
            outside = mid
    return inside
