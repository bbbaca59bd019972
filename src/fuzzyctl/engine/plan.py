"""The lowered form of a function block: plain, immutable data every evaluator consumes.

:func:`fuzzyctl.engine.lowering.lower.lower` turns a :class:`~fuzzyctl.model.FunctionBlock` into a
:class:`Plan`.  The scalar evaluator (interpreted and specialised), the numpy batch evaluator
and the code generators (Structured Text, C) all read this one structure, so they cannot
disagree about *what* is computed; they only differ in *how*.

Everything here is numbers, strings, tuples and small frozen dataclasses - no callables, no
model objects - and :meth:`Plan.to_dict` gives a JSON-ready view.

Indices
-------
* ``slot``: position of a VAR_INPUT in :attr:`Plan.inputs` (the evaluation's input vector).
* fuzzy variable ``var``: position in :attr:`Plan.fuzzy_inputs` (inputs that are fuzzified).
* chained variable ``var``: position in :attr:`Plan.chained` (variables concluded by rules
  and used in conditions of other rules: chained inference).
* ``output``: position in :attr:`Plan.outputs`.
* ``term``: position in the owning variable's ``terms``.

Parameters
----------
A numeric parameter is a ``float`` or a :class:`Slot` (the current value of an input,
IEC 61131-7 5.2.2 / 5.2.4: points and weights may be variables).
"""

from __future__ import annotations

import dataclasses
from collections.abc import Iterator
from dataclasses import dataclass
from typing import Any, TypeAlias


@dataclass(frozen=True)
class Slot:
    """The current value of input ``index``."""

    index: int


PParam: TypeAlias = float | Slot


# --------------------------------------------------------------------------- expressions (function terms)


@dataclass(frozen=True)
class ENum:
    value: float


@dataclass(frozen=True)
class EInput:
    slot: int


@dataclass(frozen=True)
class EOutput:
    """The defuzzified value of an output computed earlier in the same evaluation."""

    output: int


@dataclass(frozen=True)
class EX:
    """The crisp value of the variable a function membership term belongs to (``x``)."""


@dataclass(frozen=True)
class EUnary:
    op: str
    operand: ExprPlan


@dataclass(frozen=True)
class EBinary:
    op: str  # + - * / ^ %
    left: ExprPlan
    right: ExprPlan


@dataclass(frozen=True)
class ECall:
    function: str
    args: tuple[ExprPlan, ...]


ExprPlan: TypeAlias = ENum | EInput | EOutput | EX | EUnary | EBinary | ECall


def expr_children(e: ExprPlan) -> tuple[ExprPlan, ...]:
    """The expressions ``e`` applies its operator or function to (none for a leaf)."""
    if isinstance(e, EUnary):
        return (e.operand,)
    if isinstance(e, EBinary):
        return (e.left, e.right)
    return e.args if isinstance(e, ECall) else ()


def expr_nodes(e: ExprPlan) -> Iterator[ExprPlan]:
    """``e`` and every expression inside it, depth first (what a question such as "does it
    read x?" walks)."""
    yield e
    for child in expr_children(e):
        yield from expr_nodes(child)


# --------------------------------------------------------------------------- terms


@dataclass(frozen=True)
class TermPlan:
    """A term.  ``kind`` is a shape kind of :data:`fuzzyctl.model.SHAPES`, ``"points"``
    (``params`` = x0, y0, x1, y1, ...), ``"singleton"`` (``params`` = (value,)),
    ``"singletons"`` (x0, y0, ...), or ``"function"`` (``expr``).

    ``pwl`` is the breakpoint list when the term is piecewise linear with constant
    parameters (see :mod:`fuzzyctl.engine.semantics.shapes`)."""

    name: str
    kind: str
    params: tuple[PParam, ...]
    height: PParam = 1.0
    expr: ExprPlan | None = None
    pwl: tuple[tuple[float, float], ...] | None = None

    @property
    def constant(self) -> bool:
        return not isinstance(self.height, Slot) and not any(isinstance(p, Slot) for p in self.params)


@dataclass(frozen=True)
class FuzzyInputPlan:
    """An input variable with a FUZZIFY block."""

    name: str
    slot: int
    terms: tuple[TermPlan, ...]


@dataclass(frozen=True)
class InputPlan:
    name: str
    default: float | None = None  # the declared initial value: the input may be omitted
    degree: bool = False  # used as a degree (bare variable in a condition or a WITH weight)
    #: ``(low, high)``: the value is limited to this range before anything reads it
    #: (fuzzylite ``lock-range`` on an input, model ``FuzzifyBlock.clamp``)
    clamp: tuple[float, float] | None = None


# --------------------------------------------------------------------------- conditions


@dataclass(frozen=True)
class CTerm:
    """``variable IS [NOT] [hedges] term`` on a fuzzified input."""

    var: int
    term: int
    hedges: tuple[str, ...] = ()
    negated: bool = False


@dataclass(frozen=True)
class CChained:
    """``variable IS term`` on a variable concluded by other rules: the accumulated degree."""

    var: int
    term: int
    hedges: tuple[str, ...] = ()
    negated: bool = False


