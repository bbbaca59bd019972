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


def _lower_set(term: Term, act: str, firing: float, low: float, high: float) -> dict[str, Any] | None:
    """The set a conclusion activates on the lower function: ``act(firing, lower(x))``
    over the output's range (the lower curve's breakpoints included)."""
    from fuzzyctl.engine.semantics.operators import TNORMS

    curve = _lower_curve(term, low, high)
    if curve is None:
        return None
    xs = sorted({low + (high - low) * i / (SAMPLES - 1) for i in range(SAMPLES)} | {p[0] for p in curve})
    xs = [x for x in xs if low <= x <= high]
    where = f"term {term.name}"
    norm = TNORMS[act].scalar
    return {"x": xs, "y": [float(norm(firing, sets.lower_value(term, x, where))) for x in xs]}


def rule_view(
    controller: Any, fb: FunctionBlock, inputs: dict[str, float], ranges: dict[str, list[float]]
) -> dict[str, Any]:
    """The rule viewer's rows for a type-2 system: each literal's degree interval
    (``lower``, ``degree`` the upper), each rule's firing interval, each conclusion's
    activated upper set (``set``) and lower set (``lower_set``), and each output's
    type-reduced ``interval`` with its value."""
    from fuzzyctl.studio.ruleview import activated, literals, rule_text

    e = controller.explain(inputs)
    x = e.inputs
    rows: list[dict[str, Any]] = []
    fired = iter(e.rules)
    for bi, rb in enumerate(fb.rule_blocks):
        for ri, rule in enumerate(rb.rules):
            interval = next(fired)
            lits = []
            for lit in literals(rule.condition):
                blk = fb.fuzzify_block(lit.variable)
                term = blk.term(lit.term) if blk is not None else None
                where = f"term {lit.variable}.{lit.term}"
                up = sets.mf_value(term.mf, x[lit.variable], where) if term is not None else None
                lo = sets.lower_value(term, x[lit.variable], where) if term is not None else None
                lits.append(
                    {
                        "variable": lit.variable,
                        "term": lit.term,
                        "negated": lit.negated,
                        "hedges": list(lit.hedges),
                        "degree": up,
                        "lower": lo,
                    }
                )
            conclusions = []
            for c in rule.conclusions:
                dblk = fb.defuzzify_block(c.variable)
                term = dblk.term(c.term) if dblk is not None and c.term is not None else None
                low, high = ranges.get(c.variable, [0.0, 1.0])
                conclusions.append(
                    {
                        "variable": c.variable,
                        "term": c.term,
                        "weight": 1.0,
                        "degree": interval.upper,
                        "lower": interval.lower,
                        "set": activated(term, controller.act, interval.upper, 1.0, False, low, high),
                        "lower_set": _lower_set(term, controller.act, interval.lower, low, high)
                        if term is not None and term.lower is not None
                        else None,
                    }
                )
            rows.append(
                {
                    "block": bi,
                    "index": ri,
                    "label": rule.label,
                    "text": rule_text(rule.condition, rule.conclusions),
                    "literals": lits,
                    "evaluated": True,
                    "degree": interval.upper,
                    "lower": interval.lower,
                    "conclusions": conclusions,
                }
            )
    outputs = [{"name": o.name, "value": o.value, "interval": [o.yl, o.yr]} for o in e.outputs]
    return {"inputs": x, "rules": rows, "outputs": outputs, "type2": True}
