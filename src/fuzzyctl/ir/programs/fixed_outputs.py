"""The outputs of the integer block (:mod:`fuzzyctl.ir.programs.fixed_block`): singleton
COGS and Takagi-Sugeno WTAVER / WTSUM as integer weighted sums, and each output's
worst-case error bound.

A weighted average ``sum g_i z_i / sum g_i`` computed from weights ``g'_i`` (each within
``e_i`` of the exact ``g_i``) and values ``z'_i`` (within ``ez``) differs from the exact one by
at most ``ez + sum e_i * spread / (L - sum e_i)`` before its final rounding, where ``spread``
bounds ``|z_i - average|`` and ``L`` is a lower bound of the exact ``sum g_i`` over every input
(:func:`fuzzyctl.ir.builders.fixed_bound.weight_bounds`).  Where no such ``L > sum e_i``
exists (some input fires no rule, and near it the average has no bounded error) the output
is refused with an input where it happens."""

from __future__ import annotations

import math
from fractions import Fraction
from typing import TYPE_CHECKING

from fuzzyctl.engine.plan import OutputPlan, Plan, PParam, Slot
from fuzzyctl.escape import CodegenError
from fuzzyctl.ir.builders import fixed_arith as fa
from fuzzyctl.ir.builders.fixed_arith import FX
from fuzzyctl.ir.builders.fixed_bound import Group, WeightBounds, weight_bounds
from fuzzyctl.ir.nodes import Int, Var
from fuzzyctl.kinds import norms
from fuzzyctl.kinds import shapes as registry
from fuzzyctl.kinds.methods import METHODS

if TYPE_CHECKING:
    from fuzzyctl.ir.programs.fixed_block import FixedBlock, Port

__all__ = ["emit_outputs"]


def _groups(op: OutputPlan) -> tuple[list[Group], list[int]]:
    """The denominator's items (accumulation, (rule, weight) pairs) and each item's term."""
    if op.kind == "ts" and op.accu is None:
        items: list[Group] = []
        terms: list[int] = []
        for c in op.contributions:
            if c.term is not None:
                items.append(("SUM", ((c.rule, constant(c.weight)),)))
                terms.append(c.term)
        return items, terms
    accu = op.accu or "MAX"
    terms = sorted({c.term for c in op.contributions if c.term is not None})
    groups: list[Group] = [
        (accu, tuple((c.rule, constant(c.weight)) for c in op.contributions if c.term == t)) for t in terms
    ]
    return groups, terms


def constant(p: PParam) -> float:
    """A parameter the checks found constant."""
    assert not isinstance(p, Slot)
    return float(p)


def _z_interval(blk: FixedBlock, op: OutputPlan, t: int) -> tuple[Fraction, Fraction]:
    """The exact values of term ``t`` over the input domain."""
    term = op.terms[t]
    if not registry.flag(term.kind, "ts_linear"):
        v = Fraction(constant(term.params[0]))
        return v, v
    n = len(blk.plan.inputs)
    cs = [Fraction(constant(c)) for c in term.params]
    lo = hi = cs[n] if len(cs) > n else Fraction(0)
    for i, c in enumerate(cs[:n]):
        if c == 0:
            continue
        p = blk.inputs[i]
        a, b = p.low * p.scale + p.offset, p.high * p.scale + p.offset
        lo, hi = lo + min(c * a, c * b), hi + max(c * a, c * b)
    return lo, hi


def _z_fx(blk: FixedBlock, op: OutputPlan, t: int, scale: Fraction, offset: Fraction) -> FX:
    """Term ``t``'s value in the output's stored units."""
    w, term = blk.w, op.terms[t]
    if not registry.flag(term.kind, "ts_linear"):
        return fa.const(w, Fraction(constant(term.params[0])) - offset, scale, what=f"term {term.name!r}")
    n = len(blk.plan.inputs)
    cs = [Fraction(constant(c)) for c in term.params]
    base = (cs[n] if len(cs) > n else Fraction(0)) - offset
    used = [(i, c) for i, c in enumerate(cs[:n]) if c != 0]
    for i, c in used:
        base += c * blk.inputs[i].offset
    for q in range(2 * blk.arith.bits, -1, -1):
        fine = scale / (1 << q)
        try:
            total = fa.const(w, base, fine, True)
            for i, c in used:
                total = fa.add(
                    w, total, fa.mul(w, blk.x[i], fa.const(w, c * blk.inputs[i].scale, fine, True))
                )
            return fa.narrow(w, fa.rdiv(w, total, 1 << q), f"term {term.name!r}")
        except CodegenError:
            continue
    raise CodegenError(
        f"output {op.name!r}: term {term.name!r} does not fit the type in integer arithmetic "
        "(use --arith float)"
    )


