"""The scalar interpreter: evaluates a :class:`~fuzzyctl.engine.plan.Plan` for one input
vector and records every intermediate result (term degrees, rule degrees, accumulated sets).

It is the reference the specialised scalar path and the numpy batch path are tested against,
serves ``explain()``, and evaluates what the specialiser does not handle (membership points or
output terms given by variables, smooth output sets).
"""

from __future__ import annotations

import functools
import itertools
import math
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from fuzzyctl.engine.lowering.grid import build_grid
from fuzzyctl.engine.plan import (
    CAnd,
    CChained,
    CDegree,
    CNot,
    CondPlan,
    COr,
    CTerm,
    CTrue,
    OutputPlan,
    Plan,
    PParam,
    Slot,
    TermPlan,
)
from fuzzyctl.engine.reference import pwl, quadrature
from fuzzyctl.engine.semantics import selection, shapes
from fuzzyctl.engine.semantics.expr import eval_expr, eval_expr_np
from fuzzyctl.engine.semantics.operators import (
    CLIP_BRANCH,
    SNORMS,
    TNORMS,
    accumulate,
    accumulate_np,
    activation_levels,
    clamp,
    fsum,
)
from fuzzyctl.kinds import norms
from fuzzyctl.kinds import shapes as registry
from fuzzyctl.kinds.methods import METHODS

# --------------------------------------------------------------------------- records


@dataclass
class OutputRecord:
    """What one output did in one evaluation."""

    value: float
    fired: bool
    pieces: list[pwl.Piece] = field(default_factory=list)  # exact accumulated set
    points: list[tuple[float, float]] = field(default_factory=list)  # singletons / point values
    samples: tuple[Any, Any] | None = None  # (x, mu) arrays for smooth sets
    weights: list[tuple[str, float, float]] = field(default_factory=list)  # TS: (term, weight, z)


@dataclass
class Record:
    """Everything one evaluation computed (the raw material of an explanation)."""

    term_degrees: list[list[float]]
    rule_degrees: list[float]  # the degree each rule fires with (weight and selection applied)
    conclusion_degrees: list[list[tuple[float, float]]]  # per rule: (hedged degree, weight)
    chained_degrees: list[list[float]]
    outputs: list[OutputRecord]
    condition_degrees: list[float] = field(default_factory=list)  # each rule's condition alone


# --------------------------------------------------------------------------- the interpreter


