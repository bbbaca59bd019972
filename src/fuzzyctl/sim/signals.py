"""Pre- and post-processing of a controller's signals as small arithmetic expressions.

IEC 61131-7 A.3 leaves the dynamics to the structure around the fuzzy block: "the control
error ... has to be formed outside fuzzy control", derivatives and integrals are "elements of
the first order" whose outputs become additional fuzzy inputs, and the outputs may be
integrated or distributed among several actuators.  A loop configuration writes each of
those signals as an expression over named signals::

    distance = "target - position"          # control error from setpoint and measurement
    rate     = "60 * ddt(error, 5)"          # de/dt in K/min through a 5 s first-order filter
    force    = "balance + centering"         # two fuzzy outputs onto one actuator

Grammar: numbers, names, ``+ - * / **``, unary minus, parentheses and the functions
``abs min max clip(x, lo, hi) sqrt sign deg rad`` and the stateful elements
``ddt(x[, tf])`` (backward difference through a first-order filter of time constant ``tf``
seconds; 0 on the first call), ``integral(x)`` (rectangle rule) and ``delay(x, n)``
(the value ``n`` calls ago).  Expressions are parsed once (Python's ``ast``, whitelisted
nodes only - nothing is ``eval``-ed) and then evaluated each cycle.
"""

from __future__ import annotations

import ast
import math
from collections import deque
from collections.abc import Callable, Mapping
from dataclasses import dataclass, field

from fuzzyctl.diagnostics import InputError

Env = Mapping[str, float]
_Eval = Callable[[Env, float], float]

_PURE: dict[str, tuple[int, int, Callable[..., float]]] = {
    "abs": (1, 1, abs),
    "min": (2, 8, min),
    "max": (2, 8, max),
    "clip": (3, 3, lambda x, lo, hi: min(max(x, lo), hi)),
    "sqrt": (1, 1, math.sqrt),
    "sign": (1, 1, lambda x: float((x > 0) - (x < 0))),
    "deg": (1, 1, math.degrees),
    "rad": (1, 1, math.radians),
}
_STATEFUL = ("ddt", "integral", "delay")


@dataclass
class _Ddt:
    tf: float
    last: float | None = None
    value: float = 0.0

    def __call__(self, x: float, dt: float) -> float:
        if self.last is None or dt <= 0:
            self.last = x
            return self.value
        raw = (x - self.last) / dt
        self.last = x
        # Backward-Euler first-order filter: stable for any tf/dt, tf = 0 is the plain difference.
        self.value += (raw - self.value) * dt / (self.tf + dt)
        return self.value

    def reset(self) -> None:
        self.last, self.value = None, 0.0


@dataclass
class _Integral:
    value: float = 0.0

    def __call__(self, x: float, dt: float) -> float:
        self.value += x * dt
        return self.value

    def reset(self) -> None:
        self.value = 0.0


@dataclass
class _Delay:
    n: int
    past: deque[float] = field(default_factory=deque)

    def __call__(self, x: float, dt: float) -> float:
        self.past.append(x)
        if len(self.past) > self.n + 1:
            self.past.popleft()
        return self.past[0]

    def reset(self) -> None:
        self.past.clear()


