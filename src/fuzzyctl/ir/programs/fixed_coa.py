"""Mamdani outputs of the integer block by centre of area (CoA, the bisector): the point
that splits the area of the accumulated set in two halves, in fixed point, with a worst-case
error bound against the exact engine.

*Convention* (the exact reference, :func:`fuzzyctl.engine.reference.pwl.bisector`): with
``F(x)`` the area of the accumulated set left of ``x`` and ``A`` its whole area, the points
where ``F = A / 2`` form an interval (longer than a point only across a gap, where the set
is 0), and CoA is its midpoint.

*Computation.*  The output axis is cut into the pieces of the CoG form
(:mod:`fuzzyctl.ir.programs.fixed_mamdani`: grid intervals, cut where two terms' lines
cross), each piece further cut into equal *cells* (at most :data:`CELLS` over the range, as
many as :data:`~fuzzyctl.ir.programs.fixed_mamdani.MAX_CLIPS` allows), all known at
generation time.  Each cell's area is the CoG form's exact closed form of its clipped lines.
A first pass sums them into ``A``; a second pass sums them again into ``C_i`` and takes the
first cell ``i`` where ``2 C_i >= A`` (compared as ``C_i >= A - C_i``: no half is rounded).
Inside that cell the result is interpolated linearly in the area:
``x = a_i + (b_i - a_i) (A - 2 C_(i-1)) / (2 (C_i - C_(i-1)))``, the fraction first brought
below a generation-time limit by at most ``log2`` of the wide type's width halvings (five or
six ``IF`` s, no loop), then limited to the cell.  No square root is taken: under MIN
activation the set is not linear on a cell (a clipped line bends where it meets its level,
at a point known only at run time), so the quadratic of a linear density would not be the
exact solution either; the chord of ``F`` over a cell is what the second proof below uses.

*Bound.*  Let ``e`` bound the error of every computed ``C_i`` (the tracked error of the
total, :mod:`fuzzyctl.ir.builders.fixed_arith`: partial sums carry less) and
``E = 3 e / 2``.  The cell found satisfies ``F(a_i) < A/2 + E`` and ``F(b_i) >= A/2 - E``, so
it meets the *band* ``{x : |F(x) - A/2| <= E}``, an interval (``F`` is continuous and
non-decreasing) that holds the exact CoA.  The result lies in ``[floor(a_i), ceil(b_i)]``,
hence ``|x - CoA| <= W(E) + max_i (ceil(b_i) - floor(a_i))`` with ``W(E)`` the band's width.
Second proof: the interpolated point ``x_lin`` solves ``G(x) = A_computed / 2`` for ``G`` the
chord of the computed ``C_(i-1), C_i`` over the cell, within ``e`` of the chord of ``F``, which
is within ``s h^2 / 4`` of ``F`` (``s`` a bound of the set's slope on the cell, ``h`` its
width: ``F' = mu`` varies by at most ``s h`` there); so ``x_lin`` lies in the band of
``E + max s h^2 / 4`` and ``|x - CoA| <= W(E + s h^2 / 4) + 3/2 + 10 h_max / limit`` (the
ends ``floor(a_i)``, ``ceil(b_i)``: 1; the last division: 1/2; each of the halvings moves the
fraction by ``3 / (2 limit)``).  Per box of inputs the smaller of the two is taken.  The
widths are bounded by branch and bound on boxes of the input domain
(:func:`band_width`): on a box each set's level lies in an interval
(:func:`fuzzyctl.ir.builders.fixed_bound.rule_intervals`), the accumulated set is monotone in
the levels, so ``F_lo <= F <= F_hi`` and ``A_lo <= A <= A_hi`` (the exact piecewise-linear
sets of the reference at the interval ends), and the band lies in ``[inf{F_hi >= A_lo/2 - E},
sup{F_lo <= A_hi/2 + E}]``.  Boxes with the widest such interval are split first; the
largest over the remaining boxes is the bound (rigorous at any budget).

``W`` is where CoA differs from CoG: where rules can fire two sets apart with nothing
between, the exact bisector jumps across the gap as their areas pass each other, and no
finite precision follows it; the bound then holds the gap's width.  It is stated when below
:data:`USEFUL` of the range; past it the output is refused, naming the input where the band
is widest.  Where no lower bound of the area above ``E`` is proven, the output is refused as
under CoG."""

