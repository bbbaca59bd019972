"""Attach source comments to the place they were written, so that ``fmt`` keeps them there.

Every comment gets an owner (an element of the model) and a place relative to it (see
:data:`fuzzyctl.model.PlacedComments`):

* inside a statement, or after it on the line it ends on: ``"after"`` that statement
  (``TERM cold := ...; // below 10 degC``); after a block's END_ keyword on its line:
  the block's ``"tail"``; on a block's header line: its ``"head"``;
* on lines of its own: ``"before"`` the next statement or block of the same block
  (its ``comments``), else at the ``"end"`` of the block (before its END_ keyword);
* a single-valued item (RANGE, METHOD, DEFAULT, ACCU, AND, OR, ACT) is a statement of
  its block: ``"method.before"``, ``"method.after"``, ...;
* the VAR_... sections are not in the model (the writer groups the declarations by kind),
  so a comment next to a section keyword says so: ``"section.before"`` (before VAR_INPUT),
  ``"section.head"`` (after it on its line), ``"section.end"`` (before END_VAR),
  ``"section.tail"`` (after END_VAR on its line) of the first or last variable;
* after the last function block: the document's ``comments``.

Both readers (lark and :mod:`fuzzyctl.fcl.fast`) give the same spans and the same comment
list, so they attach the same way.  Comments never take part in equality."""

from __future__ import annotations

import re
from bisect import bisect_right
from collections.abc import Sequence
from dataclasses import dataclass, field, replace
from typing import Any, Protocol

from fuzzyctl.model import Document, FunctionBlock, RuleBlock, Span

Pos = tuple[int, int]  # (line, column), 1-based

_VAR_KEYWORD = re.compile(r"\bVAR(?:_INPUT|_OUTPUT)?\b", re.I)
_END_VAR = re.compile(r"\bEND_VAR\b", re.I)


class CommentLike(Protocol):
    text: str
    line: int
    column: int


@dataclass
class _Node:
    """A statement or block of the source: where it is, which object holds its comments,
    and the prefix of its places (``"method."`` for an item held by its block)."""

    start: Pos
    end: Pos
    owner: int
    prefix: str = ""
    kind: str = "statement"  # statement | variable | block
    children: list[_Node] = field(default_factory=list)
    starts: list[Pos] = field(default_factory=list)  # of the children, for bisection

    def adopt(self, found: Sequence[_Node | None]) -> None:
        self.children = sorted((n for n in found if n is not None), key=lambda n: n.start)
        self.starts = [n.start for n in self.children]


def _node(obj: Any, span: Span | None, prefix: str = "", kind: str = "statement") -> _Node | None:
    if span is None:
        return None
    start = (span.line, span.column)
    end = start if span.end_line is None or span.end_column is None else (span.end_line, span.end_column)
    return _Node(start, end, id(obj), prefix, kind)


def _block(obj: Any, items: Sequence[tuple[str, Span | None]], statements: Sequence[Any]) -> _Node | None:
    node = _node(obj, obj.span, kind="block")
    if node is None:
        return None
    found = [_node(obj, span, prefix=f"{key}.") for key, span in items]
    found.extend(_node(s, s.span) for s in statements)
    node.adopt(found)
    return node


def _tree(doc: Document) -> list[_Node]:
    """The function blocks of ``doc`` with their statements and blocks, in source order."""
    out: list[_Node] = []
    for fb in doc.blocks:
        node = _node(fb, fb.span, kind="block")
        if node is None:
            continue
        found: list[_Node | None] = [_node(v, v.span, kind="variable") for v in fb.variables]
        for f in fb.fuzzify:
            found.append(_block(f, [("range", f.range.span if f.range else None)], f.terms))
        for d in fb.defuzzify:
            items = [(k, s) for k, s in d.item_spans if k != "range"]
            found.append(_block(d, [("range", d.range.span if d.range else None), *items], d.terms))
        for rb in fb.rule_blocks:
            found.append(_block(rb, list(rb.item_spans), rb.rules))
        found.extend(_node(o, o.span) for o in fb.options)
        node.adopt(found)
        out.append(node)
    return out


