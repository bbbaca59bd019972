"""A function block as a lookup table: breakpoints per input, the engine's outputs at every
grid point, multi-linear interpolation between them, and a proven bound on the error.

Breakpoints start at the kinks the engine knows (every breakpoint of the input terms) and the
range ends; more are added where the interpolation error on a dense design grid is worst,
along the input whose line through that point bends most, until the error is within
``tolerance`` (a fraction of each output's range) or the table reaches ``max_bytes``.

The bound stated (:attr:`Table.bound`) is then proven: the error is computed exactly at
sample points dense in every cell, and between them bounded by how far the engine's output
can move (:mod:`fuzzyctl.engine.table_bound`, derived from the terms' slopes and the
defuzzification) plus how far the interpolation can move (its steepest slope in the cell);
cells where that margin is large are sampled more densely.  Integer tables (``bits`` 16 or
32) place breakpoints on the stored-integer grid, round the entries, and add the rounding of
the interpolation (one unit per input) to the bound; REAL tables add single-precision
rounding.  The inputs are limited to their ranges before the table is read."""

from __future__ import annotations

import itertools
import math
from collections.abc import Sequence
from dataclasses import dataclass, field
from typing import Any

import numpy as np
import numpy.typing as npt

from fuzzyctl.diagnostics import FuzzyctlError, apart
from fuzzyctl.engine.controller import Controller
from fuzzyctl.engine.plan import Plan, Slot
from fuzzyctl.engine.table_bound import BELL_KINDS, Certifier, refusal
from fuzzyctl.kinds import shapes as registry

Arr = npt.NDArray[np.float64]

#: ``--tolerance`` default: 0.1 % of each output's range
DEFAULT_TOLERANCE = 0.001
#: ``--max-bytes`` default
DEFAULT_MAX_BYTES = 16384
#: design grid points per input, by input count
_DESIGN = {1: 4001, 2: 241, 3: 49}
#: certification samples at most, by input count
_SAMPLES = {1: 400_000, 2: 3_000_000, 3: 4_000_000}
#: certification boxes at most for CoA/LM/RM/MoM outputs (each box costs a pass over the
#: output cells)
_SAMPLES_ENCLOSED = {1: 40_000, 2: 60_000, 3: 80_000}
#: stored-integer span of an input or output, by width: products of two fit the wide type
QUANTA = {16: 16383, 32: 1 << 20}
#: bytes of a stored value, by arithmetic
VALUE_BYTES = {"REAL": 4, "LREAL": 8, 16: 2, 32: 4}


class TableError(FuzzyctlError):
    """What keeps a function block from becoming a table (the reason, and the tolerance a
    size limit allows when that is what stops it)."""


