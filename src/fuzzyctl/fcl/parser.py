"""FCL text to :class:`fuzzyctl.model.Document`.

The grammar is ``fcl.lark`` (LALR(1), contextual lexer); a parse-time transformer builds the
immutable model directly, so no intermediate tree is kept (the 290 KB corpus file parses in
a fraction of a second).  Problems that the grammar accepts but the model cannot take (an
unknown METHOD keyword, a shape with the wrong number of parameters) become diagnostics;
syntax errors are translated into human messages by :mod:`fuzzyctl.fcl.errors`.
"""

from __future__ import annotations

import math
import re
import textwrap
import threading
from collections.abc import Sequence
from dataclasses import dataclass, field, replace
from functools import cache
from typing import Any, cast

from lark import Lark, Token, Transformer
from lark.exceptions import UnexpectedInput, VisitError

from fuzzyctl import model as m
from fuzzyctl.diagnostics import Diagnostic, Severity, error, warning
from fuzzyctl.fcl import keywords, shapes
from fuzzyctl.fcl.fast import FastResult
from fuzzyctl.fcl.fast_blocks import merge_blocks, merge_decls, read_blocks
from fuzzyctl.fcl.grammar import cached_lark, terminal_names
from fuzzyctl.fcl.names import resolve_names
from fuzzyctl.fcl.source import Source
from fuzzyctl.limits import MAX_NESTING, shorten

_MINUS_SIGNS = str.maketrans({"\u2212": "-", "\u2013": "-"})


def _between(first: Any, last: Any) -> m.Span | None:
    """The span from the start of ``first`` to the end of ``last`` (tokens or model
    objects with a span); ``None`` when a position is unknown."""
    a = _start(first)
    b = _end(last)
    if a is None:
        return None
    if b is None:
        return a
    return m.Span(a.line, a.column, b.end_line, b.end_column)


def _start(obj: Any) -> m.Span | None:
    if isinstance(obj, Token):
        return _tok_span(obj)
    span = getattr(obj, "span", None)
    return span if isinstance(span, m.Span) else None


def _end(obj: Any) -> m.Span | None:
    return _start(obj)


def _outer(children: Sequence[Any]) -> m.Span | None:
    located = [c for c in children if _start(c) is not None]
    return _between(located[0], located[-1]) if located else None


def _tok_span(tok: Token) -> m.Span:
    return m.Span(tok.line or 0, tok.column or 0, tok.end_line, tok.end_column)


def _number(tok: Token) -> float:
    return float(str(tok).translate(_MINUS_SIGNS))


def _tokens(children: Sequence[Any], *types: str) -> list[Token]:
    return [c for c in children if isinstance(c, Token) and c.type in types]


@dataclass
class _Item:
    """A single-valued statement inside a block (METHOD, ACCU, AND, ...)."""

    key: str
    value: Any
    span: m.Span


@dataclass
class _Decls:
    names: list[tuple[str, m.Span]]
    data_type: str
    initial: float | bool | str | None
    range: m.Range | None
    span: m.Span | None


@dataclass
class _Function:
    """A FUNCTION term before its source text is known (the TERM's ';' ends it)."""

    expr: m.Expr
    start: int


@dataclass
class _Comment:
    text: str
    line: int
    column: int
    end_line: int


@dataclass
class ParseState:
    """What the transformer learns while building the model."""

    source: Source
    diagnostics: list[Diagnostic] = field(default_factory=list)
    comments: list[_Comment] = field(default_factory=list)
    prev_token: Token | None = None
    last_token: Token | None = None
    # How each shape was spelled, for the conformance report (kind -> spellings).
    spellings: set[str] = field(default_factory=set)
    # Statements read by the fast reader (fuzzyctl.fcl.fast), merged into their blocks.
    fast: FastResult | None = None

    def fast_items(self, children: Sequence[Any], items: list[Any]) -> list[Any]:
        """``items`` of the block made of ``children`` (its opening keyword first, its END
        last) with the statements the fast reader took from the same block, in source order."""
        fast = self.fast
        if fast is None or not children:
            return items
        first, last = children[0], children[-1]
        if not isinstance(first, Token) or not isinstance(last, Token):
            return items
        got = fast.between(first.start_pos or 0, last.start_pos or 0)
        if not got:
            return items
        merged = items + [item for _offset, item, _spelling in got]
        merged.sort(key=lambda x: (x.span.line, x.span.column))
        return merged

    def error(self, message: str, span: m.Span | None, code: str, hint: str | None = None) -> None:
        self.diagnostics.append(error(message, span, code=code, file=self.source.path, hint=hint))

    def warn(self, message: str, span: m.Span | None, code: str, hint: str | None = None) -> None:
        self.diagnostics.append(warning(message, span, code=code, file=self.source.path, hint=hint))

    def note(self, message: str, span: m.Span | None, code: str) -> None:
        self.diagnostics.append(Diagnostic(Severity.NOTE, message, span, self.source.path, code))


