"""Writing fuzzylite language (FLL, fuzzylite 6 layout) from the model."""

from __future__ import annotations

import math
from dataclasses import replace

from fuzzyctl.escape import one_line
from fuzzyctl.formats import Loss
from fuzzyctl.formats.common.adapt import (
    SUM_LIKE,
    point_accumulation,
    prepare,
    rule_label,
    term_losses,
    uncumulate,
    with_range,
)
from fuzzyctl.formats.common.basics import fmt_number
from fuzzyctl.formats.common.expr import format_expr
from fuzzyctl.formats.common.terms import FLL_OF_KIND, FLL_TYPES, TS_KINDS, fll_ts_name
from fuzzyctl.formats.fll.names import DEFUZZIFIERS, HEDGE_WORDS, KEYWORDS, SNORMS_ACCU, SNORMS_OR, TNORMS
from fuzzyctl.kinds import methods, norms
from fuzzyctl.model import (
    HEDGES,
    And,
    Condition,
    DefuzzifyBlock,
    Document,
    FunctionBlock,
    FunctionMF,
    FuzzifyBlock,
    Is,
    Or,
    PointsMF,
    ShapeMF,
    SingletonMF,
    Term,
)

_TNORM_NAMES = {v: k for k, v in TNORMS.items()}
_OR_NAMES = {v: k for k, v in SNORMS_OR.items()}
_ACCU_NAMES = {v: k for k, v in SNORMS_ACCU.items()}
_DEFUZZ_NAMES = {v: k for k, v in DEFUZZIFIERS.items()}
_DEFUZZ_NAMES["COGS"] = "WeightedAverage"
FLL_HEDGES = frozenset(HEDGES)
INTEGRAL_METHODS = methods.ON_SETS  # fuzzylite integral defuzzifiers (take a resolution)
RESOLUTION = 1000
"""Integration steps written for fuzzylite's integral defuzzifiers (fuzzyctl itself is
exact; fuzzylite approximates with this many midpoint samples)."""


def adapt(document: Document) -> tuple[Document, list[Loss]]:
    """The model as FLL can state it, and what had to be dropped."""
    # a variable or term called "very" or "then" would read as a hedge or a keyword
    fb, losses, _ = prepare(document, "FLL", reserved=HEDGE_WORDS | KEYWORDS)
    fb = replace(
        fb,
        fuzzify=tuple(with_range(fb, f, losses, "FLL") for f in fb.fuzzify),  # type: ignore[misc]
        defuzzify=tuple(with_range(fb, d, losses, "FLL") for d in fb.defuzzify),  # type: ignore[misc]
    )
    supported = set(FLL_OF_KIND) | TS_KINDS
    all_blocks: list[FuzzifyBlock | DefuzzifyBlock] = [*fb.fuzzify, *fb.defuzzify]
    for blk in all_blocks:
        kept = tuple(t for t in blk.terms if _term_ok(blk.variable, t, supported, losses, blk))
        if len(kept) != len(blk.terms):
            fb = _replace_block(fb, replace(blk, terms=kept))
    blocks = []
    for block in fb.rule_blocks:
        rules = []
        for rule in block.rules:
            hedges = [h for a in _ises(rule.condition) for h in a.hedges] + [
                h for c in rule.conclusions for h in c.hedges
            ]
            unknown = sorted({h for h in hedges if h not in FLL_HEDGES})
            if unknown:
                losses.append(Loss(rule_label(block, rule), f"FLL has no hedge {', '.join(unknown)}"))
                continue
            if not _terms_exist(fb, rule):
                losses.append(Loss(rule_label(block, rule), "refers to a term that could not be written"))
                continue
            rules.append(rule)
        blocks.append(replace(block, rules=tuple(rules)))
    for d in fb.defuzzify:
        if d.method in methods.POINT_OUTPUTS:
            continue  # NSUM adds the degrees of a weighted average, written UnboundedSum
        if norms.stand_in(d.accu) or any(norms.stand_in(b.accu) for b in fb.rule_blocks):
            losses.append(
                Loss(
                    f"output {d.variable!r}",
                    "FLL has no IEC NSUM accumulation (fuzzylite's NormalizedSum normalises pairwise)",
                )
            )
    # what is written instead (--lossy): UnboundedSum, which NSUM only scales by a constant
    # (the same centroid; a weighted average writes SUM already)
    blocks = [replace(b, accu=a) if (a := norms.stand_in(b.accu)) else b for b in blocks]
    defuzzify = tuple(replace(d, accu=a) if (a := norms.stand_in(d.accu)) else d for d in fb.defuzzify)
    return Document((replace(fb, rule_blocks=tuple(blocks), defuzzify=defuzzify),), document.path), losses