@dataclass
class Table:
    """A lookup table of one function block.  ``axes[i]`` are input ``i``'s breakpoints (in
    engineering units), ``values[k]`` output ``k`` on the grid; ``bound[k]`` the proven
    maximum error against the engine on the input ranges, ``observed[k]`` the largest error
    seen at the samples; ``bits`` 0 (floating point) or the width of an integer table, whose
    inputs and outputs are stored as ``value = stored * scale + offset``."""

    name: str | None
    inputs: tuple[str, ...]
    outputs: tuple[str, ...]
    axes: list[Arr]
    values: list[Arr]
    out_ranges: list[tuple[float, float]]
    bound: list[float] = field(default_factory=list)
    observed: list[float] = field(default_factory=list)
    tolerance: float = DEFAULT_TOLERANCE
    bits: int = 0
    in_scale: list[tuple[float, float]] = field(default_factory=list)  # (scale, offset)
    out_scale: list[tuple[float, float]] = field(default_factory=list)
    samples: int = 0

    @property
    def shape(self) -> tuple[int, ...]:
        return tuple(len(a) for a in self.axes)

    def size_bytes(self, real: str = "REAL") -> int:
        """Breakpoints and entries, in bytes, stored as ``real`` (floating tables) or the
        table's integers."""
        per = VALUE_BYTES[self.bits] if self.bits else VALUE_BYTES[real]
        return per * (sum(self.shape) + len(self.values) * math.prod(self.shape))

    def relative(self, values: Sequence[float]) -> list[float]:
        """``values`` (one per output) as fractions of the output ranges."""
        return [v / (hi - lo) for v, (lo, hi) in zip(values, self.out_ranges, strict=True)]

    def stored_values(self) -> list[npt.NDArray[np.int64]]:
        """The integer table's entries (stored integers)."""
        return [
            np.rint((v - off) / sc).astype(np.int64)
            for v, (sc, off) in zip(self.values, self.out_scale, strict=True)
        ]

    def stored_axes(self) -> list[npt.NDArray[np.int64]]:
        return [
            np.rint((a - off) / sc).astype(np.int64)
            for a, (sc, off) in zip(self.axes, self.in_scale, strict=True)
        ]

    def interpolate(self, cols: Sequence[Arr]) -> list[Arr]:
        """The outputs at the points ``cols`` (one array per input, limited to the ranges)."""
        weights = [hat(a, np.asarray(c, dtype=np.float64)) for a, c in zip(self.axes, cols, strict=True)]
        out = []
        for v in self.values:
            acc = np.zeros(len(weights[0][0]) if weights else 1)
            for corner in itertools.product((0, 1), repeat=len(weights)):
                w = np.ones_like(acc)
                idx = []
                for (lo, t), side in zip(weights, corner, strict=True):
                    w = w * (t if side else 1.0 - t)
                    idx.append(lo + side)
                acc = acc + w * v[tuple(idx)]
            out.append(acc)
        return out


def hat(axis: Arr, x: Arr) -> tuple[npt.NDArray[np.intp], Arr]:
    """The cell of each ``x`` (limited to the axis) and the fraction across it."""
    x = np.clip(x, axis[0], axis[-1])
    if len(axis) == 1:
        return np.zeros(len(x), dtype=np.intp), np.zeros(len(x))
    lo = np.clip(np.searchsorted(axis, x, side="right") - 1, 0, len(axis) - 2)
    t = (x - axis[lo]) / (axis[lo + 1] - axis[lo])
    return lo, t


def _interp_matrix(sub: Arr, full: Arr) -> Arr:
    """Linear interpolation from the points ``sub`` onto ``full`` as a matrix."""
    lo, t = hat(sub, full)
    m = np.zeros((len(full), len(sub)))
    rows = np.arange(len(full))
    m[rows, lo] += 1.0 - t
    if len(sub) > 1:
        m[rows, lo + 1] += t
    return m


def input_range(plan: Plan, ctl: Controller, i: int) -> tuple[float, float]:
    """Input ``i``'s range: its clamp, its RANGE, else the hull of its terms' points."""
    spec = plan.inputs[i]
    if spec.clamp is not None:
        return spec.clamp
    declared = ctl.inputs[spec.name].range
    if declared is not None:
        return declared
    xs = [float(p[0]) for fi in plan.fuzzy_inputs if fi.slot == i for t in fi.terms for p in (t.pwl or ())]
    for fi in plan.fuzzy_inputs:
        if fi.slot == i:
            for t in fi.terms:
                if t.pwl is None and t.kind in BELL_KINDS:
                    c, s = (float(p) for p in t.params if not isinstance(p, Slot))
                    xs += [c - 3 * abs(s), c + 3 * abs(s)]
    if not xs or min(xs) == max(xs):
        raise TableError(f"input {spec.name} has no range: declare RANGE")
    return min(xs), max(xs)


