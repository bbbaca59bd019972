"""The FPL lexer and parser: source text -> the project's VARs, rule base and CONNECTs, with
every diagnostic at its place (the model is built from them in :mod:`fuzzyctl.formats.fpl`).

Reading time is linear in the size of the file and small per character, as a file of any
shape may be untrusted (issue 14): one regular expression checks the whole text for
characters FPL has no token for before anything else is done (a file with any is refused
with them, as nothing else would be reported), then the parser takes the tokens one at a
time, so an error stops the reading at once.  Tokens are tuples holding their offset; the
line and column of one are only worked out (by bisection in the offsets of the line starts)
when a diagnostic or the model asks for its place.  A plain rule - the bulk of a large rule
base - is read by one match; conditions nest without recursion.
"""

from __future__ import annotations

import math
import re
from bisect import bisect_right
from dataclasses import dataclass, field
from itertools import accumulate
from sys import intern
from typing import NamedTuple, NoReturn

from fuzzyctl.diagnostics import Diagnostic, Severity, error, warning
from fuzzyctl.formats.fpl.names import KEYWORDS, MAX_NAME, OBJECTS, STRUCTURAL
from fuzzyctl.limits import MAX_NESTING, shorten
from fuzzyctl.model import And, Conclusion, Condition, Is, Span

__all__ = ["MAX_UNEXPECTED", "lex_errors", "parse_project"]

# --------------------------------------------------------------------------- lexer

_COMMENT = r"(?P<comment>/\*.*?\*/)"
_OTHERS = r"""
  | (?P<code>\#CODE\b.*?(?:\#END_CODE\b|\Z))
  | (?P<number>[-+]?(?:\d+\.?\d*|\.\d+)(?:[eE][-+]?\d+)?)
  | (?P<word>[^\W\d]\w*)
  | (?P<string>"[^"\n]*")
  | (?P<punct>[(),=])
"""
_FLAGS = re.VERBOSE | re.DOTALL | re.IGNORECASE
# The tokens, found by searching: the whitespace between them is skipped, and so would be
# a character no token starts with - which lex_errors has ruled out before.
_TOKEN = re.compile(_COMMENT + _OTHERS, _FLAGS)
# The longest run of tokens and whitespace from a place (possessive: in one pass, without
# keeping a way back); it stops only at a character no token starts with, or at the end.
# (No capturing groups: Python 3.11's re fails on them inside a possessive repeat.)
_UNNAMED = re.compile(r"\(\?P<\w+>")
_CLEAN = re.compile(_UNNAMED.sub("(?:", rf"(?:{_COMMENT}{_OTHERS}|\s+)*+"), _FLAGS)
# The same where no comment can start: after a "/*" that no "*/" follows, trying one at
# each later "/*" would scan to the end of the file each time.
_CLEAN_UNCOMMENTED = re.compile(_UNNAMED.sub("(?:", rf"(?:(?!){_OTHERS}|\s+)*+"), _FLAGS)

#: How many unexpected characters are reported one by one; after that the lexer stops
#: with one error saying so (a binary file or another format would give one per byte).
MAX_UNEXPECTED = 1000

# The manual's texts for the tolerated elements (Siemens 1.3, "Tolerated FPL Elements").
_TOLERATED_ATTRIBUTES = {
    "MAP": "MAP ignored: no mapping possible",
    "INITIALLY": "INITIALLY ignored: preallocation not permitted",
    "DEFAULT": "DEFAULT ignored: value output with inactive rules not possible "
    "(Fuzzy Control keeps the last output value)",
}
_TOLERATED_OBJECTS = {
    "OPTIONS": "OPTIONS ignored: additional information for objects",
    "SOURCE": "SOURCE ignored: C code parts are not used by Fuzzy Control",
    "FRAGMENT": "FRAGMENT ignored: C code parts are not used by Fuzzy Control",
}


class _Tok(NamedTuple):
    kind: str  # "word", "number", "string", "punct", "code", "eof"
    text: str
    pos: int  # offset in the source text
    upper: str  # the word upper-cased (keywords are matched so), "" for other kinds