def _replace_block(fb: FunctionBlock, blk: FuzzifyBlock | DefuzzifyBlock) -> FunctionBlock:
    if isinstance(blk, DefuzzifyBlock):
        return replace(fb, defuzzify=tuple(blk if d.variable == blk.variable else d for d in fb.defuzzify))
    return replace(fb, fuzzify=tuple(blk if f.variable == blk.variable else f for f in fb.fuzzify))


def _term_ok(owner: str, term: Term, supported: set[str], losses: list[Loss], blk: object) -> bool:
    if isinstance(term.mf, SingletonMF) and not (
        isinstance(blk, DefuzzifyBlock) and blk.method in methods.POINT_OUTPUTS
    ):
        losses.append(
            Loss(
                f"term {term.name!r} of {owner!r}",
                "FLL has singletons only as Constant terms of a weighted-average output",
            )
        )
        return False
    if (
        isinstance(term.mf, ShapeMF)
        and term.mf.kind in TS_KINDS
        and not (isinstance(blk, DefuzzifyBlock) and blk.method in methods.POINT_OUTPUTS)
    ):
        losses.append(
            Loss(
                f"term {term.name!r} of {owner!r}", "Constant/Linear terms belong to weighted-average outputs"
            )
        )
        return False
    return term_losses(owner, term, supported, "FLL", losses)


def _terms_exist(fb: FunctionBlock, rule: object) -> bool:
    from fuzzyctl.model import Rule

    assert isinstance(rule, Rule)
    for a in _ises(rule.condition):
        blk = fb.fuzzify_block(a.variable) or fb.defuzzify_block(a.variable)
        if blk is None or blk.term(a.term) is None:
            return False
    for c in rule.conclusions:
        blk2 = fb.defuzzify_block(c.variable)
        if blk2 is None or blk2.term(c.term or "") is None:
            return False
    return True


def _ises(condition: Condition | None) -> list[Is]:
    if condition is None:
        return []
    if isinstance(condition, Is):
        return [condition]
    if isinstance(condition, And | Or):
        return [a for c in condition.operands for a in _ises(c)]
    return []


def _params(values: list[float], height: float) -> str:
    text = " ".join(fmt_number(v) for v in values)
    return text if height == 1.0 else f"{text} {fmt_number(height)}"


def term_text(term: Term) -> str:
    mf = term.mf
    if isinstance(mf, ShapeMF):
        if mf.kind in TS_KINDS:  # Constant value, Linear c1 .. cn constant: no height
            coefs = " ".join(fmt_number(float(p)) for p in mf.params)  # type: ignore[arg-type]
            return f"{term.name} {fll_ts_name(mf.kind)} {coefs}"
        cls = FLL_OF_KIND[mf.kind]
        values = FLL_TYPES[cls].from_model(tuple(float(p) for p in mf.params))  # type: ignore[arg-type]
        return f"{term.name} {cls} {_params(values, float(mf.height))}"  # type: ignore[arg-type]
    if isinstance(mf, PointsMF):
        return f"{term.name} Discrete " + " ".join(
            f"{fmt_number(float(p.x))} {fmt_number(float(p.y))}"  # type: ignore[arg-type]
            for p in mf.points
        )
    if isinstance(mf, SingletonMF):
        return f"{term.name} Constant {fmt_number(float(mf.value))}"  # type: ignore[arg-type]
    if isinstance(mf, FunctionMF):
        return f"{term.name} Function {format_expr(mf.expr)}"
    raise TypeError(f"term {term.name!r} cannot be written as FLL")


def condition_text(condition: Condition, top: bool = True) -> str:
    if isinstance(condition, Is):
        words = [condition.variable, "is"]
        if condition.negated:
            words.append("not")
        words.extend(condition.hedges)
        words.append(condition.term)
        return " ".join(words)
    assert isinstance(condition, And | Or)
    word = " and " if isinstance(condition, And) else " or "
    text = word.join(condition_text(c, top=False) for c in condition.operands)
    return text if top else f"({text})"


