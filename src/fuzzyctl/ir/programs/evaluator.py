"""The evaluator of ``compile()`` as one IR program, printed as Python
(:mod:`~fuzzyctl.ir.render.pysrc`), numpy (:mod:`~fuzzyctl.ir.render.npsrc`) and the native
backend's C (:mod:`fuzzyctl.ir.render.c`).

Rule evaluation is :class:`~fuzzyctl.ir.builders.rules.RuleBuilder` (the PLC function block's
code); what differs from the PLC block is that every constant is a literal and that the output
geometry is known here, so a Mamdani CoG on a constant grid is the closed form of
:class:`~fuzzyctl.engine.plan.GridPlan`: the band polynomials of the intervals a term has to
itself, and an exact integral (the ``AM_LINES`` kernel) where sets overlap.  Large rule bases
become tables and loops (:mod:`fuzzyctl.ir.programs.rule_table`).

What Python and numpy write by hand is a :class:`~fuzzyctl.ir.nodes.Kernel`; the native
backend's builder (:mod:`fuzzyctl.ir.programs.native`) writes every one of them in the IR
(HOLD aside, which each renderer prints as two lines):

==============  ==================================================================
``AM_LINES``    area and moment of the accumulated lines on one grid interval
``MAMDANI``     a whole Mamdani output the closed form above does not cover (other
                methods, terms given by inputs, smooth sets: quadrature; Python and numpy)
``HOLD``        DEFAULT / NC / lock-range of an output (a running fill on a batch)
``SELECT``      fuzzylite's rule activation methods (Python and numpy only)
``MEMBER``      a membership function whose points are inputs (Python and numpy only)
``EXPR``        a function term (Python and numpy; C writes it as IR)
``TS``          a Takagi-Sugeno output with Tsukamoto terms (Python and numpy only)
==============  ==================================================================

A plan element a target cannot express raises :class:`~fuzzyctl.ir.state.CodegenError`;
``compile()`` then uses the next path (native -> Python -> the interpreter).

Merging before integration (exact, any target): activated sets of one output term combine
into one set when the operators allow it without changing the accumulated set:

* MAX accumulation, any ACT (every t-norm is non-decreasing in each argument):
  ``max_k w*T(a_k, mu) = w*T(max_k a_k, mu)`` for one weight ``w``;
* SUM / NSUM / BSUM accumulation with PROD activation: ``sum_k w_k a_k mu = (sum_k w_k a_k) mu``
  (BSUM limits the total sum);
* nothing else (PROBOR, MIN under a sum, weights given by inputs under MAX).

So the 343 rules of a 3-input grid reach the integration as at most 7 sets, one per output term.
"""

from __future__ import annotations

import dataclasses
from collections.abc import Callable
from dataclasses import dataclass

from fuzzyctl.engine.plan import (
    EX,
    EBinary,
    ECall,
    EInput,
    ENum,
    EOutput,
    EUnary,
    ExprPlan,
    GridPlan,
    OutputPlan,
    Plan,
    SelectionPlan,
)
from fuzzyctl.engine.semantics import shapes
from fuzzyctl.ir.builders.rules import Contrib, Literals, Params, RuleBuilder
from fuzzyctl.ir.nodes import Ex, Kernel, Num, Program, Pwl, Var, ex
from fuzzyctl.ir.state import CodegenError, Gen
from fuzzyctl.kinds import norms
from fuzzyctl.kinds.methods import METHODS

#: A key of :data:`fuzzyctl.kinds.targets.TARGETS` whose renderer prints the evaluator
#: (py, np, c): its record's ``kernels`` say which routines the program may call.
FastTarget = str

#: Above this many rules the rule section is tables and loops (:mod:`fuzzyctl.ir.programs.rule_table`).
TABLE_THRESHOLD = 200


@dataclass(frozen=True)
class Group:
    """One activated set after merging: ``w * act(a, term)``."""

    term: int
    a: Ex
    w: Ex
    act: str


