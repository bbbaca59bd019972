"""Centre of gravity of a smooth output (Gaussian, bell, sigmoid, ... terms, or operators that
bend straight lines) in the generated block, exact to a tolerance fixed at generation time.

An accumulated set of smooth terms has no closed-form integral.  The generated code does what
the native evaluator does (:data:`fuzzyctl.codegen.c_kernels.SMOOTH_DRIVER`), written in the
IR so that Structured Text (``EXP`` is an IEC 61131-3 standard function) and C share it:

1. the output range is cut at constant breakpoints: every term's characteristic points
   (peaks, joins, support ends: :func:`fuzzyctl.engine.shapes.characteristic_points`), its
   corners when piecewise linear, and the panels the calibration below adds;
2. each interval is sampled at :data:`SAMPLES` points; where the branch the set takes changes
   between two samples (which activated set is the largest, whether it is clipped, whether a
   bounded sum reached 1) the kink is located by :data:`BISECTIONS` halvings (several kinks
   between two samples: up to :data:`ROUNDS`);
3. every piece between breakpoints and kinks is smooth and is integrated with the
   :data:`NODES`-point Gauss-Legendre rule (area and first moment).

Calibration (generation time): each interval is halved until, for every term of the output,
the ``NODES``-point rule and the ``2*NODES``-point rule agree on the term's area and first
moment over the interval to :data:`PANEL_TOL` times the interval's width (times the range
for the moment).  A piece is part of an interval and the integrand on a piece is a term
scaled by constants (MIN/PROD activation, MAX/SUM/BSUM accumulation), so the area and the
moment of the set are then within ``n * PANEL_TOL * (high - low)`` (``n`` activated sets) and
the CoG within :func:`cog_bound` of the exact value - a bound written in the header of the
generated code and checked against the engine by the tests.  In REAL (32-bit) arithmetic
rounding (about 1e-6 of the range) dominates it.
"""

from __future__ import annotations

import itertools
import math
from dataclasses import dataclass

import numpy as np

from fuzzyctl.engine import irterms as T
from fuzzyctl.engine import shapes
from fuzzyctl.engine.grid import left_limit, right_limit
from fuzzyctl.engine.ir import Ex, Num, Var, not_
from fuzzyctl.engine.irgen import Gen
from fuzzyctl.engine.plan import OutputPlan, Slot, TermPlan
from fuzzyctl.engine.pwl import gauss_legendre

SAMPLES = 8  # points per interval where the branch taken is compared
BISECTIONS = 30  # halvings locating a kink (to 1e-9 of the sample spacing)
ROUNDS = 4  # kinks located between two samples at most
NODES = 8  # Gauss-Legendre nodes per piece
PANEL_TOL = 1e-10  # calibration tolerance per unit of width
MAX_DEPTH = 8  # halvings of one interval at most


@dataclass(frozen=True)
class SmoothSet:
    """One activated set: ``w * act(a, term)``."""

    term: int
    a: Ex
    w: Ex
    act: str


@dataclass(frozen=True)
class Calibration:
    cuts: tuple[float, ...]
    worst: float  # largest disagreement found per unit of width (<= PANEL_TOL when met)


def constant_term(t: TermPlan) -> bool:
    return not isinstance(t.height, Slot) and not any(isinstance(p, Slot) for p in t.params)


def _degree_np(t: TermPlan, x: np.ndarray) -> np.ndarray:
    if t.pwl is not None:
        return shapes.pwl_value_np(t.pwl, x)
    return shapes.membership_np(t.kind, [float(p) for p in t.params], float(t.height), x)  # type: ignore[arg-type]


def _breakpoints(op: OutputPlan) -> list[float]:
    assert op.low is not None and op.high is not None
    lo, hi = op.low, op.high
    pts = {lo, hi}
    for t in op.terms:
        if t.pwl is not None:
            cand = [x for x, _y in t.pwl]
        else:
            cand = list(shapes.characteristic_points(t.kind, [float(p) for p in t.params]))  # type: ignore[arg-type]
        pts.update(c for c in cand if lo < c < hi and math.isfinite(c))
    return sorted(pts)


def calibrate(op: OutputPlan) -> Calibration:
    """The breakpoints of ``op`` refined until every term is integrated to :data:`PANEL_TOL`."""
    assert op.low is not None and op.high is not None
    width, low = op.high - op.low, op.low
    x8, w8 = (np.array(v) for v in gauss_legendre(NODES))
    x16, w16 = (np.array(v) for v in gauss_legendre(2 * NODES))
    worst = 0.0

    def err(a: float, b: float) -> float:
        d = b - a
        out = 0.0
        for t in op.terms:
            xa, xb = a + x8 * d, a + x16 * d
            fa, fb = _degree_np(t, xa), _degree_np(t, xb)
            e_area = abs(float(fa @ w8 - fb @ w16)) * d
            e_mom = abs(float((fa * (xa - low)) @ w8 - (fb * (xb - low)) @ w16)) * d / width
            out = max(out, e_area, e_mom)
        return out / d

    cuts: list[float] = []
    bps = _breakpoints(op)
    for a, b in itertools.pairwise(bps):
        stack = [(a, b, 0)]
        pieces: list[float] = []
        while stack:
            u, v, depth = stack.pop()
            e = err(u, v)
            if e > PANEL_TOL and depth < MAX_DEPTH:
                m = 0.5 * (u + v)
                stack += [(m, v, depth + 1), (u, m, depth + 1)]
                continue
            worst = max(worst, e)
            pieces.append(u)
        cuts += pieces
    cuts.append(bps[-1])
    return Calibration(tuple(cuts), worst)


