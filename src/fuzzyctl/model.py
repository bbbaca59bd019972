"""The immutable model of a fuzzy control program (IEC 61131-7 FCL and what our readers import).

Every reader (FCL, FIS, FLL, FPL, XFUZ tables, JSON) produces these objects and every
consumer (engine, code generators, PLC blocks, studio) reads them.  Objects are frozen
dataclasses holding tuples, so a model can be shared between threads and compared with
``==``.  Source positions (``span``) and comments never take part in equality: a program
written back out and read again compares equal to the original.

Conventions
-----------
* Names are kept exactly as written; FCL identifiers are case-sensitive in this model
  (keywords are not).  Operator and method keywords are stored upper-case in their
  canonical spelling (``"MIN"``, ``"COG"``), see the ``*_OPERATORS`` / ``*_METHODS`` sets.
* A numeric parameter that may be given by a variable (membership points, singleton
  positions, shape parameters, WITH weights) is a :data:`Param`: a ``float`` or a
  :class:`Ref` to a variable (normally a VAR_INPUT, IEC 61131-7 5.2.2 and 5.2.4).
* ``None`` means "not written in the source"; the engine documents the default it uses.
"""

from __future__ import annotations

import math
from collections.abc import Iterator
from dataclasses import dataclass, field
from enum import StrEnum
from functools import cached_property
from typing import TypeAlias

from fuzzyctl.diagnostics import FuzzyctlError
from fuzzyctl.kinds import methods as method_kinds
from fuzzyctl.kinds.shapes import SHAPES as SHAPE_REGISTRY
from fuzzyctl.kinds.shapes import Shape

# --------------------------------------------------------------------------- comments

PlacedComments: TypeAlias = tuple[tuple[str, str], ...]
"""``(place, text)`` pairs: the comments of an element written somewhere else than on the
lines before it (those are its ``comments``).  Places: ``"after"`` (on its line, after
it), ``"head"`` (after a block's header), ``"end"`` (on the lines before a block's END_
keyword), ``"tail"`` (after the END_ keyword), ``"ITEM.before"`` / ``"ITEM.after"`` around
a block's single-valued item (``method``, ``range``, ``and_op``, ...), and for a variable
``"section.before"`` / ``"section.head"`` / ``"section.end"`` / ``"section.tail"`` (its
VAR_... section, when it opens or closes one).  Filled by the FCL reader, written again by
the FCL writer so that ``fmt`` keeps every comment where it was."""


def comments_at(element: object, place: str) -> tuple[str, ...]:
    """The comment texts of ``element`` at ``place`` (see :data:`PlacedComments`), in
    source order; ``"before"`` gives its ``comments``."""
    placed: PlacedComments = getattr(element, "placed_comments", ())
    found = tuple(text for where, text in placed if where == place)
    if place == "before":  # an element without ``comments`` (OPTIONS) keeps them here
        return (*getattr(element, "comments", ()), *found)
    return found


# --------------------------------------------------------------------------- positions


@dataclass(frozen=True, slots=True)
class Span:
    """A source position, 1-based line and column, optionally with its end (exclusive)."""

    line: int
    column: int
    end_line: int | None = None
    end_column: int | None = None

    def __str__(self) -> str:
        return f"{self.line}:{self.column}"

    def __reduce__(self) -> tuple[type[Span], tuple[int, int, int | None, int | None]]:
        # dataclasses pickle slotted frozen classes through fields() per object: 2 s of the
        # 4 s a 40,000-rule document took to cache; a constructor call is ten times cheaper
        return (Span, (self.line, self.column, self.end_line, self.end_column))


# --------------------------------------------------------------------------- parameters


@dataclass(frozen=True)
class Ref:
    """A parameter given by the current value of a variable (e.g. ``(bp_warm1, 0.0)``)."""

    name: str
    span: Span | None = field(default=None, compare=False, repr=False)


Param: TypeAlias = float | Ref
"""A number, or a reference to a variable whose value is read at each evaluation."""


def is_constant(p: Param) -> bool:
    """True when the parameter is a literal number."""
    return not isinstance(p, Ref)


# --------------------------------------------------------------------------- membership functions


@dataclass(frozen=True)
class Point:
    """One ``(x, y)`` point of a piecewise-linear membership function (5.2.2)."""

    x: Param
    y: Param
    span: Span | None = field(default=None, compare=False, repr=False)


