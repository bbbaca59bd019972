"""Plan -> :class:`~fuzzyctl.ir.nodes.Program`: one evaluation of a function block as
target-neutral imperative code.

Nothing here decides semantics: every choice (operators, hedges, weights, accumulation,
defaults, chained inference, the exact integration) is read off the
:class:`~fuzzyctl.engine.plan.Plan` that :func:`fuzzyctl.engine.lowering.lower.lower` made, and each
step mirrors the interpreter (:mod:`fuzzyctl.engine.reference.interp`) it is tested against.

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

from fuzzyctl.engine.plan import OutputPlan, Plan, TermPlan
from fuzzyctl.engine.semantics import shapes
from fuzzyctl.ir.builders import quadrature as Q
from fuzzyctl.ir.builders import terms as T
from fuzzyctl.ir.builders.mamdani import ExactOutput, Group, exact_outputs, term_points
from fuzzyctl.ir.builders.rules import Contrib, Params, RuleBuilder, literal, single_use
from fuzzyctl.ir.builders.smooth_methods import method_bound, smooth_method
from fuzzyctl.ir.cost import cost
from fuzzyctl.ir.nodes import Ex, Index, Int, Num, Program, Var, ex, not_
from fuzzyctl.ir.programs.guard import check_known_fields
from fuzzyctl.ir.state import CodegenError, Gen, Target
from fuzzyctl.kinds import norms
from fuzzyctl.kinds.methods import METHODS

#: INFO codes (modelled on the Siemens FUZZY block's INFO byte).
INFO_OK = 0x00
INFO_DISABLED = 0x01  # ENABLE = FALSE: outputs keep their values
INFO_DEFAULT = 0x02  # no rule fired for at least one output: DEFAULT or the previous value
INFO_QUADRATURE = 0x04  # a smooth output's quadrature (or peak search) reached its cap
INFO_DEGREE_RANGE = 0x31  # an input used as a degree (or WITH weight) is outside [0, 1]


class _Builder(RuleBuilder):
    """The PLC function block: rule evaluation from :class:`RuleBuilder`, constants as
    tunable parameter arrays, the output geometry built at run time."""

    def __init__(self, plan: Plan, target: Target) -> None:
        super().__init__(plan, Gen(target))
        self.notes: list[str] = []  # header lines: how smooth outputs are integrated
        self.capped: dict[str, Var] = {}  # smooth output -> TRUE when its quadrature hit the cap
        self.readable = True  # names from the model, rule text comments

    def pwl_points(self, t: TermPlan, xs: Params, ys: Params, where: str) -> list[tuple[Ex, Ex]]:
        """A piecewise-linear term as breakpoints, constant ones as tunable entries."""
        return term_points(self, t, xs, ys, where)

    # ------------------------------------------------------------------ the block

    def build(self) -> Program:
        plan, g = self.plan, self.g
        b = g.b
        self._check()
        for inp in plan.inputs:
            self.inputs.append(self._io(inp.name, "input", inp.default))
        for inp, iv in zip(plan.inputs, list(self.inputs), strict=True):
            if inp.clamp is not None:  # lock-range: the limited value is what everything reads
                lo, hi = inp.clamp
                lim = g.temp(hint="LIM")
                b.set(lim, iv)
                with b.if_(iv.lt(lo)):
                    b.set(lim, lo)
                with b.elif_(iv.gt(hi)):
                    b.set(lim, hi)
                self.inputs[self.inputs.index(iv)] = lim
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
            if not math.isfinite(v) and not g.caps.numbers.nonfinite:
                raise g.refuse(
                    f"output {op.name}: DEFAULT := nan",
                    f"portable {g.caps.label} has no NaN; choose what the block outputs when no "
                    "rule fires with --default VALUE or --default hold (keep the last value)",
                )
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
            contribs = self._rule_section(degrees, weights)
            values: dict[int, Ex] = {}
            exact = [
                oi
                for oi in plan.output_order
                if plan.outputs[oi].kind == "mamdani" and plan.outputs[oi].exact
            ]
            results: dict[int, tuple[Ex, Ex]] = {}
            if exact:
                with b.region("defuzzify (exact, piecewise linear)"):
                    specs = [self._mamdani(plan.outputs[oi], contribs[oi]) for oi in exact]
                    vals, fireds = exact_outputs(g, specs)
                for k, oi in enumerate(exact):
                    results[oi] = (vals[k], fireds[k])
            for oi in plan.output_order:
                op = plan.outputs[oi]
                with b.region(f"output {op.name}"):
                    val, fired = results[oi] if oi in results else self._output(oi, op, contribs[oi], values)
                    if op.name in self.capped:
                        with b.if_(self.capped[op.name].and_(info.eq(Int(INFO_OK)))):
                            b.set(info, Int(INFO_QUADRATURE))
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
                                b.set(outs[oi], literal(op.default if op.default is not None else 0.0))
                    if op.clamp is not None:  # lock-range of the output (DEFAULT and NC included)
                        with b.if_(outs[oi].lt(op.clamp[0])):
                            b.set(outs[oi], op.clamp[0])
                        with b.elif_(outs[oi].gt(op.clamp[1])):
                            b.set(outs[oi], op.clamp[1])
                    b.set(prev[oi], outs[oi])
                    values[oi] = outs[oi]
        for p in self.params:
            p.finish()
        header = [f"function block {plan.name}: generated by fuzzyctl from the lowered plan", *self.notes]
        prog = Program(plan.name or "FUZZY", g.decls, b.root, header, g.uses)
        prog.header += cost(prog).header()
        return prog

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
                for t in op.terms:
                    if not Q.constant_term(t) or t.kind == "function":
                        raise g.refuse(
                            f"term {op.name}.{t.name}",
                            "a smooth output term with parameters given by variables (the "
                            "integration breakpoints are fixed at generation); give it numbers",
                        )
            if op.kind == "ts":
                for t in op.terms:
                    if t.kind in shapes.TSUKAMOTO_KINDS:
                        raise g.refuse(
                            f"term {op.name}.{t.name}",
                            "Tsukamoto (monotonic) outputs are not generated yet; use singleton "
                            "or linear terms for this output, or run the system with the engine",
                        )

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
            px = self.new_params(
                f"{fi.name}_X",
                "PX",
                f"{fi.name}: term points x (sorted only when retuned out of order)",
            )
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
            pp = smooth[var]
            if all(fi.terms[ti].kind in shapes.PWL_KINDS for ti in term_ids):
                continue
            with g.b.region(f"fuzzify {fi.name}"):
                for ti in term_ids:
                    if fi.terms[ti].kind not in shapes.PWL_KINDS:
                        degrees[(var, ti)] = self.fuzzify_term(var, ti, pp)
        return degrees

    def _fuzzify_pwl(
        self, terms: list[tuple[int, int, list[tuple[Ex, Ex]]]], degrees: dict[tuple[int, int], Ex]
    ) -> None:
        """Every piecewise-linear input term.  Points that are all tunable entries are read
        where they are, one unrolled term after the other, while every term's points are in
        order (the engine's stable sort leaves them so); only when a retuned point is out of
        order are they copied and sorted (:meth:`_fuzzify_sorting`).  Points given by inputs
        are sorted on every cycle."""
        g = self.g
        b = g.b
        fixed = [_fixed_span(ps) for _v, _t, ps in terms]
        if any(f is None for f in fixed):
            self._fuzzify_sorting(terms, degrees, None)
            return
        named = [self._degree_var(v, ti) for v, ti, _p in terms]
        checks: list[Ex] = []
        for span in fixed:
            assert span is not None
            xs, _ys, first, last = span
            checks += [xs[k + 1].lt(xs[k]) for k in range(first, last)]
        found = g.temp_named("FOUND", "BOOL")

        def in_order() -> None:
            for (v, _ti, _p), span, out in zip(terms, fixed, named, strict=True):
                assert span is not None
                xs, ys, first, last = span
                x = self.inputs[self.plan.fuzzy_inputs[v].slot]
                T.pwl_value_fixed(g, xs, ys, first, last, x, out, found)

        if checks:
            disorder = checks[0]
            for c in checks[1:]:
                disorder = disorder.or_(c)
            with b.if_(disorder, rare=True):
                b.comment("a point was retuned out of order: sort copies (stably, as the engine)")
                self._fuzzify_sorting(terms, degrees, named)
            with b.else_():
                in_order()
        else:
            in_order()
        for (v, ti, _p), out in zip(terms, named, strict=True):
            degrees[(v, ti)] = out

    def _degree_var(self, var: int, ti: int) -> Var:
        fi = self.plan.fuzzy_inputs[var]
        return self.g.temp_named(f"DEG_{fi.name}_{fi.terms[ti].name}")

    def _fuzzify_sorting(
        self,
        terms: list[tuple[int, int, list[tuple[Ex, Ex]]]],
        degrees: dict[tuple[int, int], Ex],
        named: list[Var] | None,
    ) -> None:
        """Every piecewise-linear input term in one loop over a table: copy its points, sort
        them (stably: they may come from inputs or be retuned), take the degree at its
        input's value; into ``named`` (one variable per term) when given."""
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
        span = max(counts)
        with b.for_(tt, 0, len(terms) - 1) as tv:
            T.sort_points(g, wx, wy, tab["IOFF"][tv], tab["ILAST"][tv], span)
            at = xin[tab["IVAR"][tv]]
            b.set(deg[tv], T.pwl_value(g, wx, wy, tab["IOFF"][tv], tab["ILAST"][tv], at, span))
        for k, (v, ti, _p) in enumerate(terms):
            if named is None:
                degrees[(v, ti)] = deg[k]
            else:
                b.set(named[k], deg[k])

    # ------------------------------------------------------------------ outputs

    def _rule_section(self, degrees: dict[tuple[int, int], Ex], weights: Params) -> dict[int, list[Contrib]]:
        """Each output's activated sets: one statement per rule, or above
        :data:`~fuzzyctl.ir.programs.evaluator.TABLE_THRESHOLD` rules a loop over constant tables
        (:mod:`fuzzyctl.ir.programs.rule_table`; weights are then table entries, not tunable)."""
        from fuzzyctl.ir.programs.evaluator import TABLE_THRESHOLD
        from fuzzyctl.ir.programs.rule_table import table_applies, table_rules

        plan = self.plan
        if len(plan.rules) >= TABLE_THRESHOLD and table_applies(plan):
            return table_rules(self, degrees, sparse=False)  # type: ignore[arg-type]
        concl = self.rules(degrees, weights)
        out = {oi: self.contribs(op, concl) for oi, op in enumerate(plan.outputs)}
        self.single_use = single_use(self.g, out)
        return out

    def _output(
        self, oi: int, op: OutputPlan, contribs: list[Contrib], values: dict[int, Ex]
    ) -> tuple[Ex, Ex]:
        if op.kind == "degree":
            return self.degree_output(op, contribs)
        if op.kind == "singleton":
            return self.singleton(op, contribs)
        if op.kind == "mamdani":  # not exact: smooth sets
            return self._smooth(op, contribs)
        assert op.kind == "ts"
        return self.ts(op, contribs, values)

    def _smooth(self, op: OutputPlan, contribs: list[Contrib]) -> tuple[Ex, Ex]:
        """A smooth set by its method (CoG, CoA, LM, RM, MoM) on quadrature panels to a
        tolerance fixed now (ir/builders/quadrature.py, smooth_methods.py: the native
        evaluator's IR)."""
        from fuzzyctl.ir.programs.evaluator import merge

        groups = merge(self.g, contribs, op.accu or "MAX")
        sets = [Q.SmoothSet(gr.term, gr.a, gr.w, gr.act) for gr in groups]
        cal = Q.calibrate(op)
        rtol = self.plan.options.quad_rtol
        entry = METHODS[op.method]
        head = f"output {op.name}: smooth set"
        where = f"on {len(cal.cuts) - 1} intervals, split at located kinks"
        if entry.integrating and not entry.bisects:
            self.notes.append(f"{head}, CoG by adaptive Gauss-Kronrod 7/15 {where}: {Q.cog_bound()}")
        else:
            self.notes.append(f"{head}, {op.method} on the panels of adaptive Gauss-Kronrod 7/15 {where}")
            self.notes += [f"output {op.name}: {line}" for line in method_bound(op, rtol)]
        value, fired, capped = smooth_method(self.g, op, sets, cal, rtol)
        self.capped[op.name] = capped
        return value, fired

    def _mamdani(self, op: OutputPlan, contribs: list[Contrib]) -> ExactOutput:
        g = self.g
        assert op.low is not None and op.high is not None
        accu = op.accu or "MAX"
        xs = self.new_params(f"{op.name}_X", "OX", f"{op.name}: term points x (sorted at run time)")
        ys = self.new_params(f"{op.name}_Y", "OY", f"{op.name}: term points degree")
        points = [self.pwl_points(t, xs, ys, t.name) for t in op.terms]
        # what MAX accumulation lets combine before integrating (engine fastprog.merge):
        # max_k w*min(a_k, mu) = w*min(max_k a_k, mu) for one weight, and (w*a)*mu for PROD
        groups: list[Group] = []
        merged: dict[tuple[int, bool, int], Group] = {}
        for t, a, w, act in contribs:
            assert t is not None
            is_min = norms.is_min(act)
            if norms.is_max(accu) and not is_min:
                key = (t, False, 0)
                a = g.let(w * a, "AW") if not (isinstance(w, Num) and w.value == 1.0) else a
                w = ex(1.0)
            elif norms.is_max(accu) and isinstance(w, Num | Index):
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


def _fixed_span(points: list[tuple[Ex, Ex]]) -> tuple[Var, Var, int, int] | None:
    """(x array, y array, first, last) when a term's points are consecutive entries at the same
    indices of two tunable arrays; None when an input gives one of them."""
    if not points:
        return None
    spans = []
    for xe, ye in points:
        if not (isinstance(xe, Index) and isinstance(ye, Index)):
            return None
        if not (isinstance(xe.index, Int) and isinstance(ye.index, Int)):
            return None
        spans.append((xe.name, ye.name, xe.index.value, ye.index.value))
    first = spans[0][2]
    for k, (xn, yn, xi, yi) in enumerate(spans):
        if (xn, yn) != spans[0][:2] or xi != yi or xi != first + k:
            return None
    return Var(spans[0][0]), Var(spans[0][1]), first, first + len(points) - 1


def _weight_key(w: Ex) -> int:
    if isinstance(w, Num):
        return -1  # the literal 1.0 (no WITH)
    assert isinstance(w, Index) and isinstance(w.index, Int)
    return w.index.value


def _info_comment() -> str:
    return (
        f"16#{INFO_OK:02X} ok, 16#{INFO_DISABLED:02X} ENABLE is FALSE (outputs unchanged), "
        f"16#{INFO_DEFAULT:02X} no rule fired for an output (DEFAULT or previous value), "
        f"16#{INFO_QUADRATURE:02X} a smooth output's quadrature hit its cap (may miss its stated bound), "
        f"16#{INFO_DEGREE_RANGE:02X} a degree input is outside 0..1 (outputs unchanged)"
    )


def build_program(plan: Plan, target: Target) -> Program:
    """The program of one lowered function block for ``target`` ("c" or "st").  Raises
    :class:`~fuzzyctl.ir.state.CodegenError` naming the first element the target
    cannot express."""
    if plan.options.emulate is not None:
        raise CodegenError(
            f"the {plan.options.emulate} profile reproduces another tool's arithmetic (1000-point "
            "sets, ...) for cross-checks; generate code from the iec profile"
        )
    return _Builder(plan, target).build()