from __future__ import annotations

import heapq
import itertools
import math
from dataclasses import dataclass
from fractions import Fraction
from typing import TYPE_CHECKING

from fuzzyctl.engine.plan import OutputPlan
from fuzzyctl.engine.reference.pwl import grid_pieces
from fuzzyctl.engine.semantics.operators import CLIP_BRANCH
from fuzzyctl.escape import CodegenError
from fuzzyctl.ir.builders.fixed_arith import FX
from fuzzyctl.ir.builders.fixed_bound import input_cells, rule_intervals
from fuzzyctl.ir.nodes import Int, Var
from fuzzyctl.ir.programs.fixed_mamdani import (
    MAX_CLIPS,
    Pieces,
    accumulate,
    activated_sets,
    check_clip_work,
    clip_work,
    combine,
    crossings,
    lines_on,
    lower_area,
    output_axis,
    piece_ends,
    refuse,
    store_default,
    store_in_range,
)

if TYPE_CHECKING:
    from fuzzyctl.ir.programs.fixed_block import FixedBlock, Port

__all__ = ["CELLS", "USEFUL", "band_width", "coa_output"]

#: the most cells over the output range (fewer when the clipped-set integrals would pass
#: MAX_CLIPS): the result is interpolated inside one cell, whose width is part of the bound
CELLS = 64
#: the largest stated bound, as a fraction of the output range, that is still useful: past
#: it the output is refused (a value known only to within a third of its range says little)
USEFUL = Fraction(1, 3)
#: boxes of the input domain examined for the band's width
BUDGET = 3000

Iv = tuple[float, float]


@dataclass(frozen=True)
class Cell:
    """``[a, b]`` on the output axis (stored units) and the accumulated set's area there
    (per part, as degrees times the width)."""

    a: Fraction
    b: Fraction
    parts: list[FX]
    slope: Fraction  # a bound of the accumulated set's slope there (degree per stored unit)


def _cells(
    blk: FixedBlock, op: OutputPlan, pieces: Pieces, xi: tuple[Fraction, ...], span: Fraction
) -> list[Cell]:
    """The cells: every piece cut into equal parts no wider than ``span / n``, ``n`` the
    largest of CELLS, CELLS/2, ... whose integrals stay within MAX_CLIPS."""
    todo = []
    for j in range(len(xi) - 1):
        if xi[j + 1] <= xi[j]:
            continue
        lines = lines_on(op, pieces.sets, j)
        if not lines:
            continue
        ts = crossings(lines) if combine(op) == "envelope" else [Fraction(0), Fraction(1)]
        todo += [(j, lines, ta, tb) for ta, tb in itertools.pairwise(ts)]
    n = CELLS
    while True:
        plan = []
        for j, lines, ta, tb in todo:
            width = (xi[j + 1] - xi[j]) * (tb - ta)
            k = max(1, math.ceil(width * n / span))
            plan += [
                (j, lines, ta + (tb - ta) * Fraction(i, k), ta + (tb - ta) * Fraction(i + 1, k))
                for i in range(k)
            ]
        work = clip_work(plan)
        if work <= MAX_CLIPS or n <= 1:
            break
        n //= 2
    check_clip_work(op.name, f"{len(plan)} cells", plan)
    out = []
    for j, lines, ta, tb in plan:
        a, b = piece_ends(xi, j, ta, tb)
        # each set's line (MIN: clipped, PROD: scaled by its level) has at most its slope
        slopes = []
        for k, y0, y1 in lines:
            st = pieces.sets[k]
            top = Fraction(1) if st.is_min else st.level.hi * blk.dscale + st.level.err
            slopes.append(abs(y1 - y0) * top / (xi[j + 1] - xi[j]))
        slope = max(slopes) if combine(op) == "envelope" else sum(slopes, Fraction(0))
        out.append(Cell(a, b, [area for area, _m in pieces.piece(lines, ta, tb)], slope))
    return out


# --------------------------------------------------------------------------- the band's width


