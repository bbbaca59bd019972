"""The bulk of a large FCL file read without lark: runs of RULE and TERM statements.

A file with thousands of rules (or terms) is almost entirely a run of statements of one
kind, each of which the grammar reads the same way whatever came before.  This module finds
such runs (outside comments and OPTIONS text, which it skips as the lark lexer does), reads
each statement with a small hand-written scanner (conditions with the iterative parser of
fuzzyctl.fcl.fast_conditions) into the same model objects and spans the lark transformer
builds, and tells the caller which text to blank out (spaces in place of every character
but ``\\n``, so that lines and columns of what lark still reads are unchanged).  Runs do not
depend on line ends: a file written on one line is read the same way.

The fast reader only accepts the forms that produce no diagnostic; anything else (a
multi-word name, a keyword used as a name, a missing ';' after a TERM, an unknown shape,
FUNCTION terms, a number out of range, ...) ends the run, and lark reads it.  The first and
the last statement of a run are always left to lark, so that lark enters and leaves the
blanked text in the state it would have been in, and every syntax error (with its "previous
token") is found by lark exactly as before.  Of the rules and terms lark reads, a long
condition followed by THEN (or one nesting deeper than limits.MAX_NESTING) and a long point
list followed by ';' are still read here: lark reads a one-character placeholder in their
place and the transformer puts back what was read here (FastResult.conditions, .points), so
that a single rule of a million parentheses costs lark nothing.  ``fcl.lark`` stays the
grammar of record; tests/fcl/test_fast.py checks that both paths give the same model and
diagnostics on every FCL file we have, on generated blocks and on deep and long conditions.
"""

from __future__ import annotations

import math
import re
from bisect import bisect_left, bisect_right
from dataclasses import dataclass, field
from typing import Any

from fuzzyctl.fcl import shapes
from fuzzyctl.fcl.fast_conditions import (
    COMMENT,
    KEYWORDS,
    LABEL,
    NUMBER,
    PUNCT,
    WORD,
    Bail,
    ConditionParser,
)
from fuzzyctl.fcl.fast_conditions import join as _join
from fuzzyctl.limits import depth as nesting
from fuzzyctl.model import (
    And,
    Conclusion,
    Condition,
    Is,
    MembershipFunction,
    Or,
    Param,
    Point,
    PointsMF,
    Ref,
    Rule,
    SingletonMF,
    Span,
    Term,
    Variable,
)

# lark's NUMBER (fcl.lark), its COMMENT_* terminals and its WS.
NUMBER_RE = (
    r"[-+\u2212\u2013]?(?:(?:\d+(?:\.(?!\.)\d*)?|\.\d+)(?:[eE][-+]?\d+)?|(?i:nan|inf(?:inity)?)(?!\w))"
)
COMMENT_RE = r"\(\*.*?\*\)|/\*.*?\*/|//[^\r\n]*"
_WS = r"[ \t\f\r\n\ufeff]*"
# One token with the white space before it: 1 comment, 2 number, 3 word, 4 other \w run,
# 5 punctuation.
_TOKEN = re.compile(rf"{_WS}(?:({COMMENT_RE})|({NUMBER_RE})|([^\W\d]\w*)|(\w+)|(:=|[:;,()]))", re.S)
_LABEL = re.compile(r"\w+")
# Where runs may start: comments and OPTIONS text are skipped as lark skips them.
_SCAN = re.compile(rf"({COMMENT_RE})|\b(RULE|TERM|OPTIONS|OPTION)\b", re.S | re.I)
_OPTIONS_END = re.compile(r"(?s:.+?)(?=\bEND_OPTIONS?\b)", re.I)
# The most common rule, on one line with spaces only: read with one match (possessive
# repeats: no backtracking entry kept per AND of a long chain).
_NAME = r"[^\W\d]\w*"
_ATOM = rf"{_NAME}[ \t]+IS[ \t]+{_NAME}"
_SIMPLE_RULE = re.compile(
    rf"RULE[ \t]+(\w+)[ \t]*:[ \t]*IF[ \t]+({_ATOM}(?:[ \t]+(?:AND|OR)[ \t]+{_ATOM})*+)"
    rf"[ \t]+THEN[ \t]+({_ATOM}(?:[ \t]*,[ \t]*{_ATOM})*+)[ \t]*;",
    re.I,
)
# The rest of a point ``(x, y)`` after its '(' when both are numbers.
_POINT_REST = re.compile(rf"[ \t]*({NUMBER_RE})[ \t]*,[ \t]*({NUMBER_RE})[ \t]*\)")
# The most common TERM, on one line with spaces only: points (short of SUBSTITUTE_MIN) or
# one number, read with one match.
_SIMPLE_TERM = re.compile(
    rf"TERM[ \t]+({_NAME})[ \t]*:=[ \t]*((?:\([ \t]*{NUMBER_RE}[ \t]*,[ \t]*{NUMBER_RE}[ \t]*\)[ \t]*)++"
    rf"|{NUMBER_RE})[ \t]*;",
    re.I,
)
_POINT = re.compile(rf"\([ \t]*({NUMBER_RE})[ \t]*,[ \t]*({NUMBER_RE})[ \t]*\)")
_PART = re.compile(rf"({_NAME})[ \t]+IS[ \t]+({_NAME})|(AND|OR)", re.I)
_WORD_CHAR = re.compile(r"\w")
_MINUS_SIGNS = str.maketrans({"\u2212": "-", "\u2013": "-"})

