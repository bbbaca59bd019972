"""Interval type-2 terms in FCL: an Open-level extension of this tool (docs/fcl.md, "Interval
type-2 terms").  A term gives its lower membership function after the upper one::

    TERM good := (0, 0) (5, 1) (10, 0) LOWER SCALE 0.9 LAG 0.2;      (MATLAB's form)
    TERM rancid := TRAPE -2 0 1 3 LOWER SCALE 1 LAG 0.1 0.3;        (left and right lag)
    TERM cheap := (0, 0) (5, 1) (10, 0) LOWER (2, 0) (5, 0.8) (8, 0);  (any function)

and a DEFUZZIFY block its type reduction: ``TYPE_REDUCTION : KM;`` (EKM, IASC, EIASC).

The parser of type-1 FCL does not know these words: :func:`split` blanks them out of the
text (keeping every line and column, so every other diagnostic stays where it was) and
records them; :func:`attach` puts them on the parsed model.  A type-1 tool reading such a
file stops at ``LOWER`` or ``TYPE_REDUCTION`` with a syntax error; fuzzyctl's ``check``
lists both as Open-level features.
"""

from __future__ import annotations

import re
from dataclasses import dataclass, field, replace

from fuzzyctl.diagnostics import Diagnostic, error
from fuzzyctl.kinds import type_reduction as tr
from fuzzyctl.model import Document, FunctionBlock, LowerMF, MembershipFunction, Span

_WORD = re.compile(r"\b(LOWER|TYPE_REDUCTION)\b", re.IGNORECASE)
# LOWER is a keyword only inside a TERM statement, after its membership function (so a term,
# variable or rule word spelled ``lower`` stays a name); TYPE_REDUCTION only where a
# DEFUZZIFY statement starts and ``:`` follows it.
_TOKENS = re.compile(
    r"\(\*.*?\*\)|/\*.*?\*/|//[^\n]*"
    r"|\b(FUZZIFY|DEFUZZIFY|TERM)\b\s*([A-Za-z_]\w*)?"
    r"|\b(END_FUZZIFY|END_DEFUZZIFY|LOWER|TYPE_REDUCTION)\b|:=|;",
    re.IGNORECASE | re.DOTALL,
)
_SCALE_LAG = re.compile(
    r"^\s*SCALE\s+([-+0-9.eE]+)\s+LAG\s+([-+0-9.eE]+)(?:\s+([-+0-9.eE]+))?\s*$", re.IGNORECASE
)


@dataclass
class Extras:
    """What :func:`split` took out: lower functions by (block variable, term) and type
    reductions by output, with where each was written."""

    lowers: dict[tuple[str, str], tuple[str, Span]] = field(default_factory=dict)
    reductions: dict[str, tuple[str, Span]] = field(default_factory=dict)

    def __bool__(self) -> bool:
        return bool(self.lowers or self.reductions)


def _span(text: str, offset: int) -> Span:
    line = text.count("\n", 0, offset) + 1
    return Span(line, offset - (text.rfind("\n", 0, offset) + 1) + 1)


def _blank(chars: list[str], start: int, end: int) -> None:
    for i in range(start, end):
        if chars[i] not in "\r\n":
            chars[i] = " "


def split(text: str) -> tuple[str, Extras]:
    """``text`` with the type-2 parts blanked out, and those parts."""
    extras = Extras()
    if _WORD.search(text) is None:  # (the common case: one scan of the text)
        return text, extras
    chars = list(text)
    scan = _Scan(text)
    for m in _TOKENS.finditer(text):
        found = scan.step(m)
        if found is None:
            continue
        word, start, body, end = found
        value = text[body:end].strip()
        if word == "LOWER":
            extras.lowers[(scan.block, scan.term)] = (value, _span(text, start))
            _blank(chars, start, end)
        else:
            extras.reductions[scan.block] = (value.lstrip(":").strip(), _span(text, start))
            _blank(chars, start, end + 1)
    return "".join(chars), extras


@dataclass
class _Scan:
    """Where the scan of :func:`split` is: the block and term it is in, whether the term's
    membership function has started, and an open LOWER / TYPE_REDUCTION."""

    text: str
    block: str = ""
    term: str = ""
    in_term: bool = False
    mf_start: int = -1  # where the term's text after ``:=`` starts (-1: no ``:=`` yet)
    statement_start: int = 0  # where the current statement of a DEFUZZIFY block starts
    in_defuzzify: bool = False
    pending: tuple[str, int, int] | None = None  # keyword, its start, where its text starts

    def step(self, m: re.Match[str]) -> tuple[str, int, int, int] | None:
        """Advance over one token; a finished LOWER / TYPE_REDUCTION as (keyword, start,
        start of its text, end of its text)."""
        token = m.group(0)
        if token.startswith(("(*", "/*", "//")):
            return None
        head = (m.group(1) or "").upper()
        word = (m.group(3) or "").upper()
        if head in ("FUZZIFY", "DEFUZZIFY"):
            self.block, self.in_defuzzify = m.group(2) or "", head == "DEFUZZIFY"
            self.statement_start = m.end()
        elif head == "TERM" and self.pending is None:
            self.term, self.in_term, self.mf_start = m.group(2) or "", True, -1
        elif word in ("END_FUZZIFY", "END_DEFUZZIFY"):
            self.in_term = self.in_defuzzify = False
            self.pending = None
        elif token == ":=" and self.in_term and self.mf_start < 0:
            self.mf_start = m.end()
        elif self.pending is None and self._opens(word, m):
            self.pending = (word, m.start(), m.end())
        elif token == ";":
            found = None if self.pending is None else (*self.pending, m.start())
            self.pending, self.in_term = None, False
            self.statement_start = m.end()
            return found
        return None

    def _opens(self, word: str, m: re.Match[str]) -> bool:
        if word == "LOWER":
            return self._after_mf(m.start())
        return word == "TYPE_REDUCTION" and self._starts_statement(m)

    def _after_mf(self, at: int) -> bool:
        return self.in_term and self.mf_start >= 0 and self.text[self.mf_start : at].strip() != ""

    def _starts_statement(self, m: re.Match[str]) -> bool:
        before = self.text[self.statement_start : m.start()]
        return (
            self.in_defuzzify
            and _COMMENTS.sub("", before).strip() == ""
            and self.text[m.end() :].lstrip().startswith(":")
        )


