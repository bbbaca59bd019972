"""How far a Takagi-Sugeno output, or a Mamdani output defuzzified by CoA, LM, RM or MoM,
can move within a box of inputs: the bounds :mod:`fuzzyctl.engine.table_bound` derives for
these outputs (its module docstring gives the inequalities).

Each takes, per contribution of the output (:attr:`OutputPlan.contributions`), the rule's
weighted degree at the box centres and its least and greatest value over the boxes, and
returns per box a bound of ``|F(x) - F(x')|`` (``inf`` where the bound does not hold: a box
where possibly no rule fires)."""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
import numpy.typing as npt

from fuzzyctl.engine.plan import OutputPlan, Plan, TermPlan
from fuzzyctl.engine.reference.pwl import COA_TOL, MAX_TOL
from fuzzyctl.engine.semantics.operators import TNORMS, accumulate_np
from fuzzyctl.engine.semantics.shapes import TSUKAMOTO_KINDS, membership_np
from fuzzyctl.kinds import methods
from fuzzyctl.kinds import shapes as registry

Arr = npt.NDArray[np.float64]
#: (degree at the centres, least, greatest) of one contribution, weight applied
Degrees = tuple[Arr, Arr, Arr]
#: boxes per pass of the output-cell computation (boxes x cells floats in memory)
_CHUNK = 2048


def ts_term_refusal(t: TermPlan) -> str | None:
    """Why a Takagi-Sugeno term's value has no box bound here (None: constant or linear)."""
    if not t.constant:
        return "a parameter given by a variable"
    if t.kind in TSUKAMOTO_KINDS:
        return "a Tsukamoto term (its value depends on the rule's degree)"
    if t.kind == "singleton" or registry.flag(t.kind, "ts_constant") or registry.flag(t.kind, "ts_linear"):
        return None
    return f"a {t.kind} term"


def _ts_value(t: TermPlan, centre: Sequence[Arr], half: Sequence[Arr]) -> tuple[Arr, Arr]:
    """A constant or linear term's value at the centres and its largest move on the boxes
    (the reference's ``ts_value``: coefficients of every input in order, then the constant)."""
    cs = [float(p) for p in t.params]  # type: ignore[arg-type]
    n = len(centre)
    if t.kind == "singleton" or not registry.flag(t.kind, "ts_linear"):
        return np.full(len(centre[0]), cs[0]), np.zeros(len(centre[0]))
    z = np.full(len(centre[0]), cs[n] if len(cs) > n else 0.0)
    dz = np.zeros(len(centre[0]))
    for c, x, h in zip(cs[:n], centre, half, strict=False):
        z = z + c * x
        dz = dz + abs(c) * h
    return z, dz


def ts_move(
    o: OutputPlan, contribs: Sequence[tuple[int, Degrees]], centre: Sequence[Arr], half: Sequence[Arr]
) -> Arr:
    """The move bound of a Takagi-Sugeno output (WTAVER or WTSUM).  ``contribs``: per
    contribution its term and its weighted degrees.  Accumulated per term unless ``accu`` is
    None (every rule with its own weight, the Sugeno definition); every accumulation admitted
    is monotone in each operand, so the least and greatest accumulate alike."""
    n = len(centre[0])
    items: list[tuple[int, Degrees]] = []
    if o.accu is None:
        items = list(contribs)
    else:
        acc: dict[int, Degrees] = {}
        for term, (m, lo, hi) in contribs:
            if term in acc:
                pm, plo, phi = acc[term]
                m, lo, hi = (
                    accumulate_np(o.accu, pm, m),
                    accumulate_np(o.accu, plo, lo),
                    accumulate_np(o.accu, phi, hi),
                )
            acc[term] = (m, lo, hi)
        items = sorted(acc.items(), key=lambda kv: kv[0])
    values = {t: _ts_value(o.terms[t], centre, half) for t in {t for t, _ in items}}
    average = methods.method(o.method).weighted == "average"
    d_mid, d_low = np.zeros(n), np.zeros(n)
    num = np.zeros(n)
    for t, (m, lo, _hi) in items:
        d_mid, d_low, num = d_mid + m, d_low + lo, num + m * values[t][0]
    with np.errstate(divide="ignore", invalid="ignore"):
        f = num / d_mid if average else num  # the output at the centres, before any clamp
        move = np.zeros(n)
        for t, (m, lo, hi) in items:
            z, dz = values[t]
            dw = np.maximum(hi - m, m - lo)
            reach = np.abs(z - f) + dz if average else np.abs(z) + dz
            move = move + dw * reach + m * dz
        if average:
            return np.where(d_low > 0.0, move / d_low, np.inf)
    default = o.default if o.default is not None else 0.0
    # WTSUM is 0 where no rule fires: no jump unless the DEFAULT differs
    return move if default == 0.0 else np.where(d_low > 0.0, move, np.inf)


