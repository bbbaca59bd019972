"""Lowering: FunctionBlock -> :class:`~fuzzyctl.engine.plan.Plan`, with every semantic
decision the standard leaves open made here, once (documented in docs/engine.md).

:func:`lower` returns the plan and the diagnostics; a plan is produced only when there is no
error.  Whatever the FCL parser accepts either lowers or yields an error diagnostic here, so
:func:`fuzzyctl.engine.support.unsupported` is this module's diagnostics.
"""

from __future__ import annotations

import dataclasses
import heapq
import math
from collections.abc import Iterable
from dataclasses import dataclass, field

from fuzzyctl import model as m
from fuzzyctl.diagnostics import Diagnostic, error, warning
from fuzzyctl.engine import operators as ops
from fuzzyctl.engine import shapes
from fuzzyctl.engine.grid import build_grid
from fuzzyctl.engine.plan import (
    CAnd,
    CChained,
    CDegree,
    ChainedPlan,
    CNot,
    ConclusionPlan,
    CondPlan,
    Contribution,
    COr,
    CTerm,
    CTrue,
    EBinary,
    ECall,
    EInput,
    ENum,
    EOutput,
    EUnary,
    EX,
    ExprPlan,
    FuzzyInputPlan,
    InputPlan,
    Options,
    OutputPlan,
    Plan,
    PParam,
    RulePlan,
    Slot,
    TermPlan,
)

METHOD_ALIASES = {"MM": "MOM", "COGF": "WTAVER", "CENTROID": "COG", "BISECTOR": "COA",
                  "SOM": "LM", "LOM": "RM", "WTAV": "WTAVER"}
FUNCTIONS = frozenset({"sin", "cos", "tan", "asin", "acos", "atan", "sinh", "cosh", "tanh", "exp",
                       "log", "log10", "sqrt", "abs", "fabs", "floor", "ceil", "round", "pow",
                       "min", "max", "atan2", "fmod", "sign", "ln"})
CONSTANTS = {"pi": math.pi, "e": math.e}
HEDGE_NAMES = frozenset(shapes.HEDGES)


@dataclass
class _Ctx:
    fb: m.FunctionBlock
    options: Options
    diags: list[Diagnostic] = field(default_factory=list)
    slots: dict[str, int] = field(default_factory=dict)
    constants: dict[str, float] = field(default_factory=dict)

    def err(self, msg: str, span: m.Span | None, code: str, hint: str | None = None) -> None:
        self.diags.append(error(msg, span, code=code, hint=hint))

    def warn(self, msg: str, span: m.Span | None, code: str) -> None:
        self.diags.append(warning(msg, span, code=code))


def lower(fb: m.FunctionBlock, options: Options | None = None) -> tuple[Plan | None, list[Diagnostic]]:
    """Lower ``fb``; returns ``(plan, diagnostics)`` with ``plan`` None when there are errors."""
    ctx = _Ctx(fb, options or Options())
    plan = _lower(ctx)
    if any(d.is_error for d in ctx.diags):
        return None, ctx.diags
    return plan, ctx.diags


# --------------------------------------------------------------------------- parameters and terms


def _param(ctx: _Ctx, p: m.Param, where: str) -> PParam | None:
    if isinstance(p, m.Ref):
        if p.name in ctx.slots:
            return Slot(ctx.slots[p.name])
        if p.name in ctx.constants:
            return ctx.constants[p.name]
        ctx.err(f"{where}: parameter {p.name!r} is not a VAR_INPUT (only inputs can give values at run time)",
                p.span, "param-not-input")
        return None
    v = float(p)
    if not math.isfinite(v):
        ctx.err(f"{where}: parameter {v} is not a finite number", None, "param-not-finite")
        return None
    return v


