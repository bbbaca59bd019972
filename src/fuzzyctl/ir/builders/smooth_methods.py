"""CoA, LM, RM and MoM of a smooth output (sets that are not piecewise linear) in the IR: the
IR twins of :func:`fuzzyctl.engine.reference.quadrature.bisector` and
:func:`~fuzzyctl.engine.reference.quadrature.maxima`, on the pieces and panels of
:mod:`fuzzyctl.ir.builders.quadrature` (the smooth CoG's), so that the native evaluator runs
every method in C and the PLC block (ir/programs/plc_block.py) in ST, C and PLCopen, with
bounded work per cycle (every search has a step limit; the caps set ``capped``, INFO 16#04).

* CoA: the panels are integrated once for the total area, then visited again (the same
  panels in the same order: the acceptance test is deterministic) to find the panel where
  the cumulated area reaches half, from the left and from the right, with the reference's
  tolerance (``max(COA_TOL, 10 quad_rtol)`` of the area: a whole panel within it answers
  its end); inside the panel the point is found by bisection on a 15-point Kronrod estimate
  of the area from the panel's start, as the reference does.
* LM, RM, MoM: the first visit gives the area (fired) and the largest value at the
  nodes of the accepted panels, their ends and the ends of every piece (an isolated point
  where a drastic sum reaches 1 lies between two pieces too narrow to integrate); the
  second walks those nodes in increasing x with a window of three: a node with both
  neighbours lower and within 1e-6 of the top is a smooth peak refined by golden-section
  search (at most :data:`PEAKS` of them are searched and kept: more set ``capped``), a run
  of nodes at the top (to :data:`PLATEAU_TOL`) is a
  plateau whose edges are found by bisection.  The maximum is the plateaus when the top is
  reached on one (MoM: their centroid), else the peaks within 1e-12 of the height (MoM:
  their mean).

The nodes differ from the reference's (its panels are chosen by its own acceptance test),
so a smooth peak found by golden-section search agrees to what a flat maximum allows in
double precision (about 1e-8 of the range: the set is flat to sqrt(eps) around a smooth
maximum); plateau edges and the CoA agree to 1e-9 of the range (tests/codegen/
test_native_methods.py).
"""

from __future__ import annotations

import math

from fuzzyctl.engine.plan import OutputPlan
from fuzzyctl.engine.reference.pwl import COA_TOL
from fuzzyctl.engine.reference.quadrature import PLATEAU_TOL
from fuzzyctl.ir.builders import quadrature as Q
from fuzzyctl.ir.nodes import Ex, Var, not_
from fuzzyctl.ir.state import Gen
from fuzzyctl.kinds.methods import METHODS

PEAKS = 16  # smooth peaks within 1e-6 of the top searched at most (more: the first ones, capped)
GOLDEN = 80  # golden-section steps at most (the reference's)
HALVINGS = 100  # bisection steps at most (the reference's; they stop at the last bit)
PEAK_NEAR = 1e-6  # a node this close below the top may hide a higher smooth peak
SAME_TOP = 1e-12  # peaks and plateaus this close to the height reach it


def smooth_method(
    g: Gen, op: OutputPlan, sets: list[Q.SmoothSet], cal: Q.Calibration, rtol: float
) -> tuple[Var, Var, Var]:
    """(value, fired, capped) of ``op`` by its method from its activated ``sets``; ``rtol`` is
    the plan's quadrature tolerance (the CoA's half-area tolerance derives from it).
    ``capped`` is TRUE when a cap on the work was reached: a panel accepted short of the
    quadrature's tolerance, or (LM, RM, MoM) a smooth peak within 1e-6 of the top left
    unsearched beyond :data:`PEAKS` (the PLC block's INFO 16#04)."""
    entry = METHODS[op.method]
    if entry.integrating and not entry.bisects:
        return Q.smooth_cog(g, op, sets, cal)
    pts, n = Q.smooth_pieces(g, op, sets, cal)
    capped = g.let(False, "QCAPPED", "BOOL")
    if entry.bisects:
        value, fired = _bisector(g, op, sets, pts, n, rtol, capped)
    else:
        assert entry.maximum is not None
        value, fired = _maxima(g, op, sets, pts, n, entry.maximum, capped)
    return value, fired, capped


