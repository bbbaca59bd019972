"""Rule evaluation as IR, written once for every generated evaluator.

:class:`RuleBuilder` turns the parts of a :class:`~fuzzyctl.engine.plan.Plan` that do not
depend on how an evaluator integrates - fuzzification of smooth, singleton and function input
terms, conditions (the operator templates of :mod:`fuzzyctl.engine.semantics.operators`), hedges, rule
weights, the firing threshold, conclusions, chained inference, and the singleton,
Takagi-Sugeno and degree outputs - into IR statements.  Two programs are built on it:

* :mod:`fuzzyctl.ir.programs.plc_block` - the PLC function block (Structured Text, C): every
  constant a tunable parameter array;
* :mod:`fuzzyctl.ir.programs.evaluator` - the evaluator of ``compile()`` (rendered as Python,
  numpy and native C): constants as literals.

Each step mirrors :mod:`fuzzyctl.engine.reference.interp`, the readable reference they are tested
against.  Subclasses decide the parameters (:meth:`RuleBuilder.new_params`), function terms
and rule activation methods (:meth:`RuleBuilder.function_term`, :meth:`RuleBuilder.select`).
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass, field

from fuzzyctl.engine.lowering.terms import uses_x
from fuzzyctl.engine.plan import (
    CAnd,
    CChained,
    CDegree,
    CNot,
    CondPlan,
    COr,
    CTerm,
    CTrue,
    OutputPlan,
    Plan,
    PParam,
    SelectionPlan,
    Slot,
    TermPlan,
)
from fuzzyctl.engine.reference import pwl
from fuzzyctl.engine.semantics import shapes
from fuzzyctl.ir.builders import terms as T
from fuzzyctl.ir.builders.ruletext import rule_text
from fuzzyctl.ir.coalesce import rename, share_temps
from fuzzyctl.ir.nodes import Call, Decl, Ex, Num, Var, ex, not_
from fuzzyctl.ir.state import Gen
from fuzzyctl.kinds import norms
from fuzzyctl.kinds import shapes as registry
from fuzzyctl.kinds.methods import METHODS

#: (term, degree, weight, ACT) of one activated set
Contrib = tuple[int | None, Ex, Ex, str]


@dataclass
class Params:
    """A tunable parameter array being filled (a PLC function block's online-tunable data)."""

    g: Gen
    name: str
    what: str
    values: list[float] = field(default_factory=list)
    notes: list[str] = field(default_factory=list)

    def add(self, value: float, note: str) -> Ex:
        self.values.append(float(value))
        self.notes.append(note)
        return Var(self.name)[len(self.values) - 1]

    def finish(self) -> None:
        if not self.values:
            self.g.names.discard(self.name.upper())
            return
        lines = [self.what] + [f"[{i}] {n}" for i, n in enumerate(self.notes)]
        self.g.decls.append(
            Decl(self.name, "REAL", "param", len(self.values), tuple(self.values), "\n".join(lines))
        )


class Literals(Params):
    """Parameters written as literals (the evaluator of ``compile()``: nothing to tune)."""

    def add(self, value: float, note: str) -> Ex:
        return Num(float(value))

    def finish(self) -> None:
        pass


class RuleBuilder:
    """Shared rule evaluation (see the module docstring)."""

    def __init__(self, plan: Plan, g: Gen) -> None:
        self.plan = plan
        self.g = g
        self.inputs: list[Ex] = []
        self.params: list[Params] = []
        #: temporaries that one contribution of one output reads and nothing else (set by a
        #: builder that knows; scaled in place by :meth:`scale_tiny`)
        self.single_use: set[str] = set()
        #: names from the model and rule text comments (the PLC block); the evaluators of
        #: compile() keep names that do not depend on the model's text
        self.readable = False

    # ------------------------------------------------------------------ hooks

    def new_params(self, hint: str, fallback: str, what: str) -> Params:
        name = self.g.fresh(hint, fallback)
        self.g.names.add(name.upper())
        p = Params(self.g, name, what)
        self.params.append(p)
        return p

    def function_term(self, expr: object, x: Ex | None, outputs: Callable[[int], Ex], where: str) -> Ex:
        """The value of a function term (``engine.expr``): IR expressions (C only)."""
        from fuzzyctl.engine.plan import EX, EBinary, ECall, EInput, ENum, EOutput, EUnary

        assert isinstance(expr, ENum | EInput | EOutput | EX | EUnary | EBinary | ECall)
        return T.expression(self.g, expr, self.inputs, outputs, x, where)

    def select(self, sel: SelectionPlan, degrees: list[Ex]) -> list[Ex]:
        """fuzzylite's rule activation methods: not expressible by default."""
        raise self.g.refuse(f"rule block activation {sel.method}", "rule activation methods")

    # ------------------------------------------------------------------ parameters

    def pv(self, p: PParam, arr: Params | None, note: str) -> Ex:
        """A parameter: an input's current value, a tunable entry, or a literal."""
        if isinstance(p, Slot):
            return self.inputs[p.index]
        if arr is None:
            return Num(p)
        return arr.add(p, note)

    # ------------------------------------------------------------------ fuzzification

    def fuzzify_term(self, var: int, ti: int, pp: Params) -> Ex:
        """The degree of a singleton, function or smooth input term."""
        g = self.g
        fi = self.plan.fuzzy_inputs[var]
        x = self.inputs[fi.slot]
        t = fi.terms[ti]
        where = f"term {fi.name}.{t.name}"
        if t.kind == "singleton":
            pos = self.pv(t.params[0], pp, f"{t.name} position")
            dv = g.temp(hint="MU")
            with g.b.if_(x.eq(pos)):
                g.b.set(dv, self.pv(t.height, None, ""))
            with g.b.else_():
                g.b.set(dv, 0.0)
            return dv
        if t.kind == "function":
            assert t.expr is not None
            return g.let(self.function_term(t.expr, x, _no_outputs, where), "MU")
        if t.kind in shapes.SMOOTH_KINDS:
            ps = [
                self.pv(p, pp, f"{t.name} {name}")
                for p, name in zip(t.params, _param_names(t.kind, len(t.params)), strict=True)
            ]
            m: Ex = T.smooth(g, t.kind, ps, x, where)
            h = t.height
            return m if (not isinstance(h, Slot) and h == 1.0) else g.let(self.pv(h, None, "") * m, "MU")
        raise g.refuse(where, f"{t.kind} terms on inputs")

    # ------------------------------------------------------------------ rules

    def rules(self, degrees: dict[tuple[int, int], Ex], weights: Params) -> list[list[tuple[Ex, Ex]]]:
        """Rule degrees in plan order; returns per rule the (hedged degree, weight) of each
        conclusion (``interp.run``)."""
        plan, g = self.plan, self.g
        b = g.b
        chained: dict[tuple[int, int], Var] = {}
        bare: dict[int, Var] = {}
        for ci, chp in enumerate(plan.chained):
            for ti in range(len(chp.terms)):
                chained[(ci, ti)] = g.let(0.0, f"C{ci}_{ti}")
            bare[ci] = g.let(0.0, f"CB{ci}")
        normalised: set[int] = set()
        concl: list[list[tuple[Ex, Ex]]] = [[] for _ in plan.rules]
        with b.region("rules"):
            selected = self._selections(degrees, chained, bare)
            for ri in plan.order:
                rule = plan.rules[ri]
                b.comment(f"RULE {rule.label}" + (f" (block {rule.block})" if rule.block else ""))
                if self.readable:
                    b.comment(rule_text(plan, rule))
                for ci in sorted(_chained_reads(rule.condition) - normalised):
                    normalised.add(ci)
                    self._normalise(ci, chained)
                a = selected[ri] if ri in selected else self.weighted(ri, degrees, chained, bare)
                self.conclude(ri, a, weights, concl, chained, bare)
        return concl

    def weighted(
        self,
        ri: int,
        degrees: dict[tuple[int, int], Ex],
        chained: dict[tuple[int, int], Var],
        bare: dict[int, Var],
    ) -> Var:
        """``weight * condition``, 0 at or below the firing threshold (``interp.weighted``)."""
        g, rule = self.g, self.plan.rules[ri]
        decl_mark, stmt_mark = len(g.decls), len(g.b.cur)
        c = self.cond(rule.condition, degrees, chained, bare)
        if isinstance(rule.weight, Slot) or rule.weight != 1.0:
            c = c * self.pv(rule.weight, None, "")
        what = f"RULE_{rule.label}" if self.readable else f"R{ri}"
        a = self._adopt(c, what, decl_mark, stmt_mark)
        threshold = self.plan.options.firing_threshold
        if threshold > 0.0:
            with g.b.if_(a.le(threshold)):
                g.b.set(a, 0.0)
        return a

    def _adopt(self, c: Ex, what: str, decl_mark: int, stmt_mark: int) -> Var:
        """A variable named ``what`` holding ``c``: the temporary that already holds it when
        it was made for this value (renamed: no copy), else a new one assigned ``c``."""
        g = self.g
        name = g.named(what)
        if isinstance(c, Var):
            for d in g.decls[decl_mark:]:
                if d.name == c.name and d.storage == "temp" and d.type == "REAL" and d.size is None:
                    g.names.discard(d.name.upper())
                    g.names.add(name.upper())
                    d.name = name
                    rename(g.b.cur[stmt_mark:], c.name, name)
                    return Var(name)
        v = g.declare(name, "REAL", "temp")
        g.b.set(v, c)
        return v

    def _selections(
        self,
        degrees: dict[tuple[int, int], Ex],
        chained: dict[tuple[int, int], Var],
        bare: dict[int, Var],
    ) -> dict[int, Ex]:
        """Rule blocks with an activation method: their rules read no chained variable, so
        they are evaluated first and selected together (``interp.run``)."""
        out: dict[int, Ex] = {}
        threshold = self.plan.options.firing_threshold
        for sel in self.plan.selections:
            raw: list[Ex] = [self.weighted(ri, degrees, chained, bare) for ri in sel.rules]
            for ri, d in zip(sel.rules, self.select(sel, raw), strict=True):
                v = self.g.let(d, f"R{ri}")
                if threshold > 0.0:
                    with self.g.b.if_(v.le(threshold)):
                        self.g.b.set(v, 0.0)
                out[ri] = v
        return out

    def _normalise(self, ci: int, chained: dict[tuple[int, int], Var]) -> None:
        """NSUM: a chained variable's degrees divided by max(1, their maximum) before reading."""
        g, b = self.g, self.g.b
        if norms.normalised(self.plan.chained[ci].accu) and self.plan.chained[ci].terms:
            top = g.let(1.0, "TOP")
            names = [chained[(ci, t)] for t in range(len(self.plan.chained[ci].terms))]
            for n in names:  # max([1.0, *accs])
                with b.if_(n.gt(top)):
                    b.set(top, n)
            for n in names:
                b.set(n, n / top)

    def conclude(
        self,
        ri: int,
        a: Ex,
        weights: Params,
        concl: list[list[tuple[Ex, Ex]]],
        chained: dict[tuple[int, int], Var],
        bare: dict[int, Var],
    ) -> None:
        """Hedged degree and weight of each conclusion of rule ``ri``; chained targets
        accumulate at once."""
        plan, g = self.plan, self.g
        opts = plan.options
        rule = plan.rules[ri]
        carried: Ex = a
        for cj, cp in enumerate(rule.conclusions):
            base = carried if opts.hedges_carry_over else a
            ah = T.hedged(g, base, cp.hedges, False) if cp.hedges else base
            if opts.hedges_carry_over:
                carried = ah
            w = (
                self.pv(cp.weight, weights, f"rule {rule.label} conclusion {cj + 1}")
                if (isinstance(cp.weight, Slot) or cp.weight != 1.0)
                else Num(1.0)
            )
            concl[ri].append((ah, w))
            for ch in cp.chained:
                accu = plan.chained[ch].accu
                target = bare[ch] if cp.term is None else chained[(ch, cp.term)]
                T.accumulate_into(g, accu, target, T.mul(w, ah))

    def cond(
        self,
        c: CondPlan,
        degrees: dict[tuple[int, int], Ex],
        chained: dict[tuple[int, int], Var],
        bare: dict[int, Var],
    ) -> Ex:
        g = self.g
        if isinstance(c, CTerm | CChained):
            table: dict[tuple[int, int], Ex] = degrees if isinstance(c, CTerm) else dict(chained)
            d = Num(1.0) if "any" in c.hedges else table[(c.var, c.term)]
            return T.hedged(g, d, c.hedges, c.negated)
        if isinstance(c, CDegree):
            return self.inputs[c.slot] if c.slot is not None else bare[c.chained or 0]
        if isinstance(c, CNot):
            return g.let(1.0 - self.cond(c.operand, degrees, chained, bare), "N")
        if isinstance(c, CAnd | COr):
            acc = self.cond(c.operands[0], degrees, chained, bare)
            for o in c.operands[1:]:
                v = self.cond(o, degrees, chained, bare)
                acc = (T.tnorm if isinstance(c, CAnd) else T.snorm)(g, c.op, acc, v)
            return acc
        assert isinstance(c, CTrue)
        return Num(1.0)

    # ------------------------------------------------------------------ outputs

    def contribs(self, op: OutputPlan, concl: list[list[tuple[Ex, Ex]]]) -> list[Contrib]:
        """(term, degree, weight, act) with the weight placement of the options
        (``interp._contribs``; the a*w > 0 filter is emitted where they are used)."""
        out: list[Contrib] = []
        for c in op.contributions:
            ah, w = concl[c.rule][c.conclusion]
            if self.plan.options.weight_before_activation and not (isinstance(w, Num) and w.value == 1.0):
                out.append((c.term, self.g.let(ah * w, "AW"), ex(1.0), c.act))
            else:
                out.append((c.term, ah, w, c.act))
        return out

    def degree_output(self, op: OutputPlan, contribs: list[Contrib]) -> tuple[Ex, Ex]:
        g = self.g
        v = g.let(0.0, "Y")
        for _t, a, w, _act in contribs:
            with g.b.if_(T.mul(w, a).gt(0.0)):
                T.accumulate_into(g, op.accu or "MAX", v, T.mul(w, a))
        return v, ex(True)

    def scale_tiny(self, contribs: list[Contrib]) -> list[Contrib]:
        """``pwl.tiny_degree_scale`` in the program: the same power-of-two steps on the
        largest degree, applied to every degree of the output (exact)."""
        if not contribs:
            return contribs
        g = self.g
        # a degree read by this output only is scaled where it is (no copy)
        hs = [
            a if isinstance(a, Var) and a.name in self.single_use else g.let(a, "H")
            for _t, a, _w, _act in contribs
        ]
        top = g.let(hs[0], "TOP")
        for h in hs[1:]:
            with g.b.if_(h.gt(top)):
                g.b.set(top, h)
        low = top.lt(pwl.TINY_BELOW)  # checked once outside: the usual case costs one test
        with g.b.if_(low, rare=True), g.b.for_(g.counter("K"), 1, pwl.TINY_COUNT), g.b.if_(low):
            g.b.set(top, top * pwl.TINY_FACTOR)
            for h in hs:
                g.b.set(h, h * pwl.TINY_FACTOR)
        return [(t, h, w, act) for (t, _a, w, act), h in zip(contribs, hs, strict=True)]

    def singleton(self, op: OutputPlan, contribs: list[Contrib]) -> tuple[Ex, Ex]:
        g = self.g
        contribs = self.scale_tiny(contribs)
        b = g.b
        accu = op.accu or "MAX"
        sx = self.new_params(f"{op.name}_S", "OS", f"{op.name}: singleton positions")
        sy = self.new_params(f"{op.name}_SY", "OSY", f"{op.name}: singleton degrees")
        entries: list[list[tuple[Ex, Ex]]] = []
        for term in op.terms:
            if term.kind == "singleton":
                entries.append([(self.pv(term.params[0], sx, term.name), Num(1.0))])
            else:
                es: list[tuple[Ex, Ex]] = []
                for k in range(0, len(term.params), 2):
                    es.append(
                        (
                            self.pv(term.params[k], sx, f"{term.name} x{k // 2}"),
                            self.pv(term.params[k + 1], sy, f"{term.name} y{k // 2}"),
                        )
                    )
                entries.append(es)
        acc = {
            (t, i): g.let_named(0.0, f"ACC_{op.name}_{op.terms[t].name}" + (f"_{i}" if len(es) > 1 else ""))
            if self.readable
            else g.let(0.0, "ACC")
            for t, es in enumerate(entries)
            for i in range(len(es))
        }
        pool: list[tuple[str, str]] = []  # the activation's temporaries, shared by the rules
        for t, a, w, act in contribs:
            assert t is not None
            decl_mark, stmt_mark = len(g.decls), len(b.cur)
            with b.if_(T.mul(w, a).gt(0.0)):
                for i, (_x, y) in enumerate(entries[t]):
                    c = T.mul(w, T.tnorm(g, act, a, y))
                    T.accumulate_into(g, accu, acc[(t, i)], c)
            share_temps(g, decl_mark, b.cur[stmt_mark:], pool, f"ACT_{op.name}" if self.readable else "ACT")
        used = sorted({t for t, _a, _w, _act in contribs if t is not None})
        keys = [(t, i) for t in used for i in range(len(entries[t]))]
        value = g.temp(hint="Y")
        fired = g.temp("BOOL", "FIRED")
        total = g.let(0.0, "DEN")
        for key in keys:
            b.set(total, total + acc[key])
        b.set(fired, total.gt(0.0))
        if METHODS[op.method].weighted is not None:
            num = g.let(0.0, "NUM")
            for key in keys:
                b.set(num, num + entries[key[0]][key[1]][0] * acc[key])
            with b.if_(fired):
                b.set(value, num / total)
            with b.else_():
                b.set(value, 0.0)
            return value, fired
        self._singleton_maxima(op, entries, keys, acc, value, fired)
        return value, fired

    def _singleton_maxima(
        self,
        op: OutputPlan,
        entries: list[list[tuple[Ex, Ex]]],
        keys: list[tuple[int, int]],
        acc: dict[tuple[int, int], Var],
        value: Var,
        fired: Var,
    ) -> None:
        """LM / RM / MoM over the positions reaching the largest degree (exact equality)."""
        g = self.g
        b = g.b
        sup = g.let(0.0, "SUP")
        for key in keys:
            with b.if_(acc[key].gt(sup)):
                b.set(sup, acc[key])
        lm, rm, s, n = g.let(0.0, "LMX"), g.let(0.0, "RMX"), g.let(0.0, "SUM"), g.let(0, "CNT", "INT")
        for idx, key in enumerate(keys):
            x = entries[key[0]][key[1]][0]
            with b.if_(acc[key].eq(sup).and_(sup.gt(0.0))):
                with b.if_(n.eq(0).or_(x.lt(lm))):
                    b.set(lm, x)
                with b.if_(n.eq(0).or_(x.gt(rm))):
                    b.set(rm, x)
                # count each position once (the engine takes the set of positions)
                dup: Ex = ex(False)
                for k2 in keys[:idx]:
                    x2 = entries[k2[0]][k2[1]][0]
                    dup = dup.or_(acc[k2].eq(sup).and_(x2.eq(x)))
                with b.if_(not_(dup)):
                    b.set(s, s + x)
                    b.set(n, n + 1)
        with b.if_(fired.and_(n.gt(0))):
            b.set(value, {"LM": lm, "RM": rm}.get(op.method, s / g.call("TO_REAL", n)))
        with b.else_():
            b.set(value, 0.0)

    def ts(self, op: OutputPlan, contribs: list[Contrib], values: dict[int, Ex]) -> tuple[Ex, Ex]:
        g = self.g
        b = g.b
        zs: dict[int, Ex] = {}
        coef = self.new_params(f"{op.name}_Z", "OZ", f"{op.name}: Takagi-Sugeno values and coefficients")
        num = g.let(0.0, "NUM")
        den = g.let(0.0, "DEN")
        if op.accu is None:
            for t, a, w, _act in contribs:
                assert t is not None
                wt = g.let(T.mul(w, a), "WT")
                zt = self._ts_value(op, t, values, zs, coef, wt)
                with b.if_(wt.gt(0.0)):
                    b.set(num, num + wt * zt)
                    b.set(den, den + wt)
        else:
            per: dict[int, Var] = {}
            for t, a, w, _act in contribs:
                assert t is not None
                if t not in per:
                    per[t] = g.let(0.0, "WT")
                with b.if_(T.mul(w, a).gt(0.0)):
                    T.accumulate_into(g, op.accu, per[t], T.mul(w, a))
            for t in sorted(per):
                zt = self._ts_value(op, t, values, zs, coef, per[t])
                with b.if_(per[t].gt(0.0)):
                    b.set(num, num + per[t] * zt)
                    b.set(den, den + per[t])
        fired = g.let(den.gt(0.0), "FIRED", "BOOL")
        value = g.temp(hint="Y")
        with b.if_(fired):
            b.set(value, num / den if METHODS[op.method].weighted == "average" else num)
        with b.else_():
            b.set(value, 0.0)
        return value, fired

    def _ts_value(
        self, op: OutputPlan, t: int, values: dict[int, Ex], zs: dict[int, Ex], coef: Params, wt: Ex
    ) -> Ex:
        """z of a Takagi-Sugeno term (computed once per evaluation); of a Tsukamoto term,
        where it reaches the weight ``wt`` (computed for each weight)."""
        g = self.g
        term = op.terms[t]
        where = f"term {op.name}.{term.name}"
        if term.kind in shapes.TSUKAMOTO_KINDS:
            ps = [self.pv(p, coef, f"{term.name} {k}") for k, p in enumerate(term.params)]
            pts = None
            if term.kind == "points" and not any(isinstance(p, Slot) for p in (*term.params, term.height)):
                pts = shapes.pwl_points("points", [float(p) for p in term.params], float(term.height))  # type: ignore[arg-type]
            return T.tsukamoto(g, term.kind, ps, self.pv(term.height, None, ""), wt, pts)
        if t in zs:
            return zs[t]
        n_in = len(self.plan.inputs)
        if term.kind == "singleton" or registry.flag(term.kind, "ts_constant"):
            zs[t] = self.pv(term.params[0], coef, term.name)
        elif registry.flag(term.kind, "ts_linear"):
            acc: Ex = Num(0.0)
            for i, c in enumerate(term.params[:n_in]):
                acc = acc + self.pv(c, coef, f"{term.name} * {self.plan.inputs[i].name}") * self.inputs[i]
            if len(term.params) > n_in:
                acc = acc + self.pv(term.params[n_in], coef, f"{term.name} constant")
            zs[t] = g.let(acc, "Z")
        else:
            assert term.expr is not None
            if uses_x(term.expr):
                raise g.refuse(where, "a function of x on a Takagi-Sugeno output")
            zs[t] = g.let(self.function_term(term.expr, None, lambda o: values[o], where), "Z")
        return zs[t]


def single_use(g: Gen, contribs: dict[int, list[Contrib]]) -> set[str]:
    """The REAL scalar temporaries that appear as exactly one contribution's degree over all
    outputs (the rule variables of a rule with one conclusion, say)."""
    seen: dict[str, int] = {}
    for cs in contribs.values():
        for _t, a, _w, _act in cs:
            if isinstance(a, Var):
                seen[a.name] = seen.get(a.name, 0) + 1
    temps = {d.name for d in g.decls if d.storage == "temp" and d.type == "REAL" and d.size is None}
    return {n for n, k in seen.items() if k == 1 and n in temps}


def _no_outputs(_o: int) -> Ex:
    raise AssertionError("input terms cannot read outputs")


def literal(v: float) -> Ex:
    """A REAL literal, NaN included (``DEFAULT := nan``)."""
    if math.isnan(v):
        return Call("NAN", ())
    return Num(v)


def chained_reads(c: CondPlan) -> set[int]:
    if isinstance(c, CChained):
        return {c.var}
    if isinstance(c, CNot):
        return chained_reads(c.operand)
    if isinstance(c, CAnd | COr):
        out: set[int] = set()
        for o in c.operands:
            out |= chained_reads(o)
        return out
    return set()


_chained_reads = chained_reads


def _param_names(kind: str, n: int) -> list[str]:
    from fuzzyctl.model import SHAPES

    spec = SHAPES.get(kind)
    names = list(spec.params) if spec is not None else []
    return (names + [f"p{i}" for i in range(len(names), n)])[:n]


__all__ = ["Contrib", "Literals", "Params", "RuleBuilder", "TermPlan", "chained_reads", "literal"]