def output_range(
    plan: Plan, ctl: Controller, k: int, in_r: Sequence[tuple[float, float]]
) -> tuple[float, float]:
    """Output ``k``'s range: its RANGE, else the hull of its terms' values (a linear term's
    over the input ranges)."""
    o = plan.outputs[k]
    declared = ctl.outputs[o.name].range
    if declared is not None:
        return declared
    zs = []
    for t in o.terms:
        if not t.params or any(isinstance(p, Slot) for p in t.params):
            continue
        if o.kind == "ts" and registry.flag(t.kind, "ts_linear"):
            cs = [float(p) for p in t.params]  # type: ignore[arg-type]
            const = cs[len(in_r)] if len(cs) > len(in_r) else 0.0
            for corner in itertools.product(*in_r):
                zs.append(const + sum(c * x for c, x in zip(cs, corner, strict=False)))
        else:
            zs.append(float(t.params[0]))  # type: ignore[arg-type]
    if not zs or min(zs) == max(zs):
        raise TableError(f"output {o.name} has no range: declare RANGE")
    return min(zs), max(zs)


def kinks(plan: Plan, i: int, lo: float, hi: float) -> list[float]:
    """Where input ``i``'s terms bend inside its range."""
    return sorted(
        {
            float(p[0])
            for fi in plan.fuzzy_inputs
            if fi.slot == i
            for t in fi.terms
            for p in (t.pwl or ())
            if lo < p[0] < hi
        }
    )


class Evaluator:
    """The engine's outputs on tensor grids (native when a compiler is there)."""

    def __init__(self, plan: Plan) -> None:
        self.plan = plan
        self.ctl: Any = Controller(plan)
        try:
            from fuzzyctl.engine.native import NativeController, build

            self.ctl = NativeController(plan, build(plan, None, None), None)
        except Exception:
            pass

    def grid(self, coords: Sequence[Arr]) -> list[Arr]:
        """The outputs on the tensor grid of ``coords``."""
        shape = tuple(len(c) for c in coords)
        mesh = np.meshgrid(*coords, indexing="ij")
        return [v.reshape(shape) for v in self.points([m.ravel() for m in mesh])]

    def points(self, cols: Sequence[Arr]) -> list[Arr]:
        """The outputs at the points ``cols`` (one array per input)."""
        self.ctl.reset()
        named = {inp.name: c for inp, c in zip(self.plan.inputs, cols, strict=True)}
        out = self.ctl.evaluate_batch(named, out_of_range="ignore")
        return [np.asarray(out[o.name], dtype=np.float64) for o in self.plan.outputs]


@dataclass
class _Design:
    """The dense design grid, the engine on it, and the breakpoints chosen (indices)."""

    grid: list[Arr]
    values: list[Arr]
    spans: list[float]
    chosen: list[list[int]]

    def table_values(self, snap: Any) -> list[Arr]:
        sel = np.ix_(*[np.array(c) for c in self.chosen])
        return [snap(k, v[sel]) for k, v in enumerate(self.values)]

    def error(self, snap: Any) -> Arr:
        mats = [_interp_matrix(g[c], g) for g, c in zip(self.grid, self.chosen, strict=True)]
        worst = np.zeros(self.values[0].shape)
        for k, sub in enumerate(self.table_values(snap)):
            approx = sub
            for ax, m in enumerate(mats):
                approx = np.moveaxis(np.tensordot(m, approx, axes=([1], [ax])), 0, ax)
            worst = np.maximum(worst, np.abs(self.values[k] - approx) / self.spans[k])
        return worst

    def split(self, at: tuple[int, ...]) -> bool:
        """Add a breakpoint along the input whose line through ``at`` bends most."""
        best: tuple[float, int, int] = (-1.0, -1, -1)
        for ax, g in enumerate(self.grid):
            chosen = self.chosen[ax]
            pos = int(np.searchsorted(chosen, at[ax], side="right")) - 1
            pos = min(max(pos, 0), len(chosen) - 2)
            a, b = chosen[pos], chosen[pos + 1]
            if b - a < 2:
                continue
            line = [slice(None) if j == ax else at[j] for j in range(len(at))]
            seg = np.arange(a, b + 1)
            gain = np.zeros(len(seg))
            for k, v in enumerate(self.values):
                ys = v[tuple(line)][seg]
                t = (g[seg] - g[a]) / (g[b] - g[a])
                gain = np.maximum(gain, np.abs(ys - (ys[0] + t * (ys[-1] - ys[0]))) / self.spans[k])
            j = int(np.argmax(gain[1:-1])) + 1
            if gain[j] <= 1e-12:  # straight along this input: its middle, wide intervals first
                j = len(seg) // 2
            score = float(gain[j]) + 1e-9 * (b - a) / len(g)
            if score > best[0]:
                best = (score, ax, int(seg[j]))
        if best[1] < 0:
            return False
        self.chosen[best[1]] = sorted({*self.chosen[best[1]], best[2]})
        return True


