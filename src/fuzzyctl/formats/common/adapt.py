"""What FIS and FLL share when a model is written: one function block, rule weights in the
fuzzylite/MATLAB sense, renamed identifiers, and the list of what cannot be said.

A model written to FIS or FLL first goes through :func:`prepare`, which returns an
equivalent :class:`FunctionBlock` (same evaluation results) using only what both formats
share, plus the :class:`Loss` list for what it had to drop.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import replace

from fuzzyctl.diagnostics import Diagnostic, DiagnosticError, error
from fuzzyctl.engine.semantics import operators as ops
from fuzzyctl.formats import Loss
from fuzzyctl.formats.common.basics import identifier, is_identifier
from fuzzyctl.kinds import methods, norms
from fuzzyctl.kinds import shapes as registry
from fuzzyctl.model import (
    DEFUZZ_METHODS,
    And,
    Binary,
    Call,
    Conclusion,
    Condition,
    Default,
    DefuzzifyBlock,
    Degree,
    Document,
    Expr,
    FunctionBlock,
    FunctionMF,
    FuzzifyBlock,
    Is,
    MembershipFunction,
    Name,
    Not,
    Or,
    Param,
    Point,
    PointsMF,
    Range,
    Ref,
    Rule,
    RuleBlock,
    ShapeMF,
    SingletonMF,
    SingletonsMF,
    Span,
    Term,
    Unary,
    VarKind,
    implied_operators,
)

# Defuzzification methods whose output terms act as points (a weighted average of term
# values): activation MIN and PROD give the same result there, so an IEC WITH weight
# equals a MATLAB/fuzzylite rule weight.
POINT_METHODS = methods.codes(lambda m: m.weighted is not None and m.lowers_to is None)
DEFAULT_WHEN_ABSENT = 0.0
"""What our engine outputs before any rule has fired when no DEFAULT value is written: an
output without DEFAULT, or with ``DEFAULT := NC``, keeps its previous value (docs/engine.md),
which FIS and FLL say as ``Default=0`` with ``LockPrevious=1`` / ``lock-previous: true``."""


def rule_label(block: RuleBlock, rule: Rule) -> str:
    return f"rule {rule.label!r}" + (f" of block {block.name!r}" if block.name else "")


def negation_free(condition: Condition | None) -> bool:
    """True when NOT appears only as ``x IS NOT t``."""
    if condition is None or isinstance(condition, Is):
        return True
    if isinstance(condition, Degree | Not):
        return False
    return all(negation_free(c) for c in condition.operands)


def simplify_not(condition: Condition | None) -> Condition | None:
    """``NOT (x IS t)`` -> ``x IS NOT t`` (equal by definition: 1 - mu)."""
    if isinstance(condition, Not) and isinstance(condition.operand, Is) and not condition.operand.negated:
        return replace(condition.operand, negated=True)
    if isinstance(condition, And):
        return And(tuple(simplify_not(c) or c for c in condition.operands), condition.span)
    if isinstance(condition, Or):
        return Or(tuple(simplify_not(c) or c for c in condition.operands), condition.span)
    return condition


def uncumulate(hedges: list[tuple[str, ...]]) -> list[tuple[str, ...]] | None:
    """Written hedges per conclusion such that fuzzylite's running degree gives the model's
    effective ``hedges``; None when no such list exists (the rule must then be split)."""
    written: list[tuple[str, ...]] = []
    previous: tuple[str, ...] = ()
    for effective in hedges:
        if len(effective) < len(previous) or effective[len(effective) - len(previous) :] != previous:
            return None
        written.append(effective[: len(effective) - len(previous)])
        previous = effective
    return written


def split_for_running_hedges(rule: Rule) -> list[Rule]:
    """``rule`` itself when fuzzylite's running conclusion hedges can say its conclusions'
    hedges (:func:`uncumulate`), else one rule per conclusion."""
    if uncumulate([c.hedges for c in rule.conclusions]) is not None:
        return [rule]
    return [
        replace(rule, label=f"{rule.label}_{j + 1}", conclusions=(c,)) for j, c in enumerate(rule.conclusions)
    ]


def split_rules(
    fb: FunctionBlock, block: RuleBlock, rule: Rule, losses: list[Loss], running_hedges: bool = True
) -> list[Rule]:
    """Rules equivalent to ``rule`` whose weight is a single rule weight (MATLAB/fuzzylite)
    and, with ``running_hedges`` (fuzzylite), whose conclusion hedges can be written; splits
    per conclusion when needed."""
    act = block.act or "MIN"
    groups: dict[float, list[Conclusion]] = {}
    for c in rule.conclusions:
        if isinstance(c.weight, Ref) or isinstance(rule.weight, Ref):
            losses.append(Loss(rule_label(block, rule), "a weight given by a variable cannot be written"))
            return []
        w_conclusion = 1.0 if c.weight is None else float(c.weight)
        w_rule = 1.0 if rule.weight is None else float(rule.weight)
        out = fb.defuzzify_block(c.variable)
        points = out is not None and (out.method or "") in POINT_METHODS
        if w_conclusion != 1.0 and w_rule != 1.0 and not (points or norms.is_prod(act)):
            losses.append(
                Loss(
                    rule_label(block, rule),
                    "both a rule weight and a WITH weight under ACT MIN cannot be written as one weight",
                )
            )
            return []
        if w_conclusion != 1.0 and not (points or norms.is_prod(act)):
            losses.append(
                Loss(
                    rule_label(block, rule),
                    f"WITH {w_conclusion:g} scales the activated term under ACT {act}; the target's rule "
                    "weight scales the degree before activation",
                )
            )
            return []
        groups.setdefault(w_rule * w_conclusion, []).append(replace(c, weight=None))
    out_rules: list[Rule] = []
    for i, (weight, conclusions) in enumerate(groups.items()):
        label = rule.label if len(groups) == 1 else f"{rule.label}_{i + 1}"
        one = replace(
            rule, label=label, conclusions=tuple(conclusions), weight=None if weight == 1.0 else weight
        )
        out_rules.extend(split_for_running_hedges(one) if running_hedges else [one])
    return out_rules


def support(term: Term) -> tuple[float, float] | None:
    """Where a term is non-zero, for terms whose support is bounded."""
    mf = term.mf
    if isinstance(mf, PointsMF):
        if any(isinstance(p.x, Ref) or isinstance(p.y, Ref) for p in mf.points):
            return None
        xs = [float(p.x) for p in mf.points]  # type: ignore[arg-type]
        ys = [float(p.y) for p in mf.points]  # type: ignore[arg-type]
        if ys[0] != 0.0 or ys[-1] != 0.0:
            return None
        return min(xs), max(xs)
    if isinstance(mf, SingletonMF) and not isinstance(mf.value, Ref):
        return float(mf.value), float(mf.value)
    if isinstance(mf, ShapeMF) and not any(isinstance(p, Ref) for p in mf.params):
        p = [float(v) for v in mf.params]  # type: ignore[arg-type]
        shape = registry.SHAPES.get(mf.kind)
        if shape is not None and not isinstance(shape.zero_outside, registry.NA):
            return shape.zero_outside(p)
    return None


def _lowered(method: str | None) -> str | None:
    """The method a writer says for ``method`` (the registry's ``lowers_to``: COGF's weighted
    average), ``method`` itself for the others."""
    m = methods.METHODS.get(method or "")
    return m.lowers_to if m is not None and m.lowers_to is not None else method


def _method(name: str) -> str:
    if name not in DEFUZZ_METHODS:
        raise KeyError(name)
    return name


def unknown_operators(fb: FunctionBlock) -> list[Diagnostic]:
    """Operators and methods the engine does not know (JSON and the studio carry them as free
    strings): the FIS and FLL writers look them up in their tables, so they are refused here,
    with their place, as the engine refuses them."""
    found: list[Diagnostic] = []

    def check(what: str, value: str | None, resolve: Callable[[str], object], span: Span | None) -> None:
        if value is None:
            return
        try:
            resolve(value)
        except KeyError:
            found.append(error(f"unknown {what} {value[:60]!r}", span, code="operator-unknown"))

    for rb in fb.rule_blocks:
        check("AND operator", rb.and_op, lambda v: ops.resolve_pair(v, None), rb.span)
        check("OR operator", rb.or_op, lambda v: ops.resolve_pair(None, v), rb.span)
        check("activation", rb.act, ops.resolve_act, rb.span)
        check("accumulation", rb.accu, ops.resolve_accu, rb.span)
    for d in fb.defuzzify:
        check("accumulation", d.accu, ops.resolve_accu, d.span)
        check("defuzzification method", d.method, _method, d.span)
    return found


def prepare(
    document: Document, target: str, running_hedges: bool = True, reserved: frozenset[str] = frozenset()
) -> tuple[FunctionBlock, list[Loss], dict[str, str]]:
    """The main function block rewritten for FIS/FLL, the losses, and the renaming applied
    (old name -> new name, variables and terms share one map per variable).  With
    ``running_hedges`` rules are split where fuzzylite's running conclusion hedges cannot
    say the model's (the FIS writer decides later, see :func:`split_for_running_hedges`).
    Names that are not identifiers, or are ``reserved`` words of the target, are renamed."""
    losses: list[Loss] = []
    fb = document.main
    problems = unknown_operators(fb)
    if problems:
        raise DiagnosticError(problems)
    # jFuzzyLogic's COGF is the weighted average of the terms' values (docs/engine.md)
    fb = replace(fb, defuzzify=tuple(replace(d, method=_lowered(d.method)) for d in fb.defuzzify))
    for other in document.blocks[1:]:
        losses.append(
            Loss(f"function block {other.name!r}", f"{target} holds one system per file; not written")
        )
    for opt in fb.options:
        losses.append(Loss(f"{opt.keyword} block", f"{target} has no vendor options; dropped"))
    for var in fb.locals:
        losses.append(Loss(f"local variable {var.name!r}", f"{target} has no intermediate variables"))
    for var in fb.inputs:
        if fb.fuzzify_block(var.name) is None:
            used = any(
                isinstance(c, Degree) and c.variable == var.name
                for _, r in fb.rules()
                for c in _atoms(r.condition)
            )
            if used:
                continue  # reported with the rule
    for out in fb.outputs:
        if fb.defuzzify_block(out.name) is None:
            losses.append(Loss(f"output {out.name!r}", "has no DEFUZZIFY block"))

    # Rules: resolve NOT, weights and hedges into what FIS and FLL say.
    new_blocks: list[RuleBlock] = []
    local_names = {v.name for v in fb.locals}
    for block in fb.rule_blocks:
        rules: list[Rule] = []
        for rule in block.rules:
            condition = simplify_not(rule.condition)
            label = rule_label(block, rule)
            if not negation_free(condition):
                losses.append(
                    Loss(label, "NOT of a compound condition, or a bare degree variable, cannot be written")
                )
                continue
            bad = [c for c in rule.conclusions if c.term is None or c.variable in local_names]
            if bad:
                losses.append(
                    Loss(label, "a conclusion that is a bare variable or a local variable cannot be written")
                )
                continue
            if any(a.variable in local_names for a in _atoms(condition) if isinstance(a, Is)):
                losses.append(Loss(label, "a condition on a local variable cannot be written"))
                continue
            rules.extend(split_rules(fb, block, replace(rule, condition=condition), losses, running_hedges))
        # Table 3: a block that declares one operator evaluates with its pair; FIS and FLL
        # have no such rule (an absent one is MIN/MAX or "none"), so the pair is written
        # when the rules use it (a block without OR keeps its OR undeclared: nothing to lose)
        and_op, or_op = block.and_op, block.or_op
        if (and_op is None) != (or_op is None):
            implied = implied_operators(and_op, or_op)
            connectives = _connectives([r.condition for r in rules])
            and_op = implied[0] if and_op is not None or And in connectives else None
            or_op = implied[1] if or_op is not None or Or in connectives else None
        new_blocks.append(replace(block, rules=tuple(rules), and_op=and_op, or_op=or_op))

    # Defaults: make the implicit explicit, so that a target with another convention keeps ours.
    defuzzify = []
    for d in fb.defuzzify:
        default = d.default if d.default is not None else Default(DEFAULT_WHEN_ABSENT, no_change=True)
        if default.value is None:  # DEFAULT := NC: 0 until a rule fires (the engine's NC start)
            default = Default(DEFAULT_WHEN_ABSENT, default.no_change)
        method = d.method
        if (
            d.terms
            and all(isinstance(t.mf, SingletonMF) for t in d.terms)
            and methods.singleton_centroid(method)
        ):
            method = "COGS"  # CoG of singletons is CoGS (docs/engine.md): say it as a weighted average
        defuzzify.append(replace(d, default=default, method=method))
    # An input singleton is the triangle (v, v, v): degree 1 exactly at v, 0 elsewhere, in our
    # engine, MATLAB's trimf and fuzzylite's Triangle alike.
    fuzzify = tuple(replace(f, terms=tuple(_singleton_as_triangle(t) for t in f.terms)) for f in fb.fuzzify)
    fb = replace(fb, rule_blocks=tuple(new_blocks), fuzzify=fuzzify, defuzzify=tuple(defuzzify))

    def valid(name: str) -> bool:
        return is_identifier(name) and name not in reserved

    fb, renames = rename(fb, valid, valid)
    return fb, losses, renames


def _connectives(conditions: list[Condition | None]) -> set[type]:
    """The connectives (:class:`And`, :class:`Or`) the conditions use."""
    found: set[type] = set()
    todo = [c for c in conditions if c is not None]
    while todo:
        c = todo.pop()
        if isinstance(c, And | Or):
            found.add(type(c))
            todo.extend(c.operands)
        elif isinstance(c, Not):
            todo.append(c.operand)
    return found


def _singleton_as_triangle(term: Term) -> Term:
    mf = term.mf
    if isinstance(mf, SingletonMF) and not isinstance(mf.value, Ref):
        v = float(mf.value)
        return replace(term, mf=ShapeMF("triangle", (v, v, v)))
    return term


def _atoms(condition: Condition | None) -> list[Condition]:
    if condition is None:
        return []
    if isinstance(condition, And | Or):
        return [a for c in condition.operands for a in _atoms(c)]
    if isinstance(condition, Not):
        return _atoms(condition.operand)
    return [condition]


def rename(
    fb: FunctionBlock,
    valid_variable: Callable[[str], bool] | None = None,
    valid_term: Callable[[str], bool] | None = None,
) -> tuple[FunctionBlock, dict[str, str]]:
    """Rename variables and terms the target cannot write to identifiers (``LDL-Level`` ->
    ``LDL_Level``).  By default a name must be an ASCII identifier; a format with other
    rules passes its own checks."""

    def fixer(valid: Callable[[str], bool] | None) -> Callable[[str, set[str]], str]:
        check = valid or is_identifier
        # the next number to try for each base within one set of names, so that n clashes
        # cost n tries in all, not n^2/2 (a block may repeat a term name thousands of times)
        next_number: dict[str, int] = {}

        def fix(name: str, taken: set[str]) -> str:
            if not taken:  # a new block's names
                next_number.clear()
            if check(name) and name not in taken:
                taken.add(name)
                return name
            # identifier() gives an ASCII identifier, which may still be one the target
            # reserves (FCL's ``if``): number it until the target accepts it
            base = identifier(name, set())
            n = next_number.get(base)
            candidate, n = (base, 2) if n is None else (f"{base}_{n}", n + 1)
            while candidate in taken or not check(candidate):
                candidate, n = f"{base}_{n}", n + 1
            next_number[base] = n
            taken.add(candidate)
            return candidate

        return fix

    fix_variable, fix_term = fixer(valid_variable), fixer(valid_term)
    taken_vars: set[str] = set()
    var_map = {v.name: fix_variable(v.name, taken_vars) for v in fb.variables}
    blocks: list[FuzzifyBlock | DefuzzifyBlock] = [*fb.fuzzify, *fb.defuzzify]
    term_maps: dict[str, dict[str, str]] = {}
    for blk in blocks:
        taken: set[str] = set()
        term_maps[blk.variable] = {t.name: fix_term(t.name, taken) for t in blk.terms}
    if all(k == v for k, v in var_map.items()) and all(
        k == v for names in term_maps.values() for k, v in names.items()
    ):
        return fb, {}

    def v(name: str) -> str:
        return var_map.get(name, name)

    def t(var: str, name: str | None) -> str | None:
        return None if name is None else term_maps.get(var, {}).get(name, name)

    def param(p: Param) -> Param:
        return Ref(v(p.name), p.span) if isinstance(p, Ref) else p

    def point(p: Point) -> Point:
        return replace(p, x=param(p.x), y=param(p.y))

    def expr(e: Expr, argument: str | None) -> Expr:
        if isinstance(e, Name):
            return e if e.name == argument else Name(v(e.name))
        if isinstance(e, Unary):
            return replace(e, operand=expr(e.operand, argument))
        if isinstance(e, Binary):
            return replace(e, left=expr(e.left, argument), right=expr(e.right, argument))
        if isinstance(e, Call):
            return replace(e, args=tuple(expr(a, argument) for a in e.args))
        return e

    def mf(f: MembershipFunction) -> MembershipFunction:
        """Parameters and expressions that name variables follow the variables."""
        if isinstance(f, ShapeMF):
            return replace(f, params=tuple(param(p) for p in f.params), height=param(f.height))
        if isinstance(f, PointsMF | SingletonsMF):
            return replace(f, points=tuple(point(p) for p in f.points))
        if isinstance(f, SingletonMF):
            return replace(f, value=param(f.value))
        return replace(f, expr=expr(f.expr, f.argument))

    def terms(b: FuzzifyBlock | DefuzzifyBlock) -> tuple[Term, ...]:
        return tuple(
            replace(term, name=t(b.variable, term.name) or term.name, mf=mf(term.mf)) for term in b.terms
        )

    def cond(c: Condition | None) -> Condition | None:
        if c is None:
            return None
        if isinstance(c, Is):
            return replace(c, variable=v(c.variable), term=t(c.variable, c.term) or c.term)
        if isinstance(c, Degree):
            return replace(c, variable=v(c.variable))
        if isinstance(c, Not):
            return replace(c, operand=cond(c.operand) or c.operand)
        return replace(c, operands=tuple(cond(o) or o for o in c.operands))

    renamed = replace(
        fb,
        variables=tuple(replace(x, name=v(x.name)) for x in fb.variables),
        fuzzify=tuple(replace(b, variable=v(b.variable), terms=terms(b)) for b in fb.fuzzify),
        defuzzify=tuple(replace(b, variable=v(b.variable), terms=terms(b)) for b in fb.defuzzify),
        rule_blocks=tuple(
            replace(
                b,
                rules=tuple(
                    replace(
                        r,
                        condition=cond(r.condition),
                        conclusions=tuple(
                            replace(
                                c,
                                variable=v(c.variable),
                                term=t(c.variable, c.term),
                                weight=None if c.weight is None else param(c.weight),
                            )
                            for c in r.conclusions
                        ),
                    )
                    for r in b.rules
                ),
            )
            for b in fb.rule_blocks
        ),
    )
    return renamed, {k: x for k, x in var_map.items() if k != x}


def term_losses(owner: str, term: Term, supported: set[str], target: str, losses: list[Loss]) -> bool:
    """Report a term the target cannot express; True when it is fine."""
    mf = term.mf
    where = f"term {term.name!r} of {owner!r}"
    if isinstance(mf, ShapeMF):
        if any(isinstance(p, Ref) for p in mf.params) or isinstance(mf.height, Ref):
            losses.append(Loss(where, "parameters given by variables cannot be written"))
            return False
        if mf.kind not in supported:
            losses.append(Loss(where, f"{target} has no {mf.kind} membership function"))
            return False
        return True
    if isinstance(mf, PointsMF):
        if any(isinstance(p.x, Ref) or isinstance(p.y, Ref) for p in mf.points):
            losses.append(Loss(where, "points given by variables cannot be written"))
            return False
        return True
    if isinstance(mf, SingletonsMF):
        losses.append(Loss(where, f"{target} has no discrete singleton sets (jFuzzyLogic SINGLETONS)"))
        return False
    if isinstance(mf, FunctionMF):
        return True
    if isinstance(mf.value, Ref):
        losses.append(Loss(where, "a singleton given by a variable cannot be written"))
        return False
    return True


def is_point_output(block: DefuzzifyBlock) -> bool:
    """A Takagi-Sugeno style output: weighted average or sum of term values."""
    return (block.method or "") in POINT_METHODS


SUM_LIKE = frozenset({"SUM", "NSUM"})
"""Accumulations that add every rule's degree (NSUM's normalisation never changes a weighted
average): for a weighted-average output they equal "every rule counts"."""


def point_accumulation(fb: FunctionBlock, block: DefuzzifyBlock) -> str | None:
    """How the engine combines the degrees of a weighted-average output's terms: its own
    ACCU, else that of the rule blocks concluding it, else none (every rule counts on its
    own) - except an output of singletons defuzzified by CoGS, which accumulates with MAX
    (IEC 61131-7), see docs/engine.md."""
    if block.accu is not None:
        return block.accu
    for rb in fb.rule_blocks:
        if rb.accu is not None and any(c.variable == block.variable for r in rb.rules for c in r.conclusions):
            return rb.accu
    singletons = bool(block.terms) and all(isinstance(t.mf, SingletonMF) for t in block.terms)
    return "MAX" if singletons and methods.singleton_centroid(block.method) else None


def term_concluded_twice(fb: FunctionBlock, variable: str) -> bool:
    """Whether some term of ``variable`` receives more than one rule's degree."""
    seen: set[str] = set()
    for rb in fb.rule_blocks:
        if not rb.enabled:
            continue
        for rule in rb.rules:
            for c in rule.conclusions:
                if c.variable == variable and c.term is not None:
                    if c.term in seen:
                        return True
                    seen.add(c.term)
    return False