_COMMENTS = re.compile(r"\(\*.*?\*\)|/\*.*?\*/|//[^\n]*", re.DOTALL)


def _lower(value: str, span: Span, path: str | None) -> LowerMF | Diagnostic:
    m = _SCALE_LAG.match(value)
    if m is not None:
        try:
            scale = float(m.group(1))
            lag = tuple(float(v) for v in m.group(2, 3) if v is not None)
        except ValueError:
            return error(
                f"LOWER SCALE s LAG l [r]: numbers expected, found {value!r}", span, file=path, code="type2"
            )
        if not 0.0 < scale <= 1.0:
            return error(f"LOWER SCALE must be in (0, 1], found {scale:g}", span, file=path, code="type2")
        if not all(0.0 <= v < 1.0 for v in lag):
            return error(f"LOWER LAG must be in [0, 1), found {list(lag)}", span, file=path, code="type2")
        return LowerMF(scale=scale, lag=lag)
    if value.upper().startswith(("SCALE", "LAG")):
        return error(f"expected LOWER SCALE s LAG l [r], found LOWER {value}", span, file=path, code="type2")
    mf = _parse_mf(value)
    if mf is None:
        return error(
            f"LOWER {value!r}: expected a membership function or SCALE s LAG l [r]",
            span,
            file=path,
            code="type2",
        )
    return LowerMF(mf=mf)


def _parse_mf(value: str) -> MembershipFunction | None:
    """The membership function ``value`` as the type-1 parser reads a term's."""
    from fuzzyctl.fcl.parser import parse_source
    from fuzzyctl.fcl.source import Source

    text = (
        "FUNCTION_BLOCK lower VAR_INPUT v : REAL; END_VAR\n"
        f"FUZZIFY v TERM t := {value}; END_FUZZIFY END_FUNCTION_BLOCK\n"
    )
    parsed = parse_source(Source(text))
    doc = parsed.document
    if doc is None or any(d.is_error for d in parsed.diagnostics) or not doc.main.fuzzify:
        return None
    terms = doc.main.fuzzify[0].terms
    return terms[0].mf if terms else None


def attach(document: Document, extras: Extras, path: str | None) -> tuple[Document, list[Diagnostic]]:
    """``document`` with the lower functions and type reductions :func:`split` found."""
    found: list[Diagnostic] = []
    used: set[tuple[str, str]] = set()

    def block(fb: FunctionBlock) -> FunctionBlock:
        def terms_of(variable: str, terms: tuple) -> tuple:  # type: ignore[type-arg]
            out = []
            for t in terms:
                entry = extras.lowers.get((variable, t.name))
                if entry is None:
                    out.append(t)
                    continue
                used.add((variable, t.name))
                lower = _lower(entry[0], entry[1], path)
                if isinstance(lower, Diagnostic):
                    found.append(lower)
                    out.append(t)
                else:
                    out.append(replace(t, lower=lower))
            return tuple(out)

        defuzzify = []
        for d in fb.defuzzify:
            code = None
            if d.variable in extras.reductions:
                value, span = extras.reductions[d.variable]
                code = tr.spelled("fcl").get(value.lower())
                if code is None:
                    known = ", ".join(tr.spelling(c, "fcl") for c in tr.METHODS)
                    found.append(
                        error(
                            f"TYPE_REDUCTION {value!r} is not known (known: {known})",
                            span,
                            file=path,
                            code="type2",
                        )
                    )
            defuzzify.append(replace(d, terms=terms_of(d.variable, d.terms), type_reduction=code))
        fuzzify = [replace(f, terms=terms_of(f.variable, f.terms)) for f in fb.fuzzify]
        return replace(fb, fuzzify=tuple(fuzzify), defuzzify=tuple(defuzzify))

    blocks = tuple(block(fb) for fb in document.blocks)
    for key, (_, span) in extras.lowers.items():
        if key not in used:
            found.append(
                error(f"LOWER outside a TERM of FUZZIFY/DEFUZZIFY {key[0]}", span, file=path, code="type2")
            )
    return replace(document, blocks=blocks), found
