"""The cell decomposition of the input space and the rule degrees on it.

Each input axis is cut at every breakpoint of the terms its rules read, at the ends of their
supports and at every point where a condition leaf (term, hedges and NOT applied) crosses one
of the levels the analysis asks about (``epsilon`` divided by the rule's weights, and one
minus it).  Piecewise-linear leaves cross by linear interpolation between breakpoints (exact);
hedged or smooth leaves by :func:`scipy.optimize.brentq` in brackets found on a sampling of
the axis (``SAMPLES`` points plus the term's characteristic points; ``xtol`` ``XTOL`` times
the axis width).  The cells of an axis are its cut points and the open intervals between
them; the cells of the space are their products.  Inside one cell every leaf is on one side
of every level, so under MIN/MAX (and, for "degree > 0", under every t-norm without zero
divisors) each rule's "degree >= level" is constant on the cell: one representative point
(the cut point, or the middle of the interval) decides it for the whole cell."""

from __future__ import annotations

from collections.abc import Iterator
from dataclasses import dataclass, field

import numpy as np

from fuzzyctl.analysis.context import Context, FloatArray, constant, leaf_axis, leaf_values, term_points
from fuzzyctl.diagnostics import FuzzyctlError
from fuzzyctl.engine.plan import (
    CAnd,
    CChained,
    CDegree,
    CNot,
    CondPlan,
    COr,
    CTerm,
    CTrue,
    Plan,
    Slot,
)
from fuzzyctl.engine.semantics import shapes
from fuzzyctl.engine.semantics.operators import SNORMS, TNORMS, accumulate_np

SAMPLES = 2049
#: refuse a decomposition larger than this many cells (8 bytes each, several arrays)
MAX_CELLS = 20_000_000
#: smooth terms' characteristic points are added as cuts while the cells stay below this
OPTIONAL_CELLS = 2_000_000
XTOL = 1e-12
#: t-norms with T(a, b) > 0 whenever a, b > 0: "degree > 0" is decided cell by cell
NO_ZERO_DIVISORS = frozenset({"MIN", "PROD", "HAMACHER", "EINSTEIN"})


