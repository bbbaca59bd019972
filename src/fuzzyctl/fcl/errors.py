"""Syntax errors in words: lark's "unexpected token, expected one of ..." turned into a
diagnostic that names the real mistake (a missing ';' or END_VAR, an unclosed point, an
empty TERM) at the place where it was made."""

from __future__ import annotations

import re
from typing import Any

from lark import Token
from lark.exceptions import UnexpectedCharacters, UnexpectedEOF, UnexpectedInput, UnexpectedToken

from fuzzyctl.diagnostics import Diagnostic, error
from fuzzyctl.model import Span

# How each terminal is named in a message.
TERMINAL_NAMES: dict[str, str] = {
    "SEMI": "';'",
    "SEMICOLON": "';'",
    "COLON": "':'",
    "COMMA": "','",
    "LPAR": "'('",
    "RPAR": "')'",
    "ASSIGN": "':='",
    "EQUAL": "'='",
    "VBAR": "'|'",
    "RANGE_DOTS": "'..'",
    "NUMBER": "a number",
    "ID": "a name",
    "FB_NAME": "a function block name",
    "RULE_LABEL": "a rule number",
    "OPTIONS_BODY": "option text",
    "PLUS": "'+'",
    "MINUS": "'-'",
    "STAR": "'*'",
    "SLASH": "'/'",
    "PERCENT": "'%'",
    "HAT": "'^'",
    "$END": "the end of the file",
}

# Block keyword -> the keyword that closes it.
CLOSERS: dict[str, str] = {
    "FUNCTION_BLOCK": "END_FUNCTION_BLOCK",
    "VAR_INPUT": "END_VAR",
    "VAR_OUTPUT": "END_VAR",
    "VAR": "END_VAR",
    "FUZZIFY": "END_FUZZIFY",
    "DEFUZZIFY": "END_DEFUZZIFY",
    "RULEBLOCK": "END_RULEBLOCK",
    "OPTIONS": "END_OPTIONS",
    "OPTION": "END_OPTION",
}
_STATEMENTS = ("TERM", "RANGE", "METHOD", "DEFAULT", "ACCU", "ACT", "AND", "OR", "RULE")
_MF_START = {"LPAR", "NUMBER", "ID", "FUNCTION"}
_OPERATOR_WORDS = {"MIN", "MAX", "PROD", "ASUM", "BSUM", "BDIF", "PROBOR", "NSUM"}


def describe(terminal: str) -> str:
    return TERMINAL_NAMES.get(terminal, terminal)


def _shown(tok: Token) -> str:
    if tok.type == "$END":
        return "the end of the file"
    text = str(tok)
    return f"'{text}'" if len(text) <= 30 else f"'{text[:27]}...'"


def _stack(exc: UnexpectedInput) -> list[Any]:
    parser = getattr(exc, "interactive_parser", None)
    state = getattr(parser, "parser_state", None) or getattr(exc, "state", None)
    return list(getattr(state, "value_stack", []) or [])


def _open_block(stack: list[Any]) -> Token | None:
    """The innermost block keyword whose END has not been read yet."""
    open_blocks: list[Token] = []
    for item in stack:
        if not isinstance(item, Token):
            continue
        if item.type in CLOSERS:
            open_blocks.append(item)
        elif open_blocks and item.type == CLOSERS[open_blocks[-1].type]:
            open_blocks.pop()
    return open_blocks[-1] if open_blocks else None


def _statement(stack: list[Any]) -> Token | None:
    """The keyword that starts the statement being read (TERM, RULE, ...)."""
    for item in reversed(stack):
        if isinstance(item, Token):
            if item.type in _STATEMENTS:
                return item
            if item.type in CLOSERS:
                return None
    return None


def _end_of(tok: Token) -> Span:
    line = tok.end_line or tok.line or 1
    column = tok.end_column or ((tok.column or 1) + len(str(tok)))
    return Span(line, column)


def _at(tok: Token) -> Span:
    return Span(tok.line or 1, tok.column or 1, tok.end_line, tok.end_column)


