"""Closed-form derivatives of a Mamdani output defuzzified by centre of gravity (COG) or
of area (COA).

The engine integrates the accumulated set exactly (:mod:`fuzzyctl.engine.reference.pwl`,
:mod:`fuzzyctl.ir.kernels.columns`): on the output grid (the range cut at every term point) each
term is linear; MIN activation adds a kink where a term crosses the rule's degree, MAX
accumulation adds the crossings of activated sets, BSUM the crossings of their sum with 1.
Between two consecutive cuts the accumulated set ``f`` is linear, and

    M0 = integral of f,   M1 = integral of x f,   y = M1 / M0,
    dy = (dM1 - y dM0) / M0.

``f`` is continuous in ``x`` (no vertical edge inside the range) and, at a fixed ``x``,
piecewise linear in every parameter, so the cuts may move with the parameters without
adding terms (Leibniz's rule: the integrand has no jump across a moving cut):

    dM0/dtheta = integral of df/dtheta,   dM1/dtheta = integral of x df/dtheta.

On one piece exactly one expression gives ``f`` (for MAX the maximal activated set, for SUM
all of them, for BSUM all of them below saturation, none above), and its derivative at a
fixed ``x`` is constant or linear in ``x``:

    MIN  f = w min(a, mu(x)):  df/da = w where clipped (a <= mu), df/dw = min(a, mu),
                               df/dtheta = w dmu/dtheta where not clipped
    PROD f = w a mu(x):        df/da = w mu, df/dw = a mu, df/dtheta = w a dmu/dtheta
    on a term segment mu = y_k + (y_k+1 - y_k)(x - x_k)/(x_k+1 - x_k):
        dmu/dx_k = (y_k+1 - y_k)(x - x_k+1)/(x_k+1 - x_k)^2,
        dmu/dx_k+1 = -(y_k+1 - y_k)(x - x_k)/(x_k+1 - x_k)^2

so every integral is a sum over pieces of ``I0 = int dx``, ``I1 = int u dx``, ``I2 = int
u^2 dx`` (``u`` measured from the grid interval's start) times constants.  Activated sets
of one term that MAX accumulation merges (``max_k w min(a_k, mu) = w min(max_k a_k, mu)``)
pass the derivative to the rule of largest degree.

COA: ``x*`` with ``int_low^x* f = M0 / 2``, so ``f(x*) dx* = dM0 / 2 - int_low^x* df``,
the same integrals up to ``x*``.

A WITH weight alone moves ``f`` only where no other set ties with its set (two rules of
equal degree clipping two terms at one level, merged sets below the second largest
degree): there the derivative from below is given, the direction a weight at its bound 1
can move.

Where it does not hold (:func:`unsupported`): other methods (LM, RM, MOM), PROBOR and
NSUM, other shapes, vertical edges inside the range (the moving jump would add a term),
and at a tie - a degree exactly equal to a plateau of a term (the derivative from below,
the direction a degree of 1 can move, is given), two sets exactly equal on a whole piece.
"""

from __future__ import annotations

import itertools
import math
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
import numpy.typing as npt

from fuzzyctl.engine.plan import OutputPlan, TermPlan
from fuzzyctl.ir.kernels.columns import coa_columns  # the engine's bisector: the same x* to the last bit
from fuzzyctl.kinds import norms
from fuzzyctl.kinds import shapes as registry
from fuzzyctl.kinds.methods import METHODS

Arr = npt.NDArray[np.float64]
Bool = npt.NDArray[np.bool_]
#: accumulations the closed form covers
ACCUS = ("MAX", "SUM", "BSUM")


def _term_unsupported(t: TermPlan, low: float, high: float) -> str | None:
    if t.kind != "points" and registry.vertices(t.kind) is None:
        return f"shape {t.kind}"
    if not t.constant or t.pwl is None:
        return "parameters given by variables"
    xs = [x for x, _ in t.pwl]
    if not all(math.isfinite(x) for x in xs) or len(t.pwl) != len(_param_index(t)):
        return "infinite vertices"
    if t.kind == "points" and [float(p) for p in t.params[0::2]] != xs:  # type: ignore[arg-type]
        return "points not in ascending order"
    for a, b in itertools.pairwise(xs):
        if a == b and low < a < high:
            return f"a vertical edge at {a:g} inside the range"
    return None