#: Conditions at least this long (in characters) of the rules that lark reads (the first
#: and last of a run, a rule alone) are read here all the same, and lark reads a one-letter
#: name in their place (see FastResult.conditions); so are conditions nesting too deep.
SUBSTITUTE_MIN = 200
#: Shortest run worth taking from lark (its first and last statements stay with lark).
MIN_RUN = 3
#: Statements in a row not taken after which only the one-match forms are tried.
MAX_MISSES = 1000


@dataclass
class FastComment:
    text: str
    offset: int
    line: int
    column: int
    end_line: int


@dataclass
class FastResult:
    """Statements read here (by source offset) and the text lark reads instead."""

    text: str
    offsets: list[int] = field(default_factory=list)
    items: list[Rule | Term] = field(default_factory=list)
    spellings: list[str | None] = field(default_factory=list)
    comments: list[FastComment] = field(default_factory=list)
    #: Conditions of rules that lark reads, read here instead: lark reads the name ``_`` at
    #: (line, column) in their place.  Each with its depth (``None``: deeper than
    #: limits.MAX_NESTING, which the rule reports).
    conditions: dict[tuple[int, int], tuple[Condition | None, int]] = field(default_factory=dict)
    #: Long point lists of the TERMs that lark reads, read here instead: lark reads ``0`` in
    #: their place.  By the (line, column) of the TERM keyword.
    points: dict[tuple[int, int], PointsMF] = field(default_factory=dict)
    #: Whole blocks read by fuzzyctl.fcl.fast_blocks (FuzzifyBlock, DefuzzifyBlock,
    #: RuleBlock, or the variables of a VAR block), by offset; the shape spellings of
    #: their terms; the variables of the declarations it took inside VAR blocks.
    blocks: list[tuple[int, Any]] = field(default_factory=list)
    block_spellings: list[tuple[int, str]] = field(default_factory=list)
    decls: list[tuple[int, list[Variable]]] = field(default_factory=list)

    def between(self, start: int, end: int) -> list[tuple[int, Rule | Term, str | None]]:
        """The statements read here whose offset lies in ``[start, end)``."""
        lo, hi = bisect_left(self.offsets, start), bisect_left(self.offsets, end)
        return list(zip(self.offsets[lo:hi], self.items[lo:hi], self.spellings[lo:hi], strict=True))

    def blocks_between(self, start: int, end: int) -> list[Any]:
        """The blocks read here whose offset lies in ``[start, end)``."""
        lo = bisect_left(self.blocks, start, key=_offset)
        hi = bisect_left(self.blocks, end, key=_offset)
        return [b for _, b in self.blocks[lo:hi]]

    def decls_between(self, start: int, end: int) -> list[Variable]:
        """The variables of the declarations read here whose offset lies in ``[start, end)``."""
        lo = bisect_left(self.decls, start, key=_offset)
        hi = bisect_left(self.decls, end, key=_offset)
        return [v for _, vs in self.decls[lo:hi] for v in vs]

    _at: tuple[int, int, int] = (0, 1, 0)  # an offset, its line, where that line starts

    def add_comment(self, body: str, offset: int) -> None:
        """Record a comment (in source order)."""
        pos, line, ls = self._at
        text = self.text
        line += text.count("\n", pos, offset)
        nl = text.rfind("\n", pos, offset)
        if nl >= 0:
            ls = nl + 1
        self._at = (offset, line, ls)
        self.comments.append(FastComment(body, offset, line, offset - ls + 1, line + body.count("\n")))

    def condition_at(self, span: Span | None) -> tuple[Condition | None, int] | None:
        """The condition read here whose placeholder lark read at ``span``."""
        return self.conditions.get((span.line, span.column)) if span is not None else None

    def points_at(self, span: Span | None) -> PointsMF | None:
        """The points read here of the TERM whose keyword lark read at ``span``."""
        return self.points.get((span.line, span.column)) if span is not None else None

    def spellings_before(self, end: int | None) -> set[str]:
        n = len(self.offsets) if end is None else bisect_left(self.offsets, end)
        found = {s for s in self.spellings[:n] if s is not None}
        found.update(s for at, s in self.block_spellings if end is None or at < end)
        return found

    def comments_before(self, end: int | None) -> list[FastComment]:
        if end is None:
            return list(self.comments)
        return self.comments[: bisect_right([c.offset for c in self.comments], end - 1)]


