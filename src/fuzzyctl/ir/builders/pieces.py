"""The pieces of an accumulated set on one grid interval, and what each method does with
them (used by :mod:`fuzzyctl.ir.builders.mamdani`): pwl.interval_pieces, pwl._combine,
pwl.piece_area_moment, pwl.bisector/_solve_in_piece and pwl.maxima as run-time loops."""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

from fuzzyctl.engine.reference.pwl import COA_TOL, MAX_TOL
from fuzzyctl.ir.builders import terms as T
from fuzzyctl.ir.nodes import Ex, Index, Var, ex, not_
from fuzzyctl.ir.state import Gen
from fuzzyctl.kinds import methods as kinds

#: The run-time code of each method on sets, in registry order (1 CoG, 2 CoA, 3 LM, 4 RM,
#: 5 MoM): the PLC block reads an output's method from a table of these.
METHODS = {code: k + 1 for k, code in enumerate(c for c, m in kinds.METHODS.items() if m.on_sets)}


def having(methods: set[str], predicate: Callable[[kinds.Method], bool]) -> list[str]:
    """The methods of ``methods`` whose registry entry satisfies ``predicate``, by code."""
    return sorted((m for m in methods if predicate(kinds.METHODS[m])), key=METHODS.__getitem__)


def code_test(mc: Ex, predicate: Callable[[kinds.Method], bool]) -> Ex:
    """``mc`` (a run-time method code) is one of the methods satisfying ``predicate``: a
    single comparison when their codes are the last ones, else one per code."""
    codes = sorted(METHODS[m] for m in METHODS if predicate(kinds.METHODS[m]))
    if len(codes) > 1 and codes == list(range(codes[0], max(METHODS.values()) + 1)):
        return mc.ge(codes[0])
    test = mc.eq(codes[0])
    for k in codes[1:]:
        test = test.or_(mc.eq(k))
    return test


def _centroid(m: kinds.Method) -> bool:
    return m.centroid


def _bisects(m: kinds.Method) -> bool:
    return m.bisects


def _maximum(m: kinds.Method) -> bool:
    return m.maximum is not None


ACCUS = {"MAX": 1, "SUM": 2, "NSUM": 2, "BSUM": 3, "PROBOR": 4}


@dataclass
class Ctx:
    g: Gen
    v: dict[str, Var]
    a: dict[str, Var]
    st: dict[str, Var]
    gl: tuple[Var, Var, Var, Var] | None
    methods: set[str]
    accus: set[int]
    wx: Var
    wy: Var
    toff: Var
    tlast: Var
    gt: Var
    gmin: Var
    ga: Var
    gw: Var
    pass_: Var | None = None
    forward: Ex | None = None


def dedupe(g: Gen, arr: Var, n: Var) -> None:
    """Drop repeated values from a sorted array (Python's sorted(set(...)))."""
    b = g.b
    wr = g.temp("INT", "W")
    b.set(wr, 0)
    k = g.counter("K")
    with b.for_(k, 1, n - 1) as kv, b.if_(arr[kv].ne(arr[wr])):
        b.set(wr, wr + 1)
        b.set(arr[wr], arr[kv])
    b.set(n, wr + 1)


def accumulate_dynamic(c: Ctx, acc: Var, val: Ex) -> None:
    """acc := accumulate(accu of the current output, acc, val)."""
    g, b = c.g, c.g.b
    present = [
        (code, name) for name, code in (("MAX", 1), ("SUM", 2), ("BSUM", 3), ("PROBOR", 4)) if code in c.accus
    ] or [(1, "MAX")]
    for i, (code, name) in enumerate(present):
        ctx_mgr = b.if_(c.v["AC"].eq(code)) if i == 0 else b.elif_(c.v["AC"].eq(code))
        with ctx_mgr:
            b.set(acc, T.accumulate(g, name, acc, val))


