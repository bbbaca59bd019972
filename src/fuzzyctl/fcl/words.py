"""Every word the FCL writer copies from the model, checked before it is written.

A model read from JSON (or sent by the studio) carries its operators, methods, hedges, data
types, references and rule words as free strings: ``AND : MIN; END_RULEBLOCK
END_FUNCTION_BLOCK FUNCTION_BLOCK evil ...`` written as it is would add a block to the
file.  Names of declarations are checked by :func:`fuzzyctl.fcl.writer.unwritable_names`;
this module checks the rest, and the writer refuses the model (all such words listed) rather
than write a file that says something else than the model (comments and OPTIONS text are
made inert by :mod:`fuzzyctl.escape` instead: they are text, not words)."""

from __future__ import annotations

import re
from collections.abc import Iterator

from fuzzyctl import model as m
from fuzzyctl.diagnostics import Diagnostic, error
from fuzzyctl.fcl.identifiers import fcl_term

__all__ = ["unwritable_words"]

_WORD = re.compile(r"[^\W\d]\w*")  # fcl.lark's ID (keywords such as MIN are words here)
_OPERATORS = frozenset("+-*/%^")  # fcl/writer.py's _PRECEDENCE


def _params(mf: m.MembershipFunction) -> Iterator[m.Param]:
    if isinstance(mf, m.PointsMF | m.SingletonsMF):
        for p in mf.points:
            yield p.x
            yield p.y
    elif isinstance(mf, m.SingletonMF):
        yield mf.value
    elif isinstance(mf, m.ShapeMF):
        yield from mf.params


def _expr_words(e: m.Expr) -> Iterator[tuple[str, str, str]]:
    """(what, text, kind) of every word of an expression (kind: ``name``, ``word`` or ``bad``,
    an operator that is not one of FCL's)."""
    if isinstance(e, m.Name):
        yield "variable", e.name, "name"
    elif isinstance(e, m.Call):
        yield "function", e.function, "word"
        for a in e.args:
            yield from _expr_words(a)
    elif isinstance(e, m.Unary):
        if e.op not in ("+", "-"):
            yield "operator", e.op, "bad"
        yield from _expr_words(e.operand)
    elif isinstance(e, m.Binary):
        if e.op not in _OPERATORS:
            yield "operator", e.op, "bad"
        yield from _expr_words(e.left)
        yield from _expr_words(e.right)


def _condition_words(c: m.Condition | None) -> Iterator[tuple[str, str, str]]:
    if isinstance(c, m.Is):
        yield "variable", c.variable, "name"
        yield "term", c.term, "name"
        yield from (("hedge", h, "word") for h in c.hedges)
    elif isinstance(c, m.Degree):
        yield "variable", c.variable, "name"
    elif isinstance(c, m.Not):
        yield from _condition_words(c.operand)
    elif isinstance(c, m.And | m.Or):
        for operand in c.operands:
            yield from _condition_words(operand)


def _block_words(fb: m.FunctionBlock) -> Iterator[tuple[str, str, str, m.Span | None]]:
    for v in fb.variables:
        yield "data type", v.data_type, "word", v.span
        if isinstance(v.initial, str):
            yield "initial value", v.initial, "word", v.span
    blocks: list[m.FuzzifyBlock | m.DefuzzifyBlock] = [*fb.fuzzify, *fb.defuzzify]
    for blk in blocks:
        yield "variable", blk.variable, "name", blk.span
        for t in blk.terms:
            for p in _params(t.mf):
                if isinstance(p, m.Ref):
                    yield "variable", p.name, "name", t.span
            if isinstance(t.mf, m.FunctionMF):
                yield from ((*w, t.span) for w in _expr_words(t.mf.expr))
    for d in fb.defuzzify:
        for what, value in (("METHOD", d.method), ("ACCU", d.accu)):
            if value is not None:
                yield what, value, "word", d.span
    for rb in fb.rule_blocks:
        for what, value in (("AND", rb.and_op), ("OR", rb.or_op), ("ACT", rb.act), ("ACCU", rb.accu)):
            if value is not None:
                yield what, value, "word", rb.span
        for r in rb.rules:
            yield from ((*w, r.span) for w in _condition_words(r.condition))
            for c in r.conclusions:
                yield "variable", c.variable, "name", c.span
                if c.term is not None:
                    yield "term", c.term, "name", c.span
                yield from (("hedge", h, "word", c.span) for h in c.hedges)
                if isinstance(c.weight, m.Ref):
                    yield "variable", c.weight.name, "name", c.span
    for o in fb.options:
        if o.keyword.upper() not in ("OPTIONS", "OPTION"):
            yield "options keyword", o.keyword, "bad", o.span


def unwritable_words(fb: m.FunctionBlock) -> list[Diagnostic]:
    """Operators, methods, hedges, data types, initial values, functions and the names rules
    and terms refer to that FCL would not read back as the same one word."""
    found: list[Diagnostic] = []
    seen: set[tuple[str, str]] = set()  # rules repeat their names: each checked (and told) once
    for what, text, kind, span in _block_words(fb):
        if (kind, text) in seen:
            continue
        seen.add((kind, text))
        ok = fcl_term(text) if kind == "name" else kind == "word" and _WORD.fullmatch(text) is not None
        if not ok:
            found.append(
                error(
                    f"{what} {text[:60]!r} cannot be written in FCL: it is not a word FCL reads back",
                    span,
                    code="fcl-write-word",
                )
            )
    return found
