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

The terms, t-norms, aggregation and the sampled defuzzifiers come from the engine
(:mod:`fuzzyctl.engine.semantics.shapes`, :mod:`~fuzzyctl.engine.semantics.operators`,
:mod:`~fuzzyctl.engine.reference.sampled`); what is particular to XFUZ is the choice of the Discr
points and the two levels.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from fuzzyctl.engine.reference.sampled import mean_of_maxima, sampled_centroid, weighted_mean
from fuzzyctl.engine.semantics.operators import TNORMS, accumulate, accumulate_np
from fuzzyctl.engine.semantics.shapes import Points, pwl_points, pwl_value, pwl_value_np
from fuzzyctl.formats.xfuz.tables import (
    INT16_MAX,
    INT16_MIN,
    KnowledgeBase,
    SlotKind,
    XMembership,
    slot_kind,
)

FloatArray = NDArray[np.float64]

__all__ = ["InferenceResult", "XfuzInference", "discretisation_points", "to_word", "trapezoid"]


def term_points(mf: XMembership) -> Points:
    """An XFUZ term as an engine breakpoint list: 0 at A, 1 on [B, C], 0 at D.  The open
    sides (-32768, 32767) are ordinary abscissae at the ends of the 16-bit range, and a
    vertical side belongs to the plateau (the engine takes the upper value on an edge)."""
    points = pwl_points("trapezoid", [float(p) for p in mf.points])
    assert points is not None
    return points


def trapezoid(x: FloatArray | float, mf: XMembership) -> FloatArray:
    """Degree of an XFUZ term at ``x`` (scalar or array), by the engine's shape formulas."""
    return pwl_value_np(term_points(mf), np.asarray(x, dtype=np.float64))


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


def _conjunction(norm: str, values: Sequence[float]) -> float:
    """OP_ET over a rule's predicates."""
    t = TNORMS[norm].scalar
    result = values[0]
    for v in values[1:]:
        result = t(result, v)
    return result


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
        self.input_terms = tuple(
            (m.number, m.slot, term_points(m)) for m in kb.memberships if 0 <= m.slot < 8
        )
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
        and_norm = "PROD" if op_et == 1 else "MIN"
        impl = TNORMS["PROD" if op_impl == 1 else "MIN"].array
        sets: dict[int, FloatArray] = {slot: np.zeros_like(xs) for slot, xs in self.points.items()}
        points_degree: dict[int, float] = {}  # singleton mode: aggregated degree of each output term
        degrees = [0.0] * len(kb.rules)
        input_degree = {n: pwl_value(points, float(inputs[slot])) for n, slot, points in self.input_terms}

        def predicate(number: int) -> float:
            if number in input_degree:
                return input_degree[number]
            mf = kb.memberships[number]
            if out_pt or mf.slot not in sets or number not in self.sampled:
                # Only reachable when OUT_PT changed without REFRESH (2.8: "evaluation
                # erroneous"); we take such predicates as false.
                return 0.0
            # OP_CONJ: max over the Discr points of min(F, mu).
            return float(np.max(TNORMS["MIN"].array(sets[mf.slot], self.sampled[number])))

        for level in (1, 2):
            for r, rule in enumerate(kb.rules):
                if self.levels[r] != level:
                    continue
                truths = [1.0 - predicate(n) if neg else predicate(n) for n, neg in rule.predicates]
                degree = _conjunction(and_norm, truths) if truths else 0.0
                degrees[r] = degree
                if degree <= 0.0:
                    continue
                for number in rule.conclusions:
                    mf = kb.memberships[number]
                    if out_pt and slot_kind(mf.slot) is SlotKind.OUTPUT:
                        points_degree[number] = accumulate("MAX", points_degree.get(number, 0.0), degree)
                    elif number in self.sampled:
                        limited = impl(degree, self.sampled[number])  # OP_IMPL
                        sets[mf.slot] = accumulate_np("MAX", sets[mf.slot], limited)  # OP_AGREG
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
                (self.kb.memberships[n].singleton(), w)
                for n, w in points_degree.items()
                if self.kb.memberships[n].slot == slot
            ]
            return weighted_mean([x for x, _ in weights], [w for _, w in weights])
        if slot not in sets:
            return None
        if op_defuz == 1:
            return mean_of_maxima(self.points[slot], sets[slot])
        return sampled_centroid(self.points[slot], sets[slot])
