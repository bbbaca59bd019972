"""Lowering of parameters, function expressions and terms (used by :mod:`~fuzzyctl.engine.lowering.lower`)."""

from __future__ import annotations

import itertools
import math
import sys
from collections.abc import Iterable
from dataclasses import dataclass, field

from fuzzyctl import model as m
from fuzzyctl.diagnostics import Diagnostic, error, warning
from fuzzyctl.engine.plan import (
    EX,
    EBinary,
    ECall,
    EInput,
    ENum,
    EOutput,
    EUnary,
    ExprPlan,
    Options,
    PParam,
    Slot,
    TermPlan,
    expr_nodes,
)
from fuzzyctl.engine.semantics import shapes
from fuzzyctl.kinds import shapes as registry

FUNCTIONS = frozenset(
    [
        "sin",
        "cos",
        "tan",
        "asin",
        "acos",
        "atan",
        "sinh",
        "cosh",
        "tanh",
        "exp",
        "log",
        "log10",
        "ln",
        "sqrt",
        "abs",
        "fabs",
        "floor",
        "ceil",
        "round",
        "pow",
        "min",
        "max",
        "atan2",
        "fmod",
        "sign",
        "eq",
        "neq",
        "lt",
        "le",
        "gt",
        "ge",
    ]
)
CONSTANTS = {"pi": math.pi, "e": math.e}


@dataclass
class LowerContext:
    fb: m.FunctionBlock
    options: Options
    diags: list[Diagnostic] = field(default_factory=list)
    slots: dict[str, int] = field(default_factory=dict)
    constants: dict[str, float] = field(default_factory=dict)
    # FUZZIFY variable -> {term name: index of its first term of that name}
    term_index: dict[str, dict[str, int]] = field(default_factory=dict)

    def fuzzy_terms(self, variable: str) -> dict[str, int]:
        """The terms of FUZZIFY ``variable`` by name (the first of a repeated name), once
        per variable: a large rule base asks once per subcondition."""
        index = self.term_index.get(variable)
        if index is None:
            index = {}
            fz = self.fb.fuzzify_block(variable)
            for t in fz.terms if fz is not None else ():
                index.setdefault(t.name, len(index))
            self.term_index[variable] = index
        return index

    def err(self, msg: str, span: m.Span | None, code: str, hint: str | None = None) -> None:
        self.diags.append(error(msg, span, code=code, hint=hint))

    def warn(self, msg: str, span: m.Span | None, code: str) -> None:
        self.diags.append(warning(msg, span, code=code))


# --------------------------------------------------------------------------- parameters and terms


def lower_param(ctx: LowerContext, p: m.Param, where: str, allow_infinite: bool = False) -> PParam | None:
    if isinstance(p, m.Ref):
        if p.name in ctx.slots:
            return Slot(ctx.slots[p.name])
        if p.name in ctx.constants:
            return ctx.constants[p.name]
        ctx.err(
            f"{where}: parameter {p.name!r} is not a VAR_INPUT (only inputs can give values at run time)",
            p.span,
            "param-not-input",
        )
        return None
    v = float(p)
    if math.isnan(v) or (math.isinf(v) and not allow_infinite):
        ctx.err(f"{where}: parameter {v} is not a finite number", None, "param-not-finite")
        return None
    if v != 0.0 and abs(v) < sys.float_info.min:
        # a subnormal number (1e-320) is 0 for any shape, but a piece that wide divides to
        # inf: the centroid became NaN on one backend and a compile error on another
        return 0.0
    return v