def candidate(c: Ctx, x: Ex) -> None:
    """A point where the set reaches its height: LM, RM and the isolated points of MoM
    (visited in increasing x, so repeated points are adjacent)."""
    b, st = c.g.b, c.st
    with b.if_(st["ICNT"].eq(0)):
        b.set(st["LMX"], x)
        b.set(st["RMX"], x)
        b.set(st["ISUM"], x)
        b.set(st["LASTX"], x)
        b.set(st["ICNT"], 1)
    with b.else_():
        with b.if_(x.lt(st["LMX"])):
            b.set(st["LMX"], x)
        with b.if_(x.gt(st["RMX"])):
            b.set(st["RMX"], x)
        # within MAX_TOL of the range of the point before: the same point (pwl.distinct_points)
        with b.if_((x - st["LASTX"]).gt(MAX_TOL * (c.v["HIGH"] - c.v["LOW"]))):
            b.set(st["ISUM"], st["ISUM"] + x)
            b.set(st["ICNT"], st["ICNT"] + 1)
        b.set(st["LASTX"], x)


def interval(c: Ctx, x0: Var, x1: Var) -> None:
    """pwl.interval_pieces: cut where MIN activation clips a line, then combine."""
    g, b, v, a = c.g, c.g.b, c.v, c.a
    ll, lr, la, lw, lmin = a["LL"], a["LR"], a["LA"], a["LW"], a["LMIN"]
    kk, ts, p0, p1 = a["KINK"], a["TS"], a["P0"], a["P1"]
    nl, nt, nc = v["NL"], v["NT"], v["NC"]
    dx = g.let(x1 - x0, "DX")
    b.set(ts[0], 0.0)
    b.set(ts[1], 1.0)
    b.set(nt, 2)
    k = g.counter("K")
    with b.for_(k, 0, nl - 1) as kv:
        b.set(kk[kv], -1.0)
        with b.if_(lmin[kv]), b.if_(((ll[kv] - la[kv]) * (lr[kv] - la[kv])).lt(0.0)):
            b.set(kk[kv], (la[kv] - ll[kv]) / (lr[kv] - ll[kv]))
            b.set(ts[nt], kk[kv])
            b.set(nt, nt + 1)
    T.sort_points(g, ts, None, 0, nt - 1)
    dedupe(g, ts, nt)
    ii = g.counter("II")
    i = g.temp("INT", "I")
    assert c.forward is not None
    with b.for_(ii, 1, nt - 1) as iv:
        with b.if_(c.forward):
            b.set(i, iv)
        with b.else_():
            b.set(i, nt - iv)
        t0 = g.let(ts[i - 1], "T0")
        t1 = g.let(ts[i], "T1")
        xa = g.let(x0, "XA")
        with b.if_(t0.gt(0.0)):
            b.set(xa, x0 + t0 * dx)
        xb = g.let(x1, "XB")
        with b.if_(t1.lt(1.0)):
            b.set(xb, x0 + t1 * dx)
        k = g.counter("K")
        with b.for_(k, 0, nl - 1) as kv:
            for arr, t in ((p0, t0), (p1, t1)):
                with b.if_(lmin[kv]):
                    with b.if_(t.eq(kk[kv])):
                        b.set(arr[kv], lw[kv] * la[kv])
                    with b.else_():
                        y = g.let(ll[kv] + (lr[kv] - ll[kv]) * t, "Y")
                        with b.if_(y.ge(la[kv])):
                            b.set(arr[kv], lw[kv] * la[kv])
                        with b.else_():
                            b.set(arr[kv], lw[kv] * y)
                with b.else_():
                    b.set(arr[kv], lw[kv] * la[kv] * (ll[kv] + (lr[kv] - ll[kv]) * t))
        _combine(c, xa, xb)
        cc = g.counter("CC")
        ci = g.temp("INT", "C")
        cut, cv, v0, v1 = a["CUT"], a["CV"], v["V0"], v["V1"]
        with b.for_(cc, 0, nc) as ccv:
            with b.if_(c.forward):
                b.set(ci, ccv)
            with b.else_():
                b.set(ci, nc - ccv)
            pxa = g.let(xa, "PXA")
            pv0 = g.let(v0, "PV0")
            with b.if_(ci.gt(0)):
                b.set(pxa, xa + cut[ci - 1] * (xb - xa))
                b.set(pv0, cv[ci - 1])
            pxb = g.let(xb, "PXB")
            pv1 = g.let(v1, "PV1")
            with b.if_(ci.lt(nc)):
                b.set(pxb, xa + cut[ci] * (xb - xa))
                b.set(pv1, cv[ci])
            _piece(c, pxa, pxb, pv0, pv1)


