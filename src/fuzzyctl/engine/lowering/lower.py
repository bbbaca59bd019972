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

from fuzzyctl import model as m
from fuzzyctl.diagnostics import Diagnostic
from fuzzyctl.engine.lowering import jfl_rules as lower_jfl
from fuzzyctl.engine.lowering.outputs import lower_output
from fuzzyctl.engine.lowering.terms import LowerContext, first_terms, lower_param, lower_term
from fuzzyctl.engine.plan import (
    CAnd,
    CChained,
    CDegree,
    ChainedPlan,
    CNot,
    ConclusionPlan,
    CondPlan,
    COr,
    CTerm,
    CTrue,
    EBinary,
    ECall,
    EOutput,
    EUnary,
    ExprPlan,
    FuzzyInputPlan,
    InputPlan,
    Options,
    OutputPlan,
    Plan,
    PParam,
    RulePlan,
    SelectionPlan,
    Slot,
)
from fuzzyctl.engine.semantics import operators as ops
from fuzzyctl.engine.semantics import selection, shapes

HEDGE_NAMES = frozenset(shapes.HEDGES)


def lower(fb: m.FunctionBlock, options: Options | None = None) -> tuple[Plan | None, list[Diagnostic]]:
    """Lower ``fb``; returns ``(plan, diagnostics)`` with ``plan`` None when there are errors.

    A disabled rule block (fuzzylite ``enabled: false``, model ``RuleBlock.enabled``) fires
    none of its rules: it is left out here, as if it were not written."""
    if not all(rb.enabled for rb in fb.rule_blocks):
        fb = dataclasses.replace(fb, rule_blocks=tuple(rb for rb in fb.rule_blocks if rb.enabled))
    ctx = LowerContext(fb, options or Options())
    plan = _lower(ctx)
    if any(d.is_error for d in ctx.diags):
        return None, ctx.diags
    return plan, ctx.diags


# --------------------------------------------------------------------------- the block


@dataclasses.dataclass
class _Block:
    """What lowering one function block has found so far (shared by its phases)."""

    ctx: LowerContext
    inputs: list[InputPlan] = dataclasses.field(default_factory=list)
    output_names: dict[str, int] = dataclasses.field(default_factory=dict)
    block_ops: list[tuple[str, str, str, str | None]] = dataclasses.field(default_factory=list)
    concluded_terms: dict[str, list[tuple[int, m.Conclusion]]] = dataclasses.field(default_factory=dict)
    concluded_bare: dict[str, list[tuple[int, m.Conclusion]]] = dataclasses.field(default_factory=dict)
    fuzzy_inputs: list[FuzzyInputPlan] = dataclasses.field(default_factory=list)
    fuzzy_index: dict[str, int] = dataclasses.field(default_factory=dict)
    chained: list[ChainedPlan] = dataclasses.field(default_factory=list)
    chained_index: dict[str, int] = dataclasses.field(default_factory=dict)
    chained_term_names: dict[str, list[str]] = dataclasses.field(default_factory=dict)
    rules: list[RulePlan] = dataclasses.field(default_factory=list)
    rule_deps: list[set[str]] = dataclasses.field(default_factory=list)
    rule_concludes: list[set[str]] = dataclasses.field(default_factory=list)
    selections: list[SelectionPlan] = dataclasses.field(default_factory=list)

    def term_source(self, name: str) -> list[m.Term] | None:
        fb = self.ctx.fb
        db = fb.defuzzify_block(name)
        if db is not None:
            return first_terms(self.ctx, name, db.terms)
        fz = fb.fuzzify_block(name)
        if fz is not None and name not in self.ctx.slots:
            return first_terms(self.ctx, name, fz.terms)
        return None

    def accu_for(self, name: str, db: m.DefuzzifyBlock | None) -> str | None:
        ctx = self.ctx
        if db is not None and db.accu is not None:
            try:
                return ops.resolve_accu(db.accu)
            except KeyError:
                ctx.err(f"DEFUZZIFY {name}: unknown accumulation {db.accu!r}", db.span, "accu-unknown")
                return None
        found: list[str] = []
        for bi, _c in self.concluded_terms.get(name, []) + self.concluded_bare.get(name, []):
            a = self.block_ops[bi][3]
            if a is not None and a not in found:
                found.append(a)
        if len(found) > 1 and ctx.options.emulate != "jfuzzylogic":  # there each block applies its own
            ctx.warn(
                f"rule blocks concluding {name} disagree on ACCU ({', '.join(found)}); {found[0]} is used",
                db.span if db else None,
                "accu-disagree",
            )
        return found[0] if found else None


