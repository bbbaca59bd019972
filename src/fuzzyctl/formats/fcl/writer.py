"""Writing FCL (IEC 61131-7) for the format registry.

The FCL writer belongs to :mod:`fuzzyctl.fcl` (``fuzzyctl.fcl.write``); this module says what
FCL cannot express of a model that came from another format (a MATLAB/fuzzylite rule weight
under ACT MIN, fuzzylite's lock-range, ...) and rewrites what FCL says differently.
"""

from __future__ import annotations

import itertools
import math
import re
from dataclasses import replace

from fuzzyctl.fcl.identifiers import fcl_block_name, fcl_name, fcl_term
from fuzzyctl.formats import Loss
from fuzzyctl.formats.common.adapt import rename
from fuzzyctl.formats.common.basics import hedge_power, identifier
from fuzzyctl.formats.fcl.names import fcl_api
from fuzzyctl.kinds import norms
from fuzzyctl.kinds import shapes as registry
from fuzzyctl.model import (
    POWER_HEDGE_PREFIX,
    And,
    Condition,
    Document,
    FunctionBlock,
    Is,
    MembershipFunction,
    Not,
    Or,
    Point,
    PointsMF,
    Rule,
    RuleBlock,
    ShapeMF,
)

_POINT_METHODS = frozenset({"COGS", "WTAVER", "WTSUM"})


def _rule_weight_to_conclusions(fb: FunctionBlock, block: RuleBlock, rule: Rule, losses: list[Loss]) -> Rule:
    """A MATLAB/fuzzylite rule weight as IEC WITH weights, where that is the same thing."""
    if rule.weight is None:
        return rule
    act = block.act or "MIN"
    conclusions = []
    for c in rule.conclusions:
        out = fb.defuzzify_block(c.variable)
        points = out is not None and (out.method or "") in _POINT_METHODS
        if not (points or norms.is_prod(act)):
            losses.append(
                Loss(
                    f"rule {rule.label!r}",
                    f"a rule weight scales the degree before ACT {act}; FCL's WITH scales the activated term",
                )
            )
            return replace(rule, weight=None)
        if c.weight is not None and not isinstance(c.weight, float | int):
            losses.append(Loss(f"rule {rule.label!r}", "a rule weight times a variable WITH weight"))
            return replace(rule, weight=None)
        w = float(rule.weight) * (1.0 if c.weight is None else float(c.weight))  # type: ignore[arg-type]
        conclusions.append(replace(c, weight=w))
    return replace(rule, weight=None, conclusions=tuple(conclusions))


def _labels(block: RuleBlock) -> RuleBlock:
    """Rule labels FCL reads (``\\w+``, each once); others are numbered in order."""
    labels = [r.label for r in block.rules]
    if all(re.fullmatch(r"\w+", str(x)) for x in labels) and len(set(labels)) == len(labels):
        return block
    return replace(block, rules=tuple(replace(r, label=str(i)) for i, r in enumerate(block.rules, 1)))


def _power_words(hedges: tuple[str, ...]) -> tuple[str, ...] | None:
    """Power hedges (Octave's ``d^p``) as FCL hedge words: ``very`` is d^2, ``somewhat``
    sqrt(d), so d^4 is ``very very``; ``None`` when a power has no such form."""
    words: list[str] = []
    for hedge in hedges:
        if not hedge.startswith(POWER_HEDGE_PREFIX):
            words.append(hedge)
            continue
        power = hedge_power(hedge)
        if power is None or power <= 0:
            return None
        exponent = math.log2(power)
        if exponent != round(exponent) or abs(exponent) > 8:
            return None
        words += ["very" if exponent > 0 else "somewhat"] * abs(round(exponent))
    return tuple(words)


def _hedges_in_fcl(condition: Condition, where: str, losses: list[Loss]) -> Condition:
    """Octave's power hedges said with FCL's hedge words where they can be."""
    if isinstance(condition, Is):
        if not any(h.startswith(POWER_HEDGE_PREFIX) for h in condition.hedges):
            return condition
        words = _power_words(condition.hedges)
        if words is None:
            losses.append(Loss(where, f"FCL has no hedge for {' '.join(condition.hedges)}; dropped"))
            words = tuple(h for h in condition.hedges if not h.startswith(POWER_HEDGE_PREFIX))
        return replace(condition, hedges=words)
    if isinstance(condition, Not):
        return replace(condition, operand=_hedges_in_fcl(condition.operand, where, losses))
    if isinstance(condition, And | Or):
        operands = tuple(_hedges_in_fcl(c, where, losses) for c in condition.operands)
        return replace(condition, operands=operands)
    return condition


def _fcl_identifier(name: str, taken: set[str]) -> str:
    """``name`` when FCL reads it and it is free, else an identifier close to it."""
    if fcl_name(name) and name not in taken:
        taken.add(name)
        return name
    base = identifier(name, set())
    candidate, n = base, 2
    while candidate in taken or not fcl_name(candidate):
        candidate, n = f"{base}_{n}", n + 1
    taken.add(candidate)
    return candidate


def _as_points(mf: MembershipFunction) -> MembershipFunction:
    """A triangle or trapezoid with numeric, finite vertices as the IEC point list it is
    (Basic level, Table 8; the engine evaluates both the same); a list of one point (made
    through the API: no reader accepts one) as that point twice, the same constant degree
    written as 5.2.2 asks (two points at least); anything else unchanged."""
    if isinstance(mf, PointsMF) and len(mf.points) == 1:
        return PointsMF(mf.points * 2)
    vertices = registry.vertices(mf.kind) if isinstance(mf, ShapeMF) else None
    if not isinstance(mf, ShapeMF) or vertices is None:
        return mf
    values = (*mf.params, mf.height)
    if not all(isinstance(v, int | float) and math.isfinite(v) for v in values):
        return mf
    h = float(mf.height)  # type: ignore[arg-type]
    xs = [float(v) for v in mf.params]  # type: ignore[arg-type]
    ys = [v * h for v in vertices]
    if any(b < a for a, b in itertools.pairwise(xs)):
        return mf  # not a well-formed shape: keep what the source said
    return PointsMF(tuple(Point(x, y) for x, y in zip(xs, ys, strict=True)))


