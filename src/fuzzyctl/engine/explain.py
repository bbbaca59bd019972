"""Structured explanations of one evaluation: every term degree, every rule's condition degree
and activation, each output's accumulated set (as breakpoints) and the defuzzified value."""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

import numpy as np

from fuzzyctl.engine.plan import Plan
from fuzzyctl.engine.reference import pwl
from fuzzyctl.engine.reference.interp import OutputRecord, Record
from fuzzyctl.jsonsafe import clean
from fuzzyctl.kinds import norms

if TYPE_CHECKING:
    from matplotlib.figure import Figure


@dataclass(frozen=True)
class TermDegree:
    variable: str
    term: str
    degree: float


@dataclass(frozen=True)
class ConclusionTrace:
    variable: str
    term: str | None
    weight: float
    degree: float  # the rule's degree after the conclusion's hedges (before the weight)


@dataclass(frozen=True)
class RuleTrace:
    block: str | None
    label: str
    degree: float  # the degree the rule fires with: its condition's, times a rule weight, if selected
    conclusions: tuple[ConclusionTrace, ...]
    condition: float | None = None  # the condition's degree of fulfilment alone

    @property
    def fired(self) -> bool:
        return self.degree > 0.0


@dataclass(frozen=True)
class OutputTrace:
    """An output: its value and the accumulated set that produced it.

    ``breakpoints`` is the accumulated set as a polyline ``((x, mu), ...)`` (repeated ``x`` =
    a vertical edge); ``singletons`` lists ``(position, degree)`` for singleton outputs;
    ``weights`` lists ``(term, weight, z)`` for Takagi-Sugeno outputs.  ``exact`` tells whether
    the polyline *is* the set (piecewise linear) or samples it (smooth shapes, PROBOR)."""

    name: str
    value: float
    fired: bool
    kind: str
    method: str
    accumulation: str | None
    low: float | None
    high: float | None
    breakpoints: tuple[tuple[float, float], ...]
    singletons: tuple[tuple[float, float], ...]
    weights: tuple[tuple[str, float, float], ...]
    exact: bool


@dataclass(frozen=True)
class Explanation:
    inputs: dict[str, float]
    terms: tuple[TermDegree, ...]
    rules: tuple[RuleTrace, ...]
    chained: tuple[TermDegree, ...]
    outputs: tuple[OutputTrace, ...]

    @property
    def values(self) -> dict[str, float]:
        return {o.name: o.value for o in self.outputs}

    def output(self, name: str) -> OutputTrace:
        return next(o for o in self.outputs if o.name == name)

    def rule(self, label: str, block: str | None = None) -> RuleTrace:
        return next(r for r in self.rules if r.label == label and (block is None or r.block == block))

    def plot(self) -> Figure:
        """The accumulated output sets and values as a matplotlib Figure."""
        from fuzzyctl.engine.plot import explanation_figure

        return explanation_figure(self)

    def to_dict(self) -> dict[str, Any]:
        """JSON-ready (NaN becomes None)."""
        out: dict[str, Any] = clean(dataclasses.asdict(self))
        return out


def polyline(pieces: list[pwl.Piece], samples_per_poly: int = 16) -> list[tuple[float, float]]:
    """The accumulated set as breakpoints (consecutive duplicates removed)."""
    pts: list[tuple[float, float]] = []

    def add(x: float, y: float) -> None:
        if not pts or pts[-1] != (x, y):
            pts.append((x, y))

    for x0, x1, v0, v1, factors in pieces:
        if pts and x0 > pts[-1][0]:  # pieces where the set is 0 are left out: close the gap
            add(pts[-1][0], 0.0)
            add(x0, 0.0)
        add(x0, v0)
        if factors is not None:
            for i in range(1, samples_per_poly):
                s = i / samples_per_poly
                add(x0 + s * (x1 - x0), pwl._poly_value(factors, s))
        add(x1, v1)
    return pts


def build(plan: Plan, inputs: dict[str, float], rec: Record) -> Explanation:
    terms = tuple(
        TermDegree(fi.name, t.name, d)
        for fi, degs in zip(plan.fuzzy_inputs, rec.term_degrees, strict=True)
        for t, d in zip(fi.terms, degs, strict=True)
    )
    chained = tuple(
        TermDegree(c.name, tn, d)
        for c, degs in zip(plan.chained, rec.chained_degrees, strict=True)
        for tn, d in zip(c.terms, degs, strict=True)
    )
    rules = []
    for ri, r in enumerate(plan.rules):
        concl = []
        for cp, (d, w) in zip(r.conclusions, rec.conclusion_degrees[ri], strict=False):
            if cp.outputs:
                op = plan.outputs[cp.outputs[0]]
                var = op.name
                term = op.terms[cp.term].name if cp.term is not None and op.terms else None
            else:
                ch = plan.chained[cp.chained[0]]
                var = ch.name
                term = ch.terms[cp.term] if cp.term is not None else None
            concl.append(ConclusionTrace(var, term, w, d))
        condition = rec.condition_degrees[ri] if rec.condition_degrees else None
        rules.append(RuleTrace(r.block, r.label, rec.rule_degrees[ri], tuple(concl), condition))
    outs = tuple(_output(plan, i, o) for i, o in enumerate(rec.outputs))
    return Explanation(dict(inputs), terms, tuple(rules), chained, outs)


def _output(plan: Plan, index: int, o: OutputRecord) -> OutputTrace:
    op = plan.outputs[index]
    bps: list[tuple[float, float]] = []
    exact = False
    if o.pieces:
        bps = polyline(o.pieces)
        exact = all(p[4] is None for p in o.pieces)
        if norms.normalised(op.accu):
            top = max([1.0, *(v for _x, v in bps)])
            bps = [(x, v / top) for x, v in bps]
    elif o.samples is not None:
        xs, ys = o.samples
        bps = [(float(x), float(y)) for x, y in zip(np.asarray(xs), np.asarray(ys), strict=True)]
    elif op.kind == "mamdani" and op.low is not None and op.high is not None:
        bps = [(op.low, 0.0), (op.high, 0.0)]
        exact = True
    singles = tuple(o.points) if op.kind == "singleton" else ()
    return OutputTrace(
        op.name,
        o.value,
        o.fired,
        op.kind,
        op.method,
        op.accu,
        op.low,
        op.high,
        tuple(bps),
        singles,
        tuple(o.weights),
        exact,
    )