@dataclass(frozen=True)
class PointsMF:
    """IEC piecewise-linear membership function: linear between successive points and
    constant beyond the first and the last point (5.2.2)."""

    points: tuple[Point, ...]


@dataclass(frozen=True)
class SingletonMF:
    """A singleton output term ``TERM closed := 0;`` (5.2.3); the value may be a variable."""

    value: Param


@dataclass(frozen=True)
class SingletonsMF:
    """jFuzzyLogic's generalised singletons ``SINGLETONS (x1, y1) (x2, y2) ...``: a discrete
    fuzzy set with degree ``yi`` at ``xi`` and 0 elsewhere."""

    points: tuple[Point, ...]


#: A parametric shape kind's entry (parameters, their meaning, the formula, ...).
ShapeSpec = Shape

# Canonical parametric shapes: the registry :mod:`fuzzyctl.kinds.shapes`, one entry per
# kind.  Each reader maps its own spelling and parameter order onto these (e.g. jFuzzyLogic
# ``GBELL a b mean`` and fuzzylite ``Bell center width slope`` both become
# ``bell(center, width, slope)``) through the entry's spellings; writers map back.
SHAPES: dict[str, Shape] = SHAPE_REGISTRY


@dataclass(frozen=True)
class ShapeMF:
    """A parametric membership function of a kind listed in :data:`SHAPES`.

    ``height`` scales the shape (fuzzylite's optional last parameter)."""

    kind: str
    params: tuple[Param, ...]
    height: Param = 1.0


# ---- expressions of function terms (jFuzzyLogic FUNCTION, fuzzylite Function)


@dataclass(frozen=True)
class Num:
    value: float


@dataclass(frozen=True)
class Name:
    name: str


@dataclass(frozen=True)
class Unary:
    op: str  # "-" or "+"
    operand: Expr


@dataclass(frozen=True)
class Binary:
    op: str  # "+", "-", "*", "/", "^", "%"
    left: Expr
    right: Expr


@dataclass(frozen=True)
class Call:
    function: str  # lower-case: sin, cos, exp, log, sqrt, abs/fabs, ...
    args: tuple[Expr, ...]


Expr: TypeAlias = Num | Name | Unary | Binary | Call


def walk_expr(e: Expr) -> Iterator[Expr]:
    """Every node of an expression, the root first (an explicit stack, as
    :func:`walk_condition`)."""
    stack: list[Expr] = [e]
    while stack:
        node = stack.pop()
        yield node
        if isinstance(node, Unary):
            stack.append(node.operand)
        elif isinstance(node, Binary):
            stack += (node.right, node.left)
        elif isinstance(node, Call):
            stack.extend(reversed(node.args))


@dataclass(frozen=True)
class FunctionMF:
    """A term whose value is an arithmetic expression of input variables (open level)."""

    expr: Expr
    text: str = field(default="", compare=False)
    argument: str | None = None
    """The name that stands for the point at which the term is evaluated (fuzzylite's
    ``x`` in ``Function lt(x, 0.3) * ...``).  ``None``: every name is a variable and the
    expression gives the term's value directly (jFuzzyLogic FUNCTION, Takagi-Sugeno)."""


MembershipFunction: TypeAlias = PointsMF | SingletonMF | SingletonsMF | ShapeMF | FunctionMF


@dataclass(frozen=True)
class LowerMF:
    """The lower membership function of an interval type-2 term (the term's ``mf`` is the
    upper one).  Either an explicit function (``mf``: any membership function the engine
    reads) or MATLAB's form derived from the upper function (``mf`` is None):
    ``scale * max(0, (upper(x) - lag) / (1 - lag))``, with one ``lag`` for both sides or
    ``(left, right)`` for the rising and the falling side (``LowerScale`` / ``LowerLag``).
    :func:`fuzzyctl.type2.lower_problem` checks lower <= upper."""

    mf: MembershipFunction | None = None
    scale: float = 1.0
    lag: tuple[float, ...] = (0.0,)


@dataclass(frozen=True)
class Term:
    """A linguistic term ``TERM name := membership_function;``."""

    name: str
    mf: MembershipFunction
    span: Span | None = field(default=None, compare=False, repr=False)
    comments: tuple[str, ...] = field(default=(), compare=False, repr=False)
    placed_comments: PlacedComments = field(default=(), compare=False, repr=False)
    lower: LowerMF | None = None
    """Interval type-2: the lower membership function (``mf`` is then the upper one)."""