def _offset(entry: tuple[int, Any]) -> int:
    return entry[0]


_Part = tuple[int, int, "Condition | PointsMF | None", int]


class Reader:
    """Scanner and parser over ``text`` (positions are string offsets)."""

    quick_only = False  # after many statements not taken: only the one-match forms

    def __init__(self, text: str) -> None:
        self.text = text
        self.pos = 0
        self.comments: list[tuple[str, int]] = []
        # line of the current statement's start and where that line starts
        self.base = 0
        self.base_line = 1
        self.base_ls = 0
        self.next_nl = text.find("\n")
        self.la: tuple[int, int, int, str] | None = None
        # the last place whose line was counted, its line, where that line starts
        self.cursor = (0, 1, 0)
        # what lark need not read of the statement being read: start, end, what it is
        # (a condition, None when too deep, or a point list), the condition's depth
        self.cond: _Part | None = None
        self.bailed: dict[int, _Part | None] = {}
        self.last_end = 0  # where the last point read ends

    def statement(self) -> tuple[Rule | Term, str | None]:
        """One statement and the spelling of its shape (``Bail`` when not taken)."""
        raise NotImplementedError

    # ---------------------------------------------------------------- positions
    def at_statement(self, offset: int) -> None:
        text = self.text
        if offset >= self.base:
            self.base_line += text.count("\n", self.base, offset)
            nl = text.rfind("\n", self.base, offset)
            if nl >= 0:
                self.base_ls = nl + 1
        else:  # back to the last statement of a run
            self.base_line -= text.count("\n", offset, self.base)
            self.base_ls = text.rfind("\n", 0, offset) + 1
        if offset < self.base:
            nl = text.find("\n", offset, self.base)
            if nl >= 0:
                self.next_nl = nl
        elif 0 <= self.next_nl < offset:
            self.next_nl = text.find("\n", offset)
        self.base = offset
        self.cursor = (offset, self.base_line, self.base_ls)

    def lc(self, p: int) -> tuple[int, int]:
        if p <= self.next_nl or self.next_nl < 0:
            return self.base_line, p - self.base_ls + 1
        text = self.text
        pos, line, ls = self.cursor
        if p < pos:  # counted from the statement's start (positions mostly grow)
            pos, line, ls = self.base, self.base_line, self.base_ls
        line += text.count("\n", pos, p)
        nl = text.rfind("\n", pos, p)
        if nl >= 0:
            ls = nl + 1
        self.cursor = (p, line, ls)
        return line, p - ls + 1

    def span(self, a: int, b: int) -> Span:
        la, ca = self.lc(a)
        lb, cb = self.lc(b)
        return Span(la, ca, lb, cb)

    # ---------------------------------------------------------------- tokens
    def _lex(self) -> tuple[int, int, int, str]:
        """(kind, start, end, upper-case text) of the token at ``pos``, comments recorded
        and skipped."""
        m = _TOKEN.match(self.text, self.pos)
        while m is not None and m.lastindex == COMMENT:
            self.comments.append((m.group(COMMENT), m.start(COMMENT)))
            m = _TOKEN.match(self.text, m.end())
        if m is None:
            raise Bail
        k = m.lastindex or 0
        self.pos = m.end()
        return k, m.start(k), self.pos, m.group(k).upper()

    def next(self) -> tuple[int, int, int, str]:
        la = self.la
        if la is not None:
            self.la = None
            return la
        return self._lex()

    def peek(self) -> tuple[int, int, int, str]:
        """The next token, not taken (comments before it are recorded once)."""
        if self.la is None:
            self.la = self._lex()
        return self.la

    def seek(self, pos: int) -> None:
        self.pos = pos
        self.la = None

    def word(self) -> tuple[str, int, int]:
        """A name that is no keyword."""
        k, a, b, u = self.next()
        if k != WORD or u in KEYWORDS:
            raise Bail
        return self.text[a:b], a, b

    def keyword(self, *allowed: str) -> tuple[str, int, int]:
        k, a, b, u = self.next()
        if k != WORD or u not in allowed:
            raise Bail
        return u, a, b

    def punct(self, p: str) -> int:
        k, a, _, u = self.next()
        if k != PUNCT or u != p:
            raise Bail
        return a

    def number(self, a: int, b: int) -> float:
        tok = self.text[a:b]
        try:
            value = float(tok)
        except ValueError:  # a Unicode minus sign
            value = float(tok.translate(_MINUS_SIGNS))
        if (value == math.inf or value == -math.inf) and tok[-1:].isdigit():
            raise Bail  # lark's reader reports it
        return value

    def param(self) -> tuple[Param, int, int]:
        k, a, b, u = self.next()
        if k == NUMBER:
            return self.number(a, b), a, b
        if k != WORD or u in KEYWORDS:
            raise Bail
        return Ref(self.text[a:b], self.span(a, b)), a, b


