"""Mamdani outputs of the integer block (:mod:`fuzzyctl.ir.programs.fixed_block`): the exact
centre of gravity (CoG) of the accumulated set of piecewise-linear output terms, in fixed
point, with its worst-case error bound.

The output's terms are constant, so the grid of the output universe (cut at every term
breakpoint, :class:`~fuzzyctl.engine.plan.GridPlan`) is known at generation time, and so are
the points where two terms' lines cross; cutting there too leaves *pieces* on which every
activated line is linear and their order is fixed.  On a piece with lines
``l_1 >= l_2 >= ... >= l_m`` and clip levels ``g_k`` (MIN activation), the MAX accumulation is

    ``max_k min(g_k, l_k) = sum_i [min(P_i, l_i) - min(P_i, l_(i+1))]``,  ``P_i = max(g_1..g_i)``

(``l_(m+1) = 0``; a level-set argument), so each piece's area and first moment are sums of
integrals of one clipped line, ``min(P, y0 + (y1 - y0) t)`` on ``t`` in [0, 1], whose closed
forms need only products and divisions by generation-time constants (``tau = (P - ylo) /
(yhi - ylo)``: area ``P - (P - ylo) tau / 2``, moment ``P / 2 - (P - ylo) tau^2 / 6`` for a
rising line).  SUM accumulation adds the clipped lines; PROD activation scales a whole line.
No run-time sorting and no division but the last one.

Abscissae are the output's stored units (``xi = (u - offset) / scale``), taken from the centre
of the range for the moment.  Every step's rounding is tracked by
:mod:`fuzzyctl.ir.builders.fixed_arith`; an integral of a clipped line is 1-Lipschitz in its
level (its moment 1/2), so a level's error adds that much.  The quotient ``M / A`` differs
from the exact one by at most ``(eM + c eA) / (L - eA)`` (``c`` the largest distance from the
centre, ``L`` a lower bound of the exact area over every input, from
:func:`fuzzyctl.ir.builders.fixed_bound.weight_bounds`: a MIN-clipped set ``w min(a, T)`` holds
at least ``w a`` times the term's own area).  Where no ``L > eA`` is found, the output is
refused with an input where the area vanishes."""

from __future__ import annotations

import itertools
import math
from collections.abc import Sequence
from dataclasses import dataclass, replace
from fractions import Fraction
from typing import TYPE_CHECKING, NamedTuple

from fuzzyctl.engine.plan import OutputPlan
from fuzzyctl.engine.semantics.operators import CLIP_BRANCH
from fuzzyctl.escape import CodegenError
from fuzzyctl.ir.builders import fixed_arith as fa
from fuzzyctl.ir.builders.fixed_arith import FX
from fuzzyctl.ir.builders.fixed_bound import Group, weight_bounds
from fuzzyctl.ir.nodes import Int, Var
from fuzzyctl.ir.programs.fixed_maxima import check_maxima, maxima_output
from fuzzyctl.kinds.methods import METHODS

if TYPE_CHECKING:
    from fuzzyctl.ir.programs.fixed_block import FixedBlock, Port

__all__ = [
    "Pieces",
    "accumulate",
    "activated_sets",
    "check_mamdani",
    "combine",
    "crossings",
    "lines_on",
    "lower_area",
    "mamdani_output",
    "refuse",
]

#: the accumulations computed, and how the activated sets combine under each: their upper
#: envelope (cut where two lines cross) or their sum
_COMBINE = {"MAX": "envelope", "SUM": "sum"}
#: the most integrals of clipped sets one output may compute per cycle
MAX_CLIPS = 600
#: the activations computed (MIN clips a set, operators.CLIP_BRANCH; PROD scales it)
_ACT = ("MIN", "PROD")


def combine(op: OutputPlan) -> str:
    """How ``op``'s activated sets combine (its accumulation was checked to be computed)."""
    return _COMBINE[op.accu or "MAX"]


def refuse(what: str) -> CodegenError:
    return CodegenError(f"{what} in integer arithmetic (use --arith float)")


