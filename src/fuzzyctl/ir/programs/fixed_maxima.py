"""Mamdani outputs of the integer block under LM, RM and MoM (left-most, right-most maximum,
mean of maxima) of the accumulated set of piecewise-linear output terms, with two error
bounds: the worst case over every input, and the bound away from ties.

**Where the maximum lies.**  Under MAX accumulation the accumulated set is
``mu(x) = max_k s_k(x)`` over the activated sets ``s_k = min(g_k, l_k)`` (MIN activation,
``l_k = w_k T_k`` the weighted term) or ``s_k = g_k l_k`` (PROD).  Set ``k`` reaches the
height ``e_k = min(g_k, max l_k)`` (MIN) or ``g_k max l_k`` (PROD), so ``mu`` peaks at
``H = max_k e_k`` and ``mu(x) >= H`` exactly where some set with ``e_k = H`` has
``l_k(x) >= H`` (MIN) or ``l_k(x) = max l_k`` (PROD).  The maximising set is therefore the
union, over the sets at the top, of one level set of a *constant* term: where such a level
set starts (its left end ``L_k(h)``: the inverse of the term's running maximum from the
left) is a piecewise-linear function of the level ``h`` fixed at generation time, cut at the
term's breakpoints (the reference engine's pieces, :func:`fuzzyctl.engine.reference.pwl.maxima`,
take the same points: a clipped edge's crossing ``x = a + (h - y_a) (b - a) / (y_b - y_a)``,
a vertical edge, a plateau's end).  ``R_k(h)`` is the same from the right.  So at run time:
each set's height (a MIN with a constant), their maximum ``H'``, the sets within a tolerance
``delta`` of it (the *top group*), its lowest height ``h*``, and ``LM = min L_k(h*)``,
``RM = max R_k(h*)`` over the group (an if-chain over each term's level bands, one product
by a generation-time constant, one rescaling).  MoM is ``(LM + RM) / 2``: for a single top
set over a term whose level sets are intervals (required: terms with two separate humps are
refused for MoM) it is the reference's mean of the maximising set exactly (an interval's
centroid, or the point itself); for a top group of several sets it is the middle of the
group's hull, which the reference's centroid of the union equals when their level sets
overlap.  No sorting, no run-time division.  ACCU SUM is computed where no two activated
sets overlap (the sum is then the maximum); elsewhere a sum of clipped sets has its maximum
at run-time kinks, which is refused.

**Away from ties.**  Each height is within ``e`` (its tracked rounding,
:mod:`fuzzyctl.ir.builders.fixed_arith`) of the exact one.  Take ``delta = ceil(2 e D)``
stored units and ``tie_margin = delta / D + 2 e``.  Where one set alone has the exact top
height ``H``, every other set lies more than ``tie_margin`` below it, ``H > tie_margin`` and
``H`` is more than ``tie_margin`` from the levels where that set's own ``L`` or ``R`` jumps
(a flat step inside a rising edge: the start moves from one end of the step to the other),
the integer top group is that set alone and ``h* = e'_k`` is within ``e`` of ``H``; every
``L_k``, ``R_k`` is Lipschitz between its jumps with constant ``lip`` (the largest
run/rise of the term's edges), and the band chosen by comparing ``h*`` with rounded level
constants is off by at most ``1/D``: the position is within ``lip (e + 1/D)`` plus its own
rounding of the exact one.  That is ``error_bound_away_from_ties``; its condition is stated
with ``tie_margin`` (in degrees) in the header and ``--json``.  Two exact ties stay tied in
integers whatever path computed their degrees (``delta >= 2 e``).

**The worst case.**  Near a tie the exact LM itself jumps from one set's start to another's,
and the integer result may take either side: no rounding, however small, avoids it.  Both
results always lie among the candidate positions: the integer one is limited to each set's
range of ``L_k`` (``R_k``) over every level, which holds the exact one, and the default when
nothing fires.  ``error_bound`` is the width of that hull (LM: of the ``L_k`` ranges, RM: of
the ``R_k``, MoM: of both) with the default, and never less than the bound away from ties:
the largest jump the exact function and the rounding can make, computed from the candidate
positions at generation time."""

from __future__ import annotations

import contextlib
import itertools
import math
from dataclasses import dataclass, replace
from fractions import Fraction
from typing import TYPE_CHECKING