class _Builder(Transformer[Token, Any]):
    """Builds model objects while LALR reduces (see ``Lark(transformer=...)``)."""

    def __init__(self, state: ParseState) -> None:
        super().__init__(visit_tokens=False)
        self.state = state

    # ---------------------------------------------------------------- parameters
    def number(self, children: list[Token]) -> float:
        return _number(children[0])

    def ref(self, children: list[Token]) -> m.Ref:
        return m.Ref(str(children[0]), _tok_span(children[0]))

    def point(self, children: list[m.Param]) -> m.Point:
        return m.Point(children[1], children[2], _outer(children))

    # ---------------------------------------------------------------- membership functions
    def points(self, children: list[m.Point]) -> m.PointsMF:
        return m.PointsMF(tuple(children))

    def singleton(self, children: list[m.Param]) -> m.SingletonMF:
        return m.SingletonMF(children[0])

    def shape(self, children: list[Any]) -> m.MembershipFunction:
        name_tok: Token = children[0]
        args: list[m.Param] = children[1:]
        name = str(name_tok)
        if name.upper() == "DISCRETE":
            # fuzzylite's Discrete x1 y1 x2 y2 ... is the IEC point list.
            if len(args) % 2 or not args:
                self.state.error(
                    f"Discrete takes pairs of values x y, got {len(args)} values",
                    _tok_span(name_tok),
                    "shape-arity",
                )
                return m.PointsMF(())
            self.state.spellings.add("Discrete")
            return m.PointsMF(tuple(m.Point(args[i], args[i + 1]) for i in range(0, len(args), 2)))
        spelling = shapes.lookup(name)
        if spelling is None:
            self.state.error(
                f"unknown membership function '{name}'",
                _tok_span(name_tok),
                "unknown-shape",
                hint="known shapes: " + ", ".join(s.written for s in shapes.SPELLINGS),
            )
            return m.PointsMF(())
        self.state.spellings.add(spelling.written)
        try:
            return shapes.build(spelling, args)
        except shapes.ShapeError as exc:
            self.state.error(str(exc), _outer(children), "shape-arity")
            return m.PointsMF(())

    def singletons(self, children: list[Any]) -> m.MembershipFunction:
        name_tok: Token = children[0]
        if str(name_tok).upper() != "SINGLETONS":
            self.state.error(
                f"unknown membership function '{name_tok}' followed by points",
                _tok_span(name_tok),
                "unknown-shape",
                hint="a list of points is written without a name: TERM t := (0, 0) (1, 1);"
                " jFuzzyLogic's discrete singletons are SINGLETONS (x, y) ...",
            )
            return m.PointsMF(())
        self.state.spellings.add("SINGLETONS")
        return m.SingletonsMF(tuple(children[1:]))

    def function(self, children: list[Any]) -> _Function:
        self.state.spellings.add("FUNCTION")
        return _Function(children[1], children[0].end_pos or 0)

    # ---- expressions
    def num(self, children: list[Token]) -> m.Num:
        return m.Num(_number(children[0]))

    def expr_name(self, children: list[Token]) -> m.Name:
        return m.Name(str(children[0]))

    def name(self, children: list[Token]) -> Token:
        if len(children) == 1:
            return children[0]
        first, last = children[0], children[-1]
        text = " ".join(str(t) for t in children)
        self.state.warn(
            f"name of several words '{text}' (ridderware JFuzzy); FCL identifiers have no spaces",
            _between(first, last),
            "multiword-name",
        )
        return Token(
            "ID",
            text,
            start_pos=first.start_pos,
            line=first.line,
            column=first.column,
            end_line=last.end_line,
            end_column=last.end_column,
            end_pos=last.end_pos,
        )

    def call(self, children: list[Any]) -> m.Call:
        return m.Call(str(children[0]).lower(), tuple(c for c in children[1:] if c is not None))

    def binary(self, children: list[Any]) -> m.Binary:
        return m.Binary(str(children[1]), children[0], children[2])

    def unary(self, children: list[Any]) -> m.Unary:
        return m.Unary(str(children[0]), children[1])

    # ---------------------------------------------------------------- terms and blocks
    def term(self, children: list[Any]) -> m.Term:
        name, mf, semi = children[1], children[2], children[3]
        fast = self.state.fast
        if fast is not None and isinstance(mf, m.SingletonMF) and fast.points:
            mf = fast.points_at(_tok_span(children[0])) or mf  # points the fast reader read
        span = _outer(children)
        if semi is None:
            end = m.Span(span.line, span.column) if span else None
            if isinstance(mf, _Function):  # its ';' is what ends the expression's text
                self.state.error(f"missing ';' at the end of FUNCTION TERM {name}", end, "missing-semicolon")
                return m.Term(str(name), m.FunctionMF(mf.expr, ""), span)
            self.state.warn(
                f"missing ';' at the end of TERM {name} (read as if it were there, as scalablurry does)",
                end,
                "missing-semicolon",
            )
        if isinstance(mf, _Function):
            text = self.state.source.text[mf.start : semi.start_pos]
            mf = m.FunctionMF(mf.expr, " ".join(text.split()))
        return m.Term(str(name), mf, span)

    def range_stmt(self, children: list[Any]) -> m.Range:
        low, high = (_number(t) for t in _tokens(children, "NUMBER"))
        span = _outer(children)
        if low > high:
            self.state.error(f"RANGE({low:g}..{high:g}): the minimum is above the maximum", span, "bad-range")
        elif low == high:
            self.state.warn(f"RANGE({low:g}..{high:g}) is empty", span, "empty-range")
        return m.Range(low, high, span)

    def _keyword_item(
        self, key: str, label: str, table: keywords.Synonyms, children: list[Any], tok: Token
    ) -> _Item:
        spelling = str(tok)
        span = _outer(children) or _tok_span(tok)
        if not _tokens(children, "SEMI"):
            end = m.Span(tok.end_line or 0, tok.end_column or 0)
            self.state.warn(f"missing ';' after {children[0].type} : {spelling}", end, "missing-semicolon")
        if spelling.upper() in keywords.NONE_SPELLINGS:
            return _Item(key, None, span)
        value = keywords.canonical(table, spelling)
        if value is None:
            known = sorted({canon for canon, _ in table.values()})
            self.state.error(
                f"unknown {label} '{spelling}'",
                _tok_span(tok),
                "unknown-keyword",
                hint="accepted: " + ", ".join(sorted(table)) + " (stored as " + ", ".join(known) + ")",
            )
        return _Item(key, value, span)

    def method_stmt(self, children: list[Token]) -> _Item:
        return self._keyword_item(
            "method", "defuzzification METHOD", keywords.METHOD_SYNONYMS, children, children[1]
        )

    def accu_stmt(self, children: list[Token]) -> _Item:
        return self._keyword_item(
            "accu", "accumulation method (ACCU)", keywords.ACCU_SYNONYMS, children, children[1]
        )

    def act_stmt(self, children: list[Token]) -> _Item:
        return self._keyword_item(
            "act", "activation method (ACT)", keywords.ACT_SYNONYMS, children, children[1]
        )

    def operator_stmt(self, children: list[Token]) -> _Item:
        if children[0].type == "AND":
            return self._keyword_item("and_op", "AND operator", keywords.AND_SYNONYMS, children, children[1])
        return self._keyword_item("or_op", "OR operator", keywords.OR_SYNONYMS, children, children[1])

    def default_value(self, children: list[Token]) -> m.Default:
        numbers = _tokens(children, "NUMBER")
        no_change = bool(_tokens(children, "NC"))
        value = _number(numbers[0]) if numbers else None
        return m.Default(value, no_change, _outer(children))

    def default_stmt(self, children: list[Any]) -> _Item:
        default: m.Default = next(c for c in children if isinstance(c, m.Default))
        span = _outer(children)
        if _tokens(children, "EQUAL"):
            self.state.warn(
                "DEFAULT written with '=': the standard writes DEFAULT := value;", span, "default-equal"
            )
        if not _tokens(children, "SEMI"):
            self.state.warn("missing ';' after DEFAULT", span, "missing-semicolon")
        return _Item("default", replace(default, span=span), span or m.Span(0, 0))

    def _items(self, children: list[Any], block: str, span: m.Span | None) -> dict[str, _Item]:
        items: dict[str, _Item] = {}
        for c in children:
            if isinstance(c, _Item):
                if c.key in items:
                    self.state.error(
                        f"{c.key.upper().replace('_OP', '')} given twice in this {block}",
                        c.span,
                        "duplicate-item",
                    )
                    continue
                items[c.key] = c
        return items

    def _terms_and_range(
        self, children: list[Any], block: str
    ) -> tuple[str, m.Span | None, tuple[m.Term, ...], m.Range | None]:
        """The name, span, terms and (one) RANGE of a FUZZIFY or DEFUZZIFY block."""
        name: Token = children[1]
        terms = tuple(self.state.fast_items(children, [c for c in children if isinstance(c, m.Term)]))
        ranges = [c for c in children if isinstance(c, m.Range)]
        if len(ranges) > 1:
            self.state.error(f"RANGE given twice in this {block} block", ranges[1].span, "duplicate-item")
        return str(name), _outer(children), terms, ranges[0] if ranges else None

    def fuzzify_block(self, children: list[Any]) -> m.FuzzifyBlock:
        name, span, terms, rng = self._terms_and_range(children, "FUZZIFY")
        return m.FuzzifyBlock(name, terms, rng, span)

    def defuzzify_block(self, children: list[Any]) -> m.DefuzzifyBlock:
        name, span, terms, rng = self._terms_and_range(children, "DEFUZZIFY")
        items = self._items(children, "DEFUZZIFY block", span)
        method = items.get("method")
        default = items.get("default")
        accu = items.get("accu")
        return m.DefuzzifyBlock(
            name,
            terms,
            rng,
            method.value if method else None,
            default.value if default else None,
            accu.value if accu else None,
            span,
            item_spans=tuple((k, v.span) for k, v in items.items()),
        )

    # ---------------------------------------------------------------- declarations
    def initial(self, children: list[Token]) -> float | bool | str:
        tok = children[0]
        if tok.type == "NUMBER":
            return _number(tok)
        text = str(tok)
        if text.upper() in ("TRUE", "FALSE"):
            return text.upper() == "TRUE"
        return text

    def var_decl(self, children: list[Any]) -> _Decls:
        ids = [c for c in children if isinstance(c, Token) and c.type == "ID"]
        initial = next(
            (c for c in children if isinstance(c, float | bool | str) and not isinstance(c, Token)), None
        )
        rng = next((c for c in children if isinstance(c, m.Range)), None)
        names = [(str(t), _tok_span(t)) for t in ids[:-1]]
        return _Decls(names, str(ids[-1]).upper(), initial, rng, _outer(children))

    def var_block(self, children: list[Any]) -> list[m.Variable]:
        kind = m.VarKind(str(children[0].type))
        out: list[m.Variable] = []
        for decls in children:
            if not isinstance(decls, _Decls):
                continue
            for name, span in decls.names:
                where = span if len(decls.names) > 1 else decls.span
                out.append(m.Variable(name, kind, decls.data_type, decls.initial, decls.range, where))
        if self.state.fast is not None and self.state.fast.decls:
            merge_decls(self.state.fast, children, out)
        return out

    # ---------------------------------------------------------------- rules
    def is_condition(self, children: list[Token]) -> m.Is:
        ids = _tokens(children, "ID")
        negated = bool(_tokens(children, "NOT"))
        return m.Is(str(ids[0]), str(ids[-1]), negated, tuple(str(t) for t in ids[1:-1]), _outer(children))

    def degree_condition(self, children: list[Token]) -> m.Degree:
        return m.Degree(str(children[0]), _outer(children))

    def negation(self, children: list[Any]) -> m.Not:
        return m.Not(children[1], _outer(children))

    def group(self, children: list[Any]) -> m.Condition:
        inner: m.Condition = children[0]
        if isinstance(inner, m.And | m.Or):
            inner = replace(inner, grouped=True)  # for jFuzzyLogic's left-to-right reading
        return inner

    def and_condition(self, children: list[Any]) -> m.And:
        return m.And(tuple(c for c in children if not isinstance(c, Token)), _outer(children))

    def or_condition(self, children: list[Any]) -> m.Or:
        return m.Or(tuple(c for c in children if not isinstance(c, Token)), _outer(children))

    def conclusion(self, children: list[Any]) -> m.Conclusion:
        ids = _tokens(children, "ID")
        weight = next((c for c in children if not isinstance(c, Token)), None)
        term = str(ids[-1]) if len(ids) > 1 else None
        hedges = tuple(str(t) for t in ids[1:-1])
        return m.Conclusion(str(ids[0]), term, weight, _outer(children), hedges)

    def paren_conclusion(self, children: list[Any]) -> m.Conclusion:
        made = self.conclusion(children)
        self.state.warn(
            f"parentheses around a subconclusion are not FCL (5.4.1); read as {made.variable} IS {made.term}",
            made.span,
            "paren-conclusion",
        )
        return made

    def conclusions(self, children: list[Any]) -> tuple[m.Conclusion, ...]:
        return tuple(c for c in children if isinstance(c, m.Conclusion))

    def rule(self, children: list[Any]) -> m.Rule:
        from fuzzyctl.limits import MAX_NESTING, depth

        label: Token = children[1]
        condition: m.Condition | None = next(
            c for c in children if isinstance(c, m.Is | m.Degree | m.Not | m.And | m.Or)
        )
        conclusions = next(c for c in children if isinstance(c, tuple))
        span = _outer(children)
        fast = self.state.fast
        found = None
        if fast is not None and isinstance(condition, m.Degree) and condition.variable == "_":
            found = fast.condition_at(condition.span)  # a condition the fast reader read
        if found is not None:
            condition, d = found
        else:
            d = depth(condition)
        if d > MAX_NESTING:
            # refused here: every later step walks conditions recursively
            self.state.error(
                f"rule {label}: the condition nests {d} levels deep (the limit is {MAX_NESTING})",
                span or _tok_span(label),
                "too-deep",
            )
            condition = None
        return m.Rule(str(label), condition, conclusions, span)

    def rule_block(self, children: list[Any]) -> m.RuleBlock:
        name = next((str(c) for c in children if isinstance(c, Token) and c.type == "ID"), None)
        span = _outer(children)
        items = self._items(children, "RULEBLOCK", span)

        def value(key: str) -> str | None:
            item = items.get(key)
            return item.value if item else None

        return m.RuleBlock(
            name,
            tuple(self.state.fast_items(children, [c for c in children if isinstance(c, m.Rule)])),
            value("and_op"),
            value("or_op"),
            value("act"),
            value("accu"),
            span,
            item_spans=tuple((k, v.span) for k, v in items.items()),
        )

    def options_block(self, children: list[Token]) -> m.OptionsBlock:
        body = _tokens(children, "OPTIONS_BODY")
        text = textwrap.dedent(str(body[0])).strip() if body else ""
        return m.OptionsBlock(text, str(children[0].type), _outer(children))

    # ---------------------------------------------------------------- function blocks
    def fb_name(self, children: list[Token]) -> str:
        return str(children[0])

    def function_block(self, children: list[Any]) -> m.FunctionBlock:
        name = next((c for c in children if isinstance(c, str) and not isinstance(c, Token)), None)
        if self.state.fast is not None and self.state.fast.blocks:
            children = merge_blocks(self.state.fast, children)
        variables: list[m.Variable] = []
        for c in children:
            if isinstance(c, list):
                variables.extend(c)
        fb = m.FunctionBlock(
            name,
            tuple(variables),
            tuple(c for c in children if isinstance(c, m.FuzzifyBlock)),
            tuple(c for c in children if isinstance(c, m.DefuzzifyBlock)),
            tuple(c for c in children if isinstance(c, m.RuleBlock)),
            tuple(c for c in children if isinstance(c, m.OptionsBlock)),
            _outer(children),
        )
        return resolve_names(fb, lambda message, span, code: self.state.warn(message, span, code))

    def start(self, children: list[m.FunctionBlock]) -> m.Document:
        return m.Document(tuple(children), self.state.source.path)


