"""Formulas in the IR: fuzzy operators (translated from the engine's own expression templates),
hedges, smooth membership functions (translated from the shape registry's formulas), function
terms, and the run-time routines on breakpoint lists (stable sort, degree, one-sided limits)
the exact integration needs.

Operators are not rewritten by hand: :data:`fuzzyctl.engine.semantics.operators.TNORMS` and ``SNORMS``
carry each norm as a Python expression template, and :func:`norm` translates that template
(conditional expressions, comparisons, ``min``/``max``) into IR statements, so a norm changed
in the engine changes here too.
"""

from __future__ import annotations

import ast
from collections.abc import Callable

from fuzzyctl.engine.plan import EX, EBinary, ECall, EInput, ENum, EOutput, EUnary, ExprPlan
from fuzzyctl.engine.semantics.operators import SNORMS, TNORMS
from fuzzyctl.engine.semantics.shapes import Points, power_of
from fuzzyctl.ir.nodes import Bin, Ex, ExLike, Index, Neg, Num, Var, ex, not_
from fuzzyctl.ir.state import Gen
from fuzzyctl.kinds import norms
from fuzzyctl.kinds import shapes as registry
from fuzzyctl.kinds.formula import Formula

# The two helpers the Hamacher templates call, as templates themselves (operators._ham_t/_s).
_HELPERS = {
    "_ham_t": "(({a} * {b}) / ({a} + {b} - {a} * {b}) if {a} + {b} - {a} * {b} != 0.0 else 0.0)",
    # 1 - T(1-a, 1-b), the stable form of (a+b-2ab)/(1-ab) (see operators._ham_s)
    "_ham_s": "(1.0 - ((1.0 - {a}) * (1.0 - {b})) / ((1.0 - {a}) + (1.0 - {b}) - (1.0 - {a}) * (1.0 - {b}))"
    " if (1.0 - {a}) + (1.0 - {b}) - (1.0 - {a}) * (1.0 - {b}) != 0.0 else 1.0)",
}
_BINOPS = {ast.Add: "+", ast.Sub: "-", ast.Mult: "*", ast.Div: "/"}
_CMPOPS = {ast.Lt: "<", ast.Gt: ">", ast.LtE: "<=", ast.GtE: ">=", ast.Eq: "=", ast.NotEq: "<>"}


def _simple(g: Gen, v: ExLike) -> Ex:
    """Operands used several times by a template are bound to a temporary first."""
    e = ex(v)
    return e if isinstance(e, Var | Num | Index) else g.let(e)


def template(g: Gen, src: str, a: ExLike, b: ExLike) -> Ex:
    """Translate an operator template over ``{a}`` and ``{b}`` into IR (statements go to
    ``g.b``; the value is returned)."""
    env = {"a": _simple(g, a), "b": _simple(g, b)}
    return _tr(g, ast.parse(src.format(a="a", b="b"), mode="eval").body, env)


def _tr(g: Gen, node: ast.expr, env: dict[str, Ex]) -> Ex:
    if isinstance(node, ast.Name):
        return env[node.id]
    if isinstance(node, ast.Constant) and isinstance(node.value, int | float):
        return Num(float(node.value))
    if isinstance(node, ast.BinOp) and type(node.op) in _BINOPS:
        return Bin(_BINOPS[type(node.op)], _tr(g, node.left, env), _tr(g, node.right, env))
    if isinstance(node, ast.UnaryOp) and isinstance(node.op, ast.USub):
        return Neg(_tr(g, node.operand, env))
    if isinstance(node, ast.Compare) and len(node.ops) == 1 and type(node.ops[0]) in _CMPOPS:
        return Bin(_CMPOPS[type(node.ops[0])], _tr(g, node.left, env), _tr(g, node.comparators[0], env))
    if isinstance(node, ast.IfExp):
        t = g.temp()
        if isinstance(node.orelse, ast.Name | ast.Constant):
            # a plain alternative can be assigned first (shorter code, same value)
            g.b.set(t, _tr(g, node.orelse, env))
            with g.b.if_(_tr(g, node.test, env)):
                g.b.set(t, _tr(g, node.body, env))
            return t
        with g.b.if_(_tr(g, node.test, env)):
            g.b.set(t, _tr(g, node.body, env))
        with g.b.else_():
            g.b.set(t, _tr(g, node.orelse, env))
        return t
    if isinstance(node, ast.BoolOp):
        acc = _tr(g, node.values[0], env)
        for v in node.values[1:]:
            acc = acc.and_(_tr(g, v, env)) if isinstance(node.op, ast.And) else acc.or_(_tr(g, v, env))
        return acc
    if isinstance(node, ast.NamedExpr):
        # a name bound where it is written (inside its branch): a division never runs where
        # the branch is not taken (a PLC faults on a division by zero)
        env[node.target.id] = g.let(_tr(g, node.value, env), node.target.id.upper())
        return env[node.target.id]
    if isinstance(node, ast.Call) and isinstance(node.func, ast.Name):
        return _call(g, node.func.id, [_tr(g, a, env) for a in node.args])
    raise AssertionError(f"operator template construct not translated: {ast.dump(node)}")


