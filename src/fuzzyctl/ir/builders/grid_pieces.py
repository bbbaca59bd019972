"""Exact defuzzification of a piecewise-linear output on a constant grid, unrolled (the
native evaluator, :mod:`fuzzyctl.ir.programs.native`).

The PLC block builds its grid at run time and loops over tables
(:mod:`fuzzyctl.ir.builders.mamdani`); here the grid is the plan's
(:class:`~fuzzyctl.engine.plan.GridPlan`) and every interval becomes straight-line code: a
fixed list of candidate cut points (the interval's ends, each MIN-clipped set's kink, where
two linear parts of two sets cross under MAX) that only their order leaves to run time (a
sorting network), the accumulated degree at each, and the pieces between consecutive ones,
on which the set is linear.  The methods then read the pieces in increasing x:

* CoA (:func:`bisector_by_intervals`): each interval's area in closed form, then from the
  left and from the right the piece where half of it is reached, only the interval holding
  it cut into pieces (:func:`fuzzyctl.engine.reference.pwl.bisector`);
* LM, RM, MoM (:func:`leftmost`, :func:`rightmost`, :func:`mean_of_maximum`): the height
  over the pieces' ends and the grid points, then the points reaching it
  (:func:`fuzzyctl.engine.reference.pwl.maxima`).

Each method's builder is named by its entry in :mod:`fuzzyctl.kinds.methods` (``ir``).
Under MAX accumulation the maxima need not cut every interval: the height is the largest
set's (:func:`first_reaching` for LM and RM, :func:`mean_reaching` for MoM); under a sum
:func:`leftmost`, :func:`rightmost` and :func:`mean_of_maximum` read every piece.

The reference is :mod:`fuzzyctl.engine.reference.pwl`; the numpy twin of the candidate points is
``kernels_np._interval``.  Accumulations whose pieces are not linear between those points
(BSUM's cut where the sum reaches 1, PROBOR's products) use the general loops.
"""

from __future__ import annotations

from dataclasses import dataclass, field

from fuzzyctl.engine.plan import GridPlan
from fuzzyctl.engine.reference.pwl import COA_TOL, MAX_TOL
from fuzzyctl.ir.builders import terms as T
from fuzzyctl.ir.builders.pieces import Ctx, candidate, clipped_am, max_of_two, solve_linear
from fuzzyctl.ir.nodes import Ex, Num, Var, ex, not_
from fuzzyctl.ir.state import Gen
from fuzzyctl.kinds import norms

#: Accumulations whose accumulated set is linear between the candidate points (the maximum
#: and the plain sums).
LINEAR_ACCUS = frozenset(name for name, e in norms.ACCUMULATIONS.items() if e.idempotent or e.additive)


#: Above this size (:func:`unrolled_size`) the straight-line form takes longer to compile and
#: runs slower than the run-time grid's loops (:mod:`fuzzyctl.ir.builders.mamdani`), which its
#: callers then take: a 3-input, 50-rule LM system with weighted conclusions (size 50,280)
#: came to 28 MB of C and 150 s of ``cc -O3``; one of size 1,581 to 0.7 MB, 2.5 s and 2,063
#: ns/row against the loops' 0.4 s and 378 ns/row.
UNROLL_LIMIT = 1_000


def unrolled_size(grid: GridPlan, sets: list[Set], accu: str) -> int:
    """The size of the straight-line code :func:`pieces` writes, counted as :func:`_interval`
    makes it: per interval, the compare-exchanges of its candidate points' insertion network
    plus candidates times sets (the degree at each point)."""
    total = 0
    for j in range(len(grid.xs) - 1):
        lines = [(grid.left[s.term][j], grid.right[s.term][j], s) for s in sets if s.term in grid.active[j]]
        cands = sum(1 for left, right, s in lines if s.is_min and left != right)
        if norms.is_max(accu):
            flat = [[left == right for _p in range(2 if s.is_min else 1)] for left, right, s in lines]
            for i in range(len(lines)):
                for k in range(i + 1, len(lines)):
                    # a MIN set's second part (its clip) is flat; two flat parts never cross
                    cands += sum(
                        1
                        for pi, fi in enumerate(flat[i])
                        for pk, fk in enumerate(flat[k])
                        if not ((fi or pi == 1) and (fk or pk == 1))
                    )
        total += cands * (cands - 1) // 2 + cands * len(lines)
    return total


