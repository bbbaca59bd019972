"""jFuzzyLogic 3.3's formulas, written as its Java is (``membership/*.java``,
``ruleConnectionMethod``, ``ruleActivationMethod``, ``ruleAccumulationMethod``), vectorised.

These differ from :mod:`fuzzyctl.engine.semantics.shapes` only where jFuzzyLogic does: which side of a
vertical edge a point on it gets (a POINT list takes the value reached from the left, TRIAN
and TRAPE the top), how NaN (an NC output before its first value) travels through a
condition, and the last bits of a few formulas.  Its 1000-point defuzzification samples
sets exactly on vertical edges often enough that the side matters.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from typing import Any

import numpy as np

from fuzzyctl.engine.plan import EBinary, ECall, EUnary, ExprPlan, TermPlan
from fuzzyctl.engine.semantics import fdlibm, shapes
from fuzzyctl.engine.semantics.expr import eval_expr_np
from fuzzyctl.kinds import formula
from fuzzyctl.kinds import shapes as registry

Arr = Any  # numpy arrays (and floats) broadcasting together

__all__ = ["ACCU", "ACT", "AND_OR", "hashmap_order", "jfl_expr", "membership", "point_membership"]


def membership(kind: str, p: Sequence[Arr], x: Arr) -> Arr:
    """``MembershipFunction*.membership(x)`` of a continuous term (``p``: canonical params of
    :data:`fuzzyctl.model.SHAPES`, broadcasting with ``x``)."""
    with np.errstate(all="ignore"):
        if kind == "points":
            return _pwl(x, p[0::2], p[1::2])
        shape = registry.SHAPES.get(kind)
        if shape is not None and isinstance(shape.jfl, str):
            return _jfl_formula(shape)(x, *p)
    # shapes jFuzzyLogic does not have (a file using them does not load there)
    return shapes.membership_np(kind, list(p), 1.0, np.asarray(x, dtype=np.float64))


#: What jFuzzyLogic's formulas call: its Java's StrictMath (fdlibm), elementwise.
_JAVA: dict[str, Any] = {
    "exp": fdlibm.exp,
    "cos": fdlibm.cos,
    "pow": fdlibm.pow_,
    "sqrt": np.sqrt,
    "abs": np.abs,
    "min": np.minimum,
    "max": np.maximum,
    "isnan": np.isnan,
    "where": np.where,
    "pi": np.pi,
    "nan": np.nan,
}


def _jfl_formula(shape: registry.Shape) -> Callable[..., Arr]:
    """The entry's jFuzzyLogic variant (:attr:`~fuzzyctl.kinds.shapes.Shape.jfl`), compiled once."""
    fn = shape.compiled.get("jfl_np")
    if fn is None:
        fn = formula.vectorised(shape.parsed_jfl(), _JAVA, registry.HELPERS)
        shape.compiled["jfl_np"] = fn
    return fn


def _pwl(x: Arr, xs: Sequence[Arr], ys: Sequence[Arr]) -> Arr:
    """``MembershipFunctionPieceWiseLinear.membership``: points as written (never sorted),
    the first segment whose end is >= x; a point on a vertical edge gets the value reached
    from the left."""
    x = np.asarray(x, dtype=np.float64)
    res = np.full(np.broadcast_shapes(x.shape, *(np.shape(v) for v in (*xs, *ys))), np.nan)
    done = np.zeros(res.shape, dtype=bool)
    for i in range(1, len(xs)):
        hit = ~done & (x <= xs[i])
        seg = ys[i - 1] + (ys[i] - ys[i - 1]) * ((x - xs[i - 1]) / (xs[i] - xs[i - 1]))
        res = np.where(hit, seg, res)
        done |= hit
    return np.where(x <= xs[0], ys[0], np.where(x > xs[-1], ys[-1], res))


def point_membership(term: TermPlan, p: Sequence[Arr], x: Arr, position: Arr | None = None) -> Arr:
    """``membership(x)`` of a discrete term: a singleton is 1 at its value (a FUNCTION term at
    the value of its function, ``position``), SINGLETONS ``MembershipFunctionGenericSingleton``."""
    if term.kind == "singletons":
        xs, ys = p[0::2], p[1::2]
        res: Arr = np.zeros(np.shape(x))
        done = np.zeros(np.shape(x), dtype=bool)
        for i in range(1, len(xs)):
            hit = ~done & (x == xs[i])
            res = np.where(hit, ys[i], res)
            done |= hit
        return np.where(x <= xs[0], ys[0], np.where(x > xs[-1], ys[-1], res))
    shape = registry.SHAPES.get(term.kind)
    at_value = term.kind == "singleton" or (shape is not None and shape.takagi_sugeno and not shape.variadic)
    value = p[0] if at_value else position
    return np.where(x == value, 1.0, 0.0)


