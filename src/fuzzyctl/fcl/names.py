"""Name resolution after parsing: references are matched to declarations.

* IEC 61131-3 identifiers are not case-sensitive; a reference that matches a declaration
  only when case is ignored is rewritten to the declared spelling, with a warning.
* After ``IS`` the parser sees words (hedges, then the term).  The longest run of final
  words that names a declared term of the variable is the term (``AoA IS Front Left`` with a
  term ``Front Left``); the words before it are hedges (``very``).
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import replace

from fuzzyctl.model import (
    And,
    Conclusion,
    Condition,
    DefuzzifyBlock,
    Degree,
    FunctionBlock,
    FuzzifyBlock,
    Is,
    Not,
    Or,
    Rule,
    Span,
)

Warn = Callable[[str, Span | None, str], None]


class _Resolver:
    def __init__(self, fb: FunctionBlock, warn: Warn) -> None:
        self.warn = warn
        self.declared = {v.name for v in fb.variables}
        self.by_lower: dict[str, list[str]] = {}
        for name in self.declared:
            self.by_lower.setdefault(name.lower(), []).append(name)
        self._lowered: dict[int, dict[str, str]] = {}  # term set (by identity) -> lower-case map

    def variable(self, name: str, span: Span | None) -> str:
        if name in self.declared:
            return name
        hits = self.by_lower.get(name.lower(), [])
        if len(hits) == 1:
            self.warn(
                f"{name} refers to {hits[0]}: names differ only in case (IEC 61131-3 ignores case)",
                span,
                "case-mismatch",
            )
            return hits[0]
        return name

    def words(self, words: list[str], terms: set[str], span: Span | None) -> tuple[tuple[str, ...], str]:
        if len(words) == 1 and words[0] in terms:
            return (), words[0]
        for i in range(len(words)):
            if " ".join(words[i:]) in terms:
                return tuple(words[:i]), " ".join(words[i:])
        lowered = self._lowered.get(id(terms))
        if lowered is None:
            lowered = self._lowered[id(terms)] = {t.lower(): t for t in terms}
        for i in range(len(words)):
            hit = lowered.get(" ".join(words[i:]).lower())
            if hit is not None:
                written = " ".join(words[i:])
                self.warn(
                    f"{written} refers to term {hit}: names differ only in case (IEC 61131-3 ignores case)",
                    span,
                    "case-mismatch",
                )
                return tuple(words[:i]), hit
        return tuple(words[:-1]), words[-1]


def resolve_names(fb: FunctionBlock, warn: Warn) -> FunctionBlock:
    """``fb`` with references rewritten to the declared names (see module doc)."""
    r = _Resolver(fb, warn)
    fuzzify = tuple(replace(b, variable=r.variable(b.variable, b.span)) for b in fb.fuzzify)
    defuzzify = tuple(replace(b, variable=r.variable(b.variable, b.span)) for b in fb.defuzzify)
    terms: dict[str, set[str]] = {}
    blocks: list[FuzzifyBlock | DefuzzifyBlock] = [*fuzzify, *defuzzify]
    for b in blocks:
        terms.setdefault(b.variable, set()).update(t.name for t in b.terms)

    no_terms: set[str] = set()

    def condition(c: Condition) -> Condition:
        # a part that needs no change is kept as it is (no copy of a large rule base)
        if isinstance(c, Is):
            if not c.hedges and c.term in terms.get(c.variable, no_terms) and c.variable in r.declared:
                return c  # the common case: declared names, as written
            var = r.variable(c.variable, c.span)
            hedges, term = r.words([*c.hedges, c.term], terms.get(var, no_terms), c.span)
            if var == c.variable and term == c.term and hedges == c.hedges:
                return c
            return replace(c, variable=var, term=term, hedges=hedges)
        if isinstance(c, Degree):
            var = r.variable(c.variable, c.span)
            return c if var == c.variable else replace(c, variable=var)
        if isinstance(c, Not):
            operand = condition(c.operand)
            return c if operand is c.operand else replace(c, operand=operand)
        assert isinstance(c, And | Or)
        operands = tuple(condition(o) for o in c.operands)
        if all(a is b for a, b in zip(operands, c.operands, strict=True)):
            return c
        return replace(c, operands=operands)

    def conclusion(c: Conclusion) -> Conclusion:
        if not c.hedges and c.term in terms.get(c.variable, no_terms) and c.variable in r.declared:
            return c
        var = r.variable(c.variable, c.span)
        if c.term is None:
            return c if var == c.variable else replace(c, variable=var)
        hedges, term = r.words([*c.hedges, c.term], terms.get(var, no_terms), c.span)
        if var == c.variable and term == c.term and hedges == c.hedges:
            return c
        return replace(c, variable=var, term=term, hedges=hedges)

    def rule(rule: Rule) -> Rule:
        cond = condition(rule.condition) if rule.condition is not None else None
        concl = tuple(conclusion(c) for c in rule.conclusions)
        if cond is rule.condition and all(a is b for a, b in zip(concl, rule.conclusions, strict=True)):
            return rule
        return replace(rule, condition=cond, conclusions=concl)

    rule_blocks = tuple(replace(rb, rules=tuple(rule(x) for x in rb.rules)) for rb in fb.rule_blocks)
    return replace(fb, fuzzify=fuzzify, defuzzify=defuzzify, rule_blocks=rule_blocks)