@dataclass
class FastProgram:
    """The program and how to call it: input ``k`` is ``inputs[k]``, output ``k`` (plan
    order) ``outputs[k]``; ``state`` is the array of previous outputs (NC)."""

    program: Program
    target: FastTarget
    inputs: list[str]
    outputs: list[str]
    state: str
    plan: Plan


class FastBuilder(RuleBuilder):
    def __init__(self, plan: Plan, target: FastTarget) -> None:
        super().__init__(plan, Gen(target))
        self.target = target
        self.out_vars: list[Var] = []

    # ------------------------------------------------------------------ hooks

    def new_params(self, hint: str, fallback: str, what: str) -> Params:
        return Literals(self.g, "", what)

    def select(self, sel: SelectionPlan, degrees: list[Ex]) -> list[Ex]:
        if "SELECT" not in self.g.caps.kernels:
            return super().select(sel, degrees)
        outs = tuple(self.g.temp(hint="SEL") for _ in degrees)
        self.g.b.add(Kernel("SELECT", outs, tuple(degrees), sel))
        return list(outs)

    def function_term(self, expr: object, x: Ex | None, outputs: Callable[[int], Ex], where: str) -> Ex:
        assert isinstance(expr, ENum | EInput | EOutput | EX | EUnary | EBinary | ECall)
        if "EXPR" not in self.g.caps.kernels:
            return super().function_term(expr, x, outputs, where)
        refs = sorted(_expr_outputs(expr))
        args = (x if x is not None else Num(0.0), *self.inputs, *(outputs(o) for o in refs))
        out = self.g.temp(hint="F")
        self.g.b.add(Kernel("EXPR", (out,), tuple(args), (expr, tuple(refs), len(self.plan.outputs))))
        return out

    # ------------------------------------------------------------------ the program

    def build(self) -> FastProgram:
        plan, g = self.plan, self.g
        b = g.b
        check_fields(plan)
        names = []
        for i, inp in enumerate(plan.inputs):
            v = g.declare(f"FZ_IN{i}", "REAL", "input")
            self.inputs.append(v)
            names.append(v.name)
            if inp.clamp is not None:  # lock-range: the limited value is what everything reads
                lo, hi = inp.clamp
                with b.if_(v.lt(lo)):
                    b.set(v, lo)
                with b.elif_(v.gt(hi)):
                    b.set(v, hi)
        init = tuple((op.default if op.default is not None else 0.0) for op in plan.outputs)
        state = g.declare("FZ_PREV", "REAL", "state", max(1, len(plan.outputs)), init or (0.0,))
        self.out_vars = [g.declare(f"FZ_OUT{oi}", "REAL", "output") for oi in range(len(plan.outputs))]
        degrees = self.fuzzify()
        tabled: dict[int, list[Contrib]] | None = None
        concl: list[list[tuple[Ex, Ex]]] = []
        if _use_table(plan):
            from fuzzyctl.ir.programs.rule_table import table_rules

            tabled = table_rules(self, degrees, sparse=self.g.caps.data_dependent_loops)
        else:
            concl = self.rules(degrees, Literals(g, "", ""))
        values: dict[int, Ex] = {}
        for oi in plan.output_order:
            op = plan.outputs[oi]
            self.output(oi, tabled[oi] if tabled is not None else self.contribs(op, concl), values)
        prog = Program(plan.name or "FUZZY", g.decls, b.root, [], g.uses)
        return FastProgram(prog, self.target, names, [v.name for v in self.out_vars], state.name, plan)

    def fuzzify(self) -> dict[tuple[int, int], Ex]:
        """The degree of every term some condition reads."""
        plan, g = self.plan, self.g
        degrees: dict[tuple[int, int], Ex] = {}
        pp = Literals(g, "", "")
        for var, ti in plan.terms_read():
            fi = plan.fuzzy_inputs[var]
            t = fi.terms[ti]
            x = self.inputs[fi.slot]
            if t.pwl is not None:
                degrees[(var, ti)] = g.let(Pwl(x, t.pwl), "MU")
            elif t.kind in shapes.PWL_KINDS or (not t.constant and t.kind != "function"):
                degrees[(var, ti)] = self.member(var, ti, x, f"term {fi.name}.{t.name}")
            else:
                degrees[(var, ti)] = self.fuzzify_term(var, ti, pp)
        return degrees

    def member(self, var: int, ti: int, x: Ex, where: str) -> Ex:
        """A term whose points are inputs: ``shapes.membership`` at run time (Python and
        numpy; the native builder writes it in the IR)."""
        if "MEMBER" not in self.g.caps.kernels:
            raise self.g.refuse(where, "membership points given by variables")
        t = self.plan.fuzzy_inputs[var].terms[ti]
        out = self.g.temp(hint="MU")
        self.g.b.add(Kernel("MEMBER", (out,), (x, *self.inputs), t))
        return out

    # ------------------------------------------------------------------ outputs

    def output(self, oi: int, contribs: list[Contrib], values: dict[int, Ex]) -> None:
        """Output ``oi`` from its activated sets, then DEFAULT / NC / lock-range."""
        op = self.plan.outputs[oi]
        g = self.g
        out = self.out_vars[oi]
        if op.kind == "degree":
            v, _fired = self.degree_output(op, contribs)
            g.b.set(out, v)
            g.b.add(Kernel("HOLD", (out,), (out, ex(True)), (oi, 0.0, False, None)))
            values[oi] = out
            return
        if op.kind == "mamdani":  # singleton outputs scale in RuleBuilder.singleton
            contribs = self.scale_tiny(contribs)
        if op.kind == "singleton":
            value, fired = self.singleton(op, contribs)
        elif op.kind == "ts":
            value, fired = self._ts_output(oi, op, contribs, values)
        elif op.exact and op.grid is not None and METHODS[op.method].centroid:
            value, fired = self.closed_cog(op, op.grid, merge(g, contribs, op.accu or "MAX"))
        else:
            value, fired = self._mamdani_kernel(oi, op, contribs)
        default = op.default if op.default is not None else 0.0
        g.b.add(Kernel("HOLD", (out,), (value, fired), (oi, default, op.no_change, op.clamp)))
        values[oi] = out

    def _ts_output(
        self, oi: int, op: OutputPlan, contribs: list[Contrib], values: dict[int, Ex]
    ) -> tuple[Ex, Ex]:
        if not any(t.kind in shapes.TSUKAMOTO_KINDS for t in op.terms):
            return self.ts(op, contribs, values)
        if "TS" not in self.g.caps.kernels:
            raise self.g.refuse(f"output {op.name}", "Tsukamoto (monotonic) terms")
        return self._whole_output("TS", oi, op, contribs, values)

    def _mamdani_kernel(self, oi: int, op: OutputPlan, contribs: list[Contrib]) -> tuple[Ex, Ex]:
        """A Mamdani output the closed form does not cover, as one kernel (Python and numpy;
        the native builder, :mod:`fuzzyctl.ir.programs.native`, writes it in the IR)."""
        if "MAMDANI" not in self.g.caps.kernels:
            raise self.g.refuse(f"output {op.name}", f"{op.method} needs the native builder")
        groups = merge(self.g, contribs, op.accu or "MAX")
        merged: list[Contrib] = [(gr.term, gr.a, gr.w, gr.act) for gr in groups]
        return self._whole_output("MAMDANI", oi, op, merged, {})

    def am_lines(
        self, x0: float, x1: float, accu: str, geom: tuple[tuple[float, float, bool], ...], args: list[Ex]
    ) -> tuple[Ex, Ex]:
        """Area and moment of the accumulated sets on one shared grid interval: the
        ``AM_LINES`` kernel (Python and numpy; the native builder writes it in the IR)."""
        if "AM_LINES" not in self.g.caps.kernels:
            raise self.g.refuse("a shared output interval", "the AM_LINES kernel needs the native builder")
        ta, tm = self.g.temp(hint="IA"), self.g.temp(hint="IM")
        self.g.b.add(Kernel("AM_LINES", (ta, tm), tuple(args), (x0, x1, accu, geom)))
        return ta, tm

    def _whole_output(
        self, kind: str, oi: int, op: OutputPlan, contribs: list[Contrib], values: dict[int, Ex]
    ) -> tuple[Ex, Ex]:
        """A kernel evaluating a whole output from its activated sets (Python and numpy)."""
        g = self.g
        value, fired = g.temp(hint="Y"), g.temp("BOOL", "FIRED")
        args: list[Ex] = list(self.inputs)
        earlier = sorted(values)
        args += [values[o] for o in earlier]
        for _t, a, w, _act in contribs:
            args += [a, w]
        layout = (oi, tuple(earlier), tuple((t, act) for t, _a, _w, act in contribs))
        g.b.add(Kernel(kind, (value, fired), tuple(args), layout))
        return value, fired

    def closed_cog(self, op: OutputPlan, grid: GridPlan, groups: list[Group]) -> tuple[Ex, Ex]:
        """CoG on a constant grid: band polynomials where a term is alone, exact integrals
        of the overlapping sets elsewhere (``batch``/``specialise`` before, one code now)."""
        g = self.g
        b = g.b
        accu = op.accu or "MAX"
        area, moment = g.let(0.0, "A"), g.let(0.0, "M")
        per_term: dict[int, int] = {}
        for gr in groups:
            per_term[gr.term] = per_term.get(gr.term, 0) + 1
        closed = {t for t, k in per_term.items() if k == 1 or norms.adds(accu)}
        for gr in groups:
            if gr.term in closed and grid.solo[gr.term]:
                with b.if_(_positive(gr)):
                    self._solo(grid, gr, area, moment)
        general = sorted(set(grid.shared) | {j for t in per_term if t not in closed for j in grid.solo[t]})
        for j in general:
            members = [gr for gr in groups if gr.term in grid.active[j]]
            if not members:
                continue
            cond = _positive(members[0])
            for gr in members[1:]:
                cond = cond.or_(_positive(gr))
            with b.if_(cond):
                geom = tuple(
                    (grid.left[gr.term][j], grid.right[gr.term][j], norms.is_min(gr.act)) for gr in members
                )
                args: list[Ex] = []
                for gr in members:
                    args += [gr.a, gr.w]
                ta, tm = self.am_lines(grid.xs[j], grid.xs[j + 1], accu, geom, args)
                b.set(area, area + ta)
                b.set(moment, moment + tm)
        fired = g.let(area.gt(0.0), "FIRED", "BOOL")
        value = g.temp(hint="Y")
        with b.if_(fired):
            b.set(value, moment / area)
        with b.else_():
            b.set(value, 0.0)
        return value, fired

    def _solo(self, grid: GridPlan, gr: Group, area: Var, moment: Var) -> None:
        """Area and moment of ``w * act(h, term)`` over the intervals the term has alone."""
        g = self.g
        b = g.b
        w = gr.w
        one = isinstance(w, Num) and w.value == 1.0

        def scale(e: Ex) -> Ex:
            return e if one else w * e

        if not norms.is_min(gr.act):
            fa, fm = grid.full[gr.term]
            b.set(area, area + scale(gr.a * fa))
            b.set(moment, moment + scale(gr.a * fm))
            return
        # the pieces join continuously: the first band's polynomial at h clipped into it,
        # plus each further band's increase over the part of it below h (batch._band_eval)
        for k, (lo, hi, ac, mc) in enumerate(grid.min_bands[gr.term]):
            if k > 0 and ac[1] == ac[2] == 0.0 and mc[1] == mc[2] == mc[3] == 0.0:
                continue
            u = g.max_(gr.a, lo, "U") if k > 0 else gr.a
            if hi != float("inf"):
                u = g.min_(u, hi, "U")
            pa = ac[0] + u * (ac[1] + u * ac[2])
            pm = mc[0] + u * (mc[1] + u * (mc[2] + u * mc[3]))
            if k > 0:
                pa = pa - (ac[0] + lo * (ac[1] + lo * ac[2]))
                pm = pm - (mc[0] + lo * (mc[1] + lo * (mc[2] + lo * mc[3])))
            b.set(area, area + scale(pa))
            b.set(moment, moment + scale(pm))


