"""Interval type-2 inference as MATLAB's ``mamfistype2`` / ``sugfistype2`` define it.

Each input term gives an interval ``[lower(x), upper(x)]``; a rule's firing interval is its
condition evaluated on the lower degrees and on the upper ones (AND/OR/NOT and hedges on
each bound: NOT swaps them, ``[1 - upper, 1 - lower]``), times its weight.

* Mamdani: implication on both bounds (``act(f_lower, lower_t)``, ``act(f_upper,
  upper_t)``), aggregation on both bounds, then the centroid interval ``[yl, yr]`` of the
  aggregated interval set and the output ``(yl + yr) / 2``.  On piecewise-linear output
  sets with MIN/PROD implication and MAX aggregation the centroid interval is exact
  (:func:`fuzzyctl.engine.type2_sets.centroid_interval`, every type-reduction method gives
  it); otherwise, or when ``samples`` is given (MATLAB's ``OutputSampleNumber``, 101 by
  default there), the set is sampled at that many points of the output range (default
  :data:`SAMPLES`) and the system's type-reduction method runs on the samples.
* Sugeno: each rule's crisp output ``z`` (constant or linear) with its firing interval;
  the type-reduction method gives ``[yl, yr]`` of these points, the output is the mean.

When no rule fires an output takes its DEFAULT (else NaN).  :class:`Type2Controller` is the
python path (one row at a time; ``evaluate_batch`` loops); ``compile(..., backend="native")``
and ``compile(..., samples=N)`` evaluate the IR program instead
(:class:`fuzzyctl.engine.type2_compiled.Type2Compiled`: C, or Python and numpy batches).
"""

from __future__ import annotations

import itertools
import math
from collections.abc import Mapping
from dataclasses import dataclass
from typing import Any

import numpy as np

from fuzzyctl.diagnostics import FuzzyctlError
from fuzzyctl.engine import type2_sets as sets
from fuzzyctl.engine.ranges import check_values
from fuzzyctl.engine.semantics import operators as ops
from fuzzyctl.engine.semantics import shapes as sem
from fuzzyctl.kinds import methods, norms
from fuzzyctl.kinds import shapes as registry
from fuzzyctl.kinds import type_reduction as tr
from fuzzyctl.model import And, Condition, DefuzzifyBlock, FunctionBlock, Is, Not, Or, Rule, ShapeMF, Term

#: Output samples when the centroid interval cannot be found exactly.
SAMPLES = 1001
Bounds = tuple[float, float]


class Type2Unsupported(FuzzyctlError):
    """A type-2 system using something this engine does not evaluate (said once, clearly)."""


@dataclass(frozen=True)
class RuleInterval:
    label: str
    lower: float
    upper: float


@dataclass(frozen=True)
class OutputInterval:
    name: str
    value: float
    yl: float
    yr: float
    method: str
    exact: bool


@dataclass(frozen=True)
class Type2Explanation:
    """What :meth:`Type2Controller.explain` shows: firing intervals and type-reduced intervals."""

    inputs: dict[str, float]
    rules: tuple[RuleInterval, ...]
    outputs: tuple[OutputInterval, ...]

    @property
    def values(self) -> dict[str, float]:
        return {o.name: o.value for o in self.outputs}

    def to_dict(self) -> dict[str, Any]:
        return {
            "inputs": self.inputs,
            "rules": [{"label": r.label, "firing": [r.lower, r.upper]} for r in self.rules],
            "outputs": [
                {
                    "name": o.name,
                    "value": o.value,
                    "interval": [o.yl, o.yr],
                    "type_reduction": o.method,
                    "exact": o.exact,
                }
                for o in self.outputs
            ],
        }

    def text(self) -> str:
        lines = [
            "inputs: " + ", ".join(f"{k} = {v:g}" for k, v in self.inputs.items()),
            "rules (firing interval):",
        ]
        lines += [f"  {r.label}: [{r.lower:.6g}, {r.upper:.6g}]" for r in self.rules]
        lines.append("outputs (type-reduced interval -> value):")
        lines += [
            f"  {o.name}: [{o.yl:.6g}, {o.yr:.6g}] -> {o.value:.6g}  ({o.method}, {_how(o.exact)})"
            for o in self.outputs
        ]
        return "\n".join(lines)


def _how(exact: bool) -> str:
    return "exact" if exact else "sampled"


def _centroid(code: str | None) -> bool:
    """The method is the centroid of the set (MATLAB's only type-2 Mamdani defuzzification)."""
    m = methods.method(code) if code is not None else None
    return m is None or (m.integrating and not m.bisects)