class Interpreter:
    """Evaluates a plan one input vector at a time."""

    def __init__(self, plan: Plan) -> None:
        self.plan = plan
        self._is_min = {"MIN"}

    def pv(self, p: PParam, values: Sequence[float]) -> float:
        return values[p.index] if isinstance(p, Slot) else p

    def term_degree(self, t: TermPlan, x: float, values: Sequence[float]) -> float:
        if t.pwl is not None:
            return shapes.pwl_value(t.pwl, x)
        if t.kind == "function":
            assert t.expr is not None
            return eval_expr(t.expr, values, [], x)
        params = [self.pv(p, values) for p in t.params]
        return shapes.membership(t.kind, params, self.pv(t.height, values), x)

    def run(self, values: Sequence[float], state: list[float | None]) -> Record:
        """Evaluate; ``state`` holds each output's previous value (NC) and is updated."""
        plan = self.plan
        opts = plan.options
        values = clamp_inputs(plan, values)
        term_degrees = [
            [self.term_degree(t, values[fi.slot], values) for t in fi.terms] for fi in plan.fuzzy_inputs
        ]
        chained_acc: list[list[float]] = [[0.0] * len(c.terms) for c in plan.chained]
        chained_bare = [0.0] * len(plan.chained)
        chained_read: list[list[float] | None] = [None] * len(plan.chained)
        rule_degrees = [0.0] * len(plan.rules)
        concl_degrees: list[list[tuple[float, float]]] = [[] for _ in plan.rules]

        def chained_value(var: int) -> list[float]:
            got = chained_read[var]
            if got is None:
                accs = chained_acc[var]
                if norms.normalised(plan.chained[var].accu):
                    top = max([1.0, *accs])
                    accs = [a / top for a in accs]
                got = accs
                chained_read[var] = got
            return got

        def cond(c: CondPlan) -> float:
            if isinstance(c, CTerm):
                d = term_degrees[c.var][c.term] if "any" not in c.hedges else 1.0
                return _hedged(d, c.hedges, c.negated)
            if isinstance(c, CChained):
                d = chained_value(c.var)[c.term] if "any" not in c.hedges else 1.0
                return _hedged(d, c.hedges, c.negated)
            if isinstance(c, CDegree):
                if c.slot is not None:
                    return values[c.slot]
                assert c.chained is not None
                return chained_bare[c.chained]
            if isinstance(c, CNot):
                return 1.0 - cond(c.operand)
            if isinstance(c, CAnd):
                f = TNORMS[c.op].scalar
                v = cond(c.operands[0])
                for o in c.operands[1:]:
                    v = f(v, cond(o))
                return v
            if isinstance(c, COr):
                g = SNORMS[c.op].scalar
                v = cond(c.operands[0])
                for o in c.operands[1:]:
                    v = g(v, cond(o))
                return v
            assert isinstance(c, CTrue)
            return 1.0

        cond_degrees = [math.nan] * len(plan.rules)
        threshold = opts.firing_threshold

        def weighted(ri: int) -> float:
            rule = plan.rules[ri]
            c = cond(rule.condition)
            cond_degrees[ri] = c
            a = c * self.pv(rule.weight, values) if rule.weight != 1.0 else c
            return 0.0 if a <= threshold else a

        selected: dict[int, float] = {}
        for sel in plan.selections:  # these rules read no chained variable: evaluate them first
            degrees = selection.select(sel, [weighted(ri) for ri in sel.rules])
            for ri, d in zip(sel.rules, degrees, strict=True):
                selected[ri] = 0.0 if d <= threshold else d

        for ri in plan.order:
            rule = plan.rules[ri]
            a = selected[ri] if rule.selection is not None else weighted(ri)
            rule_degrees[ri] = a
            carried = a
            for cp in rule.conclusions:
                base = carried if opts.hedges_carry_over else a
                ah = _hedged(base, cp.hedges, False) if cp.hedges else base
                if opts.hedges_carry_over:
                    carried = ah
                w = self.pv(cp.weight, values)
                concl_degrees[ri].append((ah, w))
                for ch in cp.chained:
                    accu = plan.chained[ch].accu
                    if cp.term is None:
                        chained_bare[ch] = accumulate(accu, chained_bare[ch], w * ah)
                    else:
                        chained_acc[ch][cp.term] = accumulate(accu, chained_acc[ch][cp.term], w * ah)

        records = self._outputs(concl_degrees, values, state)
        chained_final = [chained_value(i) for i in range(len(plan.chained))]
        return Record(term_degrees, rule_degrees, concl_degrees, chained_final, records, cond_degrees)

    def _outputs(
        self,
        concl_degrees: list[list[tuple[float, float]]],
        values: Sequence[float],
        state: list[float | None],
    ) -> list[OutputRecord]:
        """Every output in dependency order, then DEFAULT / NC and lock-range."""
        plan = self.plan
        out_values = [math.nan] * len(plan.outputs)
        records: list[OutputRecord | None] = [None] * len(plan.outputs)
        for oi in plan.output_order:
            op = plan.outputs[oi]
            rec = self._output(op, concl_degrees, values, out_values)
            if not rec.fired:
                if op.no_change:
                    prev = state[oi]
                    rec.value = prev if prev is not None else (op.default if op.default is not None else 0.0)
                else:
                    rec.value = op.default if op.default is not None else 0.0
            if op.clamp is not None:
                rec.value = clamp(rec.value, *op.clamp)
            state[oi] = rec.value
            out_values[oi] = rec.value
            records[oi] = rec
        return [r for r in records if r is not None]

    # ------------------------------------------------------------------ outputs

    def _contribs(
        self, op: OutputPlan, concl: list[list[tuple[float, float]]]
    ) -> list[tuple[int | None, float, float, str]]:
        """(term, effective degree, effective weight, act) of every activated set, weight
        applied after activation (IEC) or folded into the degree (compat)."""
        out = []
        before = self.plan.options.weight_before_activation
        for c in op.contributions:
            ah, w = concl[c.rule][c.conclusion]
            if before:
                ah, w = ah * w, 1.0
            if ah * w > 0.0:
                out.append((c.term, ah, w, c.act))
        return out

    def _output(
        self,
        op: OutputPlan,
        concl: list[list[tuple[float, float]]],
        values: Sequence[float],
        outs: Sequence[float],
    ) -> OutputRecord:
        return self.output_from(op, self._contribs(op, concl), values, outs)

    def output_from(
        self,
        op: OutputPlan,
        contribs: list[tuple[int | None, float, float, str]],
        values: Sequence[float],
        outs: Sequence[float],
    ) -> OutputRecord:
        """One output from its activated sets ``(term, degree, weight, act)`` (weight
        placement applied, only sets with degree * weight > 0)."""
        if op.kind == "degree":
            v = 0.0
            for _t, a, w, _act in contribs:
                v = accumulate(op.accu or "MAX", v, w * a)
            return OutputRecord(v, True)
        if op.kind == "ts":
            return self._ts(op, contribs, values, outs)
        scale = pwl.tiny_degree_scale(max((a for _t, a, _w, _act in contribs), default=0.0))
        if scale != 1.0:  # subnormal degrees: one exact rescaling, every path alike
            contribs = [(t, a * scale, w, act) for t, a, w, act in contribs]
        if op.kind == "singleton":
            return self._singleton(op, contribs, values)
        if op.exact:
            return self._exact(op, contribs, values)
        return self._smooth(op, contribs, values)

    def _ts(
        self,
        op: OutputPlan,
        contribs: list[tuple[int | None, float, float, str]],
        values: Sequence[float],
        outs: Sequence[float],
    ) -> OutputRecord:
        zs: dict[tuple[int, float], float] = {}

        def z_of(t: int, wt: float) -> float:
            key = (t, wt if op.terms[t].kind in shapes.TSUKAMOTO_KINDS else 0.0)
            if key not in zs:
                zs[key] = ts_value(op.terms[t], values, outs, self.pv, wt)
            return zs[key]

        rec = OutputRecord(math.nan, False)
        if op.accu is None:
            items = [(t, w * a) for t, a, w, _act in contribs if t is not None]
        else:
            acc: dict[int, float] = {}
            for t, a, w, _act in contribs:
                if t is not None:
                    acc[t] = accumulate(op.accu, acc.get(t, 0.0), w * a)
            items = sorted(acc.items())
        num = [wt * z_of(t, wt) for t, wt in items]
        den = [wt for _t, wt in items]
        rec.weights = [(op.terms[t].name, wt, z_of(t, wt)) for t, wt in items]
        total = fsum(den)
        if not total > 0.0:
            return rec
        rec.fired = True
        rec.value = weighted_value(op.method, fsum(num), total)
        return rec

    def _singleton(
        self, op: OutputPlan, contribs: list[tuple[int | None, float, float, str]], values: Sequence[float]
    ) -> OutputRecord:
        accu = op.accu or "MAX"
        acc: dict[tuple[int, int], float] = {}
        pos: dict[tuple[int, int], float] = {}
        for t, a, w, act in contribs:
            assert t is not None
            term = op.terms[t]
            params = [self.pv(p, values) for p in term.params]
            if term.kind == "singleton":
                pairs = [(params[0], 1.0)]
            else:
                pairs = list(zip(params[0::2], params[1::2], strict=True))
            for i, (x, y) in enumerate(pairs):
                c = w * TNORMS[act].scalar(a, y)
                acc[(t, i)] = accumulate(accu, acc.get((t, i), 0.0), c)
                pos[(t, i)] = x
        rec = OutputRecord(math.nan, False)
        rec.points = sorted((pos[k], v) for k, v in acc.items())
        total = fsum(v for _x, v in rec.points)
        if not total > 0.0:
            return rec
        rec.fired = True
        entry = METHODS[op.method]
        if entry.maximum is None:
            rec.value = weighted_value(op.method, fsum(x * v for x, v in rec.points), total)
        else:
            sup = max(v for _x, v in rec.points)
            xs = sorted({x for x, v in rec.points if v == sup})
            rec.value = {"left": xs[0], "right": xs[-1], "mean": fsum(xs) / len(xs)}[entry.maximum]
        return rec

    def _exact(
        self, op: OutputPlan, contribs: list[tuple[int | None, float, float, str]], values: Sequence[float]
    ) -> OutputRecord:
        assert op.low is not None and op.high is not None
        grid = op.grid
        if grid is None:
            pts = []
            for t in op.terms:
                params = [self.pv(p, values) for p in t.params]
                got = shapes.pwl_points(t.kind, params, self.pv(t.height, values))
                assert got is not None
                pts.append(got)
            grid = build_grid(pts, op.low, op.high)
        cs = [(t, a, w, norms.is_min(act)) for t, a, w, act in contribs if t is not None]
        accu = op.accu or "MAX"
        pieces = pwl.grid_pieces(grid, cs, accu)
        pv = pwl.point_values(grid, cs, accu)
        points = list(zip(grid.xs, pv, strict=True))
        rec = OutputRecord(math.nan, False, pieces, points)
        value = pwl.defuzzify_pieces(op.method, pieces, points)
        if value is not None:
            rec.value, rec.fired = value, True
        return rec

    def _smooth(
        self, op: OutputPlan, contribs: list[tuple[int | None, float, float, str]], values: Sequence[float]
    ) -> OutputRecord:
        assert op.low is not None and op.high is not None
        rec = OutputRecord(math.nan, False)
        f = accumulated_function(op, contribs, values, self.pv)
        sets = merged_max(contribs) if norms.accumulates_by_max(op.accu) else contribs
        cuts = smooth_cuts(op, values, self.pv, sets)
        cuts += crossing_cuts(op, sets, values, self.pv, sorted(set(cuts)))
        # what the level and crossing cuts cannot foresee (a clipped Function term's kink):
        # found by sampling the accumulated set's branch and bisecting each change
        cuts += quadrature.kinks(accumulated_branch(op, contribs, values, self.pv), cuts)
        xs = np.linspace(op.low, op.high, 401)
        rec.samples = (xs, f(xs))
        if not contribs:
            return rec
        A, B, K, KM = quadrature.integrate(f, cuts, self.plan.options.quad_rtol)
        # intervals of no width (two cuts for one kink, a DMIN spike where a term is exactly 1)
        # carry no area: a node on a spike would fire a set that has none
        tiny = 1e-13 * max(abs(op.low), abs(op.high), op.high - op.low)
        wide = np.greater(B - A, tiny)
        A, B, K, KM = A[wide], B[wide], K[wide], KM[wide]
        area = float(np.sum(K))
        if not (math.isfinite(area) and math.isfinite(float(np.sum(KM)))):
            # rules fired but a term is undefined there (a 0/0 in a function term): the
            # output is NaN, not the DEFAULT of "no rule fired"
            rec.fired = True
            return rec
        entry = METHODS[op.method]
        if entry.integrating:
            if not area > 0.0:
                return rec
            rec.fired = True
            rec.value = (
                quadrature.bisector(f, A, B, K, self.plan.options.quad_rtol)
                if entry.bisects
                else float(np.sum(KM)) / area
            )
            return rec
        if not area > 0.0:
            return rec
        sup, lm, rm, mom = quadrature.maxima(f, A, B)
        if sup > 0.0:
            rec.fired = True
            assert entry.maximum is not None
            rec.value = {"left": lm, "right": rm, "mean": mom}[entry.maximum]
        return rec