def unsupported(op: OutputPlan) -> str | None:
    """Why the closed form does not apply to the Mamdani output ``op`` (``None``: it does)."""
    if not METHODS[op.method].integrating:
        return f"{op.name}: {op.method} of a Mamdani output (closed form for COG and COA only)"
    accu = op.accu or "MAX"
    if accu not in ACCUS:
        return f"{op.name}: COG with ACCU {accu} (closed form for MAX, SUM, BSUM)"
    for c in op.contributions:
        if not norms.keeps_lines(c.act) or c.term is None:
            return f"{op.name}: activation {c.act}"
        if not isinstance(c.weight, float | int):
            return f"{op.name}: WITH given by a variable"
    low, high = op.low if op.low is not None else -math.inf, op.high if op.high is not None else math.inf
    for t in op.terms:
        why = _term_unsupported(t, low, high)
        if why:
            return f"{op.name}: term {t.name}: {why}"
    if op.grid is None or not op.exact:
        return f"{op.name}: terms that are not piecewise linear with constant points"
    return None


def _param_index(t: TermPlan) -> tuple[int, ...]:
    if t.kind == "points":
        return tuple(range(0, len(t.params), 2))
    vertices = registry.vertices(t.kind)
    assert vertices is not None
    return tuple(range(len(vertices)))


@dataclass
class CogPartials:
    """``value`` (NaN where the set is empty) and its derivatives with respect to the degree
    ``a`` and the weight ``w`` of each contribution of the output (in
    ``OutputPlan.contributions`` order) and to the output terms' abscissae
    (``(term, parameter index)``)."""

    value: Arr
    d_degree: list[Arr]
    d_weight: list[Arr]
    d_term: dict[tuple[int, int], Arr]


@dataclass
class _Group:
    """One activated set: ``w min(a, mu_term)`` or ``w a mu_term`` (``is_min`` False);
    ``members`` are the contributions merged into it (MAX), ``pick`` the one of largest
    degree per sample, ``scaled`` whether ``a`` is the contribution's degree times its weight."""

    term: int
    is_min: bool
    w: float
    scaled: bool
    members: list[int]
    a: Arr
    pick: npt.NDArray[np.intp]
    #: the second largest degree of merged MIN sets: below it the others tie with the
    #: picked one, and lowering the picked one's WITH changes nothing there
    a2: Arr | None = None


def _groups(
    op: OutputPlan, degrees: Sequence[Arr], weights: Sequence[float], before: bool, n: int
) -> list[_Group]:
    accu = op.accu or "MAX"
    keyed: dict[object, list[int]] = {}
    for ci, c in enumerate(op.contributions):
        is_min = norms.is_min(c.act)
        scaled = before or not is_min  # w min(a, mu) keeps w outside; a w mu folds it in
        w = 1.0 if scaled else weights[ci]
        key = (c.term, is_min, w, scaled) if norms.is_max(accu) else ci
        keyed.setdefault(key, []).append(ci)
    out = []
    for members in keyed.values():
        c0 = op.contributions[members[0]]
        is_min = norms.is_min(c0.act)
        scaled = before or not is_min
        degs = [
            np.broadcast_to(degrees[op.contributions[ci].rule] * (weights[ci] if scaled else 1.0), (n,))
            for ci in members
        ]
        stack = np.stack(degs)
        assert c0.term is not None
        a2 = np.sort(stack, axis=0)[-2] if len(members) > 1 and not scaled else None
        w = 1.0 if scaled else weights[members[0]]
        out.append(
            _Group(c0.term, is_min, w, scaled, members, stack.max(axis=0), np.argmax(stack, axis=0), a2)
        )
    return out