def _lower(ctx: LowerContext) -> Plan | None:
    """The phases of lowering, in order; each adds to the :class:`_Block`."""
    b = _Block(ctx)
    _variables(b)
    _block_operators(b)
    _concluded(b)
    _fuzzified(b)
    _chained(b)
    _rules(b)
    order = _rule_order(ctx, b.rule_deps, b.rule_concludes, b.rules)
    outputs, output_order = _outputs(b)
    if output_order is None or order is None:
        return None
    return Plan(
        ctx.fb.name,
        tuple(b.inputs),
        tuple(b.fuzzy_inputs),
        tuple(b.chained),
        tuple(b.rules),
        tuple(order),
        tuple(outputs),
        tuple(output_order),
        ctx.options,
        tuple(b.selections),
    )


def _variables(b: _Block) -> None:
    ctx = b.ctx
    fb = ctx.fb
    seen_vars: set[str] = set()
    for v in fb.variables:
        if v.name in seen_vars:
            ctx.err(f"variable {v.name!r} is declared twice", v.span, "duplicate-variable")
        seen_vars.add(v.name)
    for v in fb.inputs:
        ctx.slots[v.name] = len(b.inputs)
        default = (
            float(v.initial)
            if isinstance(v.initial, int | float) and not isinstance(v.initial, bool)
            else None
        )
        b.inputs.append(InputPlan(v.name, default))
    for v in fb.locals:
        if isinstance(v.initial, int | float) and not isinstance(v.initial, bool):
            ctx.constants[v.name] = float(v.initial)
    b.output_names.update({v.name: i for i, v in enumerate(fb.outputs)})


def _block_operators(b: _Block) -> None:
    """Each rule block's AND/OR pair, activation and accumulation."""
    ctx = b.ctx
    jfl = ctx.options.emulate == "jfuzzylogic"
    for rb in ctx.fb.rule_blocks:
        try:
            and_op, or_op = lower_jfl.operator_pair(rb) if jfl else ops.resolve_pair(rb.and_op, rb.or_op)
        except KeyError as exc:
            ctx.err(
                f"rule block {rb.name or ''}: unknown AND/OR operator {exc.args[0]!r}",
                rb.span,
                "operator-unknown",
            )
            and_op, or_op = "MIN", "MAX"
        try:
            act = ops.resolve_act(rb.act)
        except KeyError:
            ctx.err(f"rule block {rb.name or ''}: unknown activation {rb.act!r}", rb.span, "act-unknown")
            act = "MIN"
        accu: str | None = None
        if rb.accu is not None or jfl:
            try:
                accu = lower_jfl.accumulation(rb) if jfl else ops.resolve_accu(rb.accu)
            except KeyError:
                ctx.err(
                    f"rule block {rb.name or ''}: unknown accumulation {rb.accu!r}", rb.span, "accu-unknown"
                )
        b.block_ops.append((and_op, or_op, act, accu))


def _concluded(b: _Block) -> None:
    """Who is concluded, and how."""
    ctx = b.ctx
    fb = ctx.fb
    for bi, rb in enumerate(fb.rule_blocks):
        for rule in rb.rules:
            for c in rule.conclusions:
                target = b.concluded_bare if c.term is None else b.concluded_terms
                target.setdefault(c.variable, []).append((bi, c))
                var = fb.variable(c.variable)
                if var is None:
                    ctx.err(
                        f"rule {rule.label}: conclusion on undeclared variable {c.variable!r}",
                        c.span,
                        "undeclared-variable",
                    )
                elif var.kind is m.VarKind.INPUT:
                    ctx.err(
                        f"rule {rule.label}: conclusion on input {c.variable!r}",
                        c.span,
                        "conclusion-on-input",
                    )