class _Lines:
    """Line and column of an offset: the offsets of the line starts, made on first use and
    searched by bisection.  Lines end at LF only (a CR is whitespace, as it always was)."""

    def __init__(self, text: str) -> None:
        self.text = text
        self._starts: list[int] | None = None

    def place(self, pos: int) -> tuple[int, int]:
        starts = self._starts
        if starts is None:
            lengths = map(len, self.text.split("\n"))
            starts = self._starts = list(accumulate(map((1).__add__, lengths), initial=0))
        line = bisect_right(starts, pos)
        return line, pos - starts[line - 1] + 1

    def span(self, tok: _Tok) -> Span:
        """The span of a token: its start and end, or its start alone for code and eof."""
        if tok.kind in ("code", "eof"):
            return Span(*self.place(tok.pos))
        return self.span_at(tok.pos, len(tok.text))

    def span_at(self, pos: int, length: int) -> Span:
        """The span of the ``length`` characters at ``pos`` (on one line)."""
        line, column = self.place(pos)
        return Span(line, column, line, column + length)


def lex_errors(text: str, file: str | None) -> list[Diagnostic]:
    """An error for each character no FPL token starts with (the first
    :data:`MAX_UNEXPECTED` of them, then one saying that the rest were not looked at)."""
    out: list[Diagnostic] = []
    lines = _Lines(text)
    end = len(text)
    # The first "/*" that no "*/" follows (a comment ends at a "*/" two characters on at
    # least): no comment starts after it.
    unclosed = text.find("/*", max(text.rfind("*/") - 1, 0))
    unclosed = end if unclosed < 0 else unclosed
    pos = 0
    while True:
        clean = _CLEAN if pos <= unclosed else _CLEAN_UNCOMMENTED
        pos = clean.match(text, pos).end()  # type: ignore[union-attr]  # (a star always matches)
        if pos >= end:
            return out
        line, column = lines.place(pos)
        if len(out) == MAX_UNEXPECTED:
            message = (
                f"more than {MAX_UNEXPECTED} unexpected characters: the rest of the file is not read "
                "(is this an FPL file?)"
            )
            out.append(error(message, Span(line, column), code="fpl-syntax", file=file))
            return out
        message = f"unexpected character {text[pos]!r}"
        out.append(error(message, Span(line, column), code="fpl-syntax", file=file))
        pos += 1


_EOF = "eof"
_new_token = tuple.__new__  # a token made without NamedTuple's Python-level __new__

# The plain rule that makes up the bulk of a large rule base, read by one match and two
# scans instead of token by token: ASCII names (a word token ends where \w does), flat
# conditions ``v is t`` or ``(v is t)`` joined by AND, conclusions ``v = t`` joined by AND or
# commas, no comments.  Anything else - and names that are keywords - takes the general
# path (Parser.parse_rule), which reads these the same way.
#: the longest name read (S7 Fuzzy Control's names are far shorter; a diagnostic quotes names)
_NAME = rf"[A-Za-z_][A-Za-z0-9_]{{0,{MAX_NAME - 1}}}(?!\w)"
_IS = rf"{_NAME}\s+[Ii][Ss]\s+{_NAME}"
_LEAF = rf"(?:\(\s*{_IS}\s*\)|{_IS})"
_TO = rf"{_NAME}\s*=\s*{_NAME}"
_PLAIN_RULE = re.compile(
    rf"""\s+(?P<label>{_NAME})
    \s+[Ii][Ff](?!\w)\s*(?P<cond>{_LEAF}(?:\s*[Aa][Nn][Dd](?!\w)\s*{_LEAF})*+)
    \s*[Tt][Hh][Ee][Nn](?!\w)\s*(?P<then>{_TO}(?:\s*(?:,|[Aa][Nn][Dd](?!\w))\s*{_TO})*+)
    \s*[Ee][Nn][Dd](?!\w)""",
    re.VERBOSE,
)
_PLAIN_IS = re.compile(rf"({_NAME})\s+[Ii][Ss]\s+({_NAME})")
_PLAIN_TO = re.compile(rf"({_NAME})\s*=\s*({_NAME})")


# --------------------------------------------------------------------------- parser


class Abort(Exception):
    """Stops parsing after an error the parser cannot recover from."""


@dataclass
class FplMember:
    name: str
    points: list[tuple[float, float]]
    span: Span