#: Activations and accumulations under which every piece of the set between located kinks is
#: a term times constants (or a constant): the premise of the calibrated bound.  Other norms
#: bend the terms by the rule degree (Hamacher, Einstein), jump inside an interval where no
#: branch code sees it (NIPMIN, NIPMAX, DMAX) or multiply sets (PROBOR).
BOUND_ACTS = frozenset({"MIN", "PROD"})
BOUND_ACCUS = frozenset({"MAX", "SUM", "NSUM", "BSUM"})


def cog_bound(op: OutputPlan, n_sets: int, cal: Calibration, acts: frozenset[str] = BOUND_ACTS) -> str:
    """The documented bound, as text for the header; where its premise does not hold
    (:data:`BOUND_ACTS`, :data:`BOUND_ACCUS`), a sentence saying there is none."""
    accu = op.accu or "MAX"
    outside = sorted(acts - BOUND_ACTS) + ([accu] if accu not in BOUND_ACCUS else [])
    if outside:
        return (
            f"no a-priori error bound: with {', '.join(outside)} the set is not terms times "
            f"constants between located kinks, so the error depends on the rule degrees (the "
            f"native backend of compile() integrates adaptively to 1e-10 relative)"
        )
    tol = max(cal.worst, PANEL_TOL)
    return (
        f"area and moment within {n_sets} x {tol:.1e} x (high - low) of the exact integrals, so "
        f"|CoG error| <= {2 * n_sets * tol:.1e} x (high - low)^2 / area"
    )


# --------------------------------------------------------------------------- the set at x


def _const_pwl(g: Gen, pts: tuple[tuple[float, float], ...], x: Ex) -> Var:
    """``shapes.pwl_value`` of constant breakpoints as an IF chain."""
    out = g.temp(hint="MU")
    xs = sorted({q[0] for q in pts})
    b = g.b
    branches: list[tuple[Ex, float | Ex]] = [(x.lt(xs[0]), pts[0][1])]
    for k, u in enumerate(xs):
        pv = shapes.pwl_value(pts, u)
        branches.append((x.eq(u), pv))
        if k + 1 < len(xs):
            u1 = xs[k + 1]
            r0, l1 = right_limit(pts, u), left_limit(pts, u1)
            val: float | Ex = r0 if r0 == l1 else r0 + (x - u) * ((l1 - r0) / (u1 - u))
            branches.append((x.lt(u1), val))
    for k, (cond, val) in enumerate(branches):
        with b.if_(cond) if k == 0 else b.elif_(cond):
            b.set(out, val)
    with b.else_():
        b.set(out, pts[-1][1])
    return out


def _set_at(g: Gen, op: OutputPlan, sets: list[SmoothSet], x: Var, accu: str) -> tuple[Var, Var]:
    """The accumulated set at ``x`` and a code of the branch it took (under MAX 2k, +1 when
    clipped, for the largest set k; otherwise the sum of 2^k over the clipped sets, +0.5 where
    a bounded sum reaches 1)."""
    b = g.b
    acc = g.let(0.0, "ACC")
    best = g.let(-1.0, "BEST")
    code = g.let(0.0, "CODE")
    for k, s in enumerate(sets):
        term = op.terms[s.term]
        where = f"term {op.name}.{term.name}"
        mu: Ex
        if term.pwl is not None:
            mu = _const_pwl(g, term.pwl, x)
        else:
            ps: list[Ex] = [Num(float(p)) for p in term.params]  # type: ignore[arg-type]
            mu = T.smooth(g, term.kind, ps, x, where)
            if float(term.height) != 1.0:  # type: ignore[arg-type]
                mu = g.let(Num(float(term.height)) * mu, "MU")  # type: ignore[arg-type]
        c = g.let(T.mul(s.w, T.tnorm(g, s.act, s.a, mu)), "C")
        if accu == "MAX":
            with b.if_(c.gt(best)):
                b.set(best, c)
                b.set(code, float(2 * k))
                if s.act == "MIN":
                    with b.if_(s.a.lt(mu)):
                        b.set(code, float(2 * k + 1))
            T.accumulate_into(g, accu, acc, c)
        else:
            b.set(acc, T.accumulate(g, accu, acc, c))
            if s.act == "MIN" and k < 23:  # exact in REAL up to 2^23
                with b.if_(s.a.lt(mu)):
                    b.set(code, code + float(2**k))
    if accu == "BSUM":
        with b.if_(acc.ge(1.0)):
            b.set(code, code + 0.5)
    return acc, code


