"""A proven bound on how far a function block's output moves within a small box of inputs,
for the error bound of lookup tables (:mod:`fuzzyctl.engine.table`).

The table's error is checked exactly at sample points; between them it is bounded with
these finite-difference inequalities, derived for the systems this module accepts
(:func:`refusal` says why a system is not one of them):

* a term read by a condition is piecewise linear (no vertical edge) or Gaussian, so its
  least and greatest degree on a box are exact (the ends, the breakpoints inside, a
  Gaussian's centre); every AND/OR operator admitted (MIN, PROD, BDIF, MAX, ASUM, BSUM) is
  monotone in each operand and NOT reverses, so each rule's degree ``w a`` on the box lies in
  ``[lo_r, hi_r]``, and moves from its value at the centre by at most ``Delta_r``;
* activation MIN or PROD and accumulation MAX move the accumulated set by at most
  ``max_r Delta_r`` at every point (BSUM: ``sum_r Delta_r``);
* singletons (COGS): ``F = sum_t z_t mu_t / D`` with ``D = sum_t mu_t``, so
  ``|F(x) - F(x')| <= sum_t |z_t - F(x')| |mu_t(x) - mu_t(x')| / D(x)`` and ``D(x) >= sum_t lo_t``;
* centre of gravity on ``[a, b]``: ``F(x) - F(x') = int (t - F(x')) (mu_x - mu_x') dt /
  D(x)``, so ``|F(x) - F(x')| <= sup|dmu| ((F(x') - a)^2 + (b - F(x'))^2) / 2 / D(x)``, and
  since ``act(w a, mu) >= w a mu``, ``D(x) >= max_r A_r lo_r`` with
  ``A_r`` the area of rule r's concluded term on ``[a, b]``;
* Takagi-Sugeno (WTAVER, WTSUM) with constant or linear terms: each weight ``W_i`` lies in
  ``[lo_i, hi_i]`` and each value ``z_i`` moves by at most ``sum_k |c_ik| h_k`` on the box, and
  ``F(x) - F(x') = sum_i [(W_i(x) - W_i(x')) (z_i(x) - F(x')) + W_i(x') (z_i(x) - z_i(x'))]
  / D(x)`` (WTAVER; the same without ``F(x')`` and ``D`` for WTSUM);
* CoA, LM, RM, MoM (:mod:`fuzzyctl.engine.table_methods`): not a move bound but the box's
  value range, from the accumulated set's least and greatest value on every cell of the output
  range.  These outputs can jump (LM, RM and MoM when another term's plateau becomes the
  highest, CoA across a gap where the set is 0): a table cannot follow a jump, so the bound
  stays above the tolerance there and the table is refused, naming where it jumps.

Where no rule fires the output jumps to its DEFAULT: no table can bound that, and
:class:`Certifier` reports an infinite bound there (a WTSUM output whose DEFAULT is 0 does
not jump).
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass, field

import numpy as np
import numpy.typing as npt

from fuzzyctl.engine.plan import CAnd, CNot, CondPlan, COr, CTerm, CTrue, OutputPlan, Plan, TermPlan
from fuzzyctl.engine.semantics.operators import SNORMS, TNORMS
from fuzzyctl.engine.semantics.shapes import membership_np
from fuzzyctl.engine.table_methods import OutputCells, enclosure_move, ts_move, ts_term_refusal
from fuzzyctl.kinds import methods, norms

Arr = npt.NDArray[np.float64]

#: operators moving by at most the sum of their operands' moves (1-Lipschitz in each)
LIPSCHITZ_AND = frozenset({"MIN", "PROD", "BDIF"})
LIPSCHITZ_OR = frozenset({"MAX", "ASUM", "BSUM"})
ACCUS = frozenset({"MAX", "BSUM"})
#: Takagi-Sugeno accumulations (monotone in each operand)
TS_ACCUS = frozenset({"MAX", "BSUM", "SUM", "PROBOR"})
ACTS = frozenset({"MIN", "PROD"})
#: the smooth shapes whose slope bound and box range are derived here (centre, sigma)
BELL_KINDS = frozenset({"gaussian"})


def term_slope(t: TermPlan) -> float | None:
    """The steepest slope of a membership function (None: not derived for this kind, or a
    vertical edge: the output jumps there)."""
    if t.pwl is not None:
        steep = 0.0
        for (x0, y0), (x1, y1) in zip(t.pwl, t.pwl[1:], strict=False):
            if x1 == x0:
                if y1 != y0:
                    return None
                continue
            steep = max(steep, abs(y1 - y0) / (x1 - x0))
        return steep
    if t.kind in BELL_KINDS and t.constant and len(t.params) == 2:
        sigma, height = float(t.params[1]), float(t.height)  # type: ignore[arg-type]
        return abs(height) / (abs(sigma) * math.sqrt(math.e)) if sigma != 0.0 else None
    return None


def _cond_refusal(c: CondPlan, plan: Plan) -> str | None:
    if isinstance(c, CTrue):
        return None
    if isinstance(c, CTerm):
        if c.hedges:
            return f"hedges ({', '.join(c.hedges)})"
        term = plan.fuzzy_inputs[c.var].terms[c.term]
        if term_slope(term) is None:
            name = f"{plan.fuzzy_inputs[c.var].name}.{term.name}"
            return f"term {name} ({term.kind}: a vertical edge, or a shape without a slope bound)"
        return None
    if isinstance(c, CNot):
        return _cond_refusal(c.operand, plan)
    if isinstance(c, CAnd | COr):
        allowed = LIPSCHITZ_AND if isinstance(c, CAnd) else LIPSCHITZ_OR
        if c.op not in allowed:
            return f"operator {c.op}"
        for o in c.operands:
            why = _cond_refusal(o, plan)
            if why:
                return why
        return None
    return f"condition {type(c).__name__}"


def _output_refusal(o: OutputPlan) -> str | None:
    if not o.is_output:
        return f"local variable {o.name}"
    accu = o.accu or "MAX"
    if o.kind == "singleton":
        if any(not t.constant for t in o.terms):
            return f"output {o.name}: a variable singleton"
        if accu not in ACCUS:
            return f"accumulation {accu} of {o.name}"
    elif o.kind == "mamdani":
        entry = methods.method(o.method)
        if not (entry.integrating or entry.maximum) or accu not in ACCUS or o.low is None or o.high is None:
            return f"output {o.name} ({o.method}, {accu})"
        if any(t.pwl is None for t in o.terms):
            return f"output {o.name}: a term that is not piecewise linear"
    elif o.kind == "ts":
        if o.accu is not None and o.accu not in TS_ACCUS:
            return f"accumulation {o.accu} of {o.name}"
        for t in o.terms:
            why = ts_term_refusal(t)
            if why:
                return f"term {o.name}.{t.name}: {why}"
    else:
        return f"output {o.name} ({o.kind})"
    for c in o.contributions:
        if c.term is None or not isinstance(c.weight, float) or (o.kind != "ts" and c.act not in ACTS):
            return f"a conclusion on {o.name} (activation {c.act})"
    return None


def refusal(plan: Plan) -> str | None:
    """Why the bound is not derived for ``plan`` (None: it is)."""
    if plan.chained or plan.selections or plan.options.firing_threshold or plan.options.emulate:
        return "chained variables, rule selection or another tool's semantics"
    if not 1 <= len(plan.inputs) <= 3:
        return f"{len(plan.inputs)} inputs (a table takes 1, 2 or 3)"
    slots = {f.slot for f in plan.fuzzy_inputs}
    for i, inp in enumerate(plan.inputs):
        if inp.degree or i not in slots:
            return f"input {inp.name} read as a degree"
    for r in plan.rules:
        if not isinstance(r.weight, float):
            return f"rule {r.label}: a variable weight"
        why = _cond_refusal(r.condition, plan)
        if why:
            return f"rule {r.label}: {why}"
    for o in plan.outputs:
        why = _output_refusal(o)
        if why:
            return why
    return None


def pwl_area(points: Sequence[tuple[float, float]], a: float, b: float) -> float:
    """The area of a breakpoint list on ``[a, b]`` (constant beyond its ends)."""
    xs = sorted({a, b, *(x for x, _ in points if a < x < b)})
    px = np.array([p[0] for p in points])
    py = np.array([p[1] for p in points])
    ys = np.interp(xs, px, py)
    return float(np.sum((np.diff(xs)) * (ys[1:] + ys[:-1]) / 2.0))


def term_range(t: TermPlan, lo: Arr, hi: Arr) -> tuple[Arr, Arr]:
    """The least and greatest degree of term ``t`` on each interval ``[lo, hi]`` (exact:
    a piecewise linear term's extremes lie at the ends or at its breakpoints, a Gaussian is
    monotone on each side of its centre)."""
    a = membership_np(t.kind, t.params, t.height, lo)
    b = membership_np(t.kind, t.params, t.height, hi)
    low, high = np.minimum(a, b), np.maximum(a, b)
    if t.pwl is not None:
        for xb, yb in t.pwl:
            inside = (lo < xb) & (xb < hi)
            low = np.where(inside, np.minimum(low, yb), low)
            high = np.where(inside, np.maximum(high, yb), high)
    else:  # Gaussian (refusal() admits no other smooth kind)
        centre = float(t.params[0])  # type: ignore[arg-type]
        high = np.where((lo < centre) & (centre < hi), float(t.height), high)  # type: ignore[arg-type]
    return low, high


@dataclass
class Certifier:
    """Degrees of an accepted plan at box centres, their exact ranges over the boxes, and
    the move bound of every output (see the module)."""

    plan: Plan
    #: equal steps of an output range in the CoA/LM/RM/MoM value ranges (their resolution)
    cells: int = 512
    _cells: dict[int, OutputCells] = field(default_factory=dict)

    def heavy(self) -> bool:
        """Whether some output needs the (costlier) value ranges on output cells."""
        return any(o.kind == "mamdani" and not methods.method(o.method).centroid for o in self.plan.outputs)

    def rules(self, centre: Sequence[Arr], half: Sequence[Arr]) -> list[tuple[Arr, Arr, Arr]]:
        """Each rule's condition at the centres and its least and greatest value on the
        boxes (every AND/OR operator is monotone in each operand, NOT reverses)."""
        plan = self.plan
        n = len(centre[0])
        cache: dict[tuple[int, int], tuple[Arr, Arr, Arr]] = {}

        def term(var: int, k: int) -> tuple[Arr, Arr, Arr]:
            if (var, k) not in cache:
                fi = plan.fuzzy_inputs[var]
                t = fi.terms[k]
                x, h = centre[fi.slot], half[fi.slot]
                mid = membership_np(t.kind, t.params, t.height, x)
                low, high = term_range(t, x - h, x + h)
                cache[var, k] = (mid, np.minimum(low, mid), np.maximum(high, mid))
            return cache[var, k]

        def ev(c: CondPlan) -> tuple[Arr, Arr, Arr]:
            if isinstance(c, CTrue):
                one = np.ones(n)
                return one, one, one
            if isinstance(c, CTerm):
                return term(c.var, c.term)
            if isinstance(c, CNot):
                m, lo, hi = ev(c.operand)
                return 1.0 - m, 1.0 - hi, 1.0 - lo
            norm = (TNORMS if isinstance(c, CAnd) else SNORMS)[c.op]  # type: ignore[union-attr]
            m, lo, hi = ev(c.operands[0])  # type: ignore[union-attr]
            for o in c.operands[1:]:  # type: ignore[union-attr]
                m2, lo2, hi2 = ev(o)
                m, lo, hi = norm.array(m, m2), norm.array(lo, lo2), norm.array(hi, hi2)
            return m, lo, hi

        return [tuple(np.broadcast_to(v, (n,)) for v in ev(r.condition)) for r in plan.rules]  # type: ignore[misc]

    def move(self, centre: Sequence[Arr], half: Sequence[Arr], values: Sequence[Arr]) -> list[Arr]:
        """Per output, a bound of ``|F(x) - F(x')|`` for every box centre ``x'`` and every
        ``x`` within ``half[i]`` of it along each input ``i`` (``values``: F at the centres)."""
        degs = self.rules(centre, half)
        return [self._output_move(k, degs, f, centre, half) for k, f in enumerate(values)]

    def _output_move(
        self, k: int, degs: list[tuple[Arr, Arr, Arr]], f: Arr, centre: Sequence[Arr], half: Sequence[Arr]
    ) -> Arr:
        plan = self.plan
        o = plan.outputs[k]
        if o.kind == "ts":
            weighted = []
            for c in o.contributions:
                w = float(plan.rules[c.rule].weight) * c.weight  # type: ignore[arg-type,operator]
                weighted.append((c.term, tuple(w * v for v in degs[c.rule])))
            return ts_move(o, weighted, centre, half)  # type: ignore[arg-type]
        if o.kind == "mamdani" and not methods.method(o.method).centroid:
            if k not in self._cells:
                self._cells[k] = OutputCells.of(o, self.cells)
            contribs = [
                (c.term, c.act, float(plan.rules[c.rule].weight) * c.weight, degs[c.rule])  # type: ignore[arg-type,operator]
                for c in o.contributions
            ]
            return enclosure_move(plan, o, self._cells[k], contribs, f)  # type: ignore[arg-type]
        n = len(f)
        bsum = norms.bounded(o.accu)
        per_term: dict[int, tuple[Arr, Arr, Arr]] = {}  # term -> mu at x', least, greatest
        d_low = np.zeros(n)
        sup = np.zeros(n)
        for c in o.contributions:
            assert c.term is not None and isinstance(c.weight, float)
            w = float(plan.rules[c.rule].weight) * c.weight  # type: ignore[arg-type]
            m, lo, hi = (w * v for v in degs[c.rule])
            zero = np.zeros(n)
            pm, plo, phi = per_term.get(c.term, (zero, zero, zero))
            if bsum:
                per_term[c.term] = (
                    np.minimum(1.0, pm + m),
                    np.minimum(1.0, plo + lo),
                    np.minimum(1.0, phi + hi),
                )
                sup = sup + np.maximum(hi - m, m - lo)
            else:
                per_term[c.term] = (np.maximum(pm, m), np.maximum(plo, lo), np.maximum(phi, hi))
                sup = np.maximum(sup, np.maximum(hi - m, m - lo))
            if o.kind == "mamdani":
                t = o.terms[c.term]
                assert t.pwl is not None and o.low is not None and o.high is not None
                d_low = np.maximum(d_low, pwl_area(t.pwl, o.low, o.high) * lo)
        with np.errstate(divide="ignore", invalid="ignore"):
            if o.kind == "singleton":
                num = np.zeros(n)
                for term, (m, lo, hi) in per_term.items():
                    z = float(o.terms[term].params[0])  # type: ignore[arg-type]
                    num = num + np.abs(z - f) * np.maximum(hi - m, m - lo)
                    d_low = d_low + lo
                move = num / d_low
            else:
                assert o.low is not None and o.high is not None
                spread = ((f - o.low) ** 2 + (o.high - f) ** 2) / 2.0
                move = sup * spread / d_low
        return np.where(d_low > 0.0, move, np.inf)
