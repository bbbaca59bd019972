"""Function terms (jFuzzyLogic FUNCTION, fuzzylite Function): expressions over inputs,
earlier outputs and ``x``, evaluated C-like (division by zero gives inf/nan, never raises),
for floats and for numpy arrays."""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from typing import Any

import numpy as np

from fuzzyctl.engine.plan import EX, EBinary, ECall, EInput, ENum, EOutput, EUnary, ExprPlan
from fuzzyctl.engine.semantics import libm_np

_COMPARE: dict[str, Any] = {
    "eq": lambda a, b: a == b,
    "neq": lambda a, b: a != b,
    "lt": lambda a, b: a < b,
    "le": lambda a, b: a <= b,
    "gt": lambda a, b: a > b,
    "ge": lambda a, b: a >= b,
}


def _div(a: float, b: float) -> float:
    if b == 0.0:
        return math.nan if a == 0.0 or a != a else math.copysign(math.inf, a) * math.copysign(1.0, b)
    return a / b


def _call(name: str, args: list[float]) -> float:
    try:
        if name in ("abs", "fabs"):
            return abs(args[0])
        if name in ("log", "ln"):
            return math.log(args[0]) if args[0] > 0 else (-math.inf if args[0] == 0 else math.nan)
        if name == "sign":
            return math.copysign(1.0, args[0]) if args[0] != 0 else 0.0
        if name == "pow":
            return float(args[0] ** args[1])
        if name == "fmod":
            return math.fmod(args[0], args[1])
        if name == "round":
            return float(round(args[0]))
        if name in ("min", "max"):
            return float(min(args) if name == "min" else max(args))
        if name in _COMPARE:  # fuzzylite: 1.0 when true, 0.0 when false
            return 1.0 if _COMPARE[name](args[0], args[1]) else 0.0
        fn = getattr(math, name)
        return float(fn(*args))
    except (ValueError, ZeroDivisionError):
        return math.nan
    except OverflowError:
        return math.inf


def eval_expr(e: ExprPlan, values: Sequence[float], outputs: Sequence[float], x: float = math.nan) -> float:
    """Evaluate a function term (C-like: division by zero gives inf/nan, never raises)."""
    if isinstance(e, ENum):
        return e.value
    if isinstance(e, EInput):
        return values[e.slot]
    if isinstance(e, EOutput):
        return outputs[e.output]
    if isinstance(e, EX):
        return x
    if isinstance(e, EUnary):
        v = eval_expr(e.operand, values, outputs, x)
        return -v if e.op == "-" else v
    if isinstance(e, EBinary):
        a = eval_expr(e.left, values, outputs, x)
        b = eval_expr(e.right, values, outputs, x)
        if e.op == "+":
            return a + b
        if e.op == "-":
            return a - b
        if e.op == "*":
            return a * b
        if e.op == "/":
            return _div(a, b)
        if e.op == "%":
            return math.fmod(a, b) if b != 0.0 else math.nan
        return _call("pow", [a, b])
    assert isinstance(e, ECall)
    return _call(e.function, [eval_expr(a, values, outputs, x) for a in e.args])


_NP_FUNCS: dict[str, Any] = {
    "sin": libm_np.sin,
    "cos": libm_np.cos,
    "tan": libm_np.tan,
    "asin": libm_np.asin,
    "acos": libm_np.acos,
    "atan": libm_np.atan,
    "sinh": libm_np.sinh,
    "cosh": libm_np.cosh,
    "tanh": libm_np.tanh,
    "exp": libm_np.exp,
    "log": libm_np.log,
    "ln": libm_np.log,
    "log10": libm_np.log10,
    "sqrt": np.sqrt,
    "abs": np.abs,
    "fabs": np.abs,
    "floor": np.floor,
    "ceil": np.ceil,
    "round": np.round,
    "sign": np.sign,
    "pow": libm_np.pow_,
    "atan2": libm_np.atan2,
    "fmod": np.fmod,
    "min": np.minimum,
    "max": np.maximum,
    # fuzzylite's comparisons: 1.0 when true, 0.0 when false
    "eq": lambda a, b: np.where(a == b, 1.0, 0.0),
    "neq": lambda a, b: np.where(a != b, 1.0, 0.0),
    "lt": lambda a, b: np.where(a < b, 1.0, 0.0),
    "le": lambda a, b: np.where(a <= b, 1.0, 0.0),
    "gt": lambda a, b: np.where(a > b, 1.0, 0.0),
    "ge": lambda a, b: np.where(a >= b, 1.0, 0.0),
}


def eval_expr_np(
    e: ExprPlan,
    vals: Sequence[Any],
    outs: Sequence[Any],
    x: Any = None,
    funcs: Mapping[str, Any] | None = None,
) -> Any:
    """``e`` over arrays; ``funcs`` replaces some of the functions (by name; ``pow`` also
    serves ``^``)."""
    table = _NP_FUNCS if funcs is None else {**_NP_FUNCS, **funcs}
    return _eval_np(e, vals, outs, x, table)


def _eval_np(e: ExprPlan, vals: Sequence[Any], outs: Sequence[Any], x: Any, table: Mapping[str, Any]) -> Any:
    with np.errstate(all="ignore"):
        if isinstance(e, ENum):
            return e.value
        if isinstance(e, EInput):
            return vals[e.slot]
        if isinstance(e, EOutput):
            return outs[e.output]
        if isinstance(e, EX):
            return x
        if isinstance(e, EUnary):
            v = _eval_np(e.operand, vals, outs, x, table)
            return -v if e.op == "-" else v
        if isinstance(e, EBinary):
            a = np.asarray(_eval_np(e.left, vals, outs, x, table), dtype=np.float64)
            b = np.asarray(_eval_np(e.right, vals, outs, x, table), dtype=np.float64)
            if e.op == "+":
                return a + b
            if e.op == "-":
                return a - b
            if e.op == "*":
                return a * b
            if e.op == "/":
                return a / b
            if e.op == "%":
                return np.fmod(a, b)
            return table["pow"](a, b)
        assert isinstance(e, ECall)
        args = [np.asarray(_eval_np(a, vals, outs, x, table), dtype=np.float64) for a in e.args]
        if e.function == "min" or e.function == "max":
            f = table[e.function]
            r = args[0]
            for a in args[1:]:
                r = f(r, a)
            return r
        return table[e.function](*args)