class RuleReader(Reader):
    """RULE label : IF condition THEN conclusions [;]"""

    def statement(self) -> tuple[Rule, None]:
        self.cond = None
        m = _SIMPLE_RULE.match(self.text, self.pos)
        if m is not None:
            rule = self.simple(m)
            if rule is not None:
                if rule.condition is not None and m.end(2) - m.start(2) >= SUBSTITUTE_MIN:
                    self.cond = (m.start(2), m.end(2), rule.condition, nesting(rule.condition))
                return rule, None
        if self.quick_only:
            raise Bail
        return self.general(), None

    def simple(self, m: re.Match[str]) -> Rule | None:
        """The rule matched by _SIMPLE_RULE (``None`` when a name is a keyword)."""
        text = self.text
        line, col = self.lc(m.start())
        shift = col - m.start()  # column = offset + shift on this line
        s2, e2, s3, e3 = m.start(2), m.end(2), m.start(3), m.end(3)
        condition = _spaced_condition(text[s2:e2], s2, line, shift)
        if condition is None:
            condition = self._condition(s2, e2, line, shift)
            if condition is None:
                return None
        conclusions = []
        for part in _PART.finditer(text, s3, e3):
            v, t = part.group(1), part.group(2)
            if v is None or v.upper() in KEYWORDS or t.upper() in KEYWORDS:
                return None
            span = Span(line, part.start() + shift, line, part.end() + shift)
            conclusions.append(Conclusion(v, t, None, span))
        self.seek(m.end())
        return Rule(m.group(1), condition, tuple(conclusions), Span(line, col, line, m.end() + shift))

    def _condition(self, start: int, end: int, line: int, shift: int) -> Condition | None:
        groups: list[list[Is]] = [[]]
        for part in _PART.finditer(self.text, start, end):
            if part.lastindex == 3:
                if part.group(3).upper() == "OR":
                    groups.append([])
                continue
            v, t = part.group(1), part.group(2)
            if v.upper() in KEYWORDS or t.upper() in KEYWORDS:
                return None
            groups[-1].append(Is(v, t, False, (), Span(line, part.start() + shift, line, part.end() + shift)))
        return _precedence(groups)

    def general(self) -> Rule:
        _, r0, _ = self.keyword("RULE")
        k, a, _, _ = self.next()
        if k not in (NUMBER, WORD, LABEL):
            raise Bail
        m = _LABEL.match(self.text, a)
        if m is None:
            raise Bail
        label = m.group()
        self.seek(m.end())
        self.punct(":")
        self.keyword("IF")
        start = self.peek()[1]
        condition, depth, stop = ConditionParser(self).parse()
        _, _, end = self.keyword("THEN")
        self.cond = (start, stop, condition, depth)
        if condition is None:
            raise Bail  # too deep: lark reports it, with this condition in its place
        conclusions = [self.conclusion()]
        while True:
            k, _, _, w = self.peek()
            if not ((k == PUNCT and w == ",") or (k == WORD and w == "AND")):
                break
            self.next()
            conclusions.append(self.conclusion())
        if k == PUNCT and w == ";":
            _, _, end, _ = self.next()
        elif not (k == WORD and w in ("RULE", "END_RULEBLOCK")):
            raise Bail
        return Rule(label, condition, tuple(conclusions), self.span(r0, end))

    def ids(self) -> tuple[list[str], int]:
        """ID+ (hedges and a term): names up to the next keyword or punctuation."""
        w, _, end = self.word()
        words = [w]
        while True:
            k, _, _, up = self.peek()
            if k != WORD or up in KEYWORDS:
                return words, end
            w, _, end = self.word()
            words.append(w)

    def conclusion(self) -> Conclusion:
        variable, a, end = self.word()
        term: str | None = None
        hedges: tuple[str, ...] = ()
        weight: Param | None = None
        k, _, _, w = self.peek()
        if k == WORD and w == "IS":
            self.next()
            words, end = self.ids()
            term, hedges = words[-1], tuple(words[:-1])
            k, _, _, w = self.peek()
        if k == WORD and w == "WITH":
            _, _, end, _ = self.next()
            weight, _, b = self.param()
            if isinstance(weight, Ref):
                end = b  # a number has no span of its own: the span ends at WITH
        return Conclusion(variable, term, weight, self.span(a, end), hedges)