def _expr(ctx: _Ctx, e: m.Expr, where: str, outputs: dict[str, int], allow_x: bool) -> ExprPlan | None:
    if isinstance(e, m.Num):
        return ENum(float(e.value))
    if isinstance(e, m.Name):
        if e.name in ctx.slots:
            return EInput(ctx.slots[e.name])
        if e.name in outputs:
            return EOutput(outputs[e.name])
        if e.name in ctx.constants:
            return ENum(ctx.constants[e.name])
        if allow_x and e.name == "x":
            return EX()
        if e.name.lower() in CONSTANTS:
            return ENum(CONSTANTS[e.name.lower()])
        ctx.err(f"{where}: function refers to {e.name!r}, which is not an input or output", None, "function-name")
        return None
    if isinstance(e, m.Unary):
        inner = _expr(ctx, e.operand, where, outputs, allow_x)
        return EUnary(e.op, inner) if inner is not None else None
    if isinstance(e, m.Binary):
        if e.op not in {"+", "-", "*", "/", "^", "%"}:
            ctx.err(f"{where}: unknown operator {e.op!r} in function", None, "function-op")
            return None
        left = _expr(ctx, e.left, where, outputs, allow_x)
        right = _expr(ctx, e.right, where, outputs, allow_x)
        return EBinary(e.op, left, right) if left is not None and right is not None else None
    fname = e.function.lower()
    if fname not in FUNCTIONS:
        ctx.err(f"{where}: unknown function {e.function!r}", None, "function-unknown")
        return None
    args = [_expr(ctx, a, where, outputs, allow_x) for a in e.args]
    if any(a is None for a in args):
        return None
    return ECall(fname, tuple(a for a in args if a is not None))


def _term(ctx: _Ctx, t: m.Term, var: str, outputs: dict[str, int], is_output: bool) -> TermPlan | None:
    where = f"term {var}.{t.name}"
    mf = t.mf
    if isinstance(mf, m.PointsMF):
        if not mf.points:
            ctx.err(f"{where} has no points", t.span, "term-empty")
            return None
        raw: list[PParam | None] = []
        for pt in mf.points:
            raw += [_param(ctx, pt.x, where), _param(ctx, pt.y, where)]
        if any(p is None for p in raw):
            return None
        params = tuple(p for p in raw if p is not None)
        tp = TermPlan(t.name, "points", params)
    elif isinstance(mf, m.SingletonMF):
        v = _param(ctx, mf.value, where)
        if v is None:
            return None
        tp = TermPlan(t.name, "singleton", (v,))
    elif isinstance(mf, m.SingletonsMF):
        raw = []
        for pt in mf.points:
            raw += [_param(ctx, pt.x, where), _param(ctx, pt.y, where)]
        if any(p is None for p in raw) or not raw:
            if not raw:
                ctx.err(f"{where} has no points", t.span, "term-empty")
            return None
        tp = TermPlan(t.name, "singletons", tuple(p for p in raw if p is not None))
    elif isinstance(mf, m.ShapeMF):
        spec = m.SHAPES.get(mf.kind)
        if spec is None:
            ctx.err(f"{where}: unknown shape {mf.kind!r}", t.span, "shape-unknown")
            return None
        if not spec.variadic and len(mf.params) != len(spec.params):
            ctx.err(f"{where}: {mf.kind} takes {len(spec.params)} parameters "
                    f"({', '.join(spec.params)}), got {len(mf.params)}", t.span, "shape-arity")
            return None
        raw = [_param(ctx, p, where) for p in mf.params]
        h = _param(ctx, mf.height, where)
        if any(p is None for p in raw) or h is None:
            return None
        params = tuple(p for p in raw if p is not None)
        if mf.kind in ("constant", "linear") and not is_output:
            ctx.err(f"{where}: {mf.kind} terms are Takagi-Sugeno outputs, not input sets", t.span, "ts-on-input")
            return None
        tp = TermPlan(t.name, mf.kind, params, h)
        _check_shape(ctx, tp, t.span, where)
    else:
        ex = _expr(ctx, mf.expr, where, outputs if is_output else {}, allow_x=not is_output)
        if ex is None:
            return None
        tp = TermPlan(t.name, "function", (), 1.0, ex)
    if tp.constant and tp.kind in shapes.PWL_KINDS:
        pts = shapes.pwl_points(tp.kind, [float(p) for p in tp.params if not isinstance(p, Slot)],
                                float(tp.height) if not isinstance(tp.height, Slot) else 1.0)
        tp = TermPlan(tp.name, tp.kind, tp.params, tp.height, tp.expr, pts)
    return tp


