"""Writing MATLAB FIS from the model.

The output is a MATLAB FIS (Version 2.0) that MATLAB, Octave and fuzzylite read.  When the
model needs what only fuzzylite's FIS dialect says (an explicit ``Default``, ``LockPrevious``,
an output ``LockRange``, fuzzylite hedges or membership types, heights), the file starts
with a comment naming that dialect, which our reader and fuzzylite honour.
"""

from __future__ import annotations

import itertools
import math
from collections.abc import Sequence
from dataclasses import dataclass, replace

from fuzzyctl.escape import one_line
from fuzzyctl.formats import Loss
from fuzzyctl.formats.common.adapt import (
    SUM_LIKE,
    is_point_output,
    point_accumulation,
    prepare,
    rule_label,
    split_for_running_hedges,
    term_concluded_twice,
    term_losses,
    uncumulate,
    with_range,
)
from fuzzyctl.formats.common.basics import fmt_number, hedge_power
from fuzzyctl.formats.common.expr import format_expr
from fuzzyctl.formats.common.terms import (
    FIS_OF_KIND,
    FIS_TYPES,
    MATLAB_TYPES,
    MONOTONIC_KINDS,
    TS_KINDS,
    fis_shape_problem,
    fis_ts_name,
)
from fuzzyctl.formats.fis.names import (
    AGG_METHODS,
    AND_METHODS,
    FUZZYLITE_HEDGE_CODES,
    OR_METHODS,
)
from fuzzyctl.kinds import methods as method_kinds
from fuzzyctl.kinds import norms
from fuzzyctl.model import (
    OPERATOR_PAIRS,
    And,
    Conclusion,
    Condition,
    DefuzzifyBlock,
    Document,
    FunctionBlock,
    FunctionMF,
    FuzzifyBlock,
    Is,
    Or,
    Point,
    PointsMF,
    Range,
    Ref,
    Rule,
    RuleBlock,
    ShapeMF,
    SingletonMF,
    Term,
)

_AND = {v: k for k, v in AND_METHODS.items()}
_OR = {v: k for k, v in OR_METHODS.items()}
_AGG = {v: k for k, v in AGG_METHODS.items()}
_AGG["ASUM"] = "probor"
_DEFUZZ = method_kinds.written("fis")
_DEFUZZ["COGS"] = "wtaver"
DIALECT_COMMENT = (
    "% FIS written by fuzzyctl in the fuzzylite dialect "
    "(Default/LockPrevious/LockRange keys, fuzzylite hedges and membership types)"
)
_FUZZYLITE_HEDGE_CODE = {hedges: code for code, hedges in FUZZYLITE_HEDGE_CODES.items()}


@dataclass
class _Plan:
    fb: FunctionBlock
    fuzzylite: bool


def _term_problem(term: Term, point_output: bool) -> str | None:
    """Why the FIS reader would refuse this (otherwise writable) term; ``None``: it reads it."""
    mf = term.mf
    if point_output:
        ts_term = (isinstance(mf, ShapeMF) and mf.kind in TS_KINDS) or (
            isinstance(mf, FunctionMF) and mf.argument is None
        )
        if not ts_term and not (isinstance(mf, ShapeMF) and mf.kind in MONOTONIC_KINDS):
            return (
                "a weighted-average output of a FIS has constant, linear or (fuzzylite's Tsukamoto) "
                "monotonic terms"
            )
    elif isinstance(mf, ShapeMF) and mf.kind in TS_KINDS:
        return "a Mamdani output of a FIS has no constant or linear terms"
    if isinstance(mf, ShapeMF) and mf.kind in FIS_OF_KIND and not _has_refs(mf):
        return fis_shape_problem(FIS_OF_KIND[mf.kind], tuple(float(p) for p in mf.params))  # type: ignore[arg-type]
    if isinstance(mf, PointsMF) and not _has_refs(mf):
        as_matlab = _points_as_matlab(mf)
        xs = [float(p.x) for p in mf.points]  # type: ignore[arg-type]
        if as_matlab is not None:
            return fis_shape_problem(as_matlab[0], tuple(as_matlab[1]))
        if any(b < a for a, b in itertools.pairwise(xs)):
            return "points in descending x cannot be written as discretemf"
    return None


