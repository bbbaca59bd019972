"""Whole blocks of a large FCL file read without lark: runs of small blocks, runs of
declarations.

fuzzyctl.fcl.fast takes runs of RULE and TERM statements; a file of very many small blocks
(two TERMs per FUZZIFY block, say) has no such run, and lark (about 10 microseconds a token)
would read all of it.  This module takes, the same way, runs of consecutive blocks of a
FUNCTION_BLOCK (VAR_INPUT, VAR_OUTPUT, VAR, FUZZIFY, DEFUZZIFY, RULEBLOCK) whose content
is only statements read here without any diagnostic, and runs of declarations inside a VAR
block.  As with statements, the first and the last block (declaration) of a run are left to
lark, so that lark enters and leaves the blanked text in the state it would have been in; a
block that would give a diagnostic (a RANGE given twice, an unknown METHOD, a missing ';',
a missing END_FUZZIFY, ...) ends the run and lark reads it.  The blocks are built as the
lark transformer builds them (parser._Builder); the transformer merges them back by
position (FastResult.blocks, FastResult.decls).  tests/fcl/test_fast.py compares both paths.
"""

from __future__ import annotations

import re
from bisect import bisect_right
from dataclasses import dataclass, field
from typing import Any

from fuzzyctl.fcl import keywords
from fuzzyctl.fcl.errors import CLOSERS
from fuzzyctl.fcl.fast import (
    COMMENT_RE,
    MIN_RUN,
    NUMBER_RE,
    FastResult,
    Reader,
    RuleReader,
    TermReader,
    blank_regions,
    next_item,
    read_runs,
)
from fuzzyctl.fcl.fast_conditions import KEYWORDS, PUNCT, WORD, Bail
from fuzzyctl.model import (
    Default,
    DefuzzifyBlock,
    FuzzifyBlock,
    OptionsBlock,
    Range,
    Rule,
    RuleBlock,
    Span,
    Term,
    Variable,
    VarKind,
)

_ITEMS = ("VAR_INPUT", "VAR_OUTPUT", "VAR", "FUZZIFY", "DEFUZZIFY", "RULEBLOCK")
_END = {item: CLOSERS[item] for item in _ITEMS}
# Where runs of blocks may start: comments and OPTIONS text are skipped as lark skips them.
_SCAN = re.compile(rf"({COMMENT_RE})|\b({'|'.join(_ITEMS)}|OPTIONS|OPTION)\b", re.S | re.I)
_END_SCAN = {end: re.compile(rf"({COMMENT_RE})|\b{end}\b", re.S | re.I) for end in set(_END.values())}
_WS = r"[ \t\f\r\n\ufeff]*"
# RANGE [:=] (low .. high); with white space only (lark's NUMBER stops before '..').
_RANGE = re.compile(
    rf"RANGE{_WS}(?::={_WS})?\({_WS}({NUMBER_RE}){_WS}(?:\.\.|,){_WS}({NUMBER_RE}){_WS}\){_WS};", re.I
)
# The one-line statements of DEFUZZIFY and RULEBLOCK: (key, what the message calls it, synonyms)
_KEYWORD_ITEMS = {
    "METHOD": ("method", keywords.METHOD_SYNONYMS),
    "ACCU": ("accu", keywords.ACCU_SYNONYMS),
    "ACT": ("act", keywords.ACT_SYNONYMS),
    "AND": ("and_op", keywords.AND_SYNONYMS),
    "OR": ("or_op", keywords.OR_SYNONYMS),
}
_DEFUZZIFY_ITEMS = ("METHOD", "ACCU")
_RULEBLOCK_ITEMS = ("ACCU", "ACT", "AND", "OR")

_Block = FuzzifyBlock | DefuzzifyBlock | RuleBlock | list[Variable]


@dataclass
class _Taken:
    """What the block pass took: blanks on the text, blocks and declarations by offset."""

    blanks: list[tuple[int, int, int, str]] = field(default_factory=list)
    blocks: list[tuple[int, _Block, frozenset[str]]] = field(default_factory=list)
    decls: list[tuple[int, list[Variable]]] = field(default_factory=list)
    comments: dict[int, str] = field(default_factory=dict)


