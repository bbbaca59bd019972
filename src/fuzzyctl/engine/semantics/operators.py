"""Fuzzy operators: the one place where AND/OR norms, activation and accumulation are defined.

Each operator exists as a Python function on floats, a numpy function on arrays and a Python
expression template (``{a}``/``{b}`` stand for *simple names*) used when the scalar evaluator
is specialised into straight-line source.  The three are written from the same formula; the
tests check them against each other and against IEC 61131-7 Table 3, 4 and 5.

Table 3 pairs (AND / OR): MIN/MAX, PROD/ASUM, BDIF/BSUM; open level: DMIN/DMAX (drastic),
NIPMIN/NIPMAX (nilpotent), HAMACHER, EINSTEIN (the same keyword names the t-norm in AND and
the t-conorm in OR).
"""

from __future__ import annotations

import math
from collections.abc import Callable, Iterable
from dataclasses import dataclass
from typing import Any

import numpy as np

from fuzzyctl.kinds import norms
from fuzzyctl.model import OPERATOR_PAIRS


def fsum(values: Iterable[float]) -> float:
    """``math.fsum`` (exact), with the IEEE value where it raises: ``inf`` for a sum that
    overflows, NaN for ``inf + -inf`` - what numpy and the generated C give, so that the
    scalar paths (explain, the interpreted backend) agree with them on extreme inputs."""
    items = list(values)
    try:
        return math.fsum(items)
    except (OverflowError, ValueError):
        total = 0.0
        for v in items:
            total += v
        return total


@dataclass(frozen=True)
class Norm:
    """A binary operator on degrees."""

    name: str
    scalar: Callable[[float, float], float]
    array: Callable[[Any, Any], Any]
    source: str  # Python expression over the simple names {a} and {b}


def _ham_t(a: float, b: float) -> float:
    s = a + b - a * b
    return a * b / s if s != 0.0 else 0.0


def _ham_s(a: float, b: float) -> float:
    # the dual of _ham_t, 1 - T(1-a, 1-b): the textbook (a+b-2ab)/(1-ab) cancels
    # catastrophically as a, b -> 1 (0.9999999999999999 with 1.0 gave 2.27, off [0, 1])
    p, q = 1.0 - a, 1.0 - b
    s = p + q - p * q
    return 1.0 - p * q / s if s != 0.0 else 1.0


def _ham_t_np(a: Any, b: Any) -> Any:
    s = a + b - a * b
    with np.errstate(invalid="ignore", divide="ignore"):
        return np.where(s != 0.0, a * b / np.where(s != 0.0, s, 1.0), 0.0)


def _ham_s_np(a: Any, b: Any) -> Any:
    return 1.0 - _ham_t_np(1.0 - a, 1.0 - b)


TNORMS: dict[str, Norm] = {
    n.name: n
    for n in (
        Norm("MIN", lambda a, b: a if a < b else b, np.minimum, "({a} if {a} < {b} else {b})"),
        Norm("PROD", lambda a, b: a * b, lambda a, b: a * b, "({a} * {b})"),
        Norm(
            "BDIF",
            lambda a, b: max(0.0, a + b - 1.0),
            lambda a, b: np.maximum(0.0, a + b - 1.0),
            "max(0.0, {a} + {b} - 1.0)",
        ),
        Norm(
            "DMIN",
            lambda a, b: min(a, b) if max(a, b) == 1.0 else 0.0,
            lambda a, b: np.where(np.maximum(a, b) == 1.0, np.minimum(a, b), 0.0),
            "(min({a}, {b}) if max({a}, {b}) == 1.0 else 0.0)",
        ),
        Norm(
            "NIPMIN",
            lambda a, b: min(a, b) if a + b > 1.0 else 0.0,
            lambda a, b: np.where(a + b > 1.0, np.minimum(a, b), 0.0),
            "(min({a}, {b}) if {a} + {b} > 1.0 else 0.0)",
        ),
        Norm("HAMACHER", _ham_t, _ham_t_np, "_ham_t({a}, {b})"),
        Norm(
            "EINSTEIN",
            lambda a, b: a * b / (2.0 - (a + b - a * b)),
            lambda a, b: a * b / (2.0 - (a + b - a * b)),
            "({a} * {b} / (2.0 - ({a} + {b} - {a} * {b})))",
        ),
    )
}