class _Text:
    """Where the VAR_... and END_VAR keywords of the source are (outside comments): the
    sections are not in the model.  Looked up by bisection, so that placing a comment costs
    no more when there are many."""

    def __init__(self, text: str | None, comments: Sequence[CommentLike]) -> None:
        self.text = text or ""
        self.lines = [0, *(m.end() for m in re.finditer("\n", self.text))]
        parts, last = [], 0
        for c in comments:  # blanked, so that a keyword inside a comment is not found
            a = self.offset((c.line, c.column))
            if a < last:
                continue
            parts.extend([self.text[last:a], re.sub(r"[^\n]", " ", c.text)])
            last = a + len(c.text)
        blank = "".join([*parts, self.text[last:]])
        self.found = {
            name: [(m.start(), m.end()) for m in pattern.finditer(blank)]
            for name, pattern in (("var", _VAR_KEYWORD), ("end_var", _END_VAR))
        }
        self.found_starts = {name: [a for a, _ in found] for name, found in self.found.items()}

    def offset(self, pos: Pos) -> int:
        line = min(max(pos[0], 1), len(self.lines))
        return self.lines[line - 1] + pos[1] - 1

    def last(self, keyword: str, a: Pos, b: Pos) -> int | None:
        """The end offset of the last ``keyword`` (``"var"``, ``"end_var"``) between
        positions ``a`` and ``b``, else ``None``."""
        lo, hi = self.offset(a), self.offset(b)
        i = bisect_right(self.found_starts[keyword], hi - 1) - 1
        if i < 0 or self.found[keyword][i][0] < lo or self.found[keyword][i][1] > hi:
            return None
        return self.found[keyword][i][1]

    def on_line(self, offset: int | None, b: Pos) -> bool:
        """Whether a keyword ending at ``offset`` is on the line of position ``b``."""
        return offset is not None and self.text.find("\n", offset, self.offset(b)) < 0


def _end_of(c: CommentLike) -> Pos:
    lines = c.text.split("\n")
    if len(lines) == 1:
        return (c.line, c.column + len(c.text))
    return (c.line + len(lines) - 1, len(lines[-1]) + 1)


def _after(node: _Node) -> tuple[int, str]:
    return node.owner, node.prefix + ("tail" if node.kind == "block" else "after")


def _before(node: _Node) -> tuple[int, str]:
    return node.owner, node.prefix + "before"


class _Placer:
    def __init__(self, text: _Text) -> None:
        self.text = text

    def place(self, node: _Node, c: CommentLike) -> tuple[int, str]:
        """The owner and place of comment ``c`` inside block ``node``."""
        p = (c.line, c.column)
        children = node.children
        i = bisect_right(node.starts, p)
        prev = nxt = None
        if i > 0:
            ch = children[i - 1]
            if p < ch.end:  # inside it
                return self.place(ch, c) if ch.kind == "block" else _after(ch)
            prev = ch
        if i < len(children):
            nxt = children[i]
        on_header = prev is None and p[0] == node.start[0]
        if on_header and self.text.last("var", node.start, p) is None:
            return node.owner, "head"
        if (prev is not None and prev.kind == "variable") or (nxt is not None and nxt.kind == "variable"):
            found = self.section(node, prev, nxt, c)
            if found is not None:
                return found
        if prev is not None and prev.end[0] == p[0]:
            return _after(prev)
        if on_header:
            return node.owner, "head"
        if nxt is not None:
            return _before(nxt)
        return node.owner, "end"

    def section(
        self, node: _Node, prev: _Node | None, nxt: _Node | None, c: CommentLike
    ) -> tuple[int, str] | None:
        """The place of a comment next to a VAR_... section keyword, else ``None``."""
        p, q = (c.line, c.column), _end_of(c)
        text = self.text
        if prev is not None and prev.kind == "variable":
            closed = text.last("end_var", prev.end, p)
            if text.on_line(closed, p):  # on the END_VAR line
                return prev.owner, "section.tail"
            if closed is None:
                if prev.end[0] == p[0]:
                    return prev.owner, "after"
                opens = nxt is not None and text.last("var", q, nxt.start) is not None
                if nxt is None or nxt.kind != "variable" or opens:
                    return prev.owner, "section.end"
        if nxt is not None and nxt.kind == "variable":
            if text.last("var", q, nxt.start) is not None:
                return nxt.owner, "section.before"
            if text.on_line(text.last("var", prev.end if prev is not None else node.start, p), p):
                return nxt.owner, "section.head"
        return None