def _segment_slopes(t: TermPlan, x0: float, x1: float) -> list[tuple[int, float, float]]:
    """``(parameter index, alpha, beta)`` with ``dmu/dx_p = alpha + beta u`` on ``[x0, x1]``
    (``u = x - x0``), for the abscissae the term's segment there depends on."""
    assert t.pwl is not None
    pts, idx = t.pwl, _param_index(t)
    xm = 0.5 * (x0 + x1)
    for k in range(len(pts) - 1):
        (xa, ya), (xb, yb) = pts[k], pts[k + 1]
        if xa < xm < xb:
            dy = yb - ya
            if dy == 0.0:
                return []
            d2 = (xb - xa) ** 2
            return [(idx[k], dy * (x0 - xb) / d2, dy / d2), (idx[k + 1], -dy * (x0 - xa) / d2, -dy / d2)]
    return []  # the flat continuation before the first or after the last point


Line = tuple[float, float, Arr, float, bool]  # (L, R, a, w, is_min): the term goes from L to R


def _values(lines: Sequence[Line], kinks: Sequence[Arr | None], T: Arr) -> list[Arr]:
    vs = []
    for (L, R, a, w, mn), tk in zip(lines, kinks, strict=True):
        a2 = a[:, None]
        y = L + (R - L) * T
        if mn:
            v = w * np.minimum(a2, y)
            if tk is not None:  # exactly w a at a kink, as the engine
                v = np.where(tk[:, None] == T, w * a2, v)
        else:
            v = w * a2 * y
        vs.append(np.broadcast_to(v, T.shape))
    return vs


def _combine(vs: list[Arr], accu: str) -> Arr:
    if len(vs) == 1:
        return np.asarray(vs[0])
    if norms.is_max(accu):
        return np.asarray(np.maximum.reduce(vs))
    s = np.asarray(np.add.reduce(vs))
    return np.minimum(1.0, s) if norms.bounded(accu) else s


def _cuts(
    lines: Sequence[Line], accu: str, n: int, levels: Sequence[tuple[float, float, Arr]] = ()
) -> tuple[Arr, Arr]:
    """The cuts of one grid interval (``t`` in [0, 1], sorted per row) and the accumulated
    degree there - the engine's candidates (:func:`fuzzyctl.ir.kernels.columns._interval`) and
    where a term ``(L, R, level)`` of ``levels`` crosses a level."""
    zeros, ones = np.zeros(n), np.ones(n)
    cands = [zeros, ones]
    for L, R, lv in levels:
        if L != R:
            cands.append(np.where((L - lv) * (R - lv) < 0.0, np.clip((lv - L) / (R - L), 0.0, 1.0), 0.0))
    kinks: list[Arr | None] = []
    for L, R, a, _w, mn in lines:
        if mn and L != R:
            tk = np.clip((a - L) / (R - L), 0.0, 1.0)
            inside = (L - a) * (R - a) < 0.0
            kinks.append(np.where(inside, tk, np.nan))
            cands.append(np.where(inside, tk, 0.0))
        else:
            kinks.append(None)
    if norms.is_max(accu) and len(lines) > 1:
        # the linear parts (value at t = 0, slope) of each activated set
        parts: list[list[tuple[Arr | float, Arr | float]]] = [
            [(w * L, w * (R - L)), (w * a, 0.0)] if mn else [(w * a * L, w * a * (R - L))]
            for L, R, a, w, mn in lines
        ]
        with np.errstate(all="ignore"):
            for i in range(len(lines)):
                for k in range(i + 1, len(lines)):
                    for ai, bi in parts[i]:
                        for ak, bk in parts[k]:
                            t = (np.asarray(ak - ai, dtype=np.float64) / (bi - bk)) * ones
                            cands.append(np.where((t > 0.0) & (t < 1.0), t, 0.0))
    T = np.sort(np.stack(cands, axis=1), axis=1)
    V = _combine(_values(lines, kinks, T), accu)
    if norms.bounded(accu) and len(lines) > 1:
        S = np.add.reduce(_values(lines, kinks, T))
        s0, s1 = S[:, :-1], S[:, 1:]
        with np.errstate(all="ignore"):
            s = (1.0 - s0) / (s1 - s0)
            cross = ((s0 - 1.0) * (s1 - 1.0) < 0.0) & (s > 0.0) & (s < 1.0)
            extra = np.where(cross, T[:, :-1] + s * (T[:, 1:] - T[:, :-1]), 0.0)
        T = np.sort(np.concatenate([T, extra], axis=1), axis=1)
        V = _combine(_values(lines, kinks, T), accu)
    return T, V