@dataclass(frozen=True)
class Set:
    """One activated set: ``w * min(a, term)`` (``is_min``) or ``w * a * term``."""

    term: int
    a: Ex
    w: Ex
    is_min: bool


@dataclass
class Pieces:
    """The linear pieces of the accumulated set in increasing x; ``points[j]`` the degree
    exactly at grid point ``j`` (filled for the maxima only)."""

    x0: list[Ex] = field(default_factory=list)
    x1: list[Ex] = field(default_factory=list)
    v0: list[Ex] = field(default_factory=list)
    v1: list[Ex] = field(default_factory=list)
    first: dict[int, int] = field(default_factory=dict)  # grid interval -> its first piece
    points: list[Ex] = field(default_factory=list)


def applies(accu: str) -> bool:
    return accu in LINEAR_ACCUS


def pieces(g: Gen, grid: GridPlan, sets: list[Set], accu: str, with_points: bool) -> Pieces:
    """Every interval's pieces (see the module docstring)."""
    out = Pieces()
    for j in range(len(grid.xs) - 1):
        act = grid.active[j]
        lines = [(grid.left[s.term][j], grid.right[s.term][j], s) for s in sets if s.term in act]
        if lines:
            out.first[j] = len(out.x0)
            _interval(g, grid.xs[j], grid.xs[j + 1], lines, accu, out)
    if with_points:  # pwl.point_values
        for j in range(len(grid.xs)):
            v = g.let(0.0, "GP")
            for s in sets:
                y = grid.point[s.term][j]
                if y != 0.0:
                    c = s.w * (g.min_(s.a, y, "PY") if s.is_min else s.a * y)
                    g.b.set(v, T.accumulate(g, accu, v, c))
            out.points.append(v)
    return out


Line = tuple[float, float, Set]


def _interval(g: Gen, x0: float, x1: float, lines: list[Line], accu: str, out: Pieces) -> None:
    b = g.b
    dx = x1 - x0
    cands: list[Var] = []
    kinks: list[Var | None] = []
    for left, right, s in lines:
        if s.is_min and left != right:  # where the term strictly crosses the degree
            kt = g.let(-1.0, "KT")
            with b.if_(((left - s.a) * (right - s.a)).lt(0.0)):
                b.set(kt, (s.a - left) / (right - left))
            kinks.append(kt)
            cands.append(g.max_(kt, 0.0, "CT"))
        else:
            kinks.append(None)
    if norms.is_max(accu) and len(lines) > 1:
        parts = [_parts(left, right, s) for left, right, s in lines]
        for i in range(len(lines)):
            for k in range(i + 1, len(lines)):
                for ai, bi in parts[i]:
                    for ak, bk in parts[k]:
                        if _zero(bi) and _zero(bk):  # two flat parts never cross
                            continue
                        t = g.let(0.0, "CT")
                        num, den = ak - ai, bi - bk
                        with b.if_(den.ne(0.0)):
                            b.set(t, num / den)
                        with b.if_(not_(t.gt(0.0).and_(t.lt(1.0)))):
                            b.set(t, 0.0)
                        cands.append(t)
    _sort(g, cands)
    ts: list[Ex] = [ex(0.0), *cands, ex(1.0)]
    vals = [_value_at(g, lines, kinks, t, accu) for t in ts]
    xs: list[Ex] = [ex(x0)] + [g.let(x0 + t * dx, "CX") for t in cands] + [ex(x1)]
    for k in range(len(ts) - 1):
        out.x0.append(xs[k])
        out.x1.append(xs[k + 1])
        out.v0.append(vals[k])
        out.v1.append(vals[k + 1])


def _parts(left: float, right: float, s: Set) -> list[tuple[Ex, Ex]]:
    """The linear parts ``A + B t`` of one set on the interval."""
    if s.is_min:
        return [(s.w * left, s.w * (right - left)), (s.w * s.a, ex(0.0))]
    return [(s.w * s.a * left, s.w * s.a * (right - left))]