def _slope_cells(axis_list: Sequence[Arr], v: Arr, i: int) -> Arr:
    """Per cell, the interpolation's steepest slope along input ``i``."""
    d = len(axis_list)
    form = [1] * d
    form[i] = len(axis_list[i]) - 1
    s = np.abs(np.diff(v, axis=i)) / np.diff(axis_list[i]).reshape(form)
    for j in range(d):
        if j != i:
            a = [slice(None)] * d
            b = [slice(None)] * d
            a[j], b[j] = slice(None, -1), slice(1, None)
            s = np.maximum(s[tuple(a)], s[tuple(b)])
    return s


def _boxes(table: Table, per: int) -> tuple[list[Arr], list[Arr], list[npt.NDArray[np.intp]]]:
    """Every table cell cut into ``per`` boxes along each input: centres, half-widths, cells."""
    cs, hs, ids = [], [], []
    for a in table.axes:
        w = np.diff(a) / per
        starts = (a[:-1, None] + w[:, None] * np.arange(per)[None, :]).ravel()
        cs.append(starts + np.repeat(w, per) / 2)
        hs.append(np.repeat(w, per) / 2)
        ids.append(np.repeat(np.arange(len(a) - 1), per))
    mesh = np.meshgrid(*[np.arange(len(c)) for c in cs], indexing="ij")
    pick = [m.ravel() for m in mesh]
    return (
        [c[p] for c, p in zip(cs, pick, strict=True)],
        [h[p] for h, p in zip(hs, pick, strict=True)],
        [i[p] for i, p in zip(ids, pick, strict=True)],
    )


def _box_bounds(
    table: Table,
    ev: Evaluator,
    cert: Certifier,
    steep: list[list[Arr]],
    boxes: tuple[list[Arr], list[Arr], list[npt.NDArray[np.intp]]],
) -> list[tuple[Arr, Arr]]:
    """Per output: the exact error at each box's centre and the bound over the box."""
    centre, half, cell = boxes
    f = ev.points(centre)
    approx = table.interpolate(centre)
    moves = cert.move(centre, half, f)
    out = []
    for k in range(len(table.values)):
        lmove = sum(
            (steep[k][i][tuple(cell)] * half[i] for i in range(len(centre))), np.zeros(len(centre[0]))
        )
        err = np.abs(f[k] - approx[k])
        out.append((err, err + moves[k] + lmove))
    return out