SNORMS: dict[str, Norm] = {
    n.name: n
    for n in (
        Norm("MAX", lambda a, b: a if a > b else b, np.maximum, "({a} if {a} > {b} else {b})"),
        Norm("ASUM", lambda a, b: a + b - a * b, lambda a, b: a + b - a * b, "({a} + {b} - {a} * {b})"),
        Norm(
            "BSUM",
            lambda a, b: min(1.0, a + b),
            lambda a, b: np.minimum(1.0, a + b),
            "min(1.0, {a} + {b})",
        ),
        Norm(
            "DMAX",
            lambda a, b: max(a, b) if min(a, b) == 0.0 else 1.0,
            lambda a, b: np.where(np.minimum(a, b) == 0.0, np.maximum(a, b), 1.0),
            "(max({a}, {b}) if min({a}, {b}) == 0.0 else 1.0)",
        ),
        Norm(
            "NIPMAX",
            lambda a, b: max(a, b) if a + b < 1.0 else 1.0,
            lambda a, b: np.where(a + b < 1.0, np.maximum(a, b), 1.0),
            "(max({a}, {b}) if {a} + {b} < 1.0 else 1.0)",
        ),
        Norm("HAMACHER", _ham_s, _ham_s_np, "_ham_s({a}, {b})"),
        Norm(
            "EINSTEIN",
            lambda a, b: (a + b) / (1.0 + a * b),
            lambda a, b: (a + b) / (1.0 + a * b),
            "(({a} + {b}) / (1.0 + {a} * {b}))",
        ),
    )
}

#: Helpers referenced by ``Norm.source`` templates.
SOURCE_HELPERS: dict[str, Any] = {"_ham_t": _ham_t, "_ham_s": _ham_s, "min": min, "max": max}

# Table 3: AND -> OR and back (the model's table; the open-level norms pair with their duals).
AND_TO_OR = dict(OPERATOR_PAIRS)
OR_TO_AND = {v: k for k, v in AND_TO_OR.items()}

# Spellings other tools write for the same operators.
AND_ALIASES = {
    "EPROD": "EINSTEIN",
    "HPROD": "HAMACHER",
    "NMIN": "NIPMIN",
    "DPROD": "DMIN",
    "ALGEBRAIC_PRODUCT": "PROD",
}
OR_ALIASES = {
    "PROBOR": "ASUM",
    "ESUM": "EINSTEIN",
    "HSUM": "HAMACHER",
    "NMAX": "NIPMAX",
    "DSUM": "DMAX",
    "ALGEBRAIC_SUM": "ASUM",
}


def resolve_pair(and_op: str | None, or_op: str | None) -> tuple[str, str]:
    """The AND and OR operators of a rule block: a missing one is the Table 3 pair of the one
    given; neither given means MIN/MAX.  Raises ``KeyError`` for an unknown name."""
    a = AND_ALIASES.get(and_op, and_op) if and_op else None
    o = OR_ALIASES.get(or_op, or_op) if or_op else None
    if a is not None and a not in TNORMS:
        raise KeyError(and_op)
    if o is not None and o not in SNORMS:
        raise KeyError(or_op)
    if a is None and o is None:
        return "MIN", "MAX"
    if a is None:
        assert o is not None
        return OR_TO_AND[o], o
    if o is None:
        return a, AND_TO_OR[a]
    return a, o


# --------------------------------------------------------------------------- activation (Table 4)

#: Activation methods; PROD and MIN keep piecewise-linear terms piecewise linear.  Any AND
#: norm is accepted as activation (fuzzylite's implication operators).
ACT_ALIASES = {"EPROD": "EINSTEIN", "HPROD": "HAMACHER"}