def _call(g: Gen, fn: str, args: list[Ex]) -> Ex:
    if fn in ("min", "max") and len(args) == 2:
        # Python's min/max keep the first argument unless the second is strictly better
        t = g.let(args[0])
        with g.b.if_(args[1].lt(t) if fn == "min" else args[1].gt(t)):
            g.b.set(t, args[1])
        return t
    if fn in _HELPERS and len(args) == 2:
        return template(g, _HELPERS[fn], args[0], args[1])
    if fn in registry.HELPERS:
        helper = registry.HELPERS[fn]
        return formula(g, helper, dict(zip(helper.args, args, strict=True)))
    if fn == "abs":
        return _absv(g, args[0])
    if fn == "pow":  # a target without POW (ST): exp(e ln u), for u > 0 (the formulas check)
        if g.caps.has("POW"):
            return g.call("POW", args[0], args[1])
        return g.call("EXP", args[1] * g.call("LN", args[0]))
    if fn in _FORMULA_CALLS:
        return g.call(_FORMULA_CALLS[fn], *args)
    raise AssertionError(f"formula call not translated: {fn}")


_FORMULA_CALLS = {"exp": "EXP", "cos": "COS", "sqrt": "SQRT", "log": "LN"}


def formula(g: Gen, f: Formula, env: dict[str, Ex]) -> Ex:
    """A registry formula (:mod:`fuzzyctl.kinds.formula`) in the IR: ``env`` gives each
    argument; operands used several times are bound to temporaries first."""
    local: dict[str, Ex] = {name: _simple(g, v) for name, v in env.items()}
    local["pi"] = Num(_PI)
    for name, e in f.lets:
        local[name] = g.let(_tr(g, e, local), name.upper())
    return _tr(g, f.body, local)


def tnorm(g: Gen, name: str, a: ExLike, b: ExLike) -> Ex:
    return template(g, TNORMS[name].source, a, b)


def snorm(g: Gen, name: str, a: ExLike, b: ExLike) -> Ex:
    return template(g, SNORMS[name].source, a, b)


def accumulate(g: Gen, name: str, a: ExLike, b: ExLike) -> Ex:
    """:func:`fuzzyctl.engine.semantics.operators.accumulate` (MAX, SUM/NSUM, BSUM, PROBOR, the
    other OR norms)."""
    if norms.adds(name):
        return ex(a) + ex(b)
    if norms.probabilistic(name):
        return template(g, SNORMS["ASUM"].source, a, b)
    return snorm(g, name, a, b)


def accumulate_into(g: Gen, name: str, target: Var | Index, value: ExLike) -> None:
    """``target := accumulate(name, target, value)``; MAX as one IF (``a if a > b else b``
    keeps ``a`` unless ``b`` is larger)."""
    if norms.is_max(name):
        v = _simple(g, value)
        with g.b.if_(v.gt(target)):
            g.b.set(target, v)
        return
    g.b.set(target, accumulate(g, name, target, value))