def _combine(c: Ctx, xa: Var, xb: Var) -> None:
    """pwl._combine: the accumulated values at the sub-interval's ends and the cuts inside it
    (MAX: where two sets cross; BSUM: where the sum crosses 1)."""
    g, b, v, a = c.g, c.g.b, c.v, c.a
    p0, p1, cut, cv = a["P0"], a["P1"], a["CUT"], a["CV"]
    nl, nc, v0, v1 = v["NL"], v["NC"], v["V0"], v["V1"]
    b.set(nc, 0)
    if "PR" in v:
        b.set(v["PR"], False)
    with b.if_(nl.eq(1)):
        b.set(v0, p0[0])
        b.set(v1, p1[0])
    if 1 in c.accus:
        with b.elif_(v["AC"].eq(1)):
            b.set(v0, p0[0])
            b.set(v1, p1[0])
            k = g.counter("K")
            with b.for_(k, 1, nl - 1) as kv:
                with b.if_(p0[kv].gt(v0)):
                    b.set(v0, p0[kv])
                with b.if_(p1[kv].gt(v1)):
                    b.set(v1, p1[kv])
            i = g.counter("I")
            j = g.counter("J")
            d0 = g.temp(hint="D0")
            d1 = g.temp(hint="D1")
            with b.for_(i, 0, nl - 2) as iv, b.for_(j, iv + 1, nl - 1) as jv:
                b.set(d0, p0[iv] - p0[jv])
                b.set(d1, p1[iv] - p1[jv])
                with b.if_((d0 * d1).lt(0.0)):
                    b.set(cut[nc], d0 / (d0 - d1))
                    b.set(nc, nc + 1)
            T.sort_points(g, cut, None, 0, nc - 1)
            cix = g.counter("C")
            with b.for_(cix, 0, nc - 1) as cvv:
                s = g.let(cut[cvv], "S")
                b.set(cv[cvv], p0[0] + (p1[0] - p0[0]) * s)
                k = g.counter("K")
                with b.for_(k, 1, nl - 1) as kv:
                    y = g.let(p0[kv] + (p1[kv] - p0[kv]) * s, "Y")
                    with b.if_(y.gt(cv[cvv])):
                        b.set(cv[cvv], y)
    if c.accus & {2, 3}:
        with b.elif_(v["AC"].eq(2).or_(v["AC"].eq(3))):
            s0 = g.let(0.0, "S0")
            s1 = g.let(0.0, "S1")
            k = g.counter("K")
            with b.for_(k, 0, nl - 1) as kv:
                b.set(s0, s0 + p0[kv])
                b.set(s1, s1 + p1[kv])
            b.set(v0, s0)
            b.set(v1, s1)
            if 3 in c.accus:
                with b.if_(v["AC"].eq(3)):
                    with b.if_(((s0 - 1.0) * (s1 - 1.0)).lt(0.0)):
                        b.set(cut[0], (1.0 - s0) / (s1 - s0))
                        b.set(cv[0], 1.0)
                        b.set(nc, 1)
                    b.set(v0, 1.0)
                    with b.if_(s0.lt(1.0)):
                        b.set(v0, s0)
                    b.set(v1, 1.0)
                    with b.if_(s1.lt(1.0)):
                        b.set(v1, s1)
    if 4 in c.accus:
        with b.elif_(v["AC"].eq(4)):
            b.set(v["PR"], True)
            b.set(v0, _poly(c, ex(0.0)))
            b.set(v1, _poly(c, ex(1.0)))