#: Where an activation, as a function of the term degree mu, jumps or bends: levels
#: ``offset + slope * a`` for the rule degree a (MIN bends at mu = a, NIPMIN jumps at
#: mu = 1 - a and bends at a, BDIF bends at 1 - a).  The others are smooth in mu, or (DMIN)
#: nonzero only where mu is exactly 1.  Integrators cut the output range where a term
#: crosses these levels, so that no jump, plateau or kink falls between their samples.
ACT_LEVELS: dict[str, tuple[tuple[float, float], ...]] = {
    "MIN": ((0.0, 1.0),),
    "NIPMIN": ((0.0, 1.0), (1.0, -1.0)),
    "BDIF": ((1.0, -1.0),),
}

#: Activations whose clipping edge (the level ``a``) the reference's branch tests as
#: ``mu < a`` (engine/reference/interp.py ``accumulated_branch``): a term exactly at the
#: degree counts as clipped, so that at a = 1 the stretch where a smooth peak rounds to 1 is
#: a plateau on every path (LM, RM and MoM read its edges).
CLIP_BRANCH = frozenset(name for name, e in norms.TNORMS.items() if e.clips)


def activation_levels(act: str, a: float) -> list[float]:
    """The term degrees where ``act(a, mu)`` jumps or bends (:data:`ACT_LEVELS`), those
    strictly inside (0, 1)."""
    out = []
    for offset, slope in ACT_LEVELS.get(act, ()):
        lv = offset + slope * a
        if 0.0 < lv < 1.0:
            out.append(lv)
    return out


def resolve_act(act: str | None) -> str:
    a = ACT_ALIASES.get(act, act) if act else "MIN"
    if a not in TNORMS:
        raise KeyError(act)
    return a


# --------------------------------------------------------------------------- accumulation (Table 5)

#: Accumulation methods. NSUM is the sum normalised by max(1, max over u of the sum); that
#: uniform scale never changes a defuzzified value, so NSUM is accumulated like SUM and
#: normalised only where degrees are shown or reused (explanations, chained inference).
ACCU_NAMES = frozenset({"MAX", "BSUM", "NSUM", "SUM", "PROBOR", "EINSTEIN", "HAMACHER", "DMAX", "NIPMAX"})
ACCU_ALIASES = {
    "ASUM": "PROBOR",
    "ESUM": "EINSTEIN",
    "HSUM": "HAMACHER",
    "NMAX": "NIPMAX",
    "DSUM": "DMAX",
    "USUM": "SUM",
}
#: Accumulations whose result on piecewise-linear activated sets is integrated exactly.
EXACT_ACCU = frozenset(name for name, e in norms.ACCUMULATIONS.items() if e.exact)


def resolve_accu(accu: str | None) -> str:
    a = ACCU_ALIASES.get(accu, accu) if accu else "MAX"
    if a not in ACCU_NAMES:
        raise KeyError(accu)
    return a


def accumulate(name: str, a: float, b: float) -> float:
    """Combine two activated degrees (pointwise) by an accumulation method."""
    if name == "MAX":
        return a if a > b else b
    if name in ("SUM", "NSUM"):
        return a + b
    if name == "BSUM":
        return min(1.0, a + b)
    if name == "PROBOR":
        return a + b - a * b
    return SNORMS[name].scalar(a, b)


def accumulate_np(name: str, a: Any, b: Any) -> Any:
    """Vectorised :func:`accumulate`."""
    if name == "MAX":
        return np.maximum(a, b)
    if name in ("SUM", "NSUM"):
        return a + b
    if name == "BSUM":
        return np.minimum(1.0, a + b)
    if name == "PROBOR":
        return a + b - a * b
    return SNORMS[name].array(a, b)


def activate(name: str, a: float, mu: float) -> float:
    return TNORMS[name].scalar(a, mu)


def is_finite(x: float) -> bool:
    return math.isfinite(x)


def clamp(value: float, low: float, high: float) -> float:
    """``value`` limited to ``[low, high]``, NaN kept (fuzzylite ``lock-range``: model
    ``FuzzifyBlock.clamp`` / ``DefuzzifyBlock.clamp``)."""
    if value < low:
        return low
    if value > high:
        return high
    return value


def clamp_np(values: Any, low: float, high: float) -> Any:
    """:func:`clamp` on an array (``np.clip`` keeps NaN)."""
    return np.clip(values, low, high)