def clamp_inputs(plan: Plan, values: Sequence[float]) -> Sequence[float]:
    """The input vector with every lock-range input limited to its range."""
    if not any(i.clamp is not None for i in plan.inputs):
        return values
    return [v if i.clamp is None else clamp(v, *i.clamp) for i, v in zip(plan.inputs, values, strict=True)]


def _hedged(d: float, hedges: tuple[str, ...], negated: bool) -> float:
    for h in reversed(hedges):  # the hedge nearest the term applies first
        d = shapes.hedge_function(h)(d)
    return 1.0 - d if negated else d


def weighted_value(method: str, num: float, total: float) -> float:
    """A weighted output's value from its weighted sum ``num`` and the sum of its weights:
    their ratio for a weighted average (COGS, WTAVER), ``num`` for a weighted sum (WTSUM)."""
    return num / total if METHODS[method].weighted == "average" else num


def ts_value(
    term: TermPlan, values: Sequence[float], outs: Sequence[float], pv: Any, weight: float = 1.0
) -> float:
    """z of a Takagi-Sugeno term (of a Tsukamoto term: where it reaches ``weight``)."""
    if term.kind in shapes.TSUKAMOTO_KINDS:
        return shapes.tsukamoto(
            term.kind, [pv(p, values) for p in term.params], pv(term.height, values), weight
        )
    if term.kind == "singleton" or registry.flag(term.kind, "ts_constant"):
        return float(pv(term.params[0], values))
    if registry.flag(term.kind, "ts_linear"):
        cs = [pv(p, values) for p in term.params]
        n = len(values)
        v = fsum(c * x for c, x in zip(cs[:n], values, strict=False))
        return v + (cs[n] if len(cs) > n else 0.0)
    assert term.expr is not None
    return eval_expr(term.expr, values, outs)


