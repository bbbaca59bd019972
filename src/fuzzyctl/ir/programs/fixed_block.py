"""The function block in integer arithmetic (``codegen --arith int16|int32``): singleton
(COGS) and Takagi-Sugeno (WTAVER, WTSUM) outputs over piecewise-linear input terms.

Scaling: every input is stored as an integer with ``value = stored * scale + offset``, the
scale a power of two chosen so that the input's range (its terms' span) fits the type; a
degree is stored as ``degree * D`` (``D = 2**(bits - 2)``); every output's scale is a power
of ten (``int_output="scaled"``, the finest that holds the output's values) or 1
(``"unit"``: the output in its own unit).  Every constant, interval and error bound is
derived at generation time (:mod:`fuzzyctl.ir.builders.fixed_arith`): the block cannot
overflow for any stored input, and each output's stated error bound holds for every input
(the weighted averages' denominators are bounded below by
:mod:`fuzzyctl.ir.builders.fixed_bound`).  What this cannot prove, or does not compute
(Mamdani outputs, smooth terms, hedges, chained rules, ...), is refused with the reason.
The integer block is not tunable: its constants are part of the proof."""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from fractions import Fraction

from fuzzyctl.engine.plan import (
    CAnd,
    CNot,
    CondPlan,
    COr,
    CTerm,
    CTrue,
    OutputPlan,
    Plan,
    Slot,
    TermPlan,
)
from fuzzyctl.escape import CodegenError
from fuzzyctl.ir.builders import fixed_arith as fa
from fuzzyctl.ir.builders.fixed_arith import FX, Width
from fuzzyctl.ir.builders.fixed_smooth import SmoothTerm, approximate, default_tolerance
from fuzzyctl.ir.cost import Cost, cost
from fuzzyctl.ir.nodes import Assign, Bin, Bool, Builder, Ex, Int, Program, Stmt, Var
from fuzzyctl.kinds import norms
from fuzzyctl.kinds import shapes as registry
from fuzzyctl.kinds.arith import INT_OUTPUTS, Arith
from fuzzyctl.kinds.methods import METHODS

__all__ = ["FixedDecl", "FixedProgram", "Port", "build_fixed"]

# the operators with a fixed-point form (their registry entry's ``fixed``)
_AND = tuple(name for name, e in norms.TNORMS.items() if e.fixed is not None)
_OR = tuple(name for name, e in norms.SNORMS.items() if e.fixed is not None)
_ACCU = ("MAX", "SUM")


@dataclass(frozen=True)
class Port:
    """An input or output of the block: ``value = stored * scale + offset``."""

    name: str
    scale: Fraction
    offset: Fraction
    low: int  # stored range the block accepts / produces
    high: int
    error_bound: float = 0.0  # outputs: worst case against the exact engine, in the output's unit
    comment: str = ""
    #: LM, RM, MoM: the bound where no other set's height is within ``tie_margin`` (degrees)
    error_bound_away: float | None = None
    tie_margin: float | None = None

    def formula(self) -> str:
        return f"stored * {float(self.scale)!r} + {float(self.offset)!r}"

    def to_dict(self, type_name: str, output: bool) -> dict[str, object]:
        d: dict[str, object] = {
            "name": self.name,
            "type": type_name,
            "scale": float(self.scale),
            "offset": float(self.offset),
            "stored_range": [self.low, self.high],
        }
        if output:
            d["error_bound"] = self.error_bound
            if self.error_bound_away is not None:
                d["error_bound_away_from_ties"] = self.error_bound_away
                d["tie_margin"] = self.tie_margin
        return d


@dataclass
class FixedDecl:
    name: str
    kind: str  # narrow, wide, bool, byte, index (DINT: an array index)
    storage: str  # input, output, temp, const (an array: ``size`` and its ``values``)
    init: int | None = None
    comment: str = ""
    size: int | None = None
    values: tuple[int, ...] | None = None


@dataclass
class FixedProgram:
    name: str
    arith: Arith
    inputs: list[Port]
    outputs: list[Port]
    decls: list[FixedDecl]
    body: list[Stmt]
    header: list[str] = field(default_factory=list)
    #: the smooth input terms computed as chords: input, term, kind, chords, proven
    #: deviation and tolerance (degrees)
    approximations: list[dict[str, object]] = field(default_factory=list)
    cost: Cost | None = None  # one cycle's (fuzzyctl.ir.cost)


