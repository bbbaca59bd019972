"""Arithmetic expressions of fuzzylite ``Function`` terms, to and from the model's Expr.

Grammar (fuzzylite's infix notation): numbers, names, calls ``f(a, b)``, unary ``-``/``+``,
binary ``+ - * / %`` and ``^`` (right-associative, binds tighter than unary minus:
``-x^2`` is ``-(x^2)``), parentheses.  Comparisons are functions (``lt``, ``gt``, ``eq``...).
"""

from __future__ import annotations

import math
import re
from collections.abc import Iterator
from typing import Any

from fuzzyctl.formats.common.basics import fmt_number
from fuzzyctl.limits import shorten
from fuzzyctl.model import Binary, Call, Expr, Name, Num, Unary

_BINARY_POWER = {"+": 10, "-": 10, "*": 20, "/": 20, "%": 20, "^": 40}
_UNARY_POWER = 30


class ExprError(ValueError):
    """An expression that does not parse; ``position`` is the 0-based offset."""

    def __init__(self, message: str, position: int) -> None:
        super().__init__(message)
        self.position = position


_NUMBER = r"(?:\d+\.?\d*|\.\d+)(?:[eE][+-]?\d+)?"
_ONE = rf"(?:{_NUMBER}|[A-Za-z_][A-Za-z0-9_.]*|[-+*/%^(),])"
# How far the text is made of tokens: one pass in C, keeping no state per token.
_LEXICAL = re.compile(rf"(?:\s*{_ONE})*+")
# Tokens without positions (cheaper than match objects); one is found again on an error.
_TUPLES = re.compile(rf"\s*(?:({_NUMBER})|([A-Za-z_][A-Za-z0-9_.]*)|([-+*/%^(),]))")
# Text between these characters is never one token: chunks end before one of them.
_CUT = re.compile(r"[\s*/%^(),]")
_CHUNK = 1 << 14


def _check_characters(text: str) -> None:
    """Refuse text that is not a sequence of tokens, at its first stray character (before
    any other error, wherever that is)."""
    end = len(text.rstrip())
    stop = _LEXICAL.match(text).end()  # type: ignore[union-attr]
    if stop < end:
        while text[stop].isspace():
            stop += 1
        raise ExprError(f"unexpected character {text[stop]!r} in expression", stop)


def _chunks(text: str) -> Iterator[list[tuple[str, str, str]]]:
    """The (number, name, operator) tokens of checked text, a chunk at a time, so that a long
    expression is never held as one list of tokens; each chunk ends with ``_MORE``, the last
    with ``_END``."""
    pos, size = 0, len(text)
    while True:
        cut = _CUT.search(text, pos + _CHUNK) if pos + _CHUNK < size else None
        end = cut.start() if cut else size
        tokens = _TUPLES.findall(text, pos, end)
        tokens.append(_MORE if cut else _END)
        yield tokens
        if not cut:
            return
        pos = end


def _position(text: str, index: int) -> int:
    """Where token ``index`` starts (``len(text)`` past the last)."""
    for k, m in enumerate(_TUPLES.finditer(text)):
        if k == index:
            return m.start(m.lastindex or 0)
    return len(text)


_END = ("", "", "")  # the token after the last
_MORE = ("", "", "more")  # the end of a chunk, not of the text (never returned by peek)
_BEGIN_EXPR = "expr"