def _zero(e: Ex) -> bool:
    return isinstance(e, Num) and e.value == 0.0


def _sort(g: Gen, vs: list[Var]) -> None:
    """Sort the variables in place by compare-exchange (an insertion network: few values)."""
    b = g.b
    for i in range(1, len(vs)):
        for k in range(i, 0, -1):
            lo, hi = vs[k - 1], vs[k]
            # min and max as separate selects: the C compiler makes them branch-free
            small = g.min_(hi, lo, "SL")
            b.set(hi, g.max_(lo, hi, "SH"))
            b.set(lo, small)


def _value_at(g: Gen, lines: list[Line], kinks: list[Var | None], t: Ex, accu: str) -> Var:
    """The accumulated degree at ``t`` (exactly ``w*a`` at a set's own kink)."""
    b = g.b
    acc: Var | None = None
    for (left, right, s), kink in zip(lines, kinks, strict=True):
        y = left + (right - left) * t
        if s.is_min:
            c = g.let(s.w * g.min_(s.a, y, "Y"), "CV")
            if kink is not None:
                with b.if_(kink.eq(t)):
                    b.set(c, s.w * s.a)
        else:
            c = g.let(s.w * s.a * y, "CV")
        acc = c if acc is None else g.let(T.accumulate(g, accu, acc, c), "AV")
    assert acc is not None
    return acc


# --------------------------------------------------------------------------- methods


def area(g: Gen, p: Pieces) -> tuple[list[Var], Var]:
    """Each piece's area and their sum."""
    ends = zip(p.x0, p.x1, p.v0, p.v1, strict=True)
    areas = [g.let(0.5 * (x1 - x0) * (v0 + v1), "PA") for x0, x1, v0, v1 in ends]
    total = g.let(0.0, "AREA")
    for a in areas:
        g.b.set(total, total + a)
    return areas, total


def bisector_by_intervals(g: Gen, grid: GridPlan, sets: list[Set], accu: str) -> tuple[Var, Var]:
    """CoA without cutting every interval: each interval's area in closed form (one set:
    :func:`~fuzzyctl.ir.builders.pieces.clipped_am`; two under MAX:
    :func:`~fuzzyctl.ir.builders.pieces.max_of_two`; under a sum, the sets' areas added), then
    from each side the intervals are passed by their areas and only the one where half the
    area is reached is cut into pieces (pwl.bisector on its pieces, the areas before it as
    the running sum; when rounding put the half just past its pieces, the next interval is
    tried).  Returns (value, fired)."""
    b = g.b
    spans: list[tuple[int, list[Line], Var]] = []
    for j in range(len(grid.xs) - 1):
        lines = [(grid.left[s.term][j], grid.right[s.term][j], s) for s in sets if s.term in grid.active[j]]
        if lines:
            spans.append((j, lines, _interval_area(g, grid.xs[j], grid.xs[j + 1], lines, accu)))
    total = g.let(0.0, "AREA")
    for _j, _lines, a in spans:
        b.set(total, total + a)
    fired = g.let(total.gt(0.0), "FIRED", "BOOL")
    value = g.let(0.0, "COA")
    if not spans:
        return value, fired
    with b.if_(fired):
        half = g.let(0.5 * total, "HALF")
        tol = g.let(COA_TOL * total, "CTOL")
        ends: list[Var] = []
        # half the area reached inside a piece where the set is positive: the scan from the
        # right ends at the same point (the same piece, the same area before it), so it is
        # skipped - it differs only where half is reached at the end of a piece (a zero gap)
        inside = g.let(False, "INSIDE", "BOOL")
        for left_side in (True, False):
            found = g.let(False, "FOUND", "BOOL")
            cum = g.let(0.0, "CUM")
            last = spans[-1] if left_side else spans[0]
            res = g.let(grid.xs[last[0] + 1] if left_side else grid.xs[last[0]], "END")
            if not left_side:
                b.set(found, inside)
                with b.if_(inside):
                    b.set(res, ends[0])
            for j, lines, a in spans if left_side else spans[::-1]:
                with b.if_(not_(found).and_(a.gt(0.0)).and_((cum + a).ge(half - tol))):
                    p = Pieces()
                    _interval(g, grid.xs[j], grid.xs[j + 1], lines, accu, p)
                    areas = [g.let(0.5 * (x1 - x0) * (v0 + v1), "PA") for x0, x1, v0, v1 in _ends(p)]
                    order = range(len(areas)) if left_side else range(len(areas) - 1, -1, -1)
                    flag = inside if left_side else None
                    for k in order:
                        _bisect_piece(g, p, k, areas[k], left_side, half, tol, cum, found, res, flag)
                with b.if_(not_(found)):
                    b.set(cum, cum + a)
            ends.append(res)
        b.set(value, 0.5 * (ends[0] + ends[1]))
    return value, fired