class TermReader(Reader):
    """TERM name := points | number | shape numbers ;"""

    def statement(self) -> tuple[Term, str | None]:
        self.cond = None
        if self.quick_only:
            raise Bail
        m = _SIMPLE_TERM.match(self.text, self.pos) if self.la is None else None
        if m is not None and m.group(1).upper() not in KEYWORDS and m.end(2) - m.start(2) < SUBSTITUTE_MIN:
            return self.simple(m), None
        _, t0, _ = self.keyword("TERM")
        name, _, _ = self.word()
        self.punct(":=")
        k, a, b, u = self.next()
        spelling: str | None = None
        mf: MembershipFunction
        part: _Part | None = None
        if k == PUNCT and u == "(":
            points = [self.point(a)]
            while True:
                k, _, _, w = self.peek()
                if k == PUNCT and w == ",":
                    self.next()
                    k, _, _, w = self.peek()
                    if not (k == PUNCT and w == "("):
                        raise Bail  # a ',' after the last point: lark reports it
                if not (k == PUNCT and w == "("):
                    break
                _, p, _, _ = self.next()
                points.append(self.point(p))
            mf = PointsMF(tuple(points))
            if self.last_end - a >= SUBSTITUTE_MIN:
                part = (a, self.last_end, mf, 0)
        elif k == NUMBER:
            mf = SingletonMF(self.number(a, b))
        elif k == WORD and u not in KEYWORDS:
            mf, spelling = self.shape(self.text[a:b])
        else:
            raise Bail
        end = self.punct(";") + 1
        self.cond = part
        return Term(name, mf, self.span(t0, end)), spelling

    def simple(self, m: re.Match[str]) -> Term:
        """The TERM matched by _SIMPLE_TERM (one line: columns are offsets shifted)."""
        line, col = self.lc(m.start())
        shift = col - m.start()
        mf: MembershipFunction
        if m.group(2).startswith("("):
            points = []
            for p in _POINT.finditer(self.text, m.start(2), m.end(2)):
                x, y = self.number(*p.span(1)), self.number(*p.span(2))
                points.append(Point(x, y, Span(line, p.start() + shift, line, p.end() + shift)))
            mf = PointsMF(tuple(points))
        else:
            mf = SingletonMF(self.number(*m.span(2)))
        self.seek(m.end())
        return Term(m.group(1), mf, Span(line, col, line, m.end() + shift))

    def point(self, start: int) -> Point:
        m = _POINT_REST.match(self.text, self.pos) if self.la is None else None
        if m is not None:  # two numbers and ')' with one match
            x: Param = self.number(*m.span(1))
            y: Param = self.number(*m.span(2))
            end = m.end()
            self.seek(end)
            self.last_end = end
            return Point(x, y, self.span(start, end))
        x, _, _ = self.param()  # a name, or a comment inside
        self.punct(",")
        y, _, _ = self.param()
        end = self.punct(")") + 1
        self.last_end = end
        return Point(x, y, self.span(start, end))

    def shape(self, name: str) -> tuple[MembershipFunction, str]:
        spelling = shapes.lookup(name)
        if spelling is None or name.upper() == "DISCRETE":
            raise Bail
        args: list[Param] = []
        while self.peek()[0] == NUMBER:
            _, a, b, _ = self.next()
            args.append(self.number(a, b))
        if not args:
            raise Bail
        try:
            return shapes.build(spelling, args), spelling.written
        except shapes.ShapeError:
            raise Bail from None


