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

from fuzzyctl.kinds import shapes as registry

__all__ = ["span", "span_rule"]


def span_rule(kind: str) -> str:
    """How :func:`span` computes the universe of a term of ``kind`` (for messages)."""
    if kind in ("points", "singletons"):
        return "first..last point"
    if kind == "singleton":
        return "its position"
    shape = registry.SHAPES.get(kind)
    return shape.span.rule if shape is not None else "the hull of its parameters"


def span(kind: str, params: Sequence[float]) -> tuple[float, float]:
    """The universe jFuzzyLogic gives one term (``kind`` and canonical ``params`` of
    :data:`fuzzyctl.model.SHAPES`; ``points``/``singletons`` as ``x0, y0, x1, y1, ...``).

    Written as jFuzzyLogic's ``estimateUniverse`` writes it (the registry's
    :attr:`~fuzzyctl.kinds.shapes.Shape.span`), so that the sample points of its
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
    shape = registry.SHAPES.get(kind)
    if shape is not None and (p or shape.variadic):
        return shape.span.of(p)
    if not p:
        return -math.inf, math.inf  # no parameters to span (a function of x)
    return min(p), max(p)
