"""The fuzzy operators as kinds: one entry per AND norm (t-norm, also an activation method),
OR norm (t-conorm) and accumulation method, read by every consumer (the writers of each
format, the conformance statement, the reference interpreter, the IR builders and kernels,
the fixed-point code, the tuner, the analyses) instead of comparing operator names.

The formulas themselves (float, numpy and the IR's source template) are the operators table,
:mod:`fuzzyctl.engine.semantics.operators`; an entry here says what the operator *is*:

* ``idempotent``: ``op(a, a) = a``.  MIN is the only idempotent t-norm and MAX the only
  idempotent t-conorm, so this is "the minimum" / "the maximum": an activation that clips a
  term at the rule's degree (a plateau), an accumulation whose result is the upper envelope
  of the activated sets (equal sets merge, two sets have a closed-form area);
* ``product``: the algebraic product, an activation that scales a term by the degree (a
  weight folds into the degree, a piecewise-linear term stays piecewise linear);
* ``fixed``: its form in integer (fixed-point) code, None when the integer code has none;
* the IEC 61131-7 conformance level of each use (``basic``, ``extension``, ``open``) and the
  spellings of the formats with a fixed operator set (XFUZ's operator code).

Adding an operator: its formulas in the operators table, an entry here;
tests/kinds/test_norms.py checks that every name of the table has a complete entry.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass
from typing import Literal

Level = Literal["basic", "extension", "open"]

#: What the branch code of the smooth quadrature tests after adding a set (the IR twin of the
#: reference's ``accumulated_branch``): ``larger`` which set is larger than what is
#: accumulated so far, ``sum_below_one`` whether the two sum below 1, ``both_positive``
#: whether both are above 0, ``at_one`` whether the result reached 1.
BranchTest = Literal["larger", "sum_below_one", "both_positive", "at_one"]


@dataclass(frozen=True)
class TNorm:
    """An AND operator, also accepted as an activation method (see the module docstring)."""

    name: str
    title: str
    #: the conformance level of ``AND : name`` (Table 3) and of ``ACT : name`` (Table 4)
    and_conformance: Level
    act_conformance: Level
    idempotent: bool = False
    product: bool = False
    fixed: Literal["min", "product", "bounded_difference"] | None = None
    #: XFUZ's operator code (None: XFUZ offers MIN and PROD only)
    xfuz: int | None = None

    @property
    def clips(self) -> bool:
        """As an activation: clips the term at the rule's degree (MIN)."""
        return self.idempotent

    @property
    def scales(self) -> bool:
        """As an activation: scales the term by the rule's degree (PROD)."""
        return self.product

    @property
    def keeps_lines(self) -> bool:
        """As an activation: keeps a piecewise-linear term piecewise linear with a closed
        form the gradient and the learners use (MIN and PROD)."""
        return self.idempotent or self.product


@dataclass(frozen=True)
class SNorm:
    """An OR operator (a t-conorm)."""

    name: str
    title: str
    #: the conformance level of ``OR : name`` (Table 3)
    or_conformance: Level
    idempotent: bool = False
    fixed: Literal["max", "probabilistic_sum", "bounded_sum"] | None = None


@dataclass(frozen=True)
class Accumulation:
    """An accumulation method (Table 5 and other tools'): how the activated sets of one
    output combine pointwise."""

    name: str
    title: str
    conformance: Level
    #: the pointwise maximum (the upper envelope of the sets)
    idempotent: bool = False
    #: the plain sum (SUM, NSUM): each set integrates on its own
    additive: bool = False
    #: the sum cut at 1 (BSUM)
    bounded: bool = False
    #: the probabilistic sum a + b - ab (PROBOR)
    probabilistic: bool = False
    #: divided by max(1, the maximum over the range) where degrees are shown or reused (NSUM)
    normalised: bool = False
    #: the value follows the largest set, so where two sets cross it bends (MAX, NIPMAX, DMAX)
    picks_largest: bool = False
    #: it jumps to 1 (NIPMAX where two sets sum to 1, DMAX where both are above 0)
    jumps_to_one: bool = False
    #: what the smooth quadrature's branch code tests after adding a set (:data:`BranchTest`)
    branch_tests: frozenset[BranchTest] = frozenset()
    #: integrated exactly on piecewise-linear activated sets
    exact: bool = False
    #: the accumulation it only scales by a constant (the same defuzzified value): what the
    #: formats without it (FIS, FLL) write instead
    stand_in: str | None = None
    #: how jFuzzyLogic evaluates it (NSUM as BSUM)
    jfl: str = ""

    @property
    def saturates(self) -> bool:
        """Reaches 1 by a bound or a jump (BSUM, NIPMAX, DMAX)."""
        return self.bounded or self.jumps_to_one


_B: Level = "basic"
_E: Level = "extension"
_O: Level = "open"

TNORMS: Mapping[str, TNorm] = {
    n.name: n
    for n in (
        TNorm("MIN", "minimum", _B, _E, idempotent=True, fixed="min", xfuz=0),
        TNorm("PROD", "algebraic product", _E, _E, product=True, fixed="product", xfuz=1),
        TNorm("BDIF", "bounded difference", _E, _O, fixed="bounded_difference"),
        TNorm("DMIN", "drastic product", _O, _O),
        TNorm("NIPMIN", "nilpotent minimum", _O, _O),
        TNorm("HAMACHER", "Hamacher product", _O, _O),
        TNorm("EINSTEIN", "Einstein product", _O, _O),
    )
}