def _selection(lines: Sequence[Line], accu: str, tm: Arr) -> tuple[list[Bool], list[Bool | None], Bool]:
    """On each piece (midpoints ``tm``): which sets give the accumulated degree, which MIN
    sets are clipped (``a <= mu``: from below at a tie, where degrees can move), and where
    several sets reach the maximum (MAX: e.g. two clipped plateaus at one level)."""
    no_tie: Bool = np.zeros_like(tm, dtype=bool)
    every: Bool = np.ones_like(tm, dtype=bool)
    vals: list[Arr] = []
    clipped: list[Bool | None] = []
    for L, R, a, w, mn in lines:
        mu = L + (R - L) * tm
        if mn:
            q = a[:, None] <= mu
            vals.append(w * np.where(q, a[:, None], mu))
            clipped.append(q)
        else:
            vals.append(w * a[:, None] * mu)
            clipped.append(None)
    if len(lines) == 1:
        return [every], clipped, no_tie
    if norms.is_max(accu):
        stack = np.stack(vals)
        pick = np.argmax(stack, axis=0)
        tie: Bool = np.asarray((stack == stack.max(axis=0)).sum(axis=0) > 1, dtype=bool)
        return [pick == i for i in range(len(lines))], clipped, tie
    if norms.bounded(accu):
        below: Bool = np.asarray(np.add.reduce(vals) <= 1.0, dtype=bool)
        return [below] * len(lines), clipped, no_tie
    return [every] * len(lines), clipped, no_tie


@dataclass
class _Sums:
    m0: Arr
    m1: Arr
    # (groups, n): dM0/da, dM1/da; dM0/dw, dM1/dw from below (for a scaled group, whose a is
    # degree * weight: d/da from below, which the weight's derivative is made of)
    a0: Arr
    a1: Arr
    w0: Arr
    w1: Arr
    p0: dict[tuple[int, int], Arr]
    p1: dict[tuple[int, int], Arr]