@dataclass
class Axis:
    """One input's cells: ``cuts`` sorted; cell ``2k`` is ``cuts[k]``, cell ``2k+1`` the open
    interval ``(cuts[k], cuts[k+1])``.  An input no condition reads has one cell: its range."""

    name: str
    low: float
    high: float
    cuts: FloatArray
    read: bool = True

    @property
    def reps(self) -> FloatArray:
        if not self.read:
            return np.array([0.5 * (self.low + self.high)])
        c = self.cuts
        out = np.empty(2 * len(c) - 1)
        out[0::2] = c
        out[1::2] = 0.5 * (c[:-1] + c[1:])
        return out

    @property
    def widths(self) -> FloatArray:
        if not self.read:
            return np.array([self.high - self.low])
        out = np.zeros(2 * len(self.cuts) - 1)
        out[1::2] = np.diff(self.cuts)
        return out

    def bounds(self, first: int, last: int) -> tuple[float, float]:
        """The closure of cells ``first..last``."""
        if not self.read:
            return (self.low, self.high)
        return (float(self.cuts[first // 2]), float(self.cuts[(last + 1) // 2]))


@dataclass
class Grid:
    """The rule degrees on the cells' representatives."""

    axes: list[Axis]
    best: dict[int, FloatArray]  # per output index: the highest degree a rule reaches it with
    rule_max: FloatArray  # per rule: its highest degree anywhere
    exact: bool
    notes: list[str] = field(default_factory=list)


def _nodes(c: CondPlan) -> Iterator[CondPlan]:
    """Every node of a condition, without recursion (conditions may nest deeply)."""
    stack = [c]
    while stack:
        node = stack.pop()
        yield node
        if isinstance(node, CNot):
            stack.append(node.operand)
        elif isinstance(node, CAnd | COr):
            stack.extend(node.operands)


def leaves(c: CondPlan) -> Iterator[CondPlan]:
    return (node for node in _nodes(c) if not isinstance(node, CNot | CAnd | COr))


def _ops(c: CondPlan) -> Iterator[str]:
    return (node.op for node in _nodes(c) if isinstance(node, CAnd | COr))


def levels(ctx: Context, epsilon: float) -> list[float]:
    """The degrees a leaf is compared with: epsilon over each rule's constant weights, the
    firing threshold, and one minus each (a NOT turns ``>= c`` into ``<= 1 - c``)."""
    plan = ctx.plan
    out = {plan.options.firing_threshold} if plan.options.firing_threshold > 0 else set()
    if epsilon > 0:
        for r in plan.rules:
            w = constant(r.weight)
            for cp in r.conclusions:
                wc = constant(cp.weight)
                if w and wc:
                    out.add(epsilon / (w * wc))
    out |= {1.0 - c for c in out}
    return sorted(c for c in out if 0.0 < c <= 1.0)


def _crossings(g: FloatArray, xs: FloatArray, level: float, f: object, linear: bool) -> list[float]:
    from scipy.optimize import brentq

    found = list(xs[g == level])
    d = g - level
    idx = np.nonzero(d[:-1] * d[1:] < 0)[0]
    tol = XTOL * max(1.0, float(xs[-1] - xs[0]))
    for i in idx:
        a, b = float(xs[i]), float(xs[i + 1])
        if linear:
            found.append(a + (b - a) * float(d[i] / (d[i] - d[i + 1])))
        else:
            found.append(float(brentq(lambda x: float(f(np.array([x]))[0]) - level, a, b, xtol=tol)))  # type: ignore[operator]
    return found


def _axis_cuts(
    plan: Plan, slot: int, low: float, high: float, axis_leaves: list[CondPlan], lv: list[float]
) -> tuple[FloatArray, FloatArray]:
    """The cuts the gap sets need, and the optional ones (smooth terms' characteristic
    points: they only sharpen the coverage index and the dead-rule check's resolution)."""
    cuts = [low, high]
    optional: list[float] = []
    for leaf in axis_leaves:
        assert isinstance(leaf, CTerm | CDegree)
        knots: list[float] = [low, high]
        linear = isinstance(leaf, CDegree)
        if isinstance(leaf, CTerm) and "any" not in leaf.hedges:
            t = plan.fuzzy_inputs[leaf.var].terms[leaf.term]
            pts = term_points(t)
            knots += pts
            (cuts if t.pwl is not None else optional).extend(pts)
            linear = t.pwl is not None and not leaf.hedges
            if t.pwl is None and t.constant:
                cuts += [s for s in shapes.support(t.kind, [float(p) for p in t.params], float(t.height))]  # type: ignore[arg-type]
        xs = np.unique(np.clip(np.array(knots, dtype=np.float64), low, high))
        if not linear:
            xs = np.unique(np.concatenate([xs, np.linspace(low, high, SAMPLES)]))

        def f(x: FloatArray, leaf: CondPlan = leaf) -> FloatArray:
            return leaf_values(plan, leaf, x)  # type: ignore[arg-type]

        g = f(xs)
        for level in lv:
            cuts += _crossings(g, xs, level, f, linear)
    arr = np.unique(np.array([c for c in cuts if np.isfinite(c)], dtype=np.float64))
    opt = np.unique(np.array([c for c in optional if np.isfinite(c)], dtype=np.float64))
    return arr[(arr >= low) & (arr <= high)], opt[(opt > low) & (opt < high)]


def build_axes(ctx: Context, epsilon: float) -> tuple[list[Axis], bool]:
    """The axes, and whether the optional cuts had to be left out."""
    plan = ctx.plan
    by_slot: dict[int, dict[CondPlan, None]] = {}
    for r in plan.rules:
        for leaf in leaves(r.condition):
            slot = leaf_axis(plan, leaf)
            if slot is not None:
                by_slot.setdefault(slot, {})[leaf] = None
    lv = levels(ctx, epsilon)
    axes = []
    extra = []
    for slot, name in enumerate(ctx.inputs):
        low, high = ctx.ranges[slot]
        if slot in by_slot:
            cuts, opt = _axis_cuts(plan, slot, low, high, list(by_slot[slot]), lv)
            axes.append(Axis(name, low, high, cuts))
            extra.append(opt)
        else:
            axes.append(Axis(name, low, high, np.array([low, high]), read=False))
            extra.append(np.zeros(0))
    with_extra = [np.union1d(a.cuts, e) if a.read else a.cuts for a, e in zip(axes, extra, strict=True)]
    if np.prod([2.0 * len(c) - 1 for c in with_extra]) > OPTIONAL_CELLS:
        return axes, any(len(e) for e in extra)
    for a, c in zip(axes, with_extra, strict=True):
        a.cuts = c
    return axes, False


def exactness(ctx: Context, epsilon: float) -> list[str]:
    """Why the cell representatives might not decide a cell (empty: they do, exactly)."""
    plan = ctx.plan
    notes = []
    ops = {op for r in plan.rules for op in _ops(r.condition)}
    plain = NO_ZERO_DIVISORS | set(SNORMS) if epsilon == 0 else frozenset({"MIN", "MAX"})
    if ops - plain:
        notes.append(
            f"operators {', '.join(sorted(ops - plain))}: degrees are compared at one point per cell"
        )
    if plan.chained:
        notes.append("chained variables: their degrees are compared at one point per cell")
    if plan.selections:
        notes.append("rule activation methods (First/Highest/...) are not applied: every rule counts")
    if epsilon > 0 and any(cp.hedges for r in plan.rules for cp in r.conclusions):
        notes.append("hedged conclusions: degrees are compared at one point per cell")
    if any(
        isinstance(r.weight, Slot) or any(isinstance(cp.weight, Slot) for cp in r.conclusions)
        for r in plan.rules
    ):
        notes.append("weights given by inputs: degrees are compared at one point per cell")
    return notes


class _Evaluator:
    """Rule degrees over the broadcast grid of representatives, in the engine's order.  A
    rule is evaluated only on the sub-box where each leaf of its AND is nonzero (every t-norm
    is 0 when one operand is): a rule of a 7-term grid reads 3 of 25 cells per axis."""

    def __init__(self, ctx: Context, axes: list[Axis]) -> None:
        self.plan = ctx.plan
        self.n = len(axes)
        self.shape = tuple(len(a.reps) for a in axes)
        self.reps = [a.reps for a in axes]
        self.cache: dict[CondPlan, FloatArray] = {}
        self.chained: list[list[FloatArray | None]] = [[None] * len(c.terms) for c in self.plan.chained]
        self.bare: list[FloatArray | None] = [None] * len(self.plan.chained)
        self.full = tuple(slice(0, k) for k in self.shape)

    def _shaped(self, v: FloatArray, axis: int, sl: tuple[slice, ...]) -> FloatArray:
        shape = [1] * self.n
        shape[axis] = -1
        return v[sl[axis]].reshape(shape)

    def leaf(self, c: CTerm | CDegree) -> FloatArray:
        got = self.cache.get(c)
        if got is None:
            slot = leaf_axis(self.plan, c)
            assert slot is not None
            got = leaf_values(self.plan, c, self.reps[slot])
            self.cache[c] = got
        return got

    def value(self, p: float | Slot, sl: tuple[slice, ...]) -> FloatArray:
        return self._shaped(self.reps[p.index], p.index, sl) if isinstance(p, Slot) else np.asarray(float(p))

    def _stored(self, v: FloatArray | None, sl: tuple[slice, ...]) -> FloatArray:
        return np.zeros(()) if v is None else v[sl]

    def cond(self, c: CondPlan, sl: tuple[slice, ...]) -> FloatArray:
        if isinstance(c, CTerm) or (isinstance(c, CDegree) and c.slot is not None):
            slot = leaf_axis(self.plan, c)
            assert slot is not None
            return self._shaped(self.leaf(c), slot, sl)
        if isinstance(c, CDegree):
            assert c.chained is not None
            return self._stored(self.bare[c.chained], sl)
        if isinstance(c, CChained):
            d = self._stored(self.chained[c.var][c.term], sl) if "any" not in c.hedges else np.ones(())
            for h in reversed(c.hedges):
                d = shapes.hedge_np(h, d)
            return 1.0 - d if c.negated else d
        if isinstance(c, CNot):
            return 1.0 - self.cond(c.operand, sl)
        if isinstance(c, CAnd | COr):
            norm = (TNORMS if isinstance(c, CAnd) else SNORMS)[c.op].array
            v = self.cond(c.operands[0], sl)
            for o in c.operands[1:]:
                v = norm(v, self.cond(o, sl))
            return np.asarray(v)
        assert isinstance(c, CTrue)
        return np.ones(())

    def region(self, c: CondPlan) -> tuple[slice, ...] | None:
        """The cells outside which a rule is 0 (None: nowhere nonzero)."""
        items = list(c.operands) if isinstance(c, CAnd) else [c]
        sl = list(self.full)
        for leaf in items:
            if isinstance(leaf, CTerm) or (isinstance(leaf, CDegree) and leaf.slot is not None):
                slot = leaf_axis(self.plan, leaf)
                assert slot is not None
                nz = np.nonzero(self.leaf(leaf) > 0.0)[0]
                if not len(nz):
                    return None
                a, b = max(sl[slot].start, int(nz[0])), min(sl[slot].stop, int(nz[-1]) + 1)
                if a >= b:
                    return None
                sl[slot] = slice(a, b)
        return tuple(sl)

    def rule(self, ri: int, sl: tuple[slice, ...]) -> FloatArray:
        r = self.plan.rules[ri]
        a = self.cond(r.condition, sl)
        if not (isinstance(r.weight, float | int) and r.weight == 1.0):
            a = a * self.value(r.weight, sl)
        th = self.plan.options.firing_threshold
        return np.where(a <= th, 0.0, a)

    def accumulate(
        self, store: list[FloatArray | None], k: int, accu: str, contrib: FloatArray, sl: tuple[slice, ...]
    ) -> None:
        if store[k] is None:
            store[k] = np.zeros(self.shape)
        arr = store[k]
        assert arr is not None
        arr[sl] = accumulate_np(accu, arr[sl], contrib)


def evaluate(ctx: Context, axes: list[Axis], epsilon: float) -> Grid:
    """Every rule's degree at every cell's representative; per output the best one."""
    plan = ctx.plan
    cells = int(np.prod([len(a.reps) for a in axes], dtype=np.float64))
    if cells > MAX_CELLS:
        sizes = " x ".join(f"{a.name} {len(a.reps)}" for a in axes)
        raise FuzzyctlError(
            f"analyze: the input space splits into {cells:,} cells ({sizes}), more than {MAX_CELLS:,}; "
            "analyse a block with fewer inputs or fewer distinct term breakpoints"
        )
    ev = _Evaluator(ctx, axes)
    best = {o: np.zeros(ev.shape) for o in range(len(plan.outputs))}
    rule_max = np.zeros(len(plan.rules))
    for ri in plan.order:
        r = plan.rules[ri]
        sl = ev.region(r.condition)
        if sl is None:
            continue
        a = ev.rule(ri, sl)
        rule_max[ri] = float(np.max(a))
        for cp in r.conclusions:
            ah = a
            for h in reversed(cp.hedges):
                ah = shapes.hedge_np(h, ah)
            contrib = ev.value(cp.weight, sl) * ah
            for o in cp.outputs:
                view = best[o][sl]
                np.maximum(view, contrib, out=view)
            for ch in cp.chained:
                accu = plan.chained[ch].accu
                if cp.term is None:
                    ev.accumulate(ev.bare, ch, accu, contrib, sl)
                else:
                    ev.accumulate(ev.chained[ch], cp.term, accu, contrib, sl)
    notes = exactness(ctx, epsilon)
    return Grid(axes, best, rule_max, not notes, notes)


class _RowEvaluator(_Evaluator):
    """The same evaluation on scattered points (rows of a log) instead of a grid: every
    array is one value per row, so leaves and norms combine elementwise."""

    def __init__(self, ctx: Context, columns: list[FloatArray]) -> None:
        m = len(columns[0]) if columns else 0
        super().__init__(ctx, [])
        self.n = 1
        self.shape = (m,)
        self.reps = columns
        self.chained = [[None] * len(c.terms) for c in self.plan.chained]
        self.full = (slice(0, m),)

    def _shaped(self, v: FloatArray, axis: int, sl: tuple[slice, ...]) -> FloatArray:
        return v

    def region(self, c: CondPlan) -> tuple[slice, ...] | None:
        return self.full


def row_degrees(ctx: Context, columns: list[FloatArray]) -> tuple[FloatArray, dict[int, FloatArray]]:
    """Each rule's degree (weight applied, 0 at or below the firing threshold) at each row,
    shape (rules, rows), and per output the best contribution; ``columns`` holds one array per
    input slot.  Same leaves, norms and chaining as :func:`evaluate`."""
    plan = ctx.plan
    ev = _RowEvaluator(ctx, columns)
    m = ev.shape[0]
    degrees = np.zeros((len(plan.rules), m))
    best = {o: np.zeros(m) for o in range(len(plan.outputs))}
    for ri in plan.order:
        r = plan.rules[ri]
        a = np.broadcast_to(ev.rule(ri, ev.full), (m,))
        degrees[ri] = a
        for cp in r.conclusions:
            ah = a
            for h in reversed(cp.hedges):
                ah = shapes.hedge_np(h, ah)
            contrib = np.broadcast_to(ev.value(cp.weight, ev.full) * ah, (m,))
            for o in cp.outputs:
                np.maximum(best[o], contrib, out=best[o])
            for ch in cp.chained:
                accu = plan.chained[ch].accu
                store = ev.bare if cp.term is None else ev.chained[ch]
                ev.accumulate(store, ch if cp.term is None else cp.term, accu, contrib, ev.full)
    return degrees, best
