"""Closed-form derivatives of a system's outputs with respect to its parameters.

On each piece of the engine's piecewise-linear structure (each sample inside one linear
segment of every term it reads, the same operand minimal in every MIN, the same rule
maximal in every MAX accumulation) the output of a system with

* input terms given by points, triangles, trapezoids (linear pieces) or Gaussians,
* conditions that are ANDs (MIN or PROD) of ``variable IS term``,
* singleton outputs under CoGS (accumulation MAX, SUM or BSUM), Takagi-Sugeno outputs
  (constant, linear or singleton terms) under WTAVER / WTSUM, or Mamdani outputs with
  points/triangle/trapezoid terms under COG or COA (activation MIN or PROD, accumulation
  MAX, SUM or BSUM: :mod:`fuzzyctl.tune.gradient_cog`),

is a rational function of the parameters, and its gradient follows by the chain rule:

    CoGS / WTAVER: y = sum(mu_t z_t) / sum(mu_t),   dy/dmu_t = (z_t - y) / sum(mu),
                   dy/dz_t = mu_t / sum(mu)
    linear piece:  mu = y_k + (y_k+1 - y_k) (x - x_k) / (x_k+1 - x_k),
                   dmu/dx_k = (y_k+1 - y_k) (x - x_k+1) / (x_k+1 - x_k)^2,
                   dmu/dx_k+1 = -(y_k+1 - y_k) (x - x_k) / (x_k+1 - x_k)^2
    MIN / MAX: the derivative of the operand that is selected; PROD: the product rule.

Where it does not hold (:func:`unsupported` says why): on the boundaries between pieces
(a sample exactly on a breakpoint, ties in MIN/MAX: a set of measure zero, where the
one-sided derivative is used), for Mamdani outputs by LM, RM, MOM or with PROBOR/NSUM
or smooth terms, for OR, NOT, hedges,
chained rule blocks, other norms, fuzzylite's rule activation methods and firing
threshold, and for other shapes.  There the tuner falls back to finite differences of the
engine's outputs.  Samples where no rule fires take the DEFAULT value (derivative 0).
"""

from __future__ import annotations

from collections.abc import Callable, Sequence

import numpy as np
import numpy.typing as npt

from fuzzyctl.engine.plan import CAnd, CondPlan, CTerm, CTrue, OutputPlan, Plan, TermPlan
from fuzzyctl.engine.semantics.shapes import NUMPY, membership_np, pwl_value_np
from fuzzyctl.kinds import formula, norms
from fuzzyctl.kinds import shapes as registry
from fuzzyctl.kinds.methods import METHODS
from fuzzyctl.model import DefuzzifyBlock, FunctionBlock, FuzzifyBlock
from fuzzyctl.tune import gradient_cog

Arr = npt.NDArray[np.float64]
PSlot = tuple[str, int, int, int] | tuple[str, int, int] | tuple[str, int]
Grad = dict[PSlot, Arr]

# piecewise-linear terms whose breakpoints' x are parameters: IEC points and the shapes whose
# parameters are their vertices (the registry's ``vertices``)
_PIECE_KINDS = {"points"} | {k for k in registry.SHAPES if registry.vertices(k) is not None}


def _term_unsupported(t: TermPlan) -> str | None:
    if not t.constant:
        return f"term {t.name}: parameters given by variables"
    if t.kind in _PIECE_KINDS:
        if t.pwl is None or not all(np.isfinite(x) for x, _ in t.pwl):
            return f"term {t.name}: infinite vertices"
        return None
    shape = registry.SHAPES.get(t.kind)
    if shape is not None and shape.differentiable:  # the registry writes its derivatives
        return None
    return f"term {t.name}: shape {t.kind}"


def _cond_unsupported(c: CondPlan) -> str | None:
    if isinstance(c, CTrue):
        return None
    if isinstance(c, CTerm):
        return "hedges or IS NOT in a condition" if c.hedges or c.negated else None
    if isinstance(c, CAnd):
        if not norms.keeps_lines(c.op):
            return f"AND {c.op}"
        for o in c.operands:
            why = _cond_unsupported(o)
            if why:
                return why
        return None
    return f"condition {type(c).__name__[1:].upper()}"


