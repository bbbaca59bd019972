"""The rule viewer in the manner of MATLAB's: for one input point, each rule as a row -
the degree of every term its condition reads, the degree it fires with, and the output set
each conclusion activates - with the accumulated sets and the outputs at the bottom.

Everything comes from the engine: the degrees from ``explain``, the activation operator
and the weight convention from the compiled plan, the term shapes from
``fuzzyctl.engine.semantics.shapes``; the activated set of a conclusion is ``w * act(d, mu)`` (IEC
61131-7; ``act(w * d, mu)`` under the fuzzylite option) sampled over the output's range.
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np

from fuzzyctl.engine.semantics.operators import TNORMS
from fuzzyctl.engine.semantics.shapes import FloatArray, membership_np, pwl_points
from fuzzyctl.fcl.writer import conclusion_text, condition_text
from fuzzyctl.kinds import shapes as registry
from fuzzyctl.model import (
    And,
    Condition,
    FunctionBlock,
    Is,
    Not,
    Or,
    PointsMF,
    Ref,
    ShapeMF,
    SingletonMF,
    SingletonsMF,
    Term,
)

SAMPLES = 101


def literals(condition: Condition | None) -> list[Is]:
    """The ``variable IS term`` parts of a condition, in reading order."""
    if condition is None:
        return []
    if isinstance(condition, Is):
        return [condition]
    if isinstance(condition, Not):
        return literals(condition.operand)
    if isinstance(condition, And | Or):
        return [lit for c in condition.operands for lit in literals(c)]
    return []


def rule_text(condition: Condition | None, conclusions: Any) -> str:
    """``IF ... THEN ...`` as the FCL text writes it, without the label."""
    return f"IF {condition_text(condition) if condition is not None else ''} THEN " + ", ".join(
        conclusion_text(c) for c in conclusions
    )


def _grid(term: Term, low: float, high: float) -> tuple[FloatArray, FloatArray] | None:
    """The term's degrees over ``[low, high]`` (breakpoints of piecewise-linear shapes
    included, so a clipped corner is drawn where it is); None for terms that are not a
    fuzzy set with constant parameters."""
    mf = term.mf
    xs = np.linspace(low, high, SAMPLES)
    if isinstance(mf, PointsMF):
        if any(isinstance(c, Ref) for p in mf.points for c in (p.x, p.y)):
            return None
        flat = [float(c) for p in mf.points for c in (p.x, p.y)]  # type: ignore[arg-type]
        corners = [float(p.x) for p in mf.points]  # type: ignore[arg-type]
        xs = np.unique(np.concatenate([xs, [x for x in corners if low <= x <= high]]))
        return xs, membership_np("points", flat, 1.0, xs)
    if isinstance(mf, ShapeMF) and not registry.flag(mf.kind, "takagi_sugeno"):
        if any(isinstance(p, Ref) for p in (*mf.params, mf.height)):
            return None
        params = [float(p) for p in mf.params]  # type: ignore[arg-type]
        height = float(mf.height)  # type: ignore[arg-type]
        exact = pwl_points(mf.kind, params, height)
        if exact is not None:
            corners = [x for x, _y in exact if math.isfinite(x) and low <= x <= high]
            xs = np.unique(np.concatenate([xs, corners]))
        return xs, membership_np(mf.kind, params, height, xs)
    return None


def _spikes(term: Term) -> list[tuple[float, float]] | None:
    mf = term.mf
    if isinstance(mf, SingletonMF) and not isinstance(mf.value, Ref):
        return [(float(mf.value), 1.0)]
    if isinstance(mf, SingletonsMF) and not any(isinstance(c, Ref) for p in mf.points for c in (p.x, p.y)):
        return [(float(p.x), float(p.y)) for p in mf.points]  # type: ignore[arg-type]
    return None


def _clean(values: Any) -> list[float | None]:
    return [float(v) if math.isfinite(v) else None for v in np.asarray(values, dtype=float).ravel()]


def activated(
    term: Term | None, act: str, degree: float, weight: float, before: bool, low: float, high: float
) -> dict[str, Any] | None:
    """The set a conclusion activates: ``{"x", "y"}`` or ``{"spikes": [[x, y], ...]}``."""
    if term is None:
        return None
    norm = TNORMS[act].array
    a, w = (weight * degree, 1.0) if before else (degree, weight)
    spikes = _spikes(term)
    if spikes is not None:
        return {"spikes": [[x, float(w * norm(np.float64(a), np.float64(mu)))] for x, mu in spikes]}
    grid = _grid(term, low, high)
    if grid is None:
        return None
    xs, mu = grid
    return {"x": _clean(xs), "y": _clean(w * norm(np.full(xs.shape, a), mu))}


def rule_view(
    controller: Any, fb: FunctionBlock, inputs: dict[str, float], ranges: dict[str, list[float]]
) -> dict[str, Any]:
    """The rows of the rule viewer at ``inputs`` (a fresh evaluation)."""
    from fuzzyctl.studio import type2view

    if type2view.is_type2(controller):
        return type2view.rule_view(controller, fb, inputs, ranges)
    controller.reset()
    explanation = controller.explain(inputs)
    plan = controller.plan
    before = plan.options.weight_before_activation
    degrees = {(t.variable, t.term): t.degree for t in explanation.terms}
    traces = list(zip(plan.rules, explanation.rules, strict=True))
    rows: list[dict[str, Any]] = []
    k = 0
    for bi, rb in enumerate(fb.rule_blocks):
        for ri, rule in enumerate(rb.rules):
            row: dict[str, Any] = {
                "block": bi,
                "index": ri,
                "label": rule.label,
                "text": rule_text(rule.condition, rule.conclusions),
                "literals": [
                    {
                        "variable": lit.variable,
                        "term": lit.term,
                        "negated": lit.negated,
                        "hedges": list(lit.hedges),
                        "degree": degrees.get((lit.variable, lit.term)),
                    }
                    for lit in literals(rule.condition)
                ],
                "evaluated": False,
                "degree": None,
                "conclusions": [],
            }
            here = k < len(traces) and (traces[k][0].label, traces[k][0].block) == (rule.label, rb.name)
            if rb.enabled and here:
                plan_rule, trace = traces[k]
                k += 1
                row["evaluated"] = True
                row["degree"] = trace.degree
                for c in trace.conclusions:
                    blk = fb.defuzzify_block(c.variable)
                    term = blk.term(c.term) if blk is not None and c.term is not None else None
                    low, high = ranges.get(c.variable, [0.0, 1.0])
                    row["conclusions"].append(
                        {
                            "variable": c.variable,
                            "term": c.term,
                            "weight": c.weight,
                            "degree": c.degree,
                            "set": activated(term, plan_rule.act, c.degree, c.weight, before, low, high),
                        }
                    )
            rows.append(row)
    result: dict[str, Any] = explanation.to_dict()
    return {"inputs": result["inputs"], "rules": rows, "outputs": result["outputs"]}