class _Parser:
    """Operator precedence over a token stream, with an explicit stack instead of recursion.

    It reads as the recursive descent ``expression(p) := primary (op expression(p'))*`` (the
    grammar in the module docstring) would, and reports the same errors; ``open`` counts the
    expressions begun and not finished (the descent's recursion depth), which may not exceed
    MAX_NESTING, and every node's depth is kept so that a tree deeper than that (a chain
    ``x + x + ...``) is refused as soon as it is built."""

    def __init__(self, text: str, leaves: dict[str, Num | Name]) -> None:
        from fuzzyctl.limits import MAX_NESTING

        self.text = text
        self.limit = MAX_NESTING
        self.chunks = _chunks(text)
        self.toks = next(self.chunks)  # the current chunk
        self.k = 0  # the next token's place in it
        self.before = 0  # tokens in the chunks before it
        self.open = 0  # expressions begun and not finished
        self.leaves = leaves  # equal leaves are one object (by their text)
        self.read: set[str] = set()  # the names read

    @property
    def index(self) -> int:
        """How many tokens were taken."""
        return self.before + self.k

    def fail(self, message: str, index: int | None = None) -> ExprError:
        return ExprError(message, _position(self.text, self.index if index is None else index))

    def peek(self) -> tuple[str, str, str]:
        """The next token, ``_END`` after the last."""
        tok = self.toks[self.k]
        while tok is _MORE:
            self.before += self.k
            self.toks, self.k = next(self.chunks), 0
            tok = self.toks[0]
        return tok

    def take(self) -> tuple[str, str, str]:
        tok = self.toks[self.k]
        if tok is _MORE or tok is _END:
            tok = self.peek()
            if tok is _END:
                raise ExprError("expression ends too early", len(self.text))
        self.k += 1
        return tok

    def deeper(self, depth: int) -> int:
        if depth > self.limit:
            raise ExprError(f"the expression nests more than {self.limit} levels deep", 0)
        return depth

    def parse(self) -> Expr:
        # frames: ["expr", min_power, left, its depth, pending operator], ["paren"],
        # ["unary", sign], ["call", name, args, deepest arg]
        stack: list[list[Any]] = []
        value: Expr | None = None
        depth = 0
        powers = _BINARY_POWER
        leaves, read = self.leaves, self.read
        self.begin(stack, 0)
        while True:
            if value is None:  # a primary: a leaf, or the start of what holds one
                number, name, op = self.take()
                if number:
                    value = leaves.get(number) or self.number(number)
                    depth = 1
                elif name:
                    if self.peek()[2] != "(":
                        value = leaves.get(name)
                        if value is None:
                            value = leaves[name] = Name(name)
                        read.add(name)
                        depth = 1
                    else:
                        self.k += 1
                        if self.peek()[2] == ")":
                            self.k += 1
                            value, depth = Call(name.lower(), ()), 1
                        else:
                            stack.append(["call", name.lower(), [], 0])
                            self.begin(stack, 0)
                elif op == "(":
                    stack.append(["paren"])
                    self.begin(stack, 0)
                elif op == "-" or op == "+":
                    stack.append(["unary", op])
                    self.begin(stack, _UNARY_POWER)
                else:
                    raise self.fail(f"unexpected {op!r} in expression", self.index - 1)
                continue
            frame = stack[-1]
            kind = frame[0]
            if kind is _BEGIN_EXPR:
                if frame[4] is not None:
                    depth = self.deeper(1 + max(frame[3], depth))
                    value = Binary(frame[4], frame[2], value)
                op = self.peek()[2]
                power = powers.get(op, 0) if op else 0
                if power > frame[1] or (power == frame[1] and op == "^"):
                    self.k += 1
                    frame[2], frame[3], frame[4] = value, depth, op
                    value = None
                    self.begin(stack, power if op == "^" else power + 1)
                    continue
                stack.pop()
                self.open -= 1
                if not stack:
                    return value
            elif kind == "paren":
                self.expect(")")
                stack.pop()
            elif kind == "unary":
                stack.pop()
                value, depth = Unary(frame[1], value), self.deeper(depth + 1)
            else:  # a call's argument
                frame[2].append(value)
                frame[3] = max(frame[3], depth)
                if self.peek()[2] == ",":
                    self.k += 1
                    value = None
                    self.begin(stack, 0)
                    continue
                self.expect(")")
                stack.pop()
                value, depth = Call(frame[1], tuple(frame[2])), self.deeper(frame[3] + 1)

    def begin(self, stack: list[list[Any]], min_power: int) -> None:
        """Start an expression (of operators binding at least ``min_power``)."""
        stack.append([_BEGIN_EXPR, min_power, None, 0, None])
        self.open += 1
        if self.open > self.limit:
            raise self.fail(f"the expression nests more than {self.limit} levels deep")

    def number(self, text: str) -> Num:
        value = float(text)
        if math.isinf(value):  # 1e400, 5001 digits: not an infinity the file spelt
            raise self.fail(f"the number {shorten(text)} is too large (beyond 1.8e308)", self.index - 1)
        num = self.leaves[text] = Num(value)
        return num

    def expect(self, op: str) -> None:
        tok = self.take()
        if tok[2] != op:
            raise self.fail(f"expected {op!r} but found {tok[0] or tok[1] or tok[2]!r}", self.index - 1)