def unsupported(plan: Plan, outputs: Sequence[str]) -> str | None:
    """Why the closed form does not apply to ``outputs`` of ``plan`` (``None``: it does)."""
    if plan.options.emulate is not None:
        return f"the {plan.options.emulate} profile's sampled arithmetic"
    if plan.chained:
        return "chained rule blocks (local variables)"
    if plan.selections:
        return "rule activation methods (fuzzylite)"
    if plan.options.firing_threshold > 0.0:
        return "a firing threshold"
    for fi in plan.fuzzy_inputs:
        for t in fi.terms:
            why = _term_unsupported(t)
            if why:
                return f"{fi.name}: {why}"
    for r in plan.rules:
        why = _cond_unsupported(r.condition)
        if why:
            return f"rule {r.label}: {why}"
        if not isinstance(r.weight, float | int):
            return f"rule {r.label}: weight given by a variable"
        for cp in r.conclusions:
            if cp.hedges or not isinstance(cp.weight, float | int):
                return f"rule {r.label}: hedged conclusion or WITH given by a variable"
    for name in outputs:
        op = next((o for o in plan.outputs if o.name == name), None)
        if op is None:
            return f"no output {name}"
        if op.kind == "singleton":
            if METHODS[op.method].weighted is None or not norms.plain_sum_or_max(op.accu, bounded_too=True):
                return f"{name}: {op.method} with ACCU {op.accu}"
            if any(t.kind != "singleton" or not t.constant for t in op.terms):
                return f"{name}: SINGLETONS terms"
        elif op.kind == "ts":
            if not METHODS[op.method].takagi_sugeno or not norms.plain_sum_or_max(op.accu):
                return f"{name}: {op.method} with ACCU {op.accu}"
            if any(
                not (t.kind == "singleton" or registry.flag(t.kind, "takagi_sugeno")) or not t.constant
                for t in op.terms
            ):
                return f"{name}: function or Tsukamoto terms"
        elif op.kind == "mamdani":
            why = gradient_cog.unsupported(op)
            if why:
                return why
        else:
            return f"{name}: {op.kind} output"
    return None


def _add(g: Grad, key: PSlot, v: Arr) -> None:
    g[key] = g[key] + v if key in g else v


def _scale(g: Grad, s: Arr | float) -> Grad:
    return {k: v * s for k, v in g.items()}


def _derivatives(shape: registry.Shape) -> list[Callable[..., Arr]]:
    """The registry's derivative formulas of ``shape``, compiled for numpy once."""
    if "gradient_np" not in shape.compiled:
        fs = shape.parsed_gradient()
        shape.compiled["gradient_np"] = [formula.vectorised(f, NUMPY, registry.HELPERS) for f in fs]
    found: list[Callable[..., Arr]] = shape.compiled["gradient_np"]
    return found


def _term_degree(var: int, ti: int, t: TermPlan, x: Arr) -> tuple[Arr, Grad]:
    grad: Grad = {}
    shape = registry.SHAPES.get(t.kind)
    if shape is not None and shape.differentiable:
        p64 = [np.float64(v) for v in t.params]  # type: ignore[arg-type]
        mu = membership_np(t.kind, p64, float(t.height), x)  # type: ignore[arg-type]
        for i, derivative in enumerate(_derivatives(shape)):
            grad[("in", var, ti, i)] = derivative(x, mu, *p64)
        return mu, grad
    assert t.pwl is not None
    mu = pwl_value_np(t.pwl, x)
    h = float(t.height)  # type: ignore[arg-type]
    p = [float(v) for v in t.params]  # type: ignore[arg-type]
    if t.kind == "points":
        xs, ys, idx = p[0::2], [y * h for y in p[1::2]], list(range(0, len(p), 2))
    else:
        vertices = registry.vertices(t.kind)
        assert vertices is not None
        idx = list(range(len(vertices)))
        xs = [p[i] for i in idx]
        ys = [v * h for v in vertices]
    for k in range(len(xs) - 1):
        x0, x1 = xs[k], xs[k + 1]
        if not x0 < x1:
            continue
        dy = ys[k + 1] - ys[k]
        if dy == 0.0:
            continue
        inside = (x0 < x) & (x < x1)
        span2 = (x1 - x0) ** 2
        _add(grad, ("in", var, ti, idx[k]), np.where(inside, dy * (x - x1) / span2, 0.0))
        _add(grad, ("in", var, ti, idx[k + 1]), np.where(inside, -dy * (x - x0) / span2, 0.0))
    return mu, grad


def _condition(c: CondPlan, degrees: dict[tuple[int, int], tuple[Arr, Grad]], n: int) -> tuple[Arr, Grad]:
    if isinstance(c, CTrue):
        return np.ones(n), {}
    if isinstance(c, CTerm):
        return degrees[(c.var, c.term)]
    assert isinstance(c, CAnd)
    parts = [_condition(o, degrees, n) for o in c.operands]
    vals = np.stack([np.broadcast_to(v, (n,)) for v, _ in parts])
    grad: Grad = {}
    if norms.is_min(c.op):
        pick = np.argmin(vals, axis=0)
        for k, (_v, g) in enumerate(parts):
            sel = pick == k
            for key, d in g.items():
                _add(grad, key, np.where(sel, d, 0.0))
        return vals.min(axis=0), grad
    total = np.prod(vals, axis=0)
    for k, (_v, g) in enumerate(parts):
        others = np.prod(np.delete(vals, k, axis=0), axis=0) if len(parts) > 1 else np.ones(n)
        for key, d in g.items():
            _add(grad, key, d * others)
    return total, grad


