"""A small executor for exactly the Structured Text subset fuzzyctl emits, built on blark's
parse tree (blark is GPL: test-only, never imported by src/).

blark parses the generated text; this module walks blark's transformed tree and translates it
statement by statement into a Python function, then runs it.  REAL arithmetic is emulated
with numpy.float32 (every operation rounds to single precision, as a PLC's REAL does),
LREAL with numpy.float64; INT is a Python int checked against the 16-bit range; array
accesses are bounds-checked; temporaries start as None so that reading one before writing it
fails loudly.  Only the constructs the generator emits are accepted - anything else raises,
which keeps the generator honest about its subset.
"""

from __future__ import annotations

import ast
import dataclasses
import math
from collections.abc import Callable
from pathlib import Path
from typing import Any

import numpy as np
from blark import transform as tf
from blark.parse import parse_source_code

_BINOPS = {
    "+": "+",
    "-": "-",
    "*": "*",
    "/": "/",
    "<": "<",
    ">": ">",
    "<=": "<=",
    ">=": ">=",
    "=": "==",
    "<>": "!=",
    "AND": "and",
    "OR": "or",
}
_FUNCS = {
    "EXP": "np.exp",
    "LN": "np.log",
    "LOG": "np.log10",
    "SQRT": "np.sqrt",
    "ABS": "abs",
    "SIN": "np.sin",
    "COS": "np.cos",
    "TAN": "np.tan",
    "ASIN": "np.arcsin",
    "ACOS": "np.arccos",
    "ATAN": "np.arctan",
}


class STError(AssertionError):
    """The text is outside the subset (or the code misbehaved: bounds, INT overflow, unset)."""


def _tok(x: Any) -> str:
    return str(x)


def _leaves(node: Any) -> list[Any]:
    """The literal values of an array initialiser, in order (blark nests them oddly)."""
    out: list[Any] = []
    if isinstance(node, tf.ArrayInitialization):
        for el in node.elements:
            out += _leaves(el)
    elif isinstance(node, tf.ArrayInitialElement):
        if node.count is not None:
            raise STError("repeated array initialisers are not emitted")
        out += _leaves(node.element)
    else:
        out.append(node)
    return out


@dataclasses.dataclass
class _Var:
    name: str
    type: str
    size: int | None
    lo: int
    init: list[Any] | Any
    storage: str  # input, output, static, temp


@dataclasses.dataclass
class Translation:
    """What blark's tree becomes: picklable, so that the (slow) parsing can run in worker
    processes."""

    name: str
    vars: dict[str, _Var]
    real: str
    source: str
    consts: list[Any]


def translate(source: str, name: str | None = None) -> Translation:
    """Parse ``source`` with blark and translate one FUNCTION_BLOCK into Python.

    blark's Earley parser needs ~12 ms per line, so translations are cached on disk, keyed by
    the text, the block name, blark's version and this file (tests/diskcache.py)."""
    from importlib.metadata import version

    from tests.diskcache import cached

    key = (source, name, version("blark"), Path(__file__).read_bytes())
    result: Translation = cached("blark-st", key, lambda: _Translator(source, name).result)
    return result