def _fuzzified(b: _Block) -> None:
    """The fuzzified inputs and their terms (lock-range on the input)."""
    ctx = b.ctx
    fb = ctx.fb
    for fz in fb.fuzzify:
        var = fb.variable(fz.variable)
        if var is None:
            ctx.err(f"FUZZIFY of undeclared variable {fz.variable!r}", fz.span, "undeclared-variable")
            continue
        if var.kind is not m.VarKind.INPUT:
            if fz.variable not in b.concluded_terms and fz.variable not in b.concluded_bare:
                ctx.err(
                    f"FUZZIFY {fz.variable}: {var.kind.value} variable never receives a value "
                    "(only inputs, or variables concluded by rules, can be used in conditions)",
                    fz.span,
                    "fuzzify-no-value",
                )
            continue
        terms = [lower_term(ctx, t, fz.variable, {}, False) for t in first_terms(ctx, fz.variable, fz.terms)]
        for t in terms:
            if t is not None and t.kind in shapes.TS_KINDS - {"function"}:
                ctx.err(
                    f"term {fz.variable}.{t.name}: {t.kind} is an output-only term", fz.span, "ts-on-input"
                )
        b.fuzzy_index[fz.variable] = len(b.fuzzy_inputs)
        b.fuzzy_inputs.append(
            FuzzyInputPlan(fz.variable, ctx.slots[fz.variable], tuple(t for t in terms if t is not None))
        )
        if fz.clamp:
            bounds = _clamp_bounds(ctx, fz.range or var.range, f"FUZZIFY {fz.variable}", fz.span)
            slot = ctx.slots[fz.variable]
            b.inputs[slot] = dataclasses.replace(b.inputs[slot], clamp=bounds)


def _chained(b: _Block) -> None:
    """Chained variables: concluded by rules and read in conditions."""
    fb = b.ctx.fb
    referenced: list[str] = []
    for _rb, rule in fb.rules():
        if rule.condition is not None:
            _collect_vars(rule.condition, referenced)
    chained_names = [n for n in dict.fromkeys(referenced) if _has_value(b, n)]
    b.chained_index.update({n: i for i, n in enumerate(chained_names)})
    for n in chained_names:
        src = b.term_source(n)
        b.chained_term_names[n] = [t.name for t in src] if src is not None else []
    for n in chained_names:
        b.chained.append(
            ChainedPlan(n, tuple(b.chained_term_names[n]), b.accu_for(n, fb.defuzzify_block(n)) or "MAX")
        )


def _has_value(b: _Block, name: str) -> bool:
    """Whether a variable read in a condition has a value there: rules conclude on it or, in
    the jfuzzylogic profile (conditions read outputs' crisp values), it is an output, whose
    value is its DEFAULT until it has one."""
    if name in b.concluded_terms or name in b.concluded_bare:
        return True
    var = b.ctx.fb.variable(name)
    return (
        b.ctx.options.emulate == "jfuzzylogic"
        and var is not None
        and var.kind is m.VarKind.OUTPUT
        and b.ctx.fb.defuzzify_block(name) is not None
    )


def _rules(b: _Block) -> None:
    """Every rule's condition, weight and conclusions; rule activation methods per block."""
    ctx = b.ctx
    jfl = ctx.options.emulate == "jfuzzylogic"
    for bi, rb in enumerate(ctx.fb.rule_blocks):
        and_op, or_op, act, _accu = b.block_ops[bi]
        first_rule = len(b.rules)
        for rule in rb.rules:
            deps: set[str] = set()
            condition = rule.condition
            if jfl and condition is not None:
                condition = lower_jfl.left_to_right(condition)
            scope = _RuleScope(b, and_op, or_op, deps, f"rule {rule.label}")
            cond = _cond(scope, condition) if condition is not None else CTrue()
            if jfl:
                deps.clear()  # jFuzzyLogic reads an output's crisp value: no rule waits for another
            concls: list[ConclusionPlan] = []
            conclusions = rule.conclusions
            if ctx.options.weight_whole_rule:
                w_rule = next((c.weight for c in conclusions if c.weight is not None), None)
                if w_rule is not None:
                    conclusions = tuple(dataclasses.replace(c, weight=w_rule) for c in conclusions)
            for c in conclusions:
                cp = _conclusion(b, c, rule.label)
                if cp is not None:
                    concls.append(cp)
            weight = _rule_weight(ctx, rule, b.inputs)
            if cond is None or weight is None:
                continue
            b.rules.append(
                RulePlan(rule.label, rb.name, cond, act, tuple(concls), weight, accu=_accu if jfl else None)
            )
            b.rule_deps.append(deps)
            b.rule_concludes.append({c.variable for c in rule.conclusions})
        if rb.rule_activation is not None:
            sel = _selection(ctx, rb, tuple(range(first_rule, len(b.rules))), b.rule_deps)
            if sel is not None:
                for ri in sel.rules:
                    b.rules[ri] = dataclasses.replace(b.rules[ri], selection=len(b.selections))
                b.selections.append(sel)