def _positive(gr: Group) -> Ex:
    if isinstance(gr.w, Num) and gr.w.value == 1.0:
        return gr.a.gt(0.0)
    return (gr.a * gr.w).gt(0.0)


def merge(g: Gen, contribs: list[Contrib], accu: str) -> list[Group]:
    """Activated sets combined where the operators allow it exactly (module docstring);
    each merged degree is computed once into a temporary."""
    out: list[Group] = []
    keyed: dict[tuple[int, object], list[tuple[Ex, Ex]]] = {}
    for t, a, w, act in contribs:
        assert t is not None
        if norms.is_max(accu) and isinstance(w, Num):
            key: tuple[int, object] = (t, ("max", act, w.value))
        elif norms.adds(accu) and norms.is_prod(act):
            key = (t, ("sum",))
        else:
            out.append(Group(t, a, w, act))
            continue
        keyed.setdefault(key, []).append((a, w))
    merged: list[Group] = []
    for (t, kind), members in keyed.items():
        assert isinstance(kind, tuple)
        act = "PROD" if kind[0] == "sum" else str(kind[1])
        if kind[0] == "max":
            acc: Ex = members[0][0]
            if len(members) > 1:
                acc = g.let(members[0][0], "H")
                for a, _w in members[1:]:
                    with g.b.if_(a.gt(acc)):
                        g.b.set(acc, a)
            merged.append(Group(t, acc, members[0][1], act))
        else:
            total: Ex = _times(members[0])
            for m in members[1:]:
                total = total + _times(m)
            merged.append(Group(t, total if isinstance(total, Var) else g.let(total, "H"), Num(1.0), act))
    return merged + out