def forward(plan: Plan, vals: Sequence[Arr], outputs: Sequence[str]) -> dict[str, tuple[Arr, Grad]]:
    """Values (NaN where no rule fires) and gradients of ``outputs`` at the samples ``vals``
    (one array per input of ``plan``, in its order), for a plan :func:`unsupported` accepts.

    Gradient keys: ``("in", fuzzy input, term, parameter)``, ``("out", output, term,
    parameter)``, ``("rule", rule)`` (rule weight), ``("with", rule, conclusion)``."""
    n = len(vals[0]) if vals else 0
    vals = [
        np.asarray(v, dtype=np.float64) if i.clamp is None else np.clip(v, *i.clamp)
        for i, v in zip(plan.inputs, vals, strict=True)
    ]
    degrees: dict[tuple[int, int], tuple[Arr, Grad]] = {}
    for var, fi in enumerate(plan.fuzzy_inputs):
        for ti, t in enumerate(fi.terms):
            degrees[(var, ti)] = _term_degree(var, ti, t, vals[fi.slot])
    fired_rules: list[tuple[Arr, Grad]] = []
    for ri, r in enumerate(plan.rules):
        a, g = _condition(r.condition, degrees, n)
        w = float(r.weight)  # type: ignore[arg-type]
        g = _scale(g, w)
        g[("rule", ri)] = np.asarray(a, dtype=np.float64)
        fired_rules.append((a * w, g))
    result: dict[str, tuple[Arr, Grad]] = {}
    for oi, op in enumerate(plan.outputs):
        if op.name in outputs:
            result[op.name] = _output(oi, op, plan, fired_rules, vals, n)
    return result


def _contributions(op: OutputPlan, fired: list[tuple[Arr, Grad]]) -> list[tuple[int, Arr, Grad]]:
    out = []
    for c in op.contributions:
        a, g = fired[c.rule]
        w = float(c.weight)  # type: ignore[arg-type]
        gg = _scale(g, w)
        gg[("with", c.rule, c.conclusion)] = a
        assert c.term is not None
        out.append((c.term, a * w, gg))
    return out


def _accumulate(accu: str, items: list[tuple[Arr, Grad]], n: int) -> tuple[Arr, Grad]:
    vals = np.stack([np.broadcast_to(v, (n,)) for v, _ in items])
    grad: Grad = {}
    if norms.is_max(accu):
        pick = np.argmax(vals, axis=0)
        for k, (_v, g) in enumerate(items):
            for key, d in g.items():
                _add(grad, key, np.where(pick == k, d, 0.0))
        return vals.max(axis=0), grad
    total = vals.sum(axis=0)
    for _v, g in items:
        for key, d in g.items():
            _add(grad, key, d)
    if norms.bounded(accu):
        # min(1, s): at s == 1 exactly (a degree-1 plateau under weight 1, common) the
        # left derivative, the one in the direction weights can move from 1
        grad = {k: np.where(total <= 1.0, d, 0.0) for k, d in grad.items()}
        total = np.minimum(total, 1.0)
    return total, grad