def _interval(
    j: int,
    op: OutputPlan,
    groups: list[_Group],
    idx: list[int],
    accu: str,
    sums: _Sums,
    n: int,
    upto: Arr | None = None,
) -> tuple[Arr, Arr]:
    """Add the interval's moments and their derivatives to ``sums``; with ``upto``, only the
    integrals from the interval's start to ``upto`` (the moments of ``sums`` are then
    meaningless).  Returns the cuts (x) and the accumulated degree there."""
    grid = op.grid
    assert grid is not None
    x0, x1 = grid.xs[j], grid.xs[j + 1]
    dx = x1 - x0
    lines = [
        (grid.left[gr.term][j], grid.right[gr.term][j], gr.a, gr.w, gr.is_min)
        for gr in (groups[g] for g in idx)
    ]
    levels = [
        (L, R, groups[g].a2) for (L, R, *_r), g in zip(lines, idx, strict=True) if groups[g].a2 is not None
    ]
    T, V = _cuts(lines, accu, n, levels)  # type: ignore[arg-type]
    U = T * dx
    X = x0 + U
    if upto is not None:
        U = np.minimum(U, np.maximum(upto - x0, 0.0)[:, None])
    ua, ub = U[:, :-1], U[:, 1:]
    i0 = ub - ua
    i1 = i0 * (ua + ub) / 2.0
    i2 = i0 * (ua * ua + ua * ub + ub * ub) / 3.0
    va, vb = V[:, :-1], V[:, 1:]
    area = (0.5 * i0 * (va + vb)).sum(axis=1)
    mom = (i0 * (ua * (2.0 * va + vb) + ub * (va + 2.0 * vb))).sum(axis=1) / 6.0
    sums.m0 += area
    sums.m1 += x0 * area + mom
    tm = 0.5 * (T[:, :-1] + T[:, 1:])
    sel, clipped, tie = _selection(lines, accu, tm)
    for i, g in enumerate(idx):
        L, R, a, w, _mn = lines[i]
        kappa = (R - L) / dx
        q = clipped[i]
        free = sel[i] & ~q if q is not None else sel[i]
        j0, j1, j2 = ((ik * free).sum(axis=1) for ik in (i0, i1, i2))
        p0, p1 = L * j0 + kappa * j1, L * j1 + kappa * j2  # integrals of mu, u mu where free
        # A weight alone moves f only where no other set ties with this one (WITH is often
        # at its bound 1: the derivative from below); a2: merged sets tie where mu <= a2
        alone = free & ~tie
        if groups[g].a2 is not None:
            alone &= L + (R - L) * tm > groups[g].a2[:, None]  # type: ignore[index]
        h0, h1, h2 = ((ik * alone).sum(axis=1) for ik in (i0, i1, i2))
        if q is not None:
            held = sel[i] & q
            c0, c1 = (i0 * held).sum(axis=1), (i1 * held).sum(axis=1)
            k0, k1 = (i0 * (held & ~tie)).sum(axis=1), (i1 * (held & ~tie)).sum(axis=1)
            d0a, d1a, e = w * c0, w * c1, w * np.ones(n)
            if groups[g].scaled:  # d/d(degree * weight), from below
                d0w, d1w = w * k0, w * k1
            else:  # d/dw of w min(a, mu), from below
                d0w, d1w = a * k0 + L * h0 + kappa * h1, a * k1 + L * h1 + kappa * h2
        else:  # PROD: always scaled
            d0a, d1a, e = w * p0, w * p1, w * a
            d0w, d1w = w * (L * h0 + kappa * h1), w * (L * h1 + kappa * h2)
        sums.a0[g] += d0a
        sums.a1[g] += x0 * d0a + d1a
        sums.w0[g] += d0w
        sums.w1[g] += x0 * d0w + d1w
        t = groups[g].term
        for p, alpha, beta in _segment_slopes(op.terms[t], x0, x1):
            e0, e1 = e * (alpha * j0 + beta * j1), e * (alpha * j1 + beta * j2)
            key = (t, p)
            if key not in sums.p0:
                sums.p0[key], sums.p1[key] = np.zeros(n), np.zeros(n)
            sums.p0[key] += e0
            sums.p1[key] += x0 * e0 + e1
    return X, V


def _accumulate(
    op: OutputPlan, groups: list[_Group], accu: str, n: int, upto: Arr | None = None
) -> tuple[_Sums, list[tuple[Arr, Arr]]]:
    grid = op.grid
    assert grid is not None
    z = np.zeros((len(groups), n))
    sums = _Sums(np.zeros(n), np.zeros(n), z.copy(), z.copy(), z.copy(), z.copy(), {}, {})
    pieces = []
    for j in range(len(grid.xs) - 1):
        idx = [g for g, grp in enumerate(groups) if grp.term in grid.active[j]]
        if idx:
            pieces.append(_interval(j, op, groups, idx, accu, sums, n, upto))
    return sums, pieces


