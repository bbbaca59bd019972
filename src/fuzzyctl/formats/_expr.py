"""Arithmetic expressions of fuzzylite ``Function`` terms, to and from the model's Expr.

Grammar (fuzzylite's infix notation): numbers, names, calls ``f(a, b)``, unary ``-``/``+``,
binary ``+ - * / %`` and ``^`` (right-associative, binds tighter than unary minus:
``-x^2`` is ``-(x^2)``), parentheses.  Comparisons are functions (``lt``, ``gt``, ``eq``...).
"""

from __future__ import annotations

import math
import re
from collections.abc import Iterator

from fuzzyctl.formats._common import fmt_number
from fuzzyctl.model import Binary, Call, Expr, Name, Num, Unary

_TOKEN = re.compile(
    r"\s*(?:(?P<num>(?:\d+\.?\d*|\.\d+)(?:[eE][+-]?\d+)?)|(?P<name>[A-Za-z_][A-Za-z0-9_.]*)|(?P<op>[-+*/%^(),]))"
)
_BINARY_POWER = {"+": 10, "-": 10, "*": 20, "/": 20, "%": 20, "^": 40}
_UNARY_POWER = 30


class ExprError(ValueError):
    """An expression that does not parse; ``position`` is the 0-based offset."""

    def __init__(self, message: str, position: int) -> None:
        super().__init__(message)
        self.position = position


# Every token of a text at once (atomic and possessive, so each token is the one _TOKEN
# takes at that place): where it stops is where _tokens stops.
# (without the named groups: 3.11's re fails on capturing groups in a possessive repeat)
_ALL_TOKENS = re.compile("(?>{})*+".format(re.sub(r"\(\?P<\w+>", "(?:", _TOKEN.pattern)))


def _tokens(text: str) -> Iterator[tuple[str, str, int]]:
    """The tokens of ``text``, made as the parser asks for them (an expression nested a
    million deep is refused after a hundred tokens, not after building a million), or
    :class:`ExprError` at once for a character that starts no token."""
    end = len(text.rstrip())
    pos = _ALL_TOKENS.match(text).end()  # type: ignore[union-attr]  # matches at least ""
    if pos < end:
        while pos < end and text[pos].isspace():
            pos += 1
        raise ExprError(f"unexpected character {text[pos]!r} in expression", pos)
    for m in _TOKEN.finditer(text):  # consecutive: the whole text is tokens
        kind = m.lastgroup or "op"
        yield (kind, m.group(kind), m.start(kind))


def parse_expr(text: str) -> Expr:
    """Parse an infix expression; raises :class:`ExprError` (also for one nesting deeper than
    :data:`fuzzyctl.limits.MAX_NESTING`, parentheses, calls, operators and chains alike)."""
    from fuzzyctl.limits import MAX_NESTING, expr_depth

    parser = _Parser(text, MAX_NESTING)
    result = parser.expression(0)
    leftover = parser.current
    if leftover is not None:
        raise ExprError(f"unexpected {leftover[1]!r} after the expression", leftover[2])
    if expr_depth(result) > MAX_NESTING:  # a long chain a + b + c ... is a deep tree too
        raise ExprError(f"the expression nests more than {MAX_NESTING} levels deep", 0)
    return result


class _Parser:
    """Precedence climbing over the tokens of one text.  A class rather than nested
    functions: those refer to each other, a reference cycle per expression that the readers
    (which run with the cyclic GC paused) would keep until they return."""

    def __init__(self, text: str, max_nesting: int) -> None:
        self.text = text
        self.max_nesting = max_nesting
        self.tokens = _tokens(text)
        self.current = next(self.tokens, None)
        self.depth = 0

    def take(self) -> tuple[str, str, int]:
        tok = self.current
        if tok is None:
            raise ExprError("expression ends too early", len(self.text))
        self.current = next(self.tokens, None)
        return tok

    def expect(self, op: str) -> None:
        _kind, value, pos = self.take()
        if value != op:
            raise ExprError(f"expected {op!r} but found {value!r}", pos)

    def primary(self) -> Expr:
        kind, value, pos = self.take()
        if kind == "num":
            number = float(value)
            if math.isinf(number):  # 1e400, 5001 digits: not an infinity the file spelt
                shown = value if len(value) <= 24 else f"{value[:20]}... ({len(value)} characters)"
                raise ExprError(f"the number {shown} is too large (beyond 1.8e308)", pos)
            return Num(number)
        if kind == "name":
            nxt = self.current
            if nxt is not None and nxt[1] == "(":
                self.take()
                args: list[Expr] = []
                if (self.current or ("", "", 0))[1] != ")":
                    args.append(self.expression(0))
                    while (self.current or ("", "", 0))[1] == ",":
                        self.take()
                        args.append(self.expression(0))
                self.expect(")")
                return Call(value.lower(), tuple(args))
            return Name(value)
        if value == "(":
            inner = self.expression(0)
            self.expect(")")
            return inner
        if value in {"-", "+"}:
            return Unary(value, self.expression(_UNARY_POWER))
        raise ExprError(f"unexpected {value!r} in expression", pos)

    def expression(self, min_power: int) -> Expr:
        self.depth += 1
        try:
            if self.depth > self.max_nesting:
                pos = (self.current or ("", "", len(self.text)))[2]
                raise ExprError(f"the expression nests more than {self.max_nesting} levels deep", pos)
            return self.operators(min_power)
        finally:
            self.depth -= 1

    def operators(self, min_power: int) -> Expr:
        left = self.primary()
        while True:
            tok = self.current
            if tok is None or tok[0] != "op" or tok[1] not in _BINARY_POWER:
                return left
            power = _BINARY_POWER[tok[1]]
            if power < min_power or (power == min_power and tok[1] != "^"):
                return left
            self.take()
            right = self.expression(power if tok[1] == "^" else power + 1)
            left = Binary(tok[1], left, right)


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
