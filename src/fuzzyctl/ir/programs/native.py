"""The evaluator program of ``compile()`` for the native backend: every output in the IR.

:class:`~fuzzyctl.ir.programs.evaluator.FastBuilder` writes rule evaluation, the closed-form CoG
and DEFAULT / NC once for Python, numpy and C; what Python and numpy leave to hand-written
kernels (:mod:`fuzzyctl.ir.kernels.scalar`, :mod:`fuzzyctl.ir.kernels.columns`) is built here
from the IR builders the PLC block uses, so the C compiled by :mod:`fuzzyctl.engine.native`
is the whole evaluation - no kernel is called back:

=======================  =============================================================
exact Mamdani outputs    :func:`fuzzyctl.ir.builders.mamdani.exact_outputs` on the constant
                         grid (every method the methods registry marks exact)
closed-form CoG          the shared intervals: :func:`fuzzyctl.ir.builders.pieces.max_of_two`
                         (two sets under MAX), else :func:`~fuzzyctl.ir.builders.pieces.interval`
smooth sets              :func:`fuzzyctl.ir.builders.quadrature.smooth_cog` (CoG),
                         :mod:`fuzzyctl.ir.builders.smooth_methods` (CoA, LM, RM, MoM)
terms given by inputs    their breakpoints sorted at run time (as in the PLC block)
Tsukamoto terms          :func:`fuzzyctl.ir.builders.terms.tsukamoto`
rule activation          :meth:`NativeBuilder.select` (``selection.select`` in the IR)
=======================  =============================================================

Takagi-Sugeno outputs (Tsukamoto terms included) and fuzzylite's rule activation methods
are written here too.  A plan the IR builders cannot express (a smooth output term given by
variables, a Tsukamoto term whose points are inputs) raises :class:`CodegenError` saying why;
:func:`fuzzyctl.engine.native.compile_native` reports it once.
"""

from __future__ import annotations

from fuzzyctl.engine.plan import GridPlan, OutputPlan, Plan, SelectionPlan
from fuzzyctl.engine.semantics import shapes
from fuzzyctl.ir.builders import grid_pieces as GP
from fuzzyctl.ir.builders import mamdani as M
from fuzzyctl.ir.builders import quadrature as Q
from fuzzyctl.ir.builders import terms as T
from fuzzyctl.ir.builders.pieces import ACCUS, Ctx, clipped_am, interval, max_of_two
from fuzzyctl.ir.builders.rules import Contrib, Literals
from fuzzyctl.ir.builders.smooth_methods import smooth_method
from fuzzyctl.ir.nodes import Ex, Int, Var, ex
from fuzzyctl.ir.programs.evaluator import FastBuilder, FastProgram, FastTarget, Group, merge
from fuzzyctl.ir.state import CodegenError, Gen
from fuzzyctl.kinds import norms
from fuzzyctl.kinds.methods import METHODS, implementation


