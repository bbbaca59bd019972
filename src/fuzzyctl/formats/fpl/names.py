"""Names the FPL reader and writer share: the words FPL reserves, how long a name may be, and
how Fuzzy Control accumulates (manual 1.3, 1.4)."""

from __future__ import annotations

import re
from collections.abc import Iterator

from fuzzyctl.model import And, Condition, FunctionBlock, Is, Rule

#: The longest name FPL reads (Siemens 1.3).
MAX_NAME = 255

# Objects that own an END (skipping a tolerated object counts these to find its END).
OBJECTS = {
    "PROJECT",
    "PACKAGE",
    "VAR",
    "MEMBER",
    "FUZZY",
    "RULE",
    "CONNECT",
    "OPTIONS",
    "SOURCE",
    "FRAGMENT",
}
# Words that end the arguments of a tolerated attribute (MAP, INITIALLY, DEFAULT).
STRUCTURAL = OBJECTS | {
    "END",
    "TYPE",
    "MIN",
    "MAX",
    "POINTS",
    "IF",
    "THEN",
    "FROM",
    "TO",
    "MAP",
    "INITIALLY",
    "DEFAULT",
}
# Words FPL reads as keywords wherever they stand (upper-cased): no name may be one of them.
KEYWORDS = frozenset(STRUCTURAL | {"IS", "AND", "OR", "NOT"})
WORD = re.compile(r"[^\W\d]\w*")


def is_fpl_name(name: str) -> bool:
    """True when FPL reads ``name`` back as one name (a word, not a keyword)."""
    return WORD.fullmatch(name) is not None and name.upper() not in KEYWORDS


SIEMENS_ACCU = "NSUM"
"""The IEC accumulation that computes what Fuzzy Control computes (1.4): the sum of the
rules' degrees per output term (NSUM's normalisation cancels in a centre of gravity)."""

ADDING_ACCU = frozenset({"NSUM", "SUM"})
"""Accumulations that add the rules' degrees without a bound, as Fuzzy Control does."""


def shared_conclusions(block: FunctionBlock) -> list[tuple[str, str, list[Rule]]]:
    """``(output, term, rules)`` for every output term that two or more rules conclude.

    Only there does the accumulation matter for singleton outputs: one rule per term gives
    the same degrees under MAX, BSUM, NSUM or SUM, so the Siemens sum (1.4) equals an
    IEC ``ACCU : MAX`` program exactly when this list is empty."""
    seen: dict[tuple[str, str], list[Rule]] = {}
    for _rb, rule in block.rules():
        for c in rule.conclusions:
            if c.term is not None:
                seen.setdefault((c.variable, c.term), []).append(rule)
    return [(v, t, rules) for (v, t), rules in seen.items() if len(rules) > 1]


def leaves(cond: Condition | None) -> Iterator[Is]:
    """The ``v IS t`` subconditions of an AND-only condition, left to right."""
    # A stack, not nested generators: a leaf deep in the parentheses would pass through
    # one generator per level.
    stack = [cond]
    while stack:
        item = stack.pop()
        if isinstance(item, Is):
            yield item
        elif isinstance(item, And):
            stack.extend(reversed(item.operands))