def _poly(c: Ctx, s: Ex) -> Var:
    """1 - prod(1 - c_k(s)), folded as acc + c - acc*c (pwl._poly_value)."""
    g = c.g
    p0, p1, nl = c.a["P0"], c.a["P1"], c.v["NL"]
    acc = g.let(0.0, "PP")
    k = g.counter("K")
    with g.b.for_(k, 0, nl - 1) as kv:
        cc = g.let(p0[kv] + (p1[kv] - p0[kv]) * s, "PC")
        g.b.set(acc, acc + cc - acc * cc)
    return acc


def _piece(c: Ctx, xa: Var, xb: Var, v0: Var, v1: Var) -> None:
    """One piece of the accumulated set: its area and moment, then what the method needs."""
    g, b, v, st = c.g, c.g.b, c.v, c.st
    pdx = g.let(xb - xa, "PDX")
    pa = g.temp(hint="PA")
    pm = g.temp(hint="PM")
    b.set(pa, 0.5 * pdx * (v0 + v1))
    b.set(pm, pdx * (xa * (2.0 * v0 + v1) + xb * (v0 + 2.0 * v1)) / 6.0)
    if c.gl is not None:
        glx, glw, gln, glo = c.gl
        nl = v["NL"]
        with b.if_(v["PR"]):
            ga_ = g.let(0.0, "GA")
            gm_ = g.let(0.0, "GM")
            q = g.counter("Q")
            with b.for_(q, 0, gln[nl] - 1) as qv:
                s = g.let(glx[glo[nl] + qv], "S")
                f = _poly(c, s)
                b.set(ga_, ga_ + glw[glo[nl] + qv] * f)
                b.set(gm_, gm_ + glw[glo[nl] + qv] * f * (xa + s * pdx))
            b.set(pa, ga_ * pdx)
            b.set(pm, gm_ * pdx)
    area, mom, mc = v["AREA"], v["MOM"], v["MC"]
    assert c.pass_ is not None
    ps = c.pass_
    first = True

    def branch(cond: Ex):  # type: ignore[no-untyped-def]
        nonlocal first
        mgr = b.if_(cond) if first else b.elif_(cond)
        first = False
        return mgr

    if having(c.methods, _centroid):
        with branch(code_test(mc, _centroid)):
            b.set(area, area + pa)
            b.set(mom, mom + pm)
    if having(c.methods, _bisects):
        with branch(code_test(mc, _bisects)):
            with b.if_(ps.eq(1)):
                b.set(area, area + pa)
                with b.if_(xb.gt(xa)):
                    with b.if_(not_(st["HAVE"])):
                        b.set(st["FX0"], xa)
                        b.set(st["HAVE"], True)
                    b.set(st["LX1"], xb)
            with b.elif_(xb.gt(xa)):
                # pass 2 looks from the left, pass 3 from the right (pwl.bisector)
                found = g.temp("BOOL", "FOUND")
                cum = g.temp(hint="CUMX")
                with b.if_(ps.eq(2)):
                    b.set(found, st["FOUNDL"])
                    b.set(cum, st["CUM"])
                with b.else_():
                    b.set(found, st["FOUNDR"])
                    b.set(cum, st["CUMR"])
                with b.if_(not_(found)):
                    # within COA_TOL of half before a zero gap: the gap's middle, and the
                    # whole piece within it: its end (pwl.bisector)
                    tol = g.let(st["HALF"] * (2.0 * COA_TOL), "CTOL")
                    with b.if_(pa.gt(0.0).and_((cum + pa).ge(st["HALF"] - tol))):
                        r = g.temp(hint="RR")
                        whole = g.let((st["HALF"] - cum).ge(pa - tol), "WHOLE", "BOOL")
                        with b.if_(ps.eq(2)):
                            b.set(r, st["HALF"] - cum)
                        with b.else_():
                            b.set(r, pa - (st["HALF"] - cum))
                        x = _solve(c, xa, xb, v0, v1, pdx, r)
                        with b.if_(whole.and_(ps.eq(2))):
                            b.set(x, xb)
                        with b.elif_(whole):
                            b.set(x, xa)
                        with b.if_(ps.eq(2)):
                            b.set(st["LEFT"], x)
                            b.set(st["FOUNDL"], True)
                        with b.else_():
                            b.set(st["RIGHT"], x)
                            b.set(st["FOUNDR"], True)
                    with b.elif_(ps.eq(2)):
                        b.set(st["CUM"], cum + pa)
                    with b.else_():
                        b.set(st["CUMR"], cum + pa)
    if having(c.methods, _maximum):
        with branch(code_test(mc, _maximum)):
            with b.if_(ps.eq(1)):
                b.set(area, area + pa)
                with b.if_(v0.gt(st["SUP"])):
                    b.set(st["SUP"], v0)
                with b.if_(v1.gt(st["SUP"])):
                    b.set(st["SUP"], v1)
            with b.else_():
                with b.if_(v0.ge(st["THR"])):
                    candidate(c, xa)
                with b.if_(v1.ge(st["THR"])):
                    candidate(c, xb)
                with b.if_(v0.ge(st["THR"]).and_(v1.ge(st["THR"])).and_(xb.gt(xa))):
                    b.set(st["PLEN"], st["PLEN"] + pdx)
                    b.set(st["PMOM"], st["PMOM"] + pdx * 0.5 * (xa + xb))


