"""FPL, the Togai InfraLogic Fuzzy Programming Language, in the subset that Siemens
S7 Fuzzy Control reads and writes (Siemens manual, section 1.3).

The subset: one ``PROJECT``; ``VAR`` objects with ``TYPE``, ``MIN``, ``MAX`` and ``MEMBER``
objects holding a ``POINTS`` list; one ``FUZZY`` rule base of ``RULE`` objects
``IF (v is t) AND ... THEN v = t``; ``CONNECT FROM x TO y`` objects telling inputs from
outputs; ``END`` closing every object; ``/* */`` comments.  The elements the manual lists as
tolerated are skipped: ``MAP``, ``INITIALLY`` and ``DEFAULT`` with the manual's warning,
``OPTIONS``, ``SOURCE``, ``FRAGMENT`` and ``#CODE .. #END_CODE`` with a note.

Meaning of the points lists (Siemens 1.3): an input term is a rectangle, triangle or
trapezoid; "with vertical lines specifying the upper point is sufficient", so a list that
starts or ends on degree 1 strictly inside ``[MIN, MAX]`` has a vertical edge there (we add
the foot point).  At ``MIN``/``MAX`` the edge is kept as an IEC shoulder: the FB clamps its
inputs to the limits, so both readings agree inside the range and the shoulder also agrees
with an FCL program outside it.  An output term whose points all have degree 1 (the
"narrow rectangle" of the manual) is the singleton at its centre.

The rule base reads as IEC AND MIN, ACT MIN, ACCU NSUM, METHOD COGS (COG when an output has
area terms) and ``DEFAULT := NC``: Fuzzy Control keeps the last output when no rule fires.
ACCU NSUM because Fuzzy Control *adds* the contributions of several rules to one output
term (1.4, ``x_S' = (mu_A x_A + mu_B x_B + ...) / (mu_A + mu_B + ...)`` with one mu per
rule; glossary, "Singleton Function": "the influences ... resulting from various rules are
added together"); NSUM is the Table 5 sum, and its normalisation cancels in the centre of
gravity, so with singletons it computes exactly the manual's formula.
MIN/MAX of an input become the range of its FUZZIFY block, of an output the range of its
DEFUZZIFY block.  The block limits its inputs to [MIN, MAX] (1.5); that changes nothing when
every point of the input's terms lies in [MIN, MAX] (points lists are constant beyond their
ends), else the FUZZIFY block gets ``clamp``.
"""

from __future__ import annotations

import math
import re
from collections.abc import Iterator, Sequence
from dataclasses import dataclass, field, replace
from typing import NoReturn

from fuzzyctl.diagnostics import Diagnostic, DiagnosticError, Severity, error, warning
from fuzzyctl.formats import Format, Loaded, Loss
from fuzzyctl.model import (
    And,
    Conclusion,
    Condition,
    Default,
    DefuzzifyBlock,
    Document,
    FunctionBlock,
    FuzzifyBlock,
    Is,
    MembershipFunction,
    Point,
    PointsMF,
    Range,
    Rule,
    RuleBlock,
    SingletonMF,
    Span,
    Term,
    Variable,
    VarKind,
)

NAME = "fpl"
EXTENSIONS = (".fpl",)

__all__ = [
    "ADDING_ACCU",
    "EXTENSIONS",
    "FORMAT",
    "KEYWORDS",
    "NAME",
    "SIEMENS_ACCU",
    "FplResult",
    "is_fpl_name",
    "leaves",
    "parse_fpl",
    "read_fpl",
    "shared_conclusions",
]

# --------------------------------------------------------------------------- lexer

_TOKEN = re.compile(
    r"""
    (?P<comment>/\*.*?\*/)
  | (?P<code>\#CODE\b.*?(?:\#END_CODE\b|\Z))
  | (?P<number>[-+]?(?:\d+\.?\d*|\.\d+)(?:[eE][-+]?\d+)?)
  | (?P<word>[^\W\d]\w*)
  | (?P<string>"[^"\n]*")
  | (?P<punct>[(),=])
  | (?P<space>\s+)
    """,
    re.VERBOSE | re.DOTALL | re.IGNORECASE,
)