def check_mamdani(op: OutputPlan, weight_before_activation: bool) -> None:
    """Refuse what the integer Mamdani output does not compute, naming it."""
    name = f"output {op.name!r}"
    method = METHODS[op.method]
    if method.maximum is not None:
        check_maxima(op, weight_before_activation)
    elif not method.integrating:
        raise refuse(f"{name}: Mamdani METHOD {op.method} is not computed (COG, COA, LM, RM and MoM are)")
    if not op.exact or op.grid is None:
        raise refuse(f"{name}: terms that are not piecewise linear with constant points are not computed")
    if op.accu not in _COMBINE:
        raise refuse(f"{name}: ACCU {op.accu} is not computed on fuzzy sets (MAX and SUM are)")
    for c in op.contributions:
        if c.term is None:
            raise refuse(f"{name}: a bare degree conclusion is not computed")
        if c.act not in _ACT:
            raise refuse(f"{name}: ACT {c.act} is not computed (MIN and PROD are)")
    if weight_before_activation:
        raise refuse(f"{name}: weights applied before activation are not computed")
    for t in op.terms:
        if t.pwl is None or any(not 0.0 <= y <= 1.0 for _x, y in t.pwl):
            raise refuse(f"{name}: term {t.name!r} with degrees outside 0..1 is not computed")


@dataclass(frozen=True)
class _Set:
    """One activated set: ``min(level, w * term)`` (``is_min``) or ``level * term``."""

    term: int
    level: FX
    w: Fraction  # the factor of the term's line
    is_min: bool


def activated_sets(blk: FixedBlock, op: OutputPlan, rules: list[FX]) -> list[_Set]:
    """The activated sets; under MAX, contributions of one term, activation and weight share
    one set whose level is their largest degree (``w min(a, T)`` grows with ``a``)."""
    from fuzzyctl.ir.programs.fixed_outputs import constant

    keyed: dict[object, list[int]] = {}
    for k, c in enumerate(op.contributions):
        if constant(c.weight) == 0.0:
            continue
        key: object = (c.term, c.act, constant(c.weight)) if combine(op) == "envelope" else k
        keyed.setdefault(key, []).append(k)
    out = []
    for ks in keyed.values():
        c = op.contributions[ks[0]]
        g = rules[c.rule]
        for k in ks[1:]:
            g = blk.minmax(g, rules[op.contributions[k].rule], False)
        w = constant(c.weight)
        is_min = c.act in CLIP_BRANCH
        assert c.term is not None
        out.append(_Set(c.term, blk.weighted(g, w), Fraction(w) if is_min else Fraction(1), is_min))
    return out


# --------------------------------------------------------------------------- one clipped line


def _comb(blk: FixedBlock, parts: list[tuple[FX, int]], denom: int) -> FX:
    """``sum c_i x_i / denom`` rounded to a degree (``x_i`` degrees, ``c_i`` integers)."""
    w = blk.w
    acc: FX | None = None
    for x, c in parts:
        term = fa.mul(w, x, fa.const(w, Fraction(abs(c)), Fraction(1), True))
        if acc is None:
            acc = term if c > 0 else fa.sub(w, fa.const(w, Fraction(0), term.scale, True), term)
        else:
            acc = fa.add(w, acc, term) if c > 0 else fa.sub(w, acc, term)
    assert acc is not None
    # the same stored integer read as the value / denom, then rounded back to a degree
    view = FX(acc.ex, acc.lo, acc.hi, acc.scale / denom, acc.err / denom, acc.wide)
    return fa.narrow(w, fa.rdiv(w, view, denom), "an integral of a clipped set")


def _half(blk: FixedBlock, x: FX) -> FX:
    """``x / 2`` rounded to a degree."""
    wide = fa.widen(x)
    view = FX(wide.ex, wide.lo, wide.hi, x.scale / 2, x.err / 2, True)
    return fa.narrow(blk.w, fa.rdiv(blk.w, view, 2), "a moment")


