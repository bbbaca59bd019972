"""Formulas written once, as a small Python expression, and compiled to every form.

A formula is Python source: optional ``name = expression`` lines followed by one expression
(lines separated by newlines or ``;``).  It may use its arguments, the names bound before it
(``:=`` binds a name inside a branch, so a division happens only where its branch is taken),
numbers, ``pi``, ``+ - * /``, comparisons, ``and``/``or``, ``a if c else b`` and the calls
listed in :data:`FUNCTIONS` or a helper formula of :data:`HELPERS`-like tables given by the
caller.  From it come:

* a function on Python floats (:func:`scalar`: the source as written, the calls bound to the
  namespace the caller gives, e.g. ``math``);
* a function on numpy arrays (:func:`vectorised`: conditionals become ``where``, ``and``/``or``
  ``&``/``|``, the calls bound to the caller's array functions);
* the IR (``fuzzyctl.ir.builders.terms.formula`` walks :attr:`Formula.lets` and
  :attr:`Formula.body`), and through it C, Structured Text, Python and numpy source.

Because every form is derived from the same syntax tree, the evaluation order and the
constants are the same everywhere: the forms agree to the last bit where the functions do.
"""

from __future__ import annotations

import ast
import math
from collections.abc import Callable, Mapping
from dataclasses import dataclass
from typing import Any

#: Calls a formula may make, each with its arity (``pow`` is IEEE ``pow``).
FUNCTIONS: dict[str, int] = {
    "exp": 1,
    "log": 1,
    "cos": 1,
    "sqrt": 1,
    "abs": 1,
    "pow": 2,
    "min": 2,
    "max": 2,
    "isnan": 1,
}
#: Names a formula may use without binding them.
CONSTANTS = frozenset({"pi", "nan"})


class FormulaError(ValueError):
    """A formula outside the language (found when the registry is loaded)."""


@dataclass(frozen=True)
class Formula:
    """A parsed formula: ``lets`` are evaluated in order, then ``body`` is the value."""

    source: str
    args: tuple[str, ...]
    lets: tuple[tuple[str, ast.expr], ...]
    body: ast.expr

    def helpers(self) -> frozenset[str]:
        """The names of the calls that are not :data:`FUNCTIONS` (helper formulas)."""
        out: set[str] = set()
        for node in [e for _n, e in self.lets] + [self.body]:
            for n in ast.walk(node):
                if isinstance(n, ast.Call) and isinstance(n.func, ast.Name) and n.func.id not in FUNCTIONS:
                    out.add(n.func.id)
        return frozenset(out)


_ALLOWED = (
    ast.Expression,
    ast.Name,
    ast.Load,
    ast.Store,
    ast.Constant,
    ast.BinOp,
    ast.Add,
    ast.Sub,
    ast.Mult,
    ast.Div,
    ast.UnaryOp,
    ast.USub,
    ast.Compare,
    ast.Lt,
    ast.LtE,
    ast.Gt,
    ast.GtE,
    ast.Eq,
    ast.NotEq,
    ast.BoolOp,
    ast.And,
    ast.Or,
    ast.IfExp,
    ast.Call,
    ast.NamedExpr,
)


def parse(source: str, args: tuple[str, ...], helpers: Mapping[str, Formula] | None = None) -> Formula:
    """Parse and check ``source`` (arguments ``args``; calls to ``helpers`` allowed)."""
    helpers = helpers or {}
    lines = [s.strip() for s in source.replace(";", "\n").splitlines() if s.strip()]
    if not lines:
        raise FormulaError("empty formula")
    bound = set(args) | CONSTANTS
    lets: list[tuple[str, ast.expr]] = []
    for line in lines[:-1]:
        name, sep, expr = line.partition("=")
        name = name.strip()
        if not sep or not name.isidentifier():
            raise FormulaError(f"{source!r}: {line!r} is not 'name = expression'")
        node = _expr(expr, source, bound, helpers)
        lets.append((name, node))
        bound.add(name)
    body = _expr(lines[-1], source, bound, helpers)
    return Formula(source, args, tuple(lets), body)


def _expr(text: str, source: str, bound: set[str], helpers: Mapping[str, Formula]) -> ast.expr:
    try:
        tree = ast.parse(text.strip(), mode="eval")
    except SyntaxError as e:
        raise FormulaError(f"{source!r}: {e.msg}") from None
    for n in ast.walk(tree):
        if not isinstance(n, _ALLOWED):
            raise FormulaError(f"{source!r}: {type(n).__name__} is not allowed in a formula")
        if isinstance(n, ast.Call):
            if not isinstance(n.func, ast.Name) or n.keywords:
                raise FormulaError(f"{source!r}: only plain calls are allowed")
            arity = FUNCTIONS.get(n.func.id)
            if arity is None and n.func.id in helpers:
                arity = len(helpers[n.func.id].args)
            if arity is None or arity != len(n.args):
                raise FormulaError(f"{source!r}: unknown call {n.func.id}/{len(n.args)}")
        if isinstance(n, ast.NamedExpr):
            bound.add(n.target.id)
        if isinstance(n, ast.Constant) and not isinstance(n.value, int | float):
            raise FormulaError(f"{source!r}: only numbers are allowed as constants")
    # names used must be bound (walrus names are checked loosely: bound anywhere in the line)
    for n in ast.walk(tree):
        if isinstance(n, ast.Name) and isinstance(n.ctx, ast.Load) and n.id not in bound:
            is_call = any(isinstance(c, ast.Call) and c.func is n for c in ast.walk(tree))
            if not is_call:
                raise FormulaError(f"{source!r}: unknown name {n.id!r}")
    return tree.body


