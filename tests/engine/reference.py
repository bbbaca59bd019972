"""A deliberately naive reference implementation, written from IEC 61131-7 and the shape
definitions directly against the *model* (not the engine's plan), sharing no code with the
engine: membership formulas re-typed here, conditions evaluated recursively, the accumulated
set sampled on a dense grid (midpoint rule, 10^6 cells by default) and defuzzified by the
textbook formulas.  It is slow and approximate (error ~ range / cells), which is the point:
the engine must agree with it to that accuracy whatever it does internally.

Covered: points, triangle, trapezoid, rectangle, ramp, gaussian, bell, sigmoid shapes; AND/OR
pairs MIN/MAX, PROD/ASUM, BDIF/BSUM; NOT; ACT MIN/PROD; ACCU MAX/BSUM/NSUM/SUM/PROBOR;
WITH (IEC: after activation); COG/COA/LM/RM/MoM/COGS.
"""

from __future__ import annotations

import math

import numpy as np

from fuzzyctl import model as m


def _mf(mf: m.MembershipFunction, x: np.ndarray) -> np.ndarray:
    x = np.asarray(x, dtype=float)
    if isinstance(mf, m.PointsMF):
        xs = [float(p.x) for p in mf.points]  # type: ignore[arg-type]
        ys = [float(p.y) for p in mf.points]  # type: ignore[arg-type]
        order = sorted(range(len(xs)), key=lambda i: xs[i])
        xs = [xs[i] for i in order]
        ys = [ys[i] for i in order]
        out = np.interp(x, xs, ys)
        for i in range(len(xs)):  # a vertical edge takes its upper value
            same = [ys[k] for k in range(len(xs)) if xs[k] == xs[i]]
            out = np.where(x == xs[i], max(same), out)
        return out
    assert isinstance(mf, m.ShapeMF)
    p = [float(v) for v in mf.params]  # type: ignore[arg-type]
    h = float(mf.height)  # type: ignore[arg-type]
    k = mf.kind
    if k == "triangle":
        a, b, c = p
        up = np.where(b > a, (x - a) / (b - a if b > a else 1), 1.0)
        down = np.where(c > b, (c - x) / (c - b if c > b else 1), 1.0)
        y = np.where((x < a) | (x > c), 0.0, np.where(x <= b, up, down))
        y = np.where(x == b, 1.0, y)
    elif k == "trapezoid":
        a, b, c, d = p
        up = (x - a) / (b - a) if b > a else np.ones_like(x)
        down = (d - x) / (d - c) if d > c else np.ones_like(x)
        y = np.where((x < a) | (x > d), 0.0, np.where(x < b, up, np.where(x <= c, 1.0, down)))
    elif k == "rectangle":
        y = ((x >= min(p)) & (x <= max(p))).astype(float)
    elif k == "ramp":
        s, e = p
        y = np.clip((x - s) / (e - s), 0.0, 1.0)
    elif k == "gaussian":
        y = np.exp(-((x - p[0]) ** 2) / (2 * p[1] ** 2))
    elif k == "bell":
        y = 1.0 / (1.0 + np.abs((x - p[0]) / p[1]) ** (2 * p[2]))
    elif k == "sigmoid":
        y = 1.0 / (1.0 + np.exp(-p[1] * (x - p[0])))
    else:
        raise NotImplementedError(k)
    return h * y


_T = {"MIN": np.minimum, "PROD": lambda a, b: a * b, "BDIF": lambda a, b: np.maximum(0.0, a + b - 1.0)}
_S = {"MAX": np.maximum, "ASUM": lambda a, b: a + b - a * b, "BSUM": lambda a, b: np.minimum(1.0, a + b)}
_PAIR = {"MIN": "MAX", "PROD": "ASUM", "BDIF": "BSUM"}


def _cond(c: m.Condition, fb: m.FunctionBlock, inputs: dict[str, float], and_op: str, or_op: str) -> float:
    if isinstance(c, m.Is):
        fz = fb.fuzzify_block(c.variable)
        assert fz is not None
        term = fz.term(c.term)
        assert term is not None
        d = float(_mf(term.mf, np.array([inputs[c.variable]]))[0])
        return 1.0 - d if c.negated else d
    if isinstance(c, m.Not):
        return 1.0 - _cond(c.operand, fb, inputs, and_op, or_op)
    if isinstance(c, m.Degree):
        return inputs[c.variable]
    vals = [_cond(o, fb, inputs, and_op, or_op) for o in c.operands]
    f = _T[and_op] if isinstance(c, m.And) else _S[or_op]
    v = vals[0]
    for w in vals[1:]:
        v = float(f(v, w))
    return v