def _times(m: tuple[Ex, Ex]) -> Ex:
    a, w = m
    return a if isinstance(w, Num) and w.value == 1.0 else a * w


def _expr_outputs(e: ExprPlan) -> set[int]:
    if isinstance(e, EOutput):
        return {e.output}
    if isinstance(e, EUnary):
        return _expr_outputs(e.operand)
    if isinstance(e, EBinary):
        return _expr_outputs(e.left) | _expr_outputs(e.right)
    if isinstance(e, ECall):
        out: set[int] = set()
        for a in e.args:
            out |= _expr_outputs(a)
        return out
    return set()


def _use_table(plan: Plan) -> bool:
    if len(plan.rules) < TABLE_THRESHOLD:
        return False
    from fuzzyctl.ir.programs.rule_table import table_applies

    return table_applies(plan)


# --------------------------------------------------------------------------- the plan guard

#: The plan fields this builder implements; a field added later (a new semantic switch)
#: with a non-default value makes it refuse, and ``compile()`` falls back to the interpreter.
KNOWN_FIELDS: dict[str, frozenset[str]] = {
    "CAnd": frozenset({"op", "operands"}),
    "CChained": frozenset({"var", "term", "hedges", "negated"}),
    "CDegree": frozenset({"slot", "chained"}),
    "CNot": frozenset({"operand"}),
    "COr": frozenset({"op", "operands"}),
    "CTerm": frozenset({"var", "term", "hedges", "negated"}),
    "CTrue": frozenset(),
    "ChainedPlan": frozenset({"name", "terms", "accu"}),
    "ConclusionPlan": frozenset({"outputs", "chained", "term", "weight", "hedges"}),
    "Contribution": frozenset({"rule", "conclusion", "term", "act", "weight"}),
    "FuzzyInputPlan": frozenset({"name", "slot", "terms"}),
    "InputPlan": frozenset({"name", "default", "degree", "clamp"}),
    "Options": frozenset(
        {
            "weight_before_activation",
            "firing_threshold",
            "ts_default_accu",
            "singleton_default_accu",
            "hedges_carry_over",
            "weight_whole_rule",
            "quad_rtol",
        }
    ),
    "OutputPlan": frozenset(
        {
            "name",
            "kind",
            "method",
            "accu",
            "terms",
            "contributions",
            "default",
            "no_change",
            "low",
            "high",
            "exact",
            "grid",
            "is_output",
            "clamp",
        }
    ),
    "Plan": frozenset(
        {
            "name",
            "inputs",
            "fuzzy_inputs",
            "chained",
            "rules",
            "order",
            "outputs",
            "output_order",
            "options",
            "selections",
        }
    ),
    "RulePlan": frozenset({"label", "block", "condition", "act", "conclusions", "weight", "selection"}),
    "SelectionPlan": frozenset({"method", "rules", "count", "threshold", "comparison"}),
    "TermPlan": frozenset({"name", "kind", "params", "height", "expr", "pwl"}),
}
_LEAVES = ("GridPlan", "Slot", "ENum", "EInput", "EOutput", "EX", "EUnary", "EBinary", "ECall")