def _outputs(b: _Block) -> tuple[list[OutputPlan], list[int] | None]:
    """The outputs (lock-range on the output) and their order (function terms read earlier
    outputs)."""
    ctx = b.ctx
    fb = ctx.fb
    outputs: list[OutputPlan] = []
    output_deps: list[set[int]] = []
    for oi, var in enumerate(fb.outputs):
        op = lower_output(ctx, var, oi, b)
        if op is None:
            continue
        db = fb.defuzzify_block(var.name)
        if db is not None and db.clamp:
            op = dataclasses.replace(
                op, clamp=_clamp_bounds(ctx, db.range or var.range, f"DEFUZZIFY {var.name}", db.span)
            )
        outputs.append(op)
        deps_o: set[int] = set()
        for t in op.terms:
            if t.expr is not None:
                _expr_outputs(t.expr, deps_o)
        output_deps.append(deps_o)
    if any(d.is_error for d in ctx.diags):
        return outputs, None
    output_order = _topo(
        ctx,
        [(i, sorted(d)) for i, d in enumerate(output_deps)],
        lambda cyc: (
            "function terms of outputs depend on each other in a cycle: "
            + " -> ".join(outputs[i].name for i in cyc)
        ),
    )
    return outputs, output_order


def _clamp_bounds(
    ctx: LowerContext, rng: m.Range | None, where: str, span: m.Span | None
) -> tuple[float, float] | None:
    """The interval a lock-range limits a value to."""
    if rng is None:
        ctx.err(f"{where}: limiting the value to its range (lock-range) needs a RANGE", span, "clamp-range")
        return None
    low, high = float(rng.low), float(rng.high)
    if math.isnan(low) or math.isnan(high) or low > high:
        ctx.err(f"{where}: RANGE({low:g}..{high:g}) cannot limit a value", rng.span or span, "clamp-range")
        return None
    return low, high


def _rule_weight(ctx: LowerContext, rule: m.Rule, inputs: list[InputPlan]) -> PParam | None:
    """The rule weight (MATLAB / fuzzylite): it scales the condition degree."""
    if rule.weight is None:
        return 1.0
    w = lower_param(ctx, rule.weight, f"rule {rule.label} weight")
    if w is None:
        return None
    if isinstance(w, Slot):
        inputs[w.index] = dataclasses.replace(inputs[w.index], degree=True)
    elif w < 0.0:
        ctx.err(f"rule {rule.label}: negative rule weight {w:g}", rule.span, "weight-negative")
        return None
    return w


def _selection(
    ctx: LowerContext, rb: m.RuleBlock, members: tuple[int, ...], rule_deps: list[set[str]]
) -> SelectionPlan | None:
    """fuzzylite's rule activation method of a block (None: every rule fires)."""
    assert rb.rule_activation is not None
    where = f"rule block {rb.name or ''}".rstrip()
    try:
        sel = selection.parse(rb.rule_activation, members)
    except ValueError as exc:
        ctx.err(f"{where}: {exc}", rb.item_span("rule_activation"), "rule-activation")
        return None
    if sel is None:
        return None
    if any(rule_deps[ri] for ri in members):
        # the selection compares every degree of the block at once, so its conditions must
        # not wait for other rules (fuzzylite evaluates blocks in sequence instead)
        ctx.err(
            f"{where}: rule activation {rb.rule_activation!r} with conditions on variables concluded "
            "by rules (chained inference) is not supported",
            rb.span,
            "rule-activation-chained",
        )
        return None
    return sel


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


def _hedges(
    ctx: LowerContext, hedges: tuple[str, ...], span: m.Span | None, where: str
) -> tuple[str, ...] | None:
    if not hedges:
        return ()
    hs = tuple(h.lower() for h in hedges)
    for h in hs:
        if h not in HEDGE_NAMES and shapes.power_of(h) is None:
            ctx.err(
                f"{where}: unknown hedge {h!r} (known: {', '.join(sorted(HEDGE_NAMES))})",
                span,
                "hedge-unknown",
            )
            return None
    return hs


@dataclasses.dataclass(frozen=True)
class _RuleScope:
    """What lowering one rule's condition needs: the block so far, the rule block's AND/OR,
    the chained variables the rule waits for (filled in) and where to point errors."""

    b: _Block
    and_op: str
    or_op: str
    deps: set[str]
    where: str