def _check_shape(ctx: _Ctx, tp: TermPlan, span: m.Span | None, where: str) -> None:
    if not tp.constant:
        return
    p = [float(v) for v in tp.params if not isinstance(v, Slot)]
    bad = None
    if tp.kind == "triangle" and not (p[0] <= p[1] <= p[2]):
        bad = "needs a <= b <= c"
    elif tp.kind == "trapezoid" and not (p[0] <= p[1] <= p[2] <= p[3]):
        bad = "needs a <= b <= c <= d"
    elif tp.kind in ("gaussian", "gaussian2") and (p[1] == 0.0 or (tp.kind == "gaussian2" and p[3] == 0.0)):
        bad = "needs a nonzero standard deviation"
    elif tp.kind == "bell" and p[1] == 0.0:
        bad = "needs a nonzero width"
    elif tp.kind in ("cosine", "spike") and p[1] == 0.0:
        bad = "needs a nonzero width"
    elif tp.kind in ("sshape", "zshape") and not p[0] < p[1]:
        bad = "needs start < end"
    elif tp.kind == "pishape" and not (p[0] < p[1] and p[2] < p[3]):
        bad = "needs a < b and c < d"
    elif tp.kind in ("arc", "semiellipse") and p[0] == p[1]:
        bad = "needs start != end"
    elif tp.kind == "cosine_half" and p[1] == 0.0:
        bad = "needs a nonzero half width"
    if bad:
        ctx.err(f"{where}: {tp.kind} {bad}", span, "shape-params")


def _first_terms(ctx: _Ctx, var: str, terms: Iterable[m.Term]) -> list[m.Term]:
    """Terms in declaration order; a repeated name keeps its first definition (as fuzzylite
    C++ does) and is reported."""
    seen: dict[str, m.Term] = {}
    out: list[m.Term] = []
    for t in terms:
        if t.name in seen:
            ctx.warn(f"term {t.name!r} of {var} is defined twice; the first definition is used",
                     t.span, "duplicate-term")
            continue
        seen[t.name] = t
        out.append(t)
    return out


# --------------------------------------------------------------------------- the block


