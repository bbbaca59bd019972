"""The defuzzification methods: one entry per method, read by every consumer (readers and
writers of each format, the lowering, the reference interpreter, the numpy kernels, the IR
builders of the native evaluator) instead of comparing method names.

An entry says what the method is (``integrating``: it integrates the accumulated set over
the output range, CoG and CoA; ``maximum``: which point of the set's maximum it picks, LM,
RM and MoM; ``weighted``: a weighted mean or sum of points, singletons and Takagi-Sugeno),
how each file format spells it (the first spelling is the one written), and where its
implementations live: ``reference`` (the readable definition every path is tested against),
``ir`` (the IR builder of the native evaluator) and, optionally, ``numpy`` (a hand-written
vectorised kernel, kept only where it was measured faster than the IR rendered as numpy;
without one a batch runs the IR rendered: :mod:`fuzzyctl.ir.kernels.rendered`).
Implementations are named ``"module:qualified.name"`` (resolved by
:func:`implementation`) so that this module stays at the bottom of the import stack.

Adding a method: an entry here, its reference function in :mod:`fuzzyctl.engine.reference.pwl`
(``(pieces, points, area, moment) -> value``) and its IR builder in
:mod:`fuzzyctl.ir.builders.grid_pieces` (``(g, pieces, grid, areas, total) -> value``), the
entry's kind flags left unset (:attr:`Method.on_pieces`: piecewise-linear outputs only; the
PLC block's run-time grid refuses it).  tests/kinds/test_methods.py checks that every entry
is complete and resolves; tests/engine/test_rendered_method.py adds one at test time.
"""

from __future__ import annotations

import functools
import importlib
from collections.abc import Callable, Mapping
from dataclasses import dataclass, field
from typing import Any, Literal

from fuzzyctl.formatspec import BUILTIN

IEC = "IEC 61131-7"
FL = "fuzzylite"
JFL = "jFuzzyLogic"

#: The file formats whose spellings an entry lists.
FORMATS = tuple(spec.name for spec in BUILTIN)

Maximum = Literal["left", "right", "mean"]


@dataclass(frozen=True)
class Method:
    """One defuzzification method (see the module docstring)."""

    code: str
    title: str
    #: format -> spellings accepted when reading (first: the one written); an empty tuple:
    #: the format cannot express the method
    spellings: Mapping[str, tuple[str, ...]]
    #: integrates the accumulated set over the range (area and moment)
    integrating: bool = False
    #: the point of the maximum it answers (LM ``left``, RM ``right``, MoM ``mean``)
    maximum: Maximum | None = None
    #: a weighted mean (``"average"``) or sum (``"sum"``) of points (singletons, Takagi-Sugeno)
    weighted: Literal["average", "sum"] | None = None
    #: the bisector of the area (CoA) rather than its centroid (CoG)
    bisects: bool = False
    reference: str = ""
    ir: str = ""
    numpy: str = ""
    #: notes on spellings (FCL keyword table: spelling -> where it comes from)
    notes: Mapping[str, str] = field(default_factory=dict)
    #: other names the lowering accepts for it (MATLAB's, in models built by hand)
    aliases: tuple[str, ...] = ()
    #: the method the lowering evaluates it as (jFuzzyLogic's COGF is a weighted average)
    lowers_to: str | None = None
    #: a Takagi-Sugeno method (weights the values of singleton, linear or function terms);
    #: the others weighting points (COGS) are the IEC methods of singleton outputs
    takagi_sugeno: bool = False
    #: its IEC 61131-7 conformance level: ``basic`` (COGS), ``extension`` (the other methods
    #: of Table 1) or ``open`` (another tool's)
    conformance: Literal["basic", "extension", "open"] = "open"
    #: the FCL keywords jFuzzyLogic reads for it (empty: jFuzzyLogic has no such method)
    jfl: tuple[str, ...] = ()
    #: meant for FUNCTION terms (a warning when an output using it has none)
    for_function_terms: bool = False

    @property
    def centroid(self) -> bool:
        """CoG: the centroid of the accumulated set."""
        return self.integrating and not self.bisects

    @property
    def on_pieces(self) -> bool:
        """A method of none of the kinds above (not integrating, no maximum, not weighted):
        defined only by its ``reference`` and ``ir`` on the linear pieces of an exact
        (piecewise-linear) accumulated set; the lowering refuses it on other outputs."""
        return not (self.integrating or self.maximum is not None or self.weighted is not None)

    @property
    def on_sets(self) -> bool:
        """Defuzzifies the accumulated fuzzy set over the range (fuzzylite's integral
        defuzzifiers: they take a resolution)."""
        return self.integrating or self.maximum is not None

    def written(self, fmt: str) -> str | None:
        """The spelling ``fmt`` writes (FCL and JSON: the code), None when it cannot express
        the method."""
        names = self.spellings.get(fmt, ())
        if fmt in ("fcl", "json"):
            return self.code if names else None
        return names[0] if names else None