def check_fields(obj: object, where: str = "plan") -> None:
    """Refuse a plan element or field this builder does not know (see :data:`KNOWN_FIELDS`).
    Walks the plan once without recursion, each element type's fields looked up once (a
    10,000-rule plan has 270,000 elements: numbers and strings are skipped by type before
    any lookup)."""
    stack = [obj]
    pop, push, extend = stack.pop, stack.append, stack.extend
    layouts: dict[type, tuple[tuple[str, bool, object], ...] | None] = {}
    while stack:
        item = pop()
        cls = type(item)
        if cls is tuple or cls is list:
            extend(item)  # type: ignore[arg-type]
            continue
        if cls in _ATOMS:
            continue
        try:
            layout = layouts[cls]
        except KeyError:
            layout = layouts[cls] = _layout(cls)
        if layout is None:
            continue
        for name, known, default in layout:
            value = getattr(item, name)
            if not known:
                if value != default and value not in ((), None, False, 0, 0.0):
                    kind = cls.__name__
                    raise CodegenError(
                        f"{where}: {kind}.{name} = {value!r}: a switch the evaluator does not implement"
                    )
            elif type(value) not in _ATOMS:
                push(value)


_ATOMS = frozenset({int, float, str, bool, type(None), bytes})


_LAYOUTS: dict[tuple[type, frozenset[str] | None], tuple[tuple[str, bool, object], ...] | None] = {}