def _bisector(pieces: list[tuple[Arr, Arr]]) -> tuple[Arr, Arr]:
    """The engine's centre of area of the pieces, and the accumulated degree there."""
    x0 = np.concatenate([X[:, :-1] for X, _V in pieces], axis=1)
    x1 = np.concatenate([X[:, 1:] for X, _V in pieces], axis=1)
    v0 = np.concatenate([V[:, :-1] for _X, V in pieces], axis=1)
    v1 = np.concatenate([V[:, 1:] for _X, V in pieces], axis=1)
    xc, _fired = coa_columns(x0, x1, v0, v1)
    inside = (x0 <= xc[:, None]) & (xc[:, None] <= x1) & (x1 > x0)
    with np.errstate(all="ignore"):
        at = v0 + (v1 - v0) * (xc[:, None] - x0) / (x1 - x0)
    return xc, np.where(inside, at, 0.0).max(axis=1, initial=0.0)


def cog_partials(
    op: OutputPlan, degrees: Sequence[Arr], weights: Sequence[float], before: bool, n: int
) -> CogPartials:
    """COG (or COA) of the Mamdani output ``op`` (for which :func:`unsupported` is None)
    and its partial derivatives, given each rule's degree (``degrees``, rule weight
    included) and each contribution's WITH weight; ``before``: the weight scales the degree
    before activation (``Options.weight_before_activation``).

    COA: ``x*`` with ``int_low^x* f = M0 / 2``, so ``f(x*) dx* = dM0 / 2 - int_low^x* df``
    (no derivative where ``f(x*) = 0``: a gap exactly halving the area)."""
    accu = op.accu or "MAX"
    groups = _groups(op, degrees, weights, before, n)
    sums, pieces = _accumulate(op, groups, accu, n)
    fired = sums.m0 > 0.0
    safe = np.where(fired, sums.m0, 1.0)
    if METHODS[op.method].bisects and pieces:
        y, height = _bisector(pieces)
        part, _p = _accumulate(op, groups, accu, n, upto=y)
        ok = fired & (height > 0.0)
        h = np.where(ok, height, 1.0)

        def dy(full: Arr, upto: Arr) -> Arr:
            return np.asarray(np.where(ok, (0.5 * full - upto) / h, 0.0), dtype=np.float64)

        d_a, d_w = (
            [dy(sums.a0[g], part.a0[g]) for g in range(len(groups))],
            [dy(sums.w0[g], part.w0[g]) for g in range(len(groups))],
        )
        d_term = {key: dy(sums.p0[key], part.p0[key]) for key in sums.p0}
    else:
        y = sums.m1 / safe

        def dq(d0: Arr, d1: Arr) -> Arr:
            return np.asarray(np.where(fired, (d1 - y * d0) / safe, 0.0), dtype=np.float64)

        d_a = [dq(sums.a0[g], sums.a1[g]) for g in range(len(groups))]
        d_w = [dq(sums.w0[g], sums.w1[g]) for g in range(len(groups))]
        d_term = {key: dq(sums.p0[key], sums.p1[key]) for key in sums.p0}
    d_deg, d_wt = _to_contributions(op, groups, degrees, weights, d_a, d_w, n)
    return CogPartials(np.where(fired, y, np.nan), d_deg, d_wt, d_term)


def _to_contributions(
    op: OutputPlan,
    groups: list[_Group],
    degrees: Sequence[Arr],
    weights: Sequence[float],
    d_a: list[Arr],
    d_w: list[Arr],
    n: int,
) -> tuple[list[Arr], list[Arr]]:
    """Derivatives of the activated sets -> of each contribution's degree and weight."""
    d_deg = [np.zeros(n) for _ in op.contributions]
    d_wt = [np.zeros(n) for _ in op.contributions]
    for g, grp in enumerate(groups):
        da, dw = d_a[g], d_w[g]
        for k, ci in enumerate(grp.members):
            mask = grp.pick == k if len(grp.members) > 1 else np.ones(n, dtype=bool)
            if grp.scaled:  # a = degree * weight
                d_deg[ci] = np.where(mask, da * weights[ci], 0.0)
                d_wt[ci] = np.where(mask, dw * degrees[op.contributions[ci].rule], 0.0)
            else:
                d_deg[ci] = np.where(mask, da, 0.0)
                d_wt[ci] = np.where(mask, dw, 0.0)
    return d_deg, d_wt