def _solve(c: Ctx, xa: Var, xb: Var, v0: Var, v1: Var, pdx: Var, r: Var) -> Var:
    """pwl._solve_in_piece: where the area from the piece's start reaches ``r``."""
    g, b, v = c.g, c.g.b, c.v
    out = g.temp(hint="SOL")
    if c.gl is not None:
        glx, glw, gln, glo = c.gl
        nl = v["NL"]
        with b.if_(v["PR"]):  # the partial area increases in s: bisection to the last bit
            lo = g.let(0.0, "LO")
            hi = g.let(1.0, "HI")
            it = g.let(0, "IT", "INT")
            go = g.let(True, "GO", "BOOL")
            with b.while_(go):
                mid = g.let(0.5 * (lo + hi), "MID")
                with b.if_(mid.eq(lo).or_(mid.eq(hi))):
                    b.set(go, False)
                with b.else_():
                    part = g.let(0.0, "PS")
                    q = g.counter("Q")
                    with b.for_(q, 0, gln[nl] - 1) as qv:
                        f = _poly(c, glx[glo[nl] + qv] * mid)
                        b.set(part, part + glw[glo[nl] + qv] * f)
                    with b.if_((pdx * mid * part).lt(r)):
                        b.set(lo, mid)
                    with b.else_():
                        b.set(hi, mid)
                    b.set(it, it + 1)
                    with b.if_(it.ge(200)):
                        b.set(go, False)
            b.set(out, xa + 0.5 * (lo + hi) * pdx)
        ctx = b.else_()
    else:
        ctx = b.if_(ex(True))
    with ctx:
        solve_linear(g, out, xa, xb, v0, v1, pdx, r)
    return out


def solve_linear(g: Gen, out: Var, xa: Ex, xb: Ex, v0: Ex, v1: Ex, pdx: Ex, r: Ex) -> None:
    """``out`` := where the area of the linear piece from ``xa`` (degree ``v0``) to ``xb``
    (``v1``) reaches ``r`` from its start (pwl._solve_in_piece: scaled, the stable root)."""
    b = g.b
    a0 = g.let(v0, "SV0")
    a1 = g.let(v1, "SV1")
    rr = g.let(r, "SR")
    m0 = g.let(a0, "SC")
    with b.if_(m0.lt(0.0)):
        b.set(m0, -m0)
    m1 = g.let(a1, "SC")
    with b.if_(m1.lt(0.0)):
        b.set(m1, -m1)
    sc = g.max_(m0, m1, "SC")
    with b.if_(sc.gt(0.0)):
        b.set(a0, a0 / sc)
        b.set(a1, a1 / sc)
        b.set(rr, rr / sc)
    kk = g.let(0.0, "SK")
    with b.if_(pdx.gt(0.0)):
        b.set(kk, (a1 - a0) / pdx)
    disc = g.let(a0 * a0 + 2.0 * kk * rr, "DISC")
    with b.if_(disc.lt(0.0)):
        b.set(disc, 0.0)
    den = g.let(a0 + g.call("SQRT", disc), "DEN")
    with b.if_(den.le(0.0)):
        b.set(out, xa)
    with b.else_():
        b.set(out, xa + 2.0 * rr / den)
        with b.if_(xb.lt(out)):
            b.set(out, xb)


