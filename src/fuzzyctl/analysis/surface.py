"""Surface facts and the surface side of the monotonicity check, from the engine's batch
evaluation on a regular grid of the input space (``resolution`` points per input, chosen so
that the grid has at most ``MAX_POINTS`` points).  Every counterexample is evaluated again,
point by point, by the controller's scalar path before it is reported."""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from fuzzyctl.analysis.context import Context, FloatArray
from fuzzyctl.analysis.gaps import Gap

MAX_POINTS = 4096
MAX_EXAMPLES = 5


@dataclass(frozen=True)
class Jump:
    """Two neighbouring grid points where the output changes abruptly: one in a gap (the
    DEFAULT takes over) and one not, or a change larger than a quarter of the output range."""

    output: str
    before: dict[str, float]
    after: dict[str, float]
    values: tuple[float, float]
    default: bool  # one of the points lies in a gap


@dataclass
class SurfaceFacts:
    output: str
    low: float
    low_at: dict[str, float]
    high: float
    high_at: dict[str, float]
    slope: float  # largest |d output / d input| between grid neighbours (output units per input unit)
    slope_input: str
    slope_at: dict[str, float]
    jumps: list[Jump] = field(default_factory=list)


@dataclass
class Sampled:
    axes: list[FloatArray]
    values: dict[str, FloatArray]  # per output, shape = grid shape
    resolution: int


def sample(ctx: Context) -> Sampled:
    n_in = max(1, len(ctx.inputs))
    res = max(3, min(201, int(MAX_POINTS ** (1.0 / n_in))))
    axes = [np.linspace(lo, hi, res) for lo, hi in ctx.ranges]
    mesh = np.meshgrid(*axes, indexing="ij")
    data = {name: m.ravel() for name, m in zip(ctx.inputs, mesh, strict=True)}
    out = ctx.controller.evaluate_batch(data)
    shape = tuple(len(a) for a in axes)
    return Sampled(axes, {k: np.asarray(v).reshape(shape) for k, v in out.items()}, res)


def _point(ctx: Context, s: Sampled, idx: tuple[int, ...]) -> dict[str, float]:
    return {name: float(s.axes[k][i]) for k, (name, i) in enumerate(zip(ctx.inputs, idx, strict=True))}


def _in_gap(point: dict[str, float], gaps: list[Gap]) -> bool:
    return any(all(lo <= point[k] <= hi for k, (lo, hi) in g.box.items()) for g in gaps)


def facts(ctx: Context, s: Sampled, gaps: list[Gap], epsilon: float = 0.0) -> list[SurfaceFacts]:
    """Range, largest slope and jumps of each output; the faces of gaps count as jumps
    only for epsilon 0 (where the DEFAULT takes over: with epsilon > 0 rules still fire)."""
    out = []
    for name, y in s.values.items():
        finite = np.where(np.isfinite(y), y, np.nan)
        if not np.isfinite(finite).any():
            continue
        lo_i = tuple(int(v) for v in np.unravel_index(int(np.nanargmin(finite)), y.shape))
        hi_i = tuple(int(v) for v in np.unravel_index(int(np.nanargmax(finite)), y.shape))
        f = SurfaceFacts(
            name, float(y[lo_i]), _point(ctx, s, lo_i), float(y[hi_i]), _point(ctx, s, hi_i), 0.0, "", {}
        )
        span = float(np.nanmax(finite) - np.nanmin(finite))
        my_gaps = [g for g in gaps if g.output == name] if epsilon <= 0 else []
        for k, xs in enumerate(s.axes):
            if len(xs) < 2:
                continue
            dy = np.diff(finite, axis=k)
            slope = np.abs(dy) / (xs[1] - xs[0])
            if np.isfinite(slope).any():
                j = tuple(int(v) for v in np.unravel_index(int(np.nanargmax(slope)), slope.shape))
                if slope[j] > f.slope:
                    f.slope, f.slope_input, f.slope_at = float(slope[j]), ctx.inputs[k], _point(ctx, s, j)
            f.jumps += _jumps(ctx, s, name, k, dy, span, my_gaps)
        f.jumps = sorted(
            f.jumps,
            key=lambda j: -abs(j.values[1] - j.values[0]) if all(map(math.isfinite, j.values)) else -math.inf,
        )[:10]
        out.append(f)
    return out


def _jumps(
    ctx: Context, s: Sampled, name: str, k: int, dy: FloatArray, span: float, gaps: list[Gap]
) -> list[Jump]:
    y = s.values[name]
    big = np.abs(np.nan_to_num(dy, nan=math.inf)) > 0.25 * span if span > 0 else np.zeros(dy.shape, bool)
    found = []
    for j in np.argwhere(big)[:50]:
        a = tuple(int(v) for v in j)
        b = tuple(v + 1 if m == k else v for m, v in enumerate(a))
        pa, pb = _point(ctx, s, a), _point(ctx, s, b)
        found.append(Jump(name, pa, pb, (float(y[a]), float(y[b])), _in_gap(pa, gaps) != _in_gap(pb, gaps)))
    for g in gaps:  # the DEFAULT takes over at each face of a gap inside the space
        for axis_name, (lo, hi) in g.box.items():
            kk = ctx.inputs.index(axis_name)
            for edge, step in ((lo, -1), (hi, 1)):
                a_lo, a_hi = ctx.ranges[kk]
                if kk != k or not a_lo < edge < a_hi or len(found) >= 20:
                    continue
                inside = {n: 0.5 * (b0 + b1) for n, (b0, b1) in g.box.items()}
                inside[axis_name] = edge
                outside = dict(inside)
                outside[axis_name] = edge + step * (a_hi - a_lo) * 1e-6
                va = ctx.controller.evaluate(inside)[name]
                vb = ctx.controller.evaluate(outside)[name]
                found.append(Jump(name, inside, outside, (va, vb), True))
    return found


def counterexamples(
    ctx: Context, s: Sampled, output: str, input_name: str, sign: str
) -> list[tuple[dict[str, float], dict[str, float]]]:
    """Neighbouring grid points along ``input_name`` where ``output`` moves against
    ``sign`` by more than 1e-9 of its range; each confirmed by the scalar evaluation."""
    y = s.values[output]
    k = ctx.inputs.index(input_name)
    if len(s.axes[k]) < 2:
        return []
    span = float(np.nanmax(y) - np.nanmin(y)) if np.isfinite(y).any() else 0.0
    tol = 1e-9 * max(span, 1e-300)
    dy = np.diff(y, axis=k) * (1.0 if sign == "+" else -1.0)
    bad = np.argwhere(dy < -tol)
    order = np.argsort(dy[tuple(bad.T)]) if len(bad) else np.zeros(0, dtype=np.int64)
    out: list[tuple[dict[str, float], dict[str, float]]] = []
    for idx in order[: MAX_EXAMPLES * 4]:
        a = tuple(int(v) for v in bad[idx])
        b = tuple(v + 1 if m == k else v for m, v in enumerate(a))
        pa, pb = _point(ctx, s, a), _point(ctx, s, b)
        va, vb = ctx.controller.evaluate(pa)[output], ctx.controller.evaluate(pb)[output]
        if (vb - va) * (1.0 if sign == "+" else -1.0) < -tol:
            out.append((pa, pb))
        if len(out) >= MAX_EXAMPLES:
            break
    return out
