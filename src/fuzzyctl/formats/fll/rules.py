"""The rules of FLL files (``rule: if a is lo and (b is hi or ...) then y is big with 0.5``).

Read with loops over the rule's words, not recursion, so that a rule of a million words
takes time linear in its length; nesting beyond :data:`fuzzyctl.limits.MAX_NESTING`
parentheses is refused as soon as it is met.  Every node of a rule shares the rule's one
:class:`Span`, and names are the variable's and term's own strings, so that a rule base of
a hundred thousand rules holds no copies (and pickles without them).
"""

from __future__ import annotations

import re

from fuzzyctl.formats.common.basics import parse_number
from fuzzyctl.formats.fll.names import HEDGE_WORDS
from fuzzyctl.limits import MAX_NESTING
from fuzzyctl.model import And, Conclusion, Condition, Is, Or, Rule, Span

# the one string object of each hedge word, shared by every proposition that names it
_HEDGES = {word: word for word in HEDGE_WORDS}
_CONCLUSION_HEDGES = HEDGE_WORDS - {"any", "not"}
_WORD = re.compile(r"\(|\)|[^\s()]+")

#: variable name -> (its name, whether it is an output, {term name: term name})
Lookup = dict[str, tuple[str, bool, dict[str, str]]]


class RuleError(Exception):
    """A rule that does not parse; the message says why (the caller adds the place)."""


def parse_rule(text: str, label: str, span: Span, variables: Lookup) -> Rule:
    """The rule written ``text`` (what follows ``rule:``); raises :class:`RuleError`."""
    words = _WORD.findall(text) if "(" in text or ")" in text else text.split()
    i = _expect(words, 0, "if")
    condition, i = _condition(words, i, span, variables)
    i = _expect(words, i, "then")
    conclusions, i = _consequent(words, i, span, variables)
    weight: float | None = None
    n = len(words)
    if i < n and words[i] == "with":
        if i + 1 >= n:
            raise RuleError("expected a weight but the rule ends")
        word = words[i + 1]
        i += 2
        try:
            weight = parse_number(word)
        except ValueError:
            raise RuleError(f"weight must be a number, found {word!r}") from None
    if i < n:
        raise RuleError(f"unexpected {words[i]!r} at the end")
    return Rule(
        label,
        None if isinstance(condition, bool) else condition,
        tuple(conclusions),
        span,
        weight=None if weight is None or weight == 1.0 else weight,
    )


def _expect(words: list[str], i: int, word: str) -> int:
    if i >= len(words):
        raise RuleError(f"expected {word!r} but the rule ends")
    if words[i] != word:
        raise RuleError(f"expected {word!r} but found {words[i]!r}")
    return i + 1


# Conditions are Condition objects, or True for "x is any" (always holds): an "and" drops
# it, an "or" holding it is true.
def _condition(words: list[str], i: int, span: Span, variables: Lookup) -> tuple[Condition | bool, int]:
    """The condition starting at word ``i`` ("and" binds tighter than "or") and the index
    after it.  ``ors`` holds the finished conjunctions of the innermost open group, ``ands``
    the operands of the conjunction being read; an open parenthesis saves both."""
    n = len(words)
    groups: list[tuple[list[Condition | bool], list[Condition | bool]]] = []
    ors: list[Condition | bool] = []
    ands: list[Condition | bool] = []
    while True:
        if i < n and words[i] == "(":
            i += 1
            if len(groups) >= MAX_NESTING:
                raise RuleError(f"the condition nests more than {MAX_NESTING} parentheses deep")
            groups.append((ors, ands))
            ors, ands = [], []
            continue
        value: Condition | bool
        value, i = _proposition(words, i, span, variables)
        ands.append(value)
        while True:  # after an operand: go on with "and"/"or", or close what ends here
            word = words[i] if i < n else None
            if word == "and":
                i += 1
                break
            ors.append(_conjunction(ands, span))
            if word == "or":
                i += 1
                ands = []
                break
            value = _disjunction(ors, span)
            if not groups:
                return value, i
            if word != ")":
                found = "the rule ends" if word is None else f"found {word!r}"
                raise RuleError(f"expected ')' but {found}")
            i += 1
            ors, ands = groups.pop()
            ands.append(value)


