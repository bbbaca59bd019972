"""What jFuzzyLogic 3.3 would reject or read differently in a file we load.

``fuzzyctl check --compat jfuzzylogic`` (``load_file(path, compat="jfuzzylogic")``) adds these
warnings: a file written for fuzzylite, scalablurry or by hand loads here, and the user learns
that jFuzzyLogic itself would refuse it (or report a syntax error and go on with what it could
read), and why.  Each rule below was read in jFuzzyLogic's grammar (``fcl/Fcl.g``) and
``FunctionBlock.fclTree*`` / ``RuleBlock.fclTree*``, and the whole list is measured against the
live jFuzzyLogic on the corpus (``tests/conformance/test_jfl_corpus.py``): a file gets a
``jfl-rejects`` warning exactly when jFuzzyLogic does not load it cleanly.

``jfl-fails`` warnings name what jFuzzyLogic loads but then throws on at every evaluation
(names differing only in case, which it keeps apart); ``jfl-differs`` what it loads but reads
differently from IEC 61131-7 (a RANGE on the declaration line, a variable declared without a
FUZZIFY/DEFUZZIFY block), which the ``jfuzzylogic`` profile of the engine reproduces where it
can (docs/engine.md).
"""

from __future__ import annotations

import re
from dataclasses import dataclass, field
from typing import Any

from fuzzyctl import model as m
from fuzzyctl.diagnostics import Diagnostic, warning
from fuzzyctl.fcl.shapes import JFL, lookup

__all__ = ["check_jfuzzylogic"]

# jFuzzyLogic's grammar (fcl/Fcl.g): the words each item takes.
_METHODS = {"COG", "COGS", "COGF", "COA", "LM", "RM", "MM"}
_AND = {"MIN", "PROD", "BDIF", "DMIN", "NIPMIN", "HAMACHER"}
_OR = {"MAX", "ASUM", "BSUM", "DMAX", "NIPMAX", "EINSTEIN"}
_ACT = {"MIN", "PROD"}
_ACCU = {"MAX", "BSUM", "NSUM", "PROBOR", "SUM"}
_FUNCTIONS = {"EXP", "LN", "LOG", "SIN", "COS", "TAN", "ABS"}
# Its lexer: identifiers are ASCII letters, digits and '_' starting with a letter, and every
# keyword token (case-insensitive) is reserved.
_ID = re.compile(r"[A-Za-z][A-Za-z0-9_]*")
_KEYWORDS = {
    "ABS", "ACCU", "ACT", "AND", "ASUM", "BDIF", "BSUM", "COA", "COSINE", "COG", "COGS", "COGF",
    "COS", "DEFAULT", "DEFUZZIFY", "DMAX", "DMIN", "DSIGM", "EINSTEIN", "END_DEFUZZIFY",
    "END_FUNCTION_BLOCK", "END_FUZZIFY", "END_RULEBLOCK", "END_VAR", "EXP", "HAMACHER",
    "FUNCTION", "GAUSS", "GAUSS2", "GBELL", "FUNCTION_BLOCK", "FUZZIFY", "IF", "IS", "LM", "LN",
    "LOG", "MAX", "METHOD", "MIN", "NIPMIN", "NIPMAX", "MM", "NC", "NOT", "NSUM", "OR", "PROBOR",
    "PROD", "RANGE", "RM", "RULE", "RULEBLOCK", "SIGM", "SIN", "SINGLETONS", "SUM", "TAN", "TERM",
    "THEN", "TRAPE", "TRIAN", "REAL", "VAR_INPUT", "VAR_OUTPUT", "WITH",
}  # fmt: skip


@dataclass
class _Found:
    """Warnings grouped by reason: the first place is shown, the others counted."""

    file: str | None
    reasons: dict[tuple[str, str], list[m.Span | None]] = field(default_factory=dict)

    def add(self, code: str, reason: str, span: m.Span | None) -> None:
        self.reasons.setdefault((code, reason), []).append(span)

    def diagnostics(self) -> list[Diagnostic]:
        out = []
        for (code, reason), spans in self.reasons.items():
            more = f" ({len(spans) - 1} more like it)" if len(spans) > 1 else ""
            prefix = {
                "jfl-rejects": "jFuzzyLogic 3.3 would reject this file: ",
                "jfl-fails": "jFuzzyLogic 3.3 loads this file but cannot evaluate it: ",
            }.get(code, "jFuzzyLogic 3.3 reads this differently: ")
            out.append(warning(prefix + reason + more, spans[0], code=code, file=self.file))
        return out