def _spaced_condition(cond: str, pos: int, line: int, shift: int) -> Condition | None:
    """``v IS t AND ...`` (as _SIMPLE_RULE matched it) with single spaces between the words,
    read by splitting (``None``: other spacing, or a keyword as a name)."""
    if "  " in cond or "\t" in cond:
        return None
    words = cond.split(" ")
    groups: list[list[Is]] = [[]]
    n = len(words)
    i = 0
    pos += shift
    while True:
        v, t = words[i], words[i + 2]
        if v.upper() in KEYWORDS or t.upper() in KEYWORDS:
            return None
        b = pos + len(v) + len(t) + 4
        groups[-1].append(Is(v, t, False, (), Span(line, pos, line, b)))
        i += 3
        if i >= n:
            return _precedence(groups)
        op = words[i]
        if len(op) == 2:
            groups.append([])
        pos = b + len(op) + 2
        i += 1


def _precedence(groups: list[list[Is]]) -> Condition:
    """OR of ANDs of the subconditions grouped between the ORs."""
    ors: list[Condition] = [
        g[0] if len(g) == 1 else And(tuple(g), _join(g[0].span, g[-1].span)) for g in groups
    ]
    return ors[0] if len(ors) == 1 else Or(tuple(ors), _join(ors[0].span, ors[-1].span))


def next_item(text: str, scan: re.Pattern[str], pos: int) -> tuple[str, int, int] | None:
    """The next keyword ``scan`` looks for at or after ``pos`` (upper case, its start and
    end), skipping comments and OPTIONS text as the lark lexer does; ``None`` at the end of
    the text or in an OPTIONS block that is never closed.  ``scan``: group 1 a comment,
    group 2 the keywords, OPTIONS and OPTION among them."""
    while True:
        m = scan.search(text, pos)
        if m is None:
            return None
        if m.lastindex == 1:
            pos = m.end()
            continue
        word = m.group(2).upper()
        if not word.startswith("OPTION"):
            return word, m.start(), m.end()
        body = _OPTIONS_END.match(text, m.end())
        if body is None:
            return None
        pos = body.end()


def read_runs(text: str) -> FastResult | None:
    """The runs of plain RULE and TERM statements of ``text``, and the long conditions of
    the rules lark reads (``None`` when there is nothing worth taking from lark)."""
    result = FastResult(text)
    blanks: list[tuple[int, int, int, str]] = []
    comments: dict[int, str] = {}
    subs: dict[int, tuple[int, int, Condition | PointsMF | None, int, int]] = {}
    readers: dict[str, Reader] = {"RULE": RuleReader(text), "TERM": TermReader(text)}
    pos = misses = 0
    while (item := next_item(text, _SCAN, pos)) is not None:
        word, start, _ = item
        taken = len(blanks)
        pos = _run(readers[word], word, start, result, blanks, comments, subs)
        misses = 0 if len(blanks) > taken else misses + 1
        if misses > MAX_MISSES:  # a file of statements this reader does not take
            for reader in readers.values():
                reader.quick_only = True
    lines = _Lines(text)
    for p in sorted(subs):
        a, b, part, levels, statement = subs[p]
        if isinstance(part, PointsMF):
            result.points[lines.at(statement)] = part
            blanks.append((a, b, p, "0"))
        else:
            result.conditions[lines.at(p)] = (part, levels)
            blanks.append((a, b, p, "_"))
    if not blanks:
        return None
    for offset in sorted(comments):
        result.add_comment(comments[offset], offset)
    blanks.sort()
    result.text = blank_regions(text, blanks)
    return result