_COMMENT_TYPES = ("COMMENT_IEC", "COMMENT_C", "COMMENT_LINE")
_ACTIVE: list[ParseState] = []
_LOCK = threading.RLock()


def _on_comment(tok: Token) -> Token:
    if _ACTIVE:
        _ACTIVE[-1].comments.append(_Comment(str(tok), tok.line or 0, tok.column or 0, tok.end_line or 0))
    return tok


def _on_token(tok: Token) -> Token:
    if _ACTIVE:
        state = _ACTIVE[-1]
        state.prev_token, state.last_token = state.last_token, tok
        if tok.type == "NUMBER" and tok[-1:].isdigit() and not math.isfinite(_number(tok)):
            # 1e400 or 5001 digits: Python reads it as inf, which the file did not say
            message = f"the number {shorten(tok)} is too large (beyond 1.8e308)"
            state.error(message, _tok_span(tok), "number-range")
    return tok


@cache
def _parser() -> Lark:
    """The one LALR parser of this process.  Its tables are computed once per grammar and
    lark version and kept in the cache directory (lark's ``cache``); a process only loads
    them.  The transformer is swapped per parse (see parse_source)."""
    callbacks: dict[str, Any] = {name: _on_comment for name in _COMMENT_TYPES}
    callbacks.update({name: _on_token for name in terminal_names() if name not in (*_COMMENT_TYPES, "WS")})
    return cached_lark(
        maybe_placeholders=True,
        lexer_callbacks=callbacks,
        transformer=_Builder(ParseState(Source(""))),
    )


