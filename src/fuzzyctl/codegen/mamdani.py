"""Exact defuzzification of piecewise-linear Mamdani outputs as run-time loops.

The generated code does at run time what :mod:`fuzzyctl.engine.grid` and
:mod:`fuzzyctl.engine.pwl` do: sort each term's points, cut ``[low, high]`` at every
breakpoint, and on each interval cut again where MIN activation clips a term and where
activated sets cross (MAX) or their sum crosses 1 (BSUM); between those cuts the accumulated
set is linear (or, for PROBOR, a product of linear factors integrated with Gauss-Legendre
nodes exact for its degree).  CoG sums closed-form areas and moments, CoA solves the
quadratic of the piece holding half the area, LM/RM/MoM scan the pieces' ends.  Because the
grid is built at run time, term points stay tunable online.

The pieces are never stored: methods needing several looks (CoA: total, then from the left,
then from the right; LM/RM/MoM: the height, then where it is reached) run the same loop
several times (``pass``), so memory is bounded by the number of activated sets, not by the
number of pieces.
"""

from __future__ import annotations

from dataclasses import dataclass

from fuzzyctl.codegen import terms as T
from fuzzyctl.codegen.context import Gen
from fuzzyctl.codegen.ir import Ex, Var, ex, not_
from fuzzyctl.engine.pwl import MAX_TOL, gauss_legendre


@dataclass
class Group:
    """One activated set: ``w * min(a, term)`` (``is_min``) or ``w * a * term``."""

    term: int
    a: Ex
    w: Ex
    is_min: bool