def method_bound(op: OutputPlan, rtol: float) -> list[str]:
    """The error the generated CoA, LM, RM or MoM of a smooth ``op`` aims at, as header lines
    (each within a comment's length; checked against the reference interpreter by
    tests/codegen/test_smooth_plc.py)."""
    entry = METHODS[op.method]
    panels = (
        f"panels accepted when Kronrod and Gauss agree to {Q.QTOL:.0e} x width ({Q.QTOL_REAL:.0e} "
        f"in a REAL build)"
    )
    caps = (
        f"unless INFO = 16#04: more than {Q.QCAP} panels of 15 points per evaluation (or "
        f"{Q.STACK - 2} nested halvings of one piece) were needed"
    )
    if entry.bisects:
        tol = max(COA_TOL, 10.0 * rtol)
        return [
            panels,
            f"the bisector is in the panel where the area from either side reaches half to "
            f"{tol:.0e} x area (a panel within it answers its end), then found by bisection to the "
            f"last bit ({HALVINGS} steps at most) on a 15-point Kronrod estimate: |CoA error| <= "
            f"({tol:.0e} x area + the panels' error) / (the set's height at the bisector)",
            caps,
        ]
    return [
        f"{panels}; their 17 nodes (ends included) are searched for the maximum",
        f"values within {PLATEAU_TOL:.0e} relative of the top count as the top: a plateau's "
        f"edges are found by bisection to the last bit ({HALVINGS} steps at most), exact",
        f"a node within {PEAK_NEAR:.0e} of the top with both neighbours lower is a smooth peak "
        f"found by golden-section search ({GOLDEN} steps at most, {PEAKS} peaks at most), peaks "
        f"within {SAME_TOP:.0e} of the height reach it: a smooth peak is placed only within the "
        f"stretch where the set is that close to its top (about (1e-12)^(1/k) of the term's "
        f"width for a maximum of order k)",
        f"{caps}, or more than {PEAKS} peaks near the top were found",
    ]


# --------------------------------------------------------------------------- CoA


def _bisector(
    g: Gen, op: OutputPlan, sets: list[Q.SmoothSet], pts: Var, n: Var, rtol: float, capped: Var
) -> tuple[Var, Var]:
    b = g.b
    accu = op.accu or "MAX"
    total = g.let(0.0, "QA")
    half, tol, cum = g.let(0.0, "HALF"), g.let(0.0, "CTOL"), g.let(0.0, "CUM")
    found = g.let(False, "FOUND", "BOOL")
    lu, ld, lk, lb = (g.let(0.0, h) for h in ("LU", "LD", "LK", "LB"))
    ru, rd, rk, rb = (g.let(0.0, h) for h in ("RU", "RD", "RK", "RB"))
    bad = g.let(False, "QBAD", "BOOL") if Q.has_function_terms(op, sets) else None
    # two visits of the same panels (one copy of the set's code): the total area, then the
    # panels where the area from the left and from the right reach half
    ps = g.counter("PASS")
    with b.for_(ps, 0, 1) as pv:
        second = pv.eq(1)
        with b.if_(pv.eq(0).or_(total.gt(0.0))):

            def visit(u: Var, d: Var, ka: Var, km: Var, ys: Var | None) -> None:
                k = g.let(ka * d, "K")
                with b.if_(not_(second)):
                    b.set(total, total + k)
                with b.elif_(k.gt(0.0)):
                    # the first panel where the area from the left reaches half (less tol) ...
                    with b.if_(not_(found).and_((cum + k).ge(half - tol))):
                        for var, val in ((lu, u), (ld, d), (lk, k), (lb, cum), (found, True)):
                            b.set(var, val)
                    # ... and the last where the area from the right does
                    with b.if_((total - cum).ge(half - tol)):
                        for var, val in ((ru, u), (rd, d), (rk, k), (rb, cum)):
                            b.set(var, val)
                b.set(cum, cum + k)

            Q.panels(g, op, sets, accu, pts, n, capped, visit, bad=bad)
            b.set(half, 0.5 * total)
            b.set(tol, max(COA_TOL, 10.0 * rtol) * total)
            b.set(cum, 0.0)
    fired = g.let(total.gt(0.0), "FIRED", "BOOL")
    value = g.let(0.0, "Y")
    with b.if_(fired):
        # the point in the left and the right panel: its end when the panel's area is
        # within tol of what is missing, else where the area from its start reaches it
        after = g.let(total - rb - rk, "AFTER")
        targets = (half - lb, rk - (half - after))
        whole = (targets[0].ge(lk - tol), (half - after).ge(rk - tol))
        ends = (lu + ld, ru)
        same = g.let(ru.eq(lu).and_(rd.eq(ld)).and_(targets[1].eq(targets[0])), "SAME", "BOOL")
        side = g.array("CSIDE", "REAL", 2)
        j = g.counter("SIDE")
        # one search serves both sides when they end in one panel at the same area (usual)
        with b.for_(j, 0, 1) as jv:
            first = jv.eq(0)
            a, d, tgt, end = g.let(ru, "SA"), g.let(rd, "SD"), g.let(targets[1], "ST"), g.let(ends[1], "SE")
            with b.if_(first):
                for var, val in ((a, lu), (d, ld), (tgt, targets[0]), (end, ends[0])):
                    b.set(var, val)
            with b.if_(first.and_(whole[0]).or_(not_(first).and_(whole[1]))):
                b.set(side[jv], end)
            with b.elif_(not_(first).and_(same).and_(not_(whole[0]))):
                b.set(side[jv], side[0])
            with b.else_():
                b.set(side[jv], _solve(g, op, sets, a, d, tgt))
        b.set(value, 0.5 * (side[0] + side[1]))
    if bad is not None:
        Q.undefined(g, bad, value, fired)
    return value, fired


