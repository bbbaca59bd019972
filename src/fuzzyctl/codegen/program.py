"""Plan -> :class:`~fuzzyctl.codegen.ir.Program`: one evaluation of a function block as
target-neutral imperative code.

Nothing here decides semantics: every choice (operators, hedges, weights, accumulation,
defaults, chained inference, the exact integration) is read off the
:class:`~fuzzyctl.engine.plan.Plan` that :func:`fuzzyctl.engine.lower.lower` made, and each
step mirrors the interpreter (:mod:`fuzzyctl.engine.interp`) it is tested against.

Layout of the generated block
-----------------------------
* inputs (the FCL VAR_INPUT names) and ``ENABLE``; outputs (the FCL VAR_OUTPUT names) and
  ``INFO``;
* tunable parameters (static, initialised from the FCL, changeable online): term points,
  singleton positions, Takagi-Sugeno coefficients, WITH weights - one array per variable,
  its comment says which entry is which;
* state: each output's previous value (``DEFAULT := NC``);
* temporaries.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

from fuzzyctl.codegen import terms as T
from fuzzyctl.codegen.context import CodegenError, Gen, Target
from fuzzyctl.codegen.guard import check_known_fields
from fuzzyctl.codegen.ir import Decl, Ex, Index, Int, Num, Program, Var, ex, not_
from fuzzyctl.codegen.mamdani import ExactOutput, Group, exact_outputs
from fuzzyctl.engine import shapes
from fuzzyctl.engine.lower_terms import uses_x
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
    Slot,
    TermPlan,
)

#: INFO codes (modelled on the Siemens FUZZY block's INFO byte).
INFO_OK = 0x00
INFO_DISABLED = 0x01  # ENABLE = FALSE: outputs keep their values
INFO_DEFAULT = 0x02  # no rule fired for at least one output: DEFAULT or the previous value
INFO_DEGREE_RANGE = 0x31  # an input used as a degree (or WITH weight) is outside [0, 1]


@dataclass
class Params:
    """A tunable parameter array being filled."""

    g: Gen
    name: str
    what: str
    values: list[float] = field(default_factory=list)
    notes: list[str] = field(default_factory=list)

    def add(self, value: float, note: str) -> Index:
        self.values.append(float(value))
        self.notes.append(note)
        return Var(self.name)[len(self.values) - 1]

    def finish(self) -> None:
        if not self.values:
            self.g.names.discard(self.name.upper())
            return
        self.g.decls.append(_param_decl(self))


def _param_decl(p: Params) -> Decl:
    lines = [p.what] + [f"[{i}] {n}" for i, n in enumerate(p.notes)]
    return Decl(p.name, "REAL", "param", len(p.values), tuple(p.values), "\n".join(lines))


class _Builder:
    def __init__(self, plan: Plan, target: Target) -> None:
        self.plan = plan
        self.g = Gen(target)
        self.inputs: list[Ex] = []
        self.params: list[Params] = []

    # ------------------------------------------------------------------ parameters

    def new_params(self, hint: str, fallback: str, what: str) -> Params:
        name = self.g.fresh(hint, fallback)
        self.g.names.add(name.upper())
        p = Params(self.g, name, what)
        self.params.append(p)
        return p

    def pv(self, p: PParam, arr: Params | None, note: str) -> Ex:
        """A parameter: an input's current value, a tunable entry, or a literal."""
        if isinstance(p, Slot):
            return self.inputs[p.index]
        if arr is None:
            return Num(p)
        return arr.add(p, note)

    def pwl_points(self, t: TermPlan, xs: Params, ys: Params, where: str) -> list[tuple[Ex, Ex]]:
        """A piecewise-linear term as breakpoints (x, y) in the engine's order
        (shapes.pwl_points); constant ones are tunable entries."""
        if t.pwl is not None:
            return [
                (xs.add(x, f"{where} x{k}"), ys.add(y, f"{where} y{k}")) for k, (x, y) in enumerate(t.pwl)
            ]
        h = t.height
        if isinstance(h, Slot):
            raise self.g.refuse(where, "a height given by a variable")
        if t.kind == "points":
            out = []
            for k in range(0, len(t.params), 2):
                px, py = t.params[k], t.params[k + 1]
                x = self.pv(px, xs, f"{where} x{k // 2}")
                y: Ex
                if isinstance(py, Slot):
                    y = self.inputs[py.index] if h == 1.0 else self.inputs[py.index] * Num(h)
                else:
                    y = ys.add(py * h, f"{where} y{k // 2}")
                out.append((x, y))
            return out
        if t.kind in ("triangle", "trapezoid"):
            ylist = [0.0, h, 0.0] if t.kind == "triangle" else [0.0, h, h, 0.0]
            return [
                (self.pv(p, xs, f"{where} x{k}"), ys.add(y, f"{where} y{k}"))
                for k, (p, y) in enumerate(zip(t.params, ylist, strict=True))
            ]
        raise self.g.refuse(
            where,
            f"{t.kind} with parameters given by variables (its breakpoints change form with the "
            "order of its parameters; write it as points)",
        )

    # ------------------------------------------------------------------ the block

    def build(self) -> Program:
        plan, g = self.plan, self.g
        b = g.b
        self._check()
        for inp in plan.inputs:
            self.inputs.append(self._io(inp.name, "input", inp.default))
        enable = g.declare("ENABLE", "BOOL", "input", init=True, comment="FALSE: outputs keep their values")
        outs: list[Var] = []
        for op in plan.outputs:
            outs.append(self._io(op.name, "output" if op.is_output else "state", None))
        info = g.declare("INFO", "BYTE", "output", init=0.0, comment=_info_comment())
        init_prev = tuple(
            (op.default if op.default is not None else 0.0) if op.kind != "degree" else 0.0
            for op in plan.outputs
        )
        for op, v in zip(plan.outputs, init_prev, strict=True):
            if not math.isfinite(v) and g.target == "st":
                raise g.refuse(f"output {op.name}: DEFAULT := nan", "portable Structured Text has no NaN")
        prev = g.declare(
            g.fresh("PREV", "PREV"),
            "REAL",
            "state",
            max(1, len(plan.outputs)),
            init_prev or (0.0,),
            "previous output values (DEFAULT := NC)",
        )
        weights = self.new_params("W", "W", "WITH weights of the rules")
        degree_inputs = [self.inputs[i] for i, inp in enumerate(plan.inputs) if inp.degree]
        with b.if_(not_(enable)):
            b.set(info, Int(INFO_DISABLED))
        if degree_inputs:
            bad: Ex = degree_inputs[0].lt(0.0).or_(degree_inputs[0].gt(1.0))
            for di in degree_inputs[1:]:
                bad = bad.or_(di.lt(0.0).or_(di.gt(1.0)))
            with b.elif_(bad):
                b.set(info, Int(INFO_DEGREE_RANGE))
        with b.else_():
            b.set(info, Int(INFO_OK))
            degrees = self._fuzzify()
            concl = self._rules(degrees, weights)
            values: dict[int, Ex] = {}
            exact = [oi for oi in plan.output_order if plan.outputs[oi].kind == "mamdani"]
            results: dict[int, tuple[Ex, Ex]] = {}
            if exact:
                with b.region("defuzzify (exact, piecewise linear)"):
                    specs = [
                        self._mamdani(plan.outputs[oi], self._contribs(plan.outputs[oi], concl))
                        for oi in exact
                    ]
                    vals, fireds = exact_outputs(g, specs)
                for k, oi in enumerate(exact):
                    results[oi] = (vals[k], fireds[k])
            for oi in plan.output_order:
                op = plan.outputs[oi]
                with b.region(f"output {op.name}"):
                    val, fired = results[oi] if oi in results else self._output(oi, op, concl, values)
                    if op.kind == "degree":
                        b.set(outs[oi], val)
                    else:
                        with b.if_(fired):
                            b.set(outs[oi], val)
                        with b.else_():
                            b.set(info, Int(INFO_DEFAULT))
                            if op.no_change:
                                b.set(outs[oi], prev[oi])
                            else:
                                b.set(outs[oi], _literal(op.default if op.default is not None else 0.0))
                    b.set(prev[oi], outs[oi])
                    values[oi] = outs[oi]
        for p in self.params:
            p.finish()
        header = [f"function block {plan.name}: generated by fuzzyctl from the lowered plan"]
        return Program(plan.name or "FUZZY", g.decls, b.root, header, g.uses)

    def _io(self, name: str, storage: str, default: float | None) -> Var:
        g = self.g
        if name.upper().startswith("FZ_") or name.upper() in ("ENABLE", "INFO"):
            raise g.refuse(f"variable {name}", "the name is reserved for the generated code")
        return g.declare(name, "REAL", storage, init=default)  # type: ignore[arg-type]

    def _check(self) -> None:
        g = self.g
        check_known_fields(g, self.plan)
        for op in self.plan.outputs:
            if op.kind == "mamdani" and not op.exact:
                raise g.refuse(
                    f"output {op.name}",
                    "the engine integrates this set numerically (smooth terms, or ACT/ACCU other "
                    "than MIN/PROD and MAX/BSUM/NSUM/SUM/PROBOR); only piecewise-linear sets are "
                    "integrated in closed form by the generated code",
                )
            if op.kind == "ts":
                for t in op.terms:
                    if t.kind in shapes.TSUKAMOTO_KINDS:
                        raise g.refuse(f"term {op.name}.{t.name}", "Tsukamoto (monotonic) outputs")

    # ------------------------------------------------------------------ fuzzification

    def _fuzzify(self) -> dict[tuple[int, int], Ex]:
        plan, g = self.plan, self.g
        degrees: dict[tuple[int, int], Ex] = {}
        by_var: dict[int, list[int]] = {}
        for var, term in plan.terms_read():
            by_var.setdefault(var, []).append(term)
        pwl_terms: list[tuple[int, int, list[tuple[Ex, Ex]]]] = []
        smooth: dict[int, Params] = {}
        for var, term_ids in by_var.items():
            fi = plan.fuzzy_inputs[var]
            px = self.new_params(f"{fi.name}_X", "PX", f"{fi.name}: term points x (sorted at run time)")
            py = self.new_params(f"{fi.name}_Y", "PY", f"{fi.name}: term points degree")
            smooth[var] = self.new_params(f"{fi.name}_P", "PP", f"{fi.name}: term parameters")
            for ti in term_ids:
                t = fi.terms[ti]
                if t.kind in shapes.PWL_KINDS:
                    pwl_terms.append((var, ti, self.pwl_points(t, px, py, t.name)))
        if pwl_terms:
            with g.b.region("fuzzify (piecewise-linear terms)"):
                self._fuzzify_pwl(pwl_terms, degrees)
        for var, term_ids in by_var.items():
            fi = plan.fuzzy_inputs[var]
            x = self.inputs[fi.slot]
            pp = smooth[var]
            if all(fi.terms[ti].kind in shapes.PWL_KINDS for ti in term_ids):
                continue
            with g.b.region(f"fuzzify {fi.name}"):
                for ti in term_ids:
                    t = fi.terms[ti]
                    where = f"term {fi.name}.{t.name}"
                    if t.kind in shapes.PWL_KINDS:
                        continue
                    d: Ex
                    if t.kind == "singleton":
                        pos = self.pv(t.params[0], pp, f"{t.name} position")
                        dv = g.temp(hint="MU")
                        with g.b.if_(x.eq(pos)):
                            g.b.set(dv, self.pv(t.height, None, ""))
                        with g.b.else_():
                            g.b.set(dv, 0.0)
                        d = dv
                    elif t.kind == "function":
                        assert t.expr is not None
                        d = g.let(T.expression(g, t.expr, self.inputs, _no_outputs, x, where), "MU")
                    elif t.kind in shapes.SMOOTH_KINDS:
                        ps = [
                            self.pv(p, pp, f"{t.name} {name}")
                            for p, name in zip(t.params, _param_names(t.kind, len(t.params)), strict=True)
                        ]
                        m: Ex = T.smooth(g, t.kind, ps, x, where)
                        h = t.height
                        d = (
                            m
                            if (not isinstance(h, Slot) and h == 1.0)
                            else g.let(self.pv(h, None, "") * m, "MU")
                        )
                    else:
                        raise g.refuse(where, f"{t.kind} terms on inputs")
                    degrees[(var, ti)] = d
        return degrees

    def _fuzzify_pwl(
        self, terms: list[tuple[int, int, list[tuple[Ex, Ex]]]], degrees: dict[tuple[int, int], Ex]
    ) -> None:
        """Every piecewise-linear input term in one loop over a table: copy its points, sort
        them (stably: they may come from inputs or be retuned), take the degree at its
        input's value."""
        g = self.g
        b = g.b
        counts = [len(p) for _v, _t, p in terms]
        offs = [sum(counts[:k]) for k in range(len(terms))]
        wx = g.array("IX", "REAL", sum(counts))
        wy = g.array("IY", "REAL", sum(counts))
        for k, (_v, _t, ps) in enumerate(terms):
            for i, (xe, ye) in enumerate(ps):
                b.set(wx[offs[k] + i], xe)
                b.set(wy[offs[k] + i], ye)
        slots = sorted({self.plan.fuzzy_inputs[v].slot for v, _t, _p in terms})
        xin = g.array("XIN", "REAL", len(slots))
        for k, slot in enumerate(slots):
            b.set(xin[k], self.inputs[slot])
        const = {
            "IOFF": offs,
            "ILAST": [o + c - 1 for o, c in zip(offs, counts, strict=True)],
            "IVAR": [slots.index(self.plan.fuzzy_inputs[v].slot) for v, _t, _p in terms],
        }
        tab = {
            k: g.declare(g.fresh(k, k), "INT", "const", len(vals), tuple(float(x) for x in vals))
            for k, vals in const.items()
        }
        deg = g.array("DEG", "REAL", len(terms))
        tt = g.counter("TT")
        with b.for_(tt, 0, len(terms) - 1) as tv:
            T.sort_points(g, wx, wy, tab["IOFF"][tv], tab["ILAST"][tv])
            b.set(deg[tv], T.pwl_value(g, wx, wy, tab["IOFF"][tv], tab["ILAST"][tv], xin[tab["IVAR"][tv]]))
        for k, (v, ti, _p) in enumerate(terms):
            degrees[(v, ti)] = deg[k]

    # ------------------------------------------------------------------ rules

    def _rules(self, degrees: dict[tuple[int, int], Ex], weights: Params) -> list[list[tuple[Ex, Ex]]]:
        """Rule degrees in plan order; returns per rule the (hedged degree, weight) of each
        conclusion (``interp.run``)."""
        plan, g = self.plan, self.g
        b = g.b
        opts = plan.options
        chained: dict[tuple[int, int], Var] = {}
        bare: dict[int, Var] = {}
        for ci, chp in enumerate(plan.chained):
            for ti in range(len(chp.terms)):
                chained[(ci, ti)] = g.let(0.0, f"C{ci}_{ti}")
            bare[ci] = g.let(0.0, f"CB{ci}")
        normalised: set[int] = set()
        concl: list[list[tuple[Ex, Ex]]] = [[] for _ in plan.rules]
        with b.region("rules"):
            for ri in plan.order:
                rule = plan.rules[ri]
                b.comment(f"RULE {rule.label}" + (f" (block {rule.block})" if rule.block else ""))
                for ci in sorted(_chained_reads(rule.condition) - normalised):
                    normalised.add(ci)
                    if plan.chained[ci].accu == "NSUM" and plan.chained[ci].terms:
                        top = g.let(1.0, "TOP")
                        names = [chained[(ci, t)] for t in range(len(plan.chained[ci].terms))]
                        for n in names:  # max([1.0, *accs])
                            with b.if_(n.gt(top)):
                                b.set(top, n)
                        for n in names:
                            b.set(n, n / top)
                a = g.let(self._cond(rule.condition, degrees, chained, bare), f"R{ri}")
                if opts.firing_threshold > 0.0:
                    with b.if_(a.le(opts.firing_threshold)):
                        b.set(a, 0.0)
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
        return concl

    def _cond(
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
            return g.let(1.0 - self._cond(c.operand, degrees, chained, bare), "N")
        if isinstance(c, CAnd | COr):
            acc = self._cond(c.operands[0], degrees, chained, bare)
            for o in c.operands[1:]:
                v = self._cond(o, degrees, chained, bare)
                acc = (T.tnorm if isinstance(c, CAnd) else T.snorm)(g, c.op, acc, v)
            return acc
        assert isinstance(c, CTrue)
        return Num(1.0)

    # ------------------------------------------------------------------ outputs

    def _contribs(
        self, op: OutputPlan, concl: list[list[tuple[Ex, Ex]]]
    ) -> list[tuple[int | None, Ex, Ex, str]]:
        """(term, degree, weight, act) with the weight placement of the options
        (``interp._contribs``; the a*w > 0 filter is emitted where they are used)."""
        out: list[tuple[int | None, Ex, Ex, str]] = []
        for c in op.contributions:
            ah, w = concl[c.rule][c.conclusion]
            if self.plan.options.weight_before_activation and not (isinstance(w, Num) and w.value == 1.0):
                out.append((c.term, self.g.let(ah * w, "AW"), ex(1.0), c.act))
            else:
                out.append((c.term, ah, w, c.act))
        return out

    def _output(
        self, oi: int, op: OutputPlan, concl: list[list[tuple[Ex, Ex]]], values: dict[int, Ex]
    ) -> tuple[Ex, Ex]:
        g = self.g
        b = g.b
        contribs = self._contribs(op, concl)
        if op.kind == "degree":
            v = g.let(0.0, "Y")
            for _t, a, w, _act in contribs:
                with b.if_(T.mul(w, a).gt(0.0)):
                    T.accumulate_into(g, op.accu or "MAX", v, T.mul(w, a))
            return v, ex(True)
        if op.kind == "singleton":
            return self._singleton(op, contribs)
        assert op.kind == "ts"
        return self._ts(op, contribs, values)

    def _mamdani(self, op: OutputPlan, contribs: list[tuple[int | None, Ex, Ex, str]]) -> ExactOutput:
        g = self.g
        assert op.low is not None and op.high is not None
        accu = op.accu or "MAX"
        xs = self.new_params(f"{op.name}_X", "OX", f"{op.name}: term points x (sorted at run time)")
        ys = self.new_params(f"{op.name}_Y", "OY", f"{op.name}: term points degree")
        points = [self.pwl_points(t, xs, ys, t.name) for t in op.terms]
        # what MAX accumulation lets combine before integrating (engine batch._merge):
        # max_k w*min(a_k, mu) = w*min(max_k a_k, mu) for one weight, and (w*a)*mu for PROD
        groups: list[Group] = []
        merged: dict[tuple[int, bool, int], Group] = {}
        for t, a, w, act in contribs:
            assert t is not None
            is_min = act == "MIN"
            if accu == "MAX" and not is_min:
                key = (t, False, 0)
                a = g.let(w * a, "AW") if not (isinstance(w, Num) and w.value == 1.0) else a
                w = ex(1.0)
            elif accu == "MAX" and isinstance(w, Num | Index):
                key = (t, True, _weight_key(w))
            else:
                groups.append(Group(t, a, w, is_min))
                continue
            if key in merged:
                gr = merged[key]
                with g.b.if_(a.gt(gr.a)):
                    g.b.set(gr.a, a)  # type: ignore[arg-type]
            else:
                gr = Group(t, g.let(a, "GA"), w, is_min)
                merged[key] = gr
                groups.append(gr)
        return ExactOutput(op.name, op.method, accu, op.low, op.high, points, groups)

    def _singleton(self, op: OutputPlan, contribs: list[tuple[int | None, Ex, Ex, str]]) -> tuple[Ex, Ex]:
        g = self.g
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
        acc = {(t, i): g.let(0.0, "ACC") for t, es in enumerate(entries) for i in range(len(es))}
        for t, a, w, act in contribs:
            assert t is not None
            with b.if_(T.mul(w, a).gt(0.0)):
                for i, (_x, y) in enumerate(entries[t]):
                    c = T.mul(w, T.tnorm(g, act, a, y))
                    T.accumulate_into(g, accu, acc[(t, i)], c)
        used = sorted({t for t, _a, _w, _act in contribs if t is not None})
        keys = [(t, i) for t in used for i in range(len(entries[t]))]
        value = g.temp(hint="Y")
        fired = g.temp("BOOL", "FIRED")
        total = g.let(0.0, "DEN")
        for key in keys:
            b.set(total, total + acc[key])
        b.set(fired, total.gt(0.0))
        if op.method == "COGS":
            num = g.let(0.0, "NUM")
            for key in keys:
                b.set(num, num + entries[key[0]][key[1]][0] * acc[key])
            with b.if_(fired):
                b.set(value, num / total)
            with b.else_():
                b.set(value, 0.0)
            return value, fired
        # LM / RM / MoM over the positions reaching the largest degree (exact equality)
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
        return value, fired

    def _ts(
        self, op: OutputPlan, contribs: list[tuple[int | None, Ex, Ex, str]], values: dict[int, Ex]
    ) -> tuple[Ex, Ex]:
        g = self.g
        b = g.b
        coef = self.new_params(f"{op.name}_Z", "OZ", f"{op.name}: Takagi-Sugeno values and coefficients")
        zs: dict[int, Ex] = {}
        n_in = len(self.plan.inputs)

        def z(t: int) -> Ex:
            if t not in zs:
                term = op.terms[t]
                where = f"term {op.name}.{term.name}"
                if term.kind in ("singleton", "constant"):
                    zs[t] = self.pv(term.params[0], coef, term.name)
                elif term.kind == "linear":
                    acc: Ex = Num(0.0)
                    for i, c in enumerate(term.params[:n_in]):
                        acc = (
                            acc
                            + self.pv(c, coef, f"{term.name} * {self.plan.inputs[i].name}") * self.inputs[i]
                        )
                    if len(term.params) > n_in:
                        acc = acc + self.pv(term.params[n_in], coef, f"{term.name} constant")
                    zs[t] = g.let(acc, "Z")
                else:
                    assert term.expr is not None
                    if uses_x(term.expr):
                        raise g.refuse(where, "a function of x on a Takagi-Sugeno output")
                    zs[t] = g.let(
                        T.expression(g, term.expr, self.inputs, lambda o: values[o], None, where), "Z"
                    )
            return zs[t]

        num = g.let(0.0, "NUM")
        den = g.let(0.0, "DEN")
        if op.accu is None:
            for t, a, w, _act in contribs:
                assert t is not None
                wt = g.let(T.mul(w, a), "WT")
                zt = z(t)
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
                zt = z(t)
                with b.if_(per[t].gt(0.0)):
                    b.set(num, num + per[t] * zt)
                    b.set(den, den + per[t])
        fired = g.let(den.gt(0.0), "FIRED", "BOOL")
        value = g.temp(hint="Y")
        with b.if_(fired):
            b.set(value, num / den if op.method == "WTAVER" else num)
        with b.else_():
            b.set(value, 0.0)
        return value, fired


def _weight_key(w: Ex) -> int:
    if isinstance(w, Num):
        return -1  # the literal 1.0 (no WITH)
    assert isinstance(w, Index) and isinstance(w.index, Int)
    return w.index.value


def _no_outputs(_o: int) -> Ex:
    raise AssertionError("input terms cannot read outputs")


def _literal(v: float) -> Ex:
    if math.isnan(v):
        from fuzzyctl.codegen.ir import Call

        return Call("NAN", ())
    return Num(v)


def _chained_reads(c: CondPlan) -> set[int]:
    if isinstance(c, CChained):
        return {c.var}
    if isinstance(c, CNot):
        return _chained_reads(c.operand)
    if isinstance(c, CAnd | COr):
        out: set[int] = set()
        for o in c.operands:
            out |= _chained_reads(o)
        return out
    return set()


def _param_names(kind: str, n: int) -> list[str]:
    from fuzzyctl.model import SHAPES

    spec = SHAPES.get(kind)
    names = list(spec.params) if spec is not None else []
    return (names + [f"p{i}" for i in range(len(names), n)])[:n]


def _info_comment() -> str:
    return (
        f"16#{INFO_OK:02X} ok, 16#{INFO_DISABLED:02X} ENABLE is FALSE (outputs unchanged), "
        f"16#{INFO_DEFAULT:02X} no rule fired for an output (DEFAULT or previous value), "
        f"16#{INFO_DEGREE_RANGE:02X} a degree input is outside 0..1 (outputs unchanged)"
    )


def build_program(plan: Plan, target: Target) -> Program:
    """The program of one lowered function block for ``target`` ("c" or "st").  Raises
    :class:`~fuzzyctl.codegen.context.CodegenError` naming the first element the target
    cannot express."""
    if plan.options.emulate is not None:
        raise CodegenError(
            f"the {plan.options.emulate} profile reproduces another tool's arithmetic (1000-point "
            "sets, ...) for cross-checks; generate code from the iec profile"
        )
    return _Builder(plan, target).build()