def _tau(blk: FixedBlock, x: FX, span: Fraction) -> FX:
    """``x / span`` as a degree (``x`` in ``[0, span]``)."""
    w = blk.w
    for s in range(2 * blk.arith.bits, -1, -1):
        fine = Fraction(1, 1 << s)
        try:
            prod = fa.mul(w, x, fa.const(w, 1 / span, fine, True, "a reciprocal slope"))
            return blk.limited(fa.rdiv(w, prod, 1 << s), 0, blk.D)
        except CodegenError:
            continue
    raise refuse("a clipped output line: its slope does not fit the wide type")


def _clip(blk: FixedBlock, level: FX, y0: Fraction, y1: Fraction) -> tuple[FX, FX]:
    """``(area, moment)`` of ``min(level, y0 + (y1 - y0) t)`` over ``t`` in [0, 1] (moment:
    of ``t``), as degrees.  Computed at the stored level, whose error is added at the end
    (the area is 1-Lipschitz in the level, the moment 1/2-Lipschitz)."""
    w, D = blk.w, blk.D
    p = replace(level, err=Fraction(0))
    ylo, yhi = min(y0, y1), max(y0, y1)
    span = yhi - ylo
    flat = Fraction(0)
    if span * D < 2:  # flatter than two units of a degree: taken as flat at its mean
        flat = span / 2
        ylo = yhi = (y0 + y1) / 2
        span = Fraction(0)
    if p.hi * blk.dscale <= ylo:  # never above the line: the level itself
        area = p
        moment = _half(blk, p)
    elif span == 0:  # a flat line
        area = p if p.hi * blk.dscale <= yhi else blk.minmax(p, fa.const(w, yhi, blk.dscale), True)
        moment = _half(blk, area)
    elif p.lo * blk.dscale >= yhi:  # never below it: the line itself
        area = fa.const(w, (y0 + y1) / 2, blk.dscale)
        moment = fa.const(w, (y0 + 2 * y1) / 6, blk.dscale)
    else:
        gc = p if p.hi * blk.dscale <= yhi else blk.minmax(p, fa.const(w, yhi, blk.dscale), True)
        x = blk.limited(fa.sub(w, gc, fa.const(w, ylo, blk.dscale)), 0, math.ceil(span * D))
        tau = _tau(blk, x, span)
        xt = blk.temp(fa.narrow(w, fa.rdiv(w, fa.mul(w, x, tau), D), "a clipped area"))
        xtt = fa.narrow(w, fa.rdiv(w, fa.mul(w, xt, tau), D), "a clipped moment")
        area = _comb(blk, [(gc, 2), (xt, -1)], 2)
        if y1 >= y0:
            moment = _comb(blk, [(gc, 3), (xtt, -1)], 6)
        else:
            moment = _comb(blk, [(gc, 3), (xt, -3), (xtt, 1)], 6)
    top = max(y0, y1)
    area = blk.limited(area, 0, math.ceil(top * D)) if area.lo < 0 or area.hi * blk.dscale > top else area
    area = replace(area, err=area.err + level.err + flat)
    moment = replace(moment, err=moment.err + level.err / 2 + flat / 2)
    return area, moment


# --------------------------------------------------------------------------- the pieces


@dataclass(frozen=True)
class _Piece:
    """A piece ``[a, b]`` of the output axis in stored units, with the area and moment (of
    ``t`` in [0, 1] across it) of the accumulated set, as degrees: one pair, or under SUM one
    pair per activated set (their sum may pass 1)."""

    a: Fraction
    b: Fraction
    parts: list[tuple[FX, FX]]


def lines_on(op: OutputPlan, sets: list[_Set], j: int) -> list[tuple[int, Fraction, Fraction]]:
    """``(set, value at the left end, at the right end)`` of the sets nonzero on interval ``j``."""
    assert op.grid is not None
    g = op.grid
    out = []
    for k, s in enumerate(sets):
        if s.term in g.active[j]:
            y0, y1 = Fraction(g.left[s.term][j]), Fraction(g.right[s.term][j])
            if y0 or y1:
                out.append((k, s.w * y0, s.w * y1))
    return out


