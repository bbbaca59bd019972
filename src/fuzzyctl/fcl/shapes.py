"""The one table of parametric membership-function spellings.

Each :class:`Spelling` says how a tool writes a shape and how its parameters map onto the
canonical kind of :data:`fuzzyctl.model.SHAPES`.  The reader uses it to build
:class:`~fuzzyctl.model.ShapeMF` objects, the writer uses it (through :func:`spelling_for`)
to write them back.  Every mapping was checked against the tool's source:

* jFuzzyLogic ``FunctionBlock.fclTreeFuzzifyTerm*`` and ``membership/MembershipFunction*.java``
  (e.g. ``GBELL a b mean`` is ``1 / (1 + |(x - mean) / a|^(2b))``, ``SIGM gain center``,
  ``DSIGM a1 c1 a2 c2`` is ``max(s1 - s2, 0)``, ``COSINE net_max offset`` has half-width
  ``net_max``);
* fuzzylite ``src/term/*.cpp`` (``configure()`` gives the parameter order, an optional extra
  parameter is the height);
* scalablurry ``FclParser.scala`` (``triangular``, ``trapetzoidal``, ``gaussian``,
  ``generalizedBell divisor exponent center``, ``sigmoidal gain center``).
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Sequence
from dataclasses import dataclass

from fuzzyctl.kinds import shapes as registry
from fuzzyctl.model import SHAPES, Param, Ref, ShapeMF


@dataclass(frozen=True)
class Spelling:
    """One way of writing a parametric shape.

    ``order[i]`` is the position, in the written parameter list, of the canonical parameter
    ``i``; ``scale[i]`` multiplies it (jFuzzyLogic's COSINE gives a half-width).  A scaled
    parameter given as a variable cannot be multiplied, so such a term becomes
    ``ref_kind`` with the written values as they are."""

    written: str
    kind: str
    order: tuple[int, ...]
    dialect: str
    height: bool = False
    scale: tuple[float, ...] | None = None
    ref_kind: str | None = None
    variadic: bool = False

    @property
    def arity(self) -> int:
        return len(self.order)

    def describe(self) -> str:
        names = SHAPES[self.kind].params
        written = [""] * self.arity
        for i, pos in enumerate(self.order):
            factor = self.scale[i] if self.scale else 1.0
            written[pos] = names[i] if factor == 1.0 else f"{names[i]}/{factor:g}"
        extra = " [height]" if self.height else ""
        return f"{self.written} {' '.join(written)}{extra}".strip()


JFL, FL, SB = registry.JFL, registry.FL, registry.SB
_DIALECTS = (JFL, FL, SB)


def _spellings() -> tuple[Spelling, ...]:
    """Every FCL spelling of the registry's entries, jFuzzyLogic's first, then fuzzylite's,
    then scalablurry's (the first of a name wins when names clash without case)."""
    out: list[Spelling] = []
    for shape in registry.ENTRIES:
        fcl = shape.spellings.fcl
        if isinstance(fcl, registry.NA):
            continue
        for w in fcl:
            if not w.write_only:
                spelling = Spelling(w.name, shape.kind, w.order, w.dialect, w.height, w.scale, w.ref_kind)
                out.append(dataclasses.replace(spelling, variadic=w.variadic))
    return tuple(sorted(out, key=lambda s: _DIALECTS.index(s.dialect)))


def _written_only() -> dict[str, Spelling]:
    """Kinds the reader never gives (a cosine whose half width is a variable) and how the
    writer spells them."""
    out: dict[str, Spelling] = {}
    for shape in registry.ENTRIES:
        fcl = shape.spellings.fcl
        for w in () if isinstance(fcl, registry.NA) else fcl:
            if w.write_only:
                out[shape.kind] = Spelling(w.name, shape.kind, w.order, w.dialect)
    return out


SPELLINGS: tuple[Spelling, ...] = _spellings()
WRITE_ONLY: dict[str, Spelling] = _written_only()

# Names are case-insensitive, as FCL keywords are, with one clash: jFuzzyLogic ``COSINE
# net_max offset`` and fuzzylite ``Cosine center width``.  fuzzylite always writes exactly
# ``Cosine``, so that exact spelling is fuzzylite's and every other casing jFuzzyLogic's.
# (``gaussian``, scalablurry, is fuzzylite's ``Gaussian`` with the same parameters.)
BY_EXACT: dict[str, Spelling] = {s.written: s for s in SPELLINGS}
BY_NAME: dict[str, Spelling] = {}
for _s in SPELLINGS:
    BY_NAME.setdefault(_s.written.upper(), _s)

# Written back in jFuzzyLogic's spelling where jFuzzyLogic has the shape (the FCL dialect most
# tools read), otherwise in fuzzylite's.
_PREFERRED: dict[str, Spelling] = {}
for _s in SPELLINGS:
    if _s.dialect == JFL:
        _PREFERRED.setdefault(_s.kind, _s)
for _s in SPELLINGS:
    if _s.dialect == FL:
        _PREFERRED.setdefault(_s.kind, _s)


class ShapeError(ValueError):
    """A shape written with the wrong number of parameters (message for people)."""


def lookup(name: str) -> Spelling | None:
    """The spelling called ``name`` (case-insensitive), or ``None``."""
    return BY_EXACT.get(name) or BY_NAME.get(name.upper())


def build(spelling: Spelling, args: Sequence[Param]) -> ShapeMF:
    """The canonical shape for ``spelling`` applied to the written ``args``."""
    if spelling.variadic:
        if not args:
            raise ShapeError(f"{spelling.written} needs at least one coefficient")
        return ShapeMF(spelling.kind, tuple(args))
    height: Param = 1.0
    values = list(args)
    if spelling.height and len(values) == spelling.arity + 1:
        height = values.pop()
    if len(values) != spelling.arity:
        extra = f" (or {spelling.arity + 1} with a height)" if spelling.height else ""
        raise ShapeError(
            f"{spelling.written} takes {spelling.arity} parameters{extra}: "
            f"{spelling.describe()}; got {len(args)}"
        )
    kind = spelling.kind
    if spelling.scale and any(
        isinstance(values[pos], Ref) and spelling.scale[i] != 1.0 for i, pos in enumerate(spelling.order)
    ):
        kind = spelling.ref_kind or kind
        return ShapeMF(kind, tuple(values[pos] for pos in spelling.order), height)
    params: list[Param] = []
    for i, pos in enumerate(spelling.order):
        value = values[pos]
        if spelling.scale and not isinstance(value, Ref):
            value = value * spelling.scale[i]
        params.append(value)
    return ShapeMF(kind, tuple(params), height)


def spelling_for(mf: ShapeMF) -> Spelling:
    """How the writer spells ``mf``: jFuzzyLogic's name where it can express the term
    exactly, else fuzzylite's."""
    if mf.kind in WRITE_ONLY:
        return WRITE_ONLY[mf.kind]
    preferred = _PREFERRED.get(mf.kind)
    if preferred is None:
        raise KeyError(f"no spelling for shape kind {mf.kind!r}")
    needs_fuzzylite = mf.height != 1.0 or (
        preferred.scale is not None and any(isinstance(p, Ref) for p in mf.params)
    )
    if preferred.dialect == JFL and not needs_fuzzylite:
        # a jFuzzyLogic spelling only for what jFuzzyLogic accepts (it rejects GAUSS2 with
        # mean1 > mean2, which fuzzylite's product form reads): the entry's degenerate rule
        # for jFuzzyLogic
        needs_fuzzylite = _jfl_refuses(mf)
    if needs_fuzzylite and preferred.dialect != FL:
        return next(s for s in SPELLINGS if s.kind == mf.kind and s.dialect == FL)
    return preferred


def _jfl_refuses(mf: ShapeMF) -> bool:
    shape = registry.SHAPES[mf.kind]
    rule = shape.jfl_refuses
    if isinstance(rule, registry.NA):
        return False
    # a parameter given by a variable is unknown here: NaN compares false
    return rule([math.nan if isinstance(p, Ref) else float(p) for p in mf.params])


def written_args(spelling: Spelling, mf: ShapeMF) -> list[Param]:
    """The parameters in ``spelling``'s order (height appended when it is not 1)."""
    if spelling.variadic:
        return list(mf.params)
    out: list[Param] = [0.0] * spelling.arity
    for i, pos in enumerate(spelling.order):
        value = mf.params[i]
        if spelling.scale and not isinstance(value, Ref):
            value = value / spelling.scale[i]
        out[pos] = value
    if mf.height != 1.0:
        out.append(mf.height)
    return out


def _self_check() -> None:
    for s in SPELLINGS:
        assert s.kind in SHAPES, s
        if not s.variadic:
            assert sorted(s.order) == list(range(len(SHAPES[s.kind].params))), s
    missing = set(SHAPES) - {s.kind for s in SPELLINGS} - set(WRITE_ONLY)
    assert not missing, missing


_self_check()
