"""Monotonicity: a declared sign of an output in an input, checked on the rule table and on
the output surface.

Rule table (exact): the terms of each input and of the output are ordered by their centre
(the middle of the set where the term is highest; a singleton's position).  Among the
conjunctive rules of the output with plain leaves (no hedge, no NOT), two rules that read
the same terms of every other input and terms ``i < j`` of the declared input must conclude
terms ordered the declared way; each pair that does not is reported.

Proof: when the table condition holds and the output is a weighted average of singletons
(COGS, or Takagi-Sugeno constants under WTAVER), the rules form a complete grid (one rule
per combination of the inputs' terms), AND is PROD, and the terms of each input form a
partition (degrees summing to 1 over the range) whose upper sums ``S_k = sum_{i >= k} mu_i``
are non-decreasing, the output is ``C_0 + sum_k (C_k - C_{k-1}) S_k(x)`` along the input with
``C_k`` non-decreasing: monotone (the multilinear-interpolation argument behind Won et al.,
Fuzzy Sets and Systems 2002, on monotone Takagi-Sugeno-Kang systems).  No such statement is
made for Mamdani outputs under COG: van Broekhoven and De Baets (Fuzzy Sets and Systems
2009) show that a monotone rule table does not make a COG model monotone in general."""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from fuzzyctl.analysis.context import Context, FloatArray, term_values
from fuzzyctl.analysis.table import Row
from fuzzyctl.diagnostics import FuzzyctlError
from fuzzyctl.engine.plan import CTerm, TermPlan
from fuzzyctl.kinds import norms
from fuzzyctl.kinds import shapes as registry
from fuzzyctl.kinds.methods import METHODS


@dataclass(frozen=True)
class Declaration:
    output: str
    input: str
    sign: str  # "+" or "-"


@dataclass
class Monotonicity:
    output: str
    input: str
    declared: str
    rule_table: str  # "holds" | "violated"
    offending: list[tuple[str, str]] = field(default_factory=list)  # (lower rule, higher rule)
    counterexamples: list[tuple[dict[str, float], dict[str, float]]] = field(default_factory=list)
    proven: bool = False
    resolution: int = 0  # grid points per input searched on the surface


def parse_declarations(specs: list[str], inputs: tuple[str, ...], outputs: list[str]) -> list[Declaration]:
    """``"valve:-temp,+pressure"`` -> declarations (errors name the parameter)."""
    out = []
    for spec in specs:
        name, sep, rest = spec.partition(":")
        if not sep or name not in outputs:
            raise FuzzyctlError(
                f"--monotone {spec!r}: expected OUTPUT:+input,-input with OUTPUT one of {', '.join(outputs)}"
            )
        for item in rest.split(","):
            item = item.strip()
            if len(item) < 2 or item[0] not in "+-" or item[1:] not in inputs:
                raise FuzzyctlError(
                    f"--monotone {spec!r}: {item!r} is not +INPUT or -INPUT (inputs: {', '.join(inputs)})"
                )
            out.append(Declaration(name, item[1:], item[0]))
    return out


def centre(t: TermPlan, low: float, high: float) -> float:
    """The middle of where a term is highest on [low, high] (a singleton: its position)."""
    if t.kind == "singleton" or registry.flag(t.kind, "ts_constant"):
        return float(t.params[0])  # type: ignore[arg-type]
    xs = np.linspace(low, high, 4097)
    if t.pwl is not None:
        xs = np.unique(np.concatenate([xs, np.clip([x for x, _ in t.pwl], low, high)]))
    v = term_values(t, xs)
    top = xs[v >= v.max() - 1e-12]
    return 0.5 * float(top[0] + top[-1])