def mul(w: Ex, x: ExLike) -> Ex:
    """``w * x``, with a literal weight 1.0 left out (1.0 * x == x exactly)."""
    if isinstance(w, Num) and w.value == 1.0:
        return ex(x)
    return w * ex(x)


# --------------------------------------------------------------------------- hedges


def power(g: Gen, x: Ex, y: Ex) -> Ex:
    """``x ** y`` for ``x > 0``: ``POW`` where the target has it, else ``EXP(y * LN(x))``
    (portable Structured Text has no power function)."""
    if g.caps.has("POW"):
        return g.call("POW", x, y)
    return g.call("EXP", y * g.call("LN", x))


def hedge(g: Gen, name: str, d: Ex) -> Ex:
    """One hedge of :data:`fuzzyctl.engine.semantics.shapes.HEDGES` (or ``pow:p``) applied to ``d``."""
    x = _simple(g, d)
    t = g.temp(hint="H")
    p = power_of(name)
    if p is not None:  # max(x, 0) ** p
        with g.b.if_(x.gt(0.0)):
            if p == int(p) and 1 <= p <= 4:
                prod: Ex = x
                for _ in range(int(p) - 1):
                    prod = prod * x
                g.b.set(t, prod)
            else:
                g.b.set(t, power(g, x, Num(p)))
        with g.b.else_():
            g.b.set(t, 1.0 if p == 0.0 else 0.0)
        return t
    if name == "not":
        g.b.set(t, 1.0 - x)
    elif name == "very":
        g.b.set(t, x * x)
    elif name == "somewhat":
        with g.b.if_(x.gt(0.0)):
            g.b.set(t, g.call("SQRT", x))
        with g.b.else_():
            g.b.set(t, 0.0)
    elif name == "extremely":
        with g.b.if_(x.le(0.5)):
            g.b.set(t, 2.0 * x * x)
        with g.b.else_():
            g.b.set(t, 1.0 - 2.0 * (1.0 - x) * (1.0 - x))
    elif name == "seldom":
        with g.b.if_(x.le(0.5)):
            g.b.set(t, g.call("SQRT", 0.5 * x))
        with g.b.else_():
            g.b.set(t, 1.0 - g.call("SQRT", 0.5 * (1.0 - x)))
    elif name == "any":
        g.b.set(t, 1.0)
    else:  # pragma: no cover - lowering rejects unknown hedges
        raise AssertionError(name)
    return t


def hedged(g: Gen, d: Ex, hedges: tuple[str, ...], negated: bool) -> Ex:
    """Hedges nearest the term first, then NOT (``interp._hedged``)."""
    for h in reversed(hedges):
        d = hedge(g, h, d)
    if negated:
        d = g.let(1.0 - d, "N")
    return d


# --------------------------------------------------------------------------- smooth shapes

P = list[Ex]


def _absv(g: Gen, v: Ex) -> Var:
    t = g.let(v, "A")
    with g.b.if_(t.lt(0.0)):
        g.b.set(t, -t)
    return t


def smooth(g: Gen, kind: str, p: P, x: Ex, what: str) -> Ex:
    """A smooth shape's registry formula (:attr:`fuzzyctl.kinds.shapes.Shape.formula`, the
    one the float and numpy forms are compiled from), height 1."""
    shape = registry.SHAPES.get(kind)
    if shape is None or not shape.smooth:
        raise g.refuse(what, f"{kind} membership functions are not supported by the code generator")
    env = dict(zip(("x", *shape.params), (x, *p), strict=True))
    out = g.temp(hint="M")
    g.b.set(out, formula(g, shape.parsed(), env))
    return out


_PI = 3.141592653589793


# --------------------------------------------------------------------------- function terms