def _basic_level(fb: FunctionBlock) -> FunctionBlock:
    """Say things the way strict IEC 61131-7 tools read them where that is the same thing:
    point lists for triangles and trapezoids, and a variable's RANGE inside its FUZZIFY /
    DEFUZZIFY block rather than on its declaration line (jFuzzyLogic's Open-level form)."""
    ranges = {v.name: v.range for v in fb.variables if v.range is not None}
    fuzzify = tuple(
        replace(
            f,
            range=f.range or ranges.get(f.variable),
            terms=tuple(replace(t, mf=_as_points(t.mf)) for t in f.terms),
        )
        for f in fb.fuzzify
    )
    defuzzify = tuple(
        replace(
            d,
            range=d.range or ranges.get(d.variable),
            terms=tuple(replace(t, mf=_as_points(t.mf)) for t in d.terms),
        )
        for d in fb.defuzzify
    )
    in_blocks = {f.variable for f in fuzzify} | {d.variable for d in defuzzify}
    variables = tuple(replace(v, range=None) if v.name in in_blocks else v for v in fb.variables)
    return replace(fb, variables=variables, fuzzify=fuzzify, defuzzify=defuzzify)


def adapt(document: Document) -> tuple[Document, list[Loss]]:
    """Rewrite what FCL says differently, report what it cannot say at all."""
    losses: list[Loss] = []
    blocks = []
    for fb in document.blocks:
        for f in fb.fuzzify:
            if f.clamp:
                losses.append(
                    Loss(
                        f"input {f.variable!r}",
                        "FCL cannot clamp an input to its RANGE (fuzzylite lock-range)",
                    )
                )
        for d in fb.defuzzify:
            if d.clamp:
                losses.append(
                    Loss(f"output {d.variable!r}", "FCL cannot clamp an output (fuzzylite lock-range)")
                )
        rule_blocks = []
        for block in fb.rule_blocks:
            if not block.enabled:
                losses.append(Loss(f"rule block {block.name!r}", "FCL has no disabled rule blocks; dropped"))
                continue
            if block.rule_activation:
                losses.append(
                    Loss(f"rule block {block.name!r}", f"FCL fires every rule ({block.rule_activation!r})")
                )
            rules = []
            for rule in block.rules:
                condition = rule.condition
                rule = _rule_weight_to_conclusions(fb, block, rule, losses)
                if condition is not None:  # no IF part: the writer's IF ALWAYS (see notes)
                    rule = replace(rule, condition=_hedges_in_fcl(condition, f"rule {rule.label!r}", losses))
                if any(c.hedges for c in rule.conclusions):
                    losses.append(Loss(f"rule {rule.label!r}", "FCL has no hedges on conclusions"))
                    rule = replace(rule, conclusions=tuple(replace(c, hedges=()) for c in rule.conclusions))
                rules.append(rule)
            rule_blocks.append(replace(block, rules=tuple(rules), enabled=True, rule_activation=None))
        fuzzify = tuple(replace(f, clamp=False) for f in fb.fuzzify)
        defuzzify = tuple(replace(d, clamp=False) for d in fb.defuzzify)
        fb = _basic_level(replace(fb, rule_blocks=tuple(rule_blocks), fuzzify=fuzzify, defuzzify=defuzzify))
        # names FCL cannot read back (MATLAB's "sugeno tipper", "a/b", a variable "if") are
        # renamed: not a loss
        fb, _renames = rename(fb, fcl_name, fcl_term)
        if fb.name is not None and not fcl_block_name(fb.name):
            fb = replace(fb, name=_fcl_identifier(fb.name, set()))
        taken: set[str] = set()
        fb = replace(
            fb,
            rule_blocks=tuple(
                _labels(replace(b, name=None if b.name is None else _fcl_identifier(b.name, taken)))
                for b in fb.rule_blocks
            ),
        )
        blocks.append(fb)
    return replace(document, blocks=tuple(blocks)), losses


def notes(document: Document) -> list[Loss]:
    """Rules without an IF part (Siemens 1.5, MATLAB's all don't-care, fuzzylite's ``x is
    any``): FCL has none; they are written ``IF ALWAYS THEN`` with ``ALWAYS : REAL := 1.0``,
    a degree input left unconnected (:mod:`fuzzyctl.fcl.no_if`), which fuzzyctl reads back as
    rules without an IF part and other IEC tools as an input."""
    from fuzzyctl.fcl.no_if import always_name

    out = []
    for fb in document.blocks:
        labels = [rule.label for _rb, rule in fb.rules() if rule.condition is None]
        if labels:
            name = always_name(fb)
            out.append(
                Loss(
                    f"rule(s) {', '.join(repr(x) for x in labels)}",
                    f"no IF part (degree 1): written 'IF {name} THEN ...' with the input "
                    f"{name} : REAL := 1.0, which must stay unconnected (fuzzyctl reads it back as a "
                    "rule without IF part; other IEC 61131-7 tools see an input)",
                )
            )
    return out


def write(document: Document) -> str:
    """FCL text of a document that :func:`adapt` returned (:func:`fuzzyctl.fcl.write`)."""
    api = fcl_api()
    assert api is not None
    text = api.write(document)
    assert isinstance(text, str)
    return text


__all__ = ["adapt", "notes", "write"]