@dataclass
class FplVar:
    name: str
    span: Span
    type_name: str | None = None
    low: float | None = None
    high: float | None = None
    members: list[FplMember] = field(default_factory=list)


@dataclass
class FplRule:
    label: str
    condition: Condition | None
    conclusions: list[Conclusion]
    span: Span


@dataclass
class FplRuleBase:
    name: str
    rules: list[FplRule]
    span: Span


class Parser:
    """The project of a text without unexpected characters (see :func:`lex_errors`).

    :meth:`parse` reads it into :attr:`vars`, :attr:`rulebases`, :attr:`connects` and
    :attr:`project`, appending diagnostics to ``diags`` and comments to ``comments``;
    it raises :class:`Abort` after an error it cannot read on from."""

    def __init__(self, text: str, file: str | None, diags: list[Diagnostic], comments: list[str]) -> None:
        self.text = text
        self.pos = 0  # where the next token is looked for
        self.comments = comments
        self.lines = _Lines(text)
        self.file = file
        self.diags = diags
        self.vars: list[FplVar] = []
        self.rulebases: list[FplRuleBase] = []
        self.connects: list[tuple[str, Span, str, Span]] = []
        self.project: str | None = None
        self.tok: _Tok = self.next_token()  # the token at the cursor

    # -- token helpers
    def next_token(self) -> _Tok:
        """The token after :attr:`pos` (the text has no unexpected characters: searching
        skips whitespace only); comments on the way are collected."""
        text = self.text
        while True:
            m = _TOKEN.search(text, self.pos)
            if m is None:
                self.pos = len(text)
                return _Tok(_EOF, "", len(text), "")
            self.pos = m.end()
            kind = m.lastgroup
            chunk = m.group()
            if kind == "word":
                tok = _new_token(_Tok, ("word", chunk, m.start(), chunk.upper()))
                if len(chunk) > MAX_NAME:  # (messages quote names: never a megabyte of one)
                    self.fail(f"the name {shorten(chunk)!r} is longer than {MAX_NAME} characters", tok)
                return tok
            if kind != "comment":
                return _new_token(_Tok, (kind, chunk, m.start(), ""))
            self.comments.append(chunk[2:-2].strip())

    def advance(self) -> _Tok:
        tok = self.tok
        if tok.kind != _EOF:
            self.tok = self.next_token()
        return tok

    def at(self, *words: str) -> bool:
        return self.tok.upper in words

    def at_punct(self, char: str) -> bool:
        return self.tok.kind == "punct" and self.tok.text == char

    def span(self, tok: _Tok) -> Span:
        return self.lines.span(tok)

    def fail(self, message: str, tok: _Tok | None = None, hint: str | None = None) -> NoReturn:
        tok = tok or self.tok
        self.diags.append(error(message, self.span(tok), code="fpl-syntax", file=self.file, hint=hint))
        raise Abort

    def describe(self, tok: _Tok) -> str:
        return "end of file" if tok.kind == "eof" else repr(shorten(tok.text))

    def value(self, tok: _Tok) -> float:
        """A number token's value; one beyond the double range is an error, never inf."""
        value = float(tok.text)
        if math.isinf(value):
            self.fail(f"the number {shorten(tok.text)} is too large (beyond 1.8e308)", tok)
        return value

    def expect_word(self, what: str) -> _Tok:
        tok = self.tok
        if tok.kind != "word":
            self.fail(f"expected {what}, found {self.describe(tok)}")
        return self.advance()

    def expect_keyword(self, word: str) -> _Tok:
        if not self.at(word):
            self.fail(f"expected {word}, found {self.describe(self.tok)}")
        return self.advance()

    def number(self, what: str) -> float:
        tok = self.tok
        if tok.kind != "number":
            self.fail(f"expected a number for {what}, found {self.describe(tok)}")
        self.advance()
        return self.value(tok)

    def note(self, message: str, tok: _Tok, severity: Severity, code: str) -> None:
        self.diags.append(Diagnostic(severity, message, self.span(tok), self.file, code))

    def warn(self, message: str, tok: _Tok, code: str) -> None:
        self.diags.append(warning(message, self.span(tok), code=code, file=self.file))

    # -- tolerated elements
    def skip_tolerated(self) -> bool:
        """Skip one tolerated element at the cursor; False when there is none."""
        tok = self.tok
        if tok.kind == "code":
            self.advance()
            self.note(
                "#CODE..#END_CODE ignored: C source code is not used by Fuzzy Control",
                tok,
                Severity.NOTE,
                "fpl-tolerated",
            )
            return True
        word = tok.upper
        if word in _TOLERATED_ATTRIBUTES:
            self.advance()
            while self.tok.kind != "eof" and self.tok.upper not in STRUCTURAL and self.tok.kind != "code":
                self.advance()
            self.note(_TOLERATED_ATTRIBUTES[word], tok, Severity.WARNING, "fpl-tolerated")
            return True
        if word in _TOLERATED_OBJECTS:
            self.advance()
            depth = 1
            while depth:
                nxt = self.advance()
                if nxt.kind == "eof":
                    self.fail(f"{word} object is not closed by END", tok)
                if nxt.upper == "END":
                    depth -= 1
                elif nxt.upper in OBJECTS:
                    depth += 1
            self.note(_TOLERATED_OBJECTS[word], tok, Severity.NOTE, "fpl-tolerated")
            return True
        return False

    # -- grammar
    def parse(self) -> None:
        while self.skip_tolerated():
            pass
        self.expect_keyword("PROJECT")
        self.project = self.expect_word("the project name").text
        while True:
            if self.skip_tolerated():
                continue
            tok = self.tok
            word = tok.upper
            if word == "VAR":
                self.parse_var()
            elif word == "FUZZY":
                self.parse_fuzzy()
            elif word == "CONNECT":
                self.parse_connect()
            elif word == "PACKAGE":
                self.fail("PACKAGE is not permissible: Fuzzy Control has no modular fuzzy systems", tok)
            elif word == "END":
                self.advance()
                break
            elif tok.kind == "eof":
                # A missing final END loses nothing; say so and accept the file.
                self.warn("PROJECT is not closed by END", tok, "fpl-missing-end")
                break
            else:
                self.fail(f"expected VAR, FUZZY, CONNECT or END, found {self.describe(tok)}")
        while self.skip_tolerated():
            pass
        if self.tok.kind != "eof":
            self.fail(f"unexpected {self.describe(self.tok)} after the end of the project")

    def parse_var(self) -> None:
        start = self.advance()
        var = FplVar(self.expect_word("a variable name").text, self.span(start))
        while True:
            if self.skip_tolerated():
                continue
            tok = self.tok
            word = tok.upper
            if word == "TYPE":
                self.advance()
                var.type_name = self.expect_word("a type name").text
                if var.type_name.upper() != "FLOAT":
                    self.warn(
                        f"TYPE {var.type_name} read as float: Fuzzy Control variables are always FLOAT",
                        tok,
                        "fpl-type",
                    )
            elif word == "MIN":
                self.advance()
                var.low = self.number("MIN")
            elif word == "MAX":
                self.advance()
                var.high = self.number("MAX")
            elif word == "MEMBER":
                var.members.append(self.parse_member())
            elif word == "END":
                self.advance()
                break
            else:
                self.fail(
                    f"expected TYPE, MIN, MAX, MEMBER or END in VAR {var.name}, found {self.describe(tok)}"
                )
        if var.low is not None and var.high is not None and var.low >= var.high:
            self.diags.append(
                error(
                    f"VAR {var.name}: MIN {var.low:g} must be below MAX {var.high:g}",
                    var.span,
                    code="fpl-range",
                    file=self.file,
                )
            )
        self.vars.append(var)

    def parse_member(self) -> FplMember:
        start = self.advance()
        member = FplMember(self.expect_word("a membership function name").text, [], self.span(start))
        while True:
            if self.skip_tolerated():
                continue
            tok = self.tok
            if tok.upper == "POINTS":
                self.advance()
                member.points.extend(self.parse_points(member.name, tok))
            elif tok.upper == "END":
                self.advance()
                break
            else:
                self.fail(
                    f"expected POINTS or END in MEMBER {member.name}, found {self.describe(tok)}",
                    hint="equations are not permissible for membership functions (Siemens 1.3)",
                )
        if not member.points:
            self.fail(f"MEMBER {member.name} has no POINTS", start)
        return member

    def parse_points(self, member: str, points_tok: _Tok) -> list[tuple[float, float]]:
        """The (x, y) pairs after POINTS: degrees in [0, 1], x never decreasing."""
        numbers: list[tuple[float, _Tok]] = []
        # Commas separate x from y; a stray comma between points (the manual's
        # "99.0,1.0, 101.0,1.0") changes nothing, so numbers are simply paired.
        while self.tok.kind == "number" or self.at_punct(","):
            t = self.advance()
            if t.kind == "number":
                numbers.append((self.value(t), t))
        if len(numbers) % 2:
            self.fail(
                f"MEMBER {member}: POINTS needs x,y pairs, found {len(numbers)} numbers",
                numbers[-1][1] if numbers else points_tok,
            )
        pts = [(numbers[k][0], numbers[k + 1][0]) for k in range(0, len(numbers), 2)]
        for k, (x, y) in enumerate(pts):
            if not 0.0 <= y <= 1.0:
                self.fail(f"MEMBER {member}: degree {y:g} is outside [0, 1]", numbers[2 * k + 1][1])
            if k and x < pts[k - 1][0]:
                self.fail(
                    f"MEMBER {member}: points must be in increasing x order "
                    f"({x:g} follows {pts[k - 1][0]:g})",
                    numbers[2 * k][1],
                )
        return pts

    def parse_fuzzy(self) -> None:
        start = self.advance()
        if self.rulebases:
            self.fail("only one set of rules (FUZZY) is permitted in Fuzzy Control", start)
        base = FplRuleBase(self.expect_word("the rule base name").text, [], self.span(start))
        while True:
            if self.skip_tolerated():
                continue
            tok = self.tok
            if tok.upper == "RULE":
                base.rules.append(self.plain_rule(tok) or self.parse_rule())
            elif tok.upper == "END":
                self.advance()
                break
            else:
                self.fail(f"expected RULE or END in FUZZY {base.name}, found {self.describe(tok)}")
        self.rulebases.append(base)

    def plain_rule(self, start: _Tok) -> FplRule | None:
        """The rule after the RULE token ``start`` when it is a plain one (see _PLAIN_RULE),
        read at once; None, with nothing consumed, for any other."""
        text = self.text
        m = _PLAIN_RULE.match(text, self.pos)
        if m is None:
            return None
        label = m.group("label")
        leaves = [
            (intern(t.group(1)), t.start(1), intern(t.group(2)))
            for t in _PLAIN_IS.finditer(text, *m.span("cond"))
        ]
        then = [
            (intern(t.group(1)), t.start(1), intern(t.group(2)))
            for t in _PLAIN_TO.finditer(text, *m.span("then"))
        ]
        names = {label.upper()}
        for var, _, term in (*leaves, *then):
            names.add(var.upper())
            names.add(term.upper())
        if not KEYWORDS.isdisjoint(names):
            return None  # FPL reads keywords as names in some places only: the general path
        span = self.lines.span_at
        parts = [Is(v, t, span=span(pos, len(v))) for v, pos, t in leaves]
        condition: Condition = parts[0]
        if len(parts) > 1:
            first = m.start("cond")
            condition = And(tuple(parts), span=span(first, 1) if text[first] == "(" else parts[0].span)
        conclusions = [Conclusion(v, t, span=span(pos, len(v))) for v, pos, t in then]
        self.pos = m.end()
        self.tok = self.next_token()
        return FplRule(label, condition, conclusions, self.span(start))

    def parse_rule(self) -> FplRule:
        start = self.advance()
        label_tok = self.tok
        if label_tok.kind not in ("word", "number") or label_tok.upper in ("IF", "THEN", "END"):
            self.fail(f"expected a rule name, found {self.describe(label_tok)}")
        self.advance()
        condition: Condition | None = None
        if self.at("IF"):
            self.advance()
            condition = self.parse_condition()
        conclusions: list[Conclusion] = []
        if self.at("THEN"):
            self.advance()
            conclusions.append(self.parse_conclusion())
            while self.at("AND") or self.at_punct(","):
                self.advance()
                conclusions.append(self.parse_conclusion())
        while self.skip_tolerated():
            pass
        if not self.at("END"):
            self.fail(f"expected THEN or END in RULE {label_tok.text}, found {self.describe(self.tok)}")
        self.advance()
        return FplRule(label_tok.text, condition, conclusions, self.span(start))

    def parse_condition(self) -> Condition:
        """``sub AND sub ...`` where a sub is ``v IS t`` or a parenthesised condition.

        Read with a stack of the enclosing parentheses rather than by recursion: besides
        the bound on the stack, a descent 100 calls deep makes CPython 3.11 allocate and free
        a block of frame memory on every call at the bottom (seconds for a long chain there)."""
        outer: list[tuple[_Tok, list[Condition]]] = []  # per open parenthesis: first, parts
        first = self.tok
        parts: list[Condition] = []
        while True:
            if self.at_punct("("):
                self.advance()
                if len(outer) >= MAX_NESTING:
                    self.fail(f"the condition nests more than {MAX_NESTING} parentheses deep")
                outer.append((first, parts))
                first, parts = self.tok, []
                continue
            parts.append(self.parse_is())
            # After a subcondition: AND reads the next one at this level, else the level ends.
            while not self.at("AND"):
                if self.at("OR"):
                    self.fail("OR is not permissible in Fuzzy Control rules: only AND (Siemens 1.3)")
                cond = parts[0] if len(parts) == 1 else And(tuple(parts), span=self.span(first))
                if not outer:
                    return cond
                if not self.at_punct(")"):
                    self.fail(f"expected ')', found {self.describe(self.tok)}")
                self.advance()
                first, parts = outer.pop()
                parts.append(cond)
            self.advance()

    def parse_is(self) -> Is:
        if self.at("NOT"):
            self.fail("NOT is not permissible in Fuzzy Control rules: only AND (Siemens 1.3)")
        var = self.expect_word("a variable name")
        self.expect_keyword("IS")
        if self.at("NOT"):
            self.fail("NOT is not permissible in Fuzzy Control rules: only AND (Siemens 1.3)")
        term = self.expect_word("a membership function name")
        return Is(var.text, term.text, span=self.span(var))

    def parse_conclusion(self) -> Conclusion:
        paren = self.at_punct("(")
        if paren:
            self.advance()
        var = self.expect_word("an output variable name")
        if self.at_punct("=") or self.at("IS"):
            self.advance()
        else:
            self.fail(f"expected '=' after {var.text}, found {self.describe(self.tok)}")
        term = self.expect_word("a membership function name")
        if paren:
            if not self.at_punct(")"):
                self.fail(f"expected ')', found {self.describe(self.tok)}")
            self.advance()
        return Conclusion(var.text, term.text, span=self.span(var))

    def parse_connect(self) -> None:
        start = self.advance()
        ends: dict[str, _Tok] = {}
        while not self.at("END"):
            kw = self.tok
            if kw.upper not in ("FROM", "TO"):
                self.fail(f"expected FROM, TO or END in CONNECT, found {self.describe(kw)}")
            self.advance()
            if self.at("FROM", "TO"):
                # The manual's own example has "FROM FROM ProFuzzy": read it, say so.
                self.warn(f"repeated {self.tok.text} in CONNECT", self.tok, "fpl-repeated-keyword")
                continue
            if kw.upper in ends:
                self.fail(f"CONNECT has two {kw.upper} parts", kw)
            ends[kw.upper] = self.expect_word("a variable or rule base name")
        self.advance()
        if set(ends) != {"FROM", "TO"}:
            self.fail("CONNECT needs FROM and TO", start)
        src, dst = ends["FROM"], ends["TO"]
        self.connects.append((src.text, self.span(src), dst.text, self.span(dst)))


def parse_project(text: str, file: str | None, diags: list[Diagnostic], comments: list[str]) -> Parser | None:
    """The parsed project of ``text``, or None when it has errors (appended to ``diags``)."""
    lexical = lex_errors(text, file)
    if lexical:
        diags.extend(lexical)
        return None
    try:
        parser = Parser(text, file, diags, comments)
        parser.parse()
    except Abort:
        return None
    return parser