from fuzzyctl.engine.plan import OutputPlan
from fuzzyctl.engine.semantics.operators import CLIP_BRANCH
from fuzzyctl.escape import CodegenError
from fuzzyctl.ir.builders import fixed_arith as fa
from fuzzyctl.ir.builders.fixed_arith import FX
from fuzzyctl.ir.builders.fixed_bound import Group, weight_bounds
from fuzzyctl.ir.nodes import Call, Ex, Int, Var
from fuzzyctl.kinds import norms
from fuzzyctl.kinds.methods import METHODS

if TYPE_CHECKING:
    from fuzzyctl.ir.programs.fixed_block import FixedBlock, Port

__all__ = ["Profile", "away_from_ties", "check_maxima", "maxima_output", "profiles", "term_edges"]

#: one band of a profile: for levels ``h`` in ``(h0, h1]`` the position is
#: ``x0 + (h - h0) (x1 - x0) / (h1 - h0)`` (stored output units)
Band = tuple[Fraction, Fraction, Fraction, Fraction]
Edge = tuple[Fraction, Fraction, Fraction, Fraction]  # (xa, xb, ya, yb): linear from a to b


def _refuse(what: str) -> CodegenError:
    return CodegenError(f"{what} in integer arithmetic (use --arith float)")


@dataclass(frozen=True)
class Profile:
    """Where the level set ``{x: term(x) >= h}`` starts, for ``h`` in ``(0, peak]``, seen
    from one side: bands of levels on each of which it moves linearly, and the levels where
    it jumps (the running maximum is flat over a stretch, then rises again)."""

    bands: tuple[Band, ...]
    jumps: tuple[Fraction, ...]
    peak: Fraction

    def at(self, h: Fraction) -> Fraction:
        """The position at level ``h`` (0 < h <= peak), exactly."""
        for h0, h1, x0, x1 in self.bands:
            if h <= h1:
                return x0 if h1 == h0 else x0 + (h - h0) * (x1 - x0) / (h1 - h0)
        return self.bands[-1][3]

    def lip(self) -> Fraction:
        """The largest run / rise of its bands (positions per unit of level)."""
        return max(
            (abs(x1 - x0) / (h1 - h0) for h0, h1, x0, x1 in self.bands if h1 > h0), default=Fraction(0)
        )

    def span(self) -> tuple[Fraction, Fraction]:
        xs = [x for b in self.bands for x in b[2:]]
        return min(xs), max(xs)

    def scaled(self, w: Fraction) -> Profile:
        """The profile of ``w * term``."""
        return Profile(
            tuple((h0 * w, h1 * w, x0, x1) for h0, h1, x0, x1 in self.bands),
            tuple(j * w for j in self.jumps),
            self.peak * w,
        )


def _profile(edges: list[Edge]) -> Profile:
    """The running maximum of the edges (in increasing x) inverted."""
    m = Fraction(0)
    bands: list[Band] = []
    jumps: list[Fraction] = []

    def add(top: Fraction, x0: Fraction, x1: Fraction) -> None:
        nonlocal m
        if bands and bands[-1][3] < x0:  # flat at m, then higher further on
            jumps.append(m)
        bands.append((m, top, x0, x1))
        m = top

    for xa, xb, ya, yb in edges:
        if ya > m:  # a vertical edge at xa (or the first value of the range)
            add(ya, xa, xa)
        if yb > m:
            add(yb, xa if ya >= m else xa + (m - ya) / (yb - ya) * (xb - xa), xb)
    return Profile(tuple(bands), tuple(jumps), m)


def term_edges(op: OutputPlan, t: int, xi: tuple[Fraction, ...]) -> list[Edge]:
    """Term ``t`` on the output's grid, in stored units ``xi`` (its intervals of zero width left
    out); a degree exactly at a grid point above both its neighbours (a spike no piece has)
    is refused."""
    assert op.grid is not None
    g = op.grid
    out: list[Edge] = []
    for j in range(len(xi) - 1):
        if xi[j + 1] <= xi[j]:
            continue
        on = t in g.active[j]
        ya = Fraction(g.left[t][j]) if on else Fraction(0)
        yb = Fraction(g.right[t][j]) if on else Fraction(0)
        out.append((xi[j], xi[j + 1], ya, yb))
    for j, p in enumerate(g.point[t]):
        near = [Fraction(g.right[t][j - 1])] if j > 0 else []
        near += [Fraction(g.left[t][j])] if j < len(g.left[t]) else []
        if near and Fraction(p) > max(near):
            raise _refuse(f"output {op.name!r}: term {op.terms[t].name!r} has a lone point above its edges")
    return out