def _lower(ctx: _Ctx) -> Plan | None:  # noqa: C901 - one pass over the block, in order
    fb = ctx.fb
    seen_vars: set[str] = set()
    for v in fb.variables:
        if v.name in seen_vars:
            ctx.err(f"variable {v.name!r} is declared twice", v.span, "duplicate-variable")
        seen_vars.add(v.name)
    inputs: list[InputPlan] = []
    for v in fb.inputs:
        ctx.slots[v.name] = len(inputs)
        default = float(v.initial) if isinstance(v.initial, int | float) and not isinstance(v.initial, bool) else None
        inputs.append(InputPlan(v.name, default))
    for v in fb.locals:
        if isinstance(v.initial, int | float) and not isinstance(v.initial, bool):
            ctx.constants[v.name] = float(v.initial)
    output_names = {v.name: i for i, v in enumerate(fb.outputs)}

    # ---- rule blocks: operators
    block_ops: list[tuple[str, str, str, str | None]] = []
    for rb in fb.rule_blocks:
        try:
            and_op, or_op = ops.resolve_pair(rb.and_op, rb.or_op)
        except KeyError as exc:
            ctx.err(f"rule block {rb.name or ''}: unknown AND/OR operator {exc.args[0]!r}", rb.span, "operator-unknown")
            and_op, or_op = "MIN", "MAX"
        try:
            act = ops.resolve_act(rb.act)
        except KeyError:
            ctx.err(f"rule block {rb.name or ''}: unknown activation {rb.act!r}", rb.span, "act-unknown")
            act = "MIN"
        accu: str | None = None
        if rb.accu is not None:
            try:
                accu = ops.resolve_accu(rb.accu)
            except KeyError:
                ctx.err(f"rule block {rb.name or ''}: unknown accumulation {rb.accu!r}", rb.span, "accu-unknown")
        block_ops.append((and_op, or_op, act, accu))

    # ---- who is concluded, and how
    concluded_terms: dict[str, list[tuple[int, m.Conclusion]]] = {}
    concluded_bare: dict[str, list[tuple[int, m.Conclusion]]] = {}
    for bi, rb in enumerate(fb.rule_blocks):
        for rule in rb.rules:
            for c in rule.conclusions:
                target = concluded_bare if c.term is None else concluded_terms
                target.setdefault(c.variable, []).append((bi, c))
                var = fb.variable(c.variable)
                if var is None:
                    ctx.err(f"rule {rule.label}: conclusion on undeclared variable {c.variable!r}", c.span,
                            "undeclared-variable")
                elif var.kind is m.VarKind.INPUT:
                    ctx.err(f"rule {rule.label}: conclusion on input {c.variable!r}", c.span, "conclusion-on-input")

    def term_source(name: str) -> list[m.Term] | None:
        db = fb.defuzzify_block(name)
        if db is not None:
            return _first_terms(ctx, name, db.terms)
        fz = fb.fuzzify_block(name)
        if fz is not None and name not in ctx.slots:
            return _first_terms(ctx, name, fz.terms)
        return None

    # ---- fuzzified inputs
    fuzzy_inputs: list[FuzzyInputPlan] = []
    fuzzy_index: dict[str, int] = {}
    for fz in fb.fuzzify:
        var = fb.variable(fz.variable)
        if var is None:
            ctx.err(f"FUZZIFY of undeclared variable {fz.variable!r}", fz.span, "undeclared-variable")
            continue
        if var.kind is not m.VarKind.INPUT:
            if fz.variable not in concluded_terms and fz.variable not in concluded_bare:
                ctx.err(f"FUZZIFY {fz.variable}: {var.kind.value} variable never receives a value "
                        "(only inputs, or variables concluded by rules, can be used in conditions)",
                        fz.span, "fuzzify-no-value")
            continue
        terms = [_term(ctx, t, fz.variable, {}, False) for t in _first_terms(ctx, fz.variable, fz.terms)]
        for t in terms:
            if t is not None and t.kind in shapes.TS_KINDS - {"function"}:
                ctx.err(f"term {fz.variable}.{t.name}: {t.kind} is an output-only term", fz.span, "ts-on-input")
        fuzzy_index[fz.variable] = len(fuzzy_inputs)
        fuzzy_inputs.append(FuzzyInputPlan(fz.variable, ctx.slots[fz.variable], tuple(t for t in terms if t is not None)))

    # ---- chained variables: concluded by rules and read in conditions
    referenced: list[str] = []
    for _rb, rule in fb.rules():
        if rule.condition is not None:
            _collect_vars(rule.condition, referenced)
    chained_names = [n for n in dict.fromkeys(referenced) if n in concluded_terms or n in concluded_bare]
    chained_index = {n: i for i, n in enumerate(chained_names)}
    chained_term_names: dict[str, list[str]] = {}
    for n in chained_names:
        src = term_source(n)
        chained_term_names[n] = [t.name for t in src] if src is not None else []

    def accu_for(name: str, db: m.DefuzzifyBlock | None) -> str | None:
        if db is not None and db.accu is not None:
            try:
                return ops.resolve_accu(db.accu)
            except KeyError:
                ctx.err(f"DEFUZZIFY {name}: unknown accumulation {db.accu!r}", db.span, "accu-unknown")
                return None
        found: list[str] = []
        for bi, _c in concluded_terms.get(name, []) + concluded_bare.get(name, []):
            a = block_ops[bi][3]
            if a is not None and a not in found:
                found.append(a)
        if len(found) > 1:
            ctx.warn(f"rule blocks concluding {name} disagree on ACCU ({', '.join(found)}); {found[0]} is used",
                     db.span if db else None, "accu-disagree")
        return found[0] if found else None

    chained: list[ChainedPlan] = []
    for n in chained_names:
        chained.append(ChainedPlan(n, tuple(chained_term_names[n]), accu_for(n, fb.defuzzify_block(n)) or "MAX"))

    # ---- rules
    rules: list[RulePlan] = []
    rule_deps: list[set[str]] = []
    rule_concludes: list[set[str]] = []
    for bi, rb in enumerate(fb.rule_blocks):
        and_op, or_op, act, _accu = block_ops[bi]
        for rule in rb.rules:
            deps: set[str] = set()
            cond = (
                _cond(ctx, rule.condition, and_op, or_op, fuzzy_index, chained_index, chained_term_names,
                      concluded_bare, inputs, deps, rule.label)
                if rule.condition is not None
                else CTrue()
            )
            concls: list[ConclusionPlan] = []
            conclusions = rule.conclusions
            if ctx.options.weight_whole_rule:
                w_rule = next((c.weight for c in conclusions if c.weight is not None), None)
                if w_rule is not None:
                    conclusions = tuple(dataclasses.replace(c, weight=w_rule) for c in conclusions)
            for c in conclusions:
                cp = _conclusion(ctx, c, rule.label, output_names, chained_index, term_source, inputs)
                if cp is not None:
                    concls.append(cp)
            if cond is None:
                continue
            rules.append(RulePlan(rule.label, rb.name, cond, act, tuple(concls)))
            rule_deps.append(deps)
            rule_concludes.append({c.variable for c in rule.conclusions})

    order = _rule_order(ctx, rule_deps, rule_concludes, rules)

    # ---- outputs
    outputs: list[OutputPlan] = []
    output_deps: list[set[int]] = []
    for oi, var in enumerate(fb.outputs):
        op = _output(ctx, var, oi, rules, output_names, concluded_terms, concluded_bare, accu_for, term_source)
        if op is None:
            continue
        outputs.append(op)
        deps_o: set[int] = set()
        for t in op.terms:
            if t.expr is not None:
                _expr_outputs(t.expr, deps_o)
        output_deps.append(deps_o)
    if any(d.is_error for d in ctx.diags):
        return None
    output_order = _topo(ctx, [(i, sorted(d)) for i, d in enumerate(output_deps)],
                         lambda cyc: "function terms of outputs depend on each other in a cycle: "
                         + " -> ".join(outputs[i].name for i in cyc))
    if output_order is None or order is None:
        return None
    return Plan(fb.name, tuple(inputs), tuple(fuzzy_inputs), tuple(chained), tuple(rules), tuple(order),
                tuple(outputs), tuple(output_order), ctx.options)