@dataclass
class ParseResult:
    """The document (``None`` after a syntax error) and every diagnostic found."""

    document: m.Document | None
    diagnostics: list[Diagnostic]
    source: Source
    spellings: frozenset[str] = frozenset()


def parse_source(source: Source, *, fast: bool = True) -> ParseResult:
    """Parse decoded FCL text; never raises for bad input.  ``fast``: runs of plain RULE
    and TERM statements are read by :mod:`fuzzyctl.fcl.fast` (the same model; ``False``
    reads everything with lark)."""
    from fuzzyctl.fcl.errors import syntax_diagnostic

    state = ParseState(source)
    state.fast = read_blocks(source.text) if fast else None
    text = state.fast.text if state.fast is not None else source.text
    if _paren_run(state, text):
        return ParseResult(None, state.diagnostics, source)
    lark = _parser()
    builder = lark.options.transformer
    assert isinstance(builder, _Builder)
    # One parser and one builder serve every parse; the lock keeps parses from mixing states.
    _LOCK.acquire()
    builder.state = state
    _ACTIVE.append(state)
    try:
        document: m.Document | None = cast(m.Document, lark.parse(text))
        _merge_comments(state, None)
    except UnexpectedInput as exc:
        recovered = _recover(lark, state, exc, text)
        if recovered is None:
            _merge_comments(state, _error_pos(exc))
            state.diagnostics.insert(0, syntax_diagnostic(exc, state))
            document = None
        else:
            document = recovered
    except VisitError as exc:  # pragma: no cover - a bug in the builder
        raise exc.orig_exc from exc
    finally:
        _ACTIVE.pop()
        _LOCK.release()
    if document is not None and not document.blocks:
        state.error("no FUNCTION_BLOCK in this file", m.Span(1, 1), "no-function-block")
        document = None
    if document is not None:
        from fuzzyctl.fcl.comments import attach_comments

        document = attach_comments(document, state.comments, source.text)
    return ParseResult(document, state.diagnostics, source, frozenset(state.spellings))