# --------------------------------------------------------------------------- variables and blocks


class VarKind(StrEnum):
    INPUT = "VAR_INPUT"
    OUTPUT = "VAR_OUTPUT"
    LOCAL = "VAR"


@dataclass(frozen=True)
class Range:
    """``RANGE(low..high)``: limits the output terms (5.2.3) or, for inputs, the universe."""

    low: float
    high: float
    span: Span | None = field(default=None, compare=False, repr=False)


@dataclass(frozen=True)
class Variable:
    """A declaration in VAR_INPUT / VAR_OUTPUT / VAR: ``name : TYPE [:= initial];``."""

    name: str
    kind: VarKind
    data_type: str = "REAL"
    initial: float | bool | str | None = None
    range: Range | None = None
    span: Span | None = field(default=None, compare=False, repr=False)
    comments: tuple[str, ...] = field(default=(), compare=False, repr=False)
    placed_comments: PlacedComments = field(default=(), compare=False, repr=False)


@dataclass(frozen=True)
class FuzzifyBlock:
    """``FUZZIFY variable ... END_FUZZIFY`` (5.2.2)."""

    variable: str
    terms: tuple[Term, ...]
    range: Range | None = None
    span: Span | None = field(default=None, compare=False, repr=False)
    comments: tuple[str, ...] = field(default=(), compare=False, repr=False)
    clamp: bool = False
    """Limit the input value to ``range`` before fuzzification (fuzzylite ``lock-range``)."""
    placed_comments: PlacedComments = field(default=(), compare=False, repr=False)

    def term(self, name: str) -> Term | None:
        return next((t for t in self.terms if t.name == name), None)


@dataclass(frozen=True)
class Default:
    """``DEFAULT := value | NC``.  fuzzylite's ``DEFAULT := nan | NC`` sets both."""

    value: float | None = None
    no_change: bool = False
    span: Span | None = field(default=None, compare=False, repr=False)

    def __post_init__(self) -> None:
        # One NaN object, so that models holding NaN defaults still compare equal.
        if self.value is not None and math.isnan(self.value):
            object.__setattr__(self, "value", math.nan)


@dataclass(frozen=True)
class DefuzzifyBlock:
    """``DEFUZZIFY variable ... END_DEFUZZIFY`` (5.2.3).

    ``accu`` is fuzzylite's accumulation written inside DEFUZZIFY; the standard puts ACCU in
    the rule block."""

    variable: str
    terms: tuple[Term, ...]
    range: Range | None = None
    method: str | None = None
    default: Default | None = None
    accu: str | None = None
    span: Span | None = field(default=None, compare=False, repr=False)
    comments: tuple[str, ...] = field(default=(), compare=False, repr=False)
    clamp: bool = False
    """Limit the defuzzified value to ``range`` (fuzzylite ``lock-range``)."""
    item_spans: tuple[tuple[str, Span], ...] = field(default=(), compare=False, repr=False)
    """Where the single-valued items were written: ``("method", span)``, ``("accu", ...)``."""
    placed_comments: PlacedComments = field(default=(), compare=False, repr=False)
    type_reduction: str | None = None
    """Interval type-2: the type-reduction method (a code of
    :mod:`fuzzyctl.kinds.type_reduction`, ``None``: Karnik-Mendel)."""

    def term(self, name: str) -> Term | None:
        return next((t for t in self.terms if t.name == name), None)

    def item_span(self, item: str) -> Span | None:
        """The source position of ``item`` (``"method"``, ``"accu"``), else the block's."""
        return next((s for k, s in self.item_spans if k == item), self.span)


# --------------------------------------------------------------------------- rules


@dataclass(frozen=True)
class Is:
    """Subcondition ``variable IS [NOT] [hedges] term``."""

    variable: str
    term: str
    negated: bool = False
    hedges: tuple[str, ...] = ()
    span: Span | None = field(default=None, compare=False, repr=False)


@dataclass(frozen=True)
class Degree:
    """A bare variable in a condition: its value is a membership degree in [0, 1]."""

    variable: str
    span: Span | None = field(default=None, compare=False, repr=False)


