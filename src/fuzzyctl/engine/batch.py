"""The numpy batch evaluator: the plan evaluated on whole columns of samples at once.

Same semantics as the interpreter, same closed forms: on the output grid, intervals owned by
one term use the precomputed polynomials of :class:`~fuzzyctl.engine.plan.GridPlan`
(``min_bands``/``full``); shared intervals cut each sample's activated sets at their kinks and
crossings (a fixed number of candidate points per interval, sorted per row) and integrate the
linear pieces exactly.  Outputs the vectorised path does not cover (membership points given
by variables on an output, smooth output sets, PROBOR with CoA) are evaluated row by row by
the interpreter.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from typing import Any

import numpy as np
import numpy.typing as npt

from fuzzyctl.engine import pwl, selection, shapes
from fuzzyctl.engine.expr import eval_expr_np
from fuzzyctl.engine.interp import Interpreter
from fuzzyctl.engine.operators import SNORMS, TNORMS, accumulate_np, clamp_np
from fuzzyctl.engine.plan import (
    CAnd,
    CChained,
    CDegree,
    CNot,
    CondPlan,
    COr,
    CTerm,
    CTrue,
    GridPlan,
    OutputPlan,
    Plan,
    PParam,
    Slot,
    TermPlan,
)

Arr = npt.NDArray[np.float64]
W = Any  # a weight: float or array
Result = tuple[Arr, npt.NDArray[np.bool_]]  # (values, fired)


class BatchEvaluator:
    """Evaluates a plan on columns of samples."""

    def __init__(self, plan: Plan) -> None:
        self.plan = plan
        self.interp = Interpreter(plan)
        self.needed: set[tuple[int, int]] = set()
        for r in plan.rules:
            self._collect(r.condition)

    def _collect(self, c: CondPlan) -> None:
        if isinstance(c, CTerm):
            if "any" not in c.hedges:
                self.needed.add((c.var, c.term))
        elif isinstance(c, CNot):
            self._collect(c.operand)
        elif isinstance(c, CAnd | COr):
            for o in c.operands:
                self._collect(o)

    # ------------------------------------------------------------------ helpers

    @staticmethod
    def _pv(p: PParam, vals: Sequence[Arr]) -> W:
        return vals[p.index] if isinstance(p, Slot) else p

    def term_degree(self, t: TermPlan, x: Arr, vals: Sequence[Arr]) -> Arr:
        if t.pwl is not None:
            return shapes.pwl_value_np(t.pwl, x)
        if t.kind == "function":
            assert t.expr is not None
            return np.broadcast_to(
                np.asarray(eval_expr_np(t.expr, vals, [], x), dtype=np.float64), x.shape
            ).copy()
        params = [self._pv(p, vals) for p in t.params]
        return shapes.membership_np(t.kind, params, self._pv(t.height, vals), x)

    # ------------------------------------------------------------------ evaluation

    def run(self, vals: list[Arr], state: list[float | None]) -> list[Arr]:
        plan = self.plan
        opts = plan.options
        n = len(vals[0]) if vals else 0
        vals = [
            v if i.clamp is None else clamp_np(v, *i.clamp) for i, v in zip(plan.inputs, vals, strict=True)
        ]
        degrees: dict[tuple[int, int], Arr] = {}
        for var, term in self.needed:
            fi = plan.fuzzy_inputs[var]
            degrees[(var, term)] = self.term_degree(fi.terms[term], vals[fi.slot], vals)
        zero = np.zeros(n)
        chained_acc = [[zero for _ in c.terms] for c in plan.chained]
        chained_bare = [zero for _ in plan.chained]
        chained_read: list[list[Arr] | None] = [None] * len(plan.chained)

        def chained_value(var: int) -> list[Arr]:
            got = chained_read[var]
            if got is None:
                accs = chained_acc[var]
                if plan.chained[var].accu == "NSUM" and accs:
                    top = np.maximum(1.0, np.max(np.stack(accs), axis=0))
                    accs = [a / top for a in accs]
                got = accs
                chained_read[var] = got
            return got

        def hedged(d: Arr, hedges: tuple[str, ...], negated: bool) -> Arr:
            for h in reversed(hedges):
                d = shapes.hedge_np(h, d)
            return 1.0 - d if negated else d

        def cond(c: CondPlan) -> Arr:
            if isinstance(c, CTerm):
                d = degrees[(c.var, c.term)] if "any" not in c.hedges else np.ones(n)
                return hedged(d, c.hedges, c.negated)
            if isinstance(c, CChained):
                d = chained_value(c.var)[c.term] if "any" not in c.hedges else np.ones(n)
                return hedged(d, c.hedges, c.negated)
            if isinstance(c, CDegree):
                return vals[c.slot] if c.slot is not None else chained_bare[c.chained or 0]
            if isinstance(c, CNot):
                return 1.0 - cond(c.operand)
            if isinstance(c, CAnd | COr):
                f = (TNORMS if isinstance(c, CAnd) else SNORMS)[c.op].array
                v = cond(c.operands[0])
                for o in c.operands[1:]:
                    v = f(v, cond(o))
                return np.asarray(v, dtype=np.float64)
            assert isinstance(c, CTrue)
            return np.ones(n)

        threshold = opts.firing_threshold

        def weighted(ri: int) -> Arr:
            rule = plan.rules[ri]
            a = cond(rule.condition)
            if rule.weight != 1.0:
                a = a * self._pv(rule.weight, vals)
            return np.where(a <= threshold, 0.0, a) if threshold > 0.0 else a

        selected: dict[int, Arr] = {}
        for sel in plan.selections:  # these rules read no chained variable: evaluate them first
            stacked = np.stack([np.broadcast_to(weighted(ri), (n,)) for ri in sel.rules], axis=1)
            chosen = selection.select_np(sel, stacked)
            for j, ri in enumerate(sel.rules):
                d = chosen[:, j]
                selected[ri] = np.where(d <= threshold, 0.0, d) if threshold > 0.0 else d

        concl: list[list[tuple[Arr, W]]] = [[] for _ in plan.rules]
        for ri in plan.order:
            rule = plan.rules[ri]
            a = selected[ri] if rule.selection is not None else weighted(ri)
            carried = a
            for cp in rule.conclusions:
                base = carried if opts.hedges_carry_over else a
                ah = hedged(base, cp.hedges, False) if cp.hedges else base
                if opts.hedges_carry_over:
                    carried = ah
                w = self._pv(cp.weight, vals)
                concl[ri].append((ah, w))
                for ch in cp.chained:
                    accu = plan.chained[ch].accu
                    if cp.term is None:
                        chained_bare[ch] = accumulate_np(accu, chained_bare[ch], w * ah)
                    else:
                        chained_acc[ch][cp.term] = accumulate_np(accu, chained_acc[ch][cp.term], w * ah)

        outs: list[Arr] = [np.full(n, np.nan) for _ in plan.outputs]
        for oi in plan.output_order:
            op = plan.outputs[oi]
            value, fired = self._output(op, concl, vals, outs, n)
            outs[oi] = _apply_default(op, value, fired, state, oi)
        return outs

    def _contribs(
        self, op: OutputPlan, concl: list[list[tuple[Arr, W]]]
    ) -> list[tuple[int | None, Arr, W, str]]:
        before = self.plan.options.weight_before_activation
        out = []
        for c in op.contributions:
            ah, w = concl[c.rule][c.conclusion]
            if before:
                ah, w = ah * w, 1.0
            out.append((c.term, ah, w, c.act))
        return out

    def _output(
        self,
        op: OutputPlan,
        concl: list[list[tuple[Arr, W]]],
        vals: Sequence[Arr],
        outs: Sequence[Arr],
        n: int,
    ) -> Result:
        contribs = self._contribs(op, concl)
        if op.kind == "degree":
            v = np.zeros(n)
            for _t, a, w, _act in contribs:
                v = accumulate_np(op.accu or "MAX", v, w * a)
            return v, np.ones(n, dtype=bool)
        if op.kind == "ts":
            return self._ts(op, contribs, vals, outs, n)
        if op.kind == "singleton":
            return self._singleton(op, contribs, vals, n)
        if op.exact and op.grid is not None and not (op.accu == "PROBOR" and op.method == "COA"):
            return self._mamdani(op, op.grid, contribs, n)
        return self._rows(op, concl, vals, outs, n)

    def _rows(
        self,
        op: OutputPlan,
        concl: list[list[tuple[Arr, W]]],
        vals: Sequence[Arr],
        outs: Sequence[Arr],
        n: int,
    ) -> Result:
        value = np.full(n, np.nan)
        fired = np.zeros(n, dtype=bool)
        for r in range(n):
            row_concl = [
                [
                    (
                        float(np.asarray(a)[r] if np.ndim(a) else a),
                        float(np.asarray(w)[r] if np.ndim(w) else w),
                    )
                    for a, w in rc
                ]
                for rc in concl
            ]
            row_vals = [float(v[r]) for v in vals]
            row_outs = [float(o[r]) for o in outs]
            rec = self.interp._output(op, row_concl, row_vals, row_outs)
            value[r], fired[r] = rec.value, rec.fired
        return value, fired

    def _ts(
        self,
        op: OutputPlan,
        contribs: list[tuple[int | None, Arr, W, str]],
        vals: Sequence[Arr],
        outs: Sequence[Arr],
        n: int,
    ) -> Result:
        zs: dict[int, Arr] = {}

        def z_of(t: int, wt: Arr) -> Arr:
            term = op.terms[t]
            if term.kind in shapes.TSUKAMOTO_KINDS:
                return np.asarray(
                    shapes.tsukamoto_np(
                        term.kind, [self._pv(p, vals) for p in term.params], self._pv(term.height, vals), wt
                    ),
                    dtype=np.float64,
                )
            if t not in zs:
                if term.kind in ("singleton", "constant"):
                    z = np.full(n, 1.0) * self._pv(term.params[0], vals)
                elif term.kind == "linear":
                    cs = [self._pv(p, vals) for p in term.params]
                    m = len(vals)
                    z = np.zeros(n)
                    for c, x in zip(cs[:m], vals, strict=False):
                        z = z + c * x
                    if len(cs) > m:
                        z = z + cs[m]
                else:
                    assert term.expr is not None
                    z = np.full(n, 1.0) * eval_expr_np(term.expr, vals, outs)
                zs[t] = np.asarray(z, dtype=np.float64)
            return zs[t]

        if op.accu is None:
            items = [(t, w * a) for t, a, w, _act in contribs if t is not None]
        else:
            acc: dict[int, Arr] = {}
            for t, a, w, _act in contribs:
                if t is not None:
                    acc[t] = accumulate_np(op.accu, acc.get(t, np.zeros(n)), w * a)
            items = sorted(acc.items())
        num = np.zeros(n)
        den = np.zeros(n)
        for t, wt in items:
            z = z_of(t, wt)
            with np.errstate(invalid="ignore"):  # 0 * inf where a Tsukamoto term is not reached
                num = num + np.where(wt > 0.0, wt * z, 0.0)
            den = den + wt
        fired = den > 0.0
        with np.errstate(all="ignore"):
            value = num / den if op.method == "WTAVER" else num
        return np.where(fired, value, np.nan), fired

    def _singleton(
        self, op: OutputPlan, contribs: list[tuple[int | None, Arr, W, str]], vals: Sequence[Arr], n: int
    ) -> Result:
        accu = op.accu or "MAX"
        acc: dict[tuple[int, int], Arr] = {}
        pos: dict[tuple[int, int], Any] = {}
        for t, a, w, act in contribs:
            assert t is not None
            term = op.terms[t]
            params = [self._pv(p, vals) for p in term.params]
            pairs = (
                [(params[0], 1.0)]
                if term.kind == "singleton"
                else list(zip(params[0::2], params[1::2], strict=True))
            )
            for i, (x, y) in enumerate(pairs):
                c = w * TNORMS[act].array(a, y)
                acc[(t, i)] = accumulate_np(accu, acc.get((t, i), np.zeros(n)), c)
                pos[(t, i)] = x
        keys = list(acc)
        if not keys:
            return np.full(n, np.nan), np.zeros(n, dtype=bool)
        mu = np.stack([acc[k] for k in keys], axis=1)
        xs = np.stack([np.broadcast_to(np.asarray(pos[k], dtype=np.float64), (n,)) for k in keys], axis=1)
        total = mu.sum(axis=1)
        fired = total > 0.0
        with np.errstate(all="ignore"):
            if op.method == "COGS":
                value = (mu * xs).sum(axis=1) / total
            else:
                sup = mu.max(axis=1, keepdims=True)
                hit = (mu == sup) & fired[:, None]
                if op.method == "LM":
                    value = np.where(hit, xs, np.inf).min(axis=1)
                elif op.method == "RM":
                    value = np.where(hit, xs, -np.inf).max(axis=1)
                else:
                    value = _mean_distinct(np.where(hit, xs, np.nan))
        return np.where(fired, value, np.nan), fired

    # ------------------------------------------------------------------ exact Mamdani on a grid

    def _mamdani(
        self, op: OutputPlan, grid: GridPlan, contribs: list[tuple[int | None, Arr, W, str]], n: int
    ) -> Result:
        accu = op.accu or "MAX"
        groups = _merge(contribs, accu)
        per_term: dict[int, int] = {}
        for t, _a, _w, _mn in groups:
            per_term[t] = per_term.get(t, 0) + 1
        if op.method == "COG":
            area = np.zeros(n)
            moment = np.zeros(n)
            closed = {t for t, k in per_term.items() if k == 1 or accu in ("SUM", "NSUM")}
            for t, a, w, is_min in groups:
                if t not in closed or not grid.solo[t]:
                    continue
                if is_min:
                    ar, mo = _band_eval(grid.min_bands[t], a)
                else:
                    fa, fm = grid.full[t]
                    ar, mo = a * fa, a * fm
                area += w * ar
                moment += w * mo
            general = sorted(
                set(grid.shared) | {j for t in per_term if t not in closed for j in grid.solo[t]}
            )
            for j in general:
                lines = [
                    (grid.left[t][j], grid.right[t][j], a, w, mn)
                    for t, a, w, mn in groups
                    if t in grid.active[j]
                ]
                if not lines:
                    continue
                if accu == "MAX" and len(lines) == 2:
                    ar2, mo2 = _max_of_two(grid.xs[j], grid.xs[j + 1], lines[0], lines[1])
                    area += ar2
                    moment += mo2
                    continue
                X, V, extra = _interval(grid.xs[j], grid.xs[j + 1], lines, accu, n)
                if extra is not None:
                    area += extra[0]
                    moment += extra[1]
                else:
                    x0, x1, v0, v1 = X[:, :-1], X[:, 1:], V[:, :-1], V[:, 1:]
                    dx = x1 - x0
                    area += (0.5 * dx * (v0 + v1)).sum(axis=1)
                    moment += (dx * (x0 * (2.0 * v0 + v1) + x1 * (v0 + 2.0 * v1))).sum(axis=1) / 6.0
            fired = area > 0.0
            with np.errstate(all="ignore"):
                return np.where(fired, moment / area, np.nan), fired
        # CoA, LM, RM, MoM: every interval as pieces
        xs_all, vs_all = [], []
        for j in range(len(grid.xs) - 1):
            lines = [
                (grid.left[t][j], grid.right[t][j], a, w, mn) for t, a, w, mn in groups if t in grid.active[j]
            ]
            if not lines:
                continue
            X, V, _extra = _interval(grid.xs[j], grid.xs[j + 1], lines, accu, n)
            xs_all.append(X)
            vs_all.append(V)
        if not xs_all:
            return np.full(n, np.nan), np.zeros(n, dtype=bool)
        x0 = np.concatenate([X[:, :-1] for X in xs_all], axis=1)
        x1 = np.concatenate([X[:, 1:] for X in xs_all], axis=1)
        v0 = np.concatenate([V[:, :-1] for V in vs_all], axis=1)
        v1 = np.concatenate([V[:, 1:] for V in vs_all], axis=1)
        if op.method == "COA":
            return _coa(x0, x1, v0, v1)
        pts = _point_values(grid, groups, accu, n)
        value, _fired = _maxima(op.method, x0, x1, v0, v1, np.asarray(grid.xs), pts)
        fired = (0.5 * (x1 - x0) * (v0 + v1)).sum(axis=1) > 0.0
        return np.where(fired, value, np.nan), fired


def _apply_default(
    op: OutputPlan, value: Arr, fired: npt.NDArray[np.bool_], state: list[float | None], oi: int
) -> Arr:
    if op.clamp is not None:  # lock-range: NC keeps the limited value, DEFAULT is limited too
        value = clamp_np(value, *op.clamp)
    if fired.all():
        if len(value):
            state[oi] = float(value[-1])
        return value
    prev = state[oi]
    initial = prev if (op.no_change and prev is not None) else (op.default if op.default is not None else 0.0)
    if op.no_change:
        idx = np.where(fired, np.arange(len(value)), -1)
        np.maximum.accumulate(idx, out=idx)
        filled = np.where(idx >= 0, value[np.maximum(idx, 0)], initial)
        out = np.where(fired, value, filled)
    else:
        out = np.where(fired, value, initial)
    if op.clamp is not None:
        out = clamp_np(out, *op.clamp)
    if len(out):
        state[oi] = float(out[-1])
    return np.asarray(out, dtype=np.float64)


def _merge(contribs: list[tuple[int | None, Arr, W, str]], accu: str) -> list[tuple[int, Arr, W, bool]]:
    """Activated sets of one term that MAX accumulation can combine before integration:
    max_k w*min(a_k, mu) = w*min(max_k a_k, mu) for one constant w, and a*w*mu for PROD."""
    groups: dict[Any, list[Any]] = {}
    out: list[tuple[int, Arr, W, bool]] = []
    for t, a, w, act in contribs:
        assert t is not None
        is_min = act == "MIN"
        if accu != "MAX":
            out.append((t, a, w, is_min))
            continue
        if not is_min:
            key: Any = (t, False, 1.0)
            a, w = a * w, 1.0
        elif np.ndim(w) == 0:
            key = (t, True, float(w))
        else:
            out.append((t, a, w, is_min))
            continue
        if key in groups:
            groups[key][1] = np.maximum(groups[key][1], a)
        else:
            groups[key] = [t, a, w, is_min]
    out.extend((g[0], g[1], g[2], g[3]) for g in groups.values())
    return out


def _band_eval(
    bands: Sequence[tuple[float, float, tuple[float, ...], tuple[float, ...]]], h: Arr
) -> tuple[Arr, Arr]:
    """Area and moment polynomials of :attr:`GridPlan.min_bands` at degrees ``h``.

    The pieces join continuously, so the value is the first band's polynomial at h clipped
    into it plus, for each further band, its increase over the part of it below h; constant
    bands (above the term's top) add nothing."""
    area = np.zeros_like(h)
    moment = np.zeros_like(h)
    for k, (lo, hi, ac, mc) in enumerate(bands):
        if k > 0 and ac[1] == ac[2] == 0.0 and mc[1] == mc[2] == mc[3] == 0.0:
            continue
        u = np.clip(h, lo, hi)
        a = ac[0] + u * (ac[1] + u * ac[2])
        mo = mc[0] + u * (mc[1] + u * (mc[2] + u * mc[3]))
        if k > 0:
            a = a - (ac[0] + lo * (ac[1] + lo * ac[2]))
            mo = mo - (mc[0] + lo * (mc[1] + lo * (mc[2] + lo * mc[3])))
        area += a
        moment += mo
    return area, moment


def _polyline_am(x0: float, dx: float, ts: list[Arr], vs: list[Arr]) -> tuple[Arr, Arr]:
    """Area and moment of the polyline through (x0 + t dx, v) for ordered ts (sums kept in
    t-space: area = dx/2 sum d s, moment = x0 area + dx^2/6 sum d (t0 (s + v0) + t1 (s + v1)))."""
    area = np.zeros_like(vs[0])
    tmom = np.zeros_like(vs[0])
    for k in range(len(ts) - 1):
        d = ts[k + 1] - ts[k]
        s = vs[k] + vs[k + 1]
        area += d * s
        tmom += d * (ts[k] * (s + vs[k]) + ts[k + 1] * (s + vs[k + 1]))
    area *= 0.5 * dx
    return area, x0 * area + (dx * dx / 6.0) * tmom


def _clipped_line_am(x0: float, dx: float, line: tuple[float, float, Arr, W, bool]) -> tuple[Arr, Arr]:
    L, R, a, w, mn = line
    if not mn:
        return _polyline_am(x0, dx, [np.zeros_like(a), np.ones_like(a)], [w * a * L, w * a * R])
    tk = np.clip((a - L) / (R - L), 0.0, 1.0) if R != L else np.zeros_like(a)
    ts = [np.zeros_like(a), tk, np.ones_like(a)]
    # at a kink the set is exactly w*a: recomputing it from tk loses the low bits when a is
    # tiny (1 - (1 - a) != a), and the centroid of a set of tiny degrees is a ratio of them
    inside = (L - a) * (R - a) < 0.0
    mid = np.where(inside, a, np.minimum(a, L + (R - L) * tk))
    return _polyline_am(x0, dx, ts, [w * np.minimum(a, L), w * mid, w * np.minimum(a, R)])


def _max_of_two(
    x0: float, x1: float, l1: tuple[float, float, Arr, W, bool], l2: tuple[float, float, Arr, W, bool]
) -> tuple[Arr, Arr]:
    """Exact area and moment of max(c1, c2) on one interval without sorting candidates:
    max = c1 + c2 - min(c1, c2), and min(c1, c2) = min(H, p1, p2) is concave (two lines)
    clipped at the constant H, whose breakpoints come out ordered by construction."""
    dx = x1 - x0
    a1, b1 = _clipped_line_am(x0, dx, l1)
    a2, b2 = _clipped_line_am(x0, dx, l2)
    (L1, R1, h1, w1, mn1), (L2, R2, h2, w2, mn2) = l1, l2
    # the line parts p_i(t) = P_i + S_i t and the constant parts
    P1, S1 = (w1 * L1, w1 * (R1 - L1)) if mn1 else (w1 * h1 * L1, w1 * h1 * (R1 - L1))
    P2, S2 = (w2 * L2, w2 * (R2 - L2)) if mn2 else (w2 * h2 * L2, w2 * h2 * (R2 - L2))
    P1, S1, P2, S2 = (np.asarray(v, dtype=np.float64) for v in (P1, S1, P2, S2))
    H = np.minimum(w1 * h1 if mn1 else np.inf, w2 * h2 if mn2 else np.inf)
    zeros = np.zeros_like(h1 + h2)
    ones = zeros + 1.0
    with np.errstate(all="ignore"):
        ts = np.clip(np.where(S1 != S2, (P2 - P1) / (S1 - S2), 0.0), 0.0, 1.0)
        ts = np.where(np.isnan(ts), 0.0, ts)

        def m(t: Arr) -> Arr:
            return np.asarray(np.minimum(P1 + S1 * t, P2 + S2 * t))

        def cross(t0: Arr, t1: Arr) -> tuple[Arr, Arr]:
            v0, v1 = m(t0), m(t1)
            c = t0 + (H - v0) / (v1 - v0) * (t1 - t0)
            hit = (v0 - H) * (v1 - H) < 0.0
            return np.asarray(np.where(hit, c, t0)), hit

        ca, hit_a = cross(zeros, ts)
        cb, hit_b = cross(ts, ones)
    pts = [zeros, ca, ts, cb, ones]
    vals = [np.minimum(H, m(p)) for p in pts]
    vals[1] = np.where(hit_a, H, vals[1])  # exactly H where min(p1, p2) crosses it
    vals[3] = np.where(hit_b, H, vals[3])
    a3, b3 = _polyline_am(x0, dx, pts, vals)
    return a1 + a2 - a3, b1 + b2 - b3


def _interval(
    x0: float, x1: float, lines: list[tuple[float, float, Arr, W, bool]], accu: str, n: int
) -> tuple[Arr, Arr, tuple[Arr, Arr] | None]:
    """Candidate points of one grid interval (sorted per row), the accumulated degree there,
    and for PROBOR the exact (area, moment)."""
    zeros, ones = np.zeros(n), np.ones(n)
    cands = [zeros, ones]
    kinks: list[Arr | None] = []
    for L, R, a, _w, mn in lines:
        if mn and L != R:
            # a kink where the term strictly crosses the degree (as in pwl.interval_pieces;
            # rounding may put it on an end of the interval)
            tk = np.clip((a - L) / (R - L), 0.0, 1.0)
            inside = (L - a) * (R - a) < 0.0
            kinks.append(np.where(inside, tk, np.nan))  # NaN never equals a candidate
            cands.append(np.where(inside, tk, 0.0))
        else:
            kinks.append(None)
    if accu == "MAX" and len(lines) > 1:
        parts: list[list[tuple[Any, Any]]] = []  # per line: linear parts (A + B t)
        for L, R, a, w, mn in lines:
            if mn:
                parts.append([(w * L, w * (R - L)), (w * a, 0.0)])
            else:
                parts.append([(w * a * L, w * a * (R - L))])
        with np.errstate(all="ignore"):
            for i in range(len(lines)):
                for k in range(i + 1, len(lines)):
                    for ai, bi in parts[i]:
                        for ak, bk in parts[k]:
                            t = (np.asarray(ak - ai, dtype=np.float64) / (bi - bk)) * ones
                            cands.append(np.where((t > 0.0) & (t < 1.0), t, 0.0))
    T = np.sort(np.stack(cands, axis=1), axis=1)

    def values(T: Arr) -> list[Arr]:
        vs = []
        for (L, R, a, w, mn), tk in zip(lines, kinks, strict=True):
            a2 = a[:, None]
            y = L + (R - L) * T
            if mn:
                v = w[:, None] * np.minimum(a2, y) if np.ndim(w) else w * np.minimum(a2, y)
                if tk is not None:
                    exact = (w[:, None] if np.ndim(w) else w) * a2
                    v = np.where(tk[:, None] == T, exact, v)
            else:
                v = (w[:, None] if np.ndim(w) else w) * a2 * y
            vs.append(np.broadcast_to(v, T.shape))
        return vs

    def combine(vs: list[Arr]) -> Arr:
        if len(vs) == 1:
            return np.asarray(vs[0])
        if accu == "MAX":
            return np.asarray(np.maximum.reduce(vs))
        s = np.add.reduce(vs)
        if accu == "BSUM":
            return np.asarray(np.minimum(1.0, s))
        if accu == "PROBOR":
            acc = np.zeros_like(s)
            for v in vs:
                acc = acc + v - acc * v
            return np.asarray(acc)
        return np.asarray(s)

    vs = values(T)
    V = combine(vs)
    if accu == "BSUM" and len(lines) > 1:
        S = np.add.reduce(vs)
        s0, s1 = S[:, :-1], S[:, 1:]
        with np.errstate(all="ignore"):
            s = (1.0 - s0) / (s1 - s0)
            cross = ((s0 - 1.0) * (s1 - 1.0) < 0.0) & (s > 0.0) & (s < 1.0)
            extra = np.where(cross, T[:, :-1] + s * (T[:, 1:] - T[:, :-1]), 0.0)
        T = np.sort(np.concatenate([T, extra], axis=1), axis=1)
        V = combine(values(T))
    X = x0 + T * (x1 - x0)
    extra_am = None
    if accu == "PROBOR" and len(lines) > 1:
        nodes, weights = pwl.gauss_legendre((len(lines) + 3) // 2 + 1)
        area = np.zeros(n)
        moment = np.zeros(n)
        t0, t1 = T[:, :-1], T[:, 1:]
        for u, wt in zip(nodes, weights, strict=True):
            tu = t0 + u * (t1 - t0)
            fu = combine(values(tu))
            xu = x0 + tu * (x1 - x0)
            dxu = (t1 - t0) * (x1 - x0)
            area += (wt * fu * dxu).sum(axis=1)
            moment += (wt * fu * xu * dxu).sum(axis=1)
        extra_am = (area, moment)
    return X, V, extra_am


def _point_values(grid: GridPlan, groups: list[tuple[int, Arr, W, bool]], accu: str, n: int) -> Arr:
    from fuzzyctl.engine.operators import accumulate_np as acc_np

    cols = []
    for j in range(len(grid.xs)):
        v = np.zeros(n)
        for t, a, w, mn in groups:
            y = grid.point[t][j]
            v = acc_np(accu, v, w * (np.minimum(a, y) if mn else a * y))
        cols.append(v)
    return np.stack(cols, axis=1)


def _mean_distinct(x: Arr) -> Arr:
    """Row-wise mean of the distinct non-NaN values."""
    s = np.sort(x, axis=1)
    valid = ~np.isnan(s)
    first = np.ones_like(valid)
    first[:, 1:] = s[:, 1:] != s[:, :-1]
    keep = valid & first
    cnt = keep.sum(axis=1)
    with np.errstate(all="ignore"):
        return np.asarray(np.where(keep, s, 0.0).sum(axis=1) / cnt, dtype=np.float64)


def _maxima(method: str, x0: Arr, x1: Arr, v0: Arr, v1: Arr, gx: Arr, gv: Arr) -> Result:
    sup = np.maximum(np.maximum(v0.max(axis=1), v1.max(axis=1)), gv.max(axis=1))
    fired = sup > 0.0
    s = sup[:, None] * (1.0 - pwl.MAX_TOL)
    gxb = np.broadcast_to(gx, gv.shape)
    hit0, hit1, hitg = v0 >= s, v1 >= s, gv >= s
    if method == "LM":
        value = np.minimum(
            np.minimum(np.where(hit0, x0, np.inf).min(axis=1), np.where(hit1, x1, np.inf).min(axis=1)),
            np.where(hitg, gxb, np.inf).min(axis=1),
        )
    elif method == "RM":
        value = np.maximum(
            np.maximum(np.where(hit0, x0, -np.inf).max(axis=1), np.where(hit1, x1, -np.inf).max(axis=1)),
            np.where(hitg, gxb, -np.inf).max(axis=1),
        )
    else:
        plateau = hit0 & hit1 & (x1 > x0)
        length = np.where(plateau, x1 - x0, 0.0).sum(axis=1)
        mom = np.where(plateau, (x1 - x0) * 0.5 * (x0 + x1), 0.0).sum(axis=1)
        pts = np.concatenate(
            [np.where(hit0, x0, np.nan), np.where(hit1, x1, np.nan), np.where(hitg, gxb, np.nan)], axis=1
        )
        with np.errstate(all="ignore"):
            value = np.where(length > 0.0, mom / length, _mean_distinct(pts))
    return np.where(fired, value, np.nan), fired


def _coa(x0: Arr, x1: Arr, v0: Arr, v1: Arr) -> Result:
    dx = x1 - x0
    areas = 0.5 * dx * (v0 + v1)
    total = areas.sum(axis=1)
    fired = total > 0.0
    half = 0.5 * total

    def solve(idx: Arr, r: Arr, reverse: bool) -> Arr:
        rows = np.arange(len(idx))
        a0, b0, p0, p1 = x0[rows, idx], x1[rows, idx], v0[rows, idx], v1[rows, idx]
        d = b0 - a0
        with np.errstate(all="ignore"):
            if reverse:  # measure from the right end: mirror the piece
                p0, p1 = p1, p0
            scale = np.maximum(np.abs(p0), np.abs(p1))  # scale-free formula; avoid underflow
            scale = np.where(scale > 0.0, scale, 1.0)
            p0, p1, r = p0 / scale, p1 / scale, r / scale
            k = np.where(d > 0.0, (p1 - p0) / d, 0.0)
            den = p0 + np.sqrt(np.maximum(p0 * p0 + 2.0 * k * r, 0.0))
            s = np.where(den > 0.0, 2.0 * r / den, 0.0)
        s = np.minimum(s, d)
        return np.asarray(b0 - s if reverse else a0 + s, dtype=np.float64)

    cum = np.cumsum(areas, axis=1)
    ok = (cum >= half[:, None]) & (areas > 0.0)
    i_left = np.argmax(ok, axis=1)
    before = (
        np.take_along_axis(cum, i_left[:, None], axis=1)[:, 0]
        - np.take_along_axis(areas, i_left[:, None], axis=1)[:, 0]
    )
    left = solve(i_left, half - before, False)
    rcum = np.cumsum(areas[:, ::-1], axis=1)[:, ::-1]
    ok_r = (rcum >= half[:, None]) & (areas > 0.0)
    i_right = areas.shape[1] - 1 - np.argmax(ok_r[:, ::-1], axis=1)
    before_r = (
        np.take_along_axis(rcum, i_right[:, None], axis=1)[:, 0]
        - np.take_along_axis(areas, i_right[:, None], axis=1)[:, 0]
    )
    right = solve(i_right, half - before_r, True)
    return np.where(fired, 0.5 * (left + right), np.nan), fired


def _nan() -> float:
    return math.nan