def _collect_vars(c: m.Condition, out: list[str]) -> None:
    if isinstance(c, m.Is | m.Degree):
        out.append(c.variable)
    elif isinstance(c, m.Not):
        _collect_vars(c.operand, out)
    else:
        for o in c.operands:
            _collect_vars(o, out)


def _expr_outputs(e: ExprPlan, out: set[int]) -> None:
    if isinstance(e, EOutput):
        out.add(e.output)
    elif isinstance(e, EUnary):
        _expr_outputs(e.operand, out)
    elif isinstance(e, EBinary):
        _expr_outputs(e.left, out)
        _expr_outputs(e.right, out)
    elif isinstance(e, ECall):
        for a in e.args:
            _expr_outputs(a, out)


def _hedges(ctx: _Ctx, hedges: tuple[str, ...], span: m.Span | None, where: str) -> tuple[str, ...] | None:
    hs = tuple(h.lower() for h in hedges)
    for h in hs:
        if h not in HEDGE_NAMES:
            ctx.err(f"{where}: unknown hedge {h!r} (known: {', '.join(sorted(HEDGE_NAMES))})", span, "hedge-unknown")
            return None
    return hs


def _cond(ctx: _Ctx, c: m.Condition, and_op: str, or_op: str, fuzzy_index: dict[str, int],
          chained_index: dict[str, int], chained_terms: dict[str, list[str]],
          concluded_bare: dict[str, list[tuple[int, m.Conclusion]]], inputs: list[InputPlan],
          deps: set[str], label: str) -> CondPlan | None:
    def rec(x: m.Condition) -> CondPlan | None:
        return _cond(ctx, x, and_op, or_op, fuzzy_index, chained_index, chained_terms, concluded_bare,
                     inputs, deps, label)

    where = f"rule {label}"
    if isinstance(c, m.Is):
        hs = _hedges(ctx, c.hedges, c.span, where)
        if hs is None:
            return None
        if c.variable in chained_index:
            names = chained_terms[c.variable]
            deps.add(c.variable)
            if c.term.lower() == "any" and c.term not in names:
                hs = (*hs, "any")
            if "any" in hs:
                return CChained(chained_index[c.variable], 0, hs, c.negated)
            if c.term not in names:
                ctx.err(f"{where}: {c.variable} has no term {c.term!r}", c.span, "undeclared-term")
                return None
            return CChained(chained_index[c.variable], names.index(c.term), hs, c.negated)
        if c.variable in fuzzy_index:
            fz = ctx.fb.fuzzify_block(c.variable)
            assert fz is not None
            names = [t.name for t in _dedup(fz.terms)]
            if c.term.lower() == "any" and c.term not in names:  # fuzzylite "x is any"
                hs = (*hs, "any")
            if "any" in hs:
                return CTerm(fuzzy_index[c.variable], 0, hs, c.negated)
            if c.term not in names:
                ctx.err(f"{where}: {c.variable} has no term {c.term!r}", c.span, "undeclared-term")
                return None
            return CTerm(fuzzy_index[c.variable], names.index(c.term), hs, c.negated)
        var = ctx.fb.variable(c.variable)
        if var is None:
            ctx.err(f"{where}: undeclared variable {c.variable!r}", c.span, "undeclared-variable")
        elif var.kind is m.VarKind.INPUT:
            ctx.err(f"{where}: input {c.variable!r} has no FUZZIFY block", c.span, "no-fuzzify")
        else:
            ctx.err(f"{where}: {c.variable!r} is used in a condition but no rule concludes on it",
                    c.span, "never-concluded")
        return None
    if isinstance(c, m.Degree):
        if c.variable in ctx.slots:
            i = ctx.slots[c.variable]
            inputs[i] = InputPlan(inputs[i].name, inputs[i].default, True)
            return CDegree(slot=i)
        if c.variable in chained_index and c.variable in concluded_bare:
            deps.add(c.variable)
            return CDegree(chained=chained_index[c.variable])
        ctx.err(f"{where}: bare variable {c.variable!r} in a condition must be an input (a degree) "
                "or a variable concluded without a term", c.span, "degree-variable")
        return None
    if isinstance(c, m.Not):
        inner = rec(c.operand)
        return CNot(inner) if inner is not None else None
    parts = [rec(o) for o in c.operands]
    if any(p is None for p in parts):
        return None
    kids = tuple(p for p in parts if p is not None)
    return CAnd(and_op, kids) if isinstance(c, m.And) else COr(or_op, kids)