def accumulated_function(
    op: OutputPlan, contribs: Sequence[tuple[int | None, float, float, str]], values: Sequence[float], pv: Any
) -> quadrature.Integrand:
    """mu(u) of a Mamdani output as a vectorised function (for quadrature and plots)."""
    accu = op.accu or "MAX"
    sets = activated_sets(op, contribs, values, pv)

    def f(x: Any) -> Any:
        acc = np.zeros_like(x)
        for _mu, c in sets(x):
            acc = accumulate_np(accu, acc, c)
        return acc

    return f


def activated_sets(
    op: OutputPlan, contribs: Sequence[tuple[int | None, float, float, str]], values: Sequence[float], pv: Any
) -> Callable[[Any], list[tuple[Any, Any]]]:
    """``x -> [(mu, w * act(a, mu)), ...]``: each activated set's term and activated degree."""
    resolved = []
    for t, a, w, act in contribs:
        assert t is not None
        term = op.terms[t]
        params = [pv(p, values) for p in term.params]
        resolved.append((term, params, pv(term.height, values), a, w, TNORMS[act].array))
    vals = list(values)

    def sets(x: Any) -> list[tuple[Any, Any]]:
        out = []
        for term, params, h, a, w, act in resolved:
            if term.kind == "function":
                assert term.expr is not None
                got = eval_expr_np(term.expr, vals, [], x)
                mu = np.broadcast_to(np.asarray(got, dtype=np.float64), x.shape)
            else:
                mu = shapes.membership_np(term.kind, params, h, x)
            out.append((mu, w * act(a, mu)))
        return out

    return sets