#: Parentheses open in a row that lark is given at most.  The fast reader takes a condition
#: of any number of redundant parentheses; one it does not take (unbalanced, say) is left to
#: lark, whose error recovery over a million of them took 10 s and 500 MB.
MAX_PAREN_RUN = 100_000
_PAREN_RUN = re.compile(rf"(?:\((?!\*)[ \t\r\n\f]*){{{MAX_PAREN_RUN + 1}}}+")
_PARENS = re.compile(r"(?:\((?!\*)[ \t\r\n\f]*)++")


def _paren_run(state: ParseState, text: str) -> bool:
    """Refuse (True, with a diagnostic at its first one) a run of more than
    :data:`MAX_PAREN_RUN` opening parentheses left for lark to read."""
    found = _PAREN_RUN.search(text)
    if found is None:
        return False
    start = found.start()
    count = _PARENS.match(text, start).group().count("(")  # type: ignore[union-attr]
    line = text.count("\n", 0, start) + 1
    column = start - text.rfind("\n", 0, start)
    state.error(
        f"{count:,} parentheses open in a row: fuzzyctl reads at most {MAX_PAREN_RUN:,} "
        f"(a condition nests at most {MAX_NESTING} levels)",
        m.Span(line, column, line, column + 1),
        "too-deep",
    )
    return True