def _dedup(terms: tuple[m.Term, ...]) -> list[m.Term]:
    seen: set[str] = set()
    out = []
    for t in terms:
        if t.name not in seen:
            seen.add(t.name)
            out.append(t)
    return out


def _conclusion(ctx: _Ctx, c: m.Conclusion, label: str, output_names: dict[str, int],
                chained_index: dict[str, int], term_source: object, inputs: list[InputPlan]) -> ConclusionPlan | None:
    where = f"rule {label}"
    var = ctx.fb.variable(c.variable)
    if var is None or var.kind is m.VarKind.INPUT:
        return None  # reported while scanning conclusions
    weight: PParam = 1.0
    if c.weight is not None:
        w = _param(ctx, c.weight, f"{where} WITH")
        if w is None:
            return None
        if isinstance(w, Slot):
            inputs[w.index] = InputPlan(inputs[w.index].name, inputs[w.index].default, True)
        elif w < 0.0:
            ctx.err(f"{where}: negative weight {w}", c.span, "weight-negative")
            return None
        weight = w
    hs = _hedges(ctx, c.hedges, c.span, where)
    if hs is None:
        return None
    term_idx: int | None = None
    if c.term is not None:
        assert callable(term_source)
        src = term_source(c.variable)
        if src is None:
            ctx.err(f"{where}: {c.variable} has no terms (no DEFUZZIFY block)", c.span, "no-defuzzify")
            return None
        names = [t.name for t in src]
        if c.term not in names:
            ctx.err(f"{where}: {c.variable} has no term {c.term!r}", c.span, "undeclared-term")
            return None
        term_idx = names.index(c.term)
    outs = (output_names[c.variable],) if c.variable in output_names else ()
    chs = (chained_index[c.variable],) if c.variable in chained_index else ()
    return ConclusionPlan(outs, chs, term_idx, weight, hs)


