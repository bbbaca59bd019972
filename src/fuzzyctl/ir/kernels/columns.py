"""The kernels of the evaluator program (:mod:`fuzzyctl.ir.programs.evaluator`) on columns of
samples (numpy), called by the source :mod:`~fuzzyctl.ir.render.npsrc` prints.

Same semantics and closed forms as the scalar kernels (:mod:`fuzzyctl.ir.kernels.scalar`): on a
grid interval, two sets under MAX through the exact ``max(a, b) = a + b - min(a, b)`` kernel
(:func:`_max_of_two`), more sets by cutting each sample's activated sets at their kinks and
crossings (a fixed number of candidate points per interval, sorted per row) and integrating
the linear pieces exactly (:func:`_interval`); CoA, LM, RM and MoM from all pieces.  What has
no vectorised form here (smooth sets, terms given by variables on an output) is evaluated row
by row by the interpreter.

Every kernel takes the number of rows first; its other arguments are arrays of that length or
numbers (the same for every row).

These are hand-written because printing their IR twins as numpy was measured slower: the
twins are :meth:`fuzzyctl.ir.programs.evaluator.FastBuilder.closed_cog` with
:func:`fuzzyctl.ir.builders.pieces.max_of_two` (:func:`centroid`, :func:`_max_of_two`) and
:mod:`fuzzyctl.ir.builders.grid_pieces` (:func:`bisector_value`, :func:`maximum_point`), which the
native backend compiles; each method's entry in :mod:`fuzzyctl.kinds.methods` names both.  A
method's kernel is optional: an entry naming none runs its IR rendered
(:mod:`fuzzyctl.ir.kernels.rendered`).  ``benchmarks/bench_engine.py --only kernels`` times
every kernel here against its twin printed as numpy (column "np IR"; "np gather": printed
with a gather for an array index that differs between rows and a masked loop for a loop
whose end does, which plain if-conversion refuses).  Measured 2026-12-06 (``--quick``, ns
per row, one core):

===============  ===============================================  ===========================
kernel           IR twin                                          numpy IR (gather)
===============  ===============================================  ===========================
``AM_LINES``     :func:`fuzzyctl.ir.builders.pieces.max_of_two`,  2.5x slower (two sets);
                 :func:`~fuzzyctl.ir.builders.pieces.interval`    three sets 1.16x, PROBOR
                                                                  1.6x slower (gather)
``MAMDANI``      :mod:`fuzzyctl.ir.builders.grid_pieces`          CoA 5.3x, LM 2.7x, RM 2.6x,
                                                                  MoM 2.0x, MoM BSUM 3.3x,
                                                                  CoA PROBOR 1.3x slower
``TS``           :func:`fuzzyctl.ir.builders.terms.tsukamoto`     2.1x slower
``SELECT``       ``NativeBuilder.select``                         a tie at 4 rules (+-10%);
                 (:mod:`fuzzyctl.ir.programs.native`)             quadratic in the rule count
``MEMBER``       ``NativeBuilder.member`` (run-time sort)         1.16x slower (gather)
``EXPR``         ``RuleBuilder.function_term``                    not timed yet (Python and
                                                                  numpy print no function IR)
===============  ===============================================  ===========================

A smooth output's quadrature (``smooth CoG``) printed with gathers was 10x slower than
:mod:`fuzzyctl.ir.kernels.smooth_columns`.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Sequence
from typing import Any

import numpy as np
import numpy.typing as npt

from fuzzyctl.engine.plan import GridPlan, OutputPlan, Plan, Slot, TermPlan
from fuzzyctl.engine.reference import pwl
from fuzzyctl.engine.semantics import selection, shapes
from fuzzyctl.engine.semantics.expr import eval_expr_np
from fuzzyctl.engine.semantics.operators import accumulate_np, clamp_np
from fuzzyctl.ir.kernels.rendered import output_kernel
from fuzzyctl.kinds import norms
from fuzzyctl.kinds import shapes as registry
from fuzzyctl.kinds.methods import METHODS, implementation

Arr = npt.NDArray[np.float64]
W = Any  # a weight: float or array
Result = tuple[Arr, npt.NDArray[np.bool_]]  # (values, fired)
Kernel = Callable[..., Any]


def make(name: str, data: Any, plan: Plan) -> Kernel:
    """The vectorised routine of kernel ``name`` with its constant ``data``."""
    if name == "AM_LINES":
        return am_lines(*data)
    if name == "SELECT":
        return lambda n, *d: tuple(_sel(data, n, d))
    if name == "MEMBER":
        return member(data)
    if name == "EXPR":
        return expr(*data)
    if name in ("MAMDANI", "TS"):
        return whole_output(plan, *data)
    raise AssertionError(f"no numpy kernel {name}")


def full(n: int, x: Any) -> Arr:
    """A column of ``n`` values (a number repeated, or the array itself)."""
    if np.ndim(x) == 0:
        return np.full(n, float(x))
    return np.asarray(x, dtype=np.float64)


def col(n: int, x: Any) -> Arr:
    return np.broadcast_to(np.asarray(x, dtype=np.float64), (n,))


def pwl_membership(points: shapes.Points, x: Any) -> Any:
    return shapes.pwl_value_np(points, np.asarray(x, dtype=np.float64))


def _sel(sel: Any, n: int, degrees: Sequence[Any]) -> list[Arr]:
    stacked = np.stack([col(n, d) for d in degrees], axis=1)
    chosen = selection.select_np(sel, stacked)
    return [chosen[:, j] for j in range(len(degrees))]


def am_lines(x0: float, x1: float, accu: str, geom: tuple[tuple[float, float, bool], ...]) -> Kernel:
    """Area and moment of the accumulated sets on ``[x0, x1]`` for every row."""

    def f(n: int, *hw: Any) -> tuple[Arr, Arr]:
        lines = [
            (left, right, col(n, hw[2 * k]), hw[2 * k + 1], is_min)
            for k, (left, right, is_min) in enumerate(geom)
        ]
        if norms.is_max(accu) and len(lines) == 2:
            return _max_of_two(x0, x1, lines[0], lines[1])
        if len(lines) == 1:
            return _clipped_line_am(x0, x1 - x0, lines[0])
        X, V, extra = _interval(x0, x1, lines, accu, n)
        if extra is not None:
            return extra
        xa, xb, v0, v1 = X[:, :-1], X[:, 1:], V[:, :-1], V[:, 1:]
        dx = xb - xa
        area = (0.5 * dx * (v0 + v1)).sum(axis=1)
        moment = (dx * (xa * (2.0 * v0 + v1) + xb * (v0 + 2.0 * v1))).sum(axis=1) / 6.0
        return area, moment

    return f


def member(t: TermPlan) -> Kernel:
    """A membership function whose parameters are inputs."""

    def f(n: int, x: Any, *values: Any) -> Arr:
        params = [values[p.index] if isinstance(p, Slot) else p for p in t.params]
        h = values[t.height.index] if isinstance(t.height, Slot) else t.height
        return shapes.membership_np(t.kind, params, h, col(n, x))

    return f


def expr(e: Any, refs: tuple[int, ...], n_outputs: int) -> Kernel:
    """A function term: arguments x, the inputs, then the outputs it reads."""

    def f(n: int, x: Any, *args: Any) -> Arr:
        n_in = len(args) - len(refs)
        outs: list[Any] = [math.nan] * n_outputs
        for k, o in enumerate(refs):
            outs[o] = args[n_in + k]
        vals = [col(n, a) for a in args[:n_in]]
        got = np.asarray(eval_expr_np(e, vals, outs, col(n, x)), dtype=np.float64)
        return np.broadcast_to(got, (n,)).copy()

    return f


def hold(oi: int, default: float, no_change: bool, clamp: tuple[float, float] | None) -> Kernel:
    """DEFAULT / NC / lock-range of output ``oi`` along the batch: a row where no rule fired
    takes the previous row's value (NC) or the default; ``state[oi]`` carries the last value
    to the next batch."""

    def f(n: int, state: list[float | None], value: Any, fired: Any) -> Arr:
        value = full(n, value)
        fired = np.broadcast_to(np.asarray(fired, dtype=bool), (n,))
        if clamp is not None:  # lock-range: NC keeps the limited value, DEFAULT is limited too
            value = clamp_np(value, *clamp)
        if fired.all():
            if n:
                state[oi] = float(value[-1])
            return np.asarray(value, dtype=np.float64)
        prev = state[oi]
        initial = prev if (no_change and prev is not None) else default
        if no_change:
            idx = np.where(fired, np.arange(n), -1)
            np.maximum.accumulate(idx, out=idx)
            filled = np.where(idx >= 0, value[np.maximum(idx, 0)], initial)
            out = np.where(fired, value, filled)
        else:
            out = np.where(fired, value, initial)
        if clamp is not None:
            out = clamp_np(out, *clamp)
        if n:
            state[oi] = float(out[-1])
        return np.asarray(out, dtype=np.float64)

    return f


def whole_output(plan: Plan, oi: int, earlier: tuple[int, ...], sets: tuple[tuple[int, str], ...]) -> Kernel:
    """A whole output from its activated sets: exact Mamdani outputs on a constant grid and
    Takagi-Sugeno outputs vectorised, the rest row by row through the interpreter."""
    op = plan.outputs[oi]
    n_in = len(plan.inputs)
    rendered: list[Any] = []  # a method without a numpy kernel: its IR rendered, made once

    def f(n: int, *args: Any) -> Result:
        vals = [col(n, a) for a in args[:n_in]]
        outs: list[Any] = [np.full(n, np.nan) for _ in plan.outputs]
        for k, o in enumerate(earlier):
            outs[o] = col(n, args[n_in + k])
        base = n_in + len(earlier)
        contribs: list[tuple[int | None, Arr, Any, str]] = [
            (t, col(n, args[base + 2 * k]), args[base + 2 * k + 1], act) for k, (t, act) in enumerate(sets)
        ]
        if op.kind == "ts":
            return _ts(op, contribs, vals, outs, n)
        contribs = _scale_tiny(contribs, n)
        if (
            op.exact
            and op.grid is not None
            and not (norms.probabilistic(op.accu) and METHODS[op.method].bisects)
        ):
            if not METHODS[op.method].numpy:
                if not rendered:
                    rendered.append(output_kernel(plan, op, [(t or 0, act) for t, _a, _w, act in contribs]))
                return rendered[0](n, [x for _t, a, w, _act in contribs for x in (a, w)])  # type: ignore[no-any-return]
            groups = [(t or 0, a, w, norms.is_min(act)) for t, a, w, act in contribs]
            return _mamdani(op, op.grid, groups, n)
        from fuzzyctl.ir.kernels.smooth_columns import smooth_output

        return smooth_output(plan, op, [(t or 0, a, w, act) for t, a, w, act in contribs], vals, outs, n)

    return f


def _scale_tiny(
    contribs: list[tuple[int | None, Arr, Any, str]], n: int
) -> list[tuple[int | None, Arr, Any, str]]:
    """``pwl.tiny_degree_scale`` row by row (the same power-of-two steps, exact)."""
    if not contribs:
        return contribs
    top = np.max(np.stack([np.broadcast_to(a, (n,)) for _t, a, _w, _act in contribs]), axis=0)
    scale = np.ones(n)
    for _ in range(pwl.TINY_COUNT):
        step = np.where((top > 0.0) & (top < pwl.TINY_BELOW), pwl.TINY_FACTOR, 1.0)
        top = top * step
        scale = scale * step
    return [(t, a * scale, w, act) for t, a, w, act in contribs]


def _ts(
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
                    term.kind, [_pv(p, vals) for p in term.params], _pv(term.height, vals), wt
                ),
                dtype=np.float64,
            )
        if t not in zs:
            if term.kind == "singleton" or registry.flag(term.kind, "ts_constant"):
                z = np.full(n, 1.0) * _pv(term.params[0], vals)
            elif registry.flag(term.kind, "ts_linear"):
                cs = [_pv(p, vals) for p in term.params]
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
        value = num / den if METHODS[op.method].weighted == "average" else num
    return np.where(fired, value, np.nan), fired


def _pv(p: Any, vals: Sequence[Arr]) -> W:
    return vals[p.index] if isinstance(p, Slot) else p


Group = tuple[int, Arr, W, bool]


def _mamdani(op: OutputPlan, grid: GridPlan, groups: list[Group], n: int) -> Result:
    """An exact output on a constant grid from its (merged) activated sets: the method's
    kernel (its registry entry's ``numpy``)."""
    kernel = implementation(METHODS[op.method].numpy)
    return kernel(op, grid, groups, n)  # type: ignore[no-any-return]


def centroid(op: OutputPlan, grid: GridPlan, groups: list[Group], n: int) -> Result:
    """CoG: band polynomials where a term is alone, exact integrals where sets overlap
    (IR twin: :meth:`fuzzyctl.ir.programs.evaluator.FastBuilder.closed_cog`)."""
    accu = op.accu or "MAX"
    per_term: dict[int, int] = {}
    for t, _a, _w, _mn in groups:
        per_term[t] = per_term.get(t, 0) + 1
    area = np.zeros(n)
    moment = np.zeros(n)
    closed = {t for t, k in per_term.items() if k == 1 or norms.adds(accu)}
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
    general = sorted(set(grid.shared) | {j for t in per_term if t not in closed for j in grid.solo[t]})
    for j in general:
        lines = [
            (grid.left[t][j], grid.right[t][j], a, w, mn) for t, a, w, mn in groups if t in grid.active[j]
        ]
        if not lines:
            continue
        if norms.is_max(accu) and len(lines) == 2:
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


def _all_pieces(op: OutputPlan, grid: GridPlan, groups: list[Group], n: int) -> tuple[Arr, ...] | None:
    """Every interval as pieces: (x0, x1, v0, v1), one row per sample."""
    accu = op.accu or "MAX"
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
        return None
    x0 = np.concatenate([X[:, :-1] for X in xs_all], axis=1)
    x1 = np.concatenate([X[:, 1:] for X in xs_all], axis=1)
    v0 = np.concatenate([V[:, :-1] for V in vs_all], axis=1)
    v1 = np.concatenate([V[:, 1:] for V in vs_all], axis=1)
    return x0, x1, v0, v1


def bisector_value(op: OutputPlan, grid: GridPlan, groups: list[Group], n: int) -> Result:
    """CoA from every piece (IR twin: :func:`fuzzyctl.ir.builders.grid_pieces.bisector_by_intervals`)."""
    p = _all_pieces(op, grid, groups, n)
    if p is None:
        return np.full(n, np.nan), np.zeros(n, dtype=bool)
    return coa_columns(*p)


def maximum_point(op: OutputPlan, grid: GridPlan, groups: list[Group], n: int) -> Result:
    """LM, RM or MoM from every piece and the grid points (IR twins:
    ``grid_pieces.first_reaching`` and ``mean_reaching`` under MAX, else ``leftmost``,
    ``rightmost``, ``mean_of_maximum``)."""
    p = _all_pieces(op, grid, groups, n)
    if p is None:
        return np.full(n, np.nan), np.zeros(n, dtype=bool)
    x0, x1, v0, v1 = p
    pts = _point_values(grid, groups, op.accu or "MAX", n)
    value, _fired = _maxima(op.method, x0, x1, v0, v1, np.asarray(grid.xs), pts)
    fired = (0.5 * (x1 - x0) * (v0 + v1)).sum(axis=1) > 0.0
    return np.where(fired, value, np.nan), fired


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
    if norms.is_max(accu) and len(lines) > 1:
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
        if norms.is_max(accu):
            return np.asarray(np.maximum.reduce(vs))
        s = np.add.reduce(vs)
        if norms.bounded(accu):
            return np.asarray(np.minimum(1.0, s))
        if norms.probabilistic(accu):
            acc = np.zeros_like(s)
            for v in vs:
                acc = acc + v - acc * v
            return np.asarray(acc)
        return np.asarray(s)

    vs = values(T)
    V = combine(vs)
    if norms.bounded(accu) and len(lines) > 1:
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
    if norms.probabilistic(accu) and len(lines) > 1:
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
    from fuzzyctl.engine.semantics.operators import accumulate_np as acc_np

    cols = []
    for j in range(len(grid.xs)):
        v = np.zeros(n)
        for t, a, w, mn in groups:
            y = grid.point[t][j]
            v = acc_np(accu, v, w * (np.minimum(a, y) if mn else a * y))
        cols.append(v)
    return np.stack(cols, axis=1)


def _mean_distinct(x: Arr, near: float) -> Arr:
    """Row-wise mean of the distinct non-NaN values (within ``near`` of the one before: the
    same point, ``pwl.distinct_points``)."""
    s = np.sort(x, axis=1)
    valid = ~np.isnan(s)
    first = np.ones_like(valid)
    first[:, 1:] = s[:, 1:] - s[:, :-1] > near
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
    side = METHODS[method].maximum
    if side == "left":
        value = np.minimum(
            np.minimum(np.where(hit0, x0, np.inf).min(axis=1), np.where(hit1, x1, np.inf).min(axis=1)),
            np.where(hitg, gxb, np.inf).min(axis=1),
        )
    elif side == "right":
        value = np.maximum(
            np.maximum(np.where(hit0, x0, -np.inf).max(axis=1), np.where(hit1, x1, -np.inf).max(axis=1)),
            np.where(hitg, gxb, -np.inf).max(axis=1),
        )
    else:
        near = pwl.MAX_TOL * float(gx[-1] - gx[0])  # pwl.maxima
        plateau = hit0 & hit1 & (x1 > x0)
        length = np.where(plateau, x1 - x0, 0.0).sum(axis=1)
        mom = np.where(plateau, (x1 - x0) * 0.5 * (x0 + x1), 0.0).sum(axis=1)
        pts = np.concatenate(
            [np.where(hit0, x0, np.nan), np.where(hit1, x1, np.nan), np.where(hitg, gxb, np.nan)], axis=1
        )
        with np.errstate(all="ignore"):
            value = np.where(length > near, mom / length, _mean_distinct(pts, near))
    return np.where(fired, value, np.nan), fired


def coa_columns(x0: Arr, x1: Arr, v0: Arr, v1: Arr) -> Result:
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

    tol = pwl.COA_TOL * total  # a zero gap: its middle (pwl.bisector)
    enough = (half - tol)[:, None]
    cum = np.cumsum(areas, axis=1)
    ok = (cum >= enough) & (areas > 0.0)
    i_left = np.argmax(ok, axis=1)
    before = (
        np.take_along_axis(cum, i_left[:, None], axis=1)[:, 0]
        - np.take_along_axis(areas, i_left[:, None], axis=1)[:, 0]
    )
    a_left = np.take_along_axis(areas, i_left[:, None], axis=1)[:, 0]
    whole = half - before >= a_left - tol
    left = solve(i_left, np.where(whole, a_left, half - before), False)
    left = np.where(whole, np.take_along_axis(x1, i_left[:, None], axis=1)[:, 0], left)
    rcum = np.cumsum(areas[:, ::-1], axis=1)[:, ::-1]
    ok_r = (rcum >= enough) & (areas > 0.0)
    i_right = areas.shape[1] - 1 - np.argmax(ok_r[:, ::-1], axis=1)
    before_r = (
        np.take_along_axis(rcum, i_right[:, None], axis=1)[:, 0]
        - np.take_along_axis(areas, i_right[:, None], axis=1)[:, 0]
    )
    a_right = np.take_along_axis(areas, i_right[:, None], axis=1)[:, 0]
    whole = half - before_r >= a_right - tol
    right = solve(i_right, np.where(whole, a_right, half - before_r), True)
    right = np.where(whole, np.take_along_axis(x0, i_right[:, None], axis=1)[:, 0], right)
    return np.where(fired, 0.5 * (left + right), np.nan), fired