@dataclass
class OutputCells:
    """The output range cut into cells (every term breakpoint plus ``count`` equal steps),
    and each term's least and greatest degree on each closed cell (exact for piecewise
    linear terms: their extremes on a cell lie at its ends or at a breakpoint inside)."""

    xs: Arr
    low: Arr  # terms x cells
    high: Arr

    @classmethod
    def of(cls, o: OutputPlan, count: int) -> OutputCells:
        assert o.low is not None and o.high is not None
        cuts = [x for t in o.terms for x, _ in (t.pwl or ()) if o.low < x < o.high]
        xs = np.unique(np.concatenate([np.linspace(o.low, o.high, count + 1), cuts]))
        a, b = xs[:-1], xs[1:]
        lows, highs = [], []
        for t in o.terms:
            ya = membership_np(t.kind, t.params, t.height, a)
            yb = membership_np(t.kind, t.params, t.height, b)
            lo, hi = np.minimum(ya, yb), np.maximum(ya, yb)
            for xb, yv in t.pwl or ():
                inside = (a <= xb) & (xb <= b)  # both values of a vertical edge
                lo = np.where(inside, np.minimum(lo, yv), lo)
                hi = np.where(inside, np.maximum(hi, yv), hi)
            lows.append(lo)
            highs.append(hi)
        return cls(xs, np.array(lows), np.array(highs))


def _set_bounds(
    plan: Plan, o: OutputPlan, cells: OutputCells, contribs: Sequence[tuple[int, str, float, Degrees]]
) -> tuple[Arr, Arr]:
    """The accumulated set's least and greatest value on every cell, per box (boxes x
    cells): activation and accumulation are monotone in each operand."""
    before = plan.options.weight_before_activation
    accu = o.accu or "MAX"
    low = high = None
    for term, act, w, (_m, lo, hi) in contribs:
        norm = TNORMS[act].array
        if before:
            c_lo = norm((w * lo)[:, None], cells.low[term][None, :])
            c_hi = norm((w * hi)[:, None], cells.high[term][None, :])
        else:
            c_lo = w * norm(lo[:, None], cells.low[term][None, :])
            c_hi = w * norm(hi[:, None], cells.high[term][None, :])
        low = c_lo if low is None else accumulate_np(accu, low, c_lo)
        high = c_hi if high is None else accumulate_np(accu, high, c_hi)
    assert low is not None and high is not None
    return low, high


def _value_range(o: OutputPlan, xs: Arr, low: Arr, high: Arr) -> tuple[Arr, Arr, npt.NDArray[np.bool_]]:
    """Per box, an interval holding the defuzzified value, and whether it is valid (the set
    surely has a maximum above 0, or an area)."""
    entry = methods.method(o.method)
    if entry.maximum is not None:
        # every maximising point t has mu(t) >= sup * (1 - MAX_TOL) >= max(low) * (1 - MAX_TOL)
        thr = low.max(axis=1) * (1.0 - MAX_TOL)
        hit = high >= thr[:, None]
        first = np.argmax(hit, axis=1)
        last = hit.shape[1] - 1 - np.argmax(hit[:, ::-1], axis=1)
        return xs[first], xs[last + 1], thr > 0.0
    # CoA: the bisector's two ends each have at least half the area minus the tolerance on
    # either side, so both lie where the greatest set's area from each end reaches that
    width = np.diff(xs)
    d_low, d_high = low @ width, high @ width
    need = 0.5 * d_low - COA_TOL * d_high
    from_left = np.cumsum(high * width, axis=1)
    from_right = np.cumsum((high * width)[:, ::-1], axis=1)[:, ::-1]
    first = np.argmax(from_left >= need[:, None], axis=1)
    ok_right = from_right >= need[:, None]
    last = ok_right.shape[1] - 1 - np.argmax(ok_right[:, ::-1], axis=1)
    return xs[first], xs[last + 1], d_low > 0.0


def enclosure_move(
    plan: Plan, o: OutputPlan, cells: OutputCells, contribs: Sequence[tuple[int, str, float, Degrees]], f: Arr
) -> Arr:
    """The move bound of a CoA, LM, RM or MoM output: how far the value range on each box
    reaches from ``f`` (the output at the centres).  ``contribs``: per contribution its term,
    activation, weight and rule degrees (unweighted)."""
    n = len(f)
    out = np.empty(n)
    for s in range(0, n, _CHUNK):
        part = [
            (t, a, w, (m[s : s + _CHUNK], lo[s : s + _CHUNK], hi[s : s + _CHUNK]))
            for t, a, w, (m, lo, hi) in contribs
        ]
        low, high = _set_bounds(plan, o, cells, part)
        vlo, vhi, ok = _value_range(o, cells.xs, low, high)
        fs = f[s : s + _CHUNK]
        move = np.maximum(np.maximum(vhi - fs, fs - vlo), 0.0)
        out[s : s + _CHUNK] = np.where(ok, move, np.inf)
    return out