def _input_term_readable(variable: str, term: Term, losses: list[Loss]) -> bool:
    problem = _term_problem(term, point_output=False)
    if problem is not None:
        losses.append(Loss(f"term {term.name!r} of {variable!r}", problem))
    return problem is None


def _needs_fuzzylite(fb: FunctionBlock) -> bool:
    for d in fb.defuzzify:
        if is_point_output(d) and any(
            isinstance(t.mf, ShapeMF) and t.mf.kind in MONOTONIC_KINDS for t in d.terms
        ):
            return True  # Tsukamoto: MATLAB's Sugeno outputs have constant or linear terms only
        default = d.default
        if d.clamp or (default is not None and default.no_change):
            return True
        mid = (d.range.low + d.range.high) / 2 if d.range else None
        if (
            default is not None
            and default.value is not None
            and (mid is None or not _same(default.value, mid))
        ):
            return True
    all_blocks: list[FuzzifyBlock | DefuzzifyBlock] = [*fb.fuzzify, *fb.defuzzify]
    for blk in all_blocks:
        for t in blk.terms:
            mf = t.mf
            if isinstance(mf, FunctionMF):
                return True
            if _has_refs(mf):
                continue  # a loss, reported with the term
            if (
                isinstance(mf, ShapeMF)
                and mf.kind not in TS_KINDS
                and mf.kind in FIS_OF_KIND
                and (FIS_OF_KIND[mf.kind] not in MATLAB_TYPES or float(mf.height) != 1.0)  # type: ignore[arg-type]
            ):
                return True
            if isinstance(mf, PointsMF) and _points_as_matlab(mf) is None:
                return True
    for _, rule in fb.rules():
        hedges = [a.hedges for a in _ises(rule.condition)] + [c.hedges for c in rule.conclusions]
        if any(h in {("extremely",), ("seldom",)} for h in hedges):
            return True
        if any(c.hedges and _octave_consequent_code(fb, c) is None for c in rule.conclusions):
            return True
    return False


def _octave_consequent_code(fb: FunctionBlock, conclusion: Conclusion) -> int | None:
    """Octave's code for the hedges of a Sugeno consequent: code ``.p`` raises the rule's degree
    to 1/(p/10) (the reader's inverse), so a degree^q is written with p = 10/q."""
    block = fb.defuzzify_block(conclusion.variable)
    if block is None or not is_point_output(block):
        return None
    power = 1.0
    for h in conclusion.hedges:
        p = hedge_power(h)
        if p is None or p <= 0.0:
            return None
        power *= p
    code = 10.0 / power
    if abs(code - round(code)) > 1e-9 or not 1 <= round(code) <= 98:
        return None
    return round(code)


def _has_refs(mf: object) -> bool:
    if isinstance(mf, ShapeMF):
        return isinstance(mf.height, Ref) or any(isinstance(p, Ref) for p in mf.params)
    if isinstance(mf, PointsMF):
        return any(isinstance(p.x, Ref) or isinstance(p.y, Ref) for p in mf.points)
    return False


def _same(a: float, b: float) -> bool:
    return (math.isnan(a) and math.isnan(b)) or a == b


def _points_as_matlab(mf: PointsMF) -> tuple[str, list[float]] | None:
    """A point list that is exactly a trimf or trapmf (shoulders via +-Inf)."""
    pts = [(float(p.x), float(p.y)) for p in mf.points]  # type: ignore[arg-type]
    ys = [y for _, y in pts]
    xs = [x for x, _ in pts]
    if ys == [0.0, 1.0, 0.0]:
        return "trimf", xs
    if ys == [0.0, 1.0, 1.0, 0.0]:
        return "trapmf", xs
    if ys == [1.0, 0.0]:
        return "trapmf", [-math.inf, -math.inf, xs[0], xs[1]]
    if ys == [0.0, 1.0]:
        return "trapmf", [xs[0], xs[1], math.inf, math.inf]
    if ys == [1.0, 1.0, 0.0]:
        return "trapmf", [-math.inf, -math.inf, xs[1], xs[2]]
    if ys == [0.0, 1.0, 1.0]:
        return "trapmf", [xs[0], xs[1], math.inf, math.inf]
    return None