def finish(c: Ctx, value: Index, fired: Index) -> None:
    """The value of the current output from what the passes gathered."""
    b, v, st = c.g.b, c.v, c.st
    b.set(fired, v["AREA"].gt(0.0))
    b.set(value, 0.0)
    first = True

    def branch(cond: Ex):  # type: ignore[no-untyped-def]
        nonlocal first
        mgr = b.if_(cond) if first else b.elif_(cond)
        first = False
        return mgr

    mc = v["MC"]
    if having(c.methods, _centroid):
        with branch(code_test(mc, _centroid).and_(v["AREA"].gt(0.0))):
            b.set(value, v["MOM"] / v["AREA"])
    if having(c.methods, _bisects):
        with branch(code_test(mc, _bisects)):
            with b.if_(not_(st["FOUNDL"])):
                b.set(st["LEFT"], st["LX1"])
            with b.if_(not_(st["FOUNDR"])):
                b.set(st["RIGHT"], st["FX0"])
            b.set(value, 0.5 * (st["LEFT"] + st["RIGHT"]))
    for code in having(c.methods, _maximum):
        with branch(mc.eq(METHODS[code])):
            side = kinds.METHODS[code].maximum
            if side == "left":
                b.set(value, st["LMX"])
            elif side == "right":
                b.set(value, st["RMX"])
            else:
                with b.if_(st["PLEN"].gt(MAX_TOL * (v["HIGH"] - v["LOW"]))):  # pwl.maxima
                    b.set(value, st["PMOM"] / st["PLEN"])
                with b.elif_(st["ICNT"].gt(0)):
                    b.set(value, st["ISUM"] / c.g.call("TO_REAL", st["ICNT"]))


# --------------------------------------------------------------------------- constant geometry

#: One activated set on one grid interval of a constant grid: the term goes linearly from
#: ``L`` to ``R`` (numbers), the set is ``w * min(a, term)`` (``is_min``) or ``w * a * term``.
StaticLine = tuple[float, float, Ex, Ex, bool]


def polyline_am(g: Gen, x0: float, dx: float, ts: list[Ex], vs: list[Ex]) -> tuple[Var, Var]:
    """Area and moment of the polyline through ``(x0 + t dx, v)`` for ordered ``ts``, the
    sums kept in t-space (numpy twin: :func:`fuzzyctl.ir.kernels.columns._polyline_am`)."""
    area: Ex = ex(0.0)
    tmom: Ex = ex(0.0)
    for k in range(len(ts) - 1):
        d = g.let(ts[k + 1] - ts[k], "D")
        s = g.let(vs[k] + vs[k + 1], "S")
        area = area + d * s
        tmom = tmom + d * (ts[k] * (s + vs[k]) + ts[k + 1] * (s + vs[k + 1]))
    a = g.let(area * (0.5 * dx), "PA")
    return a, g.let(x0 * a + (dx * dx / 6.0) * tmom, "PM")


def clipped_am(g: Gen, x0: float, dx: float, line: StaticLine) -> tuple[Var, Var]:
    """One activated set alone on an interval: ``w * min(a, line)`` or ``w * a * line``
    (numpy twin: ``kernels_np._clipped_line_am``).  At the kink the set is exactly ``w*a``."""
    left, right, a, w, mn = line
    if not mn:
        return polyline_am(g, x0, dx, [ex(0.0), ex(1.0)], [w * a * left, w * a * right])
    tk = g.let(0.0, "TK")
    if right != left:
        b = g.b
        b.set(tk, (a - left) / (right - left))
        with b.if_(tk.lt(0.0)):
            b.set(tk, 0.0)
        with b.elif_(tk.gt(1.0)):
            b.set(tk, 1.0)
    mid = g.min_(a, left + (right - left) * tk, "VK")
    with g.b.if_(((a - left) * (a - right)).lt(0.0)):
        g.b.set(mid, a)
    vs: list[Ex] = [w * g.min_(a, left, "VL"), w * mid, w * g.min_(a, right, "VR")]
    return polyline_am(g, x0, dx, [ex(0.0), tk, ex(1.0)], vs)


