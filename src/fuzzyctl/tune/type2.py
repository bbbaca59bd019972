"""Tuning interval type-2 terms (docs/type2.md, "Tune"): the lower function's parameters as
slots of the tuning space, kept below the upper function for every candidate.

* MATLAB's form (scale and lag): the scale moves in ``[SCALE_MIN, 1]`` and each lag in
  ``[0, LAG_MAX]``; lower <= upper holds for every such value (the form's construction).
* An explicit lower function: its abscissae join its variable's breakpoints and its scales
  move as the upper's do (:mod:`fuzzyctl.tune.space`); the candidate is then *projected*:
  the lower function's height is multiplied by the largest factor in (0, 1] that keeps it
  below the upper function.  For piecewise-linear pairs that factor is exact (the ratio of
  two linear functions is monotone on each piece between the breakpoints of both, so its
  least value is at a breakpoint); smooth pairs use the checker's samples.

:func:`widen` turns a type-1 block into a type-2 one whose lower functions equal the upper
ones (scale 1, lag 0): the same outputs, and scale and lag then free to tune.
"""

from __future__ import annotations

import dataclasses
from collections.abc import Iterable

from fuzzyctl.engine import type2_sets as sets
from fuzzyctl.kinds import shapes as registry
from fuzzyctl.model import (
    DefuzzifyBlock,
    FunctionBlock,
    FuzzifyBlock,
    LowerMF,
    MembershipFunction,
    PointsMF,
    ShapeMF,
    Term,
)

#: The smallest lower scale a tuner gives (MATLAB's LowerScale is in (0, 1]).
SCALE_MIN = 0.01
#: The largest lag a tuner gives (LowerLag is in [0, 1); a lag near 1 leaves no lower set).
LAG_MAX = 0.95

Slot = tuple[tuple[str | int, ...], float, str, str]


def scale_lag_slots(var: str, ti: int, t: Term) -> Iterable[Slot]:
    """The slots of a scale/lag lower function: ``(key, value, role, label)``, role
    ``lower_scale`` or ``lag``."""
    lower = t.lower
    if lower is None or lower.mf is not None:
        return
    base = f"{var}.{t.name} lower"
    yield ("lower", var, ti, "scale"), float(lower.scale), "lower_scale", f"{base} scale"
    sides = ("lag",) if len(lower.lag) == 1 else ("lag left", "lag right")
    for j, (value, side) in enumerate(zip(lower.lag, sides, strict=True)):
        yield ("lower", var, ti, "lag", j), float(value), "lag", f"{base} {side}"


def box(role: str) -> tuple[float, float]:
    """Where a scale/lag slot moves."""
    return (SCALE_MIN, 1.0) if role == "lower_scale" else (0.0, LAG_MAX)


def with_values(t: Term, new: dict[tuple[str | int, ...], float], replace_mf: object) -> Term:
    """``t`` with its lower function's numbers at ``new`` (keys after ``("lower", var,
    ti)``); ``replace_mf(mf, {index: value})`` replaces an explicit function's parameters."""
    lower = t.lower
    assert lower is not None
    if lower.mf is None:
        scale = new.get(("scale",), lower.scale)
        lag = tuple(new.get(("lag", j), v) for j, v in enumerate(lower.lag))
        return dataclasses.replace(t, lower=dataclasses.replace(lower, scale=scale, lag=lag))
    params = {int(k[0]): v for k, v in new.items()}
    mf = replace_mf(lower.mf, params)  # type: ignore[operator]
    return dataclasses.replace(t, lower=dataclasses.replace(lower, mf=mf))


def _ratio(term: Term, span: tuple[float, float]) -> float:
    """The largest factor in (0, 1] that keeps ``term``'s explicit lower function below
    its upper one when the lower is multiplied by it."""
    where = f"term {term.name}"
    up, lo = sets.points_of(term.mf, where), sets.lower_points(term, where)
    if up is not None and lo is not None:
        xs = sorted({x for x, _ in up} | {x for x, _ in lo})
    else:
        a, b = span
        xs = [a + (b - a) * i / (sets.CHECK_SAMPLES - 1) for i in range(sets.CHECK_SAMPLES)]
    pairs = [(sets.mf_value(term.mf, x, where), sets.lower_value(term, x, where)) for x in xs]
    factor = 1.0
    for u, v in pairs:
        if v > u and v > 0.0:
            factor = min(factor, u / v)
    return factor


def _scaled(mf: MembershipFunction, factor: float) -> MembershipFunction:
    if isinstance(mf, ShapeMF):
        return dataclasses.replace(mf, height=float(mf.height) * factor)  # type: ignore[arg-type]
    if isinstance(mf, PointsMF):
        pts = tuple(dataclasses.replace(p, y=float(p.y) * factor) for p in mf.points)  # type: ignore[arg-type]
        return dataclasses.replace(mf, points=pts)
    return mf


def project(fb: FunctionBlock) -> FunctionBlock:
    """``fb`` with each explicit lower function that exceeds its upper one lowered (its
    height times the largest factor that keeps it below)."""
    if not fb.is_type2:
        return fb

    def fix(blk: FuzzifyBlock | DefuzzifyBlock) -> FuzzifyBlock | DefuzzifyBlock:
        span = (blk.range.low, blk.range.high) if blk.range else _span(fb, blk.variable)
        terms = []
        for t in blk.terms:
            if t.lower is not None and t.lower.mf is not None:
                f = _ratio(t, span)
                if f < 1.0:
                    # a hair under the factor: the checker allows 1e-12, rounding must not cross it
                    t = dataclasses.replace(t, lower=LowerMF(_scaled(t.lower.mf, f * (1.0 - 1e-12))))
            terms.append(t)
        return dataclasses.replace(blk, terms=tuple(terms))

    return dataclasses.replace(
        fb,
        fuzzify=tuple(fix(b) for b in fb.fuzzify),  # type: ignore[misc]
        defuzzify=tuple(fix(b) for b in fb.defuzzify),  # type: ignore[misc]
    )


def _span(fb: FunctionBlock, name: str) -> tuple[float, float]:
    v = fb.variable(name)
    if v is not None and v.range is not None and v.range.low < v.range.high:
        return (v.range.low, v.range.high)
    return (-1.0, 1.0)


def _widenable(t: Term) -> bool:
    # fuzzy sets only: Takagi-Sugeno and singleton outputs have no footprint in MATLAB's form
    if isinstance(t.mf, ShapeMF):
        return not registry.flag(t.mf.kind, "takagi_sugeno")
    return isinstance(t.mf, PointsMF)


def widen(fb: FunctionBlock, *, scale: float = 1.0, lag: float = 0.0) -> FunctionBlock:
    """A type-2 block from a type-1 one: every input term, and every fuzzy-set output term,
    gets a lower function in MATLAB's form (``scale``, ``lag``; by default equal to the
    upper one, so the outputs do not change).  Terms that already have one keep it."""

    def wide(blk: FuzzifyBlock | DefuzzifyBlock) -> FuzzifyBlock | DefuzzifyBlock:
        terms = tuple(
            dataclasses.replace(t, lower=LowerMF(None, scale, (lag,)))
            if t.lower is None and _widenable(t)
            else t
            for t in blk.terms
        )
        return dataclasses.replace(blk, terms=terms)

    return dataclasses.replace(
        fb,
        fuzzify=tuple(wide(b) for b in fb.fuzzify),  # type: ignore[misc]
        defuzzify=tuple(wide(b) for b in fb.defuzzify),  # type: ignore[misc]
    )