def exact_output(
    g: Gen,
    label: str,
    method: str,
    accu: str,
    low: float,
    high: float,
    points: list[list[tuple[Ex, Ex]]],
    groups: list[Group],
) -> tuple[Var, Var]:
    """Emit the defuzzification of one output; returns (value, fired)."""
    b = g.b
    value = g.temp(hint="Y")
    fired = g.temp("BOOL", "FIRED")
    if not groups:
        b.set(value, 0.0)
        b.set(fired, False)
        return value, fired
    counts = [len(p) for p in points]
    offs = [sum(counts[:t]) for t in range(len(points))]
    n_pts = sum(counts)
    used_terms = sorted({gr.term for gr in groups})
    # ---- each term's points, sorted (they may come from inputs or be retuned online)
    wx = g.array("WX", "REAL", n_pts)
    wy = g.array("WY", "REAL", n_pts)
    for t in used_terms:
        for k, (x, y) in enumerate(points[t]):
            b.set(wx[offs[t] + k], x)
            b.set(wy[offs[t] + k], y)
        if counts[t] > 1:
            T.sort_points(g, wx, wy, offs[t], counts[t])
    # ---- the grid: [low, high] cut at every breakpoint inside it
    gx = g.array("GX", "REAL", n_pts + 2)
    ng = g.temp("INT", "NG")
    b.set(gx[0], low)
    b.set(gx[1], high)
    b.set(ng, 2)
    for t in used_terms:
        k = g.counter("K")
        with b.for_(k, offs[t], offs[t] + counts[t] - 1) as kv:
            with b.if_(wx[kv].gt(low).and_(wx[kv].lt(high))):
                b.set(gx[ng], wx[kv])
                b.set(ng, ng + 1)
    T.sort_points(g, gx, None, 0, ng)
    wr = g.temp("INT", "W")
    b.set(wr, 0)
    k = g.counter("K")
    with b.for_(k, 1, ng - 1) as kv:
        with b.if_(gx[kv].ne(gx[wr])):
            b.set(wr, wr + 1)
            b.set(gx[wr], gx[kv])
    b.set(ng, wr + 1)
    # ---- which terms carry an activated set at all
    live: dict[int, Var] = {}
    for t in used_terms:
        lv = g.temp("BOOL", "LIVE")
        b.set(lv, False)
        for gr in groups:
            if gr.term == t:
                with b.if_((gr.a * gr.w).gt(0.0)):
                    b.set(lv, True)
        live[t] = lv

    n_groups = len(groups)
    ll, lr, la, lw = (g.array(h, "REAL", n_groups) for h in ("LL", "LR", "LA", "LW"))
    lmin = g.array("LMIN", "BOOL", n_groups)
    nl = g.temp("INT", "NL")
    kk = g.array("KINK", "REAL", n_groups)
    ts = g.array("TS", "REAL", n_groups + 2)
    nt = g.temp("INT", "NT")
    p0 = g.array("P0", "REAL", n_groups)
    p1 = g.array("P1", "REAL", n_groups)
    n_cut = max(1, n_groups * (n_groups - 1) // 2)
    cut = g.array("CUT", "REAL", n_cut)
    cv = g.array("CV", "REAL", n_cut)
    nc = g.temp("INT", "NC")
    v0 = g.temp(hint="V0")
    v1 = g.temp(hint="V1")
    probor = accu == "PROBOR" and n_groups > 1
    pr = g.temp("BOOL", "PR") if probor else None
    gl = _gl_tables(g, n_groups) if probor else None

    # ---- per-method accumulators
    acc_a = g.temp(hint="AREA")
    acc_m = g.temp(hint="MOM")
    b.set(acc_a, 0.0)
    b.set(acc_m, 0.0)
    st: dict[str, Var] = {}
    if method == "COA":
        for name, typ, init in (
            ("HALF", "REAL", 0.0),
            ("CUM", "REAL", 0.0),
            ("CUMR", "REAL", 0.0),
            ("LEFT", "REAL", 0.0),
            ("RIGHT", "REAL", 0.0),
            ("FX0", "REAL", 0.0),
            ("LX1", "REAL", 0.0),
            ("HAVE", "BOOL", False),
            ("FOUNDL", "BOOL", False),
            ("FOUNDR", "BOOL", False),
        ):
            st[name] = g.temp(typ, name)  # type: ignore[arg-type]
            b.set(st[name], init)
    elif method in ("LM", "RM", "MOM"):
        for name, typ, init in (
            ("SUP", "REAL", 0.0),
            ("THR", "REAL", 0.0),
            ("LMX", "REAL", 0.0),
            ("RMX", "REAL", 0.0),
            ("PLEN", "REAL", 0.0),
            ("PMOM", "REAL", 0.0),
            ("ISUM", "REAL", 0.0),
            ("LASTX", "REAL", 0.0),
            ("ICNT", "INT", 0),
        ):
            st[name] = g.temp(typ, name)  # type: ignore[arg-type]
            b.set(st[name], init)
    n_pass = {"COG": 1, "COA": 3}.get(method, 2)
    ps = g.counter("PASS")
    j = g.temp("INT", "J")
    with b.for_(ps, 1, n_pass) as pv:
        forward = pv.ne(3)
        if method == "COA":
            with b.if_(pv.eq(2)):
                b.set(st["HALF"], 0.5 * acc_a)
        if method in ("LM", "RM", "MOM"):
            with b.if_(pv.eq(2)):
                b.set(st["THR"], st["SUP"] * (1.0 - MAX_TOL))
        jj = g.counter("JJ")
        with b.for_(jj, 0, ng - 1) as jv:
            with b.if_(forward):
                b.set(j, jv)
            with b.else_():
                b.set(j, ng - 2 - jv)
            if method in ("LM", "RM", "MOM"):
                _grid_point(g, gx[j], pv, wx, wy, offs, counts, used_terms, groups, accu, st)
            with b.if_(j.ge(0).and_(j.le(ng - 2))):
                x0 = g.let(gx[j], "X0")
                x1 = g.let(gx[j + 1], "X1")
                dx = g.let(x1 - x0, "DX")
                lims: dict[int, tuple[Var, Var]] = {}
                for t in used_terms:
                    lt_, rt_ = g.temp(hint="L"), g.temp(hint="R")
                    b.set(lt_, 0.0)
                    b.set(rt_, 0.0)
                    with b.if_(live[t]):
                        b.set(lt_, T.right_limit(g, wx, wy, offs[t], counts[t], x0))
                        b.set(rt_, T.left_limit(g, wx, wy, offs[t], counts[t], x1))
                    lims[t] = (lt_, rt_)
                b.set(nl, 0)
                for gr in groups:
                    lt_, rt_ = lims[gr.term]
                    with b.if_((gr.a * gr.w).gt(0.0).and_(lt_.ne(0.0).or_(rt_.ne(0.0)))):
                        b.set(ll[nl], lt_)
                        b.set(lr[nl], rt_)
                        b.set(la[nl], gr.a)
                        b.set(lw[nl], gr.w)
                        b.set(lmin[nl], gr.is_min)
                        b.set(nl, nl + 1)
                with b.if_(nl.gt(0)):
                    _interval(g, locals_=dict(
                        x0=x0, x1=x1, dx=dx, ll=ll, lr=lr, la=la, lw=lw, lmin=lmin, nl=nl, kk=kk,
                        ts=ts, nt=nt, p0=p0, p1=p1, cut=cut, cv=cv, nc=nc, v0=v0, v1=v1,
                        pass_=pv, forward=forward, acc_a=acc_a, acc_m=acc_m,
                    ), accu=accu, method=method, pr=pr, gl=gl, st=st)
    # ---- the value
    if method == "COG":
        b.set(fired, acc_a.gt(0.0))
        with b.if_(fired):
            b.set(value, acc_m / acc_a)
        with b.else_():
            b.set(value, 0.0)
    elif method == "COA":
        b.set(fired, acc_a.gt(0.0))
        with b.if_(not_(st["FOUNDL"])):
            b.set(st["LEFT"], st["LX1"])
        with b.if_(not_(st["FOUNDR"])):
            b.set(st["RIGHT"], st["FX0"])
        b.set(value, 0.5 * (st["LEFT"] + st["RIGHT"]))
    else:
        b.set(fired, acc_a.gt(0.0))
        if method == "LM":
            b.set(value, st["LMX"])
        elif method == "RM":
            b.set(value, st["RMX"])
        else:
            with b.if_(st["PLEN"].gt(0.0)):
                b.set(value, st["PMOM"] / st["PLEN"])
            with b.elif_(st["ICNT"].gt(0)):
                b.set(value, st["ISUM"] / g.call("TO_REAL", st["ICNT"]))
            with b.else_():
                b.set(value, 0.0)
    return value, fired


def _gl_tables(g: Gen, n_groups: int) -> tuple[Var, Var, Var, Var]:
    """Gauss-Legendre nodes/weights on [0, 1] for every factor count 2..n_groups, with the
    engine's node count (pwl.piece_area_moment: (n + 3) // 2 + 1)."""
    counts = [0] * (n_groups + 1)
    offs = [0] * (n_groups + 1)
    xs: list[float] = []
    ws: list[float] = []
    for n in range(2, n_groups + 1):
        m = (n + 3) // 2 + 1
        nodes, weights = gauss_legendre(m)
        counts[n], offs[n] = m, len(xs)
        xs.extend(nodes)
        ws.extend(weights)
    glx = g.declare(g.fresh("GLX", "GLX"), "REAL", "const", len(xs), tuple(xs), "Gauss-Legendre nodes")
    glw = g.declare(g.fresh("GLW", "GLW"), "REAL", "const", len(ws), tuple(ws), "Gauss-Legendre weights")
    gln = g.declare(g.fresh("GLN", "GLN"), "INT", "const", len(counts), tuple(float(c) for c in counts))
    glo = g.declare(g.fresh("GLO", "GLO"), "INT", "const", len(offs), tuple(float(o) for o in offs))
    return glx, glw, gln, glo


def _grid_point(
    g: Gen,
    x: Ex,
    pv: Var,
    wx: Var,
    wy: Var,
    offs: list[int],
    counts: list[int],
    used_terms: list[int],
    groups: list[Group],
    accu: str,
    st: dict[str, Var],
) -> None:
    """The accumulated degree exactly at a grid point (pwl.point_values): it can be the
    maximum at a vertical edge."""
    b = g.b
    xp = g.let(x, "XP")
    mu: dict[int, Var] = {}
    for t in used_terms:
        mu[t] = T.pwl_value(g, wx, wy, offs[t], counts[t], xp)
    v = g.let(0.0, "PV")
    for gr in groups:
        with b.if_((gr.a * gr.w).gt(0.0)):
            y = mu[gr.term]
            c = gr.w * (g.min_(gr.a, y) if gr.is_min else gr.a * y)
            b.set(v, T.accumulate(g, accu, v, c))
    with b.if_(pv.eq(1)):
        with b.if_(v.gt(st["SUP"])):
            b.set(st["SUP"], v)
    with b.else_():
        with b.if_(v.ge(st["THR"])):
            _candidate(g, xp, st)


def _candidate(g: Gen, x: Ex, st: dict[str, Var]) -> None:
    """A point where the set reaches its height: LM, RM and the isolated points of MoM
    (visited in increasing x, so repeated points are adjacent)."""
    b = g.b
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
        with b.if_(x.ne(st["LASTX"])):
            b.set(st["ISUM"], st["ISUM"] + x)
            b.set(st["ICNT"], st["ICNT"] + 1)
            b.set(st["LASTX"], x)


def _interval(
    g: Gen,
    locals_: dict[str, Var],
    accu: str,
    method: str,
    pr: Var | None,
    gl: tuple[Var, Var, Var, Var] | None,
    st: dict[str, Var],
) -> None:
    """pwl.interval_pieces + pwl._combine on one grid interval, then each piece's action."""
    b = g.b
    L = locals_
    x0, x1, dx = L["x0"], L["x1"], L["dx"]
    ll, lr, la, lw, lmin, nl = L["ll"], L["lr"], L["la"], L["lw"], L["lmin"], L["nl"]
    kk, ts, nt, p0, p1 = L["kk"], L["ts"], L["nt"], L["p0"], L["p1"]
    cut, cv, nc, v0, v1 = L["cut"], L["cv"], L["nc"], L["v0"], L["v1"]
    pv, forward = L["pass_"], L["forward"]
    # kinks where MIN activation clips a term
    b.set(ts[0], 0.0)
    b.set(ts[1], 1.0)
    b.set(nt, 2)
    k = g.counter("K")
    with b.for_(k, 0, nl - 1) as kv:
        b.set(kk[kv], -1.0)
        with b.if_(lmin[kv]):
            with b.if_(((ll[kv] - la[kv]) * (lr[kv] - la[kv])).lt(0.0)):
                b.set(kk[kv], (la[kv] - ll[kv]) / (lr[kv] - ll[kv]))
                b.set(ts[nt], kk[kv])
                b.set(nt, nt + 1)
    T.sort_points(g, ts, None, 0, nt)
    wr = g.temp("INT", "W")
    b.set(wr, 0)
    k = g.counter("K")
    with b.for_(k, 1, nt - 1) as kv:
        with b.if_(ts[kv].ne(ts[wr])):
            b.set(wr, wr + 1)
            b.set(ts[wr], ts[kv])
    b.set(nt, wr + 1)
    ii = g.counter("II")
    i = g.temp("INT", "I")
    with b.for_(ii, 1, nt - 1) as iv:
        with b.if_(forward):
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
        _combine(g, p0, p1, nl, cut, cv, nc, v0, v1, xa, xb, accu, pr)
        cc = g.counter("CC")
        c = g.temp("INT", "C")
        with b.for_(cc, 0, nc) as ccv:
            with b.if_(forward):
                b.set(c, ccv)
            with b.else_():
                b.set(c, nc - ccv)
            pxa = g.let(xa, "PXA")
            pv0 = g.let(v0, "PV0")
            with b.if_(c.gt(0)):
                b.set(pxa, xa + cut[c - 1] * (xb - xa))
                b.set(pv0, cv[c - 1])
            pxb = g.let(xb, "PXB")
            pv1 = g.let(v1, "PV1")
            with b.if_(c.lt(nc)):
                b.set(pxb, xa + cut[c] * (xb - xa))
                b.set(pv1, cv[c])
            _piece(g, pxa, pxb, pv0, pv1, p0, p1, nl, pr, gl, method, pv, L, st)


def _combine(
    g: Gen,
    p0: Var,
    p1: Var,
    nl: Var,
    cut: Var,
    cv: Var,
    nc: Var,
    v0: Var,
    v1: Var,
    xa: Var,
    xb: Var,
    accu: str,
    pr: Var | None,
) -> None:
    """pwl._combine: the accumulated values at the sub-interval's ends and the cuts inside it
    (MAX: where two sets cross; BSUM: where the sum crosses 1)."""
    b = g.b
    b.set(nc, 0)
    if pr is not None:
        b.set(pr, False)
    with b.if_(nl.eq(1)):
        b.set(v0, p0[0])
        b.set(v1, p1[0])
    if p0.name and _capacity(g, p0) < 2:
        return  # one activated set at most: nothing to combine
    with b.else_():
        if accu == "MAX":
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
            T.sort_points(g, cut, None, 0, nc)
            c = g.counter("C")
            with b.for_(c, 0, nc - 1) as cvv:
                s = g.let(cut[cvv], "S")
                b.set(cv[cvv], p0[0] + (p1[0] - p0[0]) * s)
                k = g.counter("K")
                with b.for_(k, 1, nl - 1) as kv:
                    y = g.let(p0[kv] + (p1[kv] - p0[kv]) * s, "Y")
                    with b.if_(y.gt(cv[cvv])):
                        b.set(cv[cvv], y)
        elif accu in ("SUM", "NSUM", "BSUM"):
            s0 = g.let(0.0, "S0")
            s1 = g.let(0.0, "S1")
            k = g.counter("K")
            with b.for_(k, 0, nl - 1) as kv:
                b.set(s0, s0 + p0[kv])
                b.set(s1, s1 + p1[kv])
            if accu == "BSUM":
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
            else:
                b.set(v0, s0)
                b.set(v1, s1)
        elif accu == "PROBOR":
            assert pr is not None
            b.set(pr, True)
            b.set(v0, _poly(g, p0, p1, nl, ex(0.0)))
            b.set(v1, _poly(g, p0, p1, nl, ex(1.0)))
        else:  # pragma: no cover - lowering marks other accumulations inexact
            raise AssertionError(accu)


def _capacity(g: Gen, arr: Var) -> int:
    size = next(d.size for d in g.decls if d.name == arr.name)
    return size or 1


def _poly(g: Gen, p0: Var, p1: Var, nl: Var, s: Ex) -> Var:
    """1 - prod(1 - c_k(s)), folded as acc + c - acc*c (pwl._poly_value)."""
    acc = g.let(0.0, "PP")
    k = g.counter("K")
    with g.b.for_(k, 0, nl - 1) as kv:
        c = g.let(p0[kv] + (p1[kv] - p0[kv]) * s, "PC")
        g.b.set(acc, acc + c - acc * c)
    return acc


def _piece(
    g: Gen,
    xa: Var,
    xb: Var,
    v0: Var,
    v1: Var,
    p0: Var,
    p1: Var,
    nl: Var,
    pr: Var | None,
    gl: tuple[Var, Var, Var, Var] | None,
    method: str,
    pv: Var,
    L: dict[str, Var],
    st: dict[str, Var],
) -> None:
    b = g.b
    pdx = g.let(xb - xa, "PDX")
    pa = g.temp(hint="PA")
    pm = g.temp(hint="PM")

    def linear() -> None:
        b.set(pa, 0.5 * pdx * (v0 + v1))
        b.set(pm, pdx * (xa * (2.0 * v0 + v1) + xb * (v0 + 2.0 * v1)) / 6.0)

    if pr is not None and gl is not None:
        glx, glw, gln, glo = gl
        with b.if_(pr):
            a = g.let(0.0, "GA")
            mo = g.let(0.0, "GM")
            q = g.counter("Q")
            with b.for_(q, 0, gln[nl] - 1) as qv:
                s = g.let(glx[glo[nl] + qv], "S")
                f = _poly(g, p0, p1, nl, s)
                b.set(a, a + glw[glo[nl] + qv] * f)
                b.set(mo, mo + glw[glo[nl] + qv] * f * (xa + s * pdx))
            b.set(pa, a * pdx)
            b.set(pm, mo * pdx)
        with b.else_():
            linear()
    else:
        linear()
    acc_a, acc_m = L["acc_a"], L["acc_m"]
    if method == "COG":
        b.set(acc_a, acc_a + pa)
        b.set(acc_m, acc_m + pm)
        return
    if method == "COA":
        with b.if_(pv.eq(1)):
            b.set(acc_a, acc_a + pa)
            with b.if_(xb.gt(xa)):
                with b.if_(not_(st["HAVE"])):
                    b.set(st["FX0"], xa)
                    b.set(st["HAVE"], True)
                b.set(st["LX1"], xb)
        for side, p_no in (("L", 2), ("R", 3)):
            found, cum = st["FOUNDL" if side == "L" else "FOUNDR"], st["CUM" if side == "L" else "CUMR"]
            with b.if_(pv.eq(p_no).and_(xb.gt(xa)).and_(not_(found))):
                with b.if_(pa.gt(0.0).and_((cum + pa).ge(st["HALF"]))):
                    r = st["HALF"] - cum if side == "L" else pa - (st["HALF"] - cum)
                    x = _solve(g, xa, xb, v0, v1, pdx, g.let(r, "RR"), p0, p1, nl, pr, gl)
                    b.set(st["LEFT" if side == "L" else "RIGHT"], x)
                    b.set(found, True)
                with b.else_():
                    b.set(cum, cum + pa)
        return
    # LM / RM / MoM
    with b.if_(pv.eq(1)):
        b.set(acc_a, acc_a + pa)
        with b.if_(v0.gt(st["SUP"])):
            b.set(st["SUP"], v0)
        with b.if_(v1.gt(st["SUP"])):
            b.set(st["SUP"], v1)
    with b.else_():
        with b.if_(v0.ge(st["THR"])):
            _candidate(g, xa, st)
        with b.if_(v1.ge(st["THR"])):
            _candidate(g, xb, st)
        with b.if_(v0.ge(st["THR"]).and_(v1.ge(st["THR"])).and_(xb.gt(xa))):
            b.set(st["PLEN"], st["PLEN"] + pdx)
            b.set(st["PMOM"], st["PMOM"] + pdx * 0.5 * (xa + xb))


def _solve(
    g: Gen,
    xa: Var,
    xb: Var,
    v0: Var,
    v1: Var,
    pdx: Var,
    r: Var,
    p0: Var,
    p1: Var,
    nl: Var,
    pr: Var | None,
    gl: tuple[Var, Var, Var, Var] | None,
) -> Var:
    """pwl._solve_in_piece: where the area from the piece's start reaches ``r``."""
    b = g.b
    out = g.temp(hint="SOL")

    def linear() -> None:
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

    if pr is None or gl is None:
        linear()
        return out
    glx, glw, gln, glo = gl
    with b.if_(pr):
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
                    f = _poly(g, p0, p1, nl, glx[glo[nl] + qv] * mid)
                    b.set(part, part + glw[glo[nl] + qv] * f)
                with b.if_((pdx * mid * part).lt(r)):
                    b.set(lo, mid)
                with b.else_():
                    b.set(hi, mid)
                b.set(it, it + 1)
                with b.if_(it.ge(200)):
                    b.set(go, False)
        b.set(out, xa + 0.5 * (lo + hi) * pdx)
    with b.else_():
        linear()
    return out