def _ises(condition: Condition | None) -> list[Is]:
    if condition is None:
        return []
    if isinstance(condition, Is):
        return [condition]
    if isinstance(condition, And | Or):
        return [a for c in condition.operands for a in _ises(c)]
    return []


def adapt(document: Document) -> tuple[Document, list[Loss]]:
    """The model as a FIS can state it, and what had to be dropped."""
    fb, losses, _ = prepare(document, "FIS", running_hedges=False)
    if _needs_fuzzylite(fb):  # fuzzylite reads conclusion hedges as running ones
        fb = replace(
            fb,
            rule_blocks=tuple(
                replace(b, rules=tuple(r2 for r in b.rules for r2 in split_for_running_hedges(r)))
                for b in fb.rule_blocks
            ),
        )
    supported = set(FIS_OF_KIND) | TS_KINDS
    # Inputs of a FIS cannot be clamped (fuzzylite's FIS importer rejects LockRange there).
    fuzzify: list[FuzzifyBlock] = []
    for f in fb.fuzzify:
        if f.clamp:
            losses.append(
                Loss(f"input {f.variable!r}", "FIS cannot clamp an input to its range (lock-range)")
            )
            f = replace(f, clamp=False)
        fuzzify.append(with_range(fb, f, losses, "FIS"))  # type: ignore[arg-type]
    fb = replace(fb, fuzzify=tuple(fuzzify))
    for d in fb.defuzzify:
        accu = point_accumulation(fb, d) if is_point_output(d) else None
        if accu is not None and accu not in SUM_LIKE and term_concluded_twice(fb, d.variable):
            losses.append(
                Loss(
                    f"output {d.variable!r}",
                    f"several rules conclude one term and accumulate with {accu}; a Sugeno FIS weighs "
                    "every rule on its own",
                )
            )
    defuzzify: list[DefuzzifyBlock] = []
    for d in fb.defuzzify:
        kept = []
        for t in d.terms:
            if isinstance(t.mf, SingletonMF):
                if is_point_output(d):
                    kept.append(replace(t, mf=ShapeMF("constant", (t.mf.value,))))
                    continue
                losses.append(
                    Loss(f"term {t.name!r} of {d.variable!r}", "FIS has no singleton in a centroid output")
                )
                continue
            if term_losses(d.variable, t, supported, "FIS", losses):
                problem = _term_problem(t, is_point_output(d))
                if problem is None:
                    kept.append(t)
                else:
                    losses.append(Loss(f"term {t.name!r} of {d.variable!r}", problem))
        defuzzify.append(with_range(fb, replace(d, terms=tuple(kept)), losses, "FIS"))  # type: ignore[arg-type]
    fb = replace(fb, defuzzify=tuple(defuzzify))
    for f in fb.fuzzify:
        for t in f.terms:
            if isinstance(t.mf, SingletonMF):  # a literal one became trimf [v v v] in prepare()
                losses.append(Loss(f"term {t.name!r} of {f.variable!r}", "FIS has no singleton input term"))
    fb = replace(
        fb,
        fuzzify=tuple(
            replace(
                f,
                terms=tuple(
                    t
                    for t in f.terms
                    if not isinstance(t.mf, SingletonMF)
                    and term_losses(f.variable, t, supported - TS_KINDS, "FIS", losses)
                    and _input_term_readable(f.variable, t, losses)
                ),
            )
            for f in fb.fuzzify
        ),
    )

    # Nested conditions in the form FIS can say (one AND or OR of literals per rule).
    fb = replace(
        fb,
        rule_blocks=tuple(
            replace(b, rules=tuple(r2 for r in b.rules for r2 in _one_level(fb, b, r)))
            for b in fb.rule_blocks
        ),
    )
    # One rule block with one set of operators.
    enabled = [b for b in fb.rule_blocks if b.enabled]
    for b in fb.rule_blocks:
        if b.rule_activation:
            losses.append(
                Loss(f"rule block {b.name!r}", f"FIS fires every rule ({b.rule_activation!r} dropped)")
            )
    # Only operators that matter must agree: AND/OR where rules use them, the implication
    # where a block concludes on a Mamdani output.
    merged: dict[str, str] = {}
    for b in enabled:
        used = {
            "AndMethod": (b.and_op or "MIN") if any(isinstance(r.condition, And) for r in b.rules) else None,
            "OrMethod": (b.or_op or "MAX") if any(isinstance(r.condition, Or) for r in b.rules) else None,
            "ImpMethod": (b.act or "MIN")
            if any(
                not is_point_output(fb.defuzzify_block(c.variable) or DefuzzifyBlock(c.variable, ()))
                for r in b.rules
                for c in r.conclusions
            )
            else None,
        }
        for key, value in used.items():
            if value is None:
                continue
            if merged.setdefault(key, value) != value:
                losses.append(
                    Loss(
                        f"rule block {b.name!r}",
                        f"FIS has one {key} for all rules: {merged[key]} is kept, {value} dropped",
                    )
                )
    base = next((b for b in enabled if b.rules), enabled[0] if enabled else RuleBlock(None, ()))
    first = replace(
        base,
        and_op=merged.get("AndMethod", base.and_op),
        or_op=merged.get("OrMethod", base.or_op),
        act=merged.get("ImpMethod", base.act),
    )
    rules: list[Rule] = []
    outputs = {d.variable for d in fb.defuzzify}
    fuzzylite = _needs_fuzzylite(fb)
    for b in enabled:
        for rule in b.rules:
            reason = _rule_problem(fb, rule, outputs, fuzzylite)
            if reason:
                losses.append(Loss(rule_label(b, rule), reason))
                continue
            rules.append(replace(rule, label=str(len(rules) + 1)))
    accu_values = {d.accu for d in fb.defuzzify if d.accu and not is_point_output(d)} | (
        {b.accu for b in enabled if b.accu} if any(not is_point_output(d) for d in fb.defuzzify) else set()
    )
    if len(accu_values) > 1:
        losses.append(
            Loss("aggregation", f"FIS has one AggMethod; the outputs use {', '.join(sorted(accu_values))}")
        )
    for d in fb.defuzzify:
        if norms.stand_in(d.accu):
            losses.append(Loss(f"output {d.variable!r}", f"FIS has no {d.accu}"))
    for name in sorted(n for n in accu_values if norms.stand_in(n)):
        if not any(d.accu == name for d in fb.defuzzify):
            losses.append(Loss("aggregation", f"FIS has no {name}"))
    # what is written anyway (--lossy) says the nearest FIS aggregation
    accu_values = {norms.stand_in(a) or a for a in accu_values}
    fb = replace(
        fb, defuzzify=tuple(replace(d, accu=s) if (s := norms.stand_in(d.accu)) else d for d in fb.defuzzify)
    )
    methods = {d.method or "COG" for d in fb.defuzzify if not is_point_output(d)}
    if len(methods) > 1:
        losses.append(
            Loss("defuzzification", f"FIS has one DefuzzMethod; the outputs use {', '.join(sorted(methods))}")
        )
    ts_methods = {method_kinds.ts_method(d.method) for d in fb.defuzzify if is_point_output(d)}
    if methods and ts_methods - {"WTAVER"}:
        losses.append(
            Loss("defuzzification", "a FIS mixing Mamdani and Sugeno outputs has weighted averages only")
        )
    block = replace(first, rules=tuple(rules), accu=(sorted(accu_values)[0] if accu_values else first.accu))
    fb = replace(fb, rule_blocks=(block,))
    return Document((fb,), document.path), losses