class _Translator:
    def __init__(self, source: str, name: str | None) -> None:
        result = parse_source_code(source)
        if result.exception is not None:
            raise STError(f"blark cannot parse the text: {result.exception}")
        code = result.transform()
        blocks = [it for it in code.items if isinstance(it, tf.FunctionBlock)]
        fb = next(b for b in blocks if name is None or str(b.name) == name)
        self.name = str(fb.name)
        self.vars: dict[str, _Var] = {}
        for decl in fb.declarations:
            storage = {
                tf.InputDeclarations: "input",
                tf.OutputDeclarations: "output",
                tf.VariableDeclarations: "static",
                tf.TemporaryVariableDeclarations: "temp",
            }.get(type(decl))
            if storage is None:
                raise STError(f"declaration block {type(decl).__name__} is not emitted")
            for item in decl.items:
                self._declare(item, storage)
        reals = {v.type for v in self.vars.values() if v.type in ("REAL", "LREAL")}
        if len(reals) > 1:
            raise STError("REAL and LREAL mixed")
        self.real = reals.pop() if reals else "REAL"
        self.R = np.float32 if self.real == "REAL" else np.float64
        self.consts: list[Any] = []
        lines = ["def _step(S):"]
        for v in self.vars.values():
            if v.storage == "temp":
                lines.append(f"    {self._py(v.name)} = {'[None] * ' + str(v.size) if v.size else 'None'}")
            else:
                lines.append(f"    {self._py(v.name)} = S[{v.name!r}]")
        self._lines = lines
        self._stmts(fb.body, 1)
        for v in self.vars.values():
            if v.storage != "temp" and v.size is None:
                lines.append(f"    S[{v.name!r}] = {self._py(v.name)}")
        self.result = Translation(self.name, self.vars, self.real, "\n".join(lines) + "\n", self.consts)

    # ------------------------------------------------------------------ declarations

    def _declare(self, item: Any, storage: str) -> None:
        names = [str(dv.variable.name) for dv in item.variables]
        init = item.init
        if isinstance(item, tf.ArrayVariableInitDeclaration):
            spec = init.spec
            if len(spec.subranges) != 1:
                raise STError("only one-dimensional arrays are emitted")
            lo = int(_tok(spec.subranges[0].start.value))
            hi = int(_tok(spec.subranges[0].stop.value))
            typ = _tok(spec.type.type_name).upper()
            vals = [self._literal(x) for x in _leaves(init.value)] if init.value is not None else None
            for n in names:
                self.vars[n.upper()] = _Var(n.upper(), typ, hi - lo + 1, lo, vals, storage)
        elif isinstance(item, tf.VariableOneInitDeclaration):
            typ = _tok(init.spec.type).upper()
            val = self._literal(init.value) if init.value is not None else None
            for n in names:
                self.vars[n.upper()] = _Var(n.upper(), typ, None, 0, val, storage)
        else:
            raise STError(f"declaration {type(item).__name__} is not emitted")

    @staticmethod
    def _literal(node: Any) -> Any:
        neg = False
        if isinstance(node, tf.UnaryOperation) and _tok(node.op) == "-":
            neg, node = True, node.expr
        if isinstance(node, tf.Real):
            v: Any = float(_tok(node.value))
        elif isinstance(node, tf.Integer):
            v = int(_tok(node.value), int(node.base or 10))
        elif isinstance(node, tf.Boolean):
            v = _tok(node.value).upper() == "TRUE"
        else:
            raise STError(f"initial value {node!r} is not a literal")
        return -v if neg else v

    # ------------------------------------------------------------------ translation

    def _py(self, name: str) -> str:
        return "v_" + name.upper()

    def _const(self, value: Any) -> str:
        self.consts.append(value)
        return f"C[{len(self.consts) - 1}]"

    def _ex(self, e: Any) -> str:
        if isinstance(e, tf.ParenthesizedExpression):
            return f"({self._ex(e.expr)})"
        if isinstance(e, tf.Real):
            return self._const(self.R(float(_tok(e.value))))
        if isinstance(e, tf.Integer):
            return str(int(_tok(e.value), int(e.base or 10)))
        if isinstance(e, tf.Boolean):
            return "True" if _tok(e.value).upper() == "TRUE" else "False"
        if isinstance(e, tf.SimpleVariable):
            name = _tok(e.name).upper()
            if name not in self.vars:
                raise STError(f"undeclared variable {name}")
            return self._py(name)
        if isinstance(e, tf.MultiElementVariable):
            name = _tok(e.name.name).upper()
            var = self.vars.get(name)
            if var is None or var.size is None or len(e.elements) != 1:
                raise STError(f"bad array access {e!r}")
            sub = e.elements[0]
            if not isinstance(sub, tf.SubscriptList) or len(sub.subscripts) != 1:
                raise STError("only one subscript is emitted")
            idx = self._ex(sub.subscripts[0])
            return f"{self._py(name)}[_ck({idx}, {var.lo}, {var.size})]"
        if isinstance(e, tf.UnaryOperation):
            op = _tok(e.op).upper()
            if op == "-":
                return f"(-{self._ex(e.expr)})"
            if op == "NOT":
                return f"(not {self._ex(e.expr)})"
            raise STError(f"unary {op} is not emitted")
        if isinstance(e, tf.BinaryOperation):
            op = _tok(e.op).upper()
            if op not in _BINOPS:
                raise STError(f"operator {op} is outside the emitted subset")
            left, right = self._ex(e.left), self._ex(e.right)
            if op in ("+", "-", "*"):
                return f"_int(({left}) {_BINOPS[op]} ({right}))"
            return f"(({left}) {_BINOPS[op]} ({right}))"
        if isinstance(e, tf.FunctionCall):
            fn = _tok(e.name.name if hasattr(e.name, "name") else e.name).upper()
            args = [self._ex(p.value) for p in e.parameters]
            if fn in ("INT_TO_REAL", "INT_TO_LREAL"):
                return f"R({args[0]})"
            if fn not in _FUNCS:
                raise STError(f"function {fn} is outside the emitted subset")
            return f"{_FUNCS[fn]}({', '.join(args)})"
        raise STError(f"expression {type(e).__name__} is outside the emitted subset")

    def _target(self, t: Any) -> str:
        if isinstance(t, tf.SimpleVariable | tf.MultiElementVariable):
            return self._ex(t)
        raise STError(f"assignment target {t!r}")

    def _stmts(self, body: Any, ind: int) -> None:
        pad = "    " * ind
        stmts = body.statements if isinstance(body, tf.StatementList) else (body or [])
        if not stmts:
            self._lines.append(pad + "pass")
            return
        for s in stmts:
            if isinstance(s, tf.AssignmentStatement):
                if len(s.variables) != 1:
                    raise STError("chained assignments are not emitted")
                self._lines.append(f"{pad}{self._target(s.variables[0])} = {self._ex(s.expression)}")
            elif isinstance(s, tf.IfStatement):
                self._lines.append(f"{pad}if {self._ex(s.if_expression)}:")
                self._stmts(s.statements, ind + 1)
                for clause in s.else_ifs:
                    self._lines.append(f"{pad}elif {self._ex(clause.if_expression)}:")
                    self._stmts(clause.statements, ind + 1)
                if s.else_clause is not None:
                    self._lines.append(f"{pad}else:")
                    self._stmts(s.else_clause.statements, ind + 1)
            elif isinstance(s, tf.ForStatement):
                var = self._ex(s.control)
                start, stop = self._ex(s.from_), self._ex(s.to)
                step = int(self._literal(s.step)) if s.step is not None else 1
                if step not in (1, -1):
                    raise STError("only FOR ... BY 1 / BY -1 is emitted")
                end = f"({stop}) + 1" if step == 1 else f"({stop}) - 1"
                self._lines.append(f"{pad}for {var} in range({start}, {end}, {step}):")
                self._stmts(s.statements, ind + 1)
            elif isinstance(s, tf.WhileStatement):
                self._lines.append(f"{pad}while {self._ex(s.expression)}:")
                self._stmts(s.statements, ind + 1)
            elif isinstance(s, tf.EmptyStatement if hasattr(tf, "EmptyStatement") else ()):
                self._lines.append(pad + "pass")
            else:
                raise STError(f"statement {type(s).__name__} is outside the emitted subset")