@dataclass(frozen=True)
class Not:
    operand: Condition
    span: Span | None = field(default=None, compare=False, repr=False)


@dataclass(frozen=True)
class And:
    """Conjunction of two or more operands, written without parentheses between them."""

    operands: tuple[Condition, ...]
    span: Span | None = field(default=None, compare=False, repr=False)
    grouped: bool = field(default=False, compare=False, repr=False)
    """Written in parentheses of its own.  IEC 61131-7 binds AND tighter than OR, so
    ``a OR b AND c`` and ``a OR (b AND c)`` are the same tree; jFuzzyLogic reads AND and OR
    left to right, so its profile needs to know which one was written."""


@dataclass(frozen=True)
class Or:
    operands: tuple[Condition, ...]
    span: Span | None = field(default=None, compare=False, repr=False)
    grouped: bool = field(default=False, compare=False, repr=False)
    """Written in parentheses of its own (see :attr:`And.grouped`)."""


Condition: TypeAlias = Is | Degree | Not | And | Or


def walk_condition(c: Condition | None) -> Iterator[Is | Degree]:
    """The leaves (``IS`` tests and degree inputs) of a condition, left to right (with an
    explicit stack: nested generators cost a step per level for every leaf)."""
    if c is None:
        return
    stack: list[Condition] = [c]
    while stack:
        node = stack.pop()
        if isinstance(node, Is | Degree):
            yield node
        elif isinstance(node, Not):
            stack.append(node.operand)
        else:
            stack.extend(reversed(node.operands))


@dataclass(frozen=True)
class Conclusion:
    """Subconclusion ``variable IS term [WITH weight]`` or a bare ``variable``
    (``term is None``: the variable receives the condition degree)."""

    variable: str
    term: str | None = None
    weight: Param | None = None
    span: Span | None = field(default=None, compare=False, repr=False)
    hedges: tuple[str, ...] = ()
    """Hedges written before the term (fuzzylite ``then y is very t``), outermost first.
    They modify the degree this conclusion is activated with, as :attr:`Is.hedges` modify
    a membership degree; see :data:`HEDGES`."""


@dataclass(frozen=True)
class Rule:
    """``RULE label: IF condition THEN conclusion;``.

    ``condition`` is ``None`` for a rule with an empty IF part (Siemens 1.5: it acts with
    degree 1).  A WITH weight belongs to the subconclusion it follows (5.2.4)."""

    label: str
    condition: Condition | None
    conclusions: tuple[Conclusion, ...]
    span: Span | None = field(default=None, compare=False, repr=False)
    comments: tuple[str, ...] = field(default=(), compare=False, repr=False)
    weight: Param | None = None
    """Rule weight of MATLAB FIS and fuzzylite (``(0.5)``, ``with 0.5``): it multiplies the
    condition degree *before* activation, ``act(w * a, mu)``.  Unlike a WITH weight of a
    subconclusion (IEC 61131-7: ``w * act(a, mu)``) it differs from it under ACT MIN."""
    placed_comments: PlacedComments = field(default=(), compare=False, repr=False)


@dataclass(frozen=True)
class RuleBlock:
    """``RULEBLOCK name ... END_RULEBLOCK`` (5.2.4).  Operators as written (canonical
    upper-case spelling) or ``None`` when absent."""

    name: str | None
    rules: tuple[Rule, ...]
    and_op: str | None = None
    or_op: str | None = None
    act: str | None = None
    accu: str | None = None
    span: Span | None = field(default=None, compare=False, repr=False)
    comments: tuple[str, ...] = field(default=(), compare=False, repr=False)
    enabled: bool = True
    """A disabled rule block (fuzzylite ``enabled: false``) fires none of its rules."""
    rule_activation: str | None = None
    """fuzzylite's rule activation method when it is not ``General`` (``"First 2"``,
    ``"Highest 1"``, ``"Threshold >= 0.5"``, ...): which rules of the block fire.  ``None``:
    every rule fires (IEC 61131-7)."""
    item_spans: tuple[tuple[str, Span], ...] = field(default=(), compare=False, repr=False)
    """Where the operator items were written: ``("and_op", span)``, ``("or_op", ...)``,
    ``("act", ...)``, ``("accu", ...)``."""
    placed_comments: PlacedComments = field(default=(), compare=False, repr=False)

    def item_span(self, item: str) -> Span | None:
        """The source position of ``item`` (``"and_op"``, ``"act"``, ...), else the block's."""
        return next((s for k, s in self.item_spans if k == item), self.span)


