"""Rule conditions for the fast reader (fuzzyctl.fcl.fast): an iterative precedence parser.

``condition: or; or: and (OR and)*; and: not (AND not)*; not: NOT not | "(" or ")" | atom``
read with an explicit stack of levels (one per open parenthesis), so that no input can
overflow the Python stack.  It builds the same nodes and spans as the lark transformer:
parentheses vanish (a group is its content, an AND or OR in them marked ``grouped``), a NOT
spans from its keyword to the end of its operand.

It also measures the depth of the condition as :func:`fuzzyctl.limits.depth` does.  As soon
as the condition is known to nest deeper than :data:`~fuzzyctl.limits.MAX_NESTING` (the
open non-empty levels, pending NOTs and built nodes give a lower bound) it stops building
nodes and only counts, keeping equal levels as one level with a repeat count: a million
redundant parentheses, or ``NOT (`` written a million times, take a few list entries.
Runs of ``(``, ``)`` and ``NOT`` separated by white space only are taken with one match.
"""

from __future__ import annotations

import re
from typing import TYPE_CHECKING

from fuzzyctl.limits import MAX_NESTING
from fuzzyctl.model import And, Condition, Degree, Is, Not, Or, Span

if TYPE_CHECKING:
    from fuzzyctl.fcl.fast import RuleReader

COMMENT, NUMBER, WORD, LABEL, PUNCT = 1, 2, 3, 4, 5

# Every keyword terminal of fcl.lark: none of them is taken as a name here.
_KEYWORD_TEXT = """FUNCTION_BLOCK END_FUNCTION_BLOCK VAR_INPUT VAR_OUTPUT VAR END_VAR FUZZIFY END_FUZZIFY
DEFUZZIFY END_DEFUZZIFY RULEBLOCK END_RULEBLOCK OPTIONS END_OPTIONS OPTION END_OPTION TERM
RANGE METHOD DEFAULT NC ACCU ACT AND OR NOT RULE IF THEN IS WITH FUNCTION"""
KEYWORDS = frozenset(_KEYWORD_TEXT.split())

_WS = r"[ \t\f\r\n\ufeff]"
# More of the same token after one was read ('(*' opens a comment: not a parenthesis).
# Possessive: a plain repeated group keeps a backtracking entry per repetition (100 MB
# for a million parentheses).
_OPENS = re.compile(rf"(?:{_WS}*\((?!\*))++")
_CLOSES = re.compile(rf"(?:{_WS}*\))++")
_NOTS = re.compile(rf"(?:{_WS}*NOT(?!\w))++", re.I)
# ``NOT (`` again and again (each a level of its own)
_NOT_OPENS = re.compile(rf"(?:{_WS}*NOT(?!\w){_WS}*\((?!\*))++", re.I)
_NOT = re.compile("NOT", re.I)
# `` IS term`` followed by what ends a subcondition (so no hedge follows).
# An AND or OR after it is taken too (group 2 and 3: the look-ahead token).
_IS_TERM = re.compile(
    r"[ \t]+(?i:IS)[ \t]+([^\W\d]\w*)(?:[ \t]+((?i:AND|OR))(?!\w)|(?=[ \t]*\)|[ \t]+(?i:THEN)(?!\w)))"
)


class Bail(Exception):
    """Not a statement the fast reader takes: lark reads it."""


def join(first: Span | None, last: Span | None) -> Span | None:
    if first is None or last is None:
        return first
    return Span(first.line, first.column, last.end_line, last.end_column)


class _Level:
    """What is read so far inside one pair of parentheses (or at the top): pending NOTs,
    the operands of the current AND chain, the finished operands of the OR chain, and the
    largest depth of each.  ``rep``: how many equal levels this one stands for."""

    __slots__ = ("and_h", "ands", "n_and", "n_nots", "n_or", "nots", "or_h", "ors", "rep")

    def __init__(self) -> None:
        self.nots: list[int] = []
        self.ands: list[Condition] = []
        self.ors: list[Condition] = []
        self.n_nots = self.n_and = self.and_h = self.n_or = self.or_h = 0
        self.rep = 1

    def empty(self) -> bool:
        return not (self.n_nots or self.n_and or self.n_or)

    def shape(self) -> tuple[int, int, int, int, int]:
        return (self.n_nots, self.n_and, self.and_h, self.n_or, self.or_h)

    def counts_only(self) -> _Level:
        copy = _Level()
        copy.n_nots, copy.n_and, copy.and_h, copy.n_or, copy.or_h = self.shape()
        return copy

    def closed(self, h: int, times: int) -> int:
        """The depth of a group of depth ``h`` put into this level and the level closed at
        once, ``times`` times over (the levels of a repeated run are equal)."""
        step = self.n_nots + (self.n_and > 0) + (self.n_or > 0)
        h += self.n_nots
        if self.n_and:
            h = 1 + max(self.and_h, h)
        if self.n_or:
            h = 1 + max(self.or_h, h)
        # from the second time on the group is the deepest operand: each adds ``step``
        return h + (times - 1) * step