def _flat(condition: Condition) -> Condition:
    """Nested ANDs (ORs) joined into one: associative for every t-norm (s-norm)."""
    if isinstance(condition, And | Or):
        kind = type(condition)
        operands: list[Condition] = []
        for o in (_flat(x) for x in condition.operands):
            operands.extend(o.operands if isinstance(o, kind) else (o,))
        return kind(tuple(operands), condition.span)
    return condition


def _fis_form(condition: Condition | None) -> bool:
    if condition is None or isinstance(condition, Is):
        return True
    if isinstance(condition, And | Or) and all(isinstance(o, Is) for o in condition.operands):
        return len({o.variable for o in condition.operands if isinstance(o, Is)}) == len(condition.operands)
    return False


def _dnf(condition: Condition) -> list[tuple[Is, ...]] | None:
    """The condition as a disjunction of conjunctions of literals (None: a NOT of a compound)."""
    if isinstance(condition, Is):
        return [(condition,)]
    if isinstance(condition, Or):
        out: list[tuple[Is, ...]] = []
        for o in condition.operands:
            part = _dnf(o)
            if part is None:
                return None
            out += part
        return out
    if isinstance(condition, And):
        product: list[tuple[Is, ...]] = [()]
        for o in condition.operands:
            part = _dnf(o)
            if part is None:
                return None
            product = [a + b for a in product for b in part]
            if len(product) > MAX_SPLIT:
                return None
        return product
    return None