def _refuse(what: str) -> CodegenError:
    """A refusal naming the element first, then why, then the way past it."""
    return CodegenError(f"{what} in integer arithmetic (use --arith float)")


# --------------------------------------------------------------------------- what is computed


def smooth_term(term: TermPlan) -> bool:
    """A term computed as chords with a proven deviation (:mod:`fuzzyctl.ir.builders.fixed_smooth`)."""
    return registry.flag(term.kind, "smooth") and term.constant


def _check_cond(c: CondPlan, plan: Plan, rule: str) -> None:
    if isinstance(c, CTerm):
        fi = plan.fuzzy_inputs[c.var]
        if c.hedges:
            raise _refuse(f"rule {rule}: hedges ({' '.join(c.hedges)}) are not computed")
        term = fi.terms[c.term]
        if term.pwl is None and smooth_term(term):
            if not 0.0 <= float(term.height) <= 1.0:  # type: ignore[arg-type]
                raise _refuse(
                    f"term {term.name!r} of input {fi.name!r}: a height outside 0..1 is not computed"
                )
        elif term.pwl is None:
            raise _refuse(
                f"term {term.name!r} of input {fi.name!r}: a {term.kind} term (not piecewise linear with "
                "constant points) is not computed"
            )
    elif isinstance(c, CNot):
        _check_cond(c.operand, plan, rule)
    elif isinstance(c, CAnd | COr):
        ops = _AND if isinstance(c, CAnd) else _OR
        if c.op not in ops:
            raise _refuse(f"rule {rule}: the operator {c.op} is not computed (only {', '.join(ops)} are)")
        for o in c.operands:
            _check_cond(o, plan, rule)
    elif not isinstance(c, CTrue):
        raise _refuse(f"rule {rule}: a chained variable or a degree input in a condition is not computed")


def check_supported(plan: Plan) -> None:
    """Refuse what the integer block does not compute, naming it."""
    block = f"function block {plan.name!r}"
    if plan.chained:
        raise _refuse(f"{block}: chained inference is not computed")
    if plan.selections:
        raise _refuse("rule block activation methods are not computed")
    if plan.options.firing_threshold != 0.0:
        raise _refuse(f"{block}: a firing threshold is not computed")
    if plan.options.hedges_carry_over:
        raise _refuse(f"{block}: carried-over hedges are not computed")
    for i in plan.inputs:
        if i.clamp is not None:
            raise _refuse(f"input {i.name!r}: a locked range is not computed")
    for r in plan.rules:
        if isinstance(r.weight, Slot) or r.accu is not None or r.weight < 0:
            raise _refuse(
                f"rule {r.label}: a variable or negative weight, or a rule block's own ACCU, is not computed"
            )
        _check_cond(r.condition, plan, r.label)
        for cp in r.conclusions:
            if isinstance(cp.weight, Slot) or cp.hedges or cp.chained or cp.weight < 0:
                raise _refuse(
                    f"rule {r.label}: a variable or negative conclusion weight, or hedges, are not computed"
                )
    for fi in plan.fuzzy_inputs:
        for t in fi.terms:
            if t.pwl is not None and any(not 0.0 <= y <= 1.0 for _x, y in t.pwl):
                raise _refuse(f"term {t.name!r} of input {fi.name!r}: degrees outside 0..1 are not computed")
    for op in plan.outputs:
        _check_output(op, plan.options.weight_before_activation)


def _check_output(op: OutputPlan, weight_before_activation: bool) -> None:
    from fuzzyctl.ir.programs.fixed_mamdani import check_mamdani

    name = f"output {op.name!r}"
    if op.kind == "mamdani":
        if op.clamp is not None or not op.is_output:
            raise _refuse(f"{name}: a locked range or a local defuzzified variable is not computed")
        check_mamdani(op, weight_before_activation)
        return
    if op.kind not in ("singleton", "ts"):
        raise _refuse(f"{name}: a {op.kind} output is not computed")
    if METHODS[op.method].weighted is None:
        raise _refuse(f"{name}: METHOD {op.method} is not computed (weighted averages and sums are)")
    if op.accu is not None and op.accu not in _ACCU:
        raise _refuse(f"{name}: ACCU {op.accu} is not computed (MAX and SUM are)")
    if op.clamp is not None:
        raise _refuse(f"{name}: a locked range is not computed")
    if not op.is_output:
        raise _refuse(f"{name}: a local defuzzified variable is not computed")
    for t in op.terms:
        if any(isinstance(p, Slot) for p in t.params):
            raise _refuse(f"{name}: term {t.name!r} with variable parameters is not computed")
        ok = (
            t.kind == "singleton"
            if op.kind == "singleton"
            else t.kind == "singleton"
            or registry.flag(t.kind, "ts_constant")
            or registry.flag(t.kind, "ts_linear")
        )
        if not ok:
            raise _refuse(f"{name}: term {t.name!r} ({t.kind}) is not computed")