def _ends(p: Pieces) -> list[tuple[Ex, Ex, Ex, Ex]]:
    return list(zip(p.x0, p.x1, p.v0, p.v1, strict=True))


def _bisect_piece(
    g: Gen,
    p: Pieces,
    k: int,
    a: Var,
    left_side: bool,
    half: Var,
    tol: Var,
    cum: Var,
    found: Var,
    res: Var,
    inside: Var | None = None,
) -> None:
    """One piece of pwl.bisector's scan (``cum``: the area before it from that side);
    ``inside`` is set when the point is found inside the piece (not at its end)."""
    b = g.b
    with b.if_(not_(found)):
        with b.if_(a.gt(0.0).and_((cum + a).ge(half - tol))):
            b.set(found, True)
            with b.if_((half - cum).ge(a - tol)):  # the whole piece: its end
                b.set(res, p.x1[k] if left_side else p.x0[k])
            with b.else_():
                r = (half - cum) if left_side else a - (half - cum)
                solve_linear(g, res, p.x0[k], p.x1[k], p.v0[k], p.v1[k], p.x1[k] - p.x0[k], r)
                if inside is not None:
                    b.set(inside, True)
        with b.else_():
            b.set(cum, cum + a)


def _interval_area(g: Gen, x0: float, x1: float, lines: list[Line], accu: str) -> Var:
    """The area of the accumulated sets on one interval, in closed form where it has one."""
    as_static = [(left, right, s.a, s.w, s.is_min) for left, right, s in lines]
    if len(lines) == 1 or norms.adds(accu):
        total = g.let(0.0, "IA")
        for line in as_static:
            with g.b.if_((line[2] * line[3]).gt(0.0)):
                a, _m = clipped_am(g, x0, x1 - x0, line)
                g.b.set(total, total + a)
        return total
    if len(lines) == 2 and norms.is_max(accu):
        return max_of_two(g, x0, x1, as_static[0], as_static[1])[0]
    p = Pieces()
    _interval(g, x0, x1, lines, accu, p)
    total = g.let(0.0, "IA")
    for x0_, x1_, v0, v1 in _ends(p):
        g.b.set(total, total + 0.5 * (x1_ - x0_) * (v0 + v1))
    return total


def _height(g: Gen, p: Pieces) -> Var:
    """The level the maximum is reached at: the height over the pieces' ends and the grid
    points, less MAX_TOL of it (computed crossings: pwl.maxima)."""
    sup = g.let(0.0, "SUP")
    for v in [*p.v0, *p.v1, *p.points]:
        with g.b.if_(v.gt(sup)):
            g.b.set(sup, v)
    return g.let(sup * (1.0 - MAX_TOL), "THR")


def leftmost(g: Gen, p: Pieces, grid: GridPlan, areas: list[Var], total: Var) -> Var:
    """LM: the first point reaching the height."""
    return _extreme(g, p, grid, _height(g, p), True)


def rightmost(g: Gen, p: Pieces, grid: GridPlan, areas: list[Var], total: Var) -> Var:
    """RM: the last point reaching the height."""
    return _extreme(g, p, grid, _height(g, p), False)