def check_jfuzzylogic(doc: m.Document, file: str | None, parsed: Any = None) -> list[Diagnostic]:
    """The ``jfl-rejects`` and ``jfl-differs`` warnings for ``doc`` (``parsed``: the
    :class:`~fuzzyctl.fcl.parser.ParseResult`, for what only the text or the parser's own
    warnings show)."""
    found = _Found(file)
    text = parsed.source.text if parsed is not None else ""
    lines = text.splitlines()
    if parsed is not None:
        for d in parsed.diagnostics:
            if d.code in ("missing-semicolon", "paren-conclusion"):
                found.add("jfl-rejects", f"its grammar has no such form ({d.message})", d.span)
            elif d.code == "case-mismatch":
                found.add(
                    "jfl-fails",
                    f"its names are case-sensitive: {d.message.split(':')[0]} is another name, and "
                    "evaluating the rule throws (NullPointerException)",
                    d.span,
                )
        for spelling in sorted(parsed.spellings):
            s = lookup(spelling)
            if spelling not in ("SINGLETONS", "FUNCTION") and (s is None or s.dialect != JFL):
                found.add("jfl-rejects", f"its grammar has no shape {spelling}", None)
    code = _code(text)
    # its parser stops at the last END_FUNCTION_BLOCK: what trails it (a file name pasted
    # after it, in the corpus) is never lexed
    ends = [hit.end() for hit in re.finditer(r"(?i)\bEND_FUNCTION_BLOCK\b", code)]
    lexed = code[: ends[-1]] if ends else code
    for match in re.finditer(r"\d\.\.|\.\.\d|\.\.\s*\.\d|\(\s*\.\d|\s\.\d|\d\.(?![\d.])", lexed):
        line = text.count("\n", 0, match.start()) + 1
        found.add("jfl-rejects", "its lexer reads a number only with digits before '.' and '..' "
                  "between spaces", m.Span(line, 1))  # fmt: skip
    for fb in doc.blocks:
        _block(fb, found, lines)
    return found.diagnostics()


def _code(text: str) -> str:
    """``text`` with comments blanked (same length, so offsets keep their lines)."""

    def blank(match: re.Match[str]) -> str:
        return re.sub(r"[^\n]", " ", match.group(0))

    return re.sub(r"\(\*.*?\*\)|/\*.*?\*/|//[^\n]*", blank, text, flags=re.DOTALL)


def _written(lines: list[str], span: m.Span | None) -> str:
    """The word after ':' (or ':=') of a one-line item such as ``ACCU : MAX;``."""
    if span is None or not 0 < span.line <= len(lines):
        return ""
    match = re.match(r"\s*\w+\s*:=?\s*(\w+)", lines[span.line - 1][span.column - 1 :])
    return match.group(1).upper() if match else ""