class Expression:
    """A compiled signal expression.  ``expr(env, dt)`` evaluates it for one cycle of length
    ``dt`` seconds; :meth:`reset` clears the state of its ``ddt``/``integral``/``delay``."""

    def __init__(self, source: str, *, where: str = "expression") -> None:
        self.source = source
        self.where = where
        self.names: set[str] = set()
        self._elements: list[_Ddt | _Integral | _Delay] = []
        try:
            tree = ast.parse(source.strip(), mode="eval")
        except SyntaxError as exc:
            raise InputError(f"{where}: cannot read {source!r}: {exc.msg}") from None
        self._fn = self._compile(tree.body)

    def __call__(self, env: Env, dt: float) -> float:
        try:
            return float(self._fn(env, dt))
        except KeyError as exc:
            known = ", ".join(sorted(env))
            raise InputError(
                f"{self.where}: unknown signal {exc.args[0]!r} in {self.source!r} (signals: {known})"
            ) from None
        except (ValueError, ZeroDivisionError, OverflowError) as exc:
            raise InputError(f"{self.where}: {self.source!r}: {exc}") from None

    def reset(self) -> None:
        for element in self._elements:
            element.reset()

    def __repr__(self) -> str:
        return f"Expression({self.source!r})"

    # ------------------------------------------------------------------ compiler

    def _fail(self, node: ast.AST, why: str) -> InputError:
        col = getattr(node, "col_offset", 0) + 1
        return InputError(f"{self.where}: {why} in {self.source!r} (column {col})")

    def _constant(self, node: ast.expr) -> float:
        if (
            isinstance(node, ast.Constant)
            and isinstance(node.value, (int, float))
            and not isinstance(node.value, bool)
        ):
            return float(node.value)
        if isinstance(node, ast.UnaryOp) and isinstance(node.op, ast.USub):
            return -self._constant(node.operand)
        raise self._fail(node, "expected a number")

    def _compile(self, node: ast.expr) -> _Eval:
        if isinstance(node, ast.Constant):
            value = self._constant(node)
            return lambda env, dt: value
        if isinstance(node, ast.Name):
            name = node.id
            self.names.add(name)
            return lambda env, dt: env[name]
        if isinstance(node, ast.UnaryOp):
            inner = self._compile(node.operand)
            if isinstance(node.op, ast.USub):
                return lambda env, dt: -inner(env, dt)
            if isinstance(node.op, ast.UAdd):
                return inner
            raise self._fail(node, "only unary + and - are allowed")
        if isinstance(node, ast.BinOp):
            a, b = self._compile(node.left), self._compile(node.right)
            ops: dict[type[ast.operator], Callable[[float, float], float]] = {
                ast.Add: lambda x, y: x + y,
                ast.Sub: lambda x, y: x - y,
                ast.Mult: lambda x, y: x * y,
                ast.Div: lambda x, y: x / y,
                ast.Pow: lambda x, y: x**y,
            }
            op = ops.get(type(node.op))
            if op is None:
                raise self._fail(node, "only + - * / ** are allowed")
            return lambda env, dt: op(a(env, dt), b(env, dt))
        if isinstance(node, ast.Call) and isinstance(node.func, ast.Name) and not node.keywords:
            return self._call(node, node.func.id)
        raise self._fail(node, f"{type(node).__name__} is not allowed")

    def _call(self, node: ast.Call, name: str) -> _Eval:
        args = node.args
        if name in _PURE:
            lo, hi, fn = _PURE[name]
            if not lo <= len(args) <= hi:
                raise self._fail(node, f"{name}() takes {lo if lo == hi else f'{lo} to {hi}'} argument(s)")
            parts = [self._compile(a) for a in args]
            return lambda env, dt: fn(*(p(env, dt) for p in parts))
        if name == "ddt":
            if len(args) not in (1, 2):
                raise self._fail(node, "ddt(x[, tf]) takes 1 or 2 arguments")
            tf = self._constant(args[1]) if len(args) == 2 else 0.0
            if tf < 0:
                raise self._fail(node, "the filter time constant of ddt() must be >= 0")
            inner = self._compile(args[0])
            ddt = _Ddt(tf)
            self._elements.append(ddt)
            return lambda env, dt: ddt(inner(env, dt), dt)
        if name == "integral":
            if len(args) != 1:
                raise self._fail(node, "integral(x) takes 1 argument")
            inner = self._compile(args[0])
            integ = _Integral()
            self._elements.append(integ)
            return lambda env, dt: integ(inner(env, dt), dt)
        if name == "delay":
            if len(args) != 2:
                raise self._fail(node, "delay(x, n) takes 2 arguments")
            n = self._constant(args[1])
            if n < 0 or n != int(n):
                raise self._fail(node, "delay(x, n) needs a whole number n >= 0")
            inner = self._compile(args[0])
            delay = _Delay(int(n))
            self._elements.append(delay)
            return lambda env, dt: delay(inner(env, dt), dt)
        known = ", ".join([*sorted(_PURE), *_STATEFUL])
        raise self._fail(node, f"unknown function {name}() (functions: {known})")


def compile_all(sources: Mapping[str, str | float | Expression], *, where: str) -> dict[str, Expression]:
    """Compile a name -> expression table (strings or ready expressions)."""
    out: dict[str, Expression] = {}
    for name, src in sources.items():
        if isinstance(src, Expression):
            out[name] = src
        elif isinstance(src, str):
            out[name] = Expression(src, where=f"{where}.{name}")
        elif isinstance(src, (int, float)) and not isinstance(src, bool):
            out[name] = Expression(repr(float(src)), where=f"{where}.{name}")
        else:
            raise InputError(f"{where}.{name}: expected an expression string, got {src!r}")
    return out
