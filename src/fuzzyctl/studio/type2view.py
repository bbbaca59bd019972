"""Interval type-2 systems in the studio (docs/type2.md, "Studio"): the footprint of
uncertainty of each term (the lower curve drawn under the upper one), lower <= upper
checked as a diagnostic on the term, and the explanation of a point with firing intervals
and the type-reduced interval, in the shape the explain view reads."""

from __future__ import annotations

from typing import Any

from fuzzyctl.diagnostics import Diagnostic, Severity
from fuzzyctl.engine import type2_sets as sets
from fuzzyctl.model import DefuzzifyBlock, FunctionBlock, FuzzifyBlock, Term

SAMPLES = 201
"""Samples of a smooth lower function over the display range (as for smooth upper ones)."""


def _lower_curve(term: Term, low: float, high: float) -> list[list[float]] | None:
    where = f"term {term.name}"
    try:
        pts = sets.lower_points(term, where)
        if pts is None:
            xs = [low + (high - low) * i / (SAMPLES - 1) for i in range(SAMPLES)]
            return [[x, sets.lower_value(term, x, where)] for x in xs]
        out = [[float(x), float(y)] for x, y in pts]
        # constant beyond the first and the last point, as the engine reads them
        if low < out[0][0]:
            out.insert(0, [low, sets.lower_value(term, low, where)])
        if high > out[-1][0]:
            out.append([high, sets.lower_value(term, high, where)])
        return out
    except (sets.Type2Error, ValueError, ZeroDivisionError, TypeError):
        return None  # the check report says why


def lower_form(term: Term) -> dict[str, Any]:
    """The lower function as the editor's fields read it (``lower_fcl``: the FCL ``LOWER``
    clause; ``lower_kind``: ``scale_lag`` or ``mf``)."""
    from fuzzyctl.formats.fcl.type2 import lower_text

    assert term.lower is not None
    kind = "mf" if term.lower.mf is not None else "scale_lag"
    return {"lower_kind": kind, "lower_fcl": lower_text(term.lower)}


def _term_blocks(fb: FunctionBlock) -> list[FuzzifyBlock | DefuzzifyBlock]:
    return [*fb.fuzzify, *fb.defuzzify]


def add_lower_curves(fb: FunctionBlock, ranges: dict[str, list[float]], curves: dict[str, Any]) -> None:
    """Add ``lower`` (points from the range's start to its end) to the curve of every
    type-2 term of ``fb``, in place."""
    if not fb.is_type2:
        return
    for blk in _term_blocks(fb):
        low, high = ranges[blk.variable]
        for t in blk.terms:
            shape = curves.get(blk.variable, {}).get(t.name)
            if t.lower is None or shape is None:
                continue
            lower = _lower_curve(t, low, high)
            if lower is not None:
                shape["lower"] = lower
            shape.update(lower_form(t))


def lower_diagnostics(fb: FunctionBlock) -> list[Diagnostic]:
    """An error on each term whose lower function exceeds its upper one (or is not valid:
    a scale outside (0, 1], a lag outside [0, 1)), at the term."""
    out: list[Diagnostic] = []
    if not fb.is_type2:
        return out
    for blk in _term_blocks(fb):
        rng = (blk.range.low, blk.range.high) if blk.range else _declared(fb, blk.variable)
        for t in blk.terms:
            problem = sets.lower_problem(t, rng, f"term {blk.variable}.{t.name}")
            if problem:
                out.append(Diagnostic(Severity.ERROR, problem, t.span, code="type2-lower"))
    return out


def _declared(fb: FunctionBlock, name: str) -> tuple[float, float]:
    v = fb.variable(name)
    if v is not None and v.range is not None and v.range.low < v.range.high:
        return (v.range.low, v.range.high)
    return (-1.0, 1.0)


def is_type2(controller: Any) -> bool:
    from fuzzyctl.engine.type2 import Type2Controller

    return isinstance(controller, Type2Controller)


def explain(controller: Any, fb: FunctionBlock, inputs: dict[str, float]) -> dict[str, Any]:
    """The explain view's answer for a type-2 system: each input term's degree interval
    (``lower``, ``degree`` the upper), each rule's firing interval (``lower``, ``degree``)
    and each output's type-reduced ``interval`` with its value."""
    e = controller.explain(inputs)
    x = e.inputs
    terms = []
    for blk in fb.fuzzify:
        for t in blk.terms:
            where = f"term {blk.variable}.{t.name}"
            terms.append(
                {
                    "variable": blk.variable,
                    "term": t.name,
                    "degree": sets.mf_value(t.mf, x[blk.variable], where),
                    "lower": sets.lower_value(t, x[blk.variable], where),
                }
            )
    rules = []
    for (block, rule), fired in zip(fb.rules(), e.rules, strict=True):
        rules.append(
            {
                "block": block.name,
                "label": fired.label,
                "degree": fired.upper,
                "lower": fired.lower,
                "conclusions": [{"variable": c.variable, "term": c.term} for c in rule.conclusions],
            }
        )
    outputs = [
        {
            "name": o.name,
            "value": o.value,
            "interval": [o.yl, o.yr],
            "method": f"type-2 {o.method}, {'exact' if o.exact else 'sampled'}",
            "type_reduction": o.method,
            "exact": o.exact,
        }
        for o in e.outputs
    ]
    return {"type2": True, "inputs": x, "terms": terms, "rules": rules, "outputs": outputs}