class _BlockReader(Reader):
    """Blocks and declarations, with the TERM and RULE readers of fuzzyctl.fcl.fast."""

    def __init__(self, text: str) -> None:
        super().__init__(text)
        self.terms = TermReader(text)
        self.rules = RuleReader(text)
        self.spellings: set[str] = set()
        self.start = (1, 1)  # line and column of the block being read
        self.ends: dict[str, tuple[int, int]] = {}  # END keyword: (searched from, found)

    def go(self, pos: int) -> None:
        self.seek(pos)
        self.at_statement(pos)

    def look_past(self, at: int) -> tuple[str, int, int] | None:
        """_next_block from ``at``, the line count kept where it was: going back to a
        statement recounts from the start of its line (on a file of one line, from the
        start of the text)."""
        kept = (self.base, self.base_line, self.base_ls, self.next_nl, self.cursor)
        found = _next_block(self, at)
        self.base, self.base_line, self.base_ls, self.next_nl, self.cursor = kept
        return found

    def after(self) -> int:
        """Where the next token starts, or where the last one ended."""
        return self.la[1] if self.la is not None else self.pos

    def sub(self, reader: Reader, at: int) -> Rule | Term:
        """A statement read by ``reader`` from ``at``; this reader goes on after it."""
        reader.comments = []
        reader.seek(at)
        reader.at_statement(at)
        item, spelling = reader.statement()
        self.comments.extend(reader.comments)
        if spelling is not None:
            self.spellings.add(spelling)
        self.go(reader.la[1] if reader.la is not None else reader.pos)
        return item

    # ---------------------------------------------------------------- statements
    def range(self, at: int) -> tuple[Range, int]:
        m = _RANGE.match(self.text, at)
        if m is None:
            raise Bail
        low, high = self.number(*m.span(1)), self.number(*m.span(2))
        if low > high or low == high:
            raise Bail  # lark's transformer reports it
        self.seek(m.end())
        return Range(low, high, self.span(at, m.end())), m.end()

    def keyword_item(self, word: str, at: int) -> tuple[str, str | None, Span]:
        """``KEY : value ;`` (the ';' written, the value known)."""
        key, table = _KEYWORD_ITEMS[word]
        self.next()
        self.punct(":")
        spelling, _, _ = self.word()
        end = self.punct(";") + 1
        if spelling.upper() in keywords.NONE_SPELLINGS:
            return key, None, self.span(at, end)
        value = keywords.canonical(table, spelling)
        if value is None:
            raise Bail
        return key, value, self.span(at, end)

    def default(self, at: int) -> Default:
        """``DEFAULT := number ;`` or ``DEFAULT := NC ;``."""
        self.next()
        self.punct(":=")
        k, a, b, u = self.next()
        value: float | None = None
        if k == WORD and u == "NC":
            no_change = True
        elif k == 2:  # a number
            value, no_change = self.number(a, b), False
        else:
            raise Bail
        end = self.punct(";") + 1
        return Default(value, no_change, self.span(at, end))

    # ---------------------------------------------------------------- blocks
    def block(self, word: str, at: int) -> tuple[_Block, int]:
        """The whole block opening at ``at`` and where it ends."""
        self.go(at)
        self.spellings = set()
        self.start = self.lc(at)  # spans are counted forward from the last statement read
        self.next()
        if word == "RULEBLOCK":
            return self.rule_block(at)
        if word.startswith("VAR"):
            return self.var_block(word, at)
        name, _, _ = self.word()
        k, _, _, u = self.peek()
        if k == PUNCT and u == ";":
            self.next()
        terms: list[Term] = []
        ranges: list[Range] = []
        items: dict[str, tuple[str | Default | None, Span]] = {}
        end_word = _END[word]
        while True:
            k, a, b, u = self.peek()
            if k != WORD:
                raise Bail
            if u == end_word:
                self.next()
                break
            if u == "TERM":
                item = self.sub(self.terms, a)
                assert isinstance(item, Term)
                terms.append(item)
            elif u == "RANGE" and not ranges:
                ranges.append(self.range(a)[0])
            elif word == "DEFUZZIFY" and u in _DEFUZZIFY_ITEMS:
                key, setting, span = self.keyword_item(u, a)
                if key in items:
                    raise Bail
                items[key] = (setting, span)
            elif word == "DEFUZZIFY" and u == "DEFAULT" and "default" not in items:
                default = self.default(a)
                assert default.span is not None
                items["default"] = (default, default.span)
            else:
                raise Bail
        span = Span(*self.start, *self.lc(b))
        if word == "FUZZIFY":
            return FuzzifyBlock(name, tuple(terms), ranges[0] if ranges else None, span), b

        def value(key: str) -> str | None:
            v = items.get(key, (None,))[0]
            return v if isinstance(v, str) else None

        default_item = items.get("default", (None,))[0]
        return DefuzzifyBlock(
            name,
            tuple(terms),
            ranges[0] if ranges else None,
            value("method"),
            default_item if isinstance(default_item, Default) else None,
            value("accu"),
            span,
            item_spans=tuple((k, v[1]) for k, v in items.items()),
        ), b

    def rule_block(self, at: int) -> tuple[RuleBlock, int]:
        name: str | None = None
        k, _, _, u = self.peek()
        if k == WORD and u not in KEYWORDS:
            name, _, _ = self.word()
        rules: list[Rule] = []
        items: dict[str, tuple[str | None, Span]] = {}
        while True:
            k, a, b, u = self.peek()
            if k != WORD:
                raise Bail
            if u == "END_RULEBLOCK":
                self.next()
                break
            if u == "RULE":
                item = self.sub(self.rules, a)
                assert isinstance(item, Rule)
                rules.append(item)
            elif u in _RULEBLOCK_ITEMS:
                key, setting, span = self.keyword_item(u, a)
                if key in items:
                    raise Bail
                items[key] = (setting, span)
            else:
                raise Bail

        def value(key: str) -> str | None:
            return items.get(key, (None,))[0]

        block = RuleBlock(
            name,
            tuple(rules),
            value("and_op"),
            value("or_op"),
            value("act"),
            value("accu"),
            Span(*self.start, *self.lc(b)),
            item_spans=tuple((k, v[1]) for k, v in items.items()),
        )
        return block, b

    def var_block(self, word: str, at: int) -> tuple[list[Variable], int]:
        out: list[Variable] = []
        kind = VarKind(word)
        while True:
            k, a, b, u = self.peek()
            if k == WORD and u == "END_VAR":
                self.next()
                return out, b
            out.extend(self.decl(kind, a))

    def decl(self, kind: VarKind, at: int) -> list[Variable]:
        """``name, ... : TYPE [:= value] ; [RANGE ...]`` from ``at``."""
        names = [self.word()]
        while True:
            k, _, _, u = self.next()
            if k != PUNCT:
                raise Bail
            if u == ":":
                break
            if u != ",":
                raise Bail
            names.append(self.word())
        data_type, _, _ = self.word()
        initial: float | bool | str | None = None
        k, a, b, u = self.next()
        if k == PUNCT and u == ":=":
            k, a, b, u = self.next()
            if k == 2:  # a number
                initial = self.number(a, b)
            elif k == WORD and u not in KEYWORDS:
                text = self.text[a:b]
                initial = u == "TRUE" if u in ("TRUE", "FALSE") else text
            else:
                raise Bail
            k, a, b, u = self.next()
        if not (k == PUNCT and u == ";"):
            raise Bail
        end = b
        rng: Range | None = None
        k, a, _, u = self.peek()
        if k == WORD and u == "RANGE":
            rng, end = self.range(a)
            self.seek(end)
        span = self.span(at, end)
        many = len(names) > 1
        return [
            Variable(n, kind, data_type.upper(), initial, rng, self.span(s, e) if many else span)
            for n, s, e in names
        ]