def profiles(edges: list[Edge]) -> tuple[Profile, Profile]:
    """The left and right profiles of a term (the right one found on the mirrored axis)."""
    left = _profile(edges)
    mirrored = _profile([(-xb, -xa, yb, ya) for xa, xb, ya, yb in reversed(edges)])
    right = Profile(
        tuple((h0, h1, -x0, -x1) for h0, h1, x0, x1 in mirrored.bands), mirrored.jumps, mirrored.peak
    )
    return left, right


def _one_hump(edges: list[Edge]) -> bool:
    """Every level set is one interval: the degrees never rise again after falling."""
    ys = [y for _a, _b, ya, yb in edges for y in (ya, yb)]
    fell = False
    for a, b in itertools.pairwise(ys):
        if b < a:
            fell = True
        elif b > a and fell:
            return False
    return True


def check_maxima(op: OutputPlan, weight_before_activation: bool) -> None:
    """Refuse what LM, RM and MoM in integers do not compute, naming it (terms, activation
    and accumulation are checked by :func:`fuzzyctl.ir.programs.fixed_mamdani.check_mamdani`;
    ACCU SUM over overlapping sets when the sets are known)."""
    del weight_before_activation
    if METHODS[op.method].maximum is None:  # pragma: no cover - dispatched on it
        raise _refuse(f"output {op.name!r}: METHOD {op.method} is not a maximum")


# --------------------------------------------------------------------------- the sets


@dataclass(frozen=True)
class _Set:
    """One activated set: its level (weighted degree), its term's factor (MIN: the set is
    ``min(level, w T)``; PROD: ``level T``), and its term's profiles scaled by that factor."""

    term: int
    level: FX
    w: Fraction
    is_min: bool
    left: Profile
    right: Profile


def _sets(blk: FixedBlock, op: OutputPlan, rules: list[FX], xi: tuple[Fraction, ...]) -> list[_Set]:
    """The activated sets (as fixed_mamdani forms them: under MAX one per term, activation and
    weight, its level the largest degree)."""
    from fuzzyctl.ir.programs.fixed_outputs import constant

    is_max = norms.is_max(op.accu or "MAX")
    keyed: dict[object, list[int]] = {}
    for k, c in enumerate(op.contributions):
        if constant(c.weight) == 0.0:
            continue
        key: object = (c.term, c.act, constant(c.weight)) if is_max else k
        keyed.setdefault(key, []).append(k)
    shapes: dict[int, tuple[list[Edge], Profile, Profile]] = {}
    out = []
    for ks in keyed.values():
        c = op.contributions[ks[0]]
        assert c.term is not None
        if c.term not in shapes:
            edges = term_edges(op, c.term, xi)
            shapes[c.term] = (edges, *profiles(edges))
        edges, left, right = shapes[c.term]
        if left.peak == 0:
            continue  # zero on the range: never part of the maximum
        if METHODS[op.method].maximum == "mean" and not _one_hump(edges):
            raise _refuse(
                f"output {op.name!r}: term {op.terms[c.term].name!r} has two separate humps: the mean of "
                "maxima over level sets of two pieces is not computed"
            )
        g = rules[c.rule]
        for k in ks[1:]:
            g = blk.minmax(g, rules[op.contributions[k].rule], False)
        w = constant(c.weight)
        is_min = c.act in CLIP_BRANCH
        f = Fraction(w) if is_min else Fraction(1)
        out.append(_Set(c.term, blk.weighted(g, w), f, is_min, left.scaled(f), right.scaled(f)))
    if not is_max:
        _check_apart(op, out, xi)
    return out