def rule_table(
    ctx: Context, rows: list[Row], d: Declaration
) -> tuple[list[tuple[str, str]], list[tuple[Row, int]]]:
    plan = ctx.plan
    o = next(k for k, op in enumerate(plan.outputs) if op.name == d.output)
    op = plan.outputs[o]
    lo, hi = (op.low, op.high) if op.low is not None and op.high is not None else (-1e300, 1e300)
    out_c = [
        centre(t, lo, hi)
        if t.constant and not (t.kind == "function" or registry.flag(t.kind, "ts_linear"))
        else np.nan
        for t in op.terms
    ]
    slot = ctx.inputs.index(d.input)
    groups: dict[tuple[object, ...], list[tuple[float, float, Row]]] = {}
    used: list[tuple[Row, int]] = []
    for row in rows:
        term = next((cp.term for cp in plan.rules[row.rule].conclusions if o in cp.outputs), None)
        if term is None or any(
            not isinstance(x, CTerm) or x.hedges or x.negated for x in row.leaves.values()
        ):
            continue
        used.append((row, term))
        leaf = row.leaves.get(slot)
        if leaf is None:
            continue
        assert isinstance(leaf, CTerm)
        t = plan.fuzzy_inputs[leaf.var].terms[leaf.term]
        key = tuple(sorted(((s, lf) for s, lf in row.leaves.items() if s != slot), key=lambda p: p[0]))
        groups.setdefault(key, []).append((centre(t, *ctx.ranges[slot]), out_c[term], row))
    bad = []
    sign = 1.0 if d.sign == "+" else -1.0
    for items in groups.values():
        for xa, ya, ra in items:
            for xb, yb, rb in items:
                if xa < xb and sign * (yb - ya) < 0:
                    bad.append((ctx.rule_names[ra.rule], ctx.rule_names[rb.rule]))
    return bad, used


def _partition_ok(ctx: Context, var: int, terms: list[int]) -> bool:
    fi = ctx.plan.fuzzy_inputs[var]
    lo, hi = ctx.ranges[fi.slot]
    ts = [fi.terms[k] for k in terms]
    if any(t.pwl is None for t in ts):
        return False
    xs = np.unique(
        np.concatenate([np.linspace(lo, hi, 1025), np.clip([x for t in ts for x, _ in t.pwl or ()], lo, hi)])
    )
    ts.sort(key=lambda t: centre(t, lo, hi))
    vals: FloatArray = np.array([term_values(t, xs) for t in ts])
    if np.abs(vals.sum(axis=0) - 1.0).max() > 1e-9:
        return False
    upper = np.cumsum(vals[::-1], axis=0)[::-1]
    return bool((np.diff(upper, axis=1) >= -1e-12).all())


def proven(ctx: Context, used: list[tuple[Row, int]], d: Declaration) -> bool:
    """The sufficient condition of the module docstring."""
    plan = ctx.plan
    op = next(op for op in plan.outputs if op.name == d.output)
    if op.kind == "singleton" and METHODS[op.method].weighted is None:
        return False
    if op.kind == "ts" and (
        METHODS[op.method].weighted != "average"
        or any(not (t.kind == "singleton" or registry.flag(t.kind, "ts_constant")) for t in op.terms)
    ):
        return False
    if op.kind not in ("singleton", "ts") or not used:
        return False
    slots = set(used[0][0].leaves)
    if any(
        set(r.leaves) != slots or r.weight != 1.0 or (len(slots) > 1 and not norms.is_prod(r.op))
        for r, _ in used
    ):
        return False
    if len(used) != sum(
        1
        for r in plan.rules
        for cp in r.conclusions
        if any(plan.outputs[o].name == d.output for o in cp.outputs)
    ):
        return False
    combos = {
        tuple(sorted((s, (lf.var, lf.term)) for s, lf in r.leaves.items() if isinstance(lf, CTerm)))
        for r, _ in used
    }
    per_slot: dict[int, set[int]] = {}
    for combo in combos:
        for s, (_v, t) in combo:
            per_slot.setdefault(s, set()).add(t)
    if len(combos) != len(used) or len(combos) != int(np.prod([len(v) for v in per_slot.values()])):
        return False
    var_of = {fi.slot: v for v, fi in enumerate(plan.fuzzy_inputs)}
    return all(_partition_ok(ctx, var_of[s], sorted(ts)) for s, ts in per_slot.items())