def syntax_diagnostic(exc: UnexpectedInput, state: Any) -> Diagnostic:
    """One diagnostic for a lark syntax error, worded for a control engineer."""
    path = state.source.path
    source_text: str = state.source.text
    lines = source_text.splitlines()

    def make(message: str, span: Span, hint: str | None = None, code: str = "syntax") -> Diagnostic:
        return error(message, span, code=code, file=path, hint=hint)

    if isinstance(exc, UnexpectedCharacters):
        pos = exc.pos_in_stream or 0
        char = source_text[pos] if 0 <= pos < len(source_text) else ""
        span = Span(exc.line, exc.column)
        if source_text.startswith("(*", pos) or source_text.startswith("/*", pos):
            return make("comment is never closed", span, "close it with " + ("*)" if char == "(" else "*/"))
        shown = repr(char) if char.isprintable() and char != "'" else f"U+{ord(char):04X}" if char else "?"
        return make(f"unexpected character {shown}", span)

    stack = _stack(exc)
    if isinstance(exc, UnexpectedEOF) or (isinstance(exc, UnexpectedToken) and exc.token.type == "$END"):
        opener = _open_block(stack)
        last = len(lines) or 1
        span = Span(last, max(len(lines[-1]) if lines else 1, 1))
        if opener is not None:
            return make(
                f"unexpected end of file: {opener.type} (line {opener.line}) is not closed",
                span,
                f"add {CLOSERS[opener.type]}",
                code="unclosed-block",
            )
        return make("unexpected end of file", span)

    assert isinstance(exc, UnexpectedToken)
    tok: Token = exc.token
    expected: set[str] = set(exc.expected)
    prev: Token | None = state.prev_token if state.last_token is tok else state.last_token
    history = getattr(exc, "token_history", None)
    if history and history[-1] is not None:
        prev = history[-1]
    opener = _open_block(stack)
    statement = _statement(stack)
    start = tok.start_pos
    if start is not None and (source_text.startswith("(*", start) or source_text.startswith("/*", start)):
        closer = "*)" if source_text.startswith("(*", start) else "*/"
        return make("comment is never closed", _at(tok), f"close it with {closer}", code="unclosed-comment")

    # An empty TERM x := ;
    in_term = statement is not None and statement.type == "TERM"
    if (
        expected & _MF_START
        and "ASSIGN" not in expected
        and in_term
        and prev is not None
        and prev.type == "ASSIGN"
    ):
        term_name = _term_name(stack)
        return make(
            f"TERM {term_name} has no membership function after ':='".replace("TERM  ", "TERM "),
            _end_of(prev),
            "give points (x, y) ..., a singleton value or a shape",
            code="empty-term",
        )

    # A ';' missing at the end of a line (often swallowed by a // comment).
    if (
        ("SEMI" in expected or "SEMICOLON" in expected)
        and prev is not None
        and (tok.line or 0) > (prev.end_line or prev.line or 0)
    ):
        where = _end_of(prev)
        line_text = lines[where.line - 1] if 0 < where.line <= len(lines) else ""
        what = f" after {statement.type}" if statement is not None else ""
        hint = None
        comment = re.search(r"//.*;|\(\*.*;.*\*\)|/\*.*;.*\*/", line_text)
        if comment:
            hint = (
                f"the ';' on line {where.line} is inside a comment, "
                f"which starts at column {comment.start() + 1}"
            )
        return make(
            f"missing ';'{what} at the end of line {where.line}", where, hint, code="missing-semicolon"
        )

    # A block keyword or the END of an outer block while an inner block is open.
    if opener is not None:
        closer = CLOSERS[opener.type]
        if closer in expected and tok.type != closer and (tok.type in CLOSERS or tok.type.startswith("END_")):
            return make(
                f"missing {closer} before {tok.type}: {opener.type} (line {opener.line}) is not closed",
                _at(tok),
                code="unclosed-block",
            )

    # A point (x, y) not closed: (3, 0 (27, 1)
    if "RPAR" in expected and prev is not None and statement is not None and statement.type == "TERM":
        opening = _open_paren(stack)
        opened = f" opened at column {opening.column}" if opening is not None else ""
        return make(
            f"missing ')' to close the point{opened}",
            _end_of(prev) if tok.type == "LPAR" else _at(tok),
            code="unclosed-point",
        )

    # An identifier with a space in it: "diff y : REAL;"
    if tok.type == "ID" and prev is not None and prev.type == "ID" and "COLON" in expected:
        return make(
            f"unexpected {_shown(tok)}: a name cannot contain spaces ('{prev} {tok}')",
            _at(tok),
            "FCL identifiers are letters, digits and '_': write " + f"{prev}_{tok}",
            code="space-in-name",
        )

    if tok.type == "TERM" and opener is not None and opener.type == "FUNCTION_BLOCK":
        return make(
            "TERM outside a FUZZIFY or DEFUZZIFY block",
            _at(tok),
            _hidden_header(state, tok),
            code="term-outside-block",
        )

    if tok.type == "ID" and str(tok).upper() in _OPERATOR_WORDS and expected & {"AND", "OR"}:
        return make(
            f"unexpected {_shown(tok)} in a condition: {str(tok).upper()} is an algorithm, not an operator",
            _at(tok),
            "combine subconditions with AND, OR or NOT; choose the algorithm in the RULEBLOCK "
            f"(e.g. OR : {str(tok).upper()};)",
        )

    if not stack and tok.type != "FUNCTION_BLOCK":
        return make(
            f"{_shown(tok)} outside a FUNCTION_BLOCK: an FCL file is made of "
            "FUNCTION_BLOCK ... END_FUNCTION_BLOCK",
            _at(tok),
            code="outside-block",
        )

    wanted = ", ".join(sorted(describe(t) for t in expected if not t.startswith("__")))
    context = f" in {statement.type}" if statement is not None else f" in {opener.type}" if opener else ""
    return make(f"unexpected {_shown(tok)}{context}; expected {wanted}", _at(tok))


def _term_name(stack: list[Any]) -> str:
    for i in range(len(stack) - 1, -1, -1):
        item = stack[i]
        if isinstance(item, Token) and item.type == "TERM":
            nxt = stack[i + 1] if i + 1 < len(stack) else None
            return str(nxt) if isinstance(nxt, Token) else ""
    return ""


def _open_paren(stack: list[Any]) -> Token | None:
    for item in reversed(stack):
        if isinstance(item, Token) and item.type == "LPAR":
            return item
    return None


def _hidden_header(state: Any, tok: Token) -> str | None:
    """A block comment just before ``tok`` that swallowed a FUZZIFY/DEFUZZIFY header."""
    for c in reversed(state.comments):
        if c.line > (tok.line or 0):
            continue
        match = re.search(r"\b(DEFUZZIFY|FUZZIFY)\s+\w+", c.text, re.IGNORECASE)
        if match:
            return (
                f"the comment starting on line {c.line} contains '{match.group(0)}': "
                "the block header is commented out"
            )
        break
    return None