def _check_apart(op: OutputPlan, sets: list[_Set], xi: tuple[Fraction, ...]) -> None:
    """Under SUM, no two sets may be nonzero on one interval (the sum is then their maximum)."""
    assert op.grid is not None
    g = op.grid
    for j in range(len(xi) - 1):
        on = [s for s in sets if s.term in g.active[j] and (g.left[s.term][j] or g.right[s.term][j])]
        if xi[j + 1] > xi[j] and len(on) > 1:
            names = ", ".join(sorted({repr(op.terms[s.term].name) for s in on}))
            raise _refuse(
                f"output {op.name!r}: ACCU {op.accu} of overlapping sets ({names}) under METHOD {op.method}: "
                "the maximum of a sum of clipped sets lies at run-time kinks and is not computed"
            )


# --------------------------------------------------------------------------- run time


def _height(blk: FixedBlock, s: _Set) -> FX:
    """The set's top: ``min(level, w peak)`` (MIN) or ``level * peak`` (PROD), in a variable."""
    peak = s.left.peak
    if s.is_min:
        cap = fa.const(blk.w, peak, blk.dscale)
        e = s.level if s.level.hi <= cap.lo else blk.minmax(s.level, cap, True)
    elif peak == 1:
        e = s.level
    else:
        e = blk.product(s.level, fa.const(blk.w, peak, blk.dscale))
    return e if isinstance(e.ex, Var) else blk.temp(e, "a set's height")


def _band(blk: FixedBlock, hs: Var, lo: int, hi: int, band: Band) -> FX:
    """The position on one band for the stored level ``hs`` in ``[lo, hi]`` (scale 1, its
    rounding only)."""
    w, D = blk.w, blk.D
    h0, h1, x0, x1 = band
    if x0 == x1 or h1 == h0:
        return fa.const(w, x1, Fraction(1))
    k = (x1 - x0) / (h1 - h0)  # positions per unit of level
    c0 = max(lo, min(hi, round(h0 * D)))
    base = x0 + (Fraction(c0, D) - h0) * k
    t = FX(hs, lo, hi, Fraction(1), Fraction(0), False)
    for s in range(2 * blk.arith.bits, -1, -1):
        fine = Fraction(1, 1 << s)
        try:
            dx = fa.sub(w, fa.widen(t), fa.const(w, Fraction(c0), Fraction(1), True))
            prod = fa.mul(w, dx, fa.const(w, k / D, fine, True, "a run over a rise"))
            return fa.rdiv(w, fa.add(w, prod, fa.const(w, base, fine, True)), 1 << s)
        except CodegenError:
            continue
    raise _refuse("an output term's edge: its run over its rise does not fit the wide type")


def _position(blk: FixedBlock, prof: Profile, hs: FX, is_min: bool, extra: Fraction) -> FX:
    """Where ``prof``'s level set starts at level ``hs`` (PROD: at the peak), limited to the
    profile's positions; error: its rounding plus ``lip * extra``."""
    w = blk.w
    lo_x, hi_x = prof.span()
    lo_i, hi_i = math.floor(lo_x), math.ceil(hi_x)
    if not is_min:
        return fa.const(w, prof.at(prof.peak), Fraction(1))
    assert isinstance(hs.ex, Var)
    # (condition HS <= c, band or a constant end, the stored levels the branch sees)
    plan: list[tuple[int | None, Band | Fraction, int, int]] = []
    cur = hs.lo
    n = len(prof.bands)
    for i, band in enumerate(prof.bands):
        c = round(band[1] * blk.D)
        if c >= hs.hi:
            plan.append((None, band, cur, hs.hi))
            break
        if c < cur:
            continue  # narrower than a stored unit: the next band's line is within lip / D
        plan.append((c, band, cur, c))
        cur = c + 1
        if i == n - 1:  # a level rounded above the peak: the end of the last band
            plan.append((None, band[3], cur, hs.hi))
    v = blk.declare(f"P_{len(blk.decls)}", "narrow", comment="where a level set starts")
    err = Fraction(0)
    for k, (cut, what, lo, hi) in enumerate(plan):
        if cut is None:
            ctx = blk.b.else_() if k else contextlib.nullcontext()
        else:
            ctx = blk.b.if_(hs.ex.le(Int(cut))) if k == 0 else blk.b.elif_(hs.ex.le(Int(cut)))
        with ctx:
            if isinstance(what, Fraction):
                val = fa.const(w, what, Fraction(1))
            else:
                val = fa.narrow(w, _band(blk, hs.ex, lo, hi, what), "where a level set starts")
            err = max(err, val.err)
            blk.b.set(v, val.ex)
            if val.lo < lo_i:  # the exact position lies in the profile's span: limiting only helps
                with blk.b.if_(v.lt(Int(lo_i))):
                    blk.b.set(v, Int(lo_i))
            if val.hi > hi_i:
                with blk.b.if_(v.gt(Int(hi_i))):
                    blk.b.set(v, Int(hi_i))
    return FX(v, lo_i, hi_i, Fraction(1), err + prof.lip() * extra, False)