def _partial(g: Gen, op: OutputPlan, sets: list[Q.SmoothSet], a: Ex, x: Ex) -> Var:
    """The 15-point Kronrod estimate of the set's area over ``[a, x]``
    (``quadrature.partial``)."""
    from fuzzyctl.engine.reference.quadrature import WK as GKK

    b = g.b
    xs = Q.gk_nodes(g)
    wk = g.declare(
        g.fresh("GKK", "GKK"), "REAL", "const", 15, tuple(0.5 * float(v) for v in GKK), "Kronrod weights"
    )
    d = g.let(x - a, "PD")
    s = g.let(0.0, "PS")
    k = g.counter("PK")
    with b.for_(k, 0, 14) as kv:
        y, _code = Q.set_at(g, op, sets, g.let(a + xs[kv] * d, "PX"), op.accu or "MAX")
        b.set(s, s + wk[kv] * y)
    return g.let(s * d, "PA")


def _solve(g: Gen, op: OutputPlan, sets: list[Q.SmoothSet], a: Var, d: Var, target: Ex) -> Var:
    """The x in ``[a, a + d]`` where the area from ``a`` reaches ``target`` (``_solve`` of the
    reference: bisection to the last bit)."""
    b = g.b
    lo, hi = g.let(a, "SLO"), g.let(a + d, "SHI")
    tgt = g.let(target, "STG")
    it = g.let(0, "SIT", "INT")
    go = g.let(True, "SGO", "BOOL")
    with b.while_(go, bound=HALVINGS + 1):
        mid = g.let(0.5 * (lo + hi), "SMID")
        with b.if_(mid.eq(lo).or_(mid.eq(hi)).or_(it.ge(HALVINGS))):
            b.set(go, False)
        with b.else_():
            with b.if_(_partial(g, op, sets, a, mid).lt(tgt)):
                b.set(lo, mid)
            with b.else_():
                b.set(hi, mid)
            b.set(it, it + 1)
    return g.let(0.5 * (lo + hi), "SX")


# --------------------------------------------------------------------------- LM, RM, MoM