def _end_of(reader: _BlockReader, word: str, start: int) -> int:
    """Where the block opening at ``start`` ends (after its END keyword; -1: no END).
    The last answer for each END keyword is kept: blocks without their END (a file of
    thousands) would each search to the end of the text."""
    end_word = _END[word]
    known = reader.ends.get(end_word)
    if known is not None and known[0] <= start and (known[1] < 0 or start <= known[1] - len(end_word)):
        return known[1]
    pattern = _END_SCAN[end_word]
    pos = start
    while True:
        m = pattern.search(reader.text, pos)
        if m is None:
            found = -1
            break
        if m.lastindex != 1:
            found = m.end()
            break
        pos = m.end()
    reader.ends[end_word] = (start, found)
    return found


def _next_block(reader: _BlockReader, at: int) -> tuple[str, int, int] | None:
    """The keyword and offset of the block opening at the next token after ``at``, also
    past ``END_FUNCTION_BLOCK FUNCTION_BLOCK [name]`` (which lark reads), and where that
    next token starts."""
    reader.go(at)
    try:
        k, a, _, u = reader.peek()
        gap = a
        if k == WORD and u == "END_FUNCTION_BLOCK":
            reader.next()
            k, _, _, u = reader.next()
            if not (k == WORD and u == "FUNCTION_BLOCK"):
                return None
            k, a, b, u = reader.peek()
            if k == WORD and u not in KEYWORDS:
                if reader.text[b : b + 1] == "-":  # a name of several parts (FB_NAME)
                    return None
                reader.next()
                k, a, _, u = reader.peek()
    except Bail:
        return None
    return (u, a, gap) if k == WORD and u in _END else None