def _average(code: str | None) -> bool:
    """The method is the weighted average of rule outputs (MATLAB's type-2 Sugeno output)."""
    return code is None or methods.method(code).weighted == "average"


def _norms(fb: FunctionBlock) -> tuple[str, str, str, str]:
    block = fb.rule_blocks[0] if fb.rule_blocks else None
    and_op, or_op = ops.resolve_pair(block.and_op if block else None, block.or_op if block else None)
    act = ops.resolve_act(block.act if block else None)
    accu = ops.resolve_accu(block.accu if block else None)
    return and_op, or_op, act, accu


def _is_ts(term: Term) -> bool:
    mf = term.mf
    return isinstance(mf, ShapeMF) and (
        registry.flag(mf.kind, "ts_constant") or registry.flag(mf.kind, "ts_linear")
    )


@dataclass(frozen=True)
class InputSpec:
    """An input as the data-file evaluation asks for it (type-2 inputs have no default)."""

    name: str
    default: float | None = None


@dataclass(frozen=True)
class Type2Plan:
    """What a type-2 controller shows of its plan: its inputs."""

    inputs: tuple[InputSpec, ...]


class Type2Controller:
    """Evaluates an interval type-2 function block (see the module docstring)."""

    def __init__(self, fb: FunctionBlock, *, samples: int | None = None, method: str | None = None) -> None:
        _check_samples(samples)
        self.model = fb
        self.name = fb.name
        self.plan = Type2Plan(tuple(InputSpec(v.name) for v in fb.inputs))
        self.samples = samples
        self.method_override = method
        self.inputs = {v.name: v for v in fb.inputs}
        self.outputs = {v.name: v for v in fb.outputs}
        self.warnings: tuple[Any, ...] = ()
        self.out_of_range = "warn"
        self.input_ranges: dict[str, tuple[float, float]] = {
            f.variable: (f.range.low, f.range.high)
            for f in fb.fuzzify
            if f.range is not None and f.range.low < f.range.high
        }
        self.and_op, self.or_op, self.act, self.accu = _norms(fb)
        if len(fb.rule_blocks) > 1:
            raise Type2Unsupported("interval type-2 systems with more than one rule block are not supported")
        self._check()
        # the breakpoints of every term's upper and lower function (None: smooth), once
        self._points: dict[int, tuple[sets.Points | None, sets.Points | None]] = {
            id(t): (sets.points_of(t.mf, t.name), sets.lower_points(t, t.name))
            for terms in (*(f.terms for f in fb.fuzzify), *(d.terms for d in fb.defuzzify))
            for t in terms
            if not _is_ts(t)
        }

    # ------------------------------------------------------------------ checks
    def _check(self) -> None:
        for f in self.model.fuzzify:
            rng = (f.range.low, f.range.high) if f.range else (-1.0, 1.0)
            for t in f.terms:
                problem = sets.lower_problem(t, rng, f"term {f.variable}.{t.name}")
                if problem:
                    raise Type2Unsupported(problem)
        for d in self.model.defuzzify:
            if d.type_reduction is not None and d.type_reduction not in tr.METHODS:
                raise Type2Unsupported(
                    f"output {d.variable}: unknown type-reduction method {d.type_reduction!r}"
                )
            ts = [_is_ts(t) for t in d.terms]
            if any(ts) and not all(ts):
                raise Type2Unsupported(f"output {d.variable} mixes Takagi-Sugeno terms with fuzzy sets")
            if not all(ts):
                if not _centroid(d.method):
                    raise Type2Unsupported(
                        f"output {d.variable}: interval type-2 Mamdani outputs are defuzzified by the "
                        f"centroid after type reduction; {d.method} is not defined for them"
                    )
                rng = self._span(d)
                for t in d.terms:
                    problem = sets.lower_problem(t, rng, f"term {d.variable}.{t.name}")
                    if problem:
                        raise Type2Unsupported(problem)
            elif not _average(d.method):
                raise Type2Unsupported(
                    f"output {d.variable}: interval type-2 Sugeno outputs are the weighted average after "
                    f"type reduction; {d.method} is not defined for them"
                )
        for _, rule in self.model.rules():
            for c in rule.conclusions:
                if c.weight is not None or c.hedges:
                    raise Type2Unsupported(
                        f"rule {rule.label}: WITH weights and hedges of conclusions are not "
                        "supported in type-2 systems"
                    )

    def _span(self, d: DefuzzifyBlock) -> Bounds:
        if d.range is not None:
            return d.range.low, d.range.high
        lo, hi = math.inf, -math.inf
        for t in d.terms:
            if isinstance(t.mf, ShapeMF):
                a, b = sem.support(t.mf.kind, [float(p) for p in t.mf.params])  # type: ignore[arg-type]
            else:
                pts = sets.points_of(t.mf, t.name) or ((0.0, 0.0),)
                a, b = pts[0][0], pts[-1][0]
            lo, hi = min(lo, a), max(hi, b)
        if not (math.isfinite(lo) and math.isfinite(hi)) or hi <= lo:
            raise Type2Unsupported(f"output {d.variable} needs a RANGE")
        return lo, hi

    # ------------------------------------------------------------------ firing
    def _degree(self, c: Condition | None, x: Mapping[str, float]) -> Bounds:
        if c is None:
            return 1.0, 1.0
        if isinstance(c, Is):
            fz = self.model.fuzzify_block(c.variable)
            term = fz.term(c.term) if fz else None
            if term is None:
                raise Type2Unsupported(f"no input term {c.variable}.{c.term}")
            lo, up = self._bounds(term, x[c.variable], f"term {c.variable}.{c.term}")
            for h in reversed(c.hedges):
                f = sem.hedge_function(h)
                lo, up = f(lo), f(up)
            return (1.0 - up, 1.0 - lo) if c.negated else (lo, up)
        if isinstance(c, Not):
            lo, up = self._degree(c.operand, x)
            return 1.0 - up, 1.0 - lo
        if isinstance(c, And | Or):
            norm = (ops.TNORMS[self.and_op] if isinstance(c, And) else ops.SNORMS[self.or_op]).scalar
            parts = [self._degree(o, x) for o in c.operands]
            lo, up = parts[0]
            for a, b in parts[1:]:
                lo, up = norm(lo, a), norm(up, b)
            return lo, up
        raise Type2Unsupported(f"{type(c).__name__} conditions are not supported in type-2 systems")

    def _bounds(self, term: Term, x: float, where: str) -> Bounds:
        """``[lower(x), upper(x)]`` of an input term."""
        up_pts, lo_pts = self._points.get(id(term), (None, None))
        up = sem.pwl_value(up_pts, x) if up_pts is not None else sets.mf_value(term.mf, x, where)
        lo = sem.pwl_value(lo_pts, x) if lo_pts is not None else sets.lower_value(term, x, where)
        return lo, up

    def firing(self, x: Mapping[str, float]) -> list[tuple[Rule, Bounds]]:
        out = []
        for _, rule in self.model.rules():
            lo, up = self._degree(rule.condition, x)
            w = 1.0 if rule.weight is None else float(rule.weight)  # type: ignore[arg-type]
            out.append((rule, (lo * w, up * w)))
        return out

    # ------------------------------------------------------------------ outputs
    def _method(self, d: DefuzzifyBlock) -> str:
        return self.method_override or d.type_reduction or tr.DEFAULT

    def _sugeno(
        self, d: DefuzzifyBlock, x: Mapping[str, float], fired: list[tuple[Rule, Bounds]]
    ) -> OutputInterval:
        zs, lo, up = [], [], []
        values = [x[v] for v in self.inputs]
        for rule, (fl, fu) in fired:
            for c in rule.conclusions:
                if c.variable != d.variable or c.term is None or fu <= 0.0:
                    continue
                t = d.term(c.term)
                assert t is not None and isinstance(t.mf, ShapeMF)
                cs = [float(p) for p in t.mf.params]  # type: ignore[arg-type]
                z = (
                    cs[0]
                    if registry.flag(t.mf.kind, "ts_constant")
                    else (
                        math.fsum(a * b for a, b in zip(cs, values, strict=False))
                        + (cs[len(values)] if len(cs) > len(values) else 0.0)
                    )
                )
                zs.append(z)
                lo.append(fl)
                up.append(fu)
        method = self._method(d)
        yl, yr = tr.implementation(method)(zs, lo, up) if zs else (math.nan, math.nan)
        return self._finish(d, yl, yr, method, True)

    def _mamdani(self, d: DefuzzifyBlock, fired: list[tuple[Rule, Bounds]]) -> OutputInterval:
        span = self._span(d)
        parts = []
        for rule, (fl, fu) in fired:
            for c in rule.conclusions:
                if c.variable == d.variable and c.term is not None and fu > 0.0:
                    t = d.term(c.term)
                    assert t is not None
                    parts.append((t, fl, fu))
        method = self._method(d)
        if not parts:
            return self._finish(d, math.nan, math.nan, method, True)
        exact = self.samples is None and norms.is_max(self.accu) and norms.keeps_lines(self.act)
        pieces = [self._pwl(d, t, fl, fu) for t, fl, fu in parts] if exact else []
        if exact and all(p is not None for p in pieces):
            yl, yr = self._exact(span, pieces)  # type: ignore[arg-type]
            return self._finish(d, yl, yr, method, True)
        n = self.samples or SAMPLES
        ys = np.linspace(span[0], span[1], n)
        agg_u, agg_l = np.zeros(n), np.zeros(n)
        act = ops.TNORMS[self.act].scalar
        for t, fl, fu in parts:
            where = f"term {d.variable}.{t.name}"
            u = np.array([act(fu, sets.mf_value(t.mf, float(y), where)) for y in ys])
            lo = np.array([act(fl, sets.lower_value(t, float(y), where)) for y in ys])
            agg_u, agg_l = ops.accumulate_np(self.accu, agg_u, u), ops.accumulate_np(self.accu, agg_l, lo)
        yl, yr = tr.implementation(method)(ys.tolist(), agg_l.tolist(), agg_u.tolist())
        return self._finish(d, yl, yr, method, False)

    def _pwl(
        self, d: DefuzzifyBlock, t: Term, fl: float, fu: float
    ) -> tuple[sets.Points, sets.Points] | None:
        where = f"term {d.variable}.{t.name}"
        up, lo = self._points.get(id(t)) or (sets.points_of(t.mf, where), sets.lower_points(t, where))
        if up is None or lo is None:
            return None
        return _activated(up, fu, self.act), _activated(lo, fl, self.act)

    def _exact(self, span: Bounds, pieces: list[tuple[sets.Points, sets.Points]]) -> Bounds:
        a, b = span
        cuts = {a, b}
        for up, lo in pieces:
            cuts.update(x for x, _ in (*up, *lo) if a < x < b)
        grid = sorted(cuts)
        xs: list[float] = []
        upper: list[Bounds] = []
        lower: list[Bounds] = []
        for x0, x1 in itertools.pairwise(grid):
            if x1 <= x0:
                continue
            su = [sets.segment_values(p[0], x0, x1) for p in pieces]
            sl = [sets.segment_values(p[1], x0, x1) for p in pieces]
            inner = sorted(set(_crossings(x0, x1, su)) | set(_crossings(x0, x1, sl)))
            edges = [x0, *inner, x1]
            for e0, e1 in itertools.pairwise(edges):
                xs.append(e0)
                upper.append(_envelope(x0, x1, su, e0, e1))
                lower.append(_envelope(x0, x1, sl, e0, e1))
        xs.append(grid[-1])
        return sets.centroid_interval(xs, upper, lower)

    def _finish(self, d: DefuzzifyBlock, yl: float, yr: float, method: str, exact: bool) -> OutputInterval:
        value = 0.5 * (yl + yr)
        if math.isnan(value) and d.default is not None and d.default.value is not None:
            value = d.default.value
        return OutputInterval(d.variable, value, yl, yr, method, exact)

    # ------------------------------------------------------------------ public
    def _values(self, inputs: Mapping[str, Any], mode: str | None = None) -> dict[str, float]:
        unknown = set(inputs) - set(self.inputs)
        if unknown:
            raise FuzzyctlError(
                f"unknown input(s) {', '.join(sorted(unknown))} (inputs: {', '.join(self.inputs)})"
            )
        missing = [n for n in self.inputs if n not in inputs]
        if missing:
            raise FuzzyctlError(f"missing input(s) {', '.join(missing)}")
        names = tuple(self.inputs)
        values = check_values(
            self.input_ranges, names, [float(inputs[n]) for n in names], mode or self.out_of_range
        )
        return dict(zip(names, values, strict=True))

    def explain(
        self, inputs: Mapping[str, Any] | None = None, *, out_of_range: str | None = None, **kw: Any
    ) -> Type2Explanation:
        """Evaluate once and show the firing interval of every rule and the type-reduced
        interval of every output.  ``out_of_range`` as for type-1 controllers."""
        x = self._values({**(inputs or {}), **kw}, out_of_range)
        fired = self.firing(x)
        outs = []
        for d in self.model.defuzzify:
            ts = bool(d.terms) and all(_is_ts(t) for t in d.terms)
            outs.append(self._sugeno(d, x, fired) if ts else self._mamdani(d, fired))
        rules = tuple(RuleInterval(r.label, lo, up) for r, (lo, up) in fired)
        return Type2Explanation(x, rules, tuple(outs))

    def evaluate(
        self, inputs: Mapping[str, Any] | None = None, *, out_of_range: str | None = None, **kw: Any
    ) -> dict[str, float]:
        return self.explain(inputs, out_of_range=out_of_range, **kw).values

    def evaluate_batch(
        self, data: Any, *, out_of_range: str | None = None, rows: int | None = None, **options: Any
    ) -> dict[str, np.ndarray]:
        """Evaluate every row of ``data`` (input name -> sequence), one row at a time (type-2
        has no vectorised path yet).  ``chunk`` / ``on_invalid`` of type-1 controllers are
        accepted; an invalid row raises."""
        cols = {k: np.asarray(data[k], dtype=float) for k in self.inputs}
        n = len(next(iter(cols.values()))) if cols else int(rows or 0)
        out = {name: np.empty(n) for name in self.outputs}
        for i in range(n):
            x = {k: v[i] for k, v in cols.items()}
            if not all(math.isfinite(v) for v in x.values()) and options.get("on_invalid") == "nan":
                for name in out:
                    out[name][i] = math.nan
                continue
            row = self.evaluate(x, out_of_range=out_of_range)
            for name, v in row.items():
                out[name][i] = v
        return out

    def reset(self) -> None:
        """(No state: a type-2 system has no NC/hold outputs.)"""

    def __repr__(self) -> str:
        return (
            f"<Type2Controller {self.model.name!r}: {len(self.inputs)} inputs, {len(self.outputs)} outputs>"
        )