def with_range(
    fb: FunctionBlock, blk: FuzzifyBlock | DefuzzifyBlock, losses: list[Loss], target: str
) -> FuzzifyBlock | DefuzzifyBlock:
    """FIS and FLL variables have a range: the block's RANGE, else the variable's, else the
    span of bounded terms (the engine's universe of an output without RANGE)."""
    if blk.range is not None:
        return blk
    var = fb.variable(blk.variable)
    if var is not None and var.range is not None:
        return replace(blk, range=var.range)
    spans = [support(t) for t in blk.terms]
    if blk.terms and all(s is not None for s in spans):
        low = min(s[0] for s in spans if s)
        high = max(s[1] for s in spans if s)
        return replace(blk, range=Range(low, high))
    if isinstance(blk, DefuzzifyBlock) and not is_point_output(blk):
        losses.append(
            Loss(f"output {blk.variable!r}", f"has no RANGE and unbounded terms; {target} needs a range")
        )
    if isinstance(blk, DefuzzifyBlock):
        return replace(blk, range=Range(-math.inf, math.inf))
    # An input's range changes nothing (inputs are not clamped): the span of the terms'
    # breakpoints is what an editor shows.
    xs = [x for t in blk.terms for x in _breakpoints(t) if math.isfinite(x)]
    low, high = (min(xs), max(xs)) if xs else (0.0, 1.0)
    return replace(blk, range=Range(low, high if high > low else low + 1.0))


def _breakpoints(term: Term) -> list[float]:
    mf = term.mf
    if isinstance(mf, PointsMF):
        return [float(p.x) for p in mf.points if not isinstance(p.x, Ref)]
    if isinstance(mf, ShapeMF) and not registry.flag(mf.kind, "takagi_sugeno"):
        return [float(p) for p in mf.params if not isinstance(p, Ref)]
    if isinstance(mf, SingletonMF) and not isinstance(mf.value, Ref):
        return [float(mf.value)]
    return []


def finite(x: float) -> bool:
    return not (math.isnan(x) or math.isinf(x))


__all__ = [
    "DEFAULT_WHEN_ABSENT",
    "POINT_METHODS",
    "FuzzifyBlock",
    "VarKind",
    "finite",
    "is_point_output",
    "point_accumulation",
    "prepare",
    "rule_label",
    "split_for_running_hedges",
    "split_rules",
    "support",
    "term_concluded_twice",
    "term_losses",
    "uncumulate",
    "with_range",
]