MAX_SPLIT = 64
"""At most this many rules replace one rule with a nested condition."""


def _one_level(fb: FunctionBlock, block: RuleBlock, rule: Rule) -> list[Rule]:
    """``rule`` with a condition FIS can say: nested same operators flattened; a mix of AND
    and OR split into one rule per disjunct of its disjunctive normal form, which is exact
    when AND is MIN, OR is MAX (a distributive lattice) and every conclusion goes to a
    Mamdani output accumulated with MAX (max over the rules = OR of their conditions, since
    activation, weights and hedges are monotonic).  Otherwise the rule is left as it is and
    reported as a loss."""
    if rule.condition is None or _fis_form(rule.condition):
        return [rule]
    flat = _flat(rule.condition)
    if _fis_form(flat):
        return [replace(rule, condition=flat)]
    and_op = block.and_op or ("MIN" if block.or_op is None or norms.is_max(block.or_op) else None)
    or_op = block.or_op or OPERATOR_PAIRS.get(and_op or "", None)
    if not (norms.is_min(and_op) and norms.is_max(or_op)):
        return [rule]
    for c in rule.conclusions:
        d = fb.defuzzify_block(c.variable)
        concluding = [
            b.accu
            for b in fb.rule_blocks
            if b.accu and any(x.variable == c.variable for r in b.rules for x in r.conclusions)
        ]
        accu = (d.accu if d else None) or (concluding[0] if concluding else "MAX")
        if d is None or is_point_output(d) or not norms.is_max(accu):
            return [rule]
    disjuncts = _dnf(flat)
    if disjuncts is None or len(disjuncts) > MAX_SPLIT:
        return [rule]
    out = []
    for k, conjunction in enumerate(disjuncts, start=1):
        literals = tuple(dict.fromkeys(conjunction))  # x IS a AND x IS a is x IS a
        if len({a.variable for a in literals}) != len(literals):
            return [rule]  # tests one input twice: no FIS form
        condition: Condition = literals[0] if len(literals) == 1 else And(literals, flat.span)
        out.append(replace(rule, label=f"{rule.label}_{k}", condition=condition))
    return out


def _rule_problem(fb: FunctionBlock, rule: Rule, outputs: set[str], fuzzylite: bool) -> str | None:
    c = rule.condition
    if isinstance(c, And | Or):
        if not all(isinstance(o, Is) for o in c.operands):
            return "FIS joins a rule's conditions with one AND or OR, without nesting"
        atoms = [o for o in c.operands if isinstance(o, Is)]
    elif c is None or isinstance(c, Is):
        atoms = [] if c is None else [c]
    else:
        return "this condition has no FIS form"
    names = [a.variable for a in atoms if isinstance(a, Is)]
    if len(set(names)) != len(names):
        return "FIS can test each input once per rule"
    if any(n in outputs for n in names):
        return "FIS cannot test an output variable in a condition (chained rules)"
    if any(n not in {f.variable for f in fb.fuzzify} for n in names):
        return "the condition tests a variable without terms"
    concl = [x.variable for x in rule.conclusions]
    if len(set(concl)) != len(concl):
        return "FIS can conclude once per output in a rule"
    for a in atoms:
        if isinstance(a, Is) and _hedge_code(a.hedges, fuzzylite) is None:
            return f"FIS has no code for the hedges {' '.join(a.hedges)}"
    if fuzzylite:
        written = uncumulate([x.hedges for x in rule.conclusions])
        if written is None or any(_hedge_code(h, fuzzylite) is None for h in written):
            return "FIS has no code for these conclusion hedges"
    elif any(x.hedges and _octave_consequent_code(fb, x) is None for x in rule.conclusions):
        return "FIS has no code for these conclusion hedges"
    for x in rule.conclusions:
        blk = fb.defuzzify_block(x.variable)
        if blk is None or blk.term(x.term or "") is None:
            return "refers to a term that could not be written"
    for a in atoms:
        fblk = fb.fuzzify_block(a.variable)
        if fblk is None or fblk.term(a.term) is None:
            return "refers to a term that could not be written"
    return None