# Objects that own an END (skipping a tolerated object counts these to find its END).
_OBJECTS = {
    "PROJECT",
    "PACKAGE",
    "VAR",
    "MEMBER",
    "FUZZY",
    "RULE",
    "CONNECT",
    "OPTIONS",
    "SOURCE",
    "FRAGMENT",
}
# Words that end the arguments of a tolerated attribute (MAP, INITIALLY, DEFAULT).
_STRUCTURAL = _OBJECTS | {
    "END",
    "TYPE",
    "MIN",
    "MAX",
    "POINTS",
    "IF",
    "THEN",
    "FROM",
    "TO",
    "MAP",
    "INITIALLY",
    "DEFAULT",
}
# Words FPL reads as keywords wherever they stand (upper-cased): no name may be one of them.
KEYWORDS = frozenset(_STRUCTURAL | {"IS", "AND", "OR", "NOT"})
_WORD = re.compile(r"[^\W\d]\w*")


def is_fpl_name(name: str) -> bool:
    """True when FPL reads ``name`` back as one name (a word, not a keyword)."""
    return _WORD.fullmatch(name) is not None and name.upper() not in KEYWORDS


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


@dataclass(frozen=True)
class _Tok:
    kind: str  # "word", "number", "string", "punct", "code", "eof"
    text: str
    span: Span

    @property
    def upper(self) -> str:
        return self.text.upper() if self.kind == "word" else ""


def _lex(text: str, file: str | None, diags: list[Diagnostic], comments: list[str]) -> list[_Tok]:
    tokens: list[_Tok] = []
    line, line_start, pos = 1, 0, 0
    while pos < len(text):
        m = _TOKEN.match(text, pos)
        span = Span(line, pos - line_start + 1)
        if m is None:
            diags.append(error(f"unexpected character {text[pos]!r}", span, code="fpl-syntax", file=file))
            pos += 1
            continue
        kind = m.lastgroup or ""
        chunk = m.group()
        end_col = span.column + len(chunk)
        if kind == "comment":
            comments.append(chunk[2:-2].strip())
        elif kind == "code":
            tokens.append(_Tok("code", chunk, span))
        elif kind != "space":
            tokens.append(_Tok(kind, chunk, Span(line, span.column, line, end_col)))
        newlines = chunk.count("\n")
        if newlines:
            line += newlines
            line_start = pos + chunk.rfind("\n") + 1
        pos = m.end()
    tokens.append(_Tok("eof", "", Span(line, pos - line_start + 1)))
    return tokens


# --------------------------------------------------------------------------- parser


class _Abort(Exception):
    """Stops parsing after an error the parser cannot recover from."""


@dataclass
class _Member:
    name: str
    points: list[tuple[float, float]]
    span: Span


@dataclass
class _Var:
    name: str
    span: Span
    type_name: str | None = None
    low: float | None = None
    high: float | None = None
    members: list[_Member] = field(default_factory=list)


@dataclass
class _Rule:
    label: str
    condition: Condition | None
    conclusions: list[Conclusion]
    span: Span


@dataclass
class _RuleBase:
    name: str
    rules: list[_Rule]
    span: Span