def _conjunction(operands: list[Condition | bool], span: Span) -> Condition | bool:
    if len(operands) == 1:
        return operands[0]
    items = tuple(o for o in operands if o is not True)
    if not items:
        return True
    return items[0] if len(items) == 1 else And(items, span)  # type: ignore[arg-type]


def _disjunction(operands: list[Condition | bool], span: Span) -> Condition | bool:
    if len(operands) == 1:
        return operands[0]
    if any(o is True for o in operands):
        return True
    return Or(tuple(operands), span)  # type: ignore[arg-type]


def _proposition(words: list[str], i: int, span: Span, variables: Lookup) -> tuple[Is | bool, int]:
    """``variable is [hedges] term`` at word ``i`` (True for ``is any``)."""
    n = len(words)
    if i >= n:
        raise RuleError("expected a variable but the rule ends")
    name = words[i]
    entry = variables.get(name)
    if entry is None:
        raise RuleError(f"unknown variable {name!r}")
    i = _expect(words, i + 1, "is")
    hedges: list[str] = []
    while i < n and words[i] in HEDGE_WORDS:
        hedges.append(_HEDGES[words[i]])
        i += 1
        if hedges[-1] == "any":
            if "not" in hedges:
                raise RuleError("'not any' never holds and is not supported")
            return True, i
    if i >= n:
        raise RuleError("expected a term but the rule ends")
    term = entry[2].get(words[i])
    if term is None:
        raise RuleError(f"{name!r} has no term {words[i]!r}")
    negated = bool(hedges) and hedges[0] == "not"
    rest = tuple(hedges[1:] if negated else hedges)
    if "not" in rest:
        raise RuleError("'not' after another hedge is not supported (write it first)")
    if len(rest) > MAX_NESTING:
        raise RuleError(f"{len(rest)} hedges on {name!r} is {term!r}: the limit is {MAX_NESTING}")
    return Is(entry[0], term, negated, rest, span), i + 1


def _consequent(words: list[str], i: int, span: Span, variables: Lookup) -> tuple[list[Conclusion], int]:
    n = len(words)
    out: list[Conclusion] = []
    running: tuple[str, ...] = ()
    while True:
        if i >= n:
            raise RuleError("expected an output variable but the rule ends")
        name = words[i]
        entry = variables.get(name)
        if entry is None or not entry[1]:
            raise RuleError(f"{name!r} is not an output variable")
        i = _expect(words, i + 1, "is")
        own: list[str] = []
        while i < n and words[i] in _CONCLUSION_HEDGES:
            own.append(_HEDGES[words[i]])
            i += 1
        if i < n and words[i] in ("any", "not"):
            raise RuleError(f"hedge {words[i]!r} is not supported in a conclusion")
        if i >= n:
            raise RuleError("expected a term but the rule ends")
        term = entry[2].get(words[i])
        if term is None:
            raise RuleError(f"{name!r} has no term {words[i]!r}")
        i += 1
        if own:
            # fuzzylite hedges a running degree: earlier conclusions' hedges apply too (a
            # list per conclusion, so its length is bounded or the model grows quadratically)
            if len(own) + len(running) > MAX_NESTING:
                raise RuleError(
                    f"{len(own) + len(running)} hedges apply to {name!r} is {term!r} (its own and "
                    f"those of the conclusions before it): the limit is {MAX_NESTING}"
                )
            running = (*own, *running)
        out.append(Conclusion(entry[0], term, None, span, running))
        if i >= n or words[i] != "and":
            return out, i
        i += 1