# --------------------------------------------------------------------------- scaling


def _pow2_scale(half_span: Fraction, highest: int) -> Fraction:
    """The smallest power of two ``s`` with ``half_span <= highest * s``."""
    if half_span <= 0:
        return Fraction(1)
    k = math.floor(math.log2(half_span / highest)) - 1
    while half_span > highest * Fraction(2) ** k:
        k += 1
    return Fraction(2) ** k


def _input_port(plan: Plan, slot: int, arith: Arith, rng: tuple[float, float] | None) -> Port:
    """The scaling of one input: ``rng`` (the declared RANGE, else its terms' span) fills the
    type; stored values outside it are limited to it in the block."""
    name = plan.inputs[slot].name
    if rng is None:
        xs = [x for fi in plan.fuzzy_inputs if fi.slot == slot for t in fi.terms for x, _y in t.pwl or ()]
        # a smooth term: its universe without RANGE (the registry's span)
        xs += [
            x
            for fi in plan.fuzzy_inputs
            if fi.slot == slot
            for t in fi.terms
            if t.pwl is None and smooth_term(t)
            for x in registry.SHAPES[t.kind].span.of([float(p) for p in t.params])  # type: ignore[arg-type]
        ]
        if not all(math.isfinite(x) for x in xs):
            raise _refuse(
                f"input {name!r}: without RANGE a smooth term's universe is unbounded: give a RANGE"
            )
        if not xs:
            raise _refuse(f"input {name!r}: without RANGE or piecewise-linear terms it has no scaling")
        rng = (min(xs), max(xs))
    lo, hi = Fraction(rng[0]), Fraction(rng[1])
    if not lo < hi:
        raise _refuse(f"input {name!r}: the empty range {rng[0]:g}..{rng[1]:g} has no scaling")
    offset = Fraction(0) if lo <= 0 <= hi else Fraction(float((lo + hi) / 2))
    scale = _pow2_scale(max(hi - offset, offset - lo), arith.highest)
    low = max(arith.lowest, math.ceil((lo - offset) / scale))
    high = min(arith.highest, math.floor((hi - offset) / scale))
    return Port(name, scale, offset, low, high, comment=f"{rng[0]:g}..{rng[1]:g}")


def output_scale(
    lo: Fraction, hi: Fraction, arith: Arith, mode: str, zero_offset: bool
) -> tuple[Fraction, Fraction]:
    """``(scale, offset)`` of an output whose values lie in ``[lo, hi]``."""
    offset = Fraction(0) if zero_offset or lo <= 0 <= hi else (lo + hi) / 2
    half = max(hi - offset, offset - lo)
    if mode == "unit":
        offset = Fraction(round(offset))
        if max(hi - offset, offset - lo) > arith.highest:
            raise _refuse(
                f"output values {float(lo):g}..{float(hi):g}: too large for the type in their own unit"
            )
        return Fraction(1), offset
    k = 0
    room = arith.highest - 2  # the rounding of the values may add a unit
    while half > room * Fraction(10) ** k:
        k += 1
    while half <= room * Fraction(10) ** (k - 1) and k > -30:
        k -= 1
    scale = Fraction(10) ** k
    return scale, Fraction(round(offset / scale)) * scale


# --------------------------------------------------------------------------- the block


def _merged(branches: list[tuple[Ex | None, FX]]) -> list[tuple[Ex | None, FX]]:
    """The if-chain without a branch whose constant the next branch gives too, when that
    branch's condition (``X < c``, or none) also holds on the dropped one's values."""
    out: list[tuple[Ex | None, FX]] = []
    for cond, x in reversed(branches):
        if out and isinstance(x.ex, Int):
            nxt_cond, nxt = out[-1]
            same = isinstance(nxt.ex, Int) and nxt.ex.value == x.ex.value
            if same and (nxt_cond is None or (isinstance(nxt_cond, Bin) and nxt_cond.op == "<")):
                continue
        out.append((cond, x))
    return out[::-1]