def mean_of_maximum(g: Gen, p: Pieces, grid: GridPlan, areas: list[Var], total: Var) -> Var:
    """MoM (pwl.maxima): the centroid of the plateaus at the height, or the mean of the
    distinct points reaching it, visited in increasing x (grid point j, then the pieces of
    interval j) so that :func:`~fuzzyctl.ir.builders.pieces.candidate` sees repeated points
    next to each other."""
    b = g.b
    c = _maxima_state(g, grid.xs[0], grid.xs[-1])
    st = c.st
    thr = st["THR"] = _height(g, p)
    n_pieces = len(p.x0)
    for j in range(len(grid.xs)):
        with b.if_(p.points[j].ge(thr)):
            candidate(c, ex(grid.xs[j]))
        start = p.first.get(j)
        if start is None:
            continue
        stop = min([s for s in p.first.values() if s > start], default=n_pieces)
        for k in range(start, stop):
            _visit(c, thr, p.x0[k], p.x1[k], p.v0[k], p.v1[k])
    return _mean(g, c, grid)


def _visit(c: Ctx, thr: Var, x0: Ex, x1: Ex, v0: Ex, v1: Ex) -> None:
    """One piece for MoM: its ends reaching the height, its length when it is a plateau."""
    b, st = c.g.b, c.st
    with b.if_(v0.ge(thr)):
        candidate(c, x0)
    with b.if_(v1.ge(thr)):
        candidate(c, x1)
    with b.if_(v0.ge(thr).and_(v1.ge(thr)).and_(x1.gt(x0))):
        b.set(st["PLEN"], st["PLEN"] + (x1 - x0))
        b.set(st["PMOM"], st["PMOM"] + (x1 - x0) * 0.5 * (x0 + x1))


def _mean(g: Gen, c: Ctx, grid: GridPlan) -> Var:
    """MoM from what :func:`_visit` gathered (pwl.maxima)."""
    b, st = g.b, c.st
    value = g.let(0.0, "MX")
    near = MAX_TOL * (grid.xs[-1] - grid.xs[0])
    with b.if_(st["PLEN"].gt(near)):
        b.set(value, st["PMOM"] / st["PLEN"])
    with b.elif_(st["ICNT"].gt(0)):
        b.set(value, st["ISUM"] / g.call("TO_REAL", st["ICNT"]))
    return value


def _extreme(g: Gen, p: Pieces, grid: GridPlan, thr: Var, leftmost: bool) -> Var:
    """LM (``leftmost``) or RM: the first point reaching ``thr`` from that side."""
    b = g.b
    points: list[tuple[Ex, Ex]] = []  # (x, degree) in increasing x
    starts = sorted(p.first.items())
    for j in range(len(grid.xs)):
        points.append((ex(grid.xs[j]), p.points[j]))
        for jj, start in starts:
            if jj == j:
                stop = min([s for s in p.first.values() if s > start], default=len(p.x0))
                for k in range(start, stop):
                    points += [(p.x0[k], p.v0[k]), (p.x1[k], p.v1[k])]
    if not leftmost:
        points.reverse()
    value = g.let(0.0, "MX")
    for k, (x, v) in enumerate(points):  # an if / else-if chain: the first hit ends it
        with b.if_(v.ge(thr)) if k == 0 else b.elif_(v.ge(thr)):
            b.set(value, x)
    return value


def first_reaching(g: Gen, grid: GridPlan, sets: list[Set], leftmost: bool) -> Var:
    """LM (``leftmost``) or RM under MAX accumulation, without building every piece: the
    height is the largest set's (``w * min(a, peak)`` or ``w * a * peak``, ``peak`` the
    largest value the term's pieces end at: what :func:`pieces` would find), then the grid
    points and intervals are visited from that side, each interval's pieces built only
    while nothing reached the height yet."""
    b = g.b
    thr = _max_height(g, grid, sets)
    value = g.let(0.0, "MX")
    found = g.let(False, "FOUND", "BOOL")
    n = len(grid.xs)
    steps = [("point", j) if k % 2 == 0 else ("interval", j) for j in range(n) for k in range(2)][:-1]
    if not leftmost:
        steps.reverse()
    for kind, j in steps:
        with b.if_(not_(found)):
            if kind == "point":
                ends: list[tuple[Ex, Ex]] = [(ex(grid.xs[j]), _point(g, grid, sets, j))]
            else:
                lines = [
                    (grid.left[s.term][j], grid.right[s.term][j], s) for s in sets if s.term in grid.active[j]
                ]
                if not lines:
                    continue
                p = Pieces()
                _interval(g, grid.xs[j], grid.xs[j + 1], lines, "MAX", p)
                ends = [e for k in range(len(p.x0)) for e in ((p.x0[k], p.v0[k]), (p.x1[k], p.v1[k]))]
                if not leftmost:
                    ends.reverse()
            for x, v in ends:
                with b.if_(not_(found).and_(v.ge(thr))):
                    b.set(value, x)
                    b.set(found, True)
    return value