def _extreme(blk: FixedBlock, name: str, cands: list[tuple[Ex, FX]], left: bool) -> FX:
    """``name := min`` (left) or ``max`` of the positions whose condition holds (at least one
    does: the set at ``H'``)."""
    lo = min(p.lo for _c, p in cands)
    hi = max(p.hi for _c, p in cands)
    v = blk.declare(name, "narrow", comment="left end of the maximum" if left else "right end of the maximum")
    blk.b.set(v, Int(hi if left else lo))
    for cond, p in cands:
        with blk.b.if_(cond.and_(p.ex.lt(v) if left else p.ex.gt(v))):
            blk.b.set(v, p.ex)
    return FX(v, lo, hi, Fraction(1), max(p.err for _c, p in cands), False)


def _mean(blk: FixedBlock, in_group: list[Ex], lp: list[FX], rp: list[FX], lm: FX, rm: FX) -> FX:
    """MoM: ``(L + R) / 2`` of a single top set; of a group of several, the centroid of the
    union of their intervals (each one less what the intervals starting before it cover:
    ``[max(L_k, R_before), R_k]``, exact on the integer ends), or ``(LM + RM) / 2`` when the
    union has no length (lone points), limited to ``[LM, RM]``."""
    w = blk.w
    half = fa.narrow(w, fa.rdiv(w, fa.add(w, lm, rm), 2), "the mean of maxima")
    v = blk.declare(f"MOM_{len(blk.decls)}", "narrow", comment="mean of maxima")
    blk.b.set(v, half.ex)
    if len(lp) == 1:
        return FX(v, half.lo, half.hi, Fraction(1), half.err, False)
    lo, hi = min(p.lo for p in lp + rp), max(p.hi for p in lp + rp)
    c = (lo + hi) // 2
    reach = max(c - lo, hi - c)
    wide_hi = w.limits(True)[1]
    if reach * reach > wide_hi or 2 * (hi - lo) * len(lp) > wide_hi:
        raise _refuse("an output's mean of maxima: the union's moment does not fit the wide type")
    n = len(blk.decls)
    count = blk.declare(f"NG_{n}", "narrow", comment="sets in the top group")
    length = blk.declare(f"LEN_{n}", "wide", comment="length of the union of their level sets")
    # the union's pieces are disjoint: their moment about c, sum of (R-c)^2 - (s-c)^2, stays
    # within reach^2 in magnitude whatever the partial sum
    moment = blk.declare(f"MOM2_{n}", "wide", comment=f"twice its moment about {c}")
    start = blk.declare(f"RB_{n}", "narrow", comment="the part of a level set left uncovered starts here")
    blk.b.set(count, Int(0))
    for g in in_group:
        with blk.b.if_(g):
            blk.b.set(count, count + Int(1))
    with blk.b.if_(count.gt(Int(1))):
        blk.b.set(length, Int(0))
        blk.b.set(moment, Int(0))
        for k, (gk, lk, rk) in enumerate(zip(in_group, lp, rp, strict=True)):
            with blk.b.if_(gk):
                blk.b.set(start, lk.ex)
                for j, (gj, lj, rj) in enumerate(zip(in_group, lp, rp, strict=True)):
                    if j == k:
                        continue
                    before = lj.ex.le(lk.ex) if j < k else lj.ex.lt(lk.ex)
                    with blk.b.if_(gj.and_(before).and_(rj.ex.gt(start))):
                        blk.b.set(start, rj.ex)
                with blk.b.if_(rk.ex.gt(start)):
                    r_w, s_w = Call("WIDEN", (rk.ex,)), Call("WIDEN", (start,))
                    blk.b.set(length, length + (r_w - s_w))
                    blk.b.set(moment, moment + (r_w - s_w) * (r_w + s_w - Int(2 * c)))
        with blk.b.if_(length.gt(Int(0))):
            q = blk.declare(f"Q_{n}", "wide")
            with blk.b.if_(moment.ge(Int(0))):
                blk.b.set(q, (moment + length) / (Int(2) * length))
            with blk.b.else_():
                blk.b.set(q, -((length - moment) / (Int(2) * length)))
            blk.b.set(q, q + Int(c))
            lm_w, rm_w = Call("WIDEN", (lm.ex,)), Call("WIDEN", (rm.ex,))
            with blk.b.if_(q.lt(lm_w)):
                blk.b.set(q, lm_w)
            with blk.b.if_(q.gt(rm_w)):
                blk.b.set(q, rm_w)
            blk.b.set(v, Call("NARROW", (q,)))
    return FX(v, min(half.lo, lm.lo), max(half.hi, rm.hi), Fraction(1), half.err, False)