class FixedBlock:
    def __init__(
        self, plan: Plan, arith: Arith, name: str, int_output: str, ranges: dict[str, tuple[float, float]]
    ) -> None:
        self.plan = plan
        self.arith = arith
        self.w = Width(arith)
        self.dbits = arith.bits - 2
        self.D = 1 << self.dbits
        self.dscale = Fraction(1, self.D)
        self.name = name
        self.int_output = int_output
        self.b = Builder()
        self.decls: list[FixedDecl] = []
        self.ntemp = 0
        self.inputs = {s: _input_port(plan, s, arith, ranges.get(plan.inputs[s].name)) for s in self._slots()}
        self.x = {
            s: FX(Var(f"X_{s}"), p.low, p.high, Fraction(1), Fraction(0), False)
            for s, p in self.inputs.items()
        }

    def _slots(self) -> list[int]:
        slots = {fi.slot for fi in self.plan.fuzzy_inputs}
        for op in self.plan.outputs:
            for t in op.terms:
                if registry.flag(t.kind, "ts_linear"):
                    n = len(self.plan.inputs)
                    slots.update(i for i, c in enumerate(t.params[:n]) if c != 0.0)
        return sorted(slots)

    # ------------------------------------------------------------------ helpers

    def declare(
        self, name: str, kind: str, storage: str = "temp", comment: str = "", init: int | None = None
    ) -> Var:
        self.decls.append(FixedDecl(name, kind, storage, init, comment))
        return Var(name)

    def temp(self, x: FX, comment: str = "", name: str | None = None) -> FX:
        name = name or f"T_{self.ntemp}"
        self.ntemp += 1
        v = self.declare(name, "wide" if x.wide else "narrow", comment=comment)
        self.b.set(v, x.ex)
        return fa.var(name, x)

    def degree_const(self, y: float) -> FX:
        return fa.const(self.w, Fraction(y), self.dscale)

    # ------------------------------------------------------------------ fuzzification

    def limit_inputs(self) -> None:
        """Each stored input limited to its range (what the engine's ``out_of_range="clamp"``
        does): the proof covers exactly these values."""
        for s, p in self.inputs.items():
            v = self.declare(f"X_{s}", "narrow", comment=f"{p.name} limited to {p.low}..{p.high}")
            self.b.set(v, Var(p.name))
            with self.b.if_(v.lt(Int(p.low))):
                self.b.set(v, Int(p.low))
            with self.b.elif_(v.gt(Int(p.high))):
                self.b.set(v, Int(p.high))

    def linear_piece(self, p: int, q: int, ua: Fraction, ya: float, ub: Fraction, yb: float, xv: Var) -> FX:
        """``ya + (yb - ya) (X - ua) / (ub - ua)`` for integer X in ``[p, q]``, as degree."""
        m = (Fraction(yb) - Fraction(ya)) / (ub - ua)
        if m == 0:
            return self.degree_const(ya)
        f_p = Fraction(ya) + m * (p - ua)
        t = FX(xv, p, q, Fraction(1), Fraction(0), False)
        for s in range(2 * self.arith.bits - self.dbits, -1, -1):
            fine = self.dscale / (1 << s)
            try:
                dx = fa.sub(self.w, fa.widen(t), fa.const(self.w, Fraction(p), Fraction(1), True))
                prod = fa.mul(self.w, dx, fa.const(self.w, m, fine, True, "a slope"))
                total = fa.add(self.w, prod, fa.const(self.w, f_p, fine, True))
                return fa.rdiv(self.w, total, 1 << s)
            except CodegenError:
                continue
        raise _refuse("term: a membership slope does not fit the wide type")

    def approximate_smooth(self, tolerance: float | None) -> list[dict[str, object]]:
        """Every smooth term a rule reads replaced by its chords (``tolerance`` in degrees;
        None: the arithmetic's default, loosened when a term needs too many chords)."""
        import dataclasses

        tol = default_tolerance(self.arith) if tolerance is None else tolerance
        fis = list(self.plan.fuzzy_inputs)
        report: list[dict[str, object]] = []
        for var, term in self.plan.terms_read():
            fi = fis[var]
            t = fi.terms[term]
            if t.pwl is not None or not smooth_term(t):
                continue
            p = self.inputs[fi.slot]
            where = f"term {t.name!r} of input {fi.name!r}"
            a = approximate(t, where, p.scale, p.offset, p.low, p.high, tol, tolerance is None)
            terms = list(fi.terms)
            terms[term] = a
            fis[var] = dataclasses.replace(fi, terms=tuple(terms))
            report.append(
                {
                    "input": fi.name,
                    "term": t.name,
                    "kind": t.kind,
                    "chords": max(len(a.knots) - 1, 1),
                    "deviation": a.deviation,
                    "tolerance": a.tolerance,
                }
            )
        self.plan = dataclasses.replace(self.plan, fuzzy_inputs=tuple(fis))
        return report

    def smooth_membership(self, var: int, term: int, t: SmoothTerm) -> FX:
        """The chords of a smooth term, found by bisection over the breakpoints (as many
        comparisons as the tree is deep), with the proven deviation added to the error."""
        fi = self.plan.fuzzy_inputs[var]
        xv = Var(f"X_{fi.slot}")
        ks, ys = t.knots, t.degrees
        n = len(ks) - 1
        leaves = [
            self.linear_piece(
                ks[j], ks[j + 1] - (j < n - 1), Fraction(ks[j]), ys[j], Fraction(ks[j + 1]), ys[j + 1], xv
            )
            for j in range(n)
        ] or [self.degree_const(ys[0])]
        v = self.declare(f"DEG_{var}_{term}", "narrow", comment=f"{fi.name} IS {t.name} ({n} chords)")

        def tree(lo: int, hi: int) -> None:
            if hi - lo <= 1:
                self.b.set(v, fa.narrow(self.w, leaves[lo], "a degree").ex)
                return
            mid = (lo + hi) // 2
            with self.b.if_(xv.lt(Int(ks[mid]))):
                tree(lo, mid)
            with self.b.else_():
                tree(mid, hi)

        tree(0, len(leaves))
        lo, hi = min(x.lo for x in leaves), max(x.hi for x in leaves)
        if lo < 0 or hi > self.D:
            with self.b.if_(v.lt(Int(0))):
                self.b.set(v, Int(0))
            with self.b.elif_(v.gt(Int(self.D))):
                self.b.set(v, Int(self.D))
        err = max(x.err for x in leaves) + Fraction(t.deviation)
        return FX(v, max(lo, 0), min(hi, self.D), self.dscale, err, False)

    def membership(self, var: int, term: int) -> FX:
        fi = self.plan.fuzzy_inputs[var]
        t = fi.terms[term]
        if isinstance(t, SmoothTerm):
            return self.smooth_membership(var, term, t)
        pts = t.pwl
        assert pts is not None
        port, xv = self.inputs[fi.slot], Var(f"X_{fi.slot}")
        from fuzzyctl.engine.lowering.grid import left_limit, right_limit
        from fuzzyctl.engine.semantics.shapes import pwl_value

        us = sorted({x for x, _y in pts})
        stored = [(Fraction(u) - port.offset) / port.scale for u in us]
        branches: list[tuple[Ex | None, FX]] = []
        cur = port.low
        for k, (u, su) in enumerate(zip(us, stored, strict=True)):
            c = math.ceil(su)
            if cur <= min(c - 1, port.high):
                if k == 0:
                    val = self.degree_const(pts[0][1])
                else:
                    ya, yb = right_limit(pts, us[k - 1]), left_limit(pts, u)
                    val = self.linear_piece(cur, min(c - 1, port.high), stored[k - 1], ya, su, yb, xv)
                branches.append((xv.lt(Int(c)) if c <= port.high else None, val))
                cur = c
            if su.denominator == 1 and cur == su and port.low <= cur <= port.high:
                branches.append((xv.eq(Int(cur)), self.degree_const(pwl_value(pts, u))))
                cur += 1
            if cur > port.high:
                break
        if cur <= port.high:
            branches.append((None, self.degree_const(pts[-1][1])))
        branches = _merged(branches)
        name = f"DEG_{var}_{term}"
        v = self.declare(name, "narrow", comment=f"{fi.name} IS {t.name}")
        lo = min(x.lo for _c, x in branches)
        hi = max(x.hi for _c, x in branches)
        err = max(x.err for _c, x in branches)
        self._chain(v, branches)
        if lo < 0 or hi > self.D:
            with self.b.if_(v.lt(Int(0))):
                self.b.set(v, Int(0))
            with self.b.elif_(v.gt(Int(self.D))):
                self.b.set(v, Int(self.D))
        return FX(v, max(lo, 0), min(hi, self.D), self.dscale, err, False)

    def _chain(self, v: Var, branches: list[tuple[Ex | None, FX]]) -> None:
        def value(x: FX) -> Ex:
            return fa.narrow(self.w, x, "a degree").ex

        conds = [(c, x) for c, x in branches if c is not None]
        last = [x for c, x in branches if c is None]
        if not conds:
            self.b.set(v, value(last[0]))
            return
        for k, (c, x) in enumerate(conds):
            ctx = self.b.if_(c) if k == 0 else self.b.elif_(c)
            with ctx:
                self.b.set(v, value(x))
        if last:
            with self.b.else_():
                self.b.set(v, value(last[0]))

    # ------------------------------------------------------------------ rules

    def minmax(self, a: FX, b: FX, is_min: bool) -> FX:
        lo, hi, err = fa.fx_min(a, b) if is_min else fa.fx_max(a, b)
        t = self.temp(a)
        with self.b.if_(b.ex.lt(t.ex) if is_min else b.ex.gt(t.ex)):
            self.b.set(t.ex, b.ex)  # type: ignore[arg-type]
        return FX(t.ex, lo, hi, a.scale, err, False)

    def product(self, a: FX, b: FX) -> FX:
        return fa.narrow(self.w, fa.rdiv(self.w, fa.mul(self.w, a, b), self.D), "a product of degrees")

    def limited(self, x: FX, lo: int | None, hi: int | None) -> FX:
        """``x`` limited to ``[lo, hi]`` (the exact value lies there: the error does not grow)."""
        t = self.temp(x)
        if lo is not None and x.lo < lo:
            with self.b.if_(t.ex.lt(Int(lo))):
                self.b.set(t.ex, Int(lo))  # type: ignore[arg-type]
        if hi is not None and x.hi > hi:
            with self.b.if_(t.ex.gt(Int(hi))):
                self.b.set(t.ex, Int(hi))  # type: ignore[arg-type]
        nlo = x.lo if lo is None else max(x.lo, lo)
        nhi = x.hi if hi is None else min(x.hi, hi)
        return fa.narrow(self.w, FX(t.ex, nlo, nhi, x.scale, x.err, x.wide), "a degree")

    def cond(self, c: CondPlan, degs: dict[tuple[int, int], FX]) -> FX:
        one = self.degree_const(1.0)
        if isinstance(c, CTerm):
            d = degs[(c.var, c.term)]
            return fa.narrow(self.w, fa.sub(self.w, one, d), "NOT") if c.negated else d
        if isinstance(c, CNot):
            return fa.narrow(self.w, fa.sub(self.w, one, self.cond(c.operand, degs)), "NOT")
        if isinstance(c, CAnd | COr):
            v = self.cond(c.operands[0], degs)
            for o in c.operands[1:]:
                v = self.combine(c.op, v, self.cond(o, degs), isinstance(c, CAnd))
            return v
        return one

    def combine(self, op: str, a: FX, b: FX, is_and: bool) -> FX:
        form = norms.TNORMS[op].fixed if is_and else norms.SNORMS[op].fixed
        if form in ("min", "max"):
            return self.minmax(a, b, form == "min")
        if form == "product":
            return self.product(a, b)
        if form == "probabilistic_sum":  # a + (1 - a) b: in 0..1, which the limit makes the interval know
            rest = fa.narrow(self.w, fa.sub(self.w, self.degree_const(1.0), a), "NOT")
            return self.limited(fa.add(self.w, a, self.product(rest, b)), 0, self.D)
        if form == "bounded_sum":
            return self.limited(fa.add(self.w, a, b), None, self.D)
        assert form == "bounded_difference", op
        return self.limited(fa.sub(self.w, fa.add(self.w, a, b), self.degree_const(1.0)), 0, None)

    def weighted(self, a: FX, w: float) -> FX:
        if w == 1.0:
            return a
        return fa.narrow(
            self.w, fa.rdiv(self.w, fa.mul(self.w, a, self.degree_const(w)), self.D), "a weighted degree"
        )

    def rules(self) -> list[FX]:
        plan = self.plan
        degs = {key: self.membership(*key) for key in plan.terms_read()}
        out: list[FX] = []
        for k, r in enumerate(plan.rules):
            self.b.comment(f"rule {r.label}: {self.rule_text(r.condition)}")
            a = self.weighted(self.cond(r.condition, degs), r.weight)  # type: ignore[arg-type]
            v = self.declare(f"RULE_{k + 1}", "narrow", comment=f"degree of rule {r.label}")
            self.b.set(v, a.ex)
            out.append(FX(v, a.lo, a.hi, a.scale, a.err, False))
        return out

    def rule_text(self, c: CondPlan) -> str:
        plan = self.plan
        if isinstance(c, CTerm):
            fi = plan.fuzzy_inputs[c.var]
            return f"{fi.name} IS {'NOT ' if c.negated else ''}{fi.terms[c.term].name}"
        if isinstance(c, CNot):
            return f"NOT ({self.rule_text(c.operand)})"
        if isinstance(c, CAnd | COr):
            word = " AND " if isinstance(c, CAnd) else " OR "
            return "(" + word.join(self.rule_text(o) for o in c.operands) + ")"
        return "TRUE"