SNORMS: Mapping[str, SNorm] = {
    n.name: n
    for n in (
        SNorm("MAX", "maximum", _E, idempotent=True, fixed="max"),
        SNorm("ASUM", "algebraic (probabilistic) sum", _E, fixed="probabilistic_sum"),
        SNorm("BSUM", "bounded sum", _E, fixed="bounded_sum"),
        SNorm("DMAX", "drastic sum", _O),
        SNorm("NIPMAX", "nilpotent maximum", _O),
        SNorm("HAMACHER", "Hamacher sum", _O),
        SNorm("EINSTEIN", "Einstein sum", _O),
    )
}

ACCUMULATIONS: Mapping[str, Accumulation] = {
    n.name: n
    for n in (
        Accumulation(
            "MAX",
            "maximum",
            _B,
            idempotent=True,
            picks_largest=True,
            branch_tests=frozenset({"larger"}),
            exact=True,
            jfl="MAX",
        ),
        Accumulation(
            "BSUM",
            "bounded sum",
            _E,
            bounded=True,
            branch_tests=frozenset({"at_one"}),
            exact=True,
            jfl="BSUM",
        ),
        Accumulation(
            "NSUM",
            "normalised sum",
            _E,
            additive=True,
            normalised=True,
            exact=True,
            stand_in="SUM",
            jfl="BSUM",
        ),
        Accumulation("SUM", "unbounded sum", _O, additive=True, exact=True, jfl="SUM"),
        Accumulation("PROBOR", "probabilistic sum", _O, probabilistic=True, exact=True, jfl="PROBOR"),
        Accumulation("EINSTEIN", "Einstein sum", _O, jfl="EINSTEIN"),
        Accumulation("HAMACHER", "Hamacher sum", _O, jfl="HAMACHER"),
        Accumulation(
            "DMAX",
            "drastic sum",
            _O,
            picks_largest=True,
            jumps_to_one=True,
            branch_tests=frozenset({"both_positive"}),
            jfl="DMAX",
        ),
        Accumulation(
            "NIPMAX",
            "nilpotent maximum",
            _O,
            picks_largest=True,
            jumps_to_one=True,
            branch_tests=frozenset({"larger", "sum_below_one"}),
            jfl="NIPMAX",
        ),
    )
}


def tnorm(name: str | None) -> TNorm | None:
    """The entry of an AND operator or activation stored as ``name`` (None: absent, or not
    a canonical name)."""
    return TNORMS.get(name) if name is not None else None


def snorm(name: str | None) -> SNorm | None:
    """The entry of an OR operator stored as ``name`` (None: absent or not canonical)."""
    return SNORMS.get(name) if name is not None else None


def accumulation(name: str | None) -> Accumulation | None:
    """The entry of an accumulation stored as ``name`` (None: absent or not canonical)."""
    return ACCUMULATIONS.get(name) if name is not None else None


def is_min(name: str | None) -> bool:
    """``name`` is the minimum (the idempotent t-norm: an activation that clips)."""
    e = tnorm(name)
    return e is not None and e.idempotent


def is_prod(name: str | None) -> bool:
    """``name`` is the algebraic product (an activation that scales)."""
    e = tnorm(name)
    return e is not None and e.product


def is_max(name: str | None) -> bool:
    """``name`` is the maximum, as an OR operator or an accumulation (idempotent)."""
    e = snorm(name) or accumulation(name)
    return e is not None and e.idempotent


def accumulates_by_max(name: str | None) -> bool:
    """An output accumulated by ``name`` (absent: MAX, the default) takes the maximum."""
    return not name or is_max(name)


def adds(name: str | None) -> bool:
    """``name`` is a plain sum (SUM or NSUM)."""
    e = accumulation(name)
    return e is not None and e.additive


def bounded(name: str | None) -> bool:
    """``name`` is the bounded sum (BSUM)."""
    e = accumulation(name)
    return e is not None and e.bounded


def probabilistic(name: str | None) -> bool:
    """``name`` is the probabilistic sum (PROBOR)."""
    e = accumulation(name)
    return e is not None and e.probabilistic


def normalised(name: str | None) -> bool:
    """``name`` is normalised where degrees are shown or reused (NSUM)."""
    e = accumulation(name)
    return e is not None and e.normalised


def stand_in(name: str | None) -> str | None:
    """What a format without accumulation ``name`` writes instead (NSUM: SUM), None when
    ``name`` needs none."""
    e = accumulation(name)
    return e.stand_in if e is not None else None


def xfuz_code(name: str | None) -> int | None:
    """XFUZ's code of the AND operator or activation ``name`` (absent: MIN's), None when
    XFUZ cannot say it."""
    if name is None:
        return TNORMS["MIN"].xfuz
    e = tnorm(name)
    return e.xfuz if e is not None else None


Role = Literal["AND", "OR", "ACT", "ACCU"]


def conformance(role: Role, name: str | None) -> Level:
    """The IEC 61131-7 conformance level of ``role : name`` in a rule block (absent:
    ``basic``, the default MIN/MAX; a name of no entry: ``open``)."""
    if name is None:
        return "basic"
    if role == "OR":
        s = snorm(name)
        return s.or_conformance if s is not None else "open"
    if role == "ACCU":
        a = accumulation(name)
        return a.conformance if a is not None else "open"
    t = tnorm(name)
    if t is None:
        return "open"
    return t.and_conformance if role == "AND" else t.act_conformance


def keeps_lines(name: str | None) -> bool:
    """``name`` is MIN or PROD (:attr:`TNorm.keeps_lines`)."""
    e = tnorm(name)
    return e is not None and e.keeps_lines


def plain_sum_or_max(name: str | None, bounded_too: bool = False) -> bool:
    """An accumulation by ``name`` (absent: MAX) is the maximum or the unnormalised sum (and,
    with ``bounded_too``, the bounded sum): the ones the tuner differentiates in closed form."""
    e = accumulation(name or "MAX")
    if e is None:
        return False
    return e.idempotent or (e.additive and not e.normalised) or (bounded_too and e.bounded)