def _block(fb: m.FunctionBlock, found: _Found, lines: list[str]) -> None:
    rejects = "jfl-rejects"
    for v in fb.variables:
        if v.kind.value == "VAR":
            found.add(rejects, f"it has no local VAR declarations ({v.name})", v.span)
        elif v.range is not None:
            found.add("jfl-differs", f"a RANGE on the declaration of {v.name} is ignored", v.range.span)
        if v.initial is not None:
            found.add(rejects, f"its grammar has no initial value ({v.name} := ...)", v.span)
        if v.data_type.upper() != "REAL":
            found.add(rejects, f"its only data type is REAL ({v.name} : {v.data_type})", v.span)
        _name(v.name, "variable", v.span, found)
    if fb.name and not _ID.fullmatch(fb.name):
        found.add(rejects, f"function block name {fb.name!r} is not one of its identifiers", fb.span)
    with_terms = {b.variable for b in fb.fuzzify} | {b.variable for b in fb.defuzzify}
    for v in fb.variables:
        if v.name not in with_terms:
            found.add(
                "jfl-differs",
                f"{v.name} has no FUZZIFY or DEFUZZIFY block: jFuzzyLogic ignores VAR declarations, so "
                "it has no such variable (setting or reading it fails)",
                v.span,
            )
    defined: set[str] = set()
    blocks: list[m.FuzzifyBlock | m.DefuzzifyBlock] = [*fb.fuzzify, *fb.defuzzify]
    for block in sorted(blocks, key=lambda b: b.span.line if b.span else 0):
        kind = "FUZZIFY" if isinstance(block, m.FuzzifyBlock) else "DEFUZZIFY"
        if isinstance(block, m.FuzzifyBlock) and block.range is not None:
            found.add(rejects, "its grammar has no RANGE in FUZZIFY", block.range.span)
        if isinstance(block, m.DefuzzifyBlock):
            db = block
            if db.accu is not None:
                found.add(rejects, "ACCU belongs in the RULEBLOCK, not in DEFUZZIFY", db.item_span("accu"))
            method = _written(lines, db.item_span("method")) if db.method else "COG"
            if method and method not in _METHODS:
                found.add(rejects, f"it has no METHOD {method}", db.item_span("method"))
            d = db.default
            nan = d is not None and (d.value is not None and d.value != d.value)  # nan, nan | NC
            if nan:
                found.add(rejects, "DEFAULT takes a number or NC, not nan", db.item_span("default"))
            if db.clamp:
                found.add(rejects, "it has no lock-range", db.span)
        _name(block.variable, kind, block.span, found)
        for t in block.terms:
            _name(t.name, "term", t.span, found)
            for ref in _refs(t.mf):
                if ref not in defined:
                    found.add(
                        rejects,
                        f"term {t.name} reads {ref}, which no FUZZIFY or DEFUZZIFY block above defines "
                        "(it only knows variables from those blocks)",
                        t.span,
                    )
            if isinstance(t.mf, m.SingletonsMF):
                found.add(rejects, f"term {t.name}: its parser fails on SINGLETONS terms", t.span)
            if isinstance(t.mf, m.ShapeMF) and t.mf.height != 1.0:
                found.add(rejects, f"term {t.name}: its shapes have no height parameter", t.span)
            if isinstance(t.mf, m.FunctionMF):
                calls = {n.function.upper() for n in m.walk_expr(t.mf.expr) if isinstance(n, m.Call)}
                for call in sorted(calls - _FUNCTIONS):
                    found.add(rejects, f"term {t.name}: it has no function {call.lower()}", t.span)
        defined.add(block.variable)
    for rb in fb.rule_blocks:
        if rb.name is None:
            found.add(rejects, "a RULEBLOCK needs a name", rb.span)
        elif not _ID.fullmatch(rb.name):
            found.add(rejects, f"rule block name {rb.name!r} is not one of its identifiers", rb.span)
        for key, words in (("and_op", _AND), ("or_op", _OR), ("act", _ACT), ("accu", _ACCU)):
            if getattr(rb, key) is not None:
                w = _written(lines, rb.item_span(key))
                if w and w not in words:
                    label = key.replace("_op", "").upper()
                    found.add(rejects, f"it has no {label} : {w}", rb.item_span(key))
        if rb.rule_activation is not None or not rb.enabled:
            found.add(rejects, "it has no rule activation methods", rb.span)
        for rule in rb.rules:
            _rule(rule, found)


def _rule(rule: Any, found: _Found) -> None:
    rejects = "jfl-rejects"
    if rule.condition is None:
        found.add(rejects, f"RULE {rule.label} has no condition", rule.span)
    for c in m.walk_condition(rule.condition):
        if isinstance(c, m.Degree):
            found.add(rejects, f"RULE {rule.label}: a bare variable is not a condition", c.span)
        elif c.hedges:
            found.add(rejects, f"RULE {rule.label}: it has no hedges", c.span)
    if rule.weight is not None:
        found.add(rejects, f"RULE {rule.label}: it has no rule weight", rule.span)
    weights = [c.weight for c in rule.conclusions]
    for i, c in enumerate(rule.conclusions):
        if c.term is None:
            found.add(rejects, f"RULE {rule.label}: a conclusion needs IS and a term", c.span)
        if c.hedges:
            found.add(rejects, f"RULE {rule.label}: it has no hedges", c.span)
        if c.weight is not None and (i < len(weights) - 1 or isinstance(c.weight, m.Ref)):
            found.add(rejects, f"RULE {rule.label}: WITH takes a number and ends the rule", c.span)


def _name(name: str, what: str, span: m.Span | None, found: _Found) -> None:
    if not _ID.fullmatch(name):
        found.add("jfl-rejects", f"{what} name {name!r} is not one of its identifiers", span)
    elif name.upper() in _KEYWORDS:
        found.add("jfl-rejects", f"{what} name {name} is one of its keywords", span)


def _refs(mf: object) -> list[str]:
    if isinstance(mf, m.PointsMF | m.SingletonsMF):
        return [p.name for pt in mf.points for p in (pt.x, pt.y) if isinstance(p, m.Ref)]
    if isinstance(mf, m.SingletonMF):
        return [mf.value.name] if isinstance(mf.value, m.Ref) else []
    if isinstance(mf, m.ShapeMF):
        return [p.name for p in (*mf.params, mf.height) if isinstance(p, m.Ref)]
    if isinstance(mf, m.FunctionMF):
        return sorted({n.name for n in m.walk_expr(mf.expr) if isinstance(n, m.Name)} - {"x", "pi", "e"})
    return []