def _hedge_code(hedges: tuple[str, ...], fuzzylite: bool) -> int | None:
    """Hundredths added to a term index for these hedges (0: none), in the given dialect."""
    if not hedges:
        return 0
    if hedges in _FUZZYLITE_HEDGE_CODE:
        code = _FUZZYLITE_HEDGE_CODE[hedges]
        return code if fuzzylite or hedges not in {("extremely",), ("seldom",)} else None
    if fuzzylite:
        return None
    if len(hedges) == 1:
        power = hedge_power(hedges[0])
        if power is not None and abs(power * 10 - round(power * 10)) < 1e-9 and 1 <= round(power * 10) <= 98:
            return round(power * 10)
    return None


def _mf_text(term: Term) -> str:
    mf = term.mf
    name = term.name.replace("'", "")
    if isinstance(mf, ShapeMF):
        if mf.kind in TS_KINDS:
            kind = fis_ts_name(mf.kind)
            values = [float(p) for p in mf.params]  # type: ignore[arg-type]
        else:
            kind = FIS_OF_KIND[mf.kind]
            values = FIS_TYPES[kind].from_model(tuple(float(p) for p in mf.params))  # type: ignore[arg-type]
            if float(mf.height) != 1.0:  # type: ignore[arg-type]
                values.append(float(mf.height))  # type: ignore[arg-type]
        return f"'{name}':'{kind}',[{' '.join(fmt_number(v) for v in values)}]"
    if isinstance(mf, PointsMF):
        as_matlab = _points_as_matlab(mf)
        if as_matlab is not None:
            kind, xs = as_matlab
            return f"'{name}':'{kind}',[{' '.join(fmt_number(v) for v in xs)}]"
        flat = [v for p in mf.points for v in (float(p.x), float(p.y))]  # type: ignore[arg-type]
        return f"'{name}':'discretemf',[{' '.join(fmt_number(v) for v in flat)}]"
    if isinstance(mf, FunctionMF):
        return f"'{name}':'function',[{format_expr(mf.expr)}]"
    raise TypeError(f"term {term.name!r} has no FIS form")


def write(document: Document) -> str:
    """FIS text of a document that :func:`adapt` returned."""
    fb = document.main
    fuzzylite = _needs_fuzzylite(fb)
    block = fb.rule_blocks[0] if fb.rule_blocks else RuleBlock(None, ())
    point = [is_point_output(d) for d in fb.defuzzify]
    fis_type = "sugeno" if point and all(point) else ("hybrid" if any(point) else "mamdani")
    mamdani_methods = [d.method or "COG" for d in fb.defuzzify if not is_point_output(d)]
    ts_methods = [d.method for d in fb.defuzzify if is_point_output(d)]
    # MATLAB's one defuzzMethod of a Sugeno system: the weighted sum when an output sums
    summing = any(getattr(method_kinds.METHODS.get(m or ""), "weighted", None) == "sum" for m in ts_methods)
    defuzz = _DEFUZZ[mamdani_methods[0]] if mamdani_methods else ("wtsum" if summing else "wtaver")
    accu = (
        next((d.accu for d in fb.defuzzify if d.accu and not is_point_output(d)), None) or block.accu or "MAX"
    )
    out: list[str] = []
    if fuzzylite:
        out.append(DIALECT_COMMENT)
    out += [
        "[System]",
        f"Name='{one_line(fb.name or '').replace(chr(39), '')}'",  # free text, on its line
        f"Type='{fis_type}'",
        "Version=2.0",
        f"NumInputs={len(fb.inputs)}",
        f"NumOutputs={len(fb.defuzzify)}",
        f"NumRules={len(block.rules)}",
        f"AndMethod='{_AND[block.and_op or 'MIN']}'",
        f"OrMethod='{_OR[block.or_op or 'MAX']}'",
        f"ImpMethod='{_AND[block.act or 'MIN']}'",
        f"AggMethod='{_AGG.get(accu, 'max')}'",
        f"DefuzzMethod='{defuzz}'",
    ]
    inputs = list(fb.inputs)
    for i, var in enumerate(inputs, start=1):
        blk = fb.fuzzify_block(var.name)
        terms = blk.terms if blk else ()
        rng = (blk.range if blk else None) or var.range or Range(0.0, 1.0)
        out += [
            "",
            f"[Input{i}]",
            f"Name='{var.name}'",
            f"Range=[{fmt_number(rng.low)} {fmt_number(rng.high)}]",
            f"NumMFs={len(terms)}",
        ]
        out += [f"MF{k}={_mf_text(t)}" for k, t in enumerate(terms, start=1)]
    for i, d in enumerate(fb.defuzzify, start=1):
        rng = d.range or Range(0.0, 1.0)
        out += [
            "",
            f"[Output{i}]",
            f"Name='{d.variable}'",
            f"Range=[{fmt_number(rng.low)} {fmt_number(rng.high)}]",
        ]
        if fuzzylite:
            value = d.default.value if d.default and d.default.value is not None else 0.0
            out += [
                f"Default={fmt_number(value)}",
                f"LockPrevious={int(bool(d.default and d.default.no_change))}",
                f"LockRange={int(d.clamp)}",
            ]
        out.append(f"NumMFs={len(d.terms)}")
        out += [f"MF{k}={_mf_text(t)}" for k, t in enumerate(d.terms, start=1)]
    out += ["", "[Rules]"]
    for rule in block.rules:
        out.append(_rule_text(fb, rule, inputs, fuzzylite))
    return "\n".join(out) + "\n"


