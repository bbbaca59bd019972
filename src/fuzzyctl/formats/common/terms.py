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


# MATLAB FIS types (and fuzzylite's additions to the FIS format).  ``linear``,
# ``constant``, ``discretemf`` and ``function`` have no fixed arity and are handled apart.
FIS_TYPES: dict[str, ShapeMap] = {
    "trimf": ShapeMap("triangle", (0, 1, 2)),
    "trapmf": ShapeMap("trapezoid", (0, 1, 2, 3)),
    "gaussmf": ShapeMap("gaussian", (1, 0)),  # [sigma c]
    "gauss2mf": ShapeMap("gaussian2", (1, 0, 3, 2)),  # [sigma1 c1 sigma2 c2]
    "gbellmf": ShapeMap("bell", (2, 0, 1)),  # [a b c]: width a, slope b, centre c
    "sigmf": ShapeMap("sigmoid", (1, 0)),  # [a c]
    "dsigmf": ShapeMap("dsigmoid", (1, 0, 3, 2)),  # [a1 c1 a2 c2]
    "psigmf": ShapeMap("psigmoid", (1, 0, 3, 2)),
    "smf": ShapeMap("sshape", (0, 1)),
    "zmf": ShapeMap("zshape", (0, 1)),
    "pimf": ShapeMap("pishape", (0, 1, 2, 3)),
    # fuzzylite's FIS extensions, parameters in fuzzylite's own order
    "rampmf": ShapeMap("ramp", (0, 1)),
    "rectmf": ShapeMap("rectangle", (0, 1)),
    "cosinemf": ShapeMap("cosine", (0, 1)),
    "spikemf": ShapeMap("spike", (0, 1)),
    "concavemf": ShapeMap("concave", (0, 1)),
    "binarymf": ShapeMap("binary", (0, 1)),
}
MATLAB_TYPES = frozenset(
    {"trimf", "trapmf", "gaussmf", "gauss2mf", "gbellmf", "sigmf", "dsigmf", "psigmf", "smf", "zmf", "pimf"}
)
FIS_OF_KIND: dict[str, str] = {m.kind: name for name, m in FIS_TYPES.items()}

# fuzzylite term classes (FLL), parameters as fuzzylite writes them.
FLL_TYPES: dict[str, ShapeMap] = {
    "Triangle": ShapeMap("triangle", (0, 1, 2)),
    "Trapezoid": ShapeMap("trapezoid", (0, 1, 2, 3)),
    "Rectangle": ShapeMap("rectangle", (0, 1)),
    "Gaussian": ShapeMap("gaussian", (0, 1)),  # mean standardDeviation
    "GaussianProduct": ShapeMap("gaussian2", (0, 1, 2, 3)),  # meanA sdA meanB sdB
    "Bell": ShapeMap("bell", (0, 1, 2)),  # center width slope
    "Sigmoid": ShapeMap("sigmoid", (0, 1)),  # inflection slope
    "SigmoidDifference": ShapeMap("dsigmoid", (0, 1, 3, 2)),  # left rising falling right
    "SigmoidProduct": ShapeMap("psigmoid", (0, 1, 3, 2)),  # left rising falling right
    "Cosine": ShapeMap("cosine", (0, 1)),
    "SShape": ShapeMap("sshape", (0, 1)),
    "ZShape": ShapeMap("zshape", (0, 1)),
    "PiShape": ShapeMap("pishape", (0, 1, 2, 3)),
    "Ramp": ShapeMap("ramp", (0, 1)),
    "Spike": ShapeMap("spike", (0, 1)),
    "Concave": ShapeMap("concave", (0, 1)),
    "Binary": ShapeMap("binary", (0, 1)),
    "Arc": ShapeMap("arc", (0, 1)),
    "SemiEllipse": ShapeMap("semiellipse", (0, 1)),
}
FLL_OF_KIND: dict[str, str] = {m.kind: name for name, m in FLL_TYPES.items()}
# Terms fuzzylite 6 (the C++ library and its Debian command) cannot read.
FLL_ONLY_PYFUZZYLITE = frozenset({"Arc", "SemiEllipse"})

# Shapes whose value rises or falls monotonically: the only ones a Tsukamoto output
# (fuzzylite WeightedAverage on non-constant terms) can use.
MONOTONIC_KINDS = frozenset({"ramp", "sigmoid", "sshape", "zshape", "concave", "arc"})


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
