"""How MATLAB / Octave / fuzzylite membership functions map onto the model's shapes.

Parameter orders differ between tools; each entry gives the model kind and, for every
model parameter, the index of the tool's parameter that feeds it.  The formulas were
checked against the sources: MATLAB's ``mf.c`` (Fuzzy Logic Toolbox C engine: ``dsigmf`` is
``|f1 - f2|``, ``smf``/``zmf`` the quadratic splines joined at the midpoint, ``pimf`` their
product, ``gauss2mf`` the product of two one-sided Gaussians), fuzzylite's term classes and
``FisImporter`` (which applies the same permutations), pyfuzzylite 8 (Arc, SemiEllipse).
"""

from __future__ import annotations

from dataclasses import dataclass

from fuzzyctl.kinds import shapes as registry
from fuzzyctl.model import ShapeMF


@dataclass(frozen=True)
class ShapeMap:
    """A tool's membership type: the model kind and where each model parameter comes from."""

    kind: str
    order: tuple[int, ...]  # model parameter i is tool parameter order[i]

    @property
    def arity(self) -> int:
        return len(self.order)

    def to_model(self, params: list[float]) -> tuple[float, ...]:
        return tuple(params[i] for i in self.order)

    def from_model(self, params: tuple[float, ...]) -> list[float]:
        out = [0.0] * len(self.order)
        for model_index, tool_index in enumerate(self.order):
            out[tool_index] = params[model_index]
        return out


def _maps(fmt: str) -> dict[str, ShapeMap]:
    """The tool's type name -> its map, from the registry's spellings (``fmt``: fis or fll).
    Takagi-Sugeno outputs have no fixed arity and are read and written apart."""
    out: dict[str, ShapeMap] = {}
    for shape in registry.ENTRIES:
        w = getattr(shape.spellings, fmt)
        if isinstance(w, registry.NA) or shape.takagi_sugeno:
            continue
        out[w.name] = ShapeMap(shape.kind, w.order)
    return out


# MATLAB FIS types (and fuzzylite's additions to the FIS format).  ``linear``,
# ``constant``, ``discretemf`` and ``function`` have no fixed arity and are handled apart.
FIS_TYPES: dict[str, ShapeMap] = _maps("fis")
MATLAB_TYPES = frozenset(
    w.name
    for s in registry.ENTRIES
    if isinstance(w := s.spellings.fis, registry.Written) and w.matlab and not s.takagi_sugeno
)
FIS_OF_KIND: dict[str, str] = {m.kind: name for name, m in FIS_TYPES.items()}

# fuzzylite term classes (FLL), parameters as fuzzylite writes them.
FLL_TYPES: dict[str, ShapeMap] = _maps("fll")
FLL_OF_KIND: dict[str, str] = {m.kind: name for name, m in FLL_TYPES.items()}
# Terms fuzzylite 6 (the C++ library and its Debian command) cannot read.
FLL_ONLY_PYFUZZYLITE = frozenset(
    w.name
    for s in registry.ENTRIES
    if isinstance(w := s.spellings.fll, registry.Written) and w.pyfuzzylite_only
)

# Shapes whose value rises or falls monotonically: the only ones a Tsukamoto output
# (fuzzylite WeightedAverage on non-constant terms) can use.
MONOTONIC_KINDS = registry.kinds_where(lambda s: s.tsukamoto_invertible)
#: Takagi-Sugeno output kinds (no fixed arity in FIS and FLL).
TS_KINDS = registry.kinds_where(lambda s: s.takagi_sugeno)
#: FIS and FLL names of the Takagi-Sugeno kinds -> the kind.
FIS_TS_TYPES: dict[str, str] = {
    w.name: s.kind
    for s in registry.ENTRIES
    if s.takagi_sugeno and isinstance(w := s.spellings.fis, registry.Written)
}
FLL_TS_TYPES: dict[str, str] = {
    w.name: s.kind
    for s in registry.ENTRIES
    if s.takagi_sugeno and isinstance(w := s.spellings.fll, registry.Written)
}


def fis_ts_name(kind: str) -> str:
    """The FIS type of a Takagi-Sugeno kind (``constant``, ``linear``)."""
    return next(name for name, k in FIS_TS_TYPES.items() if k == kind)


def fll_ts_name(kind: str) -> str:
    """The FLL class of a Takagi-Sugeno kind (``Constant``, ``Linear``)."""
    return next(name for name, k in FLL_TS_TYPES.items() if k == kind)


def shape(kind: str, params: tuple[float, ...], height: float = 1.0) -> ShapeMF:
    return ShapeMF(kind, params, height)


def fis_shape_problem(fis_kind: str, values: tuple[float, ...]) -> str | None:
    """Why the FIS reader refuses a membership function of MATLAB type ``fis_kind`` with
    model-order parameters ``values`` (``None``: it reads it).  The writer asks the same
    question, so that it never writes a file the reader refuses."""
    if fis_kind == "trimf" and not values[0] <= values[1] <= values[2]:
        return f"trimf parameters must satisfy a <= b <= c, found {list(values[:3])}"
    if fis_kind == "trapmf" and not values[0] <= values[1] <= values[2] <= values[3]:
        return f"trapmf parameters must satisfy a <= b <= c <= d, found {list(values[:4])}"
    if fis_kind in {"gaussmf", "gauss2mf"} and (
        values[1] == 0 or (fis_kind == "gauss2mf" and values[3] == 0)
    ):
        return f"{fis_kind}: sigma must not be 0"
    if fis_kind == "gbellmf" and values[1] == 0:
        return "gbellmf: width a must not be 0"
    return None