# --------------------------------------------------------------------------- compiling


class _Vectorise(ast.NodeTransformer):
    """Conditionals to ``where`` and ``and``/``or`` to ``&``/``|`` (numpy evaluates every
    branch; the IEEE values of the branch not taken are dropped)."""

    def visit_IfExp(self, node: ast.IfExp) -> ast.AST:
        self.generic_visit(node)
        return ast.Call(ast.Name("where", ast.Load()), [node.test, node.body, node.orelse], [])

    def visit_BoolOp(self, node: ast.BoolOp) -> ast.AST:
        self.generic_visit(node)
        op: ast.operator = ast.BitAnd() if isinstance(node.op, ast.And) else ast.BitOr()
        acc = node.values[0]
        for v in node.values[1:]:
            acc = ast.BinOp(acc, op, v)
        return acc


class _Inline(ast.NodeTransformer):
    """Calls of helper formulas written in place (a Python call costs more than the helper's
    arithmetic): the helper's arguments replaced by the caller's names or numbers, its own
    names renamed apart.  A call with a computed argument, or of a helper with ``lets``,
    stays a call."""

    def __init__(self, helpers: Mapping[str, Formula]) -> None:
        self.helpers = helpers
        self.count = 0

    def visit_Call(self, node: ast.Call) -> ast.AST:
        self.generic_visit(node)
        helper = self.helpers.get(node.func.id) if isinstance(node.func, ast.Name) else None
        simple = all(isinstance(a, ast.Name | ast.Constant) for a in node.args)
        if helper is None or helper.lets or not simple:
            return node
        self.count += 1
        args = dict(zip(helper.args, node.args, strict=True))
        suffix = f"_{node.func.id}{self.count}"  # type: ignore[attr-defined]

        class Rename(ast.NodeTransformer):
            def visit_Call(self, n: ast.Call) -> ast.AST:
                n.args = [self.visit(a) for a in n.args]  # the function's name stays
                return n

            def visit_Name(self, n: ast.Name) -> ast.AST:
                if n.id in args:
                    return args[n.id]
                return ast.Name(n.id + suffix if n.id not in CONSTANTS else n.id, n.ctx)

        body = ast.parse(ast.unparse(helper.body), mode="eval").body
        return self.visit(Rename().visit(body))  # type: ignore[no-any-return]


def _source(f: Formula, name: str, vector: bool, helpers: Mapping[str, Formula]) -> str:
    inline = _Inline(helpers)

    def text(e: ast.expr) -> str:
        e = inline.visit(ast.parse(ast.unparse(e), mode="eval")).body
        if vector:
            e = _Vectorise().visit(e)
        return ast.unparse(ast.fix_missing_locations(e))

    lines = [f"def {name}({', '.join(f.args)}):"]
    lines += [f"    {n} = {text(e)}" for n, e in f.lets]
    lines.append(f"    return {text(f.body)}")
    return "\n".join(lines)


def _compile(
    f: Formula, namespace: Mapping[str, Any], helpers: Mapping[str, Formula], vector: bool
) -> Callable[..., Any]:
    ns: dict[str, Any] = dict(namespace)
    for h in sorted(f.helpers()):
        ns[h] = _compile(helpers[h], namespace, helpers, vector)
    code = _source(f, "formula", vector, helpers)
    exec(compile(code, f"<formula {f.source!r}>", "exec"), ns)
    fn: Callable[..., Any] = ns["formula"]
    return fn


#: ``math`` bindings for :func:`scalar`.
MATH: dict[str, Any] = {
    "exp": math.exp,
    "log": math.log,
    "cos": math.cos,
    "sqrt": math.sqrt,
    "abs": abs,
    "pow": math.pow,
    "min": min,
    "max": max,
    "isnan": math.isnan,
    "pi": math.pi,
    "nan": math.nan,
}


def scalar(
    f: Formula, helpers: Mapping[str, Formula] | None = None, namespace: Mapping[str, Any] | None = None
) -> Callable[..., float]:
    """``f`` as a function of Python floats (``math`` unless ``namespace`` says otherwise)."""
    return _compile(f, namespace or MATH, helpers or {}, vector=False)


def vectorised(
    f: Formula, namespace: Mapping[str, Any], helpers: Mapping[str, Formula] | None = None
) -> Callable[..., Any]:
    """``f`` as a function of numpy arrays; ``namespace`` binds every name of
    :data:`FUNCTIONS`, ``pi``, ``nan`` and ``where``."""
    return _compile(f, namespace, helpers or {}, vector=True)