def _weights(blk: FixedBlock, groups: list[Group], rules: list[FX]) -> list[FX]:
    out = []
    for accu, items in groups:
        g: FX | None = None
        for ri, wt in items:
            a = blk.weighted(rules[ri], wt)
            if g is None:
                g = a
            elif norms.is_max(accu):
                g = blk.minmax(g, a, False)
            else:
                g = fa.add(blk.w, g, a)
        assert g is not None
        out.append(g)
    return out


def _sums(blk: FixedBlock, op: OutputPlan, gs: list[FX], zs: list[FX]) -> tuple[int, FX, FX, list[FX]]:
    """``(shift, numerator, denominator, shifted weights)``: the weights divided by
    ``2**shift``, the smallest shift whose sums fit the wide type."""
    w = blk.w
    for r in range(0, blk.dbits + 1):
        try:
            g2 = [fa.rdiv(w, g, 1 << r) for g in gs]
            num = fa.mul(w, g2[0], zs[0])
            den = fa.widen(g2[0])
            for g, z in zip(g2[1:], zs[1:], strict=True):
                num = fa.add(w, num, fa.mul(w, g, z), "the weighted sum")
                den = fa.add(w, den, fa.widen(g), "the sum of weights")
            return r, num, den, g2
        except CodegenError:
            continue
    raise CodegenError(
        f"output {op.name!r}: the weighted sum does not fit the wide type in integer arithmetic "
        "(use --arith float)"
    )


def input_domain(blk: FixedBlock) -> dict[int, tuple[float, float]]:
    """Each fuzzified input's interval of values the block can be given (its stored range)."""
    out = {}
    for fi in blk.plan.fuzzy_inputs:
        p = blk.inputs[fi.slot]
        out[fi.slot] = (float(p.low * p.scale + p.offset), float(p.high * p.scale + p.offset))
    return out


def round_up(x: Fraction) -> float:
    """``x`` as the nearest float not below it (a stated bound never rounds down)."""
    f = float(x)
    return f if Fraction(f) >= x else math.nextafter(f, math.inf)


def _unbounded(plan: Plan, op: OutputPlan, bounds: WeightBounds, e_sum: Fraction) -> CodegenError:
    """Why no error bound was found: some input fires (nearly) no rule, or the search for a
    lower bound of the total weight ran out."""
    where = ", ".join(f"{plan.inputs[s].name}={v:g}" for s, v in sorted(bounds.witness.items()))
    if bounds.witness_total <= 2 * float(e_sum):
        why = f"comes down to {bounds.witness_total:.3g} (at {where}): near inputs where no rule fires"
    else:
        why = (
            f"could not be bounded from below (the smallest found is {bounds.witness_total:.3g}, at "
            f"{where}, but only {bounds.low:.3g} was proven within the search budget): then"
        )
    return CodegenError(
        f"output {op.name!r}: the rules' total weight {why}, integer arithmetic has no worst-case "
        "error bound (use --arith float, or write rules that cover the inputs' whole RANGE)"
    )


