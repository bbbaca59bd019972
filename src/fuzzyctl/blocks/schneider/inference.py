"""The inference of the XFUZ block (manual 2.2): Mamdani rules on 16-bit integer inputs,
output and intermediate fuzzy sets sampled on ``Discr`` points, two inference levels.

1. Input terms are evaluated at the crisp input ("fuzzy singleton" inputs, 2.2-4).
2. A rule's degree is the AND (OP_ET: MIN or product) of its predicates; a predicate with
   +100 takes ``1 - degree``.
3. Each conclusion is the conclusion term limited by the degree (OP_IMPL: MIN or product),
   sampled on the variable's Discr points ``BorneInf + k (BorneSup - BorneInf) / (Discr - 1)``.
4. Conclusions are aggregated by MAX (OP_AGREG).
5. Rules with a predicate on an intermediate variable or an output form the second level;
   such a predicate's degree is the compatibility ``max_k min(F(x_k), mu(x_k))`` of the
   first-level fuzzy set ``F`` with the term (OP_CONJ MAX/MIN), without defuzzification.
6. Outputs are defuzzified on the Discr points: centre of gravity or mean of maxima
   (OP_DEFUZ); with OUT_PT = 1 an output term is reduced to its point and the output is
   the mean of those points weighted by their aggregated degrees.

The t-norms and the aggregation come from :mod:`fuzzyctl.engine.operators`; what is
particular to XFUZ is only the sampling on Discr points and the two levels.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Sequence
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from fuzzyctl.formats.xfuz_tables import (
    INT16_MAX,
    INT16_MIN,
    KnowledgeBase,
    SlotKind,
    XMembership,
    slot_kind,
)

FloatArray = NDArray[np.float64]

__all__ = ["InferenceResult", "XfuzInference", "discretisation_points", "to_word", "trapezoid"]


def trapezoid(x: FloatArray | float, mf: XMembership) -> FloatArray:
    """Degree of an XFUZ term (points A <= B <= C <= D, open sides at -32768/32767).

    1 on [B, C], linear on ]A, B[ and ]C, D[, 0 elsewhere; a vertical side (A = B or
    C = D) belongs to the plateau."""
    xs = np.asarray(x, dtype=np.float64)
    a, b, c, d = (float(p) for p in mf.points)
    with np.errstate(divide="ignore", invalid="ignore"):
        rise = np.where(b > a, (xs - a) / (b - a if b > a else 1.0), 0.0)
        fall = np.where(d > c, (d - xs) / (d - c if d > c else 1.0), 0.0)
    mu = np.where(
        (xs >= b) & (xs <= c),
        1.0,
        np.where((xs > a) & (xs < b), rise, np.where((xs > c) & (xs < d), fall, 0.0)),
    )
    return np.asarray(mu, dtype=np.float64)


def discretisation_points(low: int, high: int, discr: int) -> FloatArray:
    """The Discr abscissae where an output or intermediate fuzzy set is computed."""
    n = max(int(discr), 2)
    return np.linspace(float(low), float(high), n)


def to_word(value: float) -> int:
    """A computed output as a 16-bit word: rounded half away from zero, saturated."""
    rounded = math.floor(abs(value) + 0.5) * (1 if value >= 0 else -1)
    return int(min(max(rounded, INT16_MIN), INT16_MAX))


@dataclass(frozen=True)
class InferenceResult:
    """One run of the rules.

    ``outputs`` maps an output number (1-6) to its value, or to None when no active rule
    concerns it (the block then uses Oi_DEF); ``degrees`` holds each rule's activation."""

    outputs: dict[int, float | None]
    degrees: tuple[float, ...]

    @property
    def any_active(self) -> bool:
        return any(d > 0.0 for d in self.degrees)


def _min_and(values: Sequence[float]) -> float:
    return min(values)


def _prod_and(values: Sequence[float]) -> float:
    return math.prod(values)


class XfuzInference:
    """The rules of one knowledge base, with the terms sampled once on their points."""

    def __init__(self, kb: KnowledgeBase) -> None:
        self.kb = kb
        self.points: dict[int, FloatArray] = {}
        self.sampled: dict[int, FloatArray] = {}
        for v in kb.variables:
            if v.kind is not SlotKind.INPUT and v.discr >= 2 and v.high > v.low:
                self.points[v.slot] = discretisation_points(v.low, v.high, v.discr)
        for mf in kb.memberships:
            if mf.slot in self.points:
                self.sampled[mf.number] = trapezoid(self.points[mf.slot], mf)
        self.levels = tuple(kb.rule_level(r) for r in kb.rules)
        self.outputs = sorted(
            {m.slot for m in kb.memberships if 0 <= m.slot < 18 and slot_kind(m.slot) is SlotKind.OUTPUT}
        )

    def run(
        self,
        inputs: Sequence[int],
        *,
        op_et: int = 0,
        op_impl: int = 0,
        op_defuz: int = 0,
        out_pt: bool = False,
    ) -> InferenceResult:
        """Evaluate the rules for the 8 input words."""
        kb = self.kb
        conj: Callable[[Sequence[float]], float] = _prod_and if op_et == 1 else _min_and
        sets: dict[int, FloatArray] = {slot: np.zeros_like(xs) for slot, xs in self.points.items()}
        points_degree: dict[int, float] = {}  # singleton mode: aggregated degree of each output term
        degrees = [0.0] * len(kb.rules)
        input_degree = {
            m.number: float(trapezoid(float(inputs[m.slot]), m)) for m in kb.memberships if 0 <= m.slot < 8
        }

        def predicate(number: int) -> float:
            if number in input_degree:
                return input_degree[number]
            mf = kb.memberships[number]
            if out_pt or mf.slot not in sets or number not in self.sampled:
                # Only reachable when OUT_PT changed without REFRESH (2.8: "evaluation
                # erroneous"); we take such predicates as false.
                return 0.0
            return float(np.max(np.minimum(sets[mf.slot], self.sampled[number])))

        for level in (1, 2):
            for r, rule in enumerate(kb.rules):
                if self.levels[r] != level:
                    continue
                truths = [1.0 - predicate(n) if neg else predicate(n) for n, neg in rule.predicates]
                degree = conj(truths) if truths else 0.0
                degrees[r] = degree
                if degree <= 0.0:
                    continue
                for number in rule.conclusions:
                    mf = kb.memberships[number]
                    if out_pt and slot_kind(mf.slot) is SlotKind.OUTPUT:
                        points_degree[number] = max(points_degree.get(number, 0.0), degree)
                    elif number in self.sampled:
                        limited = (
                            degree * self.sampled[number]
                            if op_impl == 1
                            else np.minimum(degree, self.sampled[number])
                        )
                        np.maximum(sets[mf.slot], limited, out=sets[mf.slot])
        outputs: dict[int, float | None] = {}
        for slot in self.outputs:
            outputs[slot - 7] = self._defuzzify(slot, sets, points_degree, op_defuz, out_pt)
        return InferenceResult(outputs, tuple(degrees))

    def _defuzzify(
        self,
        slot: int,
        sets: dict[int, FloatArray],
        points_degree: dict[int, float],
        op_defuz: int,
        out_pt: bool,
    ) -> float | None:
        if out_pt:
            weights = [
                (w, self.kb.memberships[n].singleton())
                for n, w in points_degree.items()
                if self.kb.memberships[n].slot == slot
            ]
            total = sum(w for w, _ in weights)
            return sum(w * x for w, x in weights) / total if total > 0 else None
        if slot not in sets:
            return None
        f, xs = sets[slot], self.points[slot]
        total = float(f.sum())
        if total <= 0.0:
            return None
        if op_defuz == 1:
            top = float(f.max())
            return float(xs[f == top].mean())
        return float((f * xs).sum() / total)