def crossings(lines: list[tuple[int, Fraction, Fraction]]) -> list[Fraction]:
    """0, 1 and the points (as fractions of the interval) where two lines cross."""
    ts = {Fraction(0), Fraction(1)}
    for i, (_k, a0, a1) in enumerate(lines):
        for _l, b0, b1 in lines[i + 1 :]:
            d0, d1 = a0 - b0, a1 - b1
            if d0 * d1 < 0:
                ts.add(d0 / (d0 - d1))
    return sorted(ts)


class Pieces:
    def __init__(self, blk: FixedBlock, op: OutputPlan, sets: list[_Set]) -> None:
        self.blk, self.op, self.sets = blk, op, sets
        self.prefix: dict[frozenset[int], FX] = {}

    def level_max(self, ks: list[int]) -> FX:
        key = frozenset(ks)
        if key not in self.prefix:
            if len(ks) == 1:
                self.prefix[key] = self.sets[ks[0]].level
            else:
                self.prefix[key] = self.blk.minmax(self.level_max(ks[:-1]), self.sets[ks[-1]].level, False)
        return self.prefix[key]

    def piece(
        self, lines: list[tuple[int, Fraction, Fraction]], ta: Fraction, tb: Fraction
    ) -> list[tuple[FX, FX]]:
        """Area and moment on the part ``[ta, tb]`` of an interval where no two lines cross."""
        blk, w = self.blk, self.blk.w
        ends = [(k, y0 + (y1 - y0) * ta, y0 + (y1 - y0) * tb) for k, y0, y1 in lines]
        if combine(self.op) == "sum" or len(ends) == 1:
            out = []
            for k, y0, y1 in ends:
                s = self.sets[k]
                out.append(_clip(blk, s.level, y0, y1) if s.is_min else _scaled(blk, s.level, y0, y1))
            return out
        if not all(self.sets[k].is_min for k, _a, _b in ends):
            raise refuse(
                f"output {self.op.name!r}: PROD activation of sets that overlap under ACCU MAX "
                "is not computed"
            )
        ends.sort(key=lambda e: -(e[1] + e[2]))
        parts: list[tuple[FX, FX, int]] = []
        for i, (_k, y0, y1) in enumerate(ends):
            p = self.level_max([k for k, _a, _b in ends[: i + 1]])
            parts.append((*_clip(blk, p, y0, y1), 1))
            if i + 1 < len(ends):
                _n, z0, z1 = ends[i + 1]
                parts.append((*_clip(blk, p, z0, z1), -1))
        top = max(max(y0, y1) for _k, y0, y1 in ends)
        area, moment = parts[0][0], parts[0][1]
        for a, m, sign in parts[1:]:
            area = fa.add(w, area, a) if sign > 0 else fa.sub(w, area, a)
            moment = fa.add(w, moment, m) if sign > 0 else fa.sub(w, moment, m)
        # the exact values lie in [0, top] and [0, top / 2]
        area = blk.limited(area, 0, math.ceil(top * blk.D))
        moment = blk.limited(moment, 0, math.ceil(top * blk.D / 2))
        return [(area, moment)]

    def all(self, xi: tuple[Fraction, ...]) -> list[_Piece]:
        todo = []
        for j in range(len(xi) - 1):
            if xi[j + 1] <= xi[j]:
                continue
            lines = lines_on(self.op, self.sets, j)
            if not lines:
                continue
            ts = crossings(lines) if combine(self.op) == "envelope" else [Fraction(0), Fraction(1)]
            todo += [(j, lines, ta, tb) for ta, tb in itertools.pairwise(ts)]
        # the work grows with the pieces times the sets over each (distinct weights make distinct
        # sets): past a limit the block would be too long for a PLC cycle and for its compiler
        check_clip_work(self.op.name, f"{len(self.sets)} activated sets over {len(todo)} pieces", todo)
        out = []
        for j, lines, ta, tb in todo:
            a, b = piece_ends(xi, j, ta, tb)
            out.append(_Piece(a, b, self.piece(lines, ta, tb)))
        return out