@dataclass(frozen=True)
class CDegree:
    """A bare variable: an input read as a degree (``slot``) or a chained variable concluded
    without a term (``chained``)."""

    slot: int | None = None
    chained: int | None = None


@dataclass(frozen=True)
class CNot:
    operand: CondPlan


@dataclass(frozen=True)
class CAnd:
    op: str
    operands: tuple[CondPlan, ...]


@dataclass(frozen=True)
class COr:
    op: str
    operands: tuple[CondPlan, ...]


@dataclass(frozen=True)
class CTrue:
    """An empty IF part: degree 1 (Siemens manual 1.5)."""


CondPlan: TypeAlias = CTerm | CChained | CDegree | CNot | CAnd | COr | CTrue


# --------------------------------------------------------------------------- rules


@dataclass(frozen=True)
class ConclusionPlan:
    """Where a rule's degree goes.  ``target`` is ``"output"`` (index into outputs) or
    ``"chained"`` (index into chained); a conclusion on a variable that is both goes to both.
    ``term`` is ``None`` for a bare-variable conclusion."""

    outputs: tuple[int, ...]
    chained: tuple[int, ...]
    term: int | None
    weight: PParam = 1.0
    hedges: tuple[str, ...] = ()


@dataclass(frozen=True)
class RulePlan:
    """A rule.  Its activation degree is ``weight * condition`` (the MATLAB / fuzzylite rule
    weight, model ``Rule.weight``), set to 0 at or below ``Options.firing_threshold``, then
    passed through the rule block's :class:`SelectionPlan` when ``selection`` is set."""

    label: str
    block: str | None
    condition: CondPlan
    act: str
    conclusions: tuple[ConclusionPlan, ...]
    weight: PParam = 1.0
    selection: int | None = None  # index into Plan.selections
    #: the rule block's own accumulation, applied as this rule is evaluated (jFuzzyLogic profile)
    accu: str | None = None


@dataclass(frozen=True)
class SelectionPlan:
    """fuzzylite's rule activation method of one rule block (model ``RuleBlock.rule_activation``):
    which of the block's ``rules`` (indices into :attr:`Plan.rules`, in block order) fire, with
    which degree.  ``method`` is ``FIRST``, ``LAST`` (the first/last ``count`` rules whose
    degree is > 0 and >= ``threshold``), ``HIGHEST``, ``LOWEST`` (the ``count`` rules with the
    highest/lowest degree > 0, earlier rules first on ties), ``PROPORTIONAL`` (every degree
    divided by their sum) or ``THRESHOLD`` (the rules whose degree satisfies ``comparison``
    ``threshold``).  Formulas: :mod:`fuzzyctl.engine.semantics.selection`."""

    method: str
    rules: tuple[int, ...]
    count: int = 1
    threshold: float = 0.0
    comparison: str = ">="


# --------------------------------------------------------------------------- outputs


@dataclass(frozen=True)
class Contribution:
    """One activated set feeding an output: rule ``rule`` (index in :attr:`Plan.rules`),
    its conclusion ``conclusion``, on ``term`` (``None``: bare degree)."""

    rule: int
    conclusion: int
    term: int | None
    act: str
    weight: PParam


@dataclass(frozen=True)
class GridPlan:
    """The output universe cut at every breakpoint of every term: on each interval
    ``[xs[j], xs[j+1]]`` every term is linear from ``left[t][j]`` (limit from the right at
    ``xs[j]``) to ``right[t][j]`` (limit from the left at ``xs[j+1]``).  ``point[t][j]`` is
    the term's degree exactly at ``xs[j]`` (the upper value on a vertical edge).  ``active[j]``
    lists the terms that are not zero on interval ``j``."""

    xs: tuple[float, ...]
    left: tuple[tuple[float, ...], ...]
    right: tuple[tuple[float, ...], ...]
    point: tuple[tuple[float, ...], ...]
    active: tuple[tuple[int, ...], ...]
    #: intervals where at least two concluded terms are nonzero (accumulation must be done
    #: pointwise there); every other interval belongs to one term alone:
    shared: tuple[int, ...] = ()
    solo: tuple[tuple[int, ...], ...] = ()  # per term: the intervals it has to itself
    #: per term, the area and first moment of min(h, term) over its solo intervals as
    #: polynomials in h: bands ``(h_low, h_high, (a0, a1, a2), (m0, m1, m2, m3))``
    #: (area = a0 + a1 h + a2 h^2, moment = m0 + ... + m3 h^3 for h_low <= h <= h_high)
    min_bands: tuple[tuple[tuple[float, float, tuple[float, ...], tuple[float, ...]], ...], ...] = ()
    #: per term, (area, moment) of the whole term over its solo intervals (PROD activation
    #: scales both by h)
    full: tuple[tuple[float, float], ...] = ()