def _output(blk: FixedBlock, op: OutputPlan, rules: list[FX], info: Var) -> Port:
    from fuzzyctl.ir.programs.fixed_block import Port, output_scale

    plan, w = blk.plan, blk.w
    groups, terms = _groups(op)
    if not groups:
        raise CodegenError(
            f"output {op.name!r}: concluded by no rule, it has no integer form (use --arith float)"
        )
    average = METHODS[op.method].weighted == "average"
    zi = [_z_interval(blk, op, t) for t in terms]
    zlo, zhi = min(a for a, _b in zi), max(b for _a, b in zi)
    weights = [constant(r.weight) for r in plan.rules]
    domain = input_domain(blk)
    # the search's cost grows with the rules each box evaluates
    bounds = weight_bounds(
        plan, groups, weights, domain, budget=max(500, min(6000, 600_000 // len(plan.rules)))
    )
    # DEFAULT := nan has no integer form; it is never reached when the output is proven below
    # to fire for every input (else the output is refused), so it is stored as 0
    nan = op.default is not None and not math.isfinite(op.default)
    default = Fraction(0.0 if op.default is None or nan else op.default)
    if average:
        lo, hi = zlo, zhi
    else:
        top = Fraction(bounds.high)
        lo, hi = min(Fraction(0), top * zlo), max(Fraction(0), top * zhi)
    if not nan:
        lo, hi = min(lo, default), max(hi, default)
    if op.low is not None and op.high is not None:
        lo, hi = min(lo, Fraction(op.low)), max(hi, Fraction(op.high))
    scale, offset = output_scale(lo, hi, blk.arith, blk.int_output, not average)
    blk.b.comment(f"output {op.name}: {'weighted average' if average else 'weighted sum'}")
    zs = [_z_fx(blk, op, t, scale, offset) for t in terms]
    zs = [
        z if isinstance(z.ex, Int) else blk.temp(z, f"{op.name}: value of term {op.terms[t].name}")
        for z, t in zip(zs, terms, strict=True)
    ]
    gs = [
        blk.temp(g, f"{op.name}: weight of {op.terms[t].name}") if not isinstance(g.ex, Var) else g
        for g, t in zip(_weights(blk, groups, rules), terms, strict=True)
    ]
    shift, num, den, g2 = _sums(blk, op, gs, zs)
    e_sum = sum((g.err for g in g2), Fraction(0))
    if Fraction(bounds.low) <= e_sum:
        raise _unbounded(plan, op, bounds, e_sum)
    n = blk.temp(num, f"{op.name}: weighted sum", f"NUM_{len(blk.decls)}")
    d = blk.temp(den, f"{op.name}: sum of weights", f"DEN_{len(blk.decls)}")
    out = blk.declare(
        op.name, "narrow", "output", comment=f"value = stored * {float(scale)!r} + {float(offset)!r}"
    )
    q = blk.declare(f"Q_{len(blk.decls)}", "wide")
    if average:
        lsb = Fraction(1, 2) + Fraction(1, 2) / max(
            1, math.floor((Fraction(bounds.low) - e_sum) / g2[0].scale)
        )
        spread = zhi - zlo
        err = max(z.err for z in zs) + e_sum * spread / (Fraction(bounds.low) - e_sum) + lsb * scale
        slo, shi = min(z.lo for z in zs), max(z.hi for z in zs)
    else:
        res = fa.rdiv(w, fa.var(n.ex.name, num), round(1 / g2[0].scale))  # type: ignore[attr-defined]
        # the exact sum lies in [lo, hi] (weights >= 0, values in [zlo, zhi]): tighter than
        # the interval of the integer sum, whose terms are bounded one by one
        err = res.err
        slo = max(res.lo, math.floor((lo - err - offset) / scale))
        shi = min(res.hi, math.ceil((hi + err - offset) / scale))
    if not w.fits(slo, shi, False):
        raise CodegenError(
            f"output {op.name!r}: may overflow its type in integer arithmetic (use --arith float)"
        )
    with blk.b.if_(d.ex.gt(Int(0))):
        if average:
            with blk.b.if_(n.ex.ge(Int(0))):
                blk.b.set(q, (n.ex + d.ex / Int(2)) / d.ex)
            with blk.b.else_():
                blk.b.set(q, -((d.ex / Int(2) - n.ex) / d.ex))
        else:
            blk.b.set(q, res.ex)
        blk.b.set(out, fa.narrow(w, FX(q, slo, shi, scale, err, True), "the output").ex)
    with blk.b.else_():
        blk.b.set(info, Int(2))
        if not op.no_change:
            blk.b.set(out, Int(0 if nan else round((default - offset) / scale)))
    del shift
    return Port(op.name, scale, offset, slo, shi, round_up(err), comment=f"{float(lo):g}..{float(hi):g}")


def emit_outputs(blk: FixedBlock, rules: list[FX], info: Var) -> list[Port]:
    from fuzzyctl.ir.programs.fixed_coa import coa_output
    from fuzzyctl.ir.programs.fixed_mamdani import mamdani_output

    def mamdani(op: OutputPlan) -> Port:
        bisects = METHODS[op.method].bisects
        return (coa_output if bisects else mamdani_output)(blk, op, rules, info)

    return [mamdani(op) if op.kind == "mamdani" else _output(blk, op, rules, info) for op in blk.plan.outputs]