def attach_comments(doc: Document, comments: Sequence[CommentLike], text: str | None = None) -> Document:
    """A copy of ``doc`` with each comment stored at its place (module docstring).
    ``text``: the source, to place comments next to VAR_... keywords (without it they go
    with the declaration before or after them)."""
    if not comments:
        return doc
    placer = _Placer(_Text(text, comments))
    tree = _tree(doc)
    starts = [fb.start for fb in tree]
    owned: dict[int, list[tuple[str, str]]] = {}
    loose: list[str] = []
    last: tuple[int, int, str] | None = None  # end line, owner and place of the last comment
    for c in comments:
        p = (c.line, c.column)
        i = bisect_right(starts, p)
        if i > 0 and p < tree[i - 1].end:
            owner, where = placer.place(tree[i - 1], c)
        elif i > 0 and tree[i - 1].end[0] == p[0]:
            owner, where = tree[i - 1].owner, "tail"
        elif i < len(tree):
            owner, where = tree[i].owner, "before"
        else:
            owner, where = 0, "loose"
        if last is not None and last[0] == c.line and _trailing(last[2]) and not _trailing(where):
            # on the line where a multi-line comment after a statement ends: with it
            owner, where = last[1], last[2]
        last = (_end_of(c)[0], owner, where)
        if where == "loose":
            loose.append(c.text)
        else:
            owned.setdefault(owner, []).append((where, c.text))
    return _rebuild(doc, owned, loose)


def _trailing(place: str) -> bool:
    """Whether ``place`` is on the line of a statement or keyword (not on lines of its own)."""
    return place.endswith(("after", "head", "tail"))


def _rebuild(doc: Document, owned: dict[int, list[tuple[str, str]]], loose: list[str]) -> Document:
    def put(obj: Any, new: Any = None) -> Any:
        """``new`` (a copy of ``obj`` with new parts, or ``obj``) with the comments of ``obj``."""
        new = obj if new is None else new
        got = owned.get(id(obj))
        if not got:
            return new
        keeps_before = hasattr(new, "comments")  # OPTIONS blocks keep them with the others
        before = tuple(t for where, t in got if where == "before" and keeps_before)
        placed = tuple((where, t) for where, t in got if where != "before" or not keeps_before)
        changes: dict[str, Any] = {"placed_comments": (*new.placed_comments, *placed)}
        if before:
            changes["comments"] = (*new.comments, *before)
        return replace(new, **changes)

    def rule_block(rb: RuleBlock) -> RuleBlock:
        new: RuleBlock = put(rb, replace(rb, rules=tuple(put(r) for r in rb.rules)))
        return new

    def block(fb: FunctionBlock) -> FunctionBlock:
        new = replace(
            fb,
            variables=tuple(put(v) for v in fb.variables),
            fuzzify=tuple(put(b, replace(b, terms=tuple(put(t) for t in b.terms))) for b in fb.fuzzify),
            defuzzify=tuple(put(b, replace(b, terms=tuple(put(t) for t in b.terms))) for b in fb.defuzzify),
            rule_blocks=tuple(rule_block(rb) for rb in fb.rule_blocks),
            options=tuple(put(o) for o in fb.options),
        )
        result: FunctionBlock = put(fb, new)
        return result

    return replace(doc, blocks=tuple(block(fb) for fb in doc.blocks), comments=(*doc.comments, *loose))