def mean_reaching(g: Gen, grid: GridPlan, sets: list[Set]) -> Var:
    """MoM under MAX accumulation: the height from each set's peak (as
    :func:`first_reaching`), then only the intervals where some set can reach it are cut
    into pieces (a set stays below ``w * min(a, max(L, R))`` on an interval)."""
    b = g.b
    thr = _max_height(g, grid, sets)
    c = _maxima_state(g, grid.xs[0], grid.xs[-1])
    c.st["THR"] = thr
    for j in range(len(grid.xs)):
        with b.if_(_point(g, grid, sets, j).ge(thr)):
            candidate(c, ex(grid.xs[j]))
        if j == len(grid.xs) - 1:
            break
        lines = [(grid.left[s.term][j], grid.right[s.term][j], s) for s in sets if s.term in grid.active[j]]
        if not lines:
            continue
        reach: Ex | None = None
        for left, right, s in lines:
            top = max(left, left + (right - left) * 1.0)
            r = (s.w * (g.min_(s.a, top, "PK") if s.is_min else s.a * top)).ge(thr)
            reach = r if reach is None else reach.or_(r)
        assert reach is not None
        with b.if_(reach):
            p = Pieces()
            _interval(g, grid.xs[j], grid.xs[j + 1], lines, "MAX", p)
            for k in range(len(p.x0)):
                _visit(c, thr, p.x0[k], p.x1[k], p.v0[k], p.v1[k])
    return _mean(g, c, grid)


def _max_height(g: Gen, grid: GridPlan, sets: list[Set]) -> Var:
    """The level of the maximum under MAX accumulation: the largest set's height (its term's
    peak, clipped or scaled), less MAX_TOL of it."""
    b = g.b
    sup = g.let(0.0, "SUP")
    for s in sets:
        peak = _peak(grid, s.term)
        top = s.w * (g.min_(s.a, peak, "PK") if s.is_min else s.a * peak)
        with b.if_(top.gt(sup)):
            b.set(sup, top)
    return g.let(sup * (1.0 - MAX_TOL), "THR")


def _peak(grid: GridPlan, t: int) -> float:
    """The largest degree term ``t`` takes at a piece end or grid point, computed as the
    pieces compute it (``L + (R - L) * 1.0`` at an interval's right end)."""
    vals = [*grid.point[t], 0.0]
    for j in range(len(grid.xs) - 1):
        if t in grid.active[j]:
            left, right = grid.left[t][j], grid.right[t][j]
            vals += [left, left + (right - left) * 1.0]
    return max(vals)


def _point(g: Gen, grid: GridPlan, sets: list[Set], j: int) -> Var:
    """The accumulated degree (MAX) exactly at grid point ``j`` (pwl.point_values)."""
    v = g.let(0.0, "GP")
    for s in sets:
        y = grid.point[s.term][j]
        if y != 0.0:
            c = s.w * (g.min_(s.a, y, "PY") if s.is_min else s.a * y)
            g.b.set(v, T.accumulate(g, "MAX", v, c))
    return v


def _maxima_state(g: Gen, low: float, high: float) -> Ctx:
    """The running state :func:`~fuzzyctl.ir.builders.pieces.candidate` updates."""
    st: dict[str, Var] = {}
    for name in ("LMX", "RMX", "PLEN", "PMOM", "ISUM", "LASTX"):
        st[name] = g.let(0.0, name)
    st["ICNT"] = g.let(0, "ICNT", "INT")
    v = {"LOW": g.let(low, "LOW"), "HIGH": g.let(high, "HIGH")}
    none = st["LMX"]  # the table fields of the context are not read here
    return Ctx(g, v, {}, st, None, set(), set(), none, none, none, none, none, none, none, none)
