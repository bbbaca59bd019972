"""Interval type-2 inference in the IR, written once for every target (the IR twin of
:class:`fuzzyctl.engine.type2.Type2Controller` in its sampled mode, which it is tested
against).

* Each input term read by a rule gives ``[lower(x), upper(x)]``: piecewise-linear functions
  (the upper one, an explicit lower one, or MATLAB's scale/lag form of a piecewise-linear
  upper, one or two lags: :func:`fuzzyctl.engine.type2_sets.lower_points`) as breakpoint
  tables read by :func:`~fuzzyctl.ir.builders.terms.pwl_value_fixed`; smooth functions by
  their registry formula (:func:`~fuzzyctl.ir.builders.terms.smooth`), the scale/lag form of
  a smooth upper as ``scale * max(0, (upper - lag) / (1 - lag))``.
* A rule's firing interval: its condition on both bounds (the block's AND/OR templates,
  hedges on each bound, NOT swapping them), times its weight.
* Sugeno (constant and linear terms): the rule points with their firing intervals, sorted
  (at generation time when every point is constant, else by a stable odd-even
  transposition network), then the type reduction.
* Mamdani: the output range sampled at ``samples`` points (``numpy.linspace``, as the
  engine); each term's upper and lower degrees at the samples are constant tables; the
  activated sets are aggregated on both bounds at each sample (under MAX the activations of
  one term are merged first: ``max_k act(f_k, mu) = act(max_k f_k, mu)``), then the type
  reduction (:mod:`fuzzyctl.ir.builders.type2_reduce`, bounded iterations).
* The output is ``(yl + yr) / 2``, its DEFAULT when no upper weight is positive.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

import fuzzyctl.engine.type2_sets as sets
from fuzzyctl.engine.semantics import operators as ops
from fuzzyctl.ir.builders import terms as T
from fuzzyctl.ir.builders import type2_reduce as R
from fuzzyctl.ir.builders.rules import literal
from fuzzyctl.ir.nodes import Ex, Int, Num, Var
from fuzzyctl.ir.state import CodegenError, Gen
from fuzzyctl.kinds import shapes as registry
from fuzzyctl.kinds import type_reduction as tr
from fuzzyctl.model import And, Condition, DefuzzifyBlock, FunctionBlock, Is, Not, Or, ShapeMF, Term

#: Output samples of a Mamdani output when none are asked for (MATLAB's OutputSampleNumber).
SAMPLES = 101
#: The PLC block's INFO when no rule fired for an output (as the type-1 block's).
INFO_DEFAULT = 0x02

Bounds = tuple[Ex, Ex]


@dataclass
class OutputInfo:
    """What the header of a generated block states about one output."""

    name: str
    kind: str  # "mamdani" or "sugeno"
    method: str
    points: int  # samples (Mamdani) or rule points (Sugeno)
    bound: int  # most iterations per end point


@dataclass
class Type2Build:
    """The inputs, outputs and per-output facts of a built type-2 evaluation."""

    inputs: list[Var]
    outputs: list[Var]
    info: list[OutputInfo] = field(default_factory=list)


def is_ts(term: Term) -> bool:
    mf = term.mf
    return isinstance(mf, ShapeMF) and (
        registry.flag(mf.kind, "ts_constant") or registry.flag(mf.kind, "ts_linear")
    )


class Type2Builder:
    """Builds one evaluation of a type-2 block into ``g`` (see the module docstring).
    ``inputs`` are the input variables in model order; ``outputs`` the output variables;
    ``method`` overrides every output's type-reduction method."""

    def __init__(self, fb: FunctionBlock, g: Gen, samples: int = SAMPLES, method: str | None = None) -> None:
        if samples < 2:
            raise CodegenError(f"samples: at least 2 output samples are needed, not {samples}")
        self.fb, self.g, self.samples, self.method = fb, g, samples, method
        block = fb.rule_blocks[0] if fb.rule_blocks else None
        if len(fb.rule_blocks) > 1:
            raise CodegenError("interval type-2 systems with more than one rule block are not supported")
        self.and_op, self.or_op = ops.resolve_pair(
            block.and_op if block else None, block.or_op if block else None
        )
        self.act = ops.resolve_act(block.act if block else None)
        self.accu = ops.resolve_accu(block.accu if block else None)
        self._degrees: dict[tuple[str, str], tuple[Ex, Ex]] = {}
        self._tables: dict[tuple[float, ...], Var] = {}
        self._found: Var | None = None

    # ------------------------------------------------------------------ tables

    def table(self, values: tuple[float, ...], hint: str) -> Var:
        """A constant REAL table (shared between equal ones)."""
        if values not in self._tables:
            self._tables[values] = self.g.declare(
                self.g.fresh(hint, hint), "REAL", "const", len(values), values
            )
        return self._tables[values]

    # ------------------------------------------------------------------ input degrees

    def _pwl(self, x: Ex, pts: sets.Points) -> Var:
        g = self.g
        xs = self.table(tuple(p[0] for p in pts), "PX")
        ys = self.table(tuple(p[1] for p in pts), "PY")
        if self._found is None:
            self._found = g.temp("BOOL", "FD")
        out = g.temp(hint="MU")
        T.pwl_value_fixed(g, xs, ys, 0, len(pts) - 1, x, out, self._found)
        return out

    def _smooth(self, mf: object, x: Ex, where: str) -> Ex:
        if not isinstance(mf, ShapeMF):
            raise CodegenError(f"{where}: {type(mf).__name__} terms are not supported in type-2 systems")
        params = sets.floats(mf.params, where)
        height = sets.floats([mf.height], where)[0]
        m = T.smooth(self.g, mf.kind, [Num(p) for p in params], x, where)
        return m if height == 1.0 else self.g.let(Num(height) * m, "MU")

    def _upper(self, term: Term, x: Ex, where: str) -> Ex:
        pts = sets.points_of(term.mf, where)
        return self._pwl(x, pts) if pts is not None else self._smooth(term.mf, x, where)

    def _lower(self, term: Term, x: Ex, upper: Ex, where: str) -> Ex:
        lower = term.lower
        if lower is None:
            return upper
        pts = sets.lower_points(term, where)
        if pts is not None:
            return self._pwl(x, pts)
        if lower.mf is not None:
            return self._smooth(lower.mf, x, where)
        left, right = sets.lags(lower, where)
        if left != right:
            raise CodegenError(f"{where}: two LowerLag values need a piecewise-linear upper function")
        # scale * max(0, (upper - lag) / (1 - lag)) as the engine computes it (_lagged)
        if left <= 0.0:
            return self.g.let(Num(lower.scale) * upper, "ML")
        v = self.g.let((upper - left) / (1.0 - left), "ML")
        with self.g.b.if_(Num(0.0).gt(v)):
            self.g.b.set(v, 0.0)
        self.g.b.set(v, Num(lower.scale) * v)
        return v

    def degree(self, variable: str, term_name: str, x: Ex) -> tuple[Ex, Ex]:
        key = (variable, term_name)
        if key not in self._degrees:
            fz = self.fb.fuzzify_block(variable)
            term = fz.term(term_name) if fz else None
            if term is None:
                raise CodegenError(f"no input term {variable}.{term_name}")
            where = f"term {variable}.{term_name}"
            self.g.b.comment(f"{where}: lower and upper degree")
            up = self._upper(term, x, where)
            self._degrees[key] = (self._lower(term, x, up, where), up)
        return self._degrees[key]

    # ------------------------------------------------------------------ firing

    def cond(self, c: Condition | None, x: dict[str, Ex]) -> tuple[Ex, Ex]:
        g = self.g
        if c is None:
            return Num(1.0), Num(1.0)
        if isinstance(c, Is):
            if c.variable not in x:
                raise CodegenError(f"no input {c.variable}")
            lo, up = self.degree(c.variable, c.term, x[c.variable])
            if c.hedges:
                lo, up = T.hedged(g, lo, c.hedges, False), T.hedged(g, up, c.hedges, False)
            return (g.let(1.0 - up, "N"), g.let(1.0 - lo, "N")) if c.negated else (lo, up)
        if isinstance(c, Not):
            lo, up = self.cond(c.operand, x)
            return g.let(1.0 - up, "N"), g.let(1.0 - lo, "N")
        if isinstance(c, And | Or):
            parts = [self.cond(o, x) for o in c.operands]
            lo, up = parts[0]
            for a, b in parts[1:]:
                if isinstance(c, And):
                    lo, up = T.tnorm(g, self.and_op, lo, a), T.tnorm(g, self.and_op, up, b)
                else:
                    lo, up = T.snorm(g, self.or_op, lo, a), T.snorm(g, self.or_op, up, b)
            return lo, up
        raise CodegenError(f"{type(c).__name__} conditions are not supported in type-2 systems")

    def firing(self, x: dict[str, Ex]) -> list[tuple[Var, Var]]:
        g = self.g
        out = []
        for _, rule in self.fb.rules():
            g.b.comment(f"RULE {rule.label}: firing interval")
            lo, up = self.cond(rule.condition, x)
            w = 1.0 if rule.weight is None else float(rule.weight)  # type: ignore[arg-type]
            out.append((g.let(lo * w, "FL"), g.let(up * w, "FU")))
        return out

    # ------------------------------------------------------------------ the whole evaluation

    def build(self, inputs: list[Var], outputs: list[Var], info: Var | None = None) -> Type2Build:
        fb, g = self.fb, self.g
        x: dict[str, Ex] = {v.name: var for v, var in zip(fb.inputs, inputs, strict=True)}
        fired = self.firing(x)
        result = Type2Build(inputs, outputs)
        for d, out in zip(fb.defuzzify, outputs, strict=True):
            method = self.method or d.type_reduction or tr.DEFAULT
            if method not in tr.METHODS:
                raise CodegenError(f"output {d.variable}: unknown type-reduction method {method!r}")
            ts = bool(d.terms) and all(is_ts(t) for t in d.terms)
            with g.b.region(f"output {d.variable}"):
                p = self.sugeno(d, fired, inputs) if ts else self.mamdani(d, fired)
                total = g.let(0.0, "SU")
                with g.b.for_(g.counter("K"), 0, p.n - 1) as k:
                    g.b.set(total, total + p.upper[k])
                with g.b.if_(total.gt(0.0)):
                    yl, yr = R.reduce(g, method, p)
                    g.b.set(out, 0.5 * (yl + yr))
                with g.b.else_():  # no upper weight: the DEFAULT (INFO says so)
                    dv = d.default.value if d.default is not None else None
                    g.b.set(out, literal(math.nan if dv is None else float(dv)))
                    if info is not None:
                        g.b.set(info, Int(INFO_DEFAULT))
            kind = "sugeno" if ts else "mamdani"
            result.info.append(OutputInfo(d.variable, kind, method, p.n, R.iterations(method, p.n)))
        return result

    # ------------------------------------------------------------------ outputs

    def _contribs(self, d: DefuzzifyBlock, fired: list[tuple[Var, Var]]) -> list[tuple[Term, Var, Var]]:
        out = []
        for (_, rule), (fl, fu) in zip(self.fb.rules(), fired, strict=True):
            for c in rule.conclusions:
                if c.weight is not None or c.hedges:
                    raise CodegenError(
                        f"rule {rule.label}: WITH weights and hedges of conclusions are not "
                        "supported in type-2 systems"
                    )
                if c.variable == d.variable and c.term is not None:
                    t = d.term(c.term)
                    if t is None:
                        raise CodegenError(f"rule {rule.label}: no output term {d.variable}.{c.term}")
                    out.append((t, fl, fu))
        return out

    def sugeno(self, d: DefuzzifyBlock, fired: list[tuple[Var, Var]], inputs: list[Var]) -> R.Points:
        g = self.g
        contribs = self._contribs(d, fired)
        n = max(1, len(contribs))
        zs: list[Ex] = []
        constant: list[float | None] = []
        for t, _fl, _fu in contribs:
            assert isinstance(t.mf, ShapeMF)
            cs = sets.floats(t.mf.params, f"term {d.variable}.{t.name}")
            if registry.flag(t.mf.kind, "ts_constant"):
                zs.append(Num(cs[0]))
                constant.append(cs[0])
                continue
            acc: Ex = Num(0.0)
            for c, v in zip(cs, inputs, strict=False):
                acc = acc + Num(c) * v
            if len(cs) > len(inputs):
                acc = acc + Num(cs[len(inputs)])
            zs.append(g.let(acc, "Z"))
            constant.append(None)
        order = list(range(len(contribs)))
        if all(c is not None for c in constant):  # constant points: sorted here (stable)
            order.sort(key=lambda i: constant[i])  # type: ignore[arg-type, return-value]
        xs, lo, up = (g.array(h, "REAL", n) for h in ("ZX", "ZL", "ZU"))
        if not contribs:
            g.b.set(up[0], 0.0)
        for k, i in enumerate(order):
            g.b.set(xs[k], zs[i])
            g.b.set(lo[k], contribs[i][1])
            g.b.set(up[k], contribs[i][2])
        if any(c is None for c in constant) and n > 1:
            self._sort(xs, lo, up, n)
        return R.Points(xs, lo, up, n)

    def _sort(self, xs: Var, lo: Var, up: Var, n: int) -> None:
        """Odd-even transposition sort by ``xs`` (``n`` rounds of compare-exchanges of
        neighbours with constant indices: stable, if-convertible)."""
        g = self.g
        t = g.temp(hint="SW")
        for r in range(n):
            for i in range(r % 2, n - 1, 2):
                with g.b.if_(xs[i].gt(xs[i + 1])):
                    for arr in (xs, lo, up):
                        g.b.set(t, arr[i])
                        g.b.set(arr[i], arr[i + 1])
                        g.b.set(arr[i + 1], t)

    def mamdani(self, d: DefuzzifyBlock, fired: list[tuple[Var, Var]]) -> R.Points:
        g, b = self.g, self.g.b
        if d.method is not None and not _centroid(d.method):
            raise CodegenError(
                f"output {d.variable}: interval type-2 Mamdani outputs are defuzzified by the "
                f"centroid after type reduction; {d.method} is not defined for them"
            )
        span = _span(d)
        n = self.samples
        ys = tuple(float(v) for v in np.linspace(span[0], span[1], n))
        xs = self.table(ys, "YS")
        agg_u, agg_l = g.array("AU", "REAL", n), g.array("AL", "REAL", n)
        with b.for_(g.counter("K"), 0, n - 1) as k:
            b.set(agg_u[k], 0.0)
            b.set(agg_l[k], 0.0)
        groups = self._merged(self._contribs(d, fired))
        for t, fl, fu in groups:
            where = f"term {d.variable}.{t.name}"
            tu = self.table(tuple(sets.mf_value(t.mf, y, where) for y in ys), "TU")
            tl = self.table(tuple(sets.lower_value(t, y, where) for y in ys), "TL")
            b.comment(f"{where}: activated on both bounds, aggregated")
            with b.if_(fu.gt(0.0)), b.for_(g.counter("K"), 0, n - 1) as k:
                T.accumulate_into(g, self.accu, agg_u[k], T.tnorm(g, self.act, fu, tu[k]))
                T.accumulate_into(g, self.accu, agg_l[k], T.tnorm(g, self.act, fl, tl[k]))
        return R.Points(xs, agg_l, agg_u, n)

    def _merged(self, contribs: list[tuple[Term, Var, Var]]) -> list[tuple[Term, Var, Var]]:
        """Under MAX the activations of one term merge into one (every t-norm is
        non-decreasing): the firing bounds' maxima."""
        # the only idempotent t-conorm is MAX: tested on the operators table's entry
        if not all(ops.accumulate(self.accu, v, v) == v for v in (0.25, 0.5, 0.75)):
            return contribs
        by_term: dict[str, list[tuple[Term, Var, Var]]] = {}
        for c in contribs:
            by_term.setdefault(c[0].name, []).append(c)
        out = []
        for cs in by_term.values():
            t, fl, fu = cs[0]
            if len(cs) > 1:
                fl, fu = self.g.let(fl, "HL"), self.g.let(fu, "HU")
                for _t, a, b in cs[1:]:
                    T.accumulate_into(self.g, self.accu, fl, a)
                    T.accumulate_into(self.g, self.accu, fu, b)
            out.append((t, fl, fu))
        return out


def _centroid(code: str) -> bool:
    from fuzzyctl.kinds import methods

    m = methods.method(code)
    return m.integrating and not m.bisects


def _span(d: DefuzzifyBlock) -> tuple[float, float]:
    if d.range is not None and d.range.low < d.range.high:
        return d.range.low, d.range.high
    raise CodegenError(f"output {d.variable}: a RANGE is needed to sample the output")