def _expr(
    ctx: LowerContext,
    e: m.Expr,
    where: str,
    outputs: dict[str, int],
    allow_x: bool,
    argument: str | None = None,
) -> ExprPlan | None:
    """Lower an expression.  ``argument`` (model ``FunctionMF.argument``) names the point a
    membership function is evaluated at and wins over a variable of that name (fuzzylite
    binds ``x`` last); without it, ``x`` is the point when no variable is called so."""
    if isinstance(e, m.Num):
        return ENum(float(e.value))
    if isinstance(e, m.Name):
        if argument is not None and e.name == argument:
            return EX()
        if e.name in ctx.slots:
            return EInput(ctx.slots[e.name])
        if e.name in outputs:
            return EOutput(outputs[e.name])
        if e.name in ctx.constants:
            return ENum(ctx.constants[e.name])
        if allow_x and e.name == "x":
            return EX()
        if e.name.lower() in CONSTANTS:
            return ENum(CONSTANTS[e.name.lower()])
        ctx.err(
            f"{where}: function refers to {e.name!r}, which is not an input or output", None, "function-name"
        )
        return None
    if isinstance(e, m.Unary):
        inner = _expr(ctx, e.operand, where, outputs, allow_x, argument)
        return EUnary(e.op, inner) if inner is not None else None
    if isinstance(e, m.Binary):
        if e.op not in {"+", "-", "*", "/", "^", "%"}:
            ctx.err(f"{where}: unknown operator {e.op!r} in function", None, "function-op")
            return None
        left = _expr(ctx, e.left, where, outputs, allow_x, argument)
        right = _expr(ctx, e.right, where, outputs, allow_x, argument)
        return EBinary(e.op, left, right) if left is not None and right is not None else None
    fname = e.function.lower()
    if fname not in FUNCTIONS:
        ctx.err(f"{where}: unknown function {e.function!r}", None, "function-unknown")
        return None
    args = [_expr(ctx, a, where, outputs, allow_x, argument) for a in e.args]
    if any(a is None for a in args):
        return None
    return ECall(fname, tuple(a for a in args if a is not None))


def lower_term(
    ctx: LowerContext, t: m.Term, var: str, outputs: dict[str, int], is_output: bool
) -> TermPlan | None:
    where = f"term {var}.{t.name}"
    mf = t.mf
    if isinstance(mf, m.PointsMF):
        if not mf.points:
            ctx.err(f"{where} has no points", t.span, "term-empty")
            return None
        raw: list[PParam | None] = []
        for pt in mf.points:
            raw += [lower_param(ctx, pt.x, where), lower_param(ctx, pt.y, where)]
        if any(p is None for p in raw):
            return None
        params = tuple(p for p in raw if p is not None)
        tp = TermPlan(t.name, "points", params)
    elif isinstance(mf, m.SingletonMF):
        v = lower_param(ctx, mf.value, where)
        if v is None:
            return None
        tp = TermPlan(t.name, "singleton", (v,))
    elif isinstance(mf, m.SingletonsMF):
        raw = []
        for pt in mf.points:
            raw += [lower_param(ctx, pt.x, where), lower_param(ctx, pt.y, where)]
        if any(p is None for p in raw) or not raw:
            if not raw:
                ctx.err(f"{where} has no points", t.span, "term-empty")
            return None
        tp = TermPlan(t.name, "singletons", tuple(p for p in raw if p is not None))
    elif isinstance(mf, m.ShapeMF):
        spec = m.SHAPES.get(mf.kind)
        if spec is None:
            ctx.err(f"{where}: unknown shape {mf.kind!r}", t.span, "shape-unknown")
            return None
        if not spec.variadic and len(mf.params) != len(spec.params):
            ctx.err(
                f"{where}: {mf.kind} takes {len(spec.params)} parameters "
                f"({', '.join(spec.params)}), got {len(mf.params)}",
                t.span,
                "shape-arity",
            )
            return None
        # infinite vertices are MATLAB/fuzzylite shoulders; fuzzylite's Binary points to +-inf
        raw = [lower_param(ctx, p, where, i in spec.infinite) for i, p in enumerate(mf.params)]
        h = lower_param(ctx, mf.height, where)
        if any(p is None for p in raw) or h is None:
            return None
        params = tuple(p for p in raw if p is not None)
        if spec.takagi_sugeno and not is_output:
            ctx.err(
                f"{where}: {mf.kind} terms are Takagi-Sugeno outputs, not input sets", t.span, "ts-on-input"
            )
            return None
        tp = TermPlan(t.name, mf.kind, params, h)
        tp = _unordered_vertices(ctx, tp, t.span, where)
        _check_shape(ctx, tp, t.span, where)
    else:
        ex = _expr(ctx, mf.expr, where, outputs if is_output else {}, True, mf.argument)
        if ex is None:
            return None
        tp = TermPlan(t.name, "function", (), 1.0, ex)
    if tp.constant and tp.kind in shapes.PWL_KINDS:
        pts = shapes.pwl_points(
            tp.kind,
            [float(p) for p in tp.params if not isinstance(p, Slot)],
            float(tp.height) if not isinstance(tp.height, Slot) else 1.0,
        )
        tp = TermPlan(tp.name, tp.kind, tp.params, tp.height, tp.expr, pts)
    return tp


