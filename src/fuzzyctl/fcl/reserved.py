"""Names that IEC 61131-7 reserves (Table 7, 5.4.2) used as identifiers.

The parser is lenient: ``MIN``, ``NC``, ``CoG`` or ``BSUM`` stand wherever a name may, since
the grammar knows from context what is meant.  A strict IEC 61131-7 tool reserves them, so
such a file would not load there: :func:`check_reserved_words` warns (an error under
``strict``), naming the keyword and the line, so that a file that passes ``check --strict``
also loads in a strict tool.
"""

from __future__ import annotations

from collections.abc import Iterator

from fuzzyctl.diagnostics import Diagnostic, error, warning
from fuzzyctl.model import DefuzzifyBlock, Document, FuzzifyBlock, Span

__all__ = ["TABLE7", "check_reserved_words", "reserved_names"]

#: IEC 61131-7 Table 7 "Reserved keywords for FCL" (the parentheses left out), upper case
#: (FCL keywords are case-insensitive); the standard's spelling where it is mixed case.
TABLE7: dict[str, str] = {
    w.upper(): w
    for w in (
        "ACCU", "ACT", "AND", "ASUM", "BDIF", "BSUM", "CoA", "CoG", "CoGS", "DEFAULT",
        "DEFUZZIFY", "END_DEFUZZIFY", "END_FUNCTION_BLOCK", "END_FUZZIFY", "END_OPTIONS",
        "END_RULEBLOCK", "END_VAR", "FUNCTION_BLOCK", "FUZZIFY", "IF", "IS", "LM", "MAX",
        "METHOD", "MIN", "NC", "NOT", "NSUM", "OPTIONS", "OR", "PROD", "RANGE", "RM", "RULE",
        "RULEBLOCK", "TERM", "THEN", "VAR", "VAR_INPUT", "VAR_OUTPUT", "WITH",
    )
}  # fmt: skip


def reserved_names(doc: Document) -> Iterator[tuple[str, str, str, Span | None]]:
    """``(what, name, keyword, span)`` for every identifier of ``doc`` that is a Table 7
    keyword: function blocks, variables, terms, rule blocks and rule labels (``what`` reads
    ``"term MIN of temp"``)."""

    for what, name, span in _identifiers(doc):
        if name and (kw := TABLE7.get(name.upper())):
            yield what, name, kw, span


def _identifiers(doc: Document) -> Iterator[tuple[str, str | None, Span | None]]:
    """``(what, name, span)`` for every identifier of ``doc`` (``name`` ``None``: not given)."""
    for fb in doc.blocks:
        yield f"function block {fb.name}", fb.name, fb.span
        for v in fb.variables:
            yield f"variable {v.name}", v.name, v.span
        blocks: list[FuzzifyBlock | DefuzzifyBlock] = [*fb.fuzzify, *fb.defuzzify]
        for block in blocks:
            for t in block.terms:
                yield f"term {t.name} of {block.variable}", t.name, t.span
        for rb in fb.rule_blocks:
            yield f"rule block {rb.name}", rb.name, rb.span
            for rule in rb.rules:
                yield f"rule label {rule.label}", rule.label, rule.span


def check_reserved_words(doc: Document, file: str | None = None, strict: bool = False) -> list[Diagnostic]:
    """A warning (``strict``: an error) per identifier that is a Table 7 keyword."""
    out = []
    for what, _name, kw, span in reserved_names(doc):
        where = f" (line {span.line})" if span is not None else ""
        message = (
            f"{what}{where}: {kw} is a keyword IEC 61131-7 reserves (Table 7); "
            "a strict IEC 61131-7 tool will not read it as a name"
        )
        make = error if strict else warning
        out.append(make(message, span, code="reserved-word", file=file, hint="rename it"))
    return out