_C_FUNCS = {
    "sin": "SIN",
    "cos": "COS",
    "tan": "TAN",
    "asin": "ASIN",
    "acos": "ACOS",
    "atan": "ATAN",
    "sinh": "SINH",
    "cosh": "COSH",
    "tanh": "TANH",
    "exp": "EXP",
    "log": "LN",
    "ln": "LN",
    "log10": "LOG",
    "sqrt": "SQRT",
    "abs": "ABS",
    "fabs": "ABS",
    "floor": "FLOOR",
    "ceil": "CEIL",
    "round": "RINT",  # Python's round(): halves to even, like rint()
    "pow": "POW",
    "atan2": "ATAN2",
    "fmod": "FMOD",
}
_COMPARE = {"eq": "=", "neq": "<>", "lt": "<", "le": "<=", "gt": ">", "ge": ">="}


def expression(
    g: Gen, e: ExprPlan, inputs: list[Ex], outputs: Callable[[int], Ex], x: Ex | None, what: str
) -> Ex:
    """A function term (``engine.expr.eval_expr``).  C: IEEE arithmetic gives the same
    inf/nan as the engine's C-like evaluation.  Structured Text: + - * /, comparisons,
    min/max/sign and the IEC 61131-3 standard functions (EXP, LN, LOG, SQRT, ABS and the
    trigonometric ones); a PLC faults where the engine would give inf or nan."""
    if not g.caps.function_terms:
        raise g.refuse(what, "function terms are an Open-level feature")

    def rec(n: ExprPlan) -> Ex:
        if isinstance(n, ENum):
            return Num(n.value)
        if isinstance(n, EInput):
            return inputs[n.slot]
        if isinstance(n, EOutput):
            return outputs(n.output)
        if isinstance(n, EX):
            assert x is not None
            return x
        if isinstance(n, EUnary):
            v = rec(n.operand)
            return Neg(v) if n.op == "-" else v
        if isinstance(n, EBinary):
            a, b = rec(n.left), rec(n.right)
            if n.op in "+-*/":
                return Bin(n.op, a, b)
            fn = "FMOD" if n.op == "%" else "POW"
            if not g.caps.has(fn):
                raise g.refuse(
                    what,
                    f"the operator {n.op} has no portable {g.caps.label} form; write the "
                    "function with + - * / and EXP/LN",
                )
            return g.call(fn, a, b)
        assert isinstance(n, ECall)
        args = [rec(a) for a in n.args]
        fn = n.function
        if fn in _COMPARE:
            t = g.temp(hint="F")
            with g.b.if_(Bin(_COMPARE[fn], args[0], args[1])):
                g.b.set(t, 1.0)
            with g.b.else_():
                g.b.set(t, 0.0)
            return t
        if fn in ("min", "max"):
            acc: Ex = args[0]
            for a in args[1:]:
                acc = g.min_(acc, a) if fn == "min" else g.max_(acc, a)
            return acc
        if fn == "sign":
            v = g.let(args[0], "F")
            t = g.temp(hint="F")
            with g.b.if_(v.gt(0.0)):
                g.b.set(t, 1.0)
            with g.b.elif_(v.lt(0.0)):
                g.b.set(t, -1.0)
            with g.b.else_():
                g.b.set(t, 0.0)
            return t
        if fn not in _C_FUNCS:
            raise g.refuse(what, f"function {fn}() is not supported")
        if not g.caps.has(_C_FUNCS[fn]):
            raise g.refuse(
                what,
                f"function {fn}() is no {g.caps.function_noun}; write the function with "
                f"+ - * / and {g.caps.function_list()}",
            )
        return g.call(_C_FUNCS[fn], *args)

    return rec(e)


# --------------------------------------------------------------------------- breakpoint lists


