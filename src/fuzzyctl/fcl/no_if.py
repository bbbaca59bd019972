"""Rules without an IF part in FCL.

The Siemens S7 block (manual 1.5) and FPL know rules with a THEN part only: "a truth degree
of 1 always acts on the THEN part" (a bias rule; ``Rule.condition is None`` in the model).
IEC 61131-7 has no such rule: every rule is ``IF condition THEN``.  Its nearest faithful form
is a condition that is always 1: a bare input variable, which 5.2.4 allows "to permit fuzzy
degrees of membership to be imported" (Table 9, "n input variables" in a condition), declared
for that purpose with the initial value 1.0 and left unconnected::

    VAR_INPUT
        (* degree 1 of the rules without an IF part (Siemens 1.5): leave unconnected *)
        ALWAYS : REAL := 1.0;
    END_VAR
    RULE bias : IF ALWAYS THEN valve IS closed;

:func:`with_if_parts` writes that form; :func:`without_if_parts` reads it back: a VAR_INPUT
named ``ALWAYS`` (``ALWAYS_2``... when the name is taken), REAL, initial value 1.0, without
FUZZIFY block or RANGE, used nowhere but as the whole condition of rules, becomes rules
without an IF part again, with a note.  Evaluated as written (another IEC tool, or our engine
before the read-back) the form gives exactly degree 1 as long as the input is not connected:
an engine uses the initial value of an input it is not given.
"""

from __future__ import annotations

import re
from collections.abc import Iterator
from dataclasses import replace

from fuzzyctl.diagnostics import Diagnostic, Severity
from fuzzyctl.fcl.checks import mf_params, term_blocks
from fuzzyctl.model import (
    And,
    Binary,
    Call,
    Condition,
    Degree,
    Document,
    Expr,
    FunctionBlock,
    FunctionMF,
    Is,
    Name,
    Not,
    Or,
    Ref,
    Rule,
    Unary,
    Variable,
    VarKind,
)

__all__ = ["ALWAYS", "COMMENT", "always_name", "with_if_parts", "without_if_parts"]

ALWAYS = "ALWAYS"
COMMENT = "degree 1 of the rules without an IF part (Siemens 1.5): leave unconnected"
_PATTERN = re.compile(rf"{ALWAYS}(_\d+)?")


def _names(fb: FunctionBlock) -> set[str]:
    names = {v.name.upper() for v in fb.variables}
    for block in term_blocks(fb):
        names.update(t.name.upper() for t in block.terms)
    names.update((rb.name or "").upper() for rb in fb.rule_blocks)
    return names | {(fb.name or "").upper()}


def always_name(fb: FunctionBlock) -> str:
    """``ALWAYS``, or ``ALWAYS_2``, ``ALWAYS_3``... when a name of ``fb`` takes it."""
    taken = _names(fb)
    name, n = ALWAYS, 1
    while name.upper() in taken:
        n += 1
        name = f"{ALWAYS}_{n}"
    return name


def has_rules_without_if(fb: FunctionBlock) -> bool:
    return any(rule.condition is None for _rb, rule in fb.rules())


def with_if_parts(fb: FunctionBlock) -> FunctionBlock:
    """``fb`` with every rule without an IF part written ``IF ALWAYS THEN ...`` and the input
    ``ALWAYS : REAL := 1.0`` declared after the last input (``fb`` itself when it has no
    such rule)."""
    if not has_rules_without_if(fb):
        return fb
    name = always_name(fb)
    var = Variable(name, VarKind.INPUT, "REAL", 1.0, comments=(f"(* {COMMENT} *)",))
    last_input = max((i for i, v in enumerate(fb.variables) if v.kind is VarKind.INPUT), default=-1)
    at = last_input + 1 if last_input >= 0 else 0
    variables = (*fb.variables[:at], var, *fb.variables[at:])
    blocks = tuple(
        replace(
            rb,
            rules=tuple(replace(r, condition=Degree(name)) if r.condition is None else r for r in rb.rules),
        )
        for rb in fb.rule_blocks
    )
    return replace(fb, variables=variables, rule_blocks=blocks)


def _mentions(c: Condition) -> Iterator[str]:
    if isinstance(c, Is | Degree):
        yield c.variable
    elif isinstance(c, Not):
        yield from _mentions(c.operand)
    elif isinstance(c, And | Or):
        for o in c.operands:
            yield from _mentions(o)


def _used_elsewhere(fb: FunctionBlock, name: str) -> bool:
    """Whether ``name`` is read anywhere but as the whole condition of a rule."""
    for _rb, rule in fb.rules():
        cond = rule.condition
        whole = isinstance(cond, Degree) and cond.variable == name
        if cond is not None and not whole and name in _mentions(cond):
            return True
        for c in rule.conclusions:
            if c.variable == name or (isinstance(c.weight, Ref) and c.weight.name == name):
                return True
        if isinstance(rule.weight, Ref) and rule.weight.name == name:
            return True
    for block in term_blocks(fb):
        if block.variable == name:
            return True
        for t in block.terms:
            if any(isinstance(p, Ref) and p.name == name for p in mf_params(t.mf)):
                return True
            if isinstance(t.mf, FunctionMF) and name in _expr_names(t.mf.expr):
                return True
    return False


def _expr_names(e: Expr) -> Iterator[str]:
    if isinstance(e, Name):
        yield e.name
    elif isinstance(e, Unary):
        yield from _expr_names(e.operand)
    elif isinstance(e, Binary):
        yield from _expr_names(e.left)
        yield from _expr_names(e.right)
    elif isinstance(e, Call):
        for a in e.args:
            yield from _expr_names(a)


def _is_always(fb: FunctionBlock, v: Variable) -> bool:
    return (
        v.kind is VarKind.INPUT
        and _PATTERN.fullmatch(v.name) is not None
        and v.data_type.upper() == "REAL"
        and isinstance(v.initial, float | int)
        and not isinstance(v.initial, bool)
        and float(v.initial) == 1.0
        and v.range is None
        and not _used_elsewhere(fb, v.name)
    )


def _is_bare(cond: Condition | None, name: str) -> bool:
    return isinstance(cond, Degree) and cond.variable == name


def without_if_parts(doc: Document) -> tuple[Document, list[Diagnostic]]:
    """Read the form :func:`with_if_parts` writes back as rules without an IF part; one note
    per input so read."""
    notes: list[Diagnostic] = []
    blocks = []
    for fb in doc.blocks:
        for v in [v for v in fb.inputs if _is_always(fb, v)]:
            rules: list[Rule] = [r for _rb, r in fb.rules() if _is_bare(r.condition, v.name)]
            if not rules:
                continue
            labels = ", ".join(r.label for r in rules)
            notes.append(
                Diagnostic(
                    Severity.NOTE,
                    f"{v.name} := 1.0, read only as the whole condition of rule(s) {labels}: they are rules "
                    f"without an IF part (degree 1, Siemens 1.5) and {v.name} is no input of the block",
                    v.span,
                    code="no-if-part",
                )
            )
            fb = replace(
                fb,
                variables=tuple(x for x in fb.variables if x is not v),
                rule_blocks=tuple(
                    replace(
                        rb,
                        rules=tuple(
                            replace(r, condition=None) if _is_bare(r.condition, v.name) else r
                            for r in rb.rules
                        ),
                    )
                    for rb in fb.rule_blocks
                ),
            )
        blocks.append(fb)
    return replace(doc, blocks=tuple(blocks)), notes