def parse_function(text: str, leaves: dict[str, Num | Name] | None = None) -> tuple[Expr, set[str]]:
    """Parse an infix expression, and say which names it reads (as :func:`names_in`);
    raises :class:`ExprError` (also for one nesting deeper than
    :data:`fuzzyctl.limits.MAX_NESTING`, parentheses, calls, operators and chains alike).
    ``leaves``: the numbers and names read before (by their text), to share with them."""
    _check_characters(text)
    parser = _Parser(text, {} if leaves is None else leaves)
    result = parser.parse()
    leftover = parser.peek()
    if leftover is not _END:
        shown = leftover[0] or leftover[1] or leftover[2]
        raise parser.fail(f"unexpected {shown!r} after the expression")
    return result, parser.read


def parse_expr(text: str) -> Expr:
    """Parse an infix expression; raises :class:`ExprError` (also for one nesting deeper than
    :data:`fuzzyctl.limits.MAX_NESTING`, parentheses, calls, operators and chains alike)."""
    return parse_function(text)[0]


def names_in(expr: Expr) -> set[str]:
    """Every name the expression reads."""
    if isinstance(expr, Name):
        return {expr.name}
    if isinstance(expr, Unary):
        return names_in(expr.operand)
    if isinstance(expr, Binary):
        return names_in(expr.left) | names_in(expr.right)
    if isinstance(expr, Call):
        out: set[str] = set()
        for a in expr.args:
            out |= names_in(a)
        return out
    return set()


def _power(expr: Expr) -> int:
    if isinstance(expr, Binary):
        return _BINARY_POWER[expr.op]
    if isinstance(expr, Unary):
        return _UNARY_POWER
    return 100


def format_expr(expr: Expr) -> str:
    """Infix text that :func:`parse_expr` reads back to an equal expression."""
    if isinstance(expr, Num):
        text = fmt_number(expr.value)
        return f"({text})" if text.startswith("-") else text
    if isinstance(expr, Name):
        return expr.name
    if isinstance(expr, Call):
        return f"{expr.function}({', '.join(format_expr(a) for a in expr.args)})"
    if isinstance(expr, Unary):
        inner = format_expr(expr.operand)
        if _power(expr.operand) <= _UNARY_POWER and not isinstance(expr.operand, Binary | Unary):
            return f"{expr.op}{inner}"
        if isinstance(expr.operand, Binary) and expr.operand.op == "^":
            return f"{expr.op}{inner}"
        return f"{expr.op}({inner})"
    power = _BINARY_POWER[expr.op]
    left, right = format_expr(expr.left), format_expr(expr.right)
    if expr.op == "^":
        # right-associative: parenthesise a left operand of equal or lower power
        if _power(expr.left) <= power:
            left = f"({left})"
        if _power(expr.right) < power:
            right = f"({right})"
    else:
        if _power(expr.left) < power:
            left = f"({left})"
        if _power(expr.right) <= power:
            right = f"({right})"
    return f"{left} {expr.op} {right}"


_CONSTANTS = {"pi": 3.141592653589793, "e": 2.718281828459045, "inf": float("inf"), "nan": float("nan")}


def eval_constant(expr: Expr) -> float:
    """The value of an expression made of numbers and the constants ``pi``, ``e``, ``Inf``,
    ``NaN`` (MATLAB evaluates a FIS ``Range=[-pi/4 pi/4]``); raises ValueError otherwise
    (division by zero and overflow included: MATLAB would give Inf, a range of Inf is no
    use either)."""
    try:
        return _eval_constant(expr)
    except ArithmeticError as exc:
        raise ValueError(f"the value cannot be computed ({exc})") from None


def _eval_constant(expr: Expr) -> float:
    eval_constant = _eval_constant
    if isinstance(expr, Num):
        return expr.value
    if isinstance(expr, Name):
        if expr.name.lower() in _CONSTANTS:
            return _CONSTANTS[expr.name.lower()]
        raise ValueError(f"unknown name {expr.name!r}")
    if isinstance(expr, Unary):
        value = eval_constant(expr.operand)
        return -value if expr.op == "-" else value
    if isinstance(expr, Binary):
        a, b = eval_constant(expr.left), eval_constant(expr.right)
        if expr.op == "+":
            return a + b
        if expr.op == "-":
            return a - b
        if expr.op == "*":
            return a * b
        if expr.op == "/":
            return a / b
        if expr.op == "^":
            power = a**b
            if isinstance(power, complex):  # (-8)^0.5: MATLAB's value is complex
                raise ValueError(f"{fmt_number(a)}^{fmt_number(b)} is not a real number")
            return float(power)
        return a % b
    raise ValueError("functions are not allowed in a number")