class NativeBuilder(FastBuilder):
    """The evaluator program with every output written in the IR (target ``"c"``)."""

    def __init__(self, plan: Plan, target: FastTarget = "c") -> None:
        # target "np": the same output IR printed as numpy (benchmarks/bench_engine.py
        # compares it with the hand-written kernels of ir/kernels/columns.py)
        super().__init__(plan, target)

    def member(self, var: int, ti: int, x: Ex, where: str) -> Ex:
        """A term whose points are inputs: its breakpoints sorted at run time, as the PLC
        block does; other shapes read their parameters from the inputs directly."""
        g = self.g
        t = self.plan.fuzzy_inputs[var].terms[ti]
        if t.kind not in shapes.PWL_KINDS:
            return self.fuzzify_term(var, ti, Literals(g, "", ""))
        lit = Literals(g, "", "")
        pts = M.term_points(self, t, lit, lit, where)
        n = len(pts)
        wx, wy = g.array("MX", "REAL", n), g.array("MY", "REAL", n)
        for k, (px, py) in enumerate(pts):
            g.b.set(wx[k], px)
            g.b.set(wy[k], py)
        T.sort_points(g, wx, wy, 0, n - 1)
        return g.let(T.pwl_value(g, wx, wy, 0, n - 1, x), "MU")

    def _ts_output(
        self, oi: int, op: OutputPlan, contribs: list[Contrib], values: dict[int, Ex]
    ) -> tuple[Ex, Ex]:
        """Takagi-Sugeno, Tsukamoto terms included (their inverse: ``irterms.tsukamoto``)."""
        return self.ts(op, contribs, values)

    def select(self, sel: SelectionPlan, degrees: list[Ex]) -> list[Ex]:
        """fuzzylite's rule activation methods (the IR twin of
        :func:`fuzzyctl.engine.semantics.selection.select`): which of the block's rules keep their
        degree."""
        g = self.g
        b = g.b
        k = len(degrees)
        ds = [g.let(d, "SD") for d in degrees]
        outs = [g.let(0.0, "SEL") for _ in ds]
        if sel.method in ("FIRST", "LAST"):
            taken = g.let(0, "TAKEN", "INT")
            for j in range(k) if sel.method == "FIRST" else range(k - 1, -1, -1):
                a = ds[j]
                with b.if_(taken.lt(sel.count).and_(a.gt(0.0)).and_(a.ge(sel.threshold))):
                    b.set(outs[j], a)
                    b.set(taken, taken + 1)
        elif sel.method in ("HIGHEST", "LOWEST"):
            for j in range(k):  # rank: the positive degrees before it (earlier rules first on ties)
                rank = g.let(0, "RANK", "INT")
                for i in range(k):
                    if i == j:
                        continue
                    before = ds[i].gt(ds[j]) if sel.method == "HIGHEST" else ds[i].lt(ds[j])
                    if i < j:
                        before = before.or_(ds[i].eq(ds[j]))
                    with b.if_(ds[i].gt(0.0).and_(before)):
                        b.set(rank, rank + 1)
                with b.if_(ds[j].gt(0.0).and_(rank.lt(sel.count))):
                    b.set(outs[j], ds[j])
        elif sel.method == "PROPORTIONAL":
            total = g.let(0.0, "TOTAL")
            for a in ds:
                with b.if_(a.gt(0.0)):
                    b.set(total, total + a)
            for a, out in zip(ds, outs, strict=True):
                with b.if_(total.gt(0.0).and_(a.gt(0.0))):
                    b.set(out, a / total)
        else:
            compare = {"<": "lt", "<=": "le", "==": "eq", "!=": "ne", ">=": "ge", ">": "gt"}[sel.comparison]
            for a, out in zip(ds, outs, strict=True):
                with b.if_(getattr(a, compare)(sel.threshold)):
                    b.set(out, a)
        return list(outs)

    def _mamdani_kernel(self, oi: int, op: OutputPlan, contribs: list[Contrib]) -> tuple[Ex, Ex]:
        groups = merge(self.g, contribs, op.accu or "MAX")
        if op.exact:
            return self.exact_output(op, groups)
        for t in op.terms:
            if not Q.constant_term(t):  # a function term of x alone is constant
                raise self.g.refuse(f"term {op.name}.{t.name}", "a smooth output term given by variables")
        sets = [Q.SmoothSet(gr.term, gr.a, gr.w, gr.act) for gr in groups]
        # every method: CoG as the PLC block integrates it, CoA/LM/RM/MoM on the same panels
        value, fired, _capped = smooth_method(self.g, op, sets, Q.calibrate(op), self.plan.options.quad_rtol)
        return value, fired

    def exact_output(self, op: OutputPlan, groups: list[Group]) -> tuple[Ex, Ex]:
        """A piecewise-linear output by any exact method: the PLC block's defuzzification
        on this output's constant grid (or its run-time one when points are inputs: a method
        the PLC block has no run-time form of is refused there, :func:`M.exact_outputs`)."""
        assert op.low is not None and op.high is not None
        accu = op.accu or "MAX"
        if op.grid is not None and GP.applies(accu) and not self._too_long(op, op.grid, groups, accu):
            return self._unrolled(op, op.grid, groups, accu)
        lit = Literals(self.g, "", "")
        points = [M.term_points(self, t, lit, lit, f"term {op.name}.{t.name}") for t in op.terms]
        spec = M.ExactOutput(
            op.name,
            op.method,
            op.accu or "MAX",
            op.low,
            op.high,
            points,
            [M.Group(gr.term, gr.a, gr.w, norms.is_min(gr.act)) for gr in groups],
        )
        value, fired = M.exact_outputs(self.g, [spec], None if op.grid is None else [op.grid])
        return value[0], fired[0]

    @staticmethod
    def _too_long(op: OutputPlan, grid: GridPlan, groups: list[Group], accu: str) -> bool:
        """Straight-line code past :data:`GP.UNROLL_LIMIT`, for a method the run-time grid's
        loops compute (same pieces, same results; they compile in seconds)."""
        entry = METHODS[op.method]
        if not (entry.integrating or entry.maximum is not None):
            return False
        sets = [GP.Set(gr.term, gr.a, gr.w, norms.is_min(gr.act)) for gr in groups]
        return GP.unrolled_size(grid, sets, accu) > GP.UNROLL_LIMIT

    def _unrolled(self, op: OutputPlan, grid: GridPlan, groups: list[Group], accu: str) -> tuple[Ex, Ex]:
        """CoA, LM, RM, MoM on the constant grid as straight-line code: the pieces
        (:mod:`~fuzzyctl.ir.builders.grid_pieces`), then the method's IR builder (its registry
        entry's ``ir``)."""
        g = self.g
        sets = [GP.Set(gr.term, gr.a, gr.w, norms.is_min(gr.act)) for gr in groups]
        entry = METHODS[op.method]
        if norms.is_max(accu) and entry.maximum is not None:
            # the height from each set's peak and fired from the closed-form area: LM and RM
            # stop at the first point reaching it, MoM cuts only the intervals that can
            _cog, fired = self.closed_cog(op, grid, groups)
            value = g.let(0.0, "Y")
            with g.b.if_(fired):
                if entry.maximum == "mean":
                    g.b.set(value, GP.mean_reaching(g, grid, sets))
                else:
                    g.b.set(value, GP.first_reaching(g, grid, sets, entry.maximum == "left"))
            return value, fired
        if entry.bisects:
            return GP.bisector_by_intervals(g, grid, sets, accu)
        # the grid points' degrees: the maxima read them, and so may a method of a new kind
        p = GP.pieces(g, grid, sets, accu, not entry.integrating)
        fired = g.let(ex(False), "FIRED", "BOOL")
        value = g.let(0.0, "Y")
        if not p.x0:
            return value, fired
        areas, total = GP.area(g, p)
        g.b.set(fired, total.gt(0.0))
        with g.b.if_(fired):
            g.b.set(value, implementation(METHODS[op.method].ir)(g, p, grid, areas, total))
        return value, fired

    def am_lines(
        self, x0: float, x1: float, accu: str, geom: tuple[tuple[float, float, bool], ...], args: list[Ex]
    ) -> tuple[Ex, Ex]:
        """Area and moment of the accumulated sets on one grid interval: the lines with a
        positive degree gathered, then :func:`fuzzyctl.ir.builders.pieces.interval`."""
        g = self.g
        b = g.b
        n = len(geom)
        lines = [(left, right, args[2 * i], args[2 * i + 1], mn) for i, (left, right, mn) in enumerate(geom)]
        if n == 2 and norms.is_max(accu):
            return max_of_two(g, x0, x1, lines[0], lines[1])
        if n == 1:
            area, mom = g.let(0.0, "IA"), g.let(0.0, "IM")
            with b.if_((lines[0][2] * lines[0][3]).gt(0.0)):
                ca, cm = clipped_am(g, x0, x1 - x0, lines[0])
                b.set(area, ca)
                b.set(mom, cm)
            return area, mom
        c = _lines_ctx(g, n, accu)
        nl = c.v["NL"]
        b.set(nl, 0)
        for i, (left, right, mn) in enumerate(geom):
            a, w = args[2 * i], args[2 * i + 1]
            with b.if_((a * w).gt(0.0)):
                b.set(c.a["LL"][nl], left)
                b.set(c.a["LR"][nl], right)
                b.set(c.a["LA"][nl], a)
                b.set(c.a["LW"][nl], w)
                b.set(c.a["LMIN"][nl], ex(mn))
                b.set(nl, nl + 1)
        b.set(c.v["AREA"], 0.0)
        b.set(c.v["MOM"], 0.0)
        with b.if_(nl.gt(0)):
            interval(c, g.let(x0, "X0"), g.let(x1, "X1"))
        return c.v["AREA"], c.v["MOM"]