def _scaled(blk: FixedBlock, level: FX, y0: Fraction, y1: Fraction) -> tuple[FX, FX]:
    """``(area, moment)`` of ``level * (y0 + (y1 - y0) t)`` (PROD activation)."""
    w = blk.w
    out = []
    for c in ((y0 + y1) / 2, (y0 + 2 * y1) / 6):
        if c == 0:
            out.append(fa.const(w, Fraction(0), blk.dscale))
            continue
        for s in range(2 * blk.arith.bits, -1, -1):
            try:
                prod = fa.mul(w, level, fa.const(w, c, blk.dscale / (1 << s), True))
                out.append(fa.narrow(w, fa.rdiv(w, prod, blk.D << s), "a scaled set's integral"))
                break
            except CodegenError:
                continue
        else:
            raise refuse(f"output: a PROD-activated set's integral does not fit ({float(c):g})")
    return out[0], out[1]


# --------------------------------------------------------------------------- sums and quotient


def accumulate(
    blk: FixedBlock, name: str, terms: list[list[tuple[FX, Fraction]]], what: str
) -> tuple[FX, list[tuple[Var, object]]]:
    """``name := sum over pieces of sum x * c`` (``x`` degrees, ``c`` constants), the constants
    on the finest power-of-two scale whose every product and partial sum fits the wide type."""
    w = blk.w
    wide_max = w.limits(True)[1]
    total = sum((abs(c) * x.hi for row in terms for x, c in row), Fraction(0)) * blk.dscale
    e = math.floor(math.log2(max(total / (wide_max * blk.dscale), Fraction(1, 1 << 200)))) if total else 0
    var = Var(name)
    for exp in range(e, e + 12):
        sigma = Fraction(2) ** exp
        try:
            stmts: list[tuple[Var, object]] = []
            acc: FX | None = None
            for row in terms:
                piece: FX | None = None
                for x, c in row:
                    if c == 0:
                        continue
                    p = fa.mul(w, x, fa.const(w, c, sigma, True, what))
                    piece = p if piece is None else fa.add(w, piece, p, what)
                if piece is None:
                    continue
                acc = piece if acc is None else fa.add(w, acc, piece, what)
                stmts.append((var, acc.ex))
                acc = fa.var(name, acc)
            if acc is None:
                raise refuse(f"{what}: the output has no set")
            return acc, stmts
        except CodegenError:
            continue
    raise refuse(f"{what} does not fit the wide type")