def _first_reach(pieces: list[tuple[float, float, float, float]], level: float, strict: bool) -> float | None:
    """The smallest ``x`` where the running area reaches ``level`` (``strict``: passes it),
    or None when it never does."""
    cum = 0.0
    for x0, x1, v0, v1 in pieces:
        dx = x1 - x0
        a = 0.5 * dx * (v0 + v1)
        if a > 0.0 and (cum + a > level if strict else cum + a >= level):
            r = max(0.0, (level - cum) / dx)
            k = v1 - v0
            den = v0 + math.sqrt(max(v0 * v0 + 2.0 * k * r, 0.0))
            s = 0.0 if den <= 0.0 else min(1.0, 2.0 * r / den)
            return x0 + s * dx
        cum += a
    return None


def band_width(
    blk: FixedBlock, op: OutputPlan, options: list[tuple[float, float]]
) -> tuple[float, dict[int, float]]:
    """An upper bound, over every input the block can be given, of ``min over (e, add) in
    options`` of the width of ``{x : |F(x) - A/2| <= e}`` plus ``add`` (engine units; ``e`` in
    engine units times degree), and the input where the largest was seen."""
    from fuzzyctl.ir.programs.fixed_outputs import constant, input_domain

    assert op.grid is not None and op.low is not None and op.high is not None
    plan, grid, accu = blk.plan, op.grid, op.accu or "MAX"
    weights = [constant(r.weight) for r in plan.rules]
    contribs = [
        (c.rule, c.term, constant(c.weight), c.act in CLIP_BRANCH)
        for c in op.contributions
        if c.term is not None and constant(c.weight) > 0.0
    ]
    lo_x, hi_x = min(op.low, grid.xs[0]), max(op.high, grid.xs[-1])
    margin = 1e-9 * (hi_x - lo_x)

    def pieces(levels: list[float]) -> tuple[list[tuple[float, float, float, float]], float]:
        cs = [(t, levels[r], w, m) for r, t, w, m in contribs if levels[r] > 0.0]
        ps = [(x0, x1, v0, v1) for x0, x1, v0, v1, _f in grid_pieces(grid, cs, accu) if x1 > x0]
        return ps, sum(0.5 * (x1 - x0) * (v0 + v1) for x0, x1, v0, v1 in ps)

    def width(box: dict[int, Iv]) -> float:
        ivs = rule_intervals(plan, box, weights)
        p_lo, a_lo = pieces([lo for lo, _hi in ivs])
        p_hi, a_hi = pieces([hi for _lo, hi in ivs])
        slack = 4e-12 * a_hi  # the floats' rounding and the reference's COA_TOL, far below it
        best = math.inf
        for e, add in options:
            ta, tb = 0.5 * a_lo - e - slack, 0.5 * a_hi + e + slack
            xa = _first_reach(p_hi, ta, False) if ta > 0.0 else None
            xb = _first_reach(p_lo, tb, True)
            left = lo_x if xa is None else xa - margin
            right = hi_x if xb is None else xb + margin
            best = min(best, max(0.0, right - left) + add)
        return best

    domain = input_domain(blk)
    heap: list[tuple[float, int, dict[int, Iv]]] = []
    seen, witness = 0.0, {s: a for s, (a, _b) in domain.items()}
    count = 0

    def push(bx: dict[int, Iv]) -> None:
        nonlocal seen, witness, count
        centre = {s: (a + b) / 2 for s, (a, b) in bx.items()}
        at = width({s: (c, c) for s, c in centre.items()})
        if at > seen:
            seen, witness = at, centre
        count += 1
        heapq.heappush(heap, (-width(bx), count, bx))

    for bx in input_cells(plan, domain, BUDGET // 4):
        push(bx)
    while heap and count < BUDGET:
        top, _n, bx = heap[0]
        if -top <= seen * 1.05 + margin:
            break
        heapq.heappop(heap)
        s = max(bx, key=lambda k: (bx[k][1] - bx[k][0]) / max(domain[k][1] - domain[k][0], 1e-300))
        a, b = bx[s]
        m = (a + b) / 2
        if not a < m < b:
            heapq.heappush(heap, (top, _n, bx))
            break
        push({**bx, s: (a, m)})
        push({**bx, s: (m, b)})
    return (-heap[0][0] if heap else 0.0), witness


# --------------------------------------------------------------------------- the block


def _found(
    blk: FixedBlock, cells: list[Cell], cum_stmts: list[tuple[Var, object]], v: dict[str, Var]
) -> None:
    """The second pass: the running area again, and the first cell where it reaches half."""
    b = blk.b
    for cell, (_var, ex) in zip(cells, cum_stmts, strict=True):
        b.set(v["prev"], v["cum"])
        b.set(v["cum"], ex)  # type: ignore[arg-type]
        with b.if_(v["found"].eq(Int(0)).and_(v["cum"].ge(v["area"] - v["cum"]))):
            b.set(v["found"], Int(1))
            b.set(v["xa"], Int(math.floor(cell.a)))
            b.set(v["xw"], Int(math.ceil(cell.b) - math.floor(cell.a)))
            b.set(v["num"], v["area"] - v["prev"] - v["prev"])
            b.set(v["den"], v["cum"] - v["prev"])


def _bound(
    blk: FixedBlock,
    op: OutputPlan,
    cells: list[Cell],
    area: FX,
    xi: tuple[Fraction, ...],
    axis: tuple[Fraction, Fraction, Fraction],
) -> tuple[Fraction, int]:
    """The stated bound in stored units (module docstring), and the limit of the fraction's
    halvings; refuses where the area can vanish or the bound would not be useful."""
    scale, xlo, xhi = axis
    w = blk.w
    # the band: every C_i within e of F at its end, the comparison C_i >= A - C_i exact
    e_cum = area.err * 3 / 2
    lower, witness, witness_total = lower_area(blk, op, xi)
    if Fraction(lower) <= 2 * e_cum:
        where = ", ".join(f"{blk.plan.inputs[s].name}={x:g}" for s, x in sorted(witness.items()))
        raise CodegenError(
            f"output {op.name!r}: the accumulated set's area comes down to "
            f"{witness_total * float(scale):.3g} (at {where}) and no lower bound above its rounding error "
            "was proven: integer arithmetic has "
            "no worst-case error bound (use --arith float, or write rules that cover the inputs' whole RANGE)"
        )
    cell_max = max(math.ceil(c.b) - math.floor(c.a) for c in cells)
    limit = w.limits(True)[1] // (4 * cell_max + 2)
    if limit < 1:
        raise refuse(f"output {op.name!r}: a cell of its axis is too wide for the wide type")
    # (1) the cell meets the band of E; (2) the interpolated point is in the band of E plus
    # how far F leaves its chord over one cell (slope * width^2 / 4), up to its rounding
    chord = max(c.slope * (c.b - c.a) ** 2 / 4 for c in cells)
    rounding = Fraction(3, 2) + Fraction(10 * cell_max, limit)
    options = [(e_cum * scale, cell_max * scale), ((e_cum + chord) * scale, rounding * scale)]
    band, seen_at = band_width(blk, op, [(float(e), float(add)) for e, add in options])
    err = Fraction(band) / scale
    if err > USEFUL * (xhi - xlo):
        where = ", ".join(f"{blk.plan.inputs[s].name}={x:g}" for s, x in sorted(seen_at.items()))
        raise refuse(
            f"output {op.name!r}: METHOD COA: the bisector can move by up to {float(err * scale):.3g} "
            f"({float(100 * err / (xhi - xlo)):.3g} % of the range; near {where}) for a rounding of the "
            "areas, where the accumulated set has a gap or little area: no useful error bound"
        )
    return err, limit


def coa_output(blk: FixedBlock, op: OutputPlan, rules: list[FX], info: Var) -> Port:
    """The CoA of ``op`` in the integer block, and its port with the stated bound."""
    from fuzzyctl.ir.programs.fixed_block import Port
    from fuzzyctl.ir.programs.fixed_outputs import round_up

    w = blk.w
    assert op.grid is not None and op.low is not None and op.high is not None
    nan, default, scale, offset, xi, xlo, xhi = output_axis(blk, op)
    blk.b.comment(f"output {op.name}: centre of area (bisector) of the accumulated set (ACCU {op.accu})")
    sets = activated_sets(blk, op, rules)
    if not sets:
        raise refuse(f"output {op.name!r}: concluded by no rule, it has no integer form")
    cells = _cells(blk, op, Pieces(blk, op, sets), xi, xhi - xlo)
    if not cells:
        raise refuse(f"output {op.name!r}: its sets are empty on its range")
    n = len(blk.decls)
    rows = [[(a, c.b - c.a) for a in c.parts] for c in cells]
    what = f"output {op.name!r}: the area"
    area, a_stmts = accumulate(blk, f"AREA_{n}", rows, what)
    _cum, c_stmts = accumulate(blk, f"CUM_{n}", rows, what)
    if area.lo < 0:
        raise refuse(f"{what} may be computed below 0")
    names = {
        "area": f"AREA_{n}",
        "cum": f"CUM_{n}",
        "prev": f"PREV_{n}",
        "num": f"NUM_{n}",
        "den": f"DEN_{n}",
    }
    v = {k: blk.declare(name, "wide", comment=f"{op.name}: {k}") for k, name in names.items()}
    v["xa"] = blk.declare(f"XA_{n}", "wide", comment=f"{op.name}: the cell found")
    v["xw"] = blk.declare(f"XW_{n}", "wide", comment=f"{op.name}: its width")
    v["found"] = blk.declare(f"FOUND_{n}", "narrow")
    for var, ex in a_stmts:
        blk.b.set(var, ex)  # type: ignore[arg-type]
    err, limit = _bound(blk, op, cells, area, xi, (scale, xlo, xhi))
    slo, shi = math.floor(xlo), math.ceil(xhi)
    dflt = 0 if nan else round((default - offset) / scale)
    slo, shi = min(slo, dflt), max(shi, dflt)
    xs_lo, xs_hi = min(math.floor(c.a) for c in cells), max(math.ceil(c.b) for c in cells)
    if not w.fits(slo, shi, False) or not w.fits(xs_lo, xs_hi, True):
        raise refuse(f"output {op.name!r}: may overflow its type")
    out = blk.declare(
        op.name, "narrow", "output", comment=f"value = stored * {float(scale)!r} + {float(offset)!r}"
    )
    q = blk.declare(f"Q_{len(blk.decls)}", "wide")
    blk.b.set(v["found"], Int(0))
    blk.b.set(v["cum"], Int(0))
    blk.b.set(v["num"], Int(0))
    blk.b.set(v["den"], Int(1))
    blk.b.set(v["xa"], Int(xs_lo))
    blk.b.set(v["xw"], Int(0))
    _found(blk, cells, c_stmts, v)
    with blk.b.if_(v["area"].gt(Int(0))):
        # a positive area: the cell found has 0 < num <= 2 den
        _position(blk, v, q, limit, area.hi)
        store_in_range(blk, q, out, (xlo, xhi), (slo, shi))
    with blk.b.else_():
        store_default(blk, op, out, info, dflt)
    bound = round_up(err * scale)
    return Port(op.name, scale, offset, slo, shi, bound, comment=f"{float(op.low):g}..{float(op.high):g}")


def _position(blk: FixedBlock, v: dict[str, Var], q: Var, limit: int, area_hi: int) -> None:
    """``q := xa + xw * num / (2 den)`` rounded, limited to the cell.  ``0 < num <= 2 den + 1``;
    the fraction is first brought to ``limit <= den < 2 limit`` (when above) by halvings of
    both, each moving it by at most ``3 / (2 limit)``, so that ``xw * num + den`` fits
    (``limit = wide max / (4 * widest cell + 2)``)."""
    w, b = blk.w, blk.b
    wide_max = w.limits(True)[1]
    steps = []
    k = 1
    while limit << k < max(area_hi, 1):
        steps.append(k)
        k *= 2
    steps.append(k)
    for k in reversed(steps):
        if limit << k <= wide_max:
            with b.if_(v["den"].ge(Int(limit << k))):
                b.set(v["num"], v["num"] / Int(1 << k))
                b.set(v["den"], v["den"] / Int(1 << k))
    b.set(q, v["xa"] + (v["xw"] * v["num"] + v["den"]) / (v["den"] + v["den"]))
    with b.if_(q.gt(v["xa"] + v["xw"])):
        b.set(q, v["xa"] + v["xw"])
