"""Exact defuzzification of piecewise-linear Mamdani outputs as run-time loops.

The generated code does at run time what :mod:`fuzzyctl.engine.grid` and
:mod:`fuzzyctl.engine.pwl` do: sort each term's points, cut ``[low, high]`` at every
breakpoint of the output's terms, and on each interval cut again where MIN activation clips a
term and where activated sets cross (MAX) or their sum crosses 1 (BSUM); between those cuts
the accumulated set is linear (or, for PROBOR, a product of linear factors integrated with
Gauss-Legendre nodes exact for its degree).  CoG sums closed-form areas and moments, CoA solves
the quadratic of the piece holding half the area, LM/RM/MoM scan the pieces' ends.  Because
the grid is built at run time, term points stay tunable online.

The pieces are never stored: methods needing several looks (CoA: the total, then from the
left, then from the right; LM/RM/MoM: the height, then where it is reached) run the same loop
several times (``pass``), so memory is bounded by the number of activated sets, not by the
number of pieces.  All exact outputs of a block share ONE copy of the algorithm: a loop over
the outputs reads each one's range, method, accumulation, terms and activated sets from
tables, which keeps the Structured Text short.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

from fuzzyctl.codegen import terms as T
from fuzzyctl.codegen.context import Gen
from fuzzyctl.codegen.ir import Ex, Index, Type, Var, ex, not_
from fuzzyctl.engine.pwl import MAX_TOL, gauss_legendre

METHODS = {"COG": 1, "COA": 2, "LM": 3, "RM": 4, "MOM": 5}
ACCUS = {"MAX": 1, "SUM": 2, "NSUM": 2, "BSUM": 3, "PROBOR": 4}


@dataclass
class Group:
    """One activated set: ``w * min(a, term)`` (``is_min``) or ``w * a * term``."""

    term: int
    a: Ex
    w: Ex
    is_min: bool


@dataclass
class ExactOutput:
    name: str
    method: str
    accu: str
    low: float
    high: float
    points: list[list[tuple[Ex, Ex]]]  # per term: its breakpoints (x, y)
    groups: list[Group]


def _const(g: Gen, hint: str, type_: Type, values: Sequence[float], comment: str = "") -> Var:
    init = tuple(float(v) for v in values)
    return g.declare(g.fresh(hint, hint), type_, "const", len(values), init, comment)


def exact_outputs(g: Gen, outs: list[ExactOutput]) -> tuple[Var, Var]:
    """Emit the defuzzification of every exact output; returns the arrays (value, fired),
    indexed like ``outs``."""
    b = g.b
    n_out = len(outs)
    methods = {o.method for o in outs}
    accus = {ACCUS[o.accu] for o in outs if len(o.groups) > 1}
    maxima = bool(methods & {"LM", "RM", "MOM"})
    # ---- tables: terms and their points, activated sets, per-output data
    term_pts: list[list[tuple[Ex, Ex]]] = []
    out_t0, out_t1, out_p0, out_p1, out_g0, out_g1 = [], [], [], [], [], []
    groups: list[Group] = []
    for o in outs:
        base_t = len(term_pts)
        out_t0.append(base_t)
        out_p0.append(sum(len(p) for p in term_pts))
        term_pts.extend(o.points)
        out_t1.append(len(term_pts) - 1)
        out_p1.append(sum(len(p) for p in term_pts) - 1)
        out_g0.append(len(groups))
        groups.extend(Group(gr.term + base_t, gr.a, gr.w, gr.is_min) for gr in o.groups)
        out_g1.append(len(groups) - 1)
    counts = [len(p) for p in term_pts]
    offs = [sum(counts[:t]) for t in range(len(term_pts))]
    n_pts, n_terms, n_groups = sum(counts), len(term_pts), len(groups)
    max_pts = max(p1 - p0 + 1 for p0, p1 in zip(out_p0, out_p1, strict=True))
    max_groups = max(max(1, len(o.groups)) for o in outs)

    value = g.array("OVAL", "REAL", n_out)
    fired = g.array("OFIRED", "BOOL", n_out)
    if n_groups == 0:
        with b.for_(g.counter("O"), 0, n_out - 1) as ov:
            b.set(value[ov], 0.0)
            b.set(fired[ov], False)
        return value, fired

    # ---- the output geometry (sorted points, grids, one-sided limits, degrees at grid
    # points) depends only on the term points: it is kept in the instance and rebuilt only
    # when a point changed (retuned online, or given by an input that moved)
    rx = g.array("RX", "REAL", n_pts)
    ry = g.array("RY", "REAL", n_pts)
    for t, pts in enumerate(term_pts):
        for k, (x, y) in enumerate(pts):
            b.set(rx[offs[t] + k], x)
            b.set(ry[offs[t] + k], y)
    toff = _const(g, "TOFF", "INT", offs, "first point of each output term")
    tlast = _const(g, "TLAST", "INT", [o + c - 1 for o, c in zip(offs, counts, strict=True)])
    term_out = [oi for oi, o in enumerate(outs) for _t in o.points]
    grid_size = [p1 - p0 + 3 for p0, p1 in zip(out_p0, out_p1, strict=True)]  # points + low, high
    goff = [sum(grid_size[:oi]) for oi in range(n_out)]
    loff = [sum(grid_size[term_out[t]] for t in range(u)) for u in range(n_terms)]
    n_lim = sum(grid_size[term_out[t]] for t in range(n_terms))
    cache = {
        "CX": g.declare(g.fresh("CX", "CX"), "REAL", "state", n_pts, (0.0,) * n_pts, "cached term points"),
        "CY": g.declare(g.fresh("CY", "CY"), "REAL", "state", n_pts, (0.0,) * n_pts),
        "SX": g.declare(g.fresh("SX", "SX"), "REAL", "state", n_pts, (0.0,) * n_pts, "sorted term points"),
        "SY": g.declare(g.fresh("SY", "SY"), "REAL", "state", n_pts, (0.0,) * n_pts),
        "SGX": g.declare(
            g.fresh("SGX", "SGX"), "REAL", "state", sum(grid_size), (0.0,) * sum(grid_size), "grids"
        ),
        "SNG": g.declare(g.fresh("SNG", "SNG"), "INT", "state", n_out, (0.0,) * n_out, "grid sizes"),
        "SLT": g.declare(
            g.fresh("SLT", "SLT"), "REAL", "state", n_lim, (0.0,) * n_lim, "term limits from the right"
        ),
        "SRT": g.declare(
            g.fresh("SRT", "SRT"), "REAL", "state", n_lim, (0.0,) * n_lim, "term limits from the left"
        ),
        "SMU": g.declare(
            g.fresh("SMU", "SMU"), "REAL", "state", n_lim, (0.0,) * n_lim, "term degrees at grid points"
        ),
        "VALID": g.declare(g.fresh("CVALID", "CVALID"), "BOOL", "state", None, False, "cache filled"),
        "GOFF": _const(g, "GOFF", "INT", goff, "first grid point of each output"),
        "LOFF": _const(g, "LOFF", "INT", loff, "first cache entry of each term"),
    }
    wx, wy = cache["SX"], cache["SY"]
    gt = _const(g, "GT", "INT", [gr.term for gr in groups], "term of each activated set")
    gmin = _const(g, "GMIN", "BOOL", [gr.is_min for gr in groups], "MIN activation (else PROD)")
    ga = g.array("GA", "REAL", n_groups)
    gw = g.array("GW", "REAL", n_groups)
    for i, gr in enumerate(groups):
        b.set(ga[i], gr.a)
        b.set(gw[i], gr.w)

    tab = {
        "T0": _const(g, "OT0", "INT", out_t0),
        "T1": _const(g, "OT1", "INT", out_t1),
        "P0": _const(g, "OP0", "INT", out_p0),
        "P1": _const(g, "OP1", "INT", out_p1),
        "G0": _const(g, "OG0", "INT", out_g0),
        "G1": _const(g, "OG1", "INT", out_g1),
        "MC": _const(g, "OMC", "INT", [METHODS[o.method] for o in outs], "1 CoG, 2 CoA, 3 LM, 4 RM, 5 MoM"),
        "AC": _const(g, "OAC", "INT", [ACCUS[o.accu] for o in outs], "1 MAX, 2 SUM/NSUM, 3 BSUM, 4 PROBOR"),
        "LOW": _const(g, "OLOW", "REAL", [o.low for o in outs], "defuzzification range"),
        "HIGH": _const(g, "OHIGH", "REAL", [o.high for o in outs]),
    }
    v: dict[str, Var] = {}
    scalars: tuple[tuple[str, Type], ...] = (
        ("O", "INT"),
        ("MC", "INT"),
        ("AC", "INT"),
        ("LOW", "REAL"),
        ("HIGH", "REAL"),
        ("NG", "INT"),
        ("NL", "INT"),
        ("NT", "INT"),
        ("NC", "INT"),
        ("J", "INT"),
        ("V0", "REAL"),
        ("V1", "REAL"),
        ("AREA", "REAL"),
        ("MOM", "REAL"),
    )
    for name, typ in scalars:
        v[name] = g.temp(typ, name)
    probor = 4 in accus
    if probor:
        v["PR"] = g.temp("BOOL", "PR")
    st = _method_state(g, methods)
    arrays = {
        "GX": g.array("GX", "REAL", max_pts + 2),
        "LL": g.array("LL", "REAL", max_groups),
        "LR": g.array("LR", "REAL", max_groups),
        "LA": g.array("LA", "REAL", max_groups),
        "LW": g.array("LW", "REAL", max_groups),
        "LMIN": g.array("LMIN", "BOOL", max_groups),
        "KINK": g.array("KINK", "REAL", max_groups),
        "TS": g.array("TS", "REAL", max_groups + 2),
        "P0": g.array("P0", "REAL", max_groups),
        "P1": g.array("P1", "REAL", max_groups),
        "CUT": g.array("CUT", "REAL", max(1, max_groups * (max_groups - 1) // 2)),
        "CV": g.array("CV", "REAL", max(1, max_groups * (max_groups - 1) // 2)),
    }
    gl = _gl_tables(g, max_groups) if probor else None
    ctx = _Ctx(g, v, arrays, st, gl, methods, accus, wx, wy, toff, tlast, gt, gmin, ga, gw)

    o_ = v["O"]
    _rebuild_cache(ctx, cache, rx, ry, n_pts, n_terms, n_out, tab)
    ov = Var(g.counter("OO"))
    with b.for_(ov.name, 0, n_out - 1):
        b.set(o_, ov)
        b.set(v["MC"], tab["MC"][o_])
        b.set(v["AC"], tab["AC"][o_])
        b.set(v["LOW"], tab["LOW"][o_])
        b.set(v["HIGH"], tab["HIGH"][o_])
        b.set(v["NG"], cache["SNG"][o_])
        b.set(v["AREA"], 0.0)
        b.set(v["MOM"], 0.0)
        for name, (typ, init) in _STATE.items():
            if name in st:
                b.set(st[name], ex(init) if typ != "REAL" else float(init))
        n_pass = g.temp("INT", "NPASS")
        b.set(n_pass, 1)
        with b.if_(v["MC"].eq(METHODS["COA"])):
            b.set(n_pass, 3)
        with b.elif_(v["MC"].ge(METHODS["LM"])):
            b.set(n_pass, 2)
        ps = Var(g.counter("PASS"))
        with b.for_(ps.name, 1, n_pass):
            ctx.pass_ = ps
            forward = ps.ne(3)
            ctx.forward = forward
            if "COA" in methods:
                with b.if_(ps.eq(2)):
                    b.set(st["HALF"], 0.5 * v["AREA"])
            if maxima:
                with b.if_(ps.eq(2)):
                    b.set(st["THR"], st["SUP"] * (1.0 - MAX_TOL))
            jj = g.counter("JJ")
            j, ng = v["J"], v["NG"]
            with b.for_(jj, 0, ng - 1) as jv:
                with b.if_(forward):
                    b.set(j, jv)
                with b.else_():
                    b.set(j, ng - 2 - jv)
                gx = cache["SGX"]
                gbase = cache["GOFF"][o_]
                if maxima:
                    with b.if_(v["MC"].ge(METHODS["LM"])):
                        _grid_point(ctx, gx[gbase + j], j, cache, tab["G0"][o_], tab["G1"][o_])
                with b.if_(j.ge(0).and_(j.le(ng - 2))):
                    _interval_lines(ctx, gx[gbase + j], gx[gbase + j + 1], j, cache, tab)
        _finish(ctx, value[o_], fired[o_])
    return value, fired


_STATE: dict[str, tuple[Type, float]] = {
    # CoA
    "HALF": ("REAL", 0.0),
    "CUM": ("REAL", 0.0),
    "CUMR": ("REAL", 0.0),
    "LEFT": ("REAL", 0.0),
    "RIGHT": ("REAL", 0.0),
    "FX0": ("REAL", 0.0),
    "LX1": ("REAL", 0.0),
    "HAVE": ("BOOL", False),
    "FOUNDL": ("BOOL", False),
    "FOUNDR": ("BOOL", False),
    # LM / RM / MoM
    "SUP": ("REAL", 0.0),
    "THR": ("REAL", 0.0),
    "LMX": ("REAL", 0.0),
    "RMX": ("REAL", 0.0),
    "PLEN": ("REAL", 0.0),
    "PMOM": ("REAL", 0.0),
    "ISUM": ("REAL", 0.0),
    "LASTX": ("REAL", 0.0),
    "ICNT": ("INT", 0),
}
_COA_STATE = ("HALF", "CUM", "CUMR", "LEFT", "RIGHT", "FX0", "LX1", "HAVE", "FOUNDL", "FOUNDR")


def _method_state(g: Gen, methods: set[str]) -> dict[str, Var]:
    st: dict[str, Var] = {}
    for name, (typ, _init) in _STATE.items():
        coa = name in _COA_STATE
        if (coa and "COA" in methods) or (not coa and methods & {"LM", "RM", "MOM"}):
            st[name] = g.temp(typ, name)
    return st


@dataclass
class _Ctx:
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


def _grid(c: _Ctx, p0: Ex, p1: Ex) -> None:
    """grid.build_grid: [low, high] and every breakpoint strictly inside, sorted, unique."""
    g, b = c.g, c.g.b
    gx, ng, low, high = c.a["GX"], c.v["NG"], c.v["LOW"], c.v["HIGH"]
    b.set(gx[0], low)
    b.set(gx[1], high)
    b.set(ng, 2)
    k = g.counter("K")
    with b.for_(k, p0, p1) as kv, b.if_(c.wx[kv].gt(low).and_(c.wx[kv].lt(high))):
        b.set(gx[ng], c.wx[kv])
        b.set(ng, ng + 1)
    T.sort_points(g, gx, None, 0, ng - 1)
    _dedupe(g, gx, ng)


def _dedupe(g: Gen, arr: Var, n: Var) -> None:
    """Drop repeated values from a sorted array (Python's sorted(set(...)))."""
    b = g.b
    wr = g.temp("INT", "W")
    b.set(wr, 0)
    k = g.counter("K")
    with b.for_(k, 1, n - 1) as kv, b.if_(arr[kv].ne(arr[wr])):
        b.set(wr, wr + 1)
        b.set(arr[wr], arr[kv])
    b.set(n, wr + 1)


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
    return (
        _const(g, "GLX", "REAL", xs or [0.0], "Gauss-Legendre nodes on [0, 1]"),
        _const(g, "GLW", "REAL", ws or [0.0], "Gauss-Legendre weights"),
        _const(g, "GLN", "INT", counts, "nodes used for n factors"),
        _const(g, "GLO", "INT", offs),
    )


def _rebuild_cache(
    c: _Ctx,
    cache: dict[str, Var],
    rx: Var,
    ry: Var,
    n_pts: int,
    n_terms: int,
    n_out: int,
    tab: dict[str, Var],
) -> None:
    """Compare the term points with the cached copy; when one differs, sort them again and
    rebuild every output's grid, the terms' one-sided limits on each grid interval and their
    degrees at each grid point (grid.build_grid: left/right/point)."""
    g, b = c.g, c.g.b
    changed = g.let(not_(cache["VALID"]), "CHANGED", "BOOL")
    k = g.counter("K")
    with b.for_(k, 0, n_pts - 1) as kv, b.if_(rx[kv].ne(cache["CX"][kv]).or_(ry[kv].ne(cache["CY"][kv]))):
        b.set(changed, True)
    with b.if_(changed):
        with b.for_(k, 0, n_pts - 1) as kv:
            for src, dst in ((rx, "CX"), (ry, "CY"), (rx, "SX"), (ry, "SY")):
                b.set(cache[dst][kv], src[kv])
        tt = g.counter("TT")
        with b.for_(tt, 0, n_terms - 1) as tv:
            T.sort_points(g, c.wx, c.wy, c.toff[tv], c.tlast[tv])
        oo = g.counter("O")
        gx, ng = c.a["GX"], c.v["NG"]
        with b.for_(oo, 0, n_out - 1) as ov:
            b.set(c.v["LOW"], tab["LOW"][ov])
            b.set(c.v["HIGH"], tab["HIGH"][ov])
            _grid(c, tab["P0"][ov], tab["P1"][ov])
            b.set(cache["SNG"][ov], ng)
            jj = g.counter("J")
            with b.for_(jj, 0, ng - 1) as jv:
                b.set(cache["SGX"][cache["GOFF"][ov] + jv], gx[jv])
                with b.for_(tt, tab["T0"][ov], tab["T1"][ov]) as tv:
                    at = cache["LOFF"][tv] + jv
                    b.set(cache["SMU"][at], T.pwl_value(g, c.wx, c.wy, c.toff[tv], c.tlast[tv], gx[jv]))
                    b.set(cache["SLT"][at], 0.0)
                    b.set(cache["SRT"][at], 0.0)
                    with b.if_(jv.lt(ng - 1)):
                        b.set(cache["SLT"][at], T.right_limit(g, c.wx, c.wy, c.toff[tv], c.tlast[tv], gx[jv]))
                        b.set(
                            cache["SRT"][at], T.left_limit(g, c.wx, c.wy, c.toff[tv], c.tlast[tv], gx[jv + 1])
                        )
        b.set(cache["VALID"], True)


def _grid_point(c: _Ctx, x: Ex, j: Var, cache: dict[str, Var], g0: Ex, g1: Ex) -> None:
    """The accumulated degree exactly at a grid point (pwl.point_values): it can be the
    maximum at a vertical edge."""
    g, b, st = c.g, c.g.b, c.st
    xp = g.let(x, "XP")
    pv = g.let(0.0, "PV")
    gg = g.counter("G")
    with b.for_(gg, g0, g1) as gv, b.if_((c.ga[gv] * c.gw[gv]).gt(0.0)):
        y = g.let(cache["SMU"][cache["LOFF"][c.gt[gv]] + j], "MU")
        cc = g.temp(hint="PC")
        with b.if_(c.gmin[gv]):
            b.set(cc, c.gw[gv] * g.min_(c.ga[gv], y))
        with b.else_():
            b.set(cc, c.gw[gv] * (c.ga[gv] * y))
        _accumulate_dynamic(c, pv, cc)
    assert c.pass_ is not None
    with b.if_(c.pass_.eq(1)), b.if_(pv.gt(st["SUP"])):
        b.set(st["SUP"], pv)
    with b.elif_(pv.ge(st["THR"])):
        _candidate(c, xp)


def _accumulate_dynamic(c: _Ctx, acc: Var, val: Ex) -> None:
    """acc := accumulate(accu of the current output, acc, val)."""
    g, b = c.g, c.g.b
    present = [
        (code, name) for name, code in (("MAX", 1), ("SUM", 2), ("BSUM", 3), ("PROBOR", 4)) if code in c.accus
    ] or [(1, "MAX")]
    for i, (code, name) in enumerate(present):
        ctx_mgr = b.if_(c.v["AC"].eq(code)) if i == 0 else b.elif_(c.v["AC"].eq(code))
        with ctx_mgr:
            b.set(acc, T.accumulate(g, name, acc, val))


def _candidate(c: _Ctx, x: Ex) -> None:
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
        with b.if_(x.ne(st["LASTX"])):
            b.set(st["ISUM"], st["ISUM"] + x)
            b.set(st["ICNT"], st["ICNT"] + 1)
            b.set(st["LASTX"], x)


def _interval_lines(c: _Ctx, gx0: Ex, gx1: Ex, j: Var, cache: dict[str, Var], tab: dict[str, Var]) -> None:
    """The activated sets on one grid interval as lines (L, R, a, w, is_min), then the
    interval's pieces."""
    g, b, v, a = c.g, c.g.b, c.v, c.a
    o_ = v["O"]
    x0 = g.let(gx0, "X0")
    x1 = g.let(gx1, "X1")
    nl = v["NL"]
    b.set(nl, 0)
    gg = g.counter("G")
    with b.for_(gg, tab["G0"][o_], tab["G1"][o_]) as gv:
        at = g.let(cache["LOFF"][c.gt[gv]] + j, "AT", "INT")
        lt_, rt_ = cache["SLT"][at], cache["SRT"][at]
        with b.if_((c.ga[gv] * c.gw[gv]).gt(0.0).and_(lt_.ne(0.0).or_(rt_.ne(0.0)))):
            b.set(a["LL"][nl], lt_)
            b.set(a["LR"][nl], rt_)
            b.set(a["LA"][nl], c.ga[gv])
            b.set(a["LW"][nl], c.gw[gv])
            b.set(a["LMIN"][nl], c.gmin[gv])
            b.set(nl, nl + 1)
    with b.if_(nl.gt(0)):
        _interval(c, x0, x1)


def _interval(c: _Ctx, x0: Var, x1: Var) -> None:
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
    _dedupe(g, ts, nt)
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


def _combine(c: _Ctx, xa: Var, xb: Var) -> None:
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


def _poly(c: _Ctx, s: Ex) -> Var:
    """1 - prod(1 - c_k(s)), folded as acc + c - acc*c (pwl._poly_value)."""
    g = c.g
    p0, p1, nl = c.a["P0"], c.a["P1"], c.v["NL"]
    acc = g.let(0.0, "PP")
    k = g.counter("K")
    with g.b.for_(k, 0, nl - 1) as kv:
        cc = g.let(p0[kv] + (p1[kv] - p0[kv]) * s, "PC")
        g.b.set(acc, acc + cc - acc * cc)
    return acc


def _piece(c: _Ctx, xa: Var, xb: Var, v0: Var, v1: Var) -> None:
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

    if "COG" in c.methods:
        with branch(mc.eq(METHODS["COG"])):
            b.set(area, area + pa)
            b.set(mom, mom + pm)
    if "COA" in c.methods:
        with branch(mc.eq(METHODS["COA"])):
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
                    with b.if_(pa.gt(0.0).and_((cum + pa).ge(st["HALF"]))):
                        r = g.temp(hint="RR")
                        with b.if_(ps.eq(2)):
                            b.set(r, st["HALF"] - cum)
                        with b.else_():
                            b.set(r, pa - (st["HALF"] - cum))
                        x = _solve(c, xa, xb, v0, v1, pdx, r)
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
    if c.methods & {"LM", "RM", "MOM"}:
        with branch(mc.ge(METHODS["LM"])):
            with b.if_(ps.eq(1)):
                b.set(area, area + pa)
                with b.if_(v0.gt(st["SUP"])):
                    b.set(st["SUP"], v0)
                with b.if_(v1.gt(st["SUP"])):
                    b.set(st["SUP"], v1)
            with b.else_():
                with b.if_(v0.ge(st["THR"])):
                    _candidate(c, xa)
                with b.if_(v1.ge(st["THR"])):
                    _candidate(c, xb)
                with b.if_(v0.ge(st["THR"]).and_(v1.ge(st["THR"])).and_(xb.gt(xa))):
                    b.set(st["PLEN"], st["PLEN"] + pdx)
                    b.set(st["PMOM"], st["PMOM"] + pdx * 0.5 * (xa + xb))


def _solve(c: _Ctx, xa: Var, xb: Var, v0: Var, v1: Var, pdx: Var, r: Var) -> Var:
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
    return out


def _finish(c: _Ctx, value: Index, fired: Index) -> None:
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
    if "COG" in c.methods:
        with branch(mc.eq(METHODS["COG"]).and_(v["AREA"].gt(0.0))):
            b.set(value, v["MOM"] / v["AREA"])
    if "COA" in c.methods:
        with branch(mc.eq(METHODS["COA"])):
            with b.if_(not_(st["FOUNDL"])):
                b.set(st["LEFT"], st["LX1"])
            with b.if_(not_(st["FOUNDR"])):
                b.set(st["RIGHT"], st["FX0"])
            b.set(value, 0.5 * (st["LEFT"] + st["RIGHT"]))
    if "LM" in c.methods:
        with branch(mc.eq(METHODS["LM"])):
            b.set(value, st["LMX"])
    if "RM" in c.methods:
        with branch(mc.eq(METHODS["RM"])):
            b.set(value, st["RMX"])
    if "MOM" in c.methods:
        with branch(mc.eq(METHODS["MOM"])):
            with b.if_(st["PLEN"].gt(0.0)):
                b.set(value, st["PMOM"] / st["PLEN"])
            with b.elif_(st["ICNT"].gt(0)):
                b.set(value, st["ISUM"] / c.g.call("TO_REAL", st["ICNT"]))