def write(document: Document, *, resolution: int = RESOLUTION) -> str:
    """FLL text of a document that :func:`adapt` returned."""
    fb = document.main
    out = [f"Engine: {one_line(fb.name or '')}".rstrip()]  # names are free text: kept on their line
    for var in fb.inputs:
        blk = fb.fuzzify_block(var.name)
        out.append(f"InputVariable: {var.name}")
        out.append("  enabled: true")
        rng = blk.range if blk and blk.range else var.range
        if rng is not None:
            out.append(f"  range: {fmt_number(rng.low)} {fmt_number(rng.high)}")
        else:
            out.append("  range: -inf inf")
        out.append(f"  lock-range: {'true' if blk and blk.clamp else 'false'}")
        for term in blk.terms if blk else ():
            out.append(f"  term: {term_text(term)}")
    accu_of_block = {
        c.variable: b.accu
        for b in fb.rule_blocks
        for _, r in [(b, r) for r in b.rules]
        for c in r.conclusions
    }
    for var in fb.outputs:
        d = fb.defuzzify_block(var.name)
        if d is None:
            continue
        out.append(f"OutputVariable: {var.name}")
        out.append("  enabled: true")
        rng = d.range or var.range
        out.append(f"  range: {fmt_number(rng.low)} {fmt_number(rng.high)}" if rng else "  range: -inf inf")
        out.append(f"  lock-range: {'true' if d.clamp else 'false'}")
        point = (d.method or "") in methods.POINT_OUTPUTS
        if point:
            # pyfuzzylite 8 aggregates a weighted average's terms as our engine does (fuzzylite 6
            # ignores the aggregation there and lets every rule count)
            accu = point_accumulation(fb, d)
            accu = "SUM" if accu in SUM_LIKE else accu
        else:
            accu = d.accu or accu_of_block.get(var.name)
        out.append(f"  aggregation: {_ACCU_NAMES[accu] if accu else ('none' if point else 'Maximum')}")
        method = d.method or "COG"
        name = _DEFUZZ_NAMES.get(method, "Centroid")
        out.append(
            f"  defuzzifier: {name} {resolution}" if method in INTEGRAL_METHODS else f"  defuzzifier: {name}"
        )
        default = d.default
        value = default.value if default and default.value is not None else 0.0
        out.append(f"  default: {fmt_number(value) if not math.isnan(value) else 'nan'}")
        out.append(f"  lock-previous: {'true' if default and default.no_change else 'false'}")
        for term in d.terms:
            out.append(f"  term: {term_text(term)}")
    for block in fb.rule_blocks:
        out.append(f"RuleBlock: {one_line(block.name or '')}".rstrip())
        out.append(f"  enabled: {'true' if block.enabled else 'false'}")
        # "none" round-trips an absent operator; fuzzylite needs one where it is used, and our
        # engine's defaults (MIN, MAX, MIN) are then written out.
        uses_and = any(_has(r.condition, And) for r in block.rules)
        uses_or = any(_has(r.condition, Or) for r in block.rules)
        mamdani = any(not _is_point(fb, c.variable) for r in block.rules for c in r.conclusions)
        out.append(
            "  conjunction: "
            + (_TNORM_NAMES[block.and_op] if block.and_op else ("Minimum" if uses_and else "none"))
        )
        out.append(
            f"  disjunction: {_OR_NAMES[block.or_op] if block.or_op else ('Maximum' if uses_or else 'none')}"
        )
        out.append(
            f"  implication: {_TNORM_NAMES[block.act] if block.act else ('Minimum' if mamdani else 'none')}"
        )
        out.append(f"  activation: {block.rule_activation or 'General'}")
        for rule in block.rules:
            out.append(f"  rule: {rule_text(fb, rule)}")
    return "\n".join(out) + "\n"


def _has(condition: Condition | None, kind: type) -> bool:
    if condition is None or isinstance(condition, Is):
        return False
    if isinstance(condition, kind):
        return True
    return any(_has(c, kind) for c in condition.operands)  # type: ignore[union-attr]


def _is_point(fb: FunctionBlock, variable: str) -> bool:
    d = fb.defuzzify_block(variable)
    return d is not None and (d.method or "") in methods.POINT_OUTPUTS


def rule_text(fb: FunctionBlock, rule: object) -> str:
    from fuzzyctl.model import Rule

    assert isinstance(rule, Rule)
    if rule.condition is None:
        first = fb.inputs[0].name if fb.inputs else fb.outputs[0].name
        antecedent = f"{first} is any"
    else:
        antecedent = condition_text(rule.condition)
    written = uncumulate([c.hedges for c in rule.conclusions]) or [c.hedges for c in rule.conclusions]
    parts = [
        " ".join([c.variable, "is", *h, c.term or ""]) for c, h in zip(rule.conclusions, written, strict=True)
    ]
    text = f"if {antecedent} then {' and '.join(parts)}"
    if rule.weight is not None:
        text += f" with {fmt_number(float(rule.weight))}"  # type: ignore[arg-type]
    return text