def _run(
    reader: Reader,
    word: str,
    start: int,
    result: FastResult,
    blanks: list[tuple[int, int, int, str]],
    comments: dict[int, str],
    subs: dict[int, tuple[int, int, Condition | PointsMF | None, int, int]],
) -> int:
    """Read the run of ``word`` statements from ``start``; keep the inner ones in ``result``
    and the long conditions of the others.  Returns where the search for the next run goes
    on."""
    got: list[tuple[int, Rule | Term, str | None]] = []
    conds: list[tuple[int, _Part]] = []
    reader.comments = []
    at = start
    resume = start + len(word)
    while True:
        reader.seek(at)
        reader.at_statement(at)
        try:
            if at in reader.bailed:  # read before: not again
                reader.cond = reader.bailed[at]
                raise Bail
            item, spelling = reader.statement()
        except Bail:
            reader.bailed[at] = reader.cond
            if reader.cond is not None:
                conds.append((at, reader.cond))
            resume = at + len(word)
            break
        if reader.cond is not None:
            conds.append((at, reader.cond))
        got.append((at, item, spelling))
        try:
            kind, a, _, u = reader.peek()  # comments before it are recorded here
        except Bail:
            resume = reader.pos
            break
        if kind != WORD or u != word:
            resume = a
            break
        at = a
    lo = hi = start
    if len(got) >= MIN_RUN:
        lo, hi = got[1][0], got[-1][0]
        blanks.append((lo, hi, -1, ""))
        for offset, item, spelling in got[1:-1]:
            result.offsets.append(offset)
            result.items.append(item)
            result.spellings.append(spelling)
        resume = hi
    regions = [(lo, hi)]
    for offset, (a, b, part, levels) in conds:
        if (lo <= offset < hi) or (part is not None and b - a < SUBSTITUTE_MIN):
            continue
        p = _placeholder(reader.text, a, b)
        if p < 0:
            continue
        subs[p] = (a, b, part, levels, offset)
        regions.append((a, b))
    for body, offset in reader.comments:
        if any(a <= offset < b for a, b in regions):
            comments[offset] = body
    return resume


def _placeholder(text: str, a: int, b: int) -> int:
    """Where lark is to read ``_`` in place of the condition ``text[a:b]``: not on a line
    end, nor glued to a word before it (``IF(``); -1 when there is no such place."""
    for p in range(a, b):
        if text[p] == "\n" or (p == a and a > 0 and _WORD_CHAR.match(text, a - 1)):
            continue
        return p
    return -1


class _Lines:
    """(line, column) of offsets asked for in increasing order."""

    def __init__(self, text: str) -> None:
        self.text = text
        self.pos, self.line, self.ls = 0, 1, 0

    def at(self, p: int) -> tuple[int, int]:
        self.line += self.text.count("\n", self.pos, p)
        nl = self.text.rfind("\n", self.pos, p)
        if nl >= 0:
            self.ls = nl + 1
        self.pos = p
        return self.line, p - self.ls + 1


def blank_regions(text: str, regions: list[tuple[int, int, int, str]]) -> str:
    """``text`` with every character of ``regions`` but ``\\n`` replaced by a space, and
    the placeholder mark at the offset of each (when not -1)."""
    out: list[str] = []
    pos = 0
    for a, b, p, mark in regions:
        out.append(text[pos:a])
        blank = "\n".join(" " * len(line) for line in text[a:b].split("\n"))
        if p >= 0:
            blank = blank[: p - a] + mark + blank[p - a + 1 :]
        out.append(blank)
        pos = b
    out.append(text[pos:])
    return "".join(out)