@dataclass(frozen=True)
class _Bounds:
    worst: Fraction  # stored units
    away: Fraction
    margin: Fraction  # degrees


def _compute(blk: FixedBlock, op: OutputPlan, sets: list[_Set]) -> tuple[FX, FX, _Bounds]:
    """Emit the heights, the top group and the result; ``(H', result, bounds)``."""
    D = blk.D
    side = METHODS[op.method].maximum
    heights = [_height(blk, s) for s in sets]
    e = max(h.err for h in heights)
    top = heights[0]
    for h in heights[1:]:
        top = blk.minmax(top, h, False)
    delta = max(1, math.ceil(2 * e * D))
    margin = Fraction(delta, D) + 2 * e
    # the top group's lowest height: every set in it reaches it
    hs = blk.temp(replace(top, err=Fraction(0)), "the top group's lowest height")
    # (conditions, not BOOL temporaries: an initialised VAR_TEMP is refused by some compilers)
    in_group = [h.ex.ge(top.ex - Int(delta)) for h in heights]
    if len(sets) > 1:
        for h, cond in zip(heights, in_group, strict=True):
            with blk.b.if_(cond.and_(h.ex.lt(hs.ex))):
                blk.b.set(hs.ex, h.ex)  # type: ignore[arg-type]
    hs = replace(hs, lo=max(0, min(h.lo for h in heights)))
    extra = e + Fraction(1, D)
    lefts = rights = None
    if side in ("left", "mean"):
        lp = [_position(blk, s.left, hs, s.is_min, extra) for s in sets]
        lefts = _extreme(blk, f"LM_{len(blk.decls)}", list(zip(in_group, lp, strict=True)), True)
    if side in ("right", "mean"):
        rp = [_position(blk, s.right, hs, s.is_min, extra) for s in sets]
        rights = _extreme(blk, f"RM_{len(blk.decls)}", list(zip(in_group, rp, strict=True)), False)
    if lefts is not None and rights is not None:
        away = max((a.err + b.err) / 2 for a, b in zip(lp, rp, strict=True)) + Fraction(1, 2)
        res = _mean(blk, in_group, lp, rp, lefts, rights)
        res = replace(res, err=away)
        spans = [p.span() for s in sets for p in (s.left, s.right)]
    else:
        one = lefts if lefts is not None else rights
        assert one is not None
        res = one
        ps = lp if lefts is not None else rp
        away = max(p.err for p in ps)
        spans = [(s.left if lefts is not None else s.right).span() for s in sets]
    lo = min(math.floor(a) for a, _b in spans)
    hi = max(math.ceil(b) for _a, b in spans)
    return top, res, _Bounds(Fraction(hi - lo), away, margin)


def _always_fires(blk: FixedBlock, op: OutputPlan, e: Fraction) -> None:
    """With a NaN default (no rule fired) there is no number to bound the error by: the top
    height must be proven above its rounding ``e`` over every input (a set ``min(w a, w p)``
    or ``w a p`` holds at least ``w a p``; the box search of the rules' degrees)."""
    from fuzzyctl.ir.programs.fixed_outputs import constant, input_domain

    items = []
    for c in op.contributions:
        w = constant(c.weight)
        if c.term is not None and w > 0:
            items.append((c.rule, w * max((y for _x, y in op.terms[c.term].pwl or ()), default=0.0)))
    groups: list[Group] = [(op.accu or "MAX", tuple(items))]
    weights = [constant(r.weight) for r in blk.plan.rules]
    found = weight_bounds(blk.plan, groups, weights, input_domain(blk), budget=2000, enough=0.75)
    if not Fraction(found.low) > e:
        where = ", ".join(f"{blk.plan.inputs[k].name}={v:g}" for k, v in sorted(found.witness.items()))
        raise _refuse(
            f"output {op.name!r}: its DEFAULT is NaN and no rule may fire (the top comes down to "
            f"{found.witness_total:.3g} at {where}): no worst-case error bound"
        )


