"""The universe of an output without RANGE: the span of its terms, as jFuzzyLogic computes it.

IEC 61131-7 integrates over the range of the output's data type when no RANGE is given, which
no tool does; jFuzzyLogic 3.3 (``Variable.estimateUniverse``) takes the smallest interval that
holds every term's own universe (``MembershipFunction*.estimateUniverse``):

* points and SINGLETONS: first x .. last x, as written;
* triangle a..c, trapezoid a..d, singleton x..x;
* gaussian mean +- 4 sigma; gaussian2 mean1 - 4 sigma1 .. mean2 + 4 sigma2;
* bell center +- 999^(1 / (2 slope)) * width (where it is 1/1000);
* sigmoid center +- 9 / |slope| (where it is within 1.2e-4 of 0 or 1); DSIGM: the hull of
  both sigmoids';
* COSINE offset +- net_max (its support).

Shapes jFuzzyLogic does not have follow the same rule - their support where it is finite,
else where they come within about 1e-4 of their limit: spike center +- |width| (exp(-10)),
psigmoid and dsigmoid like DSIGM; ramp, sshape, zshape, arc, rectangle, semiellipse: their
two parameters; pishape a..d; concave and binary (flat beyond one parameter, slow or no decay
on the other side): the hull of their parameters.  ``tests/engine/test_universe.py`` checks
every jFuzzyLogic shape against the live jFuzzyLogic's ``--info``.
"""

from __future__ import annotations

import math
from collections.abc import Sequence

__all__ = ["span", "span_rule"]

#: How the span of each kind is computed (for messages and docs).
SPAN_RULES: dict[str, str] = {
    "points": "first..last point",
    "singletons": "first..last point",
    "singleton": "its position",
    "triangle": "a..c",
    "trapezoid": "a..d",
    "gaussian": "mean +- 4 sigma",
    "gaussian2": "mean1 - 4 sigma1 .. mean2 + 4 sigma2",
    "bell": "center +- 999^(1/(2 slope)) width",
    "sigmoid": "center +- 9/|slope|",
    "dsigmoid": "centers +- 9/|slope|",
    "dsigmoid_pos": "centers +- 9/|slope|",
    "psigmoid": "centers +- 9/|slope|",
    "cosine": "center +- width/2",
    "cosine_half": "center +- half width",
    "spike": "center +- |width|",
}


def span_rule(kind: str) -> str:
    """How :func:`span` computes the universe of a term of ``kind`` (for messages)."""
    return SPAN_RULES.get(kind, "the hull of its parameters")


def _div(a: float, b: float) -> float:
    """``a / b`` as Java (and jFuzzyLogic) computes it: a zero divisor gives an infinity (or
    NaN for 0 / 0), never an exception (a Bell of slope 0, a sigmoid of slope 0)."""
    try:
        return a / b
    except ZeroDivisionError:
        return math.nan if a == 0.0 or math.isnan(a) else math.copysign(math.inf, a) * math.copysign(1.0, b)


def _pow(base: float, exponent: float) -> float:
    """``base ** exponent``, infinite where it overflows (Java's Math.pow)."""
    try:
        return math.pow(base, exponent)
    except OverflowError:
        return math.inf


def span(kind: str, params: Sequence[float]) -> tuple[float, float]:
    """The universe jFuzzyLogic gives one term (``kind`` and canonical ``params`` of
    :data:`fuzzyctl.model.SHAPES`; ``points``/``singletons`` as ``x0, y0, x1, y1, ...``).

    Written as jFuzzyLogic's ``estimateUniverse`` writes it, so that the sample points of its
    1000-point defuzzification are reproduced to the last bit.  May be infinite (a shoulder
    at -inf, a slope of 0) or reversed (a negative width); callers check.  A span that is not
    a number (a Bell of slope 0 and width 0) is the whole line."""
    low, high = _span(kind, params)
    if math.isnan(low) or math.isnan(high):
        return -math.inf, math.inf
    return low, high


def _span(kind: str, params: Sequence[float]) -> tuple[float, float]:
    p = [float(v) for v in params]
    if kind in ("points", "singletons"):
        return p[0], p[-2]
    if kind == "singleton":
        return p[0], p[0]
    if kind == "triangle":
        return p[0], p[2]
    if kind == "trapezoid":
        return p[0], p[3]
    if kind == "gaussian":
        m, s = p
        return m - 4.0 * s, m + 4.0 * s
    if kind == "gaussian2":
        return p[0] - 4.0 * p[1], p[2] + 4.0 * p[3]
    if kind == "bell":
        c, w, b = p
        delta = _pow(999.0, _div(1.0, 2.0 * b)) * w
        return c - delta, c + delta
    if kind == "sigmoid":
        c, s = p
        return c - _div(9.0, abs(s)), c + _div(9.0, abs(s))
    if kind in ("dsigmoid", "dsigmoid_pos", "psigmoid"):
        c1, s1, c2, s2 = p
        min1, max1 = c1 - _div(9.0, abs(s1)), c1 + _div(9.0, abs(s1))
        min2, max2 = c2 - _div(9.0, abs(s2)), c2 + _div(9.0, abs(s2))
        return (min1 if min1 < min2 else min2), (max1 if max1 > max2 else max2)
    if kind == "cosine":
        c, w = p
        return c - 0.5 * abs(w), c + 0.5 * abs(w)
    if kind == "cosine_half":
        c, hw = p  # jFuzzyLogic: offset - net_max .. offset + net_max
        return c - hw, c + hw
    if kind == "spike":
        c, w = p
        return c - abs(w), c + abs(w)
    if kind == "pishape":
        return p[0], p[3]
    if not p or kind in ("function", "linear", "constant"):
        return -math.inf, math.inf  # no parameters to span (a function of x)
    return min(p), max(p)