def lower_area(
    blk: FixedBlock, op: OutputPlan, xi: tuple[Fraction, ...]
) -> tuple[float, dict[int, float], float]:
    """A lower bound of the exact area (in stored output units times degree) over every
    input: each contribution's ``w a`` times its term's own area (MAX: the largest of them,
    SUM: their sum)."""
    from fuzzyctl.ir.programs.fixed_outputs import constant, input_domain

    assert op.grid is not None
    g = op.grid
    own = []
    for t in range(len(op.terms)):
        own.append(
            sum(
                (
                    (xi[j + 1] - xi[j]) * (Fraction(g.left[t][j]) + Fraction(g.right[t][j])) / 2
                    for j in range(len(xi) - 1)
                ),
                Fraction(0),
            )
        )
    items = tuple(
        (c.rule, constant(c.weight) * float(own[c.term]))
        for c in op.contributions
        if c.term is not None and constant(c.weight) > 0
    )
    groups: list[Group] = [(op.accu or "MAX", items)]
    plan = blk.plan
    weights = [constant(r.weight) for r in plan.rules]
    bounds = weight_bounds(
        plan,
        groups,
        weights,
        input_domain(blk),
        budget=max(300, min(2000, 200_000 // len(plan.rules))),
        enough=0.75,
    )
    return bounds.low, bounds.witness, bounds.witness_total


def clip_work(todo: Sequence[tuple[int, Sequence[object], Fraction, Fraction]]) -> int:
    """Clipped-set integrals per cycle of pieces ``(interval, lines, ta, tb)``: a MAX
    envelope of ``m`` lines takes ``2 m - 1``."""
    return sum(2 * len(lines) - 1 for _j, lines, _a, _b in todo)


def check_clip_work(
    name: str, what: str, todo: Sequence[tuple[int, Sequence[object], Fraction, Fraction]]
) -> None:
    """Refuse an output whose pieces need more than :data:`MAX_CLIPS` integrals per cycle."""
    work = clip_work(todo)
    if work > MAX_CLIPS:
        raise refuse(
            f"output {name!r}: {what} need {work} clipped-set integrals per cycle (more than {MAX_CLIPS})"
        )


def piece_ends(xi: tuple[Fraction, ...], j: int, ta: Fraction, tb: Fraction) -> tuple[Fraction, Fraction]:
    """The stored abscissae of the fractions ``ta`` and ``tb`` of grid interval ``j``."""
    return xi[j] + (xi[j + 1] - xi[j]) * ta, xi[j] + (xi[j + 1] - xi[j]) * tb


def store_in_range(
    blk: FixedBlock, q: Var, out: Var, stored: tuple[Fraction, Fraction], limits: tuple[int, int]
) -> None:
    """``out := q`` limited to the output's range in stored units (the exact value lies in it:
    limiting only brings the result closer), narrowed to the output's type (``limits``)."""
    xlo, xhi = stored
    with blk.b.if_(q.lt(Int(math.floor(xlo)))):
        blk.b.set(q, Int(math.floor(xlo)))
    with blk.b.elif_(q.gt(Int(math.ceil(xhi)))):
        blk.b.set(q, Int(math.ceil(xhi)))
    fx = FX(q, limits[0], limits[1], Fraction(1), Fraction(0), True)
    blk.b.set(out, fa.narrow(blk.w, fx, "the output").ex)


def store_default(blk: FixedBlock, op: OutputPlan, out: Var, info: Var, default: int) -> None:
    """No rule fired: INFO 2, and the DEFAULT unless the output keeps its value (NC)."""
    blk.b.set(info, Int(2))
    if not op.no_change:
        blk.b.set(out, Int(default))


class OutputAxis(NamedTuple):
    """A Mamdani output's stored units: NaN DEFAULT or not, the DEFAULT (0 for NaN), the
    scaling (``value = stored * scale + offset``, from RANGE and DEFAULT), the grid and the
    range in stored units."""

    nan: bool
    default: Fraction
    scale: Fraction
    offset: Fraction
    xi: tuple[Fraction, ...]
    xlo: Fraction
    xhi: Fraction


def output_axis(blk: FixedBlock, op: OutputPlan) -> OutputAxis:
    """The stored units of ``op`` (CoG, CoA and the maxima scale alike)."""
    from fuzzyctl.ir.programs.fixed_block import output_scale

    assert op.grid is not None and op.low is not None and op.high is not None
    nan = op.default is not None and not math.isfinite(op.default)
    default = Fraction(0.0 if op.default is None or nan else op.default)
    lo, hi = Fraction(op.low), Fraction(op.high)
    if not nan:
        lo, hi = min(lo, default), max(hi, default)
    scale, offset = output_scale(lo, hi, blk.arith, blk.int_output, False)
    xi = tuple((Fraction(x) - offset) / scale for x in op.grid.xs)
    xlo, xhi = (Fraction(op.low) - offset) / scale, (Fraction(op.high) - offset) / scale
    return OutputAxis(nan, default, scale, offset, xi, xlo, xhi)


def mamdani_output(blk: FixedBlock, op: OutputPlan, rules: list[FX], info: Var) -> Port:
    from fuzzyctl.ir.programs.fixed_block import Port

    if METHODS[op.method].maximum is not None:
        return maxima_output(blk, op, rules, info)
    w = blk.w
    assert op.grid is not None and op.low is not None and op.high is not None
    nan, default, scale, offset, xi, xlo, xhi = output_axis(blk, op)
    centre = round((xlo + xhi) / 2)
    blk.b.comment(f"output {op.name}: centre of gravity of the accumulated set (ACCU {op.accu})")
    sets = activated_sets(blk, op, rules)
    if not sets:
        raise refuse(f"output {op.name!r}: concluded by no rule, it has no integer form")
    pieces = Pieces(blk, op, sets).all(xi)
    if not pieces:
        raise refuse(f"output {op.name!r}: its sets are empty on its range")
    low_area, witness, witness_total = lower_area(blk, op, xi)
    n = len(blk.decls)
    area, a_stmts = accumulate(
        blk,
        f"AREA_{n}",
        [[(a, p.b - p.a) for a, _m in p.parts] for p in pieces],
        f"output {op.name!r}: the area",
    )
    moment, m_stmts = accumulate(
        blk,
        f"MOMENT_{n}",
        [
            [x for a, m in p.parts for x in ((a, (p.b - p.a) * (p.a - centre)), (m, (p.b - p.a) ** 2))]
            for p in pieces
        ],
        f"output {op.name!r}: the moment",
    )
    blk.declare(f"AREA_{n}", "wide", comment=f"{op.name}: area of the accumulated set")
    blk.declare(f"MOMENT_{n}", "wide", comment=f"{op.name}: its moment about {centre}")
    for v, e in a_stmts + m_stmts:
        blk.b.set(v, e)  # type: ignore[arg-type]
    # one scale for both: the finer one is rounded to the coarser
    if area.scale < moment.scale:
        k = moment.scale / area.scale
        assert k.denominator == 1
        area = blk.temp(fa.rdiv(w, area, int(k)), f"{op.name}: area on the moment's scale")
    elif moment.scale < area.scale:
        k = area.scale / moment.scale
        assert k.denominator == 1
        moment = blk.temp(fa.rdiv(w, moment, int(k)), f"{op.name}: moment on the area's scale")
    e_area, e_moment = area.err, moment.err
    lower = Fraction(low_area)
    if lower <= e_area:
        where = ", ".join(f"{blk.plan.inputs[s].name}={v:g}" for s, v in sorted(witness.items()))
        raise CodegenError(
            f"output {op.name!r}: the accumulated set's area comes down to "
            f"{witness_total * float(scale):.3g} "
            f"(at {where}) and no lower bound above its rounding error was proven: integer arithmetic has "
            "no worst-case error bound (use --arith float, or write rules that cover the inputs' whole RANGE)"
        )
    reach = max(abs(xlo - centre), abs(xhi - centre))
    d_min = max(1, math.floor((lower - e_area) / area.scale))
    lsb = Fraction(1, 2) + Fraction(1, 2) / d_min
    err = (e_moment + reach * e_area) / (lower - e_area) + lsb
    slo, shi = math.floor(xlo), math.ceil(xhi)
    dflt = 0 if nan else round((default - offset) / scale)
    slo, shi = min(slo, dflt), max(shi, dflt)
    if not w.fits(slo, shi, False):
        raise refuse(f"output {op.name!r}: may overflow its type")
    if not w.fits(moment.lo - area.hi, moment.hi + area.hi, True):
        raise refuse(f"output {op.name!r}: the rounded quotient does not fit the wide type")
    out = blk.declare(
        op.name, "narrow", "output", comment=f"value = stored * {float(scale)!r} + {float(offset)!r}"
    )
    q = blk.declare(f"Q_{len(blk.decls)}", "wide")
    num, den = moment.ex, area.ex
    with blk.b.if_(den.gt(Int(0))):
        with blk.b.if_(num.ge(Int(0))):
            blk.b.set(q, (num + den / Int(2)) / den)
        with blk.b.else_():
            blk.b.set(q, -((den / Int(2) - num) / den))
        blk.b.set(q, q + Int(centre))
        store_in_range(blk, q, out, (xlo, xhi), (slo, shi))
    with blk.b.else_():
        store_default(blk, op, out, info, dflt)
    from fuzzyctl.ir.programs.fixed_outputs import round_up

    bound = round_up(err * scale)
    return Port(op.name, scale, offset, slo, shi, bound, comment=f"{float(op.low):g}..{float(op.high):g}")