# --------------------------------------------------------------------------- the driver


def smooth_cog(g: Gen, op: OutputPlan, sets: list[SmoothSet], cal: Calibration) -> tuple[Var, Var]:
    """Emit the CoG of ``op`` from its activated ``sets``; returns (value, fired)."""
    b = g.b
    accu = op.accu or "MAX"
    cuts = cal.cuts
    nc = len(cuts)
    cap = (nc - 1) * (SAMPLES * ROUNDS + 1) + 2
    ctab = g.declare(g.fresh("QCUT", "QCUT"), "REAL", "const", nc, cuts, f"{op.name}: breakpoints")
    glx_v, glw_v = gauss_legendre(NODES)
    glx = g.declare(g.fresh("GLX", "GLX"), "REAL", "const", NODES, glx_v, "Gauss-Legendre nodes on 0..1")
    glw = g.declare(g.fresh("GLW", "GLW"), "REAL", "const", NODES, glw_v, "Gauss-Legendre weights")
    pts = g.array("QPT", "REAL", cap)
    n = g.let(0, "NQ", "INT")
    area, mom = g.let(0.0, "QA"), g.let(0.0, "QM")
    value, fired = g.temp(hint="Y"), g.temp("BOOL", "FIRED")
    i = g.counter("QI")
    with b.for_(i, 0, nc - 2) as iv:
        a_, b_ = g.let(ctab[iv], "QL"), g.let(ctab[iv + 1], "QR")
        b.set(pts[n], a_)
        b.set(n, n + 1)
        x = g.temp(hint="X")
        xprev, c0 = g.let(a_, "XP"), g.let(0.0, "C0")
        j = g.counter("QJ")
        with b.for_(j, 0, SAMPLES - 1) as jv:
            with b.if_(jv.eq(SAMPLES - 1)):
                b.set(x, b_)
            with b.else_():
                b.set(x, a_ + (b_ - a_) * (g.call("TO_REAL", jv) / float(SAMPLES - 1)))
            _val, cx = _set_at(g, op, sets, x, accu)
            with b.if_(jv.gt(0).and_(cx.ne(c0))):
                _locate(g, op, sets, accu, xprev, x, c0, cx, pts, n, cap)
            b.set(xprev, x)
            b.set(c0, cx)
    b.set(pts[n], cuts[-1])
    b.set(n, n + 1)
    p = g.counter("QP")
    with b.for_(p, 0, n - 2) as pv:
        d = g.let(pts[pv + 1] - pts[pv], "QD")
        with b.if_(d.gt(0.0)):
            k = g.counter("QK")
            with b.for_(k, 0, NODES - 1) as kv:
                xq = g.let(pts[pv] + glx[kv] * d, "XQ")
                y, _code = _set_at(g, op, sets, xq, accu)
                yw = g.let(y * glw[kv] * d, "YW")
                b.set(area, area + yw)
                b.set(mom, mom + yw * (xq - float(op.low or 0.0)))
    b.set(fired, area.gt(0.0))
    with b.if_(fired):
        b.set(value, float(op.low or 0.0) + mom / area)
    with b.else_():
        b.set(value, 0.0)
    return value, fired


def _locate(
    g: Gen,
    op: OutputPlan,
    sets: list[SmoothSet],
    accu: str,
    lo0: Var,
    x: Var,
    c0: Var,
    cx: Var,
    pts: Var,
    n: Var,
    cap: int,
) -> None:
    """Kinks between two samples (``lo0`` with code ``c0``, ``x`` with code ``cx``) appended to
    ``pts`` by bisection on the branch code."""
    b = g.b
    lo, hi = g.let(lo0, "LO"), g.let(x, "HI")
    code, chi = g.let(c0, "CL"), g.let(cx, "CH")
    q = g.let(0, "QR", "INT")
    go = g.let(True, "GO", "BOOL")
    with b.while_(go):
        k = g.counter("QB")
        with b.for_(k, 1, BISECTIONS):
            mid = g.let(0.5 * (lo + hi), "MID")
            _v, cm = _set_at(g, op, sets, mid, accu)
            with b.if_(cm.eq(code)):
                b.set(lo, mid)
            with b.else_():
                b.set(hi, mid)
                b.set(chi, cm)
        with b.if_(n.lt(cap - 1)):
            b.set(pts[n], 0.5 * (lo + hi))
            b.set(n, n + 1)
        b.set(q, q + 1)
        stop = chi.eq(cx).or_(not_(hi.lt(x))).or_(q.ge(ROUNDS)).or_(n.ge(cap - 1))
        with b.if_(stop):
            b.set(go, False)
        with b.else_():
            b.set(lo, hi)
            b.set(hi, x)
            b.set(code, chi)
            b.set(chi, cx)