def _block_run(reader: _BlockReader, word: str, start: int, taken: _Taken) -> int:
    """Read the run of blocks from ``start`` (the first, lark's); keep its inner blocks.
    A run goes on into the next FUNCTION_BLOCK: lark reads the words between.  Returns
    where the search for the next run goes on."""
    end = -1
    if word.startswith("VAR"):
        end = _decl_run(reader, VarKind(word), start + len(word), taken)
    if end < 0:
        try:
            # read, though lark reads it: its END may not end it (RULE END_RULEBLOCK is a
            # rule labelled END_RULEBLOCK), and lark must leave it as it leaves a block read
            # here
            _, end = reader.block(word, start)
        except Bail:
            return start + len(word)
    reader.comments = []
    # (offset, the block or None when lark reads it, spellings, where the text after the
    # block before it ends)
    got: list[tuple[int, _Block | None, frozenset[str], int]] = []
    ahead: tuple[int, tuple[str, int, int] | None] = (-1, None)  # the last look past a block
    resume = end
    while True:
        found = ahead[1] if ahead[0] == end else _next_block(reader, end)
        if found is None:
            break
        w, at, gap = found
        last = _end_of(reader, w, at + len(w))
        ahead = (last, reader.look_past(last) if last >= 0 else None)
        if ahead[1] is None:  # the last block: lark's, not read here (nor again as a first)
            got.append((at, None, frozenset(), gap))
            if w.startswith("VAR"):
                kept = reader.comments  # those of this run
                _decl_run(reader, VarKind(w), at + len(w), taken)
                reader.comments = kept
            resume = last if last >= 0 else at + len(w)
            break
        try:
            block, end = reader.block(w, at)
        except Bail:
            got.append((at, None, frozenset(), gap))
            resume = at + len(w)
            break
        got.append((at, block, frozenset(reader.spellings), gap))
        resume = end
    if len(got) < 2:
        return resume
    _keep(reader, got, taken)
    return resume


def _keep(
    reader: _BlockReader, got: list[tuple[int, _Block | None, frozenset[str], int]], taken: _Taken
) -> None:
    """Blank and keep the inner blocks of a run (all but its last) and their comments."""
    starts: list[int] = []
    stops: list[int] = []
    for i, (at, inner, spellings, _) in enumerate(got[:-1]):
        assert inner is not None
        stop = got[i + 1][3]
        taken.blanks.append((at, stop, -1, ""))
        taken.blocks.append((at, inner, spellings))
        starts.append(at)
        stops.append(stop)
    for body, offset in reader.comments:
        i = bisect_right(starts, offset) - 1
        if i >= 0 and offset < stops[i]:
            taken.comments[offset] = body