def _topo(ctx: _Ctx, nodes: list[tuple[int, list[int]]], cycle_msg: object) -> list[int] | None:
    """Kahn's algorithm keeping the written order among independent nodes."""
    n = len(nodes)
    indeg = [0] * n
    users: list[list[int]] = [[] for _ in range(n)]
    for i, deps in nodes:
        for d in set(deps):
            if d == i:
                continue
            indeg[i] += 1
            users[d].append(i)
    heap = [i for i in range(n) if indeg[i] == 0]
    heapq.heapify(heap)
    out: list[int] = []
    while heap:
        i = heapq.heappop(heap)
        out.append(i)
        for u in users[i]:
            indeg[u] -= 1
            if indeg[u] == 0:
                heapq.heappush(heap, u)
    self_loops = [i for i, deps in nodes if i in deps]
    if len(out) < n or self_loops:
        stuck = [i for i in range(n) if i not in out] or self_loops
        assert callable(cycle_msg)
        ctx.err(cycle_msg(stuck), None, "dependency-cycle")
        return None
    return out


def _rule_order(ctx: _Ctx, deps: list[set[str]], concludes: list[set[str]], rules: list[RulePlan]) -> list[int] | None:
    producers: dict[str, list[int]] = {}
    for i, cs in enumerate(concludes):
        for v in cs:
            producers.setdefault(v, []).append(i)
    nodes = [(i, [p for v in d for p in producers.get(v, [])]) for i, d in enumerate(deps)]

    def msg(stuck: list[int]) -> str:
        names = sorted({v for i in stuck for v in deps[i]})
        return ("chained inference forms a cycle through " + ", ".join(names)
                + " (rules " + ", ".join(rules[i].label for i in stuck) + ")")

    return _topo(ctx, nodes, msg)


# --------------------------------------------------------------------------- outputs