def _entry(
    code: str, title: str, fcl: dict[str, str], others: dict[str, tuple[str, ...]], **kw: Any
) -> Method:
    """An entry: ``fcl`` its FCL spellings with their notes, ``others`` the other formats'."""
    spellings = {"fcl": tuple(fcl), **{f: others.get(f, ()) for f in FORMATS if f != "fcl"}}
    spellings["json"] = (code,)
    return Method(code, title, spellings, notes=fcl, **kw)


_PWL = "fuzzyctl.engine.reference.pwl"
_GRID = "fuzzyctl.ir.builders.grid_pieces"
_NP = "fuzzyctl.ir.kernels.columns"
_WEIGHTED = {
    "reference": "fuzzyctl.engine.reference.interp:weighted_value",
    "ir": "fuzzyctl.ir.builders.rules:RuleBuilder.ts",
    "numpy": _NP + ":whole_output",
}

# the order is the FCL keyword table's (fcl/keywords.py lists the spellings in it)
METHODS: dict[str, Method] = {
    m.code: m
    for m in (
        _entry(
            "COG",
            "centre of gravity",
            {"COG": IEC + " Table 1: centre of gravity"},
            {
                "fis": ("centroid", "centroid_integral"),  # the Octave demos' integral centroid
                "fll": ("Centroid",),
                "fpl": ("COG",),
                "xfuz": ("COG",),
            },
            aliases=("CENTROID",),
            conformance="extension",
            jfl=("COG",),
            integrating=True,
            reference=_PWL + ":centroid",
            ir="fuzzyctl.ir.programs.evaluator:FastBuilder.closed_cog",
            numpy=_NP + ":centroid",
        ),
        _entry(
            "COGS",
            "centre of gravity for singletons",
            {"COGS": IEC + " Table 1: centre of gravity for singletons (fuzzylite: WeightedAverage)"},
            {"fpl": ("COGS",), "xfuz": ("COGS",)},
            weighted="average",
            conformance="basic",
            jfl=("COGS",),
            reference="fuzzyctl.engine.reference.interp:weighted_value",
            ir="fuzzyctl.ir.builders.rules:RuleBuilder.singleton",
            numpy="fuzzyctl.ir.render.npsrc:vectorise",
        ),
        _entry(
            "COA",
            "centre of area (bisector)",
            {"COA": IEC + " Table 1: centre of area (bisector)", "BIS": "fuzzylite 4: Bisector"},
            {"fis": ("bisector",), "fll": ("Bisector",)},
            aliases=("BISECTOR",),
            conformance="extension",
            jfl=("COA",),
            integrating=True,
            bisects=True,
            reference=_PWL + ":bisector_value",
            ir=_GRID + ":bisector_by_intervals",
            numpy=_NP + ":bisector_value",
        ),
        _entry(
            "LM",
            "left-most maximum",
            {
                "LM": IEC + " Table 1: left-most maximum (fuzzylite: SmallestOfMaximum)",
                "SOM": "fuzzylite 4: SmallestOfMaximum",
            },
            {"fis": ("som",), "fll": ("SmallestOfMaximum",)},
            maximum="left",
            conformance="extension",
            jfl=("LM",),
            reference=_PWL + ":leftmost",
            ir=_GRID + ":leftmost",
            numpy=_NP + ":maximum_point",
        ),
        _entry(
            "RM",
            "right-most maximum",
            {
                "RM": IEC + " Table 1: right-most maximum (fuzzylite: LargestOfMaximum)",
                "LOM": "fuzzylite 4: LargestOfMaximum",
            },
            {"fis": ("lom",), "fll": ("LargestOfMaximum",)},
            maximum="right",
            conformance="extension",
            jfl=("RM",),
            reference=_PWL + ":rightmost",
            ir=_GRID + ":rightmost",
            numpy=_NP + ":maximum_point",
        ),
        _entry(
            "MOM",
            "mean of maximum",
            {"MM": JFL + " / " + FL + ": mean of maximum", "MOM": "mean of maximum"},
            {"fis": ("mom",), "fll": ("MeanOfMaximum",), "xfuz": ("MOM",)},
            maximum="mean",
            jfl=("MM", "MOM"),
            reference=_PWL + ":mean_of_maximum",
            ir=_GRID + ":mean_of_maximum",
            numpy=_NP + ":maximum_point",
        ),
        _entry(
            "COGF",
            "centre of gravity of FUNCTION terms",
            {"COGF": JFL + ": centre of gravity of FUNCTION terms"},
            {},
            weighted="average",
            takagi_sugeno=True,
            lowers_to="WTAVER",  # jFuzzyLogic's COGF is the weighted average of the terms' values
            jfl=("COGF",),
            for_function_terms=True,
            **_WEIGHTED,
        ),
        _entry(
            "WTSUM",
            "weighted sum (Takagi-Sugeno)",
            {"COGSS": FL + ": WeightedSum (Takagi-Sugeno)", "WTSUM": "weighted sum (Takagi-Sugeno)"},
            {"fis": ("wtsum",), "fll": ("WeightedSum",)},
            weighted="sum",
            takagi_sugeno=True,
            **_WEIGHTED,
        ),
        _entry(
            "WTAVER",
            "weighted average (Takagi-Sugeno)",
            {"WTAVER": "weighted average (MATLAB wtaver)"},
            {"fis": ("wtaver",), "fll": ("WeightedAverage",)},
            aliases=("WTAV",),
            weighted="average",
            takagi_sugeno=True,
            **_WEIGHTED,
        ),
    )
}