def accumulated_branch(
    op: OutputPlan, contribs: Sequence[tuple[int | None, float, float, str]], values: Sequence[float], pv: Any
) -> Callable[[Any], list[tuple[int, ...]]]:
    """Which piece of its formula the accumulated set takes at each x: for each set under MIN
    activation whether its term is below the degree (the clipping edge), under MAX which set
    is largest and whether it is below 0 (a function term), under BSUM whether the sum is
    cut at 1.  Where this changes the set bends: the quadrature is cut there."""
    accu = op.accu or "MAX"
    sets = activated_sets(op, contribs, values, pv)
    clip = [(k, a) for k, (_t, a, _w, act) in enumerate(contribs) if act in CLIP_BRANCH]

    def branch(x: Any) -> list[tuple[int, ...]]:
        ss = sets(x)
        cols = [ss[k][0] < a for k, a in clip]
        if ss and norms.is_max(accu):
            c = np.stack([c for _mu, c in ss])
            cols += [np.argmax(c, axis=0), c.max(axis=0) < 0.0]
        elif ss and norms.bounded(accu):
            cols.append(sum(c for _mu, c in ss) >= 1.0)
        return [tuple(int(v) for v in row) for row in zip(*cols, strict=True)] if cols else [()] * len(x)

    return branch


