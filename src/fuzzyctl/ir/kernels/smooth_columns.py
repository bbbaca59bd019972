"""Smooth Mamdani outputs (sets the engine integrates numerically) on columns of samples: the
adaptive Gauss-Kronrod quadrature of :mod:`fuzzyctl.engine.reference.quadrature` run for every row at
once, started from intervals cut at the set's kinks.

1. Kinks.  Clipping (MIN activation) and maxima (MAX accumulation) make the accumulated set
   bend where the branch taken changes: which activated set is the largest, and whether it
   is clipped.  Each row's set is sampled on the terms' characteristic intervals (a fixed
   grid of 16 points per interval); where the branch changes between two samples, 52
   bisection steps locate the kink to the last bits.  Two kinks between neighbouring samples
   can escape; the adaptive integration then still converges, only with more intervals.
2. Integration.  All open intervals of all rows are evaluated together (one array of nodes,
   the accumulated set of each node's row) and accepted or halved by the scalar rule's
   criterion with each row's own total, until none is open.  Between kinks the set is smooth,
   so most intervals are accepted at once: about 5 times fewer evaluations than starting from
   the characteristic points alone, with the same tolerance (``Options.quad_rtol``, 1e-10
   relative; docs/engine.md).

CoG is vectorised; CoA, LM, RM and MoM of smooth sets, and terms whose parameters are inputs,
go row by row through the interpreter.  The IR twin is
:func:`fuzzyctl.ir.builders.quadrature.smooth_cog` (the native backend's C, and the Python of
single evaluations: :mod:`fuzzyctl.ir.programs.scalar`); printed as numpy it cannot be
if-converted (each row opens its own intervals), so a batch keeps this kernel
(``benchmarks/bench_engine.py --only kernels``, row "smooth CoG").
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any

import numpy as np

from fuzzyctl.engine.plan import OutputPlan, Plan
from fuzzyctl.engine.reference import quadrature
from fuzzyctl.engine.semantics import shapes
from fuzzyctl.engine.semantics.expr import eval_expr_np
from fuzzyctl.engine.semantics.operators import ACT_LEVELS, TNORMS, accumulate_np
from fuzzyctl.kinds import norms
from fuzzyctl.kinds.methods import METHODS

Arr = Any


def smooth_output(
    plan: Plan,
    op: OutputPlan,
    contribs: list[tuple[int, Any, Any, str]],
    vals: Sequence[Arr],
    outs: Sequence[Arr],
    n: int,
) -> tuple[Arr, Arr]:
    """(value, fired) of output ``op`` for ``n`` rows from its activated sets."""
    if not METHODS[op.method].centroid or not all(t.constant for t in op.terms) or n == 0:
        return _rows(plan, op, contribs, vals, outs, n)
    assert op.low is not None and op.high is not None
    cs = [(t, np.broadcast_to(np.asarray(a, dtype=np.float64), (n,)), w, act) for t, a, w, act in contribs]
    on = np.zeros(n, dtype=bool)
    for _t, a, w, _act in cs:
        on |= a * w > 0.0
    value = np.full(n, np.nan)
    fired = np.zeros(n, dtype=bool)
    rows = np.flatnonzero(on)
    if not len(rows):
        return value, fired
    cuts = np.array(
        sorted(
            {
                op.low,
                op.high,
                *(
                    c
                    for t in op.terms
                    for c in shapes.characteristic_points(t.kind, [float(p) for p in t.params])  # type: ignore[arg-type]
                    if op.low < c < op.high
                ),
            }
        )
    )
    arrays = [np.asarray(v) for v in vals]
    for start in range(0, len(rows), BLOCK):  # blocks of rows keep the temporaries in cache
        block = rows[start : start + BLOCK]
        f = _integrand(op, cs, arrays, block)
        a, b, r = _kinked_intervals(f, len(block), cuts, _level_points(op, cs, block, cuts))
        area, moment = integrate_rows(f, len(block), a, b, r, cuts, plan.options.quad_rtol)
        ok = area > 0.0
        # rules fired but a term is undefined there: NaN, not the DEFAULT (interp._smooth)
        undefined = ~(np.isfinite(area) & np.isfinite(moment))
        with np.errstate(all="ignore"):
            value[block] = np.where(ok & ~undefined, moment / area, np.nan)
        fired[block] = ok | undefined
    return value, fired


BLOCK = 128  # rows integrated together
ROUNDS = 4  # kinks located per sample gap at most
SAMPLES = 8  # points per characteristic interval where the branch taken is compared
BISECTIONS = 26  # steps locating a kink (to 2^-26 of a sample spacing: what is left is integrated at once)


def _integrand(op: OutputPlan, cs: list[tuple[int, Arr, Any, str]], vals: list[Arr], rows: Arr) -> Any:
    """mu(x) of the accumulated set for nodes ``x`` belonging to rows ``r`` (indices into
    ``rows``): ``interp.accumulated_function`` for many rows at once, every activated set as
    one row of a 2-D array (sets of one smooth kind in one numpy call).  With ``branch`` it
    also returns which branch each node's value took (the largest set and whether it is
    clipped under MAX; which sets are clipped otherwise)."""
    accu = op.accu or "MAX"
    k = len(cs)
    A = np.stack([a[rows] for _t, a, _w, _act in cs])  # (k, rows)
    W = np.stack(
        [
            np.broadcast_to(np.asarray(w, dtype=np.float64), (len(rows),))
            if np.ndim(w)
            else np.full(len(rows), float(w))
            for _t, _a, w, _act in cs
        ]
    )
    # a set the rule does not activate is left out, as the interpreter leaves it out: under
    # MIN activation a function term below 0 would otherwise still reach the sum
    live = A * W > 0.0
    acts = [act for _t, _a, _w, act in cs]
    is_min = np.array([norms.is_min(act) for act in acts])[:, None]
    by_kind: dict[str, list[int]] = {}
    single: list[int] = []
    for g, (t, _a, _w, _act) in enumerate(cs):
        term = op.terms[t]
        if term.kind in shapes.SMOOTH_KINDS:
            by_kind.setdefault(term.kind, []).append(g)
        else:
            single.append(g)
    stacked = []
    for kind, gs in by_kind.items():
        ps = [
            np.array([float(op.terms[cs[g][0]].params[j]) for g in gs])[:, None]  # type: ignore[arg-type]
            for j in range(len(op.terms[cs[gs[0]][0]].params))
        ]
        hs = np.array([float(op.terms[cs[g][0]].height) for g in gs])[:, None]  # type: ignore[arg-type]
        stacked.append((kind, np.array(gs), ps, hs))

    def f(x: Arr, r: Arr, branch: bool = False) -> Any:
        mu = np.empty((k, len(x)))
        for kind, gs, ps, hs in stacked:
            mu[gs] = hs * shapes.smooth_np(kind, ps, x[None, :])
        for g in single:
            mu[g] = _membership(op.terms[cs[g][0]], vals, rows, x, r)
        a = A[:, r]
        if all(norms.is_min(act) for act in acts):
            c = np.minimum(a, mu)
        elif all(norms.is_prod(act) for act in acts):
            c = a * mu
        else:
            c = np.stack([TNORMS[act].array(a[g], mu[g]) for g, act in enumerate(acts)])
        c = np.where(live[:, r], W[:, r] * c, 0.0)  # 0: what every accumulation leaves alone
        if norms.is_max(accu):
            # from the empty set, as interp.accumulated_function: a term below 0 is cut at 0
            top = c.max(axis=0)
            acc = np.maximum(top, 0.0)
        elif norms.adds(accu):
            acc = c.sum(axis=0)
        else:
            acc = np.zeros(len(x))
            for g in range(k):
                acc = accumulate_np(accu, acc, c[g])
        if not branch:
            return acc
        clipped = is_min & (a < mu)
        if norms.is_max(accu):
            win = np.argmax(c, axis=0)
            code = np.where(top < 0.0, -1, 2 * win + clipped[win, np.arange(len(x))])
        else:
            code = (clipped[:62].astype(np.int64) << np.arange(min(k, 62))[:, None]).sum(axis=0)
            entry = norms.accumulation(accu)
            # the bound reached (a jump to 1 for NIPMAX/DMAX)
            if entry is not None and entry.saturates:
                code |= (acc >= 1.0).astype(np.int64) << 62
            # which set is the largest (NIPMAX/DMAX; MAX took the branch above): kinks where that changes
            if entry is not None and entry.picks_largest:
                code ^= (np.argmax(c, axis=0).astype(np.int64) + 1) << 52
        return acc, code

    return f


def _membership(term: Any, vals: list[Arr], rows: Arr, x: Arr, r: Arr) -> Arr:
    """A term that is not stacked (piecewise linear, function of x) at nodes ``x``."""
    if term.kind == "function":
        assert term.expr is not None
        row_vals = [v[rows][r] if np.ndim(v) else v for v in vals]
        got = np.asarray(eval_expr_np(term.expr, row_vals, [], x), dtype=np.float64)
        return np.broadcast_to(got, x.shape)
    params = [float(p) for p in term.params]
    return shapes.membership_np(term.kind, params, float(term.height), x)


def _level_points(
    op: OutputPlan, cs: list[tuple[int, Arr, Any, str]], rows: Arr, cuts: Arr
) -> tuple[Arr, Arr]:
    """(x, row) where an activated term crosses a level of its activation (NIPMIN's jump,
    MIN's and BDIF's kinks: ``operators.ACT_LEVELS``), to the last bit: a narrow plateau
    between two samples has no branch change at them to be found by."""
    t = np.linspace(0.0, 1.0, 2 * SAMPLES)
    xs = (cuts[:-1, None] + (cuts[1:] - cuts[:-1])[:, None] * t[None, :]).ravel()
    found_x, found_r = [np.zeros(0)], [np.zeros(0, dtype=np.int64)]
    for ti, a, _w, act in cs:
        term = op.terms[ti]
        if term.kind == "function" or act not in ACT_LEVELS:
            continue
        params, height = [float(p) for p in term.params], float(term.height)  # type: ignore[arg-type]
        mu_xs = shapes.membership_np(term.kind, params, height, xs)
        for offset, slope in ACT_LEVELS.get(act, ()):
            lv = offset + slope * a[rows]  # (m,)
            d = mu_xs[None, :] - lv[:, None]
            r, j = np.nonzero(((d[:, :-1] < 0.0) & (d[:, 1:] > 0.0)) | ((d[:, :-1] > 0.0) & (d[:, 1:] < 0.0)))
            lo, hi, below, lvr = xs[j], xs[j + 1], d[r, j] < 0.0, lv[r]
            for _ in range(1100):  # halvings until lo and hi are neighbours
                mid = 0.5 * (lo + hi)
                open_ = (mid > lo) & (mid < hi)
                if not open_.any():
                    break
                left = (shapes.membership_np(term.kind, params, height, mid) < lvr) == below
                lo = np.where(open_ & left, mid, lo)
                hi = np.where(open_ & ~left, mid, hi)
            found_x.append(hi)
            found_r.append(r.astype(np.int64))
    return np.concatenate(found_x), np.concatenate(found_r)


def _kinked_intervals(f: Any, m: int, cuts: Arr, levels: tuple[Arr, Arr]) -> tuple[Arr, Arr, Arr]:
    """Each row's characteristic intervals cut again at the kinks found (module docstring)
    and at the ``levels`` points; returns the intervals as flat arrays (start, end, row),
    ordered by row then x."""
    k0 = len(cuts) - 1
    t = np.linspace(0.0, 1.0, SAMPLES)
    xs = cuts[:-1, None] + (cuts[1:] - cuts[:-1])[:, None] * t[None, :]  # (k0, S)
    x = np.tile(xs.ravel(), m)
    r = np.repeat(np.arange(m), k0 * SAMPLES)
    _v, code = f(x, r, branch=True)
    code = code.reshape(m * k0, SAMPLES)
    xg = x.reshape(m * k0, SAMPLES)
    iv, jv = np.nonzero(code[:, 1:] != code[:, :-1])
    lo, hi = xg[iv, jv], xg[iv, jv + 1]
    rows_k = iv // k0
    c_lo, c_hi = code[iv, jv], code[iv, jv + 1]
    found = []
    for _round in range(ROUNDS):  # a gap may hold several kinks (A -> B -> C): one per round
        if not len(lo):
            break
        end = hi.copy()
        for _ in range(BISECTIONS):
            mid = 0.5 * (lo + hi)
            _v, c_mid = f(mid, rows_k, branch=True)
            same = c_mid == c_lo
            lo = np.where(same, mid, lo)
            hi = np.where(same, hi, mid)
        found.append((0.5 * (lo + hi), rows_k))
        _v, c_right = f(hi, rows_k, branch=True)
        more = (c_right != c_hi) & (hi < end)
        lo, hi, rows_k, c_lo, c_hi = hi[more], end[more], rows_k[more], c_right[more], c_hi[more]
    kinks = np.concatenate([k for k, _r in found]) if found else np.zeros(0)
    rows_k = np.concatenate([r for _k, r in found]) if found else np.zeros(0, dtype=np.int64)
    pts_x = np.concatenate([np.tile(cuts, m), kinks, levels[0]])
    pts_r = np.concatenate([np.repeat(np.arange(m), len(cuts)), rows_k, levels[1]])
    order = np.lexsort((pts_x, pts_r))
    px, pr = pts_x[order], pts_r[order]
    keep = (pr[1:] == pr[:-1]) & (px[1:] > px[:-1])
    return px[:-1][keep], px[1:][keep], pr[:-1][keep]


def integrate_rows(f: Any, m: int, a: Arr, b: Arr, r: Arr, cuts: Any, rtol: float) -> tuple[Arr, Arr]:
    """Area and moment of ``f`` for ``m`` rows from initial intervals ``(a, b)`` of rows ``r``
    (``quadrature.integrate`` with every row's intervals in one array)."""
    span = float(cuts[-1] - cuts[0])
    scale = max(abs(float(cuts[0])), abs(float(cuts[-1])), span)
    k, ek, km, ekm = _rule(f, a, b, r)
    total = np.maximum(np.bincount(r, weights=np.abs(k), minlength=m), 1e-300)
    area = np.zeros(m)
    moment = np.zeros(m)
    count = np.bincount(r, minlength=m)
    undefined = np.zeros(m, dtype=bool)
    while True:
        share = (b - a) / span
        tol = rtol * total[r] * np.maximum(share, 1e-6)
        ok = (ek <= tol) & (ekm <= tol * scale) | ((b - a) <= 1e-13 * scale)
        ok |= count[r] > quadrature.MAX_INTERVALS  # give up refining: keep the best estimate
        # a row with NaN/inf (a 0/0 in a function term) has no number for an answer: no
        # halving makes one, so its intervals stop here (memory stays proportionate to rows)
        undefined |= np.bincount(r, weights=~(np.isfinite(k) & np.isfinite(km)), minlength=m) > 0
        ok |= undefined[r]
        area += np.bincount(r[ok], weights=k[ok], minlength=m)
        moment += np.bincount(r[ok], weights=km[ok], minlength=m)
        if ok.all():
            return area, moment
        a, b, r = a[~ok], b[~ok], r[~ok]
        mid = 0.5 * (a + b)
        a, b, r = np.concatenate([a, mid]), np.concatenate([mid, b]), np.concatenate([r, r])
        count += np.bincount(r, minlength=m)
        k, ek, km, ekm = _rule(f, a, b, r)


def _rule(f: Any, a: Arr, b: Arr, r: Arr) -> tuple[Arr, Arr, Arr, Arr]:
    half = 0.5 * (b - a)
    mid = 0.5 * (a + b)
    x = mid[:, None] + half[:, None] * quadrature.NODES[None, :]
    rr = np.repeat(r, len(quadrature.NODES))
    y = f(x.ravel(), rr).reshape(x.shape)
    k = (y @ quadrature.WK) * half
    g = (y @ quadrature.WG) * half
    km = ((y * x) @ quadrature.WK) * half
    gm = ((y * x) @ quadrature.WG) * half
    return k, np.abs(k - g), km, np.abs(km - gm)


def _rows(
    plan: Plan,
    op: OutputPlan,
    contribs: list[tuple[int, Any, Any, str]],
    vals: Sequence[Arr],
    outs: Sequence[Arr],
    n: int,
) -> tuple[Arr, Arr]:
    """Row by row through the interpreter's output code."""
    from fuzzyctl.engine.reference.interp import Interpreter

    interp = Interpreter(plan)
    value = np.full(n, np.nan)
    fired = np.zeros(n, dtype=bool)
    for i in range(n):
        cs: list[tuple[int | None, float, float, str]] = []
        for t, a, w, act in contribs:
            ai = float(np.asarray(a)[i] if np.ndim(a) else a)
            wi = float(np.asarray(w)[i] if np.ndim(w) else w)
            if ai * wi > 0.0:
                cs.append((t, ai, wi, act))
        rec = interp.output_from(op, cs, [float(v[i]) for v in vals], [float(o[i]) for o in outs])
        value[i], fired[i] = rec.value, rec.fired
    return value, fired
