"""Attach source comments to the model element they describe.

A comment at the end of a line belongs to the innermost element that starts on that line
(``TERM cold := ...; // below 10 degC``); a comment on lines of its own belongs to the next
element; what is left (a file header after the last block) goes to the document.  Comments
never take part in equality; the writer prints them again so ``fmt`` keeps them."""

from __future__ import annotations

from bisect import bisect_right
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


class _Owners:
    """Which element a comment at (line, column) belongs to: the deepest element starting
    earlier on that line, else the deepest one on the first line with an element after it
    (the first in source order among equally deep ones).  Looked up by bisection, so that a
    file with a comment on every line takes linear time."""

    def __init__(self, elements: list[tuple[int, int, int, int]]) -> None:
        self.keys = [(e[0], e[1]) for e in elements]
        self.lines = [e[0] for e in elements]
        # (line, depth) -> the columns and ids of those elements, in source order
        self.at: dict[tuple[int, int], tuple[list[int], list[int]]] = {}
        for line, column, depth, ident in elements:
            cols, ids = self.at.setdefault((line, depth), ([], []))
            cols.append(column)
            ids.append(ident)

    def of(self, line: int, column: int) -> int | None:
        for depth in (2, 1, 0):  # earlier on the same line
            found = self.at.get((line, depth))
            if found is not None and found[0][0] < column:
                return found[1][0]
        start = bisect_right(self.keys, (line, column))
        if start == len(self.keys):
            return None
        first_line = self.lines[start]
        for depth in (2, 1, 0):
            found = self.at.get((first_line, depth))
            if found is None:
                continue
            i = bisect_right(found[0], column) if first_line == line else 0
            if i < len(found[0]):
                return found[1][i]
        return None  # pragma: no cover - the element at ``start`` is one of them


def attach_comments(doc: Document, comments: Sequence[CommentLike]) -> Document:
    """A copy of ``doc`` with each comment text stored on its element."""
    if not comments:
        return doc
    owners = _Owners(_elements(doc))
    owned: dict[int, list[str]] = {}
    loose: list[str] = []
    for c in comments:
        owner = owners.of(c.line, c.column)
        if owner is None:
            loose.append(c.text)
        else:
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