def _maxima(
    g: Gen, op: OutputPlan, sets: list[Q.SmoothSet], pts: Var, n: Var, which: str, capped: Var
) -> tuple[Var, Var]:
    b = g.b
    accu = op.accu or "MAX"
    area = g.let(0.0, "QA")
    top = g.let(0.0, "TOP")  # a set below 0 (a function term) has no maximum that fires
    bad = g.let(False, "QBAD", "BOOL") if Q.has_function_terms(op, sets) else None
    count, last = g.let(0, "NACC", "DINT"), g.let(0, "LACC", "DINT")
    w = _Window(g, op, sets, top, capped)
    xs = Q.gk_nodes(g, ends=True)
    # two visits of the same panels (one copy of the set's code): the area, the top value and
    # the number of panels, then the nodes in increasing x through the window
    ps = g.counter("PASS")
    with b.for_(ps, 0, 1) as pv:
        second = pv.eq(1)
        with b.if_(pv.eq(0).or_(area.gt(0.0).and_(top.gt(0.0)))):

            def visit(u: Var, d: Var, ka: Var, km: Var, ys: Var | None) -> None:
                assert ys is not None
                k = g.counter("QN")
                with b.if_(second):
                    b.set(count, count + 1)
                    with b.for_(k, 0, Q.NODES_WITH_ENDS - 1) as kv:
                        w.push(g.let(u + xs[kv] * d, "XN"), ys[kv])
                    w.drain(count.eq(last))
                with b.else_():
                    b.set(area, area + ka * d)
                    b.set(last, last + 1)
                    with b.for_(k, 0, Q.NODES_WITH_ENDS - 1) as kv:
                        b.set(top, g.max_(top, ys[kv], "TOP"))

            Q.panels(g, op, sets, accu, pts, n, capped, visit, keep_nodes=True, bad=bad)
    value = g.let(0.0, "Y")
    fired = g.let(area.gt(0.0).and_(top.gt(0.0)), "FIRED", "BOOL")
    with b.if_(fired):
        b.set(value, w.result(which))
    if bad is not None:
        Q.undefined(g, bad, value, fired)
    return value, fired


def _at(g: Gen, op: OutputPlan, sets: list[Q.SmoothSet], x: Ex) -> Var:
    """The accumulated set at ``x``."""
    y, _code = Q.set_at(g, op, sets, x if isinstance(x, Var) else g.let(x, "XW"), op.accu or "MAX")
    return y