def certify(table: Table, ev: Evaluator, cert: Certifier, cap: int) -> tuple[list[float], list[float], int]:
    """The proven bound and the largest observed error of every output (engineering units),
    and the number of boxes checked: each table cell is cut into boxes, each box's bound is
    the error at its centre plus how far the engine and the interpolation can move within
    it; a box whose bound exceeds the tolerance mostly by that margin is cut in 2 along each
    input, while the number of boxes allows."""
    d = len(table.axes)
    spans = [hi - lo for lo, hi in table.out_ranges]
    steep = [[_slope_cells(table.axes, v, i) for i in range(d)] for v in table.values]
    cells = math.prod(len(a) - 1 for a in table.axes)
    per = max(1, int((cap / 8 / cells) ** (1.0 / d)))
    boxes = _boxes(table, per)
    bound, seen, count = [0.0] * len(spans), [0.0] * len(spans), 0
    while True:
        n = len(boxes[0][0])
        count += n
        results = [
            _box_bounds(table, ev, cert, steep, tuple([x[s : s + 200_000] for x in g] for g in boxes))  # type: ignore[arg-type]
            for s in range(0, n, 200_000)
        ]
        errs = [np.concatenate([r[k][0] for r in results]) for k in range(len(spans))]
        tots = [np.concatenate([r[k][1] for r in results]) for k in range(len(spans))]
        split = np.zeros(n, dtype=bool)
        for k, (err, tot) in enumerate(zip(errs, tots, strict=True)):
            split |= (tot > 0.95 * table.tolerance * spans[k]) & (tot - err > 0.1 * tot)
        more = bool(split.any()) and count + (1 << d) * int(split.sum()) <= cap
        for k, (err, tot) in enumerate(zip(errs, tots, strict=True)):
            seen[k] = max(seen[k], float(err.max()))
            bound[k] = max(bound[k], float((tot[~split] if more else tot).max(initial=0.0)))
        if not more:
            break
        centre, half, cell = ([x[split] for x in g] for g in boxes)
        new_c: list[list[Arr]] = [[] for _ in range(d)]
        for corner in itertools.product((-0.5, 0.5), repeat=d):
            for i in range(d):
                new_c[i].append(np.asarray(centre[i] + corner[i] * half[i], dtype=np.float64))
        boxes = (
            [np.concatenate(c) for c in new_c],
            [np.tile(h / 2, 1 << d) for h in half],
            [np.tile(c, 1 << d) for c in cell],
        )
    return bound, seen, count


def _rounding(table: Table, real: str) -> list[float]:
    """What the block's arithmetic adds: integer division truncates once per input (under
    one stored unit each); floating point rounds the entries, breakpoints and each step."""
    d = len(table.axes)
    if table.bits:
        return [d * sc for sc, _off in table.out_scale]
    eps = 2.0**-22 if real == "REAL" else 2.0**-51
    out = []
    for v in table.values:
        steep = sum(
            float(_slope_cells(table.axes, v, i).max()) * float(np.abs(a).max())
            for i, a in enumerate(table.axes)
        )
        out.append(eps * (d + 1) * (float(np.abs(v).max()) + steep))
    return out


