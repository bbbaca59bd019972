"""A brute-force oracle for Mamdani outputs under every operator the engine reads: the rule
degrees and the accumulated set written from IEC 61131-7 Tables 3-5 (and the open-level norms
as docs/engine.md defines them) against the *model*, sharing no code with the engine (operator
names are only resolved through ``fuzzyctl.engine.semantics.operators``' alias tables), and the set
integrated by vectorised adaptive Simpson quadrature with a Richardson step, started from
2^14 cells of the range plus every term parameter, each cell halved until its two Simpson
estimates agree to ``tol`` (so narrow plateaus, jumps and kinks are found by refinement, not
assumed).  Slow and independent, which is the point.

Covered: the shapes of :mod:`tests.engine.reference` plus arc and concave; Is / NOT / AND /
OR conditions (no hedges); rule weights; every activation, accumulation and AND/OR norm of
``fuzzyctl.engine.semantics.operators``; CoG and CoA.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from typing import Any

import numpy as np

from fuzzyctl import model as m
from fuzzyctl.engine.semantics.operators import resolve_accu, resolve_act, resolve_pair
from tests.engine import reference

Arr = Any
Fn = Callable[[Arr, Arr], Arr]


def _ham_t(a: Arr, b: Arr) -> Arr:
    s = a + b - a * b
    with np.errstate(all="ignore"):
        return np.where(s == 0.0, 0.0, a * b / np.where(s == 0.0, 1.0, s))


def _ham_s(a: Arr, b: Arr) -> Arr:
    # 1 - T(1-a, 1-b): (a+b-2ab)/(1-ab) cancels catastrophically as a, b -> 1
    return 1.0 - _ham_t(1.0 - a, 1.0 - b)


TNORM: dict[str, Fn] = {
    "MIN": np.minimum,
    "PROD": lambda a, b: a * b,
    "BDIF": lambda a, b: np.maximum(0.0, a + b - 1.0),
    "DMIN": lambda a, b: np.where(np.maximum(a, b) == 1.0, np.minimum(a, b), 0.0),
    "NIPMIN": lambda a, b: np.where(a + b > 1.0, np.minimum(a, b), 0.0),
    "HAMACHER": _ham_t,
    "EINSTEIN": lambda a, b: a * b / (2.0 - (a + b - a * b)),
}
SNORM: dict[str, Fn] = {
    "MAX": np.maximum,
    "ASUM": lambda a, b: a + b - a * b,
    "PROBOR": lambda a, b: a + b - a * b,
    "BSUM": lambda a, b: np.minimum(1.0, a + b),
    "SUM": lambda a, b: a + b,
    "NSUM": lambda a, b: a + b,
    "DMAX": lambda a, b: np.where(np.minimum(a, b) == 0.0, np.maximum(a, b), 1.0),
    "NIPMAX": lambda a, b: np.where(a + b < 1.0, np.maximum(a, b), 1.0),
    "HAMACHER": _ham_s,
    "EINSTEIN": lambda a, b: (a + b) / (1.0 + a * b),
}


def membership(mf: m.MembershipFunction, x: Arr) -> Arr:
    x = np.asarray(x, dtype=float)
    if isinstance(mf, m.ShapeMF) and mf.kind in ("arc", "concave"):
        s, e = (float(v) for v in mf.params)  # type: ignore[arg-type]
        h = float(mf.height)  # type: ignore[arg-type]
        if mf.kind == "arc":  # a quarter circle of radius |e - s| centred at (e, 0), 1 beyond e
            inside = (np.minimum(s, e) <= x) & (x <= np.maximum(s, e))
            y = np.sqrt(np.maximum((e - s) ** 2 - (x - e) ** 2, 0.0)) / abs(e - s)
            beyond = (x > e) if s < e else (x < e)
            return h * np.where(inside, y, np.where(beyond, 1.0, 0.0))
        with np.errstate(all="ignore"):  # concave: (e - s) / (2e - s - x) rising to e, then 1
            if s <= e:
                return h * np.where(x < e, (e - s) / (2.0 * e - s - x), 1.0)
            return h * np.where(x > e, (s - e) / (s - 2.0 * e + x), 1.0)
    return reference._mf(mf, x)


def _cond(c: m.Condition, fb: m.FunctionBlock, inputs: dict[str, float], and_op: str, or_op: str) -> float:
    if isinstance(c, m.Is):
        if c.hedges:
            raise NotImplementedError("hedges")
        fz = fb.fuzzify_block(c.variable)
        assert fz is not None
        term = fz.term(c.term)
        assert term is not None
        d = float(membership(term.mf, np.array([inputs[c.variable]]))[0])
        return 1.0 - d if c.negated else d
    if isinstance(c, m.Not):
        return 1.0 - _cond(c.operand, fb, inputs, and_op, or_op)
    if isinstance(c, m.Degree):
        return inputs[c.variable]
    vals = [_cond(o, fb, inputs, and_op, or_op) for o in c.operands]
    f = TNORM[and_op] if isinstance(c, m.And) else SNORM[or_op]
    v = vals[0]
    for w in vals[1:]:
        v = float(f(np.float64(v), np.float64(w)))
    return v


def accumulated(fb: m.FunctionBlock, inputs: dict[str, float], out: str) -> tuple[Callable[[Arr], Arr], int]:
    """The accumulated set of output ``out`` as a function of u, and the number of sets."""
    db = fb.defuzzify_block(out)
    assert db is not None
    sets: list[tuple[m.MembershipFunction, float, float, str]] = []
    accu = db.accu
    for rb in fb.rule_blocks:
        and_op, or_op = resolve_pair(rb.and_op, rb.or_op)
        act = resolve_act(rb.act)
        accu = accu or rb.accu
        for r in rb.rules:
            a = 1.0 if r.condition is None else _cond(r.condition, fb, inputs, and_op, or_op)
            for c in r.conclusions:
                if c.variable == out:
                    term = db.term(c.term or "")
                    assert term is not None
                    w = 1.0 if c.weight is None else float(c.weight)  # type: ignore[arg-type]
                    sets.append((term.mf, a, w, act))
    name = resolve_accu(accu)

    def f(u: Arr) -> Arr:
        acc = np.zeros_like(u)
        for mf, a, w, act in sets:
            acc = SNORM[name](acc, w * TNORM[act](np.full_like(u, a), membership(mf, u)))
        return acc

    return f, len(sets)


def integrate(
    f: Callable[[Arr], Arr], lo: float, hi: float, breaks: list[float], tol: float = 1e-14
) -> list[tuple[float, float, float, float]]:
    """Accepted cells ``(a, b, area, moment)`` sorted by ``a``: adaptive Simpson with a
    Richardson step, absolute tolerance ``tol`` per unit of relative width."""
    edges = np.unique(
        np.concatenate([np.linspace(lo, hi, (1 << 14) + 1), [b for b in breaks if lo < b < hi]])
    )
    a, b = edges[:-1], edges[1:]
    span = hi - lo
    scale = max(abs(lo), abs(hi), span)
    done: list[tuple[Arr, Arr, Arr, Arr]] = []
    for _level in range(80):
        mid = 0.5 * (a + b)
        xs = np.stack([a, 0.5 * (a + mid), mid, 0.5 * (mid + b), b])
        ys = f(xs.ravel()).reshape(xs.shape)
        d = b - a
        s1 = d / 6.0 * (ys[0] + 4.0 * ys[2] + ys[4])
        s2 = d / 12.0 * (ys[0] + 4.0 * ys[1] + 2.0 * ys[2] + 4.0 * ys[3] + ys[4])
        xy = xs * ys
        m1 = d / 6.0 * (xy[0] + 4.0 * xy[2] + xy[4])
        m2 = d / 12.0 * (xy[0] + 4.0 * xy[1] + 2.0 * xy[2] + 4.0 * xy[3] + xy[4])
        lim = 15.0 * tol * d / span
        ok = ((np.abs(s2 - s1) <= lim) & (np.abs(m2 - m1) <= lim * scale)) | (d <= 1e-15 * scale)
        if _level == 79 or (~ok).sum() > 100_000:  # rounding noise (Hamacher near 1): give up
            ok[:] = True
        done.append((a[ok], b[ok], (s2 + (s2 - s1) / 15.0)[ok], (m2 + (m2 - m1) / 15.0)[ok]))
        if ok.all():
            break
        a, b, mid = a[~ok], b[~ok], mid[~ok]
        a, b = np.concatenate([a, mid]), np.concatenate([mid, b])
    A = np.concatenate([x[0] for x in done])
    order = np.argsort(A)
    cols = [np.concatenate([x[i] for x in done])[order] for i in range(4)]
    return list(zip(*(c.tolist() for c in cols), strict=True))


def _breaks(db: m.DefuzzifyBlock) -> list[float]:
    out: list[float] = []
    for t in db.terms:
        if isinstance(t.mf, m.ShapeMF):
            out += [float(p) for p in t.mf.params]  # type: ignore[arg-type]
        elif isinstance(t.mf, m.PointsMF):
            out += [float(p.x) for p in t.mf.points]  # type: ignore[arg-type]
    return out


def evaluate(
    fb: m.FunctionBlock, inputs: dict[str, float], out: str, universe: tuple[float, float] | None = None
) -> float:
    """CoG or CoA of output ``out`` (NaN when the set has no area) over its RANGE, else over
    ``universe``, else over the span of its terms' parameters."""
    db = fb.defuzzify_block(out)
    assert db is not None
    var = next(v for v in fb.variables if v.name == out)
    rng = db.range or var.range
    if rng is not None:
        lo, hi = float(rng.low), float(rng.high)
    elif universe is not None:
        lo, hi = universe
    else:
        lo, hi = min(_breaks(db)), max(_breaks(db))
    f, _n = accumulated(fb, inputs, out)
    cells = integrate(f, lo, hi, _breaks(db))
    area = math.fsum(c[2] for c in cells)
    # a set that is positive only on points (DMIN where a term peaks at exactly 1, a vertical
    # edge) has no area; cells shrunk around such a point leave crumbs of ~1e-15
    if not area > 1e-12 * (hi - lo):
        return math.nan
    method = (db.method or "COG").upper()
    if method == "COG":
        return math.fsum(c[3] for c in cells) / area
    if method != "COA":
        raise NotImplementedError(method)
    return 0.5 * (_bisector(f, cells, area) + _bisector(f, cells, area, reverse=True))


def _bisector(
    f: Callable[[Arr], Arr],
    cells: list[tuple[float, float, float, float]],
    area: float,
    reverse: bool = False,
) -> float:
    """The first (or, reversed, the last) u where the area to its left (right) is half."""
    half = 0.5 * area
    cum = 0.0
    seq = reversed(cells) if reverse else iter(cells)
    for a, b, s, _m in seq:
        if s > 0.0 and cum + s >= half:
            lo, hi = a, b
            for _ in range(200):
                x = 0.5 * (lo + hi)
                if x in (lo, hi):
                    break
                u = np.linspace(a, x, 33) if not reverse else np.linspace(x, b, 33)
                part = float(
                    np.sum((u[1:] - u[:-1]) / 6.0 * (f(u[:-1]) + 4.0 * f(0.5 * (u[1:] + u[:-1])) + f(u[1:])))
                )
                if (part < half - cum) != reverse:
                    lo = x
                else:
                    hi = x
            return 0.5 * (lo + hi)
        cum += s
    return cells[0][0] if reverse else cells[-1][1]