class _Window:
    """The nodes in increasing x, three at a time (``quadrature.maxima`` streamed): node b is
    judged when the next one arrives, or the end.  Nodes are queued per panel and judged in
    one loop, so that the searches below are written once."""

    def __init__(self, g: Gen, op: OutputPlan, sets: list[Q.SmoothSet], top: Var, capped: Var) -> None:
        self.g, self.op, self.sets, self.top, self.capped = g, op, sets, top, capped
        let = g.let
        self.qx = g.array("WQX", "REAL", Q.NODES_WITH_ENDS)
        self.qy = g.array("WQY", "REAL", Q.NODES_WITH_ENDS)
        self.qn = let(0, "WQN", "INT")
        self.lastx, self.any = let(0.0, "WLX"), let(False, "WANY", "BOOL")
        self.seen = let(0, "WN", "INT")  # nodes seen (2 means: at least two)
        self.xa, self.ya, self.xb, self.yb = (let(0.0, h) for h in ("WXA", "WYA", "WXB", "WYB"))
        # the current run of nodes at the top: its first node and the one before
        self.run = let(0, "RUN", "INT")
        self.rx, self.rprev, self.rhas = let(0.0, "RX"), let(0.0, "RXP"), let(False, "RHAS", "BOOL")
        # plateaus: how many, first left edge, last right edge, total length and moment
        self.nrun = let(0, "NRUN", "INT")
        self.pl, self.pr, self.plen, self.pmom = (let(0.0, h) for h in ("PL", "PR", "PLEN", "PMOM"))
        self.kx, self.kv = g.array("PKX", "REAL", PEAKS), g.array("PKV", "REAL", PEAKS)
        self.npk = let(0, "NPK", "INT")

    def push(self, x: Ex, y: Ex) -> None:
        """Queue a node (equal x: one node, as ``np.unique``)."""
        b = self.g.b
        with b.if_(not_(self.any).or_(x.gt(self.lastx))):
            b.set(self.qx[self.qn], x)
            b.set(self.qy[self.qn], y)
            b.set(self.qn, self.qn + 1)
            b.set(self.lastx, x)
            b.set(self.any, True)

    def drain(self, end: Ex) -> None:
        """Judge the queued nodes (and, when ``end``, the last node: no right neighbour)."""
        g, b = self.g, self.g.b
        i = g.counter("WQ")
        with b.for_(i, 0, self.qn, bound=Q.NODES_WITH_ENDS + 1) as iv:  # one more than queued: the end
            more = g.let(iv.lt(self.qn), "WMORE", "BOOL")
            with b.if_(more.or_(end)):
                xr, yr = g.let(self.xb, "WXR"), g.let(-1.0, "WYR")  # the end: no right node
                with b.if_(more):
                    b.set(xr, self.qx[iv])
                    b.set(yr, self.qy[iv])
                with b.if_(self.seen.ge(1)):
                    self._judge(xr, yr, more)
                with b.if_(more):
                    b.set(self.xa, self.xb)
                    b.set(self.ya, self.yb)
                    b.set(self.xb, xr)
                    b.set(self.yb, yr)
                    with b.if_(self.seen.lt(2)):  # (an INT: no REAL temporary of min_)
                        b.set(self.seen, self.seen + 1)
        b.set(self.qn, 0)

    def _judge(self, xr: Var, yr: Var, more: Var) -> None:
        """Node b (``xb``, ``yb``) with its left neighbour a (when ``seen`` is 2) and its right
        one (``xr``, ``yr``; at the end ``xb`` and -1)."""
        g, b = self.g, self.g.b
        top = self.top
        has_left = self.seen.ge(2)
        xb, yb, xa, ya = self.xb, self.yb, self.xa, self.ya
        # at the top to rounding (PLATEAU_TOL: PROBOR's a + b - ab is not monotone in double,
        # a clipping edge's node can be an ulp above the plateau); a node with a neighbour at
        # its value, or both at the top, belongs to a plateau, not a peak
        thr = g.let(top * (1.0 - PLATEAU_TOL), "WTHR")
        level = g.min_(yb, thr, "WLV")
        peak = yb.ge(top * (1.0 - PEAK_NEAR)).and_(not_(has_left).or_(ya.lt(level))).and_(yr.lt(level))
        # beyond PEAKS peaks none is searched (it would not be kept): the work stays bounded
        with b.if_(peak.and_(self.npk.lt(PEAKS))):
            lo = g.let(xb, "GLO")
            with b.if_(has_left):
                b.set(lo, xa)
            px, pv = self._golden(lo, xr, xb, yb)
            b.set(self.kx[self.npk], px)
            b.set(self.kv[self.npk], pv)
            b.set(self.npk, self.npk + 1)
        with b.elif_(peak):
            b.set(self.capped, True)
        # runs at the top
        with b.if_(yb.ge(thr)):
            with b.if_(self.run.eq(0)):
                b.set(self.rx, xb)
                b.set(self.rprev, xa)
                b.set(self.rhas, has_left)
            b.set(self.run, self.run + 1)
            with b.if_(yr.lt(thr)):
                with b.if_(self.run.ge(2)):
                    left, right = self._edges(xr, more, thr)
                    with b.if_(self.nrun.eq(0)):
                        b.set(self.pl, left)
                    b.set(self.pr, right)
                    b.set(self.plen, self.plen + (right - left))
                    b.set(self.pmom, self.pmom + (right - left) * (0.5 * (left + right)))
                    b.set(self.nrun, self.nrun + 1)
                b.set(self.run, 0)

    def _golden(self, lo0: Ex, hi0: Ex, x0: Ex, y0: Ex) -> tuple[Var, Var]:
        """``quadrature._golden``: the peak between ``lo0`` and ``hi0``, or (x0, y0); the
        two points of a step and the final one are evaluated by one copy of the set."""
        g, b = self.g, self.g.b
        r = (math.sqrt(5.0) - 1.0) / 2.0
        lo, hi = g.let(lo0, "GL"), g.let(hi0, "GH")
        it = g.let(0, "GIT", "INT")
        go = g.let(True, "GGO", "BOOL")
        at = g.array("GP", "REAL", 2)
        val = g.array("GF", "REAL", 2)
        with b.while_(go, bound=GOLDEN + 1):
            scale = g.max_(g.max_(1.0, g.call("ABS", lo), "GS"), g.call("ABS", hi), "GS")
            with b.if_((hi - lo).le(1e-15 * scale).or_(it.ge(GOLDEN))):
                b.set(go, False)
                b.set(at[0], 0.5 * (lo + hi))
                b.set(at[1], at[0])
            with b.else_():
                b.set(at[0], hi - r * (hi - lo))
                b.set(at[1], lo + r * (hi - lo))
            k = g.counter("GK")
            with b.for_(k, 0, 1) as kv:
                b.set(val[kv], _at(g, self.op, self.sets, g.let(at[kv], "GXK")))
            with b.if_(go):
                with b.if_(val[0].eq(val[1])):  # both on the flat top: keep the middle
                    b.set(lo, at[0])
                    b.set(hi, at[1])
                with b.elif_(val[0].gt(val[1])):
                    b.set(hi, at[1])
                with b.else_():
                    b.set(lo, at[0])
                b.set(it, it + 1)
        px, pv = g.let(x0, "PX"), g.let(y0, "PV")
        with b.if_(val[0].gt(y0)):
            b.set(px, at[0])
            b.set(pv, val[0])
        return px, pv

    def _edges(self, xr: Var, more: Var, thr: Var) -> tuple[Var, Var]:
        """The run's two edges (``quadrature._edge``, bisection for where the set reaches
        the top): between the node before it and its first node (when there is one), and
        between its last node and the next (when there is one)."""
        g, b = self.g, self.g.b
        out = g.array("EX", "REAL", 2)
        k = g.counter("EK")
        with b.for_(k, 0, 1) as kv:
            o, i = g.let(xr, "EO"), g.let(self.xb, "EI")
            search = g.let(more, "ES", "BOOL")
            with b.if_(kv.eq(0)):
                b.set(o, self.rprev)
                b.set(i, self.rx)
                b.set(search, self.rhas)
            it = g.let(0, "EIT", "INT")
            with b.while_(search, bound=HALVINGS + 1):
                mid = g.let(0.5 * (o + i), "EM")
                with b.if_(mid.eq(o).or_(mid.eq(i)).or_(it.ge(HALVINGS))):
                    b.set(search, False)
                with b.else_():
                    with b.if_(_at(g, self.op, self.sets, mid).ge(thr)):
                        b.set(i, mid)
                    with b.else_():
                        b.set(o, mid)
                    b.set(it, it + 1)
            b.set(out[kv], i)
        return g.let(out[0], "EL"), g.let(out[1], "ER")

    def result(self, which: str) -> Ex:
        """LM, RM or MoM from the plateaus and the peaks within :data:`SAME_TOP` of the
        height."""
        g, b = self.g, self.g.b
        sup = g.let(self.top, "SUP")
        j = g.counter("PJ")
        with b.for_(j, 0, self.npk - 1, bound=PEAKS) as jv:
            b.set(sup, g.max_(sup, self.kv[jv], "SUP"))
        cut = g.let(sup * (1.0 - SAME_TOP), "SCUT")
        np_, lo, hi, tot = g.let(0, "NP", "INT"), g.let(0.0, "PLO"), g.let(0.0, "PHI"), g.let(0.0, "PSUM")
        j = g.counter("PJ")
        with b.for_(j, 0, self.npk - 1, bound=PEAKS) as jv, b.if_(self.kv[jv].ge(cut)):
            x = self.kx[jv]
            with b.if_(np_.eq(0)):
                b.set(lo, x)
                b.set(hi, x)
            with b.else_():
                b.set(lo, g.min_(lo, x, "PLO"))
                b.set(hi, g.max_(hi, x, "PHI"))
            b.set(np_, np_ + 1)
            b.set(tot, tot + x)
        out = g.let(0.0, "YM")
        with b.if_(self.nrun.gt(0).and_(self.top.ge(cut))):
            left, right = g.let(self.pl, "PLM"), g.let(self.pr, "PRM")
            with b.if_(np_.gt(0)):
                b.set(left, g.min_(left, lo, "PLM"))
                b.set(right, g.max_(right, hi, "PRM"))
            if which == "left":
                b.set(out, left)
            elif which == "right":
                b.set(out, right)
            else:
                with b.if_(self.plen.gt(0.0)):
                    b.set(out, self.pmom / self.plen)
                with b.else_():
                    b.set(out, 0.5 * (left + right))
        with b.else_():
            with b.if_(np_.eq(0)):  # the top node itself is always a candidate peak
                b.set(np_, 1)
                b.set(lo, self.xb)
                b.set(hi, self.xb)
                b.set(tot, self.xb)
            b.set(out, {"left": lo, "right": hi, "mean": tot / g.call("TO_REAL", np_)}[which])
        return out