def _decl_run(reader: _BlockReader, kind: VarKind, start: int, taken: _Taken) -> int:
    """The run of declarations after the VAR keyword ending at ``start``; returns where
    the block ends when all of it was read (after END_VAR), else -1."""
    reader.comments = []
    got: list[tuple[int, list[Variable]]] = []
    at = start
    end = -1
    while True:
        reader.go(at)
        try:
            k, a, b, u = reader.peek()
            if k != WORD or u in KEYWORDS:
                end = b if k == WORD and u == "END_VAR" else -1
                break
            reader.at_statement(a)
            got.append((a, reader.decl(kind, a)))
        except Bail:
            break
        at = reader.after()
    if len(got) < MIN_RUN:
        return end
    lo, hi = got[1][0], got[-1][0]
    taken.blanks.append((lo, hi, -1, ""))
    taken.decls.extend(got[1:-1])
    for body, offset in reader.comments:
        if lo <= offset < hi:
            taken.comments[offset] = body
    return end


def read_blocks(text: str) -> FastResult | None:
    """Runs of blocks and declarations of ``text``, then the runs of RULE and TERM
    statements of what is left (fuzzyctl.fcl.fast.read_runs); ``None`` when nothing is
    worth taking from lark."""
    taken = _Taken()
    reader = _BlockReader(text)
    pos = 0
    while (item := next_item(text, _SCAN, pos)) is not None:
        word, start, end = item
        pos = max(_block_run(reader, word, start, taken), end)
    if not taken.blanks:
        return read_runs(text)
    taken.blanks.sort()
    rest = blank_regions(text, taken.blanks)
    result = read_runs(rest) or FastResult(rest)
    result.blocks = [(at, block) for at, block, _ in taken.blocks]
    result.block_spellings = [(at, s) for at, _, spellings in taken.blocks for s in sorted(spellings)]
    result.decls = sorted(taken.decls, key=lambda d: d[0])
    if taken.comments:
        merged = {c.offset: c.text for c in result.comments}
        merged.update(taken.comments)
        result.comments = []
        result._at = (0, 1, 0)
        for offset in sorted(merged):
            result.add_comment(merged[offset], offset)
    return result


# ---------------------------------------------------------------- merging (parser._Builder)
def _position(item: Any) -> tuple[int, int]:
    span = item.span
    return (span.line, span.column) if span is not None else (0, 0)


def _block_position(item: Any) -> tuple[int, int]:
    """Where a block of a FUNCTION_BLOCK starts (a VAR block: its first variable)."""
    return _position(item[0] if isinstance(item, list) else item)


def _offsets(children: list[Any]) -> tuple[int, int] | None:
    """Offsets of the opening and the END keyword of the block made of ``children``."""
    first, last = children[0], children[-1]
    a, b = getattr(first, "start_pos", None), getattr(last, "start_pos", None)
    return (a, b) if isinstance(a, int) and isinstance(b, int) else None


def merge_blocks(fast: FastResult, children: list[Any]) -> list[Any]:
    """The children of a FUNCTION_BLOCK (its keyword first, END_FUNCTION_BLOCK last) with
    the blocks read here put among the others in source order."""
    where = _offsets(children)
    got = fast.blocks_between(*where) if where is not None else []
    if not got:
        return children
    blocks = [
        c
        for c in [*children[1:-1], *got]
        if (isinstance(c, list) and c)
        or isinstance(c, FuzzifyBlock | DefuzzifyBlock | RuleBlock | OptionsBlock)
    ]
    return [children[0], *sorted(blocks, key=_block_position), children[-1]]


def merge_decls(fast: FastResult, children: list[Any], variables: list[Variable]) -> None:
    """Put the declarations read here inside the VAR block made of ``children`` among
    ``variables`` (those lark read), in source order."""
    where = _offsets(children)
    if where is not None:
        variables.extend(fast.decls_between(*where))
        variables.sort(key=_position)