class ConditionParser:
    """One condition from the reader's position; see :meth:`parse`."""

    def __init__(self, reader: RuleReader) -> None:
        self.r = reader
        self.build = True  # False once the condition is known to be too deep
        self.frames: list[_Level] = []  # the enclosing levels, innermost last
        self.floor = 1  # 1 + open non-empty levels: the least depth (while building)
        self.end = 0  # where the last token read ends

    def parse(self) -> tuple[Condition | None, int, int]:
        """(the condition, or ``None`` when it nests deeper than MAX_NESTING; its depth;
        where it ends).  Raises Bail for anything else than a condition followed by a word
        or punctuation that cannot continue it."""
        r, text = self.r, self.r.text
        cur = _Level()
        while True:
            k, a, b, u = r.next()
            if k == PUNCT and u == "(":
                m = _OPENS.match(text, b)
                if m is not None:
                    r.seek(m.end())
                cur = self._open(cur, 1 + (m.group().count("(") if m else 0))
                continue
            if k == WORD and u == "NOT":
                self._nots(cur, a, b)
                continue
            node, h = self._atom(k, a, b, u)
            self._operand(cur, node, h)
            while True:  # after an operand: AND, OR, ')' or the end
                k, a, b, u = r.peek()
                if k == WORD and u == "AND":
                    r.next()
                    break
                if k == WORD and u == "OR":
                    r.next()
                    self._end_and(cur)
                    break
                if not (k == PUNCT and u == ")"):
                    if self.frames:
                        raise Bail  # a '(' not closed: lark says so
                    node, h = self._reduce(cur)
                    return (node if self.build else None), h, self.end
                r.next()
                n, self.end = 1, b
                m = _CLOSES.match(text, b)
                if m is not None:
                    r.seek(m.end())
                    n, self.end = 1 + m.group().count(")"), m.end()
                cur = self._close(cur, n)

    # ---------------------------------------------------------------- atoms and NOTs
    def _atom(self, k: int, a: int, b: int, u: str) -> tuple[Condition | None, int]:
        r = self.r
        if k != WORD or u in KEYWORDS:
            raise Bail
        m = _IS_TERM.match(r.text, b)  # the common ``v IS t`` with one match
        if m is not None and m.group(1).upper() not in KEYWORDS:
            r.seek(m.end())
            if m.start(2) >= 0:  # the AND or OR after it, as if peeked
                r.la = (WORD, m.start(2), m.end(2), m.group(2).upper())
            self.end = end = m.end(1)
            if not self.build:
                return None, 1
            return Is(r.text[a:b], m.group(1), False, (), r.span(a, end)), 1
        k2, _, _, w2 = r.peek()
        if not (k2 == WORD and w2 == "IS"):
            if (k2 == WORD and w2 in ("AND", "OR", "THEN")) or (k2 == PUNCT and w2 == ")"):
                self.end = b
                return (Degree(r.text[a:b], r.span(a, b)) if self.build else None), 1
            raise Bail
        r.next()
        k2, _, _, w2 = r.peek()
        negated = k2 == WORD and w2 == "NOT"
        if negated:
            r.next()
        words, end = r.ids()
        self.end = end
        if not self.build:
            return None, 1
        return Is(r.text[a:b], words[-1], negated, tuple(words[:-1]), r.span(a, end)), 1

    def _nots(self, cur: _Level, a: int, b: int) -> None:
        """The NOT at ``a`` and any NOTs right after it (white space between)."""
        r, text = self.r, self.r.text
        m = _NOTS.match(text, b)
        if m is not None:
            r.seek(m.end())
        more = 0 if m is None else m.group().upper().count("NOT")  # white space and NOTs
        cur.n_nots += 1 + more
        if not self.build:
            return
        if self.floor + cur.n_nots > MAX_NESTING:
            self._stop()
            return
        cur.nots.append(a)
        if m is not None:
            cur.nots.extend(x.start() for x in _NOT.finditer(text, m.start(), m.end()))

    def _stop(self) -> None:
        """Too deep: from here on depths only."""
        self.build = False

    # ---------------------------------------------------------------- chains
    def _operand(self, cur: _Level, node: Condition | None, h: int) -> None:
        """``node`` (depth ``h``) under the pending NOTs of ``cur``, added to its AND chain."""
        if cur.n_nots:
            h += cur.n_nots
            if self.build and h > MAX_NESTING:
                self._stop()
            if self.build:
                assert node is not None
                span = self.r.span
                for a in reversed(cur.nots):
                    node = Not(node, join(span(a, a + 3), node.span))
            cur.nots = []
            cur.n_nots = 0
        cur.n_and += 1
        cur.and_h = max(cur.and_h, h)
        if self.build:
            assert node is not None
            cur.ands.append(node)

    def _end_and(self, cur: _Level) -> None:
        """The AND chain of ``cur`` becomes one operand of its OR chain."""
        h = cur.and_h + (cur.n_and > 1)
        if self.build and h > MAX_NESTING:
            self._stop()
        if self.build:
            ands = cur.ands
            node = ands[0] if len(ands) == 1 else And(tuple(ands), join(ands[0].span, ands[-1].span))
            cur.ors.append(node)
        cur.ands = []
        cur.n_and = cur.and_h = 0
        cur.n_or += 1
        cur.or_h = max(cur.or_h, h)

    def _reduce(self, cur: _Level) -> tuple[Condition | None, int]:
        """The condition read in ``cur``, and its depth."""
        self._end_and(cur)
        h = cur.or_h + (cur.n_or > 1)
        if self.build and h > MAX_NESTING:
            self._stop()
        if not self.build:
            return None, h
        ors = cur.ors
        if len(ors) == 1:
            return ors[0], h
        return Or(tuple(ors), join(ors[0].span, ors[-1].span)), h

    # ---------------------------------------------------------------- parentheses
    def _push(self, level: _Level, times: int) -> None:
        frames = self.frames
        top = frames[-1] if frames else None
        if top is not None and (
            (top.empty() and level.empty()) or (not self.build and top.shape() == level.shape())
        ):
            top.rep += times
            return
        if self.build and not level.empty():
            self.floor += 1
            if self.floor > MAX_NESTING:
                self._stop()
        if not self.build and not level.empty():
            level = level.counts_only()  # its nodes are no longer needed
        level.rep = times
        frames.append(level)

    def _open(self, cur: _Level, n: int) -> _Level:
        """``n`` '(' in a row: ``cur`` is kept, then n - 1 empty levels."""
        self._push(cur, 1)
        if n > 1:
            self._push(_Level(), n - 1)
        if not self.build:  # ``NOT (`` again and again: one level, repeated
            r = self.r
            m = _NOT_OPENS.match(r.text, r.pos) if r.la is None else None
            if m is not None:
                r.seek(m.end())
                level = _Level()
                level.n_nots = 1
                self._push(level, m.group().count("("))
        return _Level()

    def _close(self, cur: _Level, n: int) -> _Level:
        """``n`` ')' in a row after the last operand of ``cur``: the level they leave open,
        the group added to it as an operand."""
        frames = self.frames
        node, h = self._group(cur)
        while True:
            if not frames:
                raise Bail  # more ')' than '(' (lark says so)
            top = frames[-1]
            if top.empty():  # closing an empty level leaves the group as it is
                take = min(n, top.rep)
                top.rep -= take
                n -= take
                if top.rep == 0:
                    frames.pop()
                if n == 0:
                    level = _Level()
                    self._operand(level, node, h)
                    return level
                continue
            if not self.build and n > 1:  # equal levels closed at once
                take = min(n - 1, top.rep)
                h = top.closed(h, take)
                top.rep -= take
                n -= take
                if top.rep == 0:
                    frames.pop()
                continue
            if top.rep > 1:
                top.rep -= 1
                level = top.counts_only()
            else:
                level = frames.pop()
                if self.build:
                    self.floor -= 1
            n -= 1
            self._operand(level, node, h)
            if n == 0:
                return level
            node, h = self._group(level)

    def _group(self, cur: _Level) -> tuple[Condition | None, int]:
        node, h = self._reduce(cur)
        if isinstance(node, And | Or) and not node.grouped:
            node = type(node)(node.operands, node.span, True)  # for jFuzzyLogic's reading
        return node, h