def _activated(points: sets.Points, f: float, act: str) -> sets.Points:
    """``act(f, mu)`` of a breakpoint list (MIN clips, cutting segments at the level)."""
    if norms.is_prod(act):
        return tuple((x, f * y) for x, y in points)
    out: list[tuple[float, float]] = []
    for i, (x, y) in enumerate(points):
        if i > 0:
            x0, y0 = points[i - 1]
            if (y0 - f) * (y - f) < 0.0 and x != x0:
                out.append((x0 + (x - x0) * (f - y0) / (y - y0), f))
        out.append((x, min(y, f)))
    return tuple(out)


def _crossings(a: float, b: float, lines: list[Bounds]) -> list[float]:
    """Where two of the lines (values at a and b) cross strictly inside (a, b)."""
    out = []
    for i in range(len(lines)):
        for j in range(i + 1, len(lines)):
            da = lines[i][0] - lines[j][0]
            db = lines[i][1] - lines[j][1]
            if da * db < 0.0:
                out.append(a + (b - a) * da / (da - db))
    return out


def _envelope(a: float, b: float, lines: list[Bounds], e0: float, e1: float) -> Bounds:
    """The maximum of the lines over [e0, e1] (no crossing inside), as values at its ends."""

    def at(line: Bounds, x: float) -> float:
        return line[0] + (line[1] - line[0]) * (x - a) / (b - a)

    mid = 0.5 * (e0 + e1)
    best = max(lines, key=lambda line: at(line, mid))
    return at(best, e0), at(best, e1)


def _check_samples(samples: object) -> None:
    """A sample count is a whole number of at least 2 (0 once fell back to the default)."""
    if samples is None:
        return
    if isinstance(samples, bool) or not isinstance(samples, int) or samples < 2:
        raise ValueError(f"samples={samples!r}: give a whole number of output samples, at least 2")


def compile_type2(fb: FunctionBlock, backend: str | None = None, **options: Any) -> Type2Controller:
    """The controller of a type-2 block; a backend whose record says it cannot evaluate
    type-2 systems is refused (:func:`fuzzyctl.kinds.type_reduction.refusal`)."""
    why = tr.refusal(backend or "auto")
    if why:
        raise Type2Unsupported(why)
    samples, method = options.get("samples"), options.get("type_reduction")
    _check_samples(samples)
    if backend == "native" or (backend in (None, "auto", "python") and samples is not None):
        # the IR evaluator (fuzzyctl.engine.type2_compiled): C, or Python and numpy
        from fuzzyctl.engine.type2_compiled import Type2Compiled

        kind = "native" if backend == "native" else "python"
        return Type2Compiled(fb, kind, samples=samples, method=method)
    return Type2Controller(fb, samples=samples, method=method)