def _layout(cls: type) -> tuple[tuple[str, bool, object], ...] | None:
    """(field, known, default) of a plan element type to check (``None``: not a dataclass,
    or a leaf); raises for an element type the builder does not know.  Kept per type and
    per set of known fields (tests change :data:`KNOWN_FIELDS`)."""
    known = KNOWN_FIELDS.get(cls.__name__)
    key = (cls, known)
    try:
        return _LAYOUTS[key]
    except KeyError:
        pass
    layout: tuple[tuple[str, bool, object], ...] | None = None
    if dataclasses.is_dataclass(cls) and cls.__name__ not in _LEAVES:
        if known is None:
            raise CodegenError(f"plan: {cls.__name__}: a plan element the evaluator generator does not know")
        layout = tuple(
            (f.name, f.name in known, f.default if f.default is not dataclasses.MISSING else None)
            for f in dataclasses.fields(cls)
        )
    _LAYOUTS[key] = layout
    return layout


def build_fast(plan: Plan, target: FastTarget) -> FastProgram:
    """The evaluator program of ``plan`` for ``target``; raises :class:`CodegenError` for
    what the target cannot express."""
    if plan.options.emulate is not None:  # another tool's arithmetic: its own evaluator only
        raise CodegenError(f"the {plan.options.emulate} profile is evaluated by its own evaluator")
    return FastBuilder(plan, target).build()