@dataclass(frozen=True)
class OptionsBlock:
    """``OPTIONS ... END_OPTIONS`` (or ``OPTION ... END_OPTION``), text kept verbatim."""

    text: str
    keyword: str = "OPTIONS"
    span: Span | None = field(default=None, compare=False, repr=False)
    placed_comments: PlacedComments = field(default=(), compare=False, repr=False)


# --------------------------------------------------------------------------- function block


@dataclass(frozen=True)
class FunctionBlock:
    """An FCL function block: interface, fuzzification, defuzzification, rules, options."""

    name: str | None
    variables: tuple[Variable, ...] = ()
    fuzzify: tuple[FuzzifyBlock, ...] = ()
    defuzzify: tuple[DefuzzifyBlock, ...] = ()
    rule_blocks: tuple[RuleBlock, ...] = ()
    options: tuple[OptionsBlock, ...] = ()
    span: Span | None = field(default=None, compare=False, repr=False)
    comments: tuple[str, ...] = field(default=(), compare=False, repr=False)
    placed_comments: PlacedComments = field(default=(), compare=False, repr=False)

    def _of_kind(self, kind: VarKind) -> tuple[Variable, ...]:
        return tuple(v for v in self.variables if v.kind is kind)

    @property
    def inputs(self) -> tuple[Variable, ...]:
        return self._of_kind(VarKind.INPUT)

    @property
    def outputs(self) -> tuple[Variable, ...]:
        return self._of_kind(VarKind.OUTPUT)

    @property
    def locals(self) -> tuple[Variable, ...]:
        return self._of_kind(VarKind.LOCAL)

    @cached_property
    def _index(self) -> tuple[dict[str, Variable], dict[str, FuzzifyBlock], dict[str, DefuzzifyBlock]]:
        """The first variable, FUZZIFY and DEFUZZIFY block of each name (lookups in constant
        time: a large system asks for them once per rule)."""
        variables: dict[str, Variable] = {}
        fuzzify: dict[str, FuzzifyBlock] = {}
        defuzzify: dict[str, DefuzzifyBlock] = {}
        for v in self.variables:
            variables.setdefault(v.name, v)
        for f in self.fuzzify:
            fuzzify.setdefault(f.variable, f)
        for d in self.defuzzify:
            defuzzify.setdefault(d.variable, d)
        return variables, fuzzify, defuzzify

    def variable(self, name: str) -> Variable | None:
        return self._index[0].get(name)

    def fuzzify_block(self, variable: str) -> FuzzifyBlock | None:
        return self._index[1].get(variable)

    def defuzzify_block(self, variable: str) -> DefuzzifyBlock | None:
        return self._index[2].get(variable)

    @cached_property
    def _term_names(self) -> dict[str, frozenset[str]]:
        names: dict[str, set[str]] = {}
        for f in self.fuzzify:
            names.setdefault(f.variable, set()).update(t.name for t in f.terms)
        for d in self.defuzzify:
            names.setdefault(d.variable, set()).update(t.name for t in d.terms)
        return {k: frozenset(v) for k, v in names.items()}

    def term_names(self, variable: str) -> frozenset[str] | None:
        """The terms of ``variable`` in its FUZZIFY and DEFUZZIFY blocks (``None``: it has no
        such block)."""
        return self._term_names.get(variable)

    def __getstate__(self) -> dict[str, object]:
        state = dict(self.__dict__)
        state.pop("_index", None)  # caches, not part of the model
        state.pop("_term_names", None)
        return state

    def rules(self) -> Iterator[tuple[RuleBlock, Rule]]:
        for block in self.rule_blocks:
            for rule in block.rules:
                yield block, rule

    @property
    def is_type2(self) -> bool:
        """An interval type-2 system: a term has a lower membership function."""
        blocks: tuple[FuzzifyBlock | DefuzzifyBlock, ...] = (*self.fuzzify, *self.defuzzify)
        return any(t.lower is not None for v in blocks for t in v.terms)