class _Parser:
    def __init__(self, tokens: list[_Tok], file: str | None, diags: list[Diagnostic]) -> None:
        self.toks = tokens
        self.i = 0
        self.file = file
        self.diags = diags
        self.vars: list[_Var] = []
        self.rulebases: list[_RuleBase] = []
        self.connects: list[tuple[str, Span, str, Span]] = []
        self.project: str | None = None

    # -- token helpers
    @property
    def tok(self) -> _Tok:
        return self.toks[self.i]

    def advance(self) -> _Tok:
        tok = self.toks[self.i]
        if tok.kind != "eof":
            self.i += 1
        return tok

    def at(self, *words: str) -> bool:
        return self.tok.upper in words

    def fail(self, message: str, tok: _Tok | None = None, hint: str | None = None) -> NoReturn:
        tok = tok or self.tok
        self.diags.append(error(message, tok.span, code="fpl-syntax", file=self.file, hint=hint))
        raise _Abort

    def describe(self, tok: _Tok) -> str:
        return "end of file" if tok.kind == "eof" else repr(tok.text)

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
        return float(tok.text)

    def note(self, message: str, tok: _Tok, severity: Severity, code: str) -> None:
        self.diags.append(Diagnostic(severity, message, tok.span, self.file, code))

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
            while self.tok.kind != "eof" and self.tok.upper not in _STRUCTURAL and self.tok.kind != "code":
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
                elif nxt.upper in _OBJECTS:
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
                self.diags.append(
                    warning("PROJECT is not closed by END", tok.span, code="fpl-missing-end", file=self.file)
                )
                break
            else:
                self.fail(f"expected VAR, FUZZY, CONNECT or END, found {self.describe(tok)}")
        while self.skip_tolerated():
            pass
        if self.tok.kind != "eof":
            self.fail(f"unexpected {self.describe(self.tok)} after the end of the project")

    def parse_var(self) -> None:
        start = self.advance()
        var = _Var(self.expect_word("a variable name").text, start.span)
        while True:
            if self.skip_tolerated():
                continue
            tok = self.tok
            word = tok.upper
            if word == "TYPE":
                self.advance()
                var.type_name = self.expect_word("a type name").text
                if var.type_name.upper() != "FLOAT":
                    self.diags.append(
                        warning(
                            f"TYPE {var.type_name} read as float: Fuzzy Control variables are always FLOAT",
                            tok.span,
                            code="fpl-type",
                            file=self.file,
                        )
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

    def parse_member(self) -> _Member:
        start = self.advance()
        member = _Member(self.expect_word("a membership function name").text, [], start.span)
        while True:
            if self.skip_tolerated():
                continue
            tok = self.tok
            if tok.upper == "POINTS":
                self.advance()
                numbers: list[tuple[float, _Tok]] = []
                # Commas separate x from y; a stray comma between points (the manual's
                # "99.0,1.0, 101.0,1.0") changes nothing, so numbers are simply paired.
                while self.tok.kind == "number" or (self.tok.kind == "punct" and self.tok.text == ","):
                    t = self.advance()
                    if t.kind == "number":
                        numbers.append((float(t.text), t))
                if len(numbers) % 2:
                    self.fail(
                        f"MEMBER {member.name}: POINTS needs x,y pairs, found {len(numbers)} numbers",
                        numbers[-1][1] if numbers else tok,
                    )
                pts = [(numbers[k][0], numbers[k + 1][0]) for k in range(0, len(numbers), 2)]
                for k, (x, y) in enumerate(pts):
                    ytok = numbers[2 * k + 1][1]
                    if not 0.0 <= y <= 1.0:
                        self.fail(f"MEMBER {member.name}: degree {y:g} is outside [0, 1]", ytok)
                    if k and x < pts[k - 1][0]:
                        self.fail(
                            f"MEMBER {member.name}: points must be in increasing x order "
                            f"({x:g} follows {pts[k - 1][0]:g})",
                            numbers[2 * k][1],
                        )
                member.points.extend(pts)
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

    def parse_fuzzy(self) -> None:
        start = self.advance()
        if self.rulebases:
            self.fail("only one set of rules (FUZZY) is permitted in Fuzzy Control", start)
        base = _RuleBase(self.expect_word("the rule base name").text, [], start.span)
        while True:
            if self.skip_tolerated():
                continue
            tok = self.tok
            if tok.upper == "RULE":
                base.rules.append(self.parse_rule())
            elif tok.upper == "END":
                self.advance()
                break
            else:
                self.fail(f"expected RULE or END in FUZZY {base.name}, found {self.describe(tok)}")
        self.rulebases.append(base)

    def parse_rule(self) -> _Rule:
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
            while self.at("AND") or (self.tok.kind == "punct" and self.tok.text == ","):
                self.advance()
                conclusions.append(self.parse_conclusion())
        while self.skip_tolerated():
            pass
        if not self.at("END"):
            self.fail(f"expected THEN or END in RULE {label_tok.text}, found {self.describe(self.tok)}")
        self.advance()
        return _Rule(label_tok.text, condition, conclusions, start.span)

    def parse_condition(self) -> Condition:
        first = self.tok
        parts = [self.parse_subcondition()]
        while self.at("AND"):
            self.advance()
            parts.append(self.parse_subcondition())
        if self.at("OR"):
            self.fail("OR is not permissible in Fuzzy Control rules: only AND (Siemens 1.3)")
        return parts[0] if len(parts) == 1 else And(tuple(parts), span=first.span)

    def parse_subcondition(self) -> Condition:
        tok = self.tok
        if tok.kind == "punct" and tok.text == "(":
            self.advance()
            inner = self.parse_condition()
            if not (self.tok.kind == "punct" and self.tok.text == ")"):
                self.fail(f"expected ')', found {self.describe(self.tok)}")
            self.advance()
            return inner
        if tok.upper == "NOT":
            self.fail("NOT is not permissible in Fuzzy Control rules: only AND (Siemens 1.3)")
        var = self.expect_word("a variable name")
        self.expect_keyword("IS")
        if self.at("NOT"):
            self.fail("NOT is not permissible in Fuzzy Control rules: only AND (Siemens 1.3)")
        term = self.expect_word("a membership function name")
        return Is(var.text, term.text, span=var.span)

    def parse_conclusion(self) -> Conclusion:
        paren = self.tok.kind == "punct" and self.tok.text == "("
        if paren:
            self.advance()
        var = self.expect_word("an output variable name")
        if (self.tok.kind == "punct" and self.tok.text == "=") or self.at("IS"):
            self.advance()
        else:
            self.fail(f"expected '=' after {var.text}, found {self.describe(self.tok)}")
        term = self.expect_word("a membership function name")
        if paren:
            if not (self.tok.kind == "punct" and self.tok.text == ")"):
                self.fail(f"expected ')', found {self.describe(self.tok)}")
            self.advance()
        return Conclusion(var.text, term.text, span=var.span)

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
                self.diags.append(
                    warning(
                        f"repeated {self.tok.text} in CONNECT",
                        self.tok.span,
                        code="fpl-repeated-keyword",
                        file=self.file,
                    )
                )
                continue
            if kw.upper in ends:
                self.fail(f"CONNECT has two {kw.upper} parts", kw)
            ends[kw.upper] = self.expect_word("a variable or rule base name")
        self.advance()
        if set(ends) != {"FROM", "TO"}:
            self.fail("CONNECT needs FROM and TO", start)
        src, dst = ends["FROM"], ends["TO"]
        self.connects.append((src.text, src.span, dst.text, dst.span))


# --------------------------------------------------------------------------- model building


@dataclass(frozen=True)
class FplResult:
    """What :func:`parse_fpl` found: the document (None when there are errors) and every
    diagnostic, warnings for the tolerated elements included."""

    document: Document | None
    diagnostics: tuple[Diagnostic, ...]


def _input_points(points: Sequence[tuple[float, float]], low: float, high: float) -> tuple[Point, ...]:
    """Siemens points list -> IEC points (vertical edges inside the range get their foot)."""
    pts = list(points)
    if len(pts) == 1:
        x, y = pts[0]
        pts = [(x, 0.0), (x, y), (x, 0.0)] if y > 0 else pts
    else:
        if pts[0][1] > 0 and pts[0][0] > low:
            pts.insert(0, (pts[0][0], 0.0))
        if pts[-1][1] > 0 and pts[-1][0] < high:
            pts.append((pts[-1][0], 0.0))
    return tuple(Point(x, y) for x, y in pts)


def _output_mf(points: Sequence[tuple[float, float]], low: float, high: float) -> MembershipFunction:
    if all(y == 1.0 for _, y in points):
        # The narrow rectangle that TILShell needs for a singleton (Siemens 1.3 and 1.4).
        return SingletonMF((points[0][0] + points[-1][0]) / 2.0)
    return PointsMF(_input_points(points, low, high))


def _build(p: _Parser, file: str | None, comments: list[str]) -> FunctionBlock:
    diags = p.diags
    by_name: dict[str, _Var] = {}
    for var in p.vars:
        if var.name in by_name:
            diags.append(error(f"VAR {var.name} is defined twice", var.span, code="fpl-duplicate", file=file))
        by_name[var.name] = var
        seen: set[str] = set()
        for m in var.members:
            if m.name in seen:
                diags.append(
                    error(
                        f"MEMBER {m.name} is defined twice in VAR {var.name}",
                        m.span,
                        code="fpl-duplicate",
                        file=file,
                    )
                )
            seen.add(m.name)
    base = p.rulebases[0] if p.rulebases else None
    base_name = base.name if base else None

    kinds: dict[str, VarKind] = {}
    for src, src_span, dst, dst_span in p.connects:
        if src == base_name and dst in by_name:
            kinds[dst] = VarKind.OUTPUT
        elif dst == base_name and src in by_name:
            kinds[src] = VarKind.INPUT
        else:
            bad, span = (src, src_span) if src not in by_name and src != base_name else (dst, dst_span)
            diags.append(
                error(
                    f"CONNECT FROM {src} TO {dst}: {bad} is not a VAR or the rule base",
                    span,
                    code="fpl-connect",
                    file=file,
                )
            )
    # Without CONNECT objects the rules tell inputs from outputs.
    for rule in base.rules if base else []:
        for c in rule.conclusions:
            kinds.setdefault(c.variable, VarKind.OUTPUT)
        for v in _condition_vars(rule.condition):
            kinds.setdefault(v, VarKind.INPUT)

    variables: list[Variable] = []
    fuzzify: list[FuzzifyBlock] = []
    defuzzify: list[DefuzzifyBlock] = []
    all_singletons = True
    outputs = [v for v in p.vars if kinds.get(v.name) is VarKind.OUTPUT]
    for var in p.vars:
        kind = kinds.get(var.name, VarKind.INPUT)  # a VAR in no rule is a monitoring input (1.5)
        rng = Range(var.low, var.high) if var.low is not None and var.high is not None else None
        low = var.low if var.low is not None else -math.inf
        high = var.high if var.high is not None else math.inf
        # MIN/MAX go where FCL puts a range: on the DEFUZZIFY block of an output, on the
        # FUZZIFY block of an input - with clamp, as the block limits its inputs (1.5) -
        # and on the declaration of a monitoring input, which has no terms.
        monitoring = kind is VarKind.INPUT and not var.members
        variables.append(Variable(var.name, kind, "REAL", range=rng if monitoring else None, span=var.span))
        if kind is VarKind.OUTPUT:
            terms = tuple(Term(m.name, _output_mf(m.points, low, high), span=m.span) for m in var.members)
            all_singletons &= all(isinstance(t.mf, SingletonMF) for t in terms)
            defuzzify.append(
                DefuzzifyBlock(var.name, terms, range=rng, default=Default(no_change=True), span=var.span)
            )
        elif var.members:
            terms = tuple(
                Term(m.name, PointsMF(_input_points(m.points, low, high)), span=m.span) for m in var.members
            )
            # Clamping only changes something when a term has points outside [MIN, MAX]:
            # IEC points lists are constant beyond their ends.
            outside = any(not low <= x <= high for m in var.members for x, _ in m.points)
            fuzzify.append(FuzzifyBlock(var.name, terms, range=rng, span=var.span, clamp=outside))
    method = "COGS" if all_singletons else "COG"
    defuzzify = [replace(d, method=method) for d in defuzzify]

    for rule in base.rules if base else []:
        for cond in leaves(rule.condition):
            _check_ref(by_name, kinds, cond.variable, cond.term, VarKind.INPUT, cond.span, file, diags)
        for c in rule.conclusions:
            _check_ref(by_name, kinds, c.variable, c.term, VarKind.OUTPUT, c.span, file, diags)
    if not outputs and base and base.rules:
        diags.append(
            warning(
                "no output variable: nothing is CONNECTed FROM the rule base",
                base.span,
                code="fpl-no-output",
                file=file,
            )
        )
    rule_blocks: tuple[RuleBlock, ...] = ()
    if base is not None:
        rules = tuple(Rule(r.label, r.condition, tuple(r.conclusions), span=r.span) for r in base.rules)
        rule_blocks = (
            RuleBlock(base.name, rules, and_op="MIN", act="MIN", accu=SIEMENS_ACCU, span=base.span),
        )
    return FunctionBlock(
        p.project, tuple(variables), tuple(fuzzify), tuple(defuzzify), rule_blocks, comments=tuple(comments)
    )


SIEMENS_ACCU = "NSUM"
"""The IEC accumulation that computes what Fuzzy Control computes (1.4): the sum of the
rules' degrees per output term (NSUM's normalisation cancels in a centre of gravity)."""

ADDING_ACCU = frozenset({"NSUM", "SUM"})
"""Accumulations that add the rules' degrees without a bound, as Fuzzy Control does."""


def shared_conclusions(block: FunctionBlock) -> list[tuple[str, str, list[Rule]]]:
    """``(output, term, rules)`` for every output term that two or more rules conclude.

    Only there does the accumulation matter for singleton outputs: one rule per term gives
    the same degrees under MAX, BSUM, NSUM or SUM, so the Siemens sum (1.4) equals an
    IEC ``ACCU : MAX`` program exactly when this list is empty."""
    seen: dict[tuple[str, str], list[Rule]] = {}
    for _rb, rule in block.rules():
        for c in rule.conclusions:
            if c.term is not None:
                seen.setdefault((c.variable, c.term), []).append(rule)
    return [(v, t, rules) for (v, t), rules in seen.items() if len(rules) > 1]


def leaves(cond: Condition | None) -> Iterator[Is]:
    """The ``v IS t`` subconditions of an AND-only condition."""
    if isinstance(cond, Is):
        yield cond
    elif isinstance(cond, And):
        for c in cond.operands:
            yield from leaves(c)


def _condition_vars(cond: Condition | None) -> Iterator[str]:
    for leaf in leaves(cond):
        yield leaf.variable


def _check_ref(
    by_name: dict[str, _Var],
    kinds: dict[str, VarKind],
    var: str,
    term: str | None,
    want: VarKind,
    span: Span | None,
    file: str | None,
    diags: list[Diagnostic],
) -> None:
    role = "output" if want is VarKind.OUTPUT else "input"
    if var not in by_name:
        diags.append(error(f"{var} is not a VAR of this project", span, code="fpl-undeclared", file=file))
    elif kinds.get(var) is not want:
        diags.append(
            error(
                f"{var} is used as an {role} but CONNECTed the other way",
                span,
                code="fpl-direction",
                file=file,
            )
        )
    elif term is not None and term not in {m.name for m in by_name[var].members}:
        diags.append(error(f"{var} has no MEMBER {term}", span, code="fpl-undeclared-term", file=file))


def parse_fpl(text: str, *, path: str | None = None) -> FplResult:
    """Read FPL source text; never raises for bad input (see :class:`FplResult`)."""
    diags: list[Diagnostic] = []
    comments: list[str] = []
    tokens = _lex(text, path, diags, comments)
    parser = _Parser(tokens, path, diags)
    block: FunctionBlock | None = None
    if not any(d.is_error for d in diags):
        try:
            parser.parse()
            block = _build(parser, path, comments)
        except _Abort:
            block = None
    ok = block is not None and not any(d.is_error for d in diags)
    doc = Document((block,), path=path, comments=tuple(comments)) if ok and block else None
    return FplResult(doc, tuple(diags))


def read_fpl(text: str, *, path: str | None = None) -> Document:
    """Read FPL source text into a :class:`~fuzzyctl.model.Document`.

    Raises :class:`~fuzzyctl.diagnostics.DiagnosticError` (every diagnostic, file:line:col)
    when the text has errors; use :func:`parse_fpl` to see the warnings of a good file."""
    result = parse_fpl(text, path=path)
    if result.document is None:
        raise DiagnosticError(result.diagnostics, text)
    return result.document


# --------------------------------------------------------------------------- registry


def _read(text: str, path: str | None) -> Loaded:
    result = parse_fpl(text, path=path)
    if result.document is None:
        raise DiagnosticError(result.diagnostics, text)
    return Loaded(result.document, result.diagnostics)


def _write(document: Document) -> str:
    from fuzzyctl.formats.fpl_write import write_fpl

    return write_fpl(document)


def _lower(document: Document) -> tuple[Document, list[Loss]]:
    from fuzzyctl.formats.fpl_write import lower_fpl

    lowered, losses = lower_fpl(document)
    return lowered, [Loss(element, reason) for element, reason in losses]


FORMAT = Format(
    NAME,
    EXTENSIONS,
    "FPL of Siemens S7 Fuzzy Control (Togai InfraLogic subset, Siemens manual 1.3)",
    read=_read,
    write=_write,
    lower=_lower,
)
