"""How jFuzzyLogic 3.3 reads a rule block, for the ``jfuzzylogic`` profile's lowering.

Read in ``RuleBlock.fclTree`` and the grammar (``fcl/Fcl.g``) of jFuzzyLogic, and confirmed with
the live jFuzzyLogic (tests/conformance/test_jfl_oracle.py):

* each AND or OR declaration sets *both* operators to its pair, so the last one written wins
  (``AND : PROD; OR : MAX;`` is MIN/MAX); HAMACHER pairs with EINSTEIN;
* ``ACCU`` defaults to SUM, and NSUM is computed as a bounded sum;
* ``condition : subcondition ((AND | OR) subcondition)*`` builds a left-deep tree: AND and OR
  have the same precedence and group left to right (``a OR b AND c`` is ``(a OR b) AND c``).
"""

from __future__ import annotations

from fuzzyctl import model as m
from fuzzyctl.engine.semantics import operators as ops
from fuzzyctl.kinds import norms

__all__ = ["accumulation", "left_to_right", "operator_pair"]

_AND_TO_OR = {
    "MIN": "MAX",
    "PROD": "ASUM",
    "BDIF": "BSUM",
    "DMIN": "DMAX",
    "NIPMIN": "NIPMAX",
    "HAMACHER": "EINSTEIN",
}
_OR_TO_AND = {v: k for k, v in _AND_TO_OR.items()}


def operator_pair(rb: m.RuleBlock) -> tuple[str, str]:
    """AND and OR of a rule block as jFuzzyLogic sets them: the last declaration written
    (by position; without positions OR, which writers put after AND) gives both.  Operators
    jFuzzyLogic does not have resolve as IEC 61131-7 pairs them (``check --compat
    jfuzzylogic`` warns that jFuzzyLogic would reject them)."""
    and_op = ops.AND_ALIASES.get(rb.and_op, rb.and_op) if rb.and_op else None
    or_op = ops.OR_ALIASES.get(rb.or_op, rb.or_op) if rb.or_op else None
    if and_op is not None and or_op is not None:
        spans = dict(rb.item_spans)
        a, o = spans.get("and_op"), spans.get("or_op")
        and_last = a is not None and o is not None and (a.line, a.column) > (o.line, o.column)
        if and_last:
            or_op = None
        else:
            and_op = None
    if and_op is not None and and_op in _AND_TO_OR:
        return and_op, _AND_TO_OR[and_op]
    if or_op is not None and or_op in _OR_TO_AND:
        return _OR_TO_AND[or_op], or_op
    return ops.resolve_pair(and_op, or_op)


def accumulation(rb: m.RuleBlock) -> str:
    """A rule block's ACCU as jFuzzyLogic applies it: SUM when absent, NSUM as BSUM."""
    accu = ops.resolve_accu(rb.accu) if rb.accu is not None else "SUM"
    return norms.ACCUMULATIONS[accu].jfl


def left_to_right(c: m.Condition) -> m.Condition:
    """``c`` regrouped as jFuzzyLogic reads the text it was written as: the AND/OR chain at
    each parenthesis level folded from the left, each connective binding two operands."""
    if isinstance(c, m.Is | m.Degree):
        return c
    if isinstance(c, m.Not):
        return m.Not(left_to_right(c.operand), c.span)
    atoms: list[m.Condition] = []
    connectives: list[type[m.And] | type[m.Or]] = []
    _chain(c, atoms, connectives, top=True)
    out = left_to_right(atoms[0])
    for kind, atom in zip(connectives, atoms[1:], strict=True):
        out = kind((out, left_to_right(atom)), c.span)
    return out


def _chain(
    c: m.Condition, atoms: list[m.Condition], connectives: list[type[m.And] | type[m.Or]], top: bool
) -> None:
    """The written sequence ``atom (AND|OR) atom ...`` of one parenthesis level."""
    if isinstance(c, m.And | m.Or) and (top or not c.grouped):
        for i, operand in enumerate(c.operands):
            if i:
                connectives.append(type(c))
            _chain(operand, atoms, connectives, top=False)
    else:
        atoms.append(c)