def _output(ctx: _Ctx, var: m.Variable, oi: int, rules: list[RulePlan], output_names: dict[str, int],
            concluded_terms: dict[str, list[tuple[int, m.Conclusion]]],
            concluded_bare: dict[str, list[tuple[int, m.Conclusion]]], accu_for: object,
            term_source: object) -> OutputPlan | None:
    assert callable(accu_for)
    fb = ctx.fb
    db = fb.defuzzify_block(var.name)
    contributions = [
        Contribution(ri, ci, c.term, r.act, c.weight)
        for ri, r in enumerate(rules)
        for ci, c in enumerate(r.conclusions)
        if oi in c.outputs
    ]
    if db is None:
        if var.name in concluded_terms:
            ctx.err(f"output {var.name} is concluded with terms but has no DEFUZZIFY block", var.span, "no-defuzzify")
            return None
        if var.name not in concluded_bare:
            ctx.warn(f"output {var.name} is never concluded by a rule and has no DEFUZZIFY block; it stays 0",
                     var.span, "output-unused")
        accu = accu_for(var.name, None) or "MAX"
        return OutputPlan(var.name, "degree", "DEGREE", accu, (), tuple(contributions), 0.0, False)
    if var.name in concluded_bare:
        ctx.err(f"output {var.name} has a DEFUZZIFY block but a rule concludes it without a term",
                concluded_bare[var.name][0][1].span, "bare-on-defuzzified")
        return None
    terms = [_term(ctx, t, var.name, output_names, True) for t in _first_terms(ctx, var.name, db.terms)]
    if any(t is None for t in terms):
        return None
    tps = tuple(t for t in terms if t is not None)
    default = db.default.value if db.default is not None else None
    no_change = db.default.no_change if db.default is not None else True
    method_raw = (db.method or "").upper() or None
    method = METHOD_ALIASES.get(method_raw, method_raw) if method_raw else None
    if method is not None and method not in m.DEFUZZ_METHODS:
        ctx.err(f"DEFUZZIFY {var.name}: unknown method {db.method!r}", db.span, "method-unknown")
        return None
    accu = accu_for(var.name, db)
    kinds = {t.kind for t in tps}
    if not tps:
        ctx.err(f"DEFUZZIFY {var.name} has no terms", db.span, "no-terms")
        return None
    singletonish = kinds <= {"singleton", "singletons"}
    ts_terms = bool(kinds & shapes.TS_KINDS)
    if method in ("COGS", "WTAVER", "WTSUM") and kinds <= shapes.TSUKAMOTO_KINDS:
        # Tsukamoto: a weighted average of where each monotonic term reaches its degree
        ts_accu = accu if accu is not None else ctx.options.ts_default_accu
        return OutputPlan(var.name, "ts", "WTSUM" if method == "WTSUM" else "WTAVER", ts_accu, tps,
                          tuple(contributions), default, no_change)
    if ts_terms or (singletonish and method in ("WTAVER", "WTSUM")):
        if not kinds <= shapes.TS_KINDS | {"singleton"}:
            ctx.err(f"DEFUZZIFY {var.name}: Takagi-Sugeno terms (constant, linear, function) cannot be mixed with "
                    "fuzzy sets", db.span, "mixed-terms")
            return None
        if method not in (None, "WTAVER", "WTSUM", "COGS", "COG"):
            ctx.err(f"DEFUZZIFY {var.name}: {method} does not apply to Takagi-Sugeno terms (use WTAVER or WTSUM)",
                    db.span, "method-ts")
            return None
        for t in tps:
            if t.kind == "linear" and len(t.params) > len(fb.inputs) + 1:
                ctx.err(f"term {var.name}.{t.name}: linear has {len(t.params)} coefficients for "
                        f"{len(fb.inputs)} inputs", db.span, "linear-arity")
                return None
        ts_accu = accu if accu is not None else ctx.options.ts_default_accu
        return OutputPlan(var.name, "ts", "WTSUM" if method == "WTSUM" else "WTAVER", ts_accu, tps,
                          tuple(contributions), default, no_change)
    if singletonish:
        if method == "COA":
            ctx.err(f"DEFUZZIFY {var.name}: CoA is not applicable to singletons (IEC 61131-7 Table 1, note 3)",
                    db.span, "coa-singletons")
            return None
        meth = "COGS" if method in (None, "COG", "COGS") else method
        s_accu = accu or ctx.options.singleton_default_accu or "MAX"
        return OutputPlan(var.name, "singleton", meth, s_accu, tps, tuple(contributions), default, no_change)
    if kinds & {"singleton", "singletons"}:
        ctx.err(f"DEFUZZIFY {var.name}: singletons cannot be mixed with fuzzy sets in one output", db.span,
                "mixed-terms")
        return None
    meth = method or "COG"
    if meth in ("COGS", "WTAVER", "WTSUM"):
        ctx.err(f"DEFUZZIFY {var.name}: {meth} needs singleton or Takagi-Sugeno terms", db.span, "method-terms")
        return None
    rng = db.range or var.range
    if rng is not None:
        low, high = float(rng.low), float(rng.high)
        if not (math.isfinite(low) and math.isfinite(high) and low < high):
            ctx.err(f"DEFUZZIFY {var.name}: RANGE must be finite with min < max", rng.span, "range-invalid")
            return None
    else:
        lows, highs = [], []
        for t in tps:
            if not t.constant:
                ctx.err(f"DEFUZZIFY {var.name}: term {t.name} has variable parameters; give a RANGE",
                        db.span, "range-needed")
                return None
            lo, hi = shapes.support(t.kind, [float(p) for p in t.params if not isinstance(p, Slot)],
                                    float(t.height) if not isinstance(t.height, Slot) else 1.0)
            if not (math.isfinite(lo) and math.isfinite(hi)):
                ctx.err(f"DEFUZZIFY {var.name}: term {t.name} ({t.kind}) is not zero outside a finite interval; "
                        "give a RANGE", db.span, "range-needed")
                return None
            lows.append(lo)
            highs.append(hi)
        low, high = min(lows), max(highs)
        if not low < high:
            ctx.err(f"DEFUZZIFY {var.name}: the terms have no extent; give a RANGE", db.span, "range-needed")
            return None
    acc = accu or "MAX"
    acts = {c.act for c in contributions}
    exact = kinds <= shapes.PWL_KINDS and acts <= {"MIN", "PROD"} and acc in ops.EXACT_ACCU
    grid = None
    if exact and all(t.constant for t in tps):
        used = {c.term for c in contributions if c.term is not None}
        grid = build_grid([t.pwl for t in tps if t.pwl is not None], low, high, used)
    return OutputPlan(var.name, "mamdani", meth, acc, tps, tuple(contributions), default, no_change, low, high,
                      exact, grid)