#: Every method code.
CODES = frozenset(METHODS)


def method(code: str) -> Method:
    """The entry of ``code`` (a canonical code, e.g. from a plan)."""
    return METHODS[code]


def spelled(fmt: str) -> dict[str, str]:
    """Spelling -> code for format ``fmt`` (what its reader accepts)."""
    return {s: m.code for m in METHODS.values() for s in m.spellings.get(fmt, ())}


def jfl_spelled() -> dict[str, str]:
    """jFuzzyLogic's FCL keyword -> code, for the methods it has."""
    return {s: code for code, m in METHODS.items() for s in m.jfl}


def lowering_aliases() -> dict[str, str]:
    """Name -> the code the lowering evaluates it as, for every name that is not itself the
    code evaluated (FCL synonyms, MATLAB names, COGF)."""
    out: dict[str, str] = {}
    for m in METHODS.values():
        target = m.lowers_to or m.code
        for name in (*m.spellings["fcl"], *m.aliases, m.code):
            if name != target:
                out[name] = target
    return out


def written(fmt: str) -> dict[str, str]:
    """Code -> the spelling format ``fmt`` writes (methods it can express)."""
    return {m.code: w for m in METHODS.values() if (w := m.written(fmt)) is not None}


def codes(predicate: Callable[[Method], bool]) -> frozenset[str]:
    """The codes of the methods satisfying ``predicate``."""
    return frozenset(m.code for m in METHODS.values() if predicate(m))


@functools.cache
def implementation(path: str) -> Any:
    """The object ``"module:qualified.name"`` names."""
    module, _, qual = path.partition(":")
    obj: Any = importlib.import_module(module)
    for part in qual.split("."):
        obj = getattr(obj, part)
    return obj


def ts_method(code: str | None) -> str:
    """The method a Takagi-Sugeno output evaluates: its own when it is one (WTAVER, WTSUM),
    else the weighted average (COG, COGS or none written)."""
    m = METHODS.get(code or "")
    return m.code if m is not None and m.takagi_sugeno and m.lowers_to is None else _TS_AVERAGE


def singleton_centroid(code: str | None) -> bool:
    """Whether ``code`` is a centroid of singletons: COG, COGS or none written."""
    m = METHODS.get(code or "COGS")
    return m is not None and (m.centroid or (m.weighted == "average" and not m.takagi_sugeno))


def singleton_method(code: str | None) -> str:
    """The method a singleton output evaluates: COGS for a centroid (COG, COGS, none
    written), else the method itself (LM, RM, MoM pick among the singletons)."""
    m = METHODS.get(code or "")
    return code if m is not None and not m.centroid and m.weighted is None else _SINGLETONS  # type: ignore[return-value]


_TS_AVERAGE = "WTAVER"
_SINGLETONS = "COGS"

#: Methods defuzzifying the accumulated set over the range (CoG, CoA, LM, RM, MoM).
ON_SETS = codes(lambda m: m.on_sets)
#: Methods weighting points (singleton and Takagi-Sugeno outputs).
WEIGHTED = codes(lambda m: m.weighted is not None)
#: Takagi-Sugeno methods.
TAKAGI_SUGENO = codes(lambda m: m.takagi_sugeno)
#: The methods of point outputs as models hold them (COGS, WTAVER, WTSUM; COGF is read as
#: jFuzzyLogic's and lowered to WTAVER).
POINT_OUTPUTS = codes(lambda m: m.weighted is not None and m.lowers_to is None)
#: The Takagi-Sugeno methods as models hold them (WTAVER, WTSUM).
SUGENO = codes(lambda m: m.takagi_sugeno and m.lowers_to is None)