def _cond(scope: _RuleScope, c: m.Condition) -> CondPlan | None:
    b, ctx, where = scope.b, scope.b.ctx, scope.where
    fuzzy_index, chained_index, inputs = b.fuzzy_index, b.chained_index, b.inputs
    if type(c) is m.Is and not c.hedges and c.variable in fuzzy_index and c.variable not in chained_index:
        found = ctx.fuzzy_terms(c.variable).get(c.term)
        if found is not None:  # the common test, `input IS term`, without the general path
            return CTerm(fuzzy_index[c.variable], found, (), c.negated)

    if isinstance(c, m.Is):
        hs = _hedges(ctx, c.hedges, c.span, where)
        if hs is None:
            return None
        chained = c.variable in chained_index
        if chained or c.variable in fuzzy_index:
            # a chained variable's accumulated degree, or a fuzzified input's term
            leaf = CChained if chained else CTerm
            slot = chained_index[c.variable] if chained else fuzzy_index[c.variable]
            names = b.chained_term_names[c.variable] if chained else ctx.fuzzy_terms(c.variable)
            if chained:
                scope.deps.add(c.variable)
            if c.term.lower() == "any" and c.term not in names:  # fuzzylite "x is any"
                hs = (*hs, "any")
            if "any" in hs:
                return leaf(slot, 0, hs, c.negated)
            if c.term not in names:
                ctx.err(f"{where}: {c.variable} has no term {c.term!r}", c.span, "undeclared-term")
                return None
            term = names[c.term] if isinstance(names, dict) else names.index(c.term)
            return leaf(slot, term, hs, c.negated)
        var = ctx.fb.variable(c.variable)
        if var is None:
            ctx.err(f"{where}: undeclared variable {c.variable!r}", c.span, "undeclared-variable")
        elif var.kind is m.VarKind.INPUT:
            ctx.err(f"{where}: input {c.variable!r} has no FUZZIFY block", c.span, "no-fuzzify")
        else:
            ctx.err(
                f"{where}: {c.variable!r} is used in a condition but no rule concludes on it",
                c.span,
                "never-concluded",
            )
        return None
    if isinstance(c, m.Degree):
        if c.variable in ctx.slots:
            i = ctx.slots[c.variable]
            inputs[i] = InputPlan(inputs[i].name, inputs[i].default, True)
            return CDegree(slot=i)
        if c.variable in chained_index and c.variable in b.concluded_bare:
            scope.deps.add(c.variable)
            return CDegree(chained=chained_index[c.variable])
        ctx.err(
            f"{where}: bare variable {c.variable!r} in a condition must be an input (a degree) "
            "or a variable concluded without a term",
            c.span,
            "degree-variable",
        )
        return None
    if isinstance(c, m.Not):
        inner = _cond(scope, c.operand)
        return CNot(inner) if inner is not None else None
    parts = [_cond(scope, o) for o in c.operands]
    if any(p is None for p in parts):
        return None
    kids = tuple(p for p in parts if p is not None)
    return CAnd(scope.and_op, kids) if isinstance(c, m.And) else COr(scope.or_op, kids)


def _conclusion(b: _Block, c: m.Conclusion, label: str) -> ConclusionPlan | None:
    ctx, inputs, where = b.ctx, b.inputs, f"rule {label}"
    var = ctx.fb.variable(c.variable)
    if var is None or var.kind is m.VarKind.INPUT:
        return None  # reported while scanning conclusions
    weight: PParam = 1.0
    if c.weight is not None:
        w = lower_param(ctx, c.weight, f"{where} WITH")
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
        src = b.term_source(c.variable)
        if src is None:
            ctx.err(f"{where}: {c.variable} has no terms (no DEFUZZIFY block)", c.span, "no-defuzzify")
            return None
        names = [t.name for t in src]
        if c.term not in names:
            ctx.err(f"{where}: {c.variable} has no term {c.term!r}", c.span, "undeclared-term")
            return None
        term_idx = names.index(c.term)
    outs = (b.output_names[c.variable],) if c.variable in b.output_names else ()
    chs = (b.chained_index[c.variable],) if c.variable in b.chained_index else ()
    return ConclusionPlan(outs, chs, term_idx, weight, hs)


def _topo(ctx: LowerContext, nodes: list[tuple[int, list[int]]], cycle_msg: object) -> list[int] | None:
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


def _rule_order(
    ctx: LowerContext, deps: list[set[str]], concludes: list[set[str]], rules: list[RulePlan]
) -> list[int] | None:
    producers: dict[str, list[int]] = {}
    for i, cs in enumerate(concludes):
        for v in cs:
            producers.setdefault(v, []).append(i)
    nodes = [(i, [p for v in d for p in producers.get(v, [])]) for i, d in enumerate(deps)]

    def msg(stuck: list[int]) -> str:
        names = sorted({v for i in stuck for v in deps[i]})
        return (
            "chained inference forms a cycle through "
            + ", ".join(names)
            + " (rules "
            + ", ".join(rules[i].label for i in stuck)
            + ")"
        )

    return _topo(ctx, nodes, msg)