def _error_pos(exc: UnexpectedInput) -> int | None:
    token = getattr(exc, "token", None)
    if isinstance(token, Token) and token.type != "$END":
        return token.start_pos
    pos = getattr(exc, "pos_in_stream", None)
    return pos if isinstance(pos, int) else None


def _merge_comments(state: ParseState, end: int | None) -> None:
    """The comments and shape spellings of the text the fast reader took (before ``end``)
    among lark's."""
    if state.fast is None:
        return
    state.spellings.update(state.fast.spellings_before(end))
    extra = state.fast.comments_before(end)
    if extra:
        state.comments.extend(_Comment(c.text, c.line, c.column, c.end_line) for c in extra)
        state.comments.sort(key=lambda c: (c.line, c.column))


# The comment terminals of fcl.lark, to find the comments of text lark does not read.
_COMMENTS = re.compile(r"\(\*.*?\*\)|/\*.*?\*/|//[^\r\n]*", re.S)


def _ignored_comments(state: ParseState, pos: int) -> None:
    """The comments of the text after the last END_FUNCTION_BLOCK, which is ignored: kept
    (after the last block), so that ``fmt`` drops no comment with it."""
    text = state.source.text
    # line and line start counted on from one comment to the next (linear in the text)
    line, at, start = text.count("\n", 0, pos) + 1, pos, text.rfind("\n", 0, pos) + 1
    for hit in _COMMENTS.finditer(text, pos):
        line += text.count("\n", at, hit.start())
        start = max(start, text.rfind("\n", at, hit.start()) + 1)
        at = hit.start()
        state.comments.append(_Comment(hit.group(0), line, at - start + 1, line + hit.group(0).count("\n")))
        line += hit.group(0).count("\n")
        start = max(start, text.rfind("\n", at, hit.end()) + 1)
        at = hit.end()


def _recover(lark: Lark, state: ParseState, exc: UnexpectedInput, text: str) -> m.Document | None:
    """Text after the last END_FUNCTION_BLOCK is ignored with a warning (jFuzzyLogic's
    ANTLR grammar stops there too); any other syntax error is not recovered.  ``text`` is
    what lark reads (see parse_source)."""
    from lark.exceptions import UnexpectedToken

    if not isinstance(exc, UnexpectedToken) or exc.expected - {"FUNCTION_BLOCK", "$END"}:
        return None
    pos = exc.token.start_pos
    if pos is None or "END_FUNCTION_BLOCK" not in state.source.text[:pos].upper():
        return None
    state.diagnostics.clear()
    state.comments.clear()
    state.spellings.clear()
    try:
        document = cast(m.Document, lark.parse(text[:pos]))
    except UnexpectedInput:
        return None
    _merge_comments(state, pos)
    _ignored_comments(state, pos)
    state.warn(
        "text after END_FUNCTION_BLOCK is ignored",
        m.Span(exc.token.line or 0, exc.token.column or 0),
        "trailing-text",
    )
    return document
