"""Attach source comments to the model element they describe.

A comment at the end of a line belongs to the innermost element that starts on that line
(``TERM cold := ...; // below 10 degC``); a comment on lines of its own belongs to the next
element; what is left (a file header after the last block) goes to the document.  Comments
never take part in equality; the writer prints them again so ``fmt`` keeps them."""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import replace
from typing import Any, Protocol

from fuzzyctl.fcl.checks import term_blocks
from fuzzyctl.model import Document, FunctionBlock, RuleBlock, Span


class CommentLike(Protocol):
    text: str
    line: int
    column: int


def _elements(doc: Document) -> list[tuple[int, int, int, int]]:
    """(line, column, depth, id) of every element that can hold comments, in source order."""
    out: list[tuple[int, int, int, int]] = []

    def add(obj: Any, depth: int) -> None:
        span: Span | None = getattr(obj, "span", None)
        if span is not None:
            out.append((span.line, span.column, depth, id(obj)))

    for fb in doc.blocks:
        add(fb, 0)
        for v in fb.variables:
            add(v, 1)
        for block in term_blocks(fb):
            add(block, 1)
            for t in block.terms:
                add(t, 2)
        for rb in fb.rule_blocks:
            add(rb, 1)
            for r in rb.rules:
                add(r, 2)
    out.sort()
    return out


def attach_comments(doc: Document, comments: Sequence[CommentLike]) -> Document:
    """A copy of ``doc`` with each comment text stored on its element."""
    if not comments:
        return doc
    elements = _elements(doc)
    owned: dict[int, list[str]] = {}
    loose: list[str] = []
    for c in comments:
        same_line = [e for e in elements if e[0] == c.line and e[1] < c.column]
        if same_line:
            owner = max(same_line, key=lambda e: e[2])[3]
        else:
            after = [e for e in elements if (e[0], e[1]) > (c.line, c.column)]
            if not after:
                loose.append(c.text)
                continue
            first_line = after[0][0]
            owner = max((e for e in after if e[0] == first_line), key=lambda e: e[2])[3]
        owned.setdefault(owner, []).append(c.text)

    def with_comments(obj: Any) -> Any:
        texts = owned.get(id(obj))
        return replace(obj, comments=tuple(texts)) if texts else obj

    def rebuild_rb(rb: RuleBlock) -> RuleBlock:
        new: RuleBlock = with_comments(replace(rb, rules=tuple(with_comments(r) for r in rb.rules)))
        return new

    def rebuild(fb: FunctionBlock) -> FunctionBlock:
        new = replace(
            fb,
            variables=tuple(with_comments(v) for v in fb.variables),
            fuzzify=tuple(
                with_comments(replace(b, terms=tuple(with_comments(t) for t in b.terms))) for b in fb.fuzzify
            ),
            defuzzify=tuple(
                with_comments(replace(b, terms=tuple(with_comments(t) for t in b.terms)))
                for b in fb.defuzzify
            ),
            rule_blocks=tuple(rebuild_rb(rb) for rb in fb.rule_blocks),
        )
        texts = owned.get(id(fb))
        return replace(new, comments=tuple(texts)) if texts else new

    blocks = tuple(rebuild(fb) for fb in doc.blocks)
    return replace(doc, blocks=blocks, comments=tuple(loose))