@dataclass(frozen=True)
class OutputPlan:
    """A defuzzified (or degree) output.

    ``kind``:
      * ``"mamdani"`` - fuzzy-set terms on ``[low, high]``; ``method`` COG, COA, LM, RM, MOM.
        ``exact`` is True when every term is piecewise linear and activation/accumulation keep
        it so (closed-form integration); otherwise adaptive quadrature.  ``grid`` is set when
        the terms' parameters are constant.
      * ``"singleton"`` - singleton terms, ``method`` COGS.
      * ``"ts"`` - Takagi-Sugeno terms (constant, linear, function, or singletons under
        WTAVER/WTSUM); ``method`` WTAVER or WTSUM; ``accu`` None means every rule counts
        with its own weight (the Sugeno definition).
      * ``"degree"`` - concluded as a bare variable: the accumulated degree itself.
    """

    name: str
    kind: str
    method: str
    accu: str | None
    terms: tuple[TermPlan, ...]
    contributions: tuple[Contribution, ...]
    default: float | None
    no_change: bool
    low: float | None = None
    high: float | None = None
    exact: bool = False
    grid: GridPlan | None = None
    is_output: bool = True  # False for a local variable with DEFUZZIFY (not returned)
    #: ``(low, high)``: the final value (DEFAULT and NC included) is limited to this range
    #: (fuzzylite ``lock-range`` on an output, model ``DefuzzifyBlock.clamp``)
    clamp: tuple[float, float] | None = None


@dataclass(frozen=True)
class ChainedPlan:
    """A variable concluded by rules and read in conditions of other rules (chained
    inference): ``v IS t`` is the accumulation (``accu``) of w*a over the rules concluding
    ``v IS t``; a bare conclusion accumulates into ``bare``."""

    name: str
    terms: tuple[str, ...]
    accu: str


@dataclass(frozen=True)
class Options:
    """Semantic switches.  The defaults are IEC 61131-7; ``compat`` profiles reproduce other
    tools for cross-checking (see docs/engine.md)."""

    weight_before_activation: bool = False  # fuzzylite/jFuzzyLogic: act(w*a, mu) instead of w*act(a, mu)
    firing_threshold: float = 0.0  # fuzzylite C++ fires a rule only when its degree > 1e-6
    ts_default_accu: str | None = None  # accumulation of Takagi-Sugeno outputs without ACCU
    singleton_default_accu: str | None = None  # COGS outputs without ACCU (None: MAX)
    hedges_carry_over: bool = False  # fuzzylite 6: a conclusion's hedges modify the next ones
    weight_whole_rule: bool = False  # jFuzzyLogic: a WITH anywhere in a rule weights every conclusion
    quad_rtol: float = 1e-10
    #: an output without RANGE whose terms do not fall to 0 is an error instead of taking the
    #: span of its terms (``--strict``)
    strict: bool = False
    #: jFuzzyLogic: the universe is always the span of the terms, never their supports' hull
    span_universe: bool = False
    #: jFuzzyLogic: a RANGE on the VAR declaration line is ignored (only DEFUZZIFY's counts)
    ignore_declared_range: bool = False
    #: ``"jfuzzylogic"``: the plan is evaluated by :mod:`fuzzyctl.engine.compat.jfl`, which reproduces
    #: jFuzzyLogic 3.3 (its 1000-point defuzzification and the rest, docs/engine.md); the
    #: code generators refuse such a plan
    emulate: str | None = None


@dataclass(frozen=True)
class Plan:
    """A lowered function block."""

    name: str | None
    inputs: tuple[InputPlan, ...]
    fuzzy_inputs: tuple[FuzzyInputPlan, ...]
    chained: tuple[ChainedPlan, ...]
    rules: tuple[RulePlan, ...]
    order: tuple[int, ...]  # rule evaluation order (chained dependencies first)
    outputs: tuple[OutputPlan, ...]
    output_order: tuple[int, ...]  # defuzzification order (function terms read earlier outputs)
    options: Options = Options()
    selections: tuple[SelectionPlan, ...] = ()  # rule activation methods of rule blocks (fuzzylite)

    def input_index(self, name: str) -> int:
        for i, inp in enumerate(self.inputs):
            if inp.name == name:
                return i
        raise KeyError(name)

    def terms_read(self) -> list[tuple[int, int]]:
        """``(fuzzy input, term)`` pairs some rule condition reads, sorted: the only terms a
        scalar evaluation needs to fuzzify (``any`` reads no term)."""
        needed: set[tuple[int, int]] = set()

        def collect(c: CondPlan) -> None:
            if isinstance(c, CTerm) and "any" not in c.hedges:
                needed.add((c.var, c.term))
            elif isinstance(c, CNot):
                collect(c.operand)
            elif isinstance(c, CAnd | COr):
                for o in c.operands:
                    collect(o)

        for r in self.rules:
            collect(r.condition)
        return sorted(needed)

    def to_dict(self) -> dict[str, Any]:
        """A JSON-ready view (dataclass names kept under ``"type"``)."""
        return _to_jsonable(self)  # type: ignore[no-any-return]


def _to_jsonable(obj: Any) -> Any:
    if dataclasses.is_dataclass(obj) and not isinstance(obj, type):
        out: dict[str, Any] = {"type": type(obj).__name__}
        for f in dataclasses.fields(obj):
            out[f.name] = _to_jsonable(getattr(obj, f.name))
        return out
    if isinstance(obj, tuple | list):
        return [_to_jsonable(v) for v in obj]
    return obj