def _unordered_vertices(ctx: LowerContext, tp: TermPlan, span: m.Span | None, where: str) -> TermPlan:
    """A triangle or trapezoid whose vertices are not in ascending order (node-fuzzylite's
    ``Trapezoid 1 0 2 3``) is read as fuzzylite reads it - its formula compares x with each
    vertex in turn - with a warning; jFuzzyLogic refuses it, and so does its profile."""
    if registry.vertices(tp.kind) is None or not tp.constant:  # triangle, trapezoid
        return tp
    p = [float(v) for v in tp.params if not isinstance(v, Slot)]
    if p == sorted(p) or not all(math.isfinite(v) for v in p) or ctx.options.emulate == "jfuzzylogic":
        return tp
    pts = fuzzylite_vertices(tp.kind, p)
    ctx.warn(
        f"{where}: {tp.kind} {' '.join(f'{v:g}' for v in p)} has its vertices out of order; read as "
        "fuzzylite reads it: " + " ".join(f"({x:g}, {y:g})" for x, y in pts),
        span,
        "shape-unordered",
    )
    params: tuple[PParam, ...] = tuple(v for x, y in pts for v in (x, y))
    return TermPlan(tp.name, "points", params, tp.height)


def fuzzylite_vertices(kind: str, p: list[float]) -> list[tuple[float, float]]:
    """The points of fuzzylite's Triangle / Trapezoid formula for any vertex order: between
    two successive vertices the same branch of the formula holds, and it is linear."""

    def branch(x: float) -> tuple[float, float, float] | None:  # (x0, y0, slope) of the branch at x
        if len(p) == 3:  # the triangle's a, b, c (else the trapezoid's a, b, c, d)
            a, b, c = p
            if x < a or x > c:
                return None
            return (a, 0.0, 1.0 / (b - a)) if x < b else (c, 0.0, -1.0 / (c - b))
        a, b, c, d = p
        if x < a or x > d:
            return None
        if x < b:
            return (a, 0.0, 1.0 / (b - a))
        if x <= c:
            return (x, 1.0, 0.0)
        return (d, 0.0, -1.0 / (d - c))

    xs = sorted(set(p))
    pts: list[tuple[float, float]] = []
    for lo, hi in itertools.pairwise(xs):
        got = branch(0.5 * (lo + hi))
        if got is None:
            ys = (0.0, 0.0)
        else:
            x0, y0, slope = got
            ys = (y0 + slope * (lo - x0), y0 + slope * (hi - x0)) if slope else (y0, y0)
        pts += [(lo, ys[0]), (hi, ys[1])]
    out: list[tuple[float, float]] = []
    for pt in pts:  # drop repeated points (a vertical edge keeps its two values)
        if not out or out[-1] != pt:
            out.append(pt)
    return out


def _check_shape(ctx: LowerContext, tp: TermPlan, span: m.Span | None, where: str) -> None:
    if not tp.constant:
        return
    p = [float(v) for v in tp.params if not isinstance(v, Slot)]
    shape = registry.SHAPES.get(tp.kind)
    rule = shape.degenerate if shape is not None else None
    bad = rule.text if isinstance(rule, registry.Degenerate) and rule.bad(p) else None
    if bad:
        ctx.err(f"{where}: {tp.kind} {bad}", span, "shape-params")


def first_terms(ctx: LowerContext, var: str, terms: Iterable[m.Term]) -> list[m.Term]:
    """Terms in declaration order; a repeated name keeps its first definition (as fuzzylite
    C++ does; jFuzzyLogic, and its profile, the last) and is reported."""
    last = ctx.options.emulate == "jfuzzylogic"
    seen: dict[str, int] = {}
    out: list[m.Term] = []
    for t in terms:
        if t.name in seen:
            ctx.warn(
                f"term {t.name!r} of {var} is defined twice; the {'last' if last else 'first'} "
                "definition is used",
                t.span,
                "duplicate-term",
            )
            if last:
                out[seen[t.name]] = t
            continue
        seen[t.name] = len(out)
        out.append(t)
    return out


def uses_x(e: ExprPlan | None) -> bool:
    """Whether a function term reads ``x``: then it is a membership function of x (fuzzylite
    Function as a fuzzy set), not a Takagi-Sugeno value."""
    return e is not None and any(isinstance(node, EX) for node in expr_nodes(e))