def max_of_two(g: Gen, x0: float, x1: float, l1: StaticLine, l2: StaticLine) -> tuple[Var, Var]:
    """Area and moment of ``max(c1, c2)`` on one interval without sorting candidates:
    ``max = c1 + c2 - min(c1, c2)``, and ``min(c1, c2) = min(H, p1, p2)`` is concave (two
    lines clipped at the constant H), whose breakpoints come out ordered by construction
    (numpy twin: ``kernels_np._max_of_two``; the scalar reference is
    :func:`fuzzyctl.engine.reference.pwl.interval_pieces`)."""
    b = g.b
    dx = x1 - x0
    area, mom = g.temp(hint="IA"), g.temp(hint="IM")
    (_l1, _r1, h1, w1, _m1), (_l2, _r2, h2, w2, _m2) = l1, l2
    for k, (cond, line) in enumerate((((h2 * w2).gt(0.0), l1), ((h1 * w1).gt(0.0), l2))):
        with b.if_(not_(cond)) if k == 0 else b.elif_(not_(cond)):
            a, m = clipped_am(g, x0, dx, line)
            b.set(area, a)
            b.set(mom, m)
    with b.else_():
        a1, m1 = clipped_am(g, x0, dx, l1)
        a2, m2 = clipped_am(g, x0, dx, l2)
        a3, m3 = _min_of_two(g, x0, dx, l1, l2)
        b.set(area, a1 + a2 - a3)
        b.set(mom, m1 + m2 - m3)
    return area, mom


def _min_of_two(g: Gen, x0: float, dx: float, l1: StaticLine, l2: StaticLine) -> tuple[Var, Var]:
    """Area and moment of ``min(H, p1, p2)``: ``p_i = P_i + S_i t`` the line parts of the two
    sets, ``H`` the smaller clip level of a MIN-activated one (none: no clip)."""
    b = g.b
    ps: list[tuple[Var, Var]] = []
    for left, right, h, w, mn in (l1, l2):
        scale = w if mn else w * h
        ps.append((g.let(scale * left, "P"), g.let(scale * (right - left), "SL")))
    (p1, s1), (p2, s2) = ps
    clips = [w * h for _l, _r, h, w, mn in (l1, l2) if mn]
    t = g.let(0.0, "TC")
    with b.if_(s1.ne(s2)):
        b.set(t, (p2 - p1) / (s1 - s2))
    with b.if_(t.ne(t)):  # NaN
        b.set(t, 0.0)
    with b.elif_(t.lt(0.0)):
        b.set(t, 0.0)
    with b.elif_(t.gt(1.0)):
        b.set(t, 1.0)

    def low(u: Ex) -> Var:
        return g.min_(p2 + s2 * u, p1 + s1 * u, "ML")

    if not clips:
        ts: list[Ex] = [ex(0.0), t, ex(1.0)]
        return polyline_am(g, x0, dx, ts, [low(u) for u in ts])
    hh = g.let(clips[0], "HC") if len(clips) == 1 else g.min_(clips[0], clips[1], "HC")
    pts: list[Ex] = [ex(0.0)]
    hits: list[Var] = []
    for ta, tb in ((ex(0.0), t), (t, ex(1.0))):
        ma, mb = low(ta), low(tb)
        hit = g.let(((ma - hh) * (mb - hh)).lt(0.0), "HIT", "BOOL")
        c = g.let(ta, "TX")
        with b.if_(hit):
            b.set(c, ta + (hh - ma) / (mb - ma) * (tb - ta))
        hits.append(hit)
        pts += [c, tb]
    vals: list[Ex] = []
    for k, u in enumerate(pts):
        v = g.min_(hh, low(u), "MV")
        if k in (1, 3):  # exactly H where min(p1, p2) crosses it
            with b.if_(hits[k // 2]):
                b.set(v, hh)
        vals.append(v)
    return polyline_am(g, x0, dx, pts, vals)