def _entry(index: int, negated: bool, hedges: tuple[str, ...], fuzzylite: bool) -> str:
    code = _hedge_code(hedges, fuzzylite) or 0
    value = index + code / 100.0
    text = f"{index}" if code == 0 else f"{value:.2f}"
    return f"-{text}" if negated else text


def _rule_text(fb: FunctionBlock, rule: Rule, inputs: Sequence[object], fuzzylite: bool) -> str:
    from fuzzyctl.model import Variable

    atoms = _ises(rule.condition)
    by_var = {a.variable: a for a in atoms}
    if rule.condition is None and fuzzylite and inputs:
        # fuzzylite reads "0.99" as "x is any" (a rule of don't-cares would not load there);
        # MATLAB truncates it to 0, a don't-care: both give degree 1.
        return (
            f"{' '.join(['0.99'] + ['0'] * (len(inputs) - 1))}, "
            + _rule_text(fb, replace(rule, condition=Is("", "")), inputs, fuzzylite).split(", ", 1)[1]
        )
    ante = []
    for var in inputs:
        assert isinstance(var, Variable)
        a = by_var.get(var.name)
        blk = fb.fuzzify_block(var.name)
        if a is None or blk is None:
            ante.append("0")
            continue
        index = [t.name for t in blk.terms].index(a.term) + 1
        ante.append(_entry(index, a.negated, a.hedges, fuzzylite))
    written = uncumulate([c.hedges for c in rule.conclusions]) or [c.hedges for c in rule.conclusions]
    hedges_of = {c.variable: h for c, h in zip(rule.conclusions, written, strict=True)}
    octave = {
        c.variable: _octave_consequent_code(fb, c) or 0
        for c in rule.conclusions
        if c.hedges and not fuzzylite
    }
    cons = []
    for d in fb.defuzzify:
        c = next((x for x in rule.conclusions if x.variable == d.variable), None)
        if c is None:
            cons.append("0")
            continue
        index = [t.name for t in d.terms].index(c.term or "") + 1
        if fuzzylite or not octave.get(d.variable):
            cons.append(_entry(index, False, hedges_of[d.variable], fuzzylite))
        else:
            cons.append(f"{index + octave[d.variable] / 100.0:.2f}")
    weight = 1.0 if rule.weight is None else float(rule.weight)  # type: ignore[arg-type]
    connection = 2 if isinstance(rule.condition, Or) else 1
    return f"{' '.join(ante)}, {' '.join(cons)} ({fmt_number(weight)}) : {connection}"


__all__ = ["Point", "adapt", "write"]