def build_table(
    plan: Plan,
    *,
    tolerance: float = DEFAULT_TOLERANCE,
    max_bytes: int = DEFAULT_MAX_BYTES,
    bits: int = 0,
    real: str = "LREAL",
    model: Any = None,
) -> Table:
    """The table of ``plan`` within ``tolerance`` (fraction of each output's range) and
    ``max_bytes``; raises :class:`TableError` with the reason, or with the tolerance the
    size limit allows."""
    if not 0.0 < tolerance < 1.0:
        raise TableError(f"tolerance {tolerance}: give a fraction of the output range in (0, 1)")
    why = refusal(plan)
    if why is not None:
        raise TableError(f"no proven error bound for this block: {why} (see docs/codegen.md, lookup tables)")
    ctl = Controller(plan, model=model)
    d = len(plan.inputs)
    in_r = [input_range(plan, ctl, i) for i in range(d)]
    out_r = [output_range(plan, ctl, k, in_r) for k in range(len(plan.outputs))]
    in_scale = [((hi - lo) / QUANTA[bits], lo) for lo, hi in in_r] if bits else []
    out_scale = [((hi - lo) / QUANTA[bits], lo) for lo, hi in out_r] if bits else []

    def snap_in(i: int, x: Arr) -> Arr:
        if not bits:
            return x
        sc, off = in_scale[i]
        return np.asarray(np.unique(off + np.rint((x - off) / sc) * sc))

    def snap(k: int, v: Arr) -> Arr:
        if bits:
            sc, off = out_scale[k]
            return off + np.rint((v - off) / sc) * sc
        return v.astype(np.float32).astype(np.float64) if real == "REAL" else v

    grid = []
    for i, (lo, hi) in enumerate(in_r):
        grid.append(
            snap_in(i, np.unique(np.concatenate([np.linspace(lo, hi, _DESIGN[d]), kinks(plan, i, lo, hi)])))
        )
    ev = Evaluator(plan)
    design = _Design(grid, ev.grid(grid), [hi - lo for lo, hi in out_r], [])
    for i, g in enumerate(grid):
        wanted = snap_in(i, np.array([in_r[i][0], in_r[i][1], *kinks(plan, i, *in_r[i])]))
        design.chosen.append(sorted({int(np.argmin(np.abs(g - w))) for w in wanted}))
    per = VALUE_BYTES[bits] if bits else VALUE_BYTES[real]
    if Certifier(plan).heavy():  # LM, RM, MoM and CoA can jump: say so before refining
        _refuse_jump(plan, find_jump(ev, design, tolerance), tolerance)
    cert = Certifier(plan, cells=min(4096, max(256, int(4.0 / tolerance))))
    cap = (_SAMPLES_ENCLOSED if cert.heavy() else _SAMPLES)[d]
    target, limited = tolerance * 0.8, False
    for _round in range(6):
        while True:
            err = design.error(snap)
            shape = [len(c) for c in design.chosen]
            if float(err.max()) <= target:
                break
            if (
                per * (sum(shape) + len(out_r) * math.prod(s + (j == 0) for j, s in enumerate(shape)))
                > max_bytes
            ):
                limited = True
                break
            if not design.split(tuple(int(v) for v in np.unravel_index(int(np.argmax(err)), err.shape))):
                break
        table = Table(
            plan.name,
            tuple(i.name for i in plan.inputs),
            tuple(o.name for o in plan.outputs),
            [g[c] for g, c in zip(grid, design.chosen, strict=True)],
            design.table_values(snap),
            out_r,
            tolerance=tolerance,
            bits=bits,
            in_scale=in_scale,
            out_scale=out_scale,
        )
        bound, seen, n = certify(table, ev, cert, cap)
        extra = _rounding(table, real)
        table.bound = [b + e for b, e in zip(bound, extra, strict=True)]
        table.observed, table.samples = seen, n
        worst = max(table.relative(table.bound))
        if worst <= tolerance or limited:
            break
        target *= max(0.3, min(0.8, 0.95 * tolerance / worst))
    if math.isinf(worst) or worst > tolerance or table.size_bytes(real) > max_bytes:
        _refuse(plan, table, worst, limited, (ev, design, cert), max_bytes, real)
    return table


def _refuse(
    plan: Plan,
    table: Table,
    worst: float,
    limited: bool,
    ctx: tuple[Any, Any, Any],
    max_bytes: int,
    real: str,
) -> None:
    """Raise the reason a table within the tolerance could not be proven: no rule fires
    somewhere, the output jumps, the bound stays wide, or the size limit."""
    ev, design, cert = ctx
    tolerance = table.tolerance
    if math.isinf(worst):
        raise TableError("no rule fires somewhere in the input ranges: the output jumps to its DEFAULT there")
    jump = find_jump(ev, design, tolerance) if worst > tolerance else None
    _refuse_jump(plan, jump, tolerance)
    bound, limit = apart(100 * worst, 100 * tolerance)  # percents; distinct when they differ
    if worst > tolerance and not limited:
        raise TableError(
            f"the error bound proven for a {'x'.join(map(str, table.shape))} table is {bound}% "
            f"of the output range, above --tolerance {limit}%: raise --tolerance"
            + (
                " (for LM, RM and MoM the bound is where the maximum can lie on each box, wide"
                " where the highest degree moves its plateau)"
                if cert.heavy()
                else ""
            )
        )
    shape, size = "x".join(map(str, table.shape)), table.size_bytes(real)
    if size > max_bytes:  # the coarsest table (its axes' ends and kinks) is already too big
        raise TableError(
            f"the smallest table, {shape} in {size} bytes, is larger than --max-bytes {max_bytes} "
            f"(it is within {apart(worst, tolerance)[0]} ({bound}%) of the output range): raise --max-bytes"
        )
    if worst > tolerance:
        raise TableError(
            f"a table within {limit}% of the output range needs more than {max_bytes} bytes "
            f"(--max-bytes); {'x'.join(map(str, table.shape))} in {table.size_bytes(real)} bytes is "
            f"within {apart(worst, tolerance)[0]} ({bound}%): raise --max-bytes or --tolerance"
        )