# --------------------------------------------------------------------------- operators

_NAN = np.nan


def _hamacher(a: Arr, b: Arr) -> Arr:
    with np.errstate(all="ignore"):
        return np.where((a == 0) & (b == 0), 0.0, (a * b) / ((a + b) - a * b))


#: ``RuleConnectionMethod*.connect``: AND and OR as jFuzzyLogic pairs them
AND_OR: dict[str, Callable[[Arr, Arr], Arr]] = {
    "MIN": np.minimum,
    "PROD": lambda a, b: a * b,
    "BDIF": lambda a, b: np.maximum(0.0, a + b - 1),
    "DMIN": lambda a, b: np.where(a == 1, b, np.where(b == 1, a, 0.0)),
    "NIPMIN": lambda a, b: np.where(a + b > 1, np.minimum(a, b), 0.0),
    "HAMACHER": _hamacher,
    "MAX": np.maximum,
    "ASUM": lambda a, b: a + b - a * b,
    "BSUM": lambda a, b: np.minimum(1.0, a + b),
    "DMAX": lambda a, b: np.where(a == 0, b, np.where(b == 0, a, 1.0)),
    "NIPMAX": lambda a, b: np.where(a + b < 1, np.maximum(a, b), 1.0),
    "EINSTEIN": lambda a, b: (a + b) / (1 + a * b),
}
#: ``RuleActivationMethod*.imply(degreeOfSupport, membership)``
ACT: dict[str, Callable[[Arr, Arr], Arr]] = {"MIN": np.minimum, "PROD": lambda d, m: d * m}
#: ``RuleAccumulationMethod*.aggregate(value, valueToAggregate)``
ACCU: dict[str, Callable[[Arr, Arr], Arr]] = {
    "MAX": np.maximum,
    "BSUM": lambda a, b: np.minimum(1.0, a + b),
    "NSUM": lambda a, b: (a + b) / np.maximum(1.0, a + b),
    "PROBOR": lambda a, b: a + b - a * b,
    "SUM": lambda a, b: a + b,
}


# --------------------------------------------------------------------------- FUNCTION terms


def jfl_expr(e: ExprPlan) -> ExprPlan:
    """A function term as jFuzzyLogic evaluates it: its ``log`` is log10, ``ln`` the natural
    logarithm (``MffLog``, ``MffLn``)."""
    if isinstance(e, ECall):
        name = {"log": "log10", "ln": "log"}.get(e.function, e.function)
        return ECall(name, tuple(jfl_expr(a) for a in e.args))
    if isinstance(e, EBinary):
        return EBinary(e.op, jfl_expr(e.left), jfl_expr(e.right))
    if isinstance(e, EUnary):
        return EUnary(e.op, jfl_expr(e.operand))
    return e


#: Java's ``Math`` as fdlibm computes it, where we have it (the other functions: numpy's)
_JAVA_MATH = {"exp": fdlibm.exp, "cos": fdlibm.cos, "pow": fdlibm.pow_}


def eval_function(e: ExprPlan, vals: Sequence[Arr], outs: Sequence[Arr]) -> Arr:
    return eval_expr_np(e, vals, outs, _NAN, _JAVA_MATH)


# --------------------------------------------------------------------------- java.util.HashMap


def _java_hash(s: str) -> int:
    h = 0
    units = s.encode("utf-16-be")
    for i in range(0, len(units), 2):
        h = (31 * h + int.from_bytes(units[i : i + 2], "big")) & 0xFFFFFFFF
    return h


def hashmap_order(keys: Sequence[str]) -> list[int]:
    """The order in which a ``java.util.HashMap<String, V>`` filled with ``keys`` (in this
    order, distinct) iterates them: by bucket of the spread hash in the final table, then by
    insertion (resizes split buckets keeping their order).  jFuzzyLogic keeps rule blocks in
    one, so that is the order it evaluates them in."""
    capacity = 16
    while len(keys) > capacity * 3 // 4:
        capacity *= 2

    def bucket(k: str) -> int:
        h = _java_hash(k)
        return (h ^ (h >> 16)) & (capacity - 1)

    return sorted(range(len(keys)), key=lambda i: (bucket(keys[i]), i))