class UnknownBlock(FuzzyctlError, KeyError):
    """A function block name the document does not have (a ``KeyError`` for lookups, and a
    :class:`~fuzzyctl.diagnostics.FuzzyctlError` so the CLI reports it as bad input)."""

    def __str__(self) -> str:  # KeyError would quote the message
        return str(self.args[0]) if self.args else "no such function block"


@dataclass(frozen=True)
class Document:
    """A parsed file: one or more function blocks (IEC allows several per file)."""

    blocks: tuple[FunctionBlock, ...]
    path: str | None = field(default=None, compare=False)
    comments: tuple[str, ...] = field(default=(), compare=False, repr=False)

    @property
    def main(self) -> FunctionBlock:
        """The first function block."""
        return self.blocks[0]

    def block(self, name: str | None = None) -> FunctionBlock:
        """The function block called ``name`` (the first one when ``name`` is None)."""
        if name is None:
            return self.main
        for b in self.blocks:
            if b.name == name:
                return b
        known = ", ".join(repr(b.name) for b in self.blocks)
        raise UnknownBlock(f"no function block {name!r} (this file has {known})")


# --------------------------------------------------------------------------- keyword sets

AND_OPERATORS = frozenset({"MIN", "PROD", "BDIF", "DMIN", "NIPMIN", "HAMACHER", "EINSTEIN"})
OR_OPERATORS = frozenset({"MAX", "ASUM", "BSUM", "DMAX", "NIPMAX", "HAMACHER", "EINSTEIN"})
# Table 3 pairs; the open-level norms pair with their usual duals.
OPERATOR_PAIRS: dict[str, str] = {
    "MIN": "MAX",
    "PROD": "ASUM",
    "BDIF": "BSUM",
    "DMIN": "DMAX",
    "NIPMIN": "NIPMAX",
    "HAMACHER": "HAMACHER",
    "EINSTEIN": "EINSTEIN",
}
_AND_OF_OR: dict[str, str] = {v: k for k, v in OPERATOR_PAIRS.items()}


def implied_operators(and_op: str | None, or_op: str | None) -> tuple[str, str]:
    """The AND and OR a rule block evaluates with (Table 3): a missing one is the pair of the
    one given, neither given is MIN/MAX.  Writers of formats that state both (FIS, FLL) or
    allow one (FPL, XFUZ) use it so that what is implied is not lost."""
    if and_op is None and or_op is None:
        return "MIN", "MAX"
    if or_op is None:
        assert and_op is not None
        return and_op, OPERATOR_PAIRS.get(and_op, "MAX")
    if and_op is None:
        return _AND_OF_OR.get(or_op, "MIN"), or_op
    return and_op, or_op


# Activation with any t-norm (fuzzylite exports e.g. ``ACT : EPROD``, stored as EINSTEIN).
ACT_METHODS = frozenset({"MIN", "PROD", "BDIF", "DMIN", "NIPMIN", "HAMACHER", "EINSTEIN"})
# Accumulation: Table 5 (MAX, BSUM, NSUM), jFuzzyLogic's SUM (unbounded) and PROBOR (a + b - ab,
# also written ASUM by fuzzylite), and the s-norms fuzzylite exports (ESUM -> EINSTEIN,
# HSUM -> HAMACHER, DSUM -> DMAX, NMAX -> NIPMAX).  The synonym table is fuzzyctl.fcl.keywords.
ACCU_METHODS = frozenset({"MAX", "BSUM", "NSUM", "SUM", "PROBOR", "DMAX", "NIPMAX", "HAMACHER", "EINSTEIN"})
DEFUZZ_METHODS = method_kinds.CODES  # one entry per method: fuzzyctl/kinds/methods.py

# Hedges (``x IS very t``, ``then y is very t``): name -> what it does to a degree d.
# fuzzylite's ``any`` (degree 1 whatever the term) is resolved by the readers, never stored.
HEDGES: dict[str, str] = {
    "very": "d^2",
    "somewhat": "sqrt(d)",
    "extremely": "2 d^2 if d <= 0.5 else 1 - 2 (1-d)^2 (fuzzylite Extremely)",
    "seldom": "sqrt(d/2) if d <= 0.5 else 1 - sqrt((1-d)/2) (fuzzylite Seldom)",
}
POWER_HEDGE_PREFIX = "pow:"
"""A hedge ``"pow:p"`` raises the degree to the power p (Octave FIS hedge codes: ``2.3`` is
term 2 with ``d^3``)."""