def _refuse_jump(plan: Plan, jump: tuple[int, float, list[float]] | None, tolerance: float) -> None:
    if jump is None:
        return

    k, size, where = jump
    o = plan.outputs[k]
    at = ", ".join(f"{inp.name} = {x:.6g}" for inp, x in zip(plan.inputs, where, strict=True))
    raise TableError(
        f"no proven error bound within {100 * tolerance:.3g}% for this block: output {o.name} "
        f"({o.method}) jumps by {size:.6g} near {at}, and a table interpolates continuously "
        "(LM, RM and MoM jump where another term's maximum becomes the highest, CoA across "
        "a gap where the set is 0)"
    )


def find_jump(ev: Evaluator, design: _Design, tolerance: float) -> tuple[int, float, list[float]] | None:
    """Where an output jumps: the largest step between neighbours of the design grid, cut
    in half 40 times towards the larger step; a step still above ``tolerance`` (fraction of
    the output range) across 1e-12 of the input range is a jump.  ``(output, size, point)``."""
    for k, v in enumerate(design.values):
        for ax, g in enumerate(design.grid):
            step = np.abs(np.diff(v, axis=ax))
            at = [int(i) for i in np.unravel_index(int(np.argmax(step)), step.shape)]
            point = [float(gr[i]) for gr, i in zip(design.grid, at, strict=True)]
            a, b = float(g[at[ax]]), float(g[at[ax] + 1])

            def value(x: float, ax: int = ax, point: list[float] = point, k: int = k) -> float:
                cols = [np.array([x if j == ax else p]) for j, p in enumerate(point)]
                return float(ev.points(cols)[k][0])

            fa, fb = value(a), value(b)
            for _ in range(40):
                m = 0.5 * (a + b)
                fm = value(m)
                if abs(fm - fa) >= abs(fb - fm):
                    b, fb = m, fm
                else:
                    a, fa = m, fm
            if abs(fb - fa) > tolerance * design.spans[k]:
                point[ax] = 0.5 * (a + b)
                return k, abs(fb - fa), point
    return None


class TableController(Controller):
    """A controller that reads a lookup table (``compile(..., backend="table")``): the
    inputs are limited to their ranges, the outputs interpolated; :attr:`table` holds the
    breakpoints and the proven error bound."""

    def __init__(self, plan: Plan, table: Table, model: Any = None) -> None:
        super().__init__(plan, specialise=False, model=model)
        self.table = table

        from fuzzyctl.ir.programs.table_block import build_table_block
        from fuzzyctl.ir.render.pysrc import table_function

        d, m = len(table.inputs), len(table.outputs)
        block = build_table_block(
            "table",
            [f"FZ_IN{i}" for i in range(d)],
            [f"FZ_OUT{k}" for k in range(m)],
            [[float(x) for x in a] for a in table.axes],
            [[float(x) for x in v.ravel()] for v in table.values],
            integer=False,
            arrays=([f"FZ_BP{i}" for i in range(d)], [f"FZ_TAB{k}" for k in range(m)]),
        )
        # one evaluation runs the table's IR program printed as Python (the same program
        # the ST and C blocks print); batches interpolate with numpy
        program = table_function(block, d, m)

        def one(values: list[float], _state: list[float | None]) -> list[float]:
            return program(values)

        def many(part: list[Arr], _state: list[float | None], _m: int) -> list[Arr]:
            return table.interpolate(part)

        self._fast_fn = one
        self._batch_fn = many

    def __repr__(self) -> str:
        return f"TableController({self.name!r}, shape={self.table.shape})"
