"""Exact defuzzification of piecewise-linear Mamdani outputs as run-time loops.

The generated code does at run time what :mod:`fuzzyctl.engine.lowering.grid` and
:mod:`fuzzyctl.engine.reference.pwl` do: sort each term's points, cut ``[low, high]`` at every
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

from fuzzyctl.engine.plan import GridPlan, Slot, TermPlan
from fuzzyctl.engine.reference import pwl
from fuzzyctl.engine.reference.pwl import MAX_TOL, gauss_legendre
from fuzzyctl.ir.builders import terms as T
from fuzzyctl.ir.builders.pieces import (
    ACCUS,
    METHODS,
    Ctx,
    accumulate_dynamic,
    candidate,
    code_test,
    dedupe,
    finish,
    having,
    interval,
)
from fuzzyctl.ir.builders.rules import Params, RuleBuilder
from fuzzyctl.ir.nodes import Ex, Num, Type, Var, ex, not_
from fuzzyctl.ir.state import Gen
from fuzzyctl.kinds import shapes as registry


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


def term_points(rb: RuleBuilder, t: TermPlan, xs: Params, ys: Params, where: str) -> list[tuple[Ex, Ex]]:
    """A piecewise-linear term as breakpoints (x, y) in the engine's order
    (shapes.pwl_points): constant ones as ``xs``/``ys`` entries (tunable in the PLC block,
    literals in the evaluator), points given by inputs as those inputs."""
    if t.pwl is not None:
        return [(xs.add(x, f"{where} x{k}"), ys.add(y, f"{where} y{k}")) for k, (x, y) in enumerate(t.pwl)]
    h = t.height
    if isinstance(h, Slot):
        raise rb.g.refuse(where, "a height given by a variable")
    if t.kind == "points":
        out = []
        for k in range(0, len(t.params), 2):
            px, py = t.params[k], t.params[k + 1]
            x = rb.pv(px, xs, f"{where} x{k // 2}")
            y: Ex
            if isinstance(py, Slot):
                y = rb.inputs[py.index] if h == 1.0 else rb.inputs[py.index] * Num(h)
            else:
                y = ys.add(py * h, f"{where} y{k // 2}")
            out.append((x, y))
        return out
    vertices = registry.vertices(t.kind)
    if vertices is not None:  # the parameters are the x of the breakpoints
        ylist = [v * h for v in vertices]
        return [
            (rb.pv(p, xs, f"{where} x{k}"), ys.add(y, f"{where} y{k}"))
            for k, (p, y) in enumerate(zip(t.params, ylist, strict=True))
        ]
    raise rb.g.refuse(
        where,
        f"{t.kind} with parameters given by variables (its breakpoints change form with the "
        "order of its parameters; write it as points)",
    )


def _const(g: Gen, hint: str, type_: Type, values: Sequence[float], comment: str = "") -> Var:
    init = tuple(float(v) for v in values)
    return g.declare(g.fresh(hint, hint), type_, "const", len(values), init, comment)


def exact_outputs(
    g: Gen, outs: list[ExactOutput], grids: Sequence[GridPlan] | None = None
) -> tuple[Var, Var]:
    """Emit the defuzzification of every exact output; returns the arrays (value, fired),
    indexed like ``outs``.  With ``grids`` (one per output: its constant points cut at
    generation, the evaluator of ``compile()``) the geometry is constant tables; without,
    it is rebuilt at run time when a point changed (the PLC block: points tunable online)."""
    b = g.b
    n_out = len(outs)
    methods = {o.method for o in outs}
    for o in outs:
        if o.method not in METHODS:  # a method of a new kind: only its constant-grid IR exists
            raise g.refuse(f"output {o.name}", f"METHOD {o.method} on a grid cut at run time")
    accus = {ACCUS[o.accu] for o in outs if len(o.groups) > 1}
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
    if grids is None:
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
    if grids is not None:
        cache = _static_cache(g, grids, term_out)
    else:
        cache = _cache(g, n_pts, grid_size, n_out, n_lim, goff, loff)
    # the sorted points are read only where the geometry is rebuilt (never when constant)
    wx, wy = (cache["SX"], cache["SY"]) if grids is None else (cache["SGX"], cache["SGX"])
    gt = _const(g, "GT", "INT", [gr.term for gr in groups], "term of each activated set")
    gmin = _const(g, "GMIN", "BOOL", [gr.is_min for gr in groups], "MIN activation (else PROD)")
    ga = g.array("GA", "REAL", n_groups)
    gw = g.array("GW", "REAL", n_groups)
    for i, gr in enumerate(groups):
        b.set(ga[i], gr.a)
        b.set(gw[i], gr.w)
    for g0, g1 in zip(out_g0, out_g1, strict=True):
        _scale_tiny(g, ga, g0, g1)

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
    v, arrays, st, gl = _work_variables(g, methods, accus, max_pts, max_groups)
    ctx = Ctx(g, v, arrays, st, gl, methods, accus, wx, wy, toff, tlast, gt, gmin, ga, gw)

    if grids is None:
        _rebuild_cache(ctx, cache, rx, ry, n_pts, n_terms, n_out, tab)
    _each_output(ctx, cache, tab, value, fired, n_out)
    return value, fired


def _work_variables(
    g: Gen, methods: set[str], accus: set[int], max_pts: int, max_groups: int
) -> tuple[dict[str, Var], dict[str, Var], dict[str, Var], tuple[Var, Var, Var, Var] | None]:
    """The scratch variables and arrays of the defuzzification loop."""
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
    gl = gl_tables(g, max_groups) if probor else None
    return v, arrays, st, gl


def _scale_tiny(g: Gen, ga: Var, g0: int, g1: int) -> None:
    """``pwl.tiny_degree_scale`` on one output's degrees ``ga[g0..g1]``: the same
    power-of-two steps as every other path, so subnormal degrees do not underflow the
    areas and moments (exact scaling)."""
    if g1 < g0:
        return
    b = g.b
    top = g.let(ga[g0], "TOP")
    for i in range(g0 + 1, g1 + 1):
        with b.if_(ga[i].gt(top)):
            b.set(top, ga[i])
    low = top.lt(pwl.TINY_BELOW)  # checked once outside: the usual case costs one test
    with b.if_(low), b.for_(g.counter("K"), 1, pwl.TINY_COUNT), b.if_(low):
        b.set(top, top * pwl.TINY_FACTOR)
        with b.for_(g.counter("I"), g0, g1) as gi:
            b.set(ga[gi], ga[gi] * pwl.TINY_FACTOR)


def _each_output(
    ctx: Ctx, cache: dict[str, Var], tab: dict[str, Var], value: Var, fired: Var, n_out: int
) -> None:
    """One loop over the outputs: each output's grid intervals in one to three passes (CoG
    one, LM/RM/MoM two: the height, then where it is reached; CoA three: the total, then
    from the left and from the right)."""
    g, b, v, st = ctx.g, ctx.g.b, ctx.v, ctx.st
    methods = ctx.methods
    maxima = bool(having(methods, lambda m: m.maximum is not None))
    o_ = v["O"]
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
        with b.if_(code_test(v["MC"], lambda m: m.bisects)):
            b.set(n_pass, 3)
        with b.elif_(code_test(v["MC"], lambda m: m.maximum is not None)):
            b.set(n_pass, 2)
        ps = Var(g.counter("PASS"))
        with b.for_(ps.name, 1, n_pass):
            ctx.pass_ = ps
            forward = ps.ne(3)
            ctx.forward = forward
            if having(methods, lambda m: m.bisects):
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
                    with b.if_(code_test(v["MC"], lambda m: m.maximum is not None)):
                        _grid_point(ctx, gx[gbase + j], j, cache, tab["G0"][o_], tab["G1"][o_])
                with b.if_(j.ge(0).and_(j.le(ng - 2))):
                    _interval_lines(ctx, gx[gbase + j], gx[gbase + j + 1], j, cache, tab)
        finish(ctx, value[o_], fired[o_])


def _cache(
    g: Gen, n_pts: int, grid_size: list[int], n_out: int, n_lim: int, goff: list[int], loff: list[int]
) -> dict[str, Var]:
    """The instance's copy of the output geometry (rebuilt when a term point changes)."""
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
    return cache