def sort_points(g: Gen, xs: Var, ys: Var | None, off: ExLike, last: ExLike, span: int | None = None) -> None:
    """Stable insertion sort of ``xs[off .. last]`` (and ``ys`` alongside) by x: the engine
    sorts points given by variables stably at each evaluation (5.2.2).  ``span``: the most
    points a segment holds (bounds the loops for the cost per cycle)."""
    i = g.counter("I")
    j = g.counter("J")
    kx = g.temp(hint="KX")
    ky = g.temp(hint="KY") if ys is not None else None
    moving = g.temp("BOOL", "MV")
    with g.b.for_(i, ex(off) + 1, last, bound=None if span is None else span - 1) as iv:
        g.b.set(kx, xs[iv])
        if ys is not None and ky is not None:
            g.b.set(ky, ys[iv])
        g.b.set(Var(j), iv - 1)
        g.b.set(moving, True)
        # no short-circuit AND in ST: the bound check and the comparison are separate IFs
        with g.b.while_(moving, bound=span):
            with g.b.if_(xs[Var(j)].gt(kx)):
                g.b.set(xs[Var(j) + 1], xs[Var(j)])
                if ys is not None:
                    g.b.set(ys[Var(j) + 1], ys[Var(j)])
                g.b.set(Var(j), Var(j) - 1)
                with g.b.if_(Var(j).lt(off)):
                    g.b.set(moving, False)
            with g.b.else_():
                g.b.set(moving, False)
        g.b.set(xs[Var(j) + 1], kx)
        if ys is not None and ky is not None:
            g.b.set(ys[Var(j) + 1], ky)


def _interp(g: Gen, xs: Var, ys: Var, off: ExLike, last: ExLike, x: Ex, out: Var) -> None:
    """grid._interp: linear between the first point right of x and its predecessor."""
    k = g.counter("K")
    done = g.temp("BOOL", "DN")
    g.b.set(done, False)
    with g.b.for_(k, ex(off) + 1, last) as kv, g.b.if_(not_(done).and_(xs[kv].gt(x))):
        g.b.set(
            out,
            ys[kv - 1] + (ys[kv] - ys[kv - 1]) * ((x - xs[kv - 1]) / (xs[kv] - xs[kv - 1])),
        )
        g.b.set(done, True)
    with g.b.if_(not_(done)):
        g.b.set(out, ys[last])


def pwl_value(g: Gen, xs: Var, ys: Var, off: ExLike, last: ExLike, x: Ex, span: int | None = None) -> Var:
    """shapes.pwl_value on the sorted segment: constant beyond the ends, the upper value on
    a vertical edge, linear between points (``span``: as for :func:`sort_points`)."""
    out = g.temp(hint="MU")
    with g.b.if_(x.lt(xs[off])):
        g.b.set(out, ys[off])
    with g.b.elif_(x.gt(xs[last])):
        g.b.set(out, ys[last])
    with g.b.else_():
        found = g.temp("BOOL", "FD")
        done = g.temp("BOOL", "DN")
        g.b.set(found, False)
        g.b.set(done, False)
        k = g.counter("K")
        with g.b.for_(k, off, last, bound=span) as kv, g.b.if_(not_(done)):
            with g.b.if_(xs[kv].eq(x)):
                with g.b.if_(not_(found)):
                    g.b.set(out, ys[kv])
                    g.b.set(found, True)
                with g.b.elif_(ys[kv].gt(out)):
                    g.b.set(out, ys[kv])
            with g.b.elif_(xs[kv].gt(x)):
                with g.b.if_(not_(found)):
                    g.b.set(
                        out,
                        ys[kv - 1] + (ys[kv] - ys[kv - 1]) * ((x - xs[kv - 1]) / (xs[kv] - xs[kv - 1])),
                    )
                g.b.set(done, True)
    return out


def pwl_value_fixed(g: Gen, xs: Var, ys: Var, first: int, last: int, x: Ex, out: Var, found: Var) -> None:
    """:func:`pwl_value` on ``xs[first .. last]`` known to be in order, without a loop
    (constant indices: no counter, no table of offsets): the upper value among the points at
    ``x``, else the segment ``x`` falls in, found by one chain of comparisons (the loop's
    first point to the right of ``x``).  ``found`` is a BOOL temporary the terms share."""
    b = g.b
    with b.if_(x.lt(xs[first])):
        b.set(out, ys[first])
    with b.elif_(x.gt(xs[last])):
        b.set(out, ys[last])
    with b.else_():
        with b.if_(xs[first].eq(x)):
            b.set(out, ys[first])
            b.set(found, True)
        with b.else_():
            b.set(found, False)
        for k in range(first + 1, last + 1):  # points at x: the first, then any larger
            with b.if_(xs[k].eq(x)):
                with b.if_(not_(found)):
                    b.set(out, ys[k])
                    b.set(found, True)
                with b.elif_(ys[k].gt(out)):
                    b.set(out, ys[k])
        if last > first:
            with b.if_(not_(found)):
                for k in range(first + 1, last + 1):
                    with b.if_(x.lt(xs[k])) if k == first + 1 else b.elif_(x.lt(xs[k])):
                        b.set(
                            out,
                            ys[k - 1] + (ys[k] - ys[k - 1]) * ((x - xs[k - 1]) / (xs[k] - xs[k - 1])),
                        )