class STBlock:
    """One FUNCTION_BLOCK instance, from source text or a :class:`Translation`."""

    def __init__(
        self,
        source: str | Translation,
        name: str | None = None,
        instrument: Callable[[ast.Module], tuple[ast.Module, dict[str, Any]]] | None = None,
    ) -> None:
        """``instrument``: rewrites the translated Python (its syntax tree) and gives the names
        the rewritten code calls (tests that count what the text executes)."""
        tr = translate(source, name) if isinstance(source, str) else source
        self.name, self.vars, self.real, self.source = tr.name, tr.vars, tr.real, tr.source
        self.R = np.float32 if self.real == "REAL" else np.float64
        env: dict[str, Any] = {"np": np, "R": self.R, "C": tr.consts, "_ck": _ck, "_int": _int}
        code: Any = self.source
        if instrument is not None:
            tree, names = instrument(ast.parse(self.source))
            code = ast.fix_missing_locations(tree)
            env.update(names)
        exec(compile(code, f"<st {self.name}>", "exec"), env)
        self._fn = env["_step"]
        self.reset()

    def _convert(self, typ: str, v: Any) -> Any:
        if v is None:
            return None
        if typ in ("REAL", "LREAL"):
            return self.R(v)
        if typ == "BOOL":
            return bool(v)
        return int(v)

    def reset(self) -> None:
        """A fresh instance: every static and output at its initial value."""
        self.state: dict[str, Any] = {}
        for v in self.vars.values():
            if v.storage == "temp":
                continue
            zero = False if v.type == "BOOL" else 0
            if v.size is None:
                self.state[v.name] = self._convert(v.type, v.init if v.init is not None else zero)
            else:
                vals = v.init if v.init is not None else [zero] * v.size
                if len(vals) != v.size:
                    raise STError(f"{v.name}: {len(vals)} initial values for {v.size} elements")
                self.state[v.name] = [self._convert(v.type, x) for x in vals]

    # ------------------------------------------------------------------ running

    def step(self, inputs: dict[str, float]) -> dict[str, Any]:
        """Set the inputs, run one cycle, return every output (by upper-case name)."""
        for k, val in inputs.items():
            var = self.vars[k.upper()]
            if var.storage != "input":
                raise KeyError(k)
            self.state[var.name] = self._convert(var.type, val)
        with np.errstate(all="ignore"):
            self._fn(self.state)
        return {v.name: self.state[v.name] for v in self.vars.values() if v.storage == "output"}


def _ck(i: int, lo: int, n: int) -> int:
    if not isinstance(i, int) or not lo <= i < lo + n:
        raise STError(f"array index {i} outside [{lo}..{lo + n - 1}]")
    return i - lo


def _int(v: Any) -> Any:
    """INT arithmetic must stay within 16 bits (REAL values pass through)."""
    if isinstance(v, int) and not isinstance(v, bool) and not -32768 <= v <= 32767:
        raise STError(f"INT overflow: {v}")
    if v is None or (isinstance(v, float) and not isinstance(v, np.floating) and not math.isnan(v)):
        raise STError(f"untyped value {v!r} in arithmetic")
    return v