def _output(
    oi: int, op: OutputPlan, plan: Plan, fired: list[tuple[Arr, Grad]], vals: Sequence[Arr], n: int
) -> tuple[Arr, Grad]:
    if op.kind == "mamdani":
        return _mamdani(oi, op, plan, fired, n)
    contribs = _contributions(op, fired)
    per_term: dict[int, list[tuple[Arr, Grad]]] = {}
    for t, v, g in contribs:
        per_term.setdefault(t, []).append((v, g))
    items: list[tuple[int, Arr, Grad]]
    if op.kind == "ts" and op.accu is None:
        items = [(t, v, g) for t, v, g in contribs]
    else:
        accu = op.accu or "MAX"
        items = [(t, *_accumulate(accu, lst, n)) for t, lst in sorted(per_term.items())]
    m = len(plan.inputs)
    zs: dict[int, tuple[Arr, Grad]] = {}
    for t, _v, _g in items:
        if t in zs:
            continue
        term = op.terms[t]
        params = [float(p) for p in term.params]  # type: ignore[arg-type]
        zg: Grad = {}
        if registry.flag(term.kind, "ts_linear"):
            z = np.zeros(n)
            for i, c in enumerate(params[:m]):
                z = z + c * vals[i]
                zg[("out", oi, t, i)] = vals[i]
            if len(params) > m:
                z = z + params[m]
                zg[("out", oi, t, m)] = np.ones(n)
        else:
            z = np.full(n, params[0])
            zg[("out", oi, t, 0)] = np.ones(n)
        zs[t] = (z, zg)
    total = np.zeros(n)
    num = np.zeros(n)
    for t, v, _g in items:
        total = total + v
        num = num + v * zs[t][0]
    fired_rows = total > 0.0
    safe = np.where(fired_rows, total, 1.0)
    average = METHODS[op.method].weighted == "average"
    y = num / safe if average else num
    grad: Grad = {}
    for t, v, g in items:
        z, zg = zs[t]
        dy_dv = (z - y) / safe if average else z
        for key, d in g.items():
            _add(grad, key, dy_dv * d)
        dy_dz = v / safe if average else v
        for key, d in zg.items():
            _add(grad, key, dy_dz * d)
    grad = {k: np.where(fired_rows, d, 0.0) for k, d in grad.items()}
    return _clamped(op, np.where(fired_rows, y, np.nan), grad)


def _clamped(op: OutputPlan, y: Arr, grad: Grad) -> tuple[Arr, Grad]:
    if op.clamp is not None:
        lo, hi = op.clamp
        inside = (y >= lo) & (y <= hi)
        grad = {k: np.where(inside, d, 0.0) for k, d in grad.items()}
        y = np.where(np.isnan(y), y, np.clip(y, lo, hi))
    return y, grad


def _mamdani(oi: int, op: OutputPlan, plan: Plan, fired: list[tuple[Arr, Grad]], n: int) -> tuple[Arr, Grad]:
    """COG or COA of a Mamdani output (:mod:`fuzzyctl.tune.gradient_cog`) chained with the
    rules' degrees; NaN where the set is empty."""
    weights = [float(c.weight) for c in op.contributions]  # type: ignore[arg-type]
    res = gradient_cog.cog_partials(
        op, [a for a, _g in fired], weights, plan.options.weight_before_activation, n
    )
    grad: Grad = {}
    for ci, c in enumerate(op.contributions):
        _a, g = fired[c.rule]
        for key, d in g.items():
            _add(grad, key, res.d_degree[ci] * d)
        _add(grad, ("with", c.rule, c.conclusion), res.d_weight[ci])
    for (t, p), d in res.d_term.items():
        _add(grad, ("out", oi, t, p), d)
    return _clamped(op, res.value, grad)


def slot_map(fb: FunctionBlock, plan: Plan) -> dict[tuple[object, ...], PSlot] | None:
    """Model parameter keys (see :mod:`fuzzyctl.tune.space`) -> gradient keys of
    :func:`forward`; ``None`` when the plan's rules do not line up with the model's."""
    out: dict[tuple[object, ...], PSlot] = {}
    sides: dict[str, tuple[str, int, list[str]]] = {}
    for k, fi in enumerate(plan.fuzzy_inputs):
        sides[fi.name] = ("in", k, [t.name for t in fi.terms])
    for k, op in enumerate(plan.outputs):
        sides.setdefault(op.name, ("out", k, [t.name for t in op.terms]))
    blocks: list[FuzzifyBlock | DefuzzifyBlock] = [*fb.fuzzify, *fb.defuzzify]
    for blk in blocks:
        if blk.variable not in sides:
            continue
        side, k, names = sides[blk.variable]
        first: dict[str, int] = {}
        for ti, t in enumerate(blk.terms):
            first.setdefault(t.name, ti)
            if first[t.name] != ti or t.name not in names:
                continue  # a duplicate term name: the engine uses the first
            j = names.index(t.name)
            npar = len(getattr(t.mf, "params", ())) or 2 * len(getattr(t.mf, "points", ())) or 1
            for p in range(npar):
                out[("term", blk.variable, ti, p)] = (side, k, j, p)
    ri = 0
    for bi, rb in enumerate(fb.rule_blocks):
        if not rb.enabled:
            continue
        for r_idx, rule in enumerate(rb.rules):
            if ri >= len(plan.rules) or plan.rules[ri].label != rule.label:
                return None
            out[("rule", bi, r_idx)] = ("rule", ri)
            for ci in range(len(rule.conclusions)):
                out[("with", bi, r_idx, ci)] = ("with", ri, ci)
            ri += 1
    return out if ri == len(plan.rules) else None