def maxima_output(blk: FixedBlock, op: OutputPlan, rules: list[FX], info: Var) -> Port:
    """The LM, RM or MoM of Mamdani output ``op`` (terms and rules checked)."""
    from fuzzyctl.ir.programs.fixed_block import Port
    from fuzzyctl.ir.programs.fixed_mamdani import output_axis
    from fuzzyctl.ir.programs.fixed_outputs import round_up

    w = blk.w
    assert op.grid is not None and op.low is not None and op.high is not None
    nan, default, scale, offset, xi, xlo, xhi = output_axis(blk, op)
    blk.b.comment(f"output {op.name}: {op.method} of the accumulated set (ACCU {op.accu or 'MAX'})")
    sets = _sets(blk, op, rules, xi)
    if not sets:
        raise _refuse(f"output {op.name!r}: concluded by no rule with a nonzero term, it has no integer form")
    top, res, bounds = _compute(blk, op, sets)
    if nan:
        _always_fires(blk, op, top.err)
    slo, shi = math.floor(xlo), math.ceil(xhi)
    dflt = 0 if nan else round((default - offset) / scale)
    worst = bounds.worst
    if not nan:  # nothing may fire in integers where the exact top is a rounding above 0
        worst = max(worst, Fraction(max(abs(dflt - slo), abs(shi - dflt))))
    slo, shi = min(slo, dflt), max(shi, dflt)
    if not w.fits(slo, shi, False):
        raise _refuse(f"output {op.name!r}: may overflow its type")
    out = blk.declare(
        op.name, "narrow", "output", comment=f"value = stored * {float(scale)!r} + {float(offset)!r}"
    )
    with blk.b.if_(top.ex.gt(Int(0))):
        blk.b.set(out, res.ex)
    with blk.b.else_():
        blk.b.set(info, Int(2))
        if not op.no_change:
            blk.b.set(out, Int(dflt))
    away = bounds.away
    return Port(
        op.name,
        scale,
        offset,
        slo,
        shi,
        round_up(max(worst, away) * scale),
        comment=f"{float(op.low):g}..{float(op.high):g}",
        error_bound_away=round_up(away * scale),
        tie_margin=round_up(bounds.margin),
    )


def away_from_ties(op: OutputPlan, degrees: list[float], margin: float) -> bool:
    """Whether the exact rule ``degrees`` (weights applied) put output ``op`` away from ties by
    ``margin``: one set alone at the top, every other set, zero and the top set's jump levels
    more than ``margin`` from its height (the condition of ``error_bound_away_from_ties``)."""
    from fuzzyctl.ir.programs.fixed_outputs import constant

    assert op.grid is not None
    xs = tuple(Fraction(x) for x in op.grid.xs)
    heights: dict[object, tuple[float, list[float]]] = {}
    for c in op.contributions:
        w = constant(c.weight)
        if c.term is None or w == 0.0:
            continue
        left, right = profiles(term_edges(op, c.term, xs))
        peak = float(left.peak)
        a = degrees[c.rule] * w
        is_min = c.act in CLIP_BRANCH
        h = min(a, w * peak) if is_min else a * peak
        jumps = [float(j) * w for j in left.jumps + right.jumps] if is_min else []
        key = (c.term, c.act, w) if norms.is_max(op.accu or "MAX") else id(c)
        if key not in heights or heights[key][0] < h:
            heights[key] = (h, jumps)
    ranked = sorted(heights.values(), key=lambda v: -v[0])
    if not ranked or ranked[0][0] <= margin:
        return False
    top, jumps = ranked[0]
    if len(ranked) > 1 and ranked[1][0] >= top - margin:
        return False
    return all(abs(top - j) > margin for j in jumps)