def evaluate(
    fb: m.FunctionBlock,
    inputs: dict[str, float],
    cells: int = 1_000_000,
    max_tol: float = 1e-15,
    runs: dict[str, list[tuple[float, float]]] | None = None,
) -> dict[str, float]:
    """Outputs of ``fb`` (NaN where no rule fired).  ``max_tol``: relative tolerance deciding
    that a sample reaches the maximum (LM, RM, MoM); ``runs`` (when given) receives, per
    output, the connected stretches of samples that reach it."""
    result: dict[str, float] = {}
    for out in fb.outputs:
        db = fb.defuzzify_block(out.name)
        assert db is not None
        contributions = []
        accu = db.accu
        for rb in fb.rule_blocks:
            and_op = rb.and_op or ("MIN" if rb.or_op is None else {v: k for k, v in _PAIR.items()}[rb.or_op])
            or_op = rb.or_op or _PAIR[and_op]
            accu = accu or rb.accu
            for r in rb.rules:
                a = 1.0 if r.condition is None else _cond(r.condition, fb, inputs, and_op, or_op)
                for c in r.conclusions:
                    if c.variable == out.name:
                        w = 1.0 if c.weight is None else float(c.weight)  # type: ignore[arg-type]
                        contributions.append((db.term(c.term or ""), a, w, rb.act or "MIN"))
        accu = accu or "MAX"
        method = (db.method or "COG").upper()
        if all(isinstance(t.mf, m.SingletonMF) for t in db.terms):
            mu: dict[str, float] = {}
            for term, a, w, _act in contributions:
                assert term is not None
                v = w * a
                old = mu.get(term.name, 0.0)
                mu[term.name] = {
                    "MAX": max(old, v),
                    "BSUM": min(1.0, old + v),
                    "SUM": old + v,
                    "NSUM": old + v,
                    "PROBOR": old + v - old * v,
                }[accu]
            den = sum(mu.values())
            num = sum(float(db.term(n).mf.value) * v for n, v in mu.items())  # type: ignore[union-attr,arg-type]
            result[out.name] = num / den if den > 0 else math.nan
            continue
        rng = db.range or out.range
        assert rng is not None
        lo, hi = float(rng.low), float(rng.high)
        u = lo + (np.arange(cells) + 0.5) * (hi - lo) / cells
        acc = np.zeros(cells)
        for term, a, w, act in contributions:
            assert term is not None
            mu_t = _mf(term.mf, u)
            c = w * (np.minimum(a, mu_t) if act == "MIN" else a * mu_t)
            if accu == "MAX":
                acc = np.maximum(acc, c)
            elif accu == "BSUM":
                acc = np.minimum(1.0, acc + c)
            elif accu in ("SUM", "NSUM"):
                acc = acc + c
            elif accu == "PROBOR":
                acc = acc + c - acc * c
        norm = max(1.0, float(acc.max())) if accu == "NSUM" else 1.0
        acc = acc / norm
        area = acc.sum()
        if not area > 0:
            result[out.name] = math.nan
            continue
        if method == "COG":
            result[out.name] = float((u * acc).sum() / area)
        elif method == "COA":  # the middle of the set of bisectors (a gap where mu = 0)
            cum = np.cumsum(acc)
            i = int(np.searchsorted(cum, area / 2))
            rcum = np.cumsum(acc[::-1])
            j = cells - 1 - int(np.searchsorted(rcum, area / 2))
            result[out.name] = float(0.5 * (u[i] + u[j]))
        else:
            # the breakpoints of the terms themselves: a vertical edge takes its upper value
            # exactly there, which midpoints never see
            xs_all = [float(p) for t in db.terms if isinstance(t.mf, m.ShapeMF) for p in t.mf.params]  # type: ignore[arg-type]
            xs_all += [float(p.x) for t in db.terms if isinstance(t.mf, m.PointsMF) for p in t.mf.points]  # type: ignore[arg-type]
            special = sorted({x for x in xs_all if lo <= x <= hi})
            sp = np.array(special)
            acc_sp = np.zeros(len(sp))
            for term, a, w, act in contributions:
                assert term is not None
                mu_t = _mf(term.mf, sp)
                c = w * (np.minimum(a, mu_t) if act == "MIN" else a * mu_t)
                acc_sp = {
                    "MAX": lambda p, q: np.maximum(p, q),
                    "BSUM": lambda p, q: np.minimum(1.0, p + q),
                    "SUM": lambda p, q: p + q,
                    "NSUM": lambda p, q: p + q,
                    "PROBOR": lambda p, q: p + q - p * q,
                }[accu](acc_sp, c)
            acc_sp = acc_sp / norm
            top = max(acc.max(), acc_sp.max() if len(sp) else 0.0)
            hit = acc >= top * (1 - max_tol)
            hit_sp = sp[acc_sp >= top * (1 - max_tol)] if len(sp) else sp
            if runs is not None:
                edges = np.flatnonzero(np.diff(np.concatenate([[0], hit.astype(np.int8), [0]])))
                starts, ends = edges[::2], edges[1::2]
                runs[out.name] = [(float(u[a]), float(u[b - 1])) for a, b in zip(starts, ends, strict=True)]
            if method == "LM":
                result[out.name] = float(min([*u[hit][:1], *hit_sp]))
            elif method == "RM":
                result[out.name] = float(max([*u[hit][-1:], *hit_sp]))
            else:
                result[out.name] = float(u[hit].mean()) if hit.any() else float(np.mean(hit_sp))
    return result
