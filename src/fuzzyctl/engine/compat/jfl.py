"""jFuzzyLogic 3.3, reproduced: the evaluator of plans compiled with ``compat="jfuzzylogic"``.

The IEC engine computes what IEC 61131-7 defines, exactly.  This module computes what
jFuzzyLogic computes (``FunctionBlock.evaluate``), step for step, so that a system written for
it gives its numbers to the last few bits (measured against the live jFuzzyLogic,
docs/engine.md).  Lowering has already made jFuzzyLogic's reading decisions (the last AND/OR
declaration sets both operators, AND/OR left to right, ACCU SUM by default and NSUM as BSUM,
the span of the terms as universe, RANGE on a declaration line ignored, the last of two
terms of one name, each rule block's ACCU on its rules); here is what happens at run time:

* each evaluation starts from a reset: an output with DEFAULT takes that value, one with NC
  (or no DEFAULT) keeps its last value - NaN before the first - and a condition on an output
  reads that crisp value through the output's term (no chained degrees);
* rule blocks run in the order of a ``java.util.HashMap`` keyed by their names, rules in
  order; a rule fires with ``condition * WITH`` and adds ``ACT(degree, mu)`` into its
  output's set with its block's ACCU, one conclusion after the other;
* continuous outputs are sets sampled at 1000 points ``x += (max - min) / 1000`` from
  ``min``; COG is the sum of x*mu over the sum of mu, COA, LM, RM and MM walk the samples as
  jFuzzyLogic's loops do (``DefuzzifierContinuous`` and its subclasses);
* singleton and FUNCTION terms (COGS, COGF) accumulate into one value per position, merged
  under the ACCU when two terms sit at the same x (``DefuzzifierDiscrete``);
* a defuzzifier that gives NaN (nothing fired) leaves the reset value.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from fuzzyctl.diagnostics import FuzzyctlError
from fuzzyctl.engine.compat import jfl_terms as jt
from fuzzyctl.engine.plan import (
    CAnd,
    CChained,
    CDegree,
    CNot,
    CondPlan,
    COr,
    CTerm,
    CTrue,
    EOutput,
    ExprPlan,
    OutputPlan,
    Plan,
    PParam,
    Slot,
    TermPlan,
)
from fuzzyctl.engine.reference.interp import OutputRecord, Record
from fuzzyctl.engine.semantics import shapes
from fuzzyctl.kinds import shapes as registry
from fuzzyctl.kinds.methods import METHODS

__all__ = ["SAMPLES", "JflEvaluator"]

SAMPLES = 1000  # DefuzzifierContinuous.DEFAULT_NUMBER_OF_POINTS
_CHUNK = 256
Arr = Any


@dataclass
class _Eval:
    """One evaluation of ``n`` rows (everything :meth:`JflEvaluator.record` shows)."""

    term_degrees: list[list[Arr]]
    conditions: list[Arr]
    degrees: list[list[Arr]]  # per rule, per conclusion: the degree it is activated with
    raw: list[Arr]  # per output: the defuzzified value, NaN where nothing fired
    sets: list[Arr | None] = field(default_factory=list)  # continuous outputs: (n, SAMPLES)
    points: list[list[tuple[Arr, Arr, Arr]]] = field(default_factory=list)  # discrete: (x, value, held)


class JflEvaluator:
    """Evaluates a ``jfuzzylogic`` plan over rows; rows are successive evaluations of one
    function block (its outputs' values carry over, as in jFuzzyLogic)."""

    def __init__(self, plan: Plan) -> None:
        if plan.options.emulate != "jfuzzylogic":
            raise ValueError("JflEvaluator evaluates plans compiled with compat='jfuzzylogic'")
        if plan.selections:
            raise FuzzyctlError("the jfuzzylogic profile has no rule activation methods (fuzzylite's)")
        self.plan = plan
        for op in plan.outputs:
            if op.kind == "degree" and op.contributions:
                raise FuzzyctlError(f"output {op.name}: jFuzzyLogic has no conclusions without a term")
            for t in op.terms if op.kind != "mamdani" and op.contributions else ():
                if not (
                    t.kind in ("singleton", "singletons", "function") or registry.flag(t.kind, "ts_constant")
                ):
                    raise FuzzyctlError(f"term {op.name}.{t.name}: jFuzzyLogic has no {t.kind} output terms")
        names = [o.name for o in plan.outputs]
        self.chained_output: list[int] = []
        for ch in plan.chained:
            if ch.name not in names:
                raise FuzzyctlError(
                    f"{ch.name}: the jfuzzylogic profile reads a variable in a condition through its "
                    "crisp value, and only outputs have one (jFuzzyLogic has no local variables)"
                )
            self.chained_output.append(names.index(ch.name))
        blocks: list[str | None] = list(dict.fromkeys(r.block for r in plan.rules))
        keys = [b if b is not None else f"RuleBlock_{i + 1}" for i, b in enumerate(blocks)]
        by_block = {b: [i for i, r in enumerate(plan.rules) if r.block == b] for b in blocks}
        self.rule_order = [i for k in jt.hashmap_order(keys) for i in by_block[blocks[k]]]
        self.exprs: dict[tuple[int, int], ExprPlan] = {
            (oi, ti): jt.jfl_expr(t.expr)
            for oi, o in enumerate(plan.outputs)
            for ti, t in enumerate(o.terms)
            if t.expr is not None
        }
        # an NC output whose crisp value a condition or function reads: rows depend on each other
        read = {
            self.chained_output[c.var]
            for r in plan.rules
            for c in _walk(r.condition)
            if isinstance(c, CChained)
        }
        read |= {o for e in self.exprs.values() for o in _outputs_read(e)}
        self.sequential = any(plan.outputs[o].default is None or plan.outputs[o].no_change for o in read)
        self.xs: list[Arr | None] = []
        for op in plan.outputs:
            if op.kind == "mamdani":
                assert op.low is not None and op.high is not None
                step = (op.high - op.low) / SAMPLES
                # x += step, as jFuzzyLogic's loops: the drift decides which side of a vertical
                # edge a sample falls on
                self.xs.append(np.cumsum(np.r_[op.low, np.full(SAMPLES - 1, step)]))
            else:
                self.xs.append(None)

    # ------------------------------------------------------------------ rows

    def run(self, values: Sequence[Arr], state: list[float | None], n: int | None = None) -> list[Arr]:
        """Outputs for every row; ``state`` (each output's value, None before the first) is
        updated to the last row's."""
        rows = n if n is not None else (len(values[0]) if values else 1)
        vals = [np.asarray(v, dtype=np.float64) for v in values]
        outs = [np.empty(rows) for _ in self.plan.outputs]
        if self.sequential:
            for r in range(rows):
                got = self._step([v[r : r + 1] for v in vals], state, 1)
                for o, g in zip(outs, got, strict=True):
                    o[r] = g[0]
            return outs
        for start in range(0, rows, _CHUNK):  # (rows, 1000) sets: a few MB at a time
            stop = min(rows, start + _CHUNK)
            got = self._step([v[start:stop] for v in vals], state, stop - start)
            for o, g in zip(outs, got, strict=True):
                o[start:stop] = g
        return outs

    def _step(self, vals: list[Arr], state: list[float | None], n: int) -> list[Arr]:
        start = [self._reset_value(oi, state) for oi in range(len(self.plan.outputs))]
        ev = self._eval(vals, [np.full(n, s) for s in start], n)
        outs = []
        for oi, op in enumerate(self.plan.outputs):
            raw = ev.raw[oi]
            if op.default is not None and not op.no_change:
                value = np.where(np.isnan(raw), op.default, raw)
            else:  # keeps the previous value: carry the last number forward
                idx = np.where(np.isnan(raw), -1, np.arange(n))
                idx = np.maximum.accumulate(idx) if n else idx
                value = np.where(idx < 0, start[oi], raw[np.maximum(idx, 0)])
            outs.append(value)
            if n:
                state[oi] = float(value[-1])
        return outs

    def _reset_value(self, oi: int, state: list[float | None]) -> float:
        op = self.plan.outputs[oi]
        if op.default is not None and not op.no_change:
            return float(op.default)
        prev = state[oi]
        return math.nan if prev is None else prev

    def record(self, values: Sequence[float], state: list[float | None]) -> Record:
        """One evaluation with every intermediate result (for ``explain``)."""
        start = [self._reset_value(oi, state) for oi in range(len(self.plan.outputs))]
        vals = [np.array([v]) for v in values]
        ev = self._eval(vals, [np.full(1, s) for s in start], 1)
        value = self._step(vals, state, 1)
        outputs = []
        for oi, op in enumerate(self.plan.outputs):
            rec = OutputRecord(float(value[oi][0]), not math.isnan(float(ev.raw[oi][0])))
            sets = ev.sets[oi]
            xs = self.xs[oi]
            if sets is not None and xs is not None:
                rec.samples = (xs, sets[0])
            elif op.kind == "ts":
                rec.weights = [(f"x={x[0]:g}", float(v[0]), float(x[0])) for x, v, h in ev.points[oi] if h[0]]
            else:
                rec.points = sorted((float(x[0]), float(v[0])) for x, v, h in ev.points[oi] if h[0])
            outputs.append(rec)
        chained = [
            [
                float(self._crisp_degree(ci, ti, [np.full(1, s) for s in start], vals)[0])
                for ti in range(len(c.terms))
            ]
            for ci, c in enumerate(self.plan.chained)
        ]
        return Record(
            [[float(d[0]) for d in degs] for degs in ev.term_degrees],
            [float(c[0]) for c in ev.conditions],
            [[(float(d[0]), 1.0) for d in degs] for degs in ev.degrees],
            chained,
            outputs,
            [float(c[0]) for c in ev.conditions],
        )

    # ------------------------------------------------------------------ one evaluation

    def _eval(self, vals: list[Arr], crisp: list[Arr], n: int) -> _Eval:
        plan = self.plan
        term_degrees = [[self._degree(t, vals, vals[fi.slot]) for t in fi.terms] for fi in plan.fuzzy_inputs]

        def cond(c: CondPlan) -> Arr:
            if isinstance(c, CTerm):
                d = term_degrees[c.var][c.term] if "any" not in c.hedges else np.ones(n)
                return _hedged(d, c.hedges, c.negated)
            if isinstance(c, CChained):
                d = self._crisp_degree(c.var, c.term, crisp, vals) if "any" not in c.hedges else np.ones(n)
                return _hedged(d, c.hedges, c.negated)
            if isinstance(c, CDegree):
                if c.slot is None:
                    raise FuzzyctlError("the jfuzzylogic profile has no bare conclusions read as degrees")
                return vals[c.slot]
            if isinstance(c, CNot):
                return 1 - cond(c.operand)
            if isinstance(c, CAnd | COr):
                f = jt.AND_OR[c.op]
                v = cond(c.operands[0])
                for o in c.operands[1:]:
                    v = f(v, cond(o))
                return v
            assert isinstance(c, CTrue)
            return np.ones(n)

        conditions = [np.broadcast_to(cond(r.condition), (n,)) for r in plan.rules]
        degrees: list[list[Arr]] = []
        for ri, r in enumerate(plan.rules):
            rule_w = _value(r.weight, vals)
            per = []
            for cp in r.conclusions:
                d = conditions[ri] * rule_w * _value(cp.weight, vals)
                per.append(_hedged(d, cp.hedges, False) if cp.hedges else d)
            degrees.append(per)
        ev = _Eval(term_degrees, conditions, degrees, [])
        for oi, op in enumerate(plan.outputs):
            if op.kind == "mamdani":
                sets = self._accumulate_set(oi, op, degrees, vals, n)
                ev.sets.append(sets)
                ev.points.append([])
                ev.raw.append(self._defuzzify(op, sets, oi))
            else:
                pts = self._accumulate_points(oi, op, degrees, vals, crisp, n)
                ev.sets.append(None)
                ev.points.append(pts)
                ev.raw.append(_cogs(pts, n))
        return ev

    def _degree(self, t: TermPlan, vals: list[Arr], x: Arr) -> Arr:
        """A term's membership of value ``x`` (an input, or an output's crisp value)."""
        p = [_value(v, vals) for v in t.params]
        if t.kind in ("singleton", "singletons") or registry.flag(t.kind, "ts_constant"):
            return jt.point_membership(t, p, x)
        if t.kind == "function":
            assert t.expr is not None
            return jt.point_membership(t, p, x, jt.eval_function(jt.jfl_expr(t.expr), vals, []))
        return jt.membership(t.kind, p, x)

    def _crisp_degree(self, var: int, term: int, crisp: list[Arr], vals: list[Arr]) -> Arr:
        oi = self.chained_output[var]
        t = self.plan.outputs[oi].terms[term] if self.plan.outputs[oi].terms else None
        if t is None:
            return np.zeros_like(crisp[oi])
        if t.kind == "function":
            position = jt.eval_function(self.exprs[(oi, term)], vals, crisp)
            return jt.point_membership(t, [], crisp[oi], position)
        return self._degree(t, vals, crisp[oi])

    def _contributions(self, oi: int, degrees: list[list[Arr]]) -> list[tuple[int, Arr, str, str]]:
        """(term, degree, act, accu) of every conclusion on output ``oi``, in jFuzzyLogic's
        evaluation order."""
        out = []
        for ri in self.rule_order:
            r = self.plan.rules[ri]
            for ci, cp in enumerate(r.conclusions):
                if oi in cp.outputs and cp.term is not None:
                    out.append((cp.term, degrees[ri][ci], r.act, r.accu or "SUM"))
        return out

    def _accumulate_set(
        self, oi: int, op: OutputPlan, degrees: list[list[Arr]], vals: list[Arr], n: int
    ) -> Arr:
        xs = self.xs[oi]
        acc = np.zeros((n, SAMPLES))
        for term, d, act, accu in self._contributions(oi, degrees):
            t = op.terms[term]
            p = [np.asarray(_value(v, vals))[..., None] if isinstance(v, Slot) else v for v in t.params]
            mu = jt.membership(t.kind, p, xs)
            with np.errstate(all="ignore"):
                acc = jt.ACCU[accu](acc, jt.ACT[act](np.asarray(d)[:, None], mu))
        return acc

    def _defuzzify(self, op: OutputPlan, v: Arr, oi: int) -> Arr:
        assert op.low is not None and op.high is not None
        lo, step = op.low, (op.high - op.low) / SAMPLES
        index_x = lo + step * np.arange(SAMPLES)  # min + stepSize * i (LM, RM, MM, COA)
        with np.errstate(all="ignore"):
            m = METHODS.get(op.method or "")
            if m is not None and m.centroid:
                s = v.sum(axis=1)
                return np.where(s <= 0, np.nan, (v * self.xs[oi]).sum(axis=1) / s)
            if m is not None and m.bisects:
                return _coa(v, lo, step)
            clean = np.where(np.isnan(v), -np.inf, v)  # jFuzzyLogic's comparisons skip NaN
            top = clean.max(axis=1)
            at_top = _at_top(clean, top[:, None])
            if m is not None and m.maximum == "left":
                x = index_x[np.argmax(at_top, axis=1)]
            elif m is not None and m.maximum == "right":
                x = index_x[SAMPLES - 1 - np.argmax(at_top[:, ::-1], axis=1)]
            else:  # MM
                x = (at_top * index_x).sum(axis=1) / at_top.sum(axis=1)
            return np.where(top > 0, x, np.nan)

    def _accumulate_points(
        self, oi: int, op: OutputPlan, degrees: list[list[Arr]], vals: list[Arr], crisp: list[Arr], n: int
    ) -> list[tuple[Arr, Arr, Arr]]:
        """``DefuzzifierDiscrete``: a ``HashMap<Double, Double>`` from position to value; the
        first term to reach a position holds it (``held``), later ones at the same x
        (``Double.equals``: NaN equals NaN, -0.0 is not 0.0) accumulate into it."""
        slots: list[tuple[Arr, Arr, Arr]] = []  # (x, value, held) per row
        for term, d, act, accu in self._contributions(oi, degrees):
            t = op.terms[term]
            p = [_value(v, vals) for v in t.params]
            if t.kind == "singletons":
                positions = p[0::2]
            elif t.kind == "function":
                positions = [jt.eval_function(self.exprs[(oi, term)], vals, crisp)]
            else:
                positions = [p[0]]
            for x in positions:
                x = np.broadcast_to(np.asarray(x, dtype=np.float64), (n,))
                y = jt.ACT[act](d, jt.point_membership(t, p, x, x))
                merged = np.zeros(n, dtype=bool)
                for k, (kx, kv, held) in enumerate(slots):
                    same = held & ~merged & _java_equal(kx, x)
                    slots[k] = (kx, np.where(same, jt.ACCU[accu](kv, y), kv), held)
                    merged |= same
                slots.append((x, jt.ACCU[accu](np.zeros(n), y), ~merged))
        return slots


# --------------------------------------------------------------------------- helpers


def _cogs(points: list[tuple[Arr, Arr, Arr]], n: int) -> Arr:
    """``DefuzzifierCenterOfGravitySingletons``: sum x*y / sum y over the positions held;
    NaN when the sum is 0."""
    total = np.zeros(n)
    weighted = np.zeros(n)
    for x, y, held in points:
        total = np.where(held, total + y, total)
        weighted = np.where(held, weighted + x * y, weighted)
    with np.errstate(all="ignore"):
        return np.where(total != 0, weighted / total, np.nan)


def _at_top(values: Arr, top: Arr) -> Arr:
    """The samples LM, RM and MM take as the maximum: jFuzzyLogic compares doubles exactly,
    so a sample that PROBOR or BSUM rounded an ulp above the others is the maximum alone
    (unlike the IEC paths' 1e-14; measured against jFuzzyLogic, docs/engine.md)."""
    return values == top


def _java_equal(a: Arr, b: Arr) -> Arr:
    """``Double.equals``: the same bits (NaN equals NaN, -0.0 differs from 0.0)."""
    return ((a == b) & (np.signbit(a) == np.signbit(b))) | (np.isnan(a) & np.isnan(b))


def _coa(v: Arr, lo: float, step: float) -> Arr:
    """``DefuzzifierCenterOfArea``: two running sums walking in from both ends."""
    n = v.shape[0]
    rows = np.arange(n)
    low = np.zeros(n, dtype=np.int64)
    hi = np.full(n, SAMPLES - 1, dtype=np.int64)
    sum_low = np.zeros(n)
    sum_high = np.zeros(n)
    for _ in range(SAMPLES - 1):
        left = sum_low <= sum_high
        low = np.where(left, low + 1, low)
        hi = np.where(left, hi, hi - 1)
        sum_low = np.where(left, sum_low + v[rows, np.minimum(low, SAMPLES - 1)], sum_low)
        sum_high = np.where(left, sum_high, sum_high + v[rows, np.maximum(hi, 0)])
    return np.where(sum_low <= 0, np.nan, lo + step * low)


def _value(p: PParam, vals: list[Arr]) -> Arr:
    return vals[p.index] if isinstance(p, Slot) else p


def _hedged(d: Arr, hedges: tuple[str, ...], negated: bool) -> Arr:
    for h in reversed(hedges):
        d = shapes.hedge_np(h, d)
    return 1 - d if negated else d


def _walk(c: CondPlan) -> list[CondPlan]:
    if isinstance(c, CNot):
        return _walk(c.operand)
    if isinstance(c, CAnd | COr):
        return [x for o in c.operands for x in _walk(o)]
    return [c]


def _outputs_read(e: ExprPlan) -> set[int]:
    if isinstance(e, EOutput):
        return {e.output}
    out: set[int] = set()
    for attr in ("operand", "left", "right"):
        if hasattr(e, attr):
            out |= _outputs_read(getattr(e, attr))
    for a in getattr(e, "args", ()):
        out |= _outputs_read(a)
    return out