def build_fixed(
    plan: Plan,
    arith: Arith,
    int_output: str = "scaled",
    ranges: dict[str, tuple[float, float]] | None = None,
    term_tolerance: float | None = None,
) -> FixedProgram:
    """The integer block of ``plan`` (raises :class:`CodegenError` naming what it cannot compute
    or prove).  Smooth input terms are computed as chords within ``term_tolerance`` degrees
    (None: the arithmetic's default, see :mod:`fuzzyctl.ir.builders.fixed_smooth`)."""
    from fuzzyctl.ir.programs.fixed_outputs import emit_outputs

    if plan.options.emulate is not None:
        raise _refuse(f"function block {plan.name!r}: the {plan.options.emulate} profile is not computed")
    if int_output not in INT_OUTPUTS:
        raise CodegenError(f"unknown int_output {int_output!r} (known: {', '.join(INT_OUTPUTS)})")
    check_supported(plan)
    name = plan.name or "fuzzy"
    blk = FixedBlock(plan, arith, name, int_output, ranges or {})
    approximations = blk.approximate_smooth(term_tolerance)
    for p in blk.inputs.values():
        blk.declare(
            p.name,
            "narrow",
            "input",
            comment=f"value = {p.formula()}",
        )
    enable = blk.declare("ENABLE", "bool", "input", comment="FALSE: outputs keep their values")
    info = blk.declare(
        "INFO", "byte", "output", init=0, comment="16#00 ok, 16#01 ENABLE is FALSE, 16#02 no rule fired"
    )
    outer = blk.b
    blk.b = Builder()
    blk.limit_inputs()
    rule_fx = blk.rules()
    outputs = emit_outputs(blk, rule_fx, info)
    body: list[Stmt] = [Assign(info, Int(0))]
    with outer.if_(enable.eq(Bool(False))):
        outer.set(info, Int(1))
    with outer.else_():
        outer.cur.extend(body + blk.b.root)
    header = [
        f"function block {name}: generated by fuzzyctl in {arith.name} fixed point ({arith.help})",
        f"degrees stored as degree * {blk.D}; no floating point anywhere in the block",
        "every intermediate value's range proven at generation time (interval analysis): no overflow",
        "inputs outside their range (RANGE, else the terms' span) are limited to it",
    ]
    for p in blk.inputs.values():
        header.append(f"input {p.name}: value = {p.formula()} (range {p.comment})")
    for a in approximations:
        header.append(
            f"input {a['input']} IS {a['term']} ({a['kind']}): {a['chords']} chords, proven to deviate "
            f"at most {a['deviation']:.3g} degrees from the term (tolerance {a['tolerance']:g}), "
            "counted in the errors"
        )
    for p in outputs:
        header.append(
            f"output {p.name}: value = {p.formula()}; worst-case error against the exact engine "
            f"{p.error_bound:.3g} (from each step's rounding, for every stored input)"
        )
        if p.error_bound_away is not None:
            header.append(
                f"output {p.name}: {p.error_bound_away:.3g} away from ties (one set alone at the top, every "
                f"other set's height and the top's own jump levels more than {p.tie_margin:.3g} below or "
                "away from it); the worst case includes the jump of the maximum where heights tie"
            )
    # what one cycle costs (a smooth term's bisection counts its deepest path only); the
    # generator prints it in the header
    spent = cost(Program(name, [], outer.root))
    prog = FixedProgram(
        name, arith, list(blk.inputs.values()), outputs, blk.decls, outer.root, header, approximations, spent
    )
    return prog