def smooth_cuts(
    op: OutputPlan,
    values: Sequence[float],
    pv: Any,
    contribs: Sequence[tuple[int | None, float, float, str]] = (),
) -> list[float]:
    """Where the accumulated set may bend or jump: the terms' characteristic points and where
    an activated term crosses a level of its activation (``operators.ACT_LEVELS``: MIN clips at
    the rule's degree, NIPMIN jumps at 1 - degree, ...): a plateau edge or a narrow plateau
    inside an interval can be too small for the error estimate to see."""
    assert op.low is not None and op.high is not None
    cuts = [op.low, op.high]
    for t in op.terms:
        params = [pv(p, values) for p in t.params]
        for c in shapes.characteristic_points(t.kind, params):
            if op.low < c < op.high:
                cuts.append(c)
    base = sorted(set(cuts))
    for ti, a, _w, act in contribs:
        term = op.terms[ti] if ti is not None else None
        levels = activation_levels(act, a)
        if term is None or not levels or term.kind == "function":
            continue
        params = [pv(p, values) for p in term.params]
        height = pv(term.height, values)
        pts = shapes.pwl_points(term.kind, params, height) if term.kind in shapes.PWL_KINDS else None
        for lv in levels:
            if pts is not None:
                for (x0, y0), (x1, y1) in itertools.pairwise(pts):
                    if x1 > x0 and min(y0, y1) < lv < max(y0, y1):
                        c = x0 + (lv - y0) * (x1 - x0) / (y1 - y0)
                        if op.low < c < op.high:
                            cuts.append(c)
            else:
                mu = functools.partial(shapes.membership_np, term.kind, params, height)
                cuts += level_crossings(mu, lv, base)
    return cuts


#: Sets beyond which crossings are left to the adaptive quadrature (pairs grow as n^2).
MAX_CROSSING_SETS = 24


def merged_max(
    contribs: Sequence[tuple[int | None, float, float, str]],
) -> list[tuple[int | None, float, float, str]]:
    """Under MAX, the sets of one term, activation and weight as one (``w * act(max a, mu)``:
    every t-norm is non-decreasing): the same set, fewer kinks to look for."""
    best: dict[tuple[int | None, float, str], float] = {}
    for t, a, w, act in contribs:
        key = (t, w, act)
        best[key] = max(best.get(key, a), a)
    return [(t, a, w, act) for (t, w, act), a in best.items()]


def crossing_cuts(
    op: OutputPlan,
    contribs: Sequence[tuple[int | None, float, float, str]],
    values: Sequence[float],
    pv: Any,
    cuts: Sequence[float],
) -> list[float]:
    """Where two activated sets cross under MAX (and DMAX, NIPMAX: the largest changes) and,
    under NIPMAX, where two of them sum to 1 (a jump to 1): kinks and jumps that the error
    estimate of the quadrature can misjudge (a kink left inside an interval costs 1e-8)."""
    entry = norms.accumulation(op.accu or "MAX")
    if entry is None or not entry.picks_largest or not 2 <= len(contribs) <= MAX_CROSSING_SETS:
        return []
    if any(t is None or op.terms[t].kind == "function" for t, _a, _w, _act in contribs):
        return []
    sets = [accumulated_function(op, [c], values, pv) for c in contribs]
    out: list[float] = []
    for i, j in itertools.combinations(range(len(sets)), 2):
        fi, fj = sets[i], sets[j]
        out += level_crossings(lambda x, fi=fi, fj=fj: fi(x) - fj(x), 0.0, cuts)
        if "sum_below_one" in entry.branch_tests:
            out += level_crossings(lambda x, fi=fi, fj=fj: fi(x) + fj(x), 1.0, cuts)
    return out


def level_crossings(mu: Any, level: float, cuts: Sequence[float], samples: int = 16) -> list[float]:
    """Where the vectorised function ``mu`` crosses ``level`` between sorted ``cuts``: each
    interval sampled at ``samples`` points, every sign change located by bisection to the
    last bit."""
    xs = np.concatenate(
        [np.linspace(a, b, samples)[:-1] for a, b in itertools.pairwise(cuts) if b > a]
        + [np.array(cuts[-1:])]
    )
    d = np.asarray(mu(xs), dtype=np.float64) - level
    out = []
    for j in np.flatnonzero(((d[:-1] < 0.0) & (d[1:] > 0.0)) | ((d[:-1] > 0.0) & (d[1:] < 0.0))):
        lo, hi, below = float(xs[j]), float(xs[j + 1]), bool(d[j] < 0.0)
        while True:
            mid = 0.5 * (lo + hi)
            if not lo < mid < hi:
                break
            if (float(mu(np.array([mid]))[0]) < level) == below:
                lo = mid
            else:
                hi = mid
        out.append(hi)
    return out