def _lines_ctx(g: Gen, n: int, accu: str) -> Ctx:
    """The scratch variables of :func:`fuzzyctl.ir.builders.pieces.interval` for at most ``n``
    lines and one accumulation, the method CoG."""
    code = ACCUS[accu]
    v: dict[str, Var] = {}
    for name, typ in (("AC", "INT"), ("MC", "INT"), ("NL", "INT"), ("NT", "INT"), ("NC", "INT")):
        v[name] = g.temp(typ, name)  # type: ignore[arg-type]
    for name in ("V0", "V1", "AREA", "MOM"):
        v[name] = g.temp(hint=name)
    g.b.set(v["AC"], Int(code))
    g.b.set(v["MC"], Int(1))
    if code == 4:
        v["PR"] = g.temp("BOOL", "PR")
    pairs = max(1, n * (n - 1) // 2)
    arrays = {
        **{k: g.array(k, "REAL", n) for k in ("LL", "LR", "LA", "LW", "KINK", "P0", "P1")},
        "LMIN": g.array("LMIN", "BOOL", n),
        "TS": g.array("TS", "REAL", n + 2),
        "CUT": g.array("CUT", "REAL", pairs),
        "CV": g.array("CV", "REAL", pairs),
    }
    gl = M.gl_tables(g, n) if code == 4 else None
    one = g.let(1, "PASS", "INT")
    dummy = arrays["LL"]
    # the term tables are read only by the PLC block's run-time geometry, never here
    d = dummy
    return Ctx(g, v, arrays, {}, gl, {"COG"}, {code}, d, d, d, d, d, d, d, d, one, ex(True))


def build_native(plan: Plan) -> FastProgram:
    """The native evaluator program of ``plan``; raises :class:`CodegenError` naming what
    the IR cannot express."""
    if plan.options.emulate is not None:
        raise CodegenError(f"the {plan.options.emulate} profile is evaluated by its own evaluator")
    return NativeBuilder(plan).build()