def _static_cache(g: Gen, grids: Sequence[GridPlan], term_out: list[int]) -> dict[str, Var]:
    """The output geometry as constant tables (the same entries :func:`_rebuild_cache`
    computes at run time, read off each output's :class:`GridPlan`)."""
    gx: list[float] = []
    goff: list[int] = []
    for grid in grids:
        goff.append(len(gx))
        gx.extend(grid.xs)
    loff: list[int] = []
    lt: list[float] = []
    rt: list[float] = []
    mu: list[float] = []
    local = 0
    for t, oi in enumerate(term_out):
        local = 0 if t == 0 or term_out[t - 1] != oi else local + 1
        grid = grids[oi]
        n = len(grid.xs)
        loff.append(len(mu))
        mu.extend(grid.point[local])
        lt.extend([*grid.left[local], 0.0])
        rt.extend([*grid.right[local], 0.0])
        assert len(mu) == len(lt) == len(rt) and n == len(grid.point[local])
    return {
        "SGX": _const(g, "SGX", "REAL", gx or [0.0], "grids"),
        "SNG": _const(g, "SNG", "INT", [len(gr.xs) for gr in grids], "grid sizes"),
        "SLT": _const(g, "SLT", "REAL", lt or [0.0], "term limits from the right"),
        "SRT": _const(g, "SRT", "REAL", rt or [0.0], "term limits from the left"),
        "SMU": _const(g, "SMU", "REAL", mu or [0.0], "term degrees at grid points"),
        "GOFF": _const(g, "GOFF", "INT", goff, "first grid point of each output"),
        "LOFF": _const(g, "LOFF", "INT", loff or [0], "first table entry of each term"),
    }


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
    coa = bool(having(methods, lambda m: m.bisects))
    maxima = bool(having(methods, lambda m: m.maximum is not None))
    for name, (typ, _init) in _STATE.items():
        if coa if name in _COA_STATE else maxima:
            st[name] = g.temp(typ, name)
    return st


def _grid(c: Ctx, p0: Ex, p1: Ex) -> None:
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
    dedupe(g, gx, ng)


def gl_tables(g: Gen, n_groups: int) -> tuple[Var, Var, Var, Var]:
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
    c: Ctx,
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


def _grid_point(c: Ctx, x: Ex, j: Var, cache: dict[str, Var], g0: Ex, g1: Ex) -> None:
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
        accumulate_dynamic(c, pv, cc)
    assert c.pass_ is not None
    with b.if_(c.pass_.eq(1)), b.if_(pv.gt(st["SUP"])):
        b.set(st["SUP"], pv)
    with b.elif_(pv.ge(st["THR"])):
        candidate(c, xp)


def _interval_lines(c: Ctx, gx0: Ex, gx1: Ex, j: Var, cache: dict[str, Var], tab: dict[str, Var]) -> None:
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
        interval(c, x0, x1)