def right_limit(g: Gen, xs: Var, ys: Var, off: ExLike, last: ExLike, x: Ex) -> Var:
    """grid.right_limit: lim u -> x+ (the last point at x on a vertical edge)."""
    out = g.temp(hint="RL")
    with g.b.if_(x.lt(xs[off])):
        g.b.set(out, ys[off])
    with g.b.elif_(x.ge(xs[last])):
        g.b.set(out, ys[last])
    with g.b.else_():
        found = g.temp("BOOL", "FD")
        g.b.set(found, False)
        k = g.counter("K")
        with g.b.for_(k, last, off, step=-1) as kv, g.b.if_(not_(found).and_(xs[kv].eq(x))):
            g.b.set(out, ys[kv])
            g.b.set(found, True)
        with g.b.if_(not_(found)):
            _interp(g, xs, ys, off, last, x, out)
    return out


def left_limit(g: Gen, xs: Var, ys: Var, off: ExLike, last: ExLike, x: Ex) -> Var:
    """grid.left_limit: lim u -> x- (the first point at x on a vertical edge)."""
    out = g.temp(hint="LL")
    with g.b.if_(x.le(xs[off])):
        g.b.set(out, ys[off])
    with g.b.elif_(x.gt(xs[last])):
        g.b.set(out, ys[last])
    with g.b.else_():
        found = g.temp("BOOL", "FD")
        g.b.set(found, False)
        k = g.counter("K")
        with g.b.for_(k, off, last) as kv, g.b.if_(not_(found).and_(xs[kv].eq(x))):
            g.b.set(out, ys[kv])
            g.b.set(found, True)
        with g.b.if_(not_(found)):
            _interp(g, xs, ys, off, last, x, out)
    return out


def tsukamoto(g: Gen, kind: str, ps: list[Ex], h: Ex, y: Ex, points: Points | None = None) -> Ex:
    """The x at which a monotonic term reaches degree ``y`` (Tsukamoto inference; the IR
    twin of :func:`fuzzyctl.engine.semantics.shapes.tsukamoto`).  ``points``: the breakpoints of a
    constant ``points`` term (their inverse is an if-chain, as ``numpy.interp`` reads it)."""
    b = g.b
    if kind == "points":
        if points is None:
            raise g.refuse("a Tsukamoto points term", "points given by variables")
        xs, ys = [x for x, _v in points], [v for _x, v in points]
        if ys[0] > ys[-1]:
            xs, ys = xs[::-1], ys[::-1]
        out = g.let(xs[-1], "TZ")
        with b.if_(y.lt(ys[0])):
            b.set(out, xs[0])
        for j in range(len(xs) - 2, -1, -1):
            if ys[j + 1] > ys[j]:
                slope = (xs[j + 1] - xs[j]) / (ys[j + 1] - ys[j])
                with b.elif_(y.ge(ys[j]).and_(y.lt(ys[-1]))):
                    b.set(out, slope * (y - ys[j]) + xs[j])
        return out
    shape = registry.SHAPES.get(kind)
    if shape is not None and shape.tsukamoto_invertible:  # the registry's inverse, written once
        env = dict(zip(("y", "h", *shape.params), (y, h, *ps), strict=True))
        return g.let(formula(g, shape.parsed_tsukamoto(), env), "TZ")
    raise g.refuse(f"a {kind} term", "not monotonic (no Tsukamoto inverse)")
