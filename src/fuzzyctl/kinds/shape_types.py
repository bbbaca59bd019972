"""The types of the shape registry (:mod:`fuzzyctl.kinds.shapes`) and what its entries share:
:class:`Shape` and its parts, :class:`NA` for a field that does not apply, the helper formulas
the shape formulas call, Java's arithmetic (jFuzzyLogic's universe) and shoulders.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
from typing import Any, Literal

from fuzzyctl.kinds import formula as fm

Points = tuple[tuple[float, float], ...]
Family = Literal["pwl", "smooth", "ts"]
Role = Literal["x", "width", "slope", "number", "coef"]


@dataclass(frozen=True)
class NA:
    """A field that does not apply to a shape, and why."""

    reason: str


@dataclass(frozen=True)
class Written:
    """How a tool writes a shape: its name and, for canonical parameter ``i``, the position
    ``order[i]`` in the written list.

    ``dialect`` (FCL): jFuzzyLogic, fuzzylite or scalablurry; ``height``: an optional trailing
    height; ``scale[i]`` multiplies the written value (jFuzzyLogic's COSINE gives a half
    width), and a scaled parameter given by a variable makes the term ``ref_kind``;
    ``matlab`` (FIS): one of MATLAB's own types, not a fuzzylite extension;
    ``pyfuzzylite_only`` (FLL): fuzzylite 6 cannot read it."""

    name: str
    order: tuple[int, ...]
    dialect: str = ""
    height: bool = False
    scale: tuple[float, ...] | None = None
    ref_kind: str | None = None
    variadic: bool = False
    matlab: bool = False
    pyfuzzylite_only: bool = False
    write_only: bool = False  # FCL: how the writer spells the kind; the reader never gives it


JFL, FL, SB = "jFuzzyLogic", "fuzzylite", "scalablurry"


@dataclass(frozen=True)
class Spellings:
    """A shape in every format.  FPL and XFUZ have no parametric shapes: ``fpl`` gives the
    points FPL writes, ``xfuz`` which parameters are XFUZ's trapezoid abscissae a, b, c, d."""

    fcl: tuple[Written, ...] | NA
    fis: Written | NA
    fll: Written | NA
    fpl: Callable[[Sequence[float]], list[tuple[float, float]]] | NA
    xfuz: tuple[int, int, int, int] | NA
    json: str  # the model's own kind name


@dataclass(frozen=True)
class Degenerate:
    """Parameters that define no shape: ``bad(params)`` says so, ``text`` says what is needed."""

    text: str
    bad: Callable[[Sequence[float]], bool]


@dataclass(frozen=True)
class Span:
    """The universe of a term without RANGE (jFuzzyLogic ``estimateUniverse``)."""

    rule: str
    of: Callable[[Sequence[float]], tuple[float, float]]


@dataclass(frozen=True)
class Studio:
    """The studio's view: ``placement`` gives each parameter from where the term is placed,
    an expression over a, b (the support), c (the peak) and w (b - a) (a variadic shape gets
    zeros, one per input and a constant); ``handles`` the draggable points (``at``: the
    parameter; ``y``: the height there; with ``centre`` and ``factor``: at
    ``centre + factor * |p|``; ``line``: a vertical line); ``polygon``: the handles are the
    curve's corners (drawn live); ``pickable``: offered in the Shape picker."""

    placement: tuple[str, ...]
    handles: tuple[dict[str, Any], ...]
    polygon: bool = False
    pickable: bool = True


@dataclass(frozen=True)
class Shape:
    """One parametric shape; see the module docstring for each field's consumers."""

    kind: str
    params: tuple[str, ...]
    roles: tuple[Role, ...]
    summary: str
    family: Family
    formula: str | NA  # over x and the parameters (smooth shapes)
    breakpoints: Callable[[Sequence[float], float], Points] | NA  # piecewise-linear shapes
    support: Callable[[Sequence[float]], tuple[float, float]] | NA  # smooth shapes
    characteristic: Callable[[Sequence[float]], tuple[float, ...]] | NA
    tsukamoto: str | NA  # x where the shape reaches y (over y, h and the parameters)
    spellings: Spellings
    probe: tuple[float, ...] | NA  # conformance statement, universe 0..10
    studio: Studio
    degenerate: Degenerate | NA
    span: Span
    jfl: str | NA  # jFuzzyLogic's formula (numpy over x and the parameters, fdlibm calls)
    infinite: tuple[int, ...] = ()  # parameters that may be infinite (shoulders, directions)
    probe_output: tuple[float, ...] | None = None  # default: the probe doubled
    variadic: bool = False
    vertices: tuple[float, ...] | NA = field(
        default_factory=lambda: NA("its parameters are not the x of its breakpoints")
    )  # the degrees at the parameters, when the parameters are the breakpoints' x in order
    jfl_refuses: Callable[[Sequence[float]], bool] | NA = field(
        default_factory=lambda: NA("jFuzzyLogic reads every value its spelling can write")
    )
    zero_outside: Callable[[Sequence[float]], tuple[float, float]] | NA = field(
        default_factory=lambda: NA("the writers do not bound it (FPL and XFUZ sample it over the range)")
    )  # the interval outside which the degree is exactly 0, as the writers clip the shape
    gradient: tuple[str, ...] | NA = field(
        default_factory=lambda: NA("no analytic derivative written yet (the gradient tuner refuses it)")
    )  # d(degree)/d(parameter i), over x, mu (the degree, height included) and the parameters
    compiled: dict[str, Any] = field(default_factory=dict, compare=False, repr=False)

    # ---- family flags
    @property
    def piecewise_linear(self) -> bool:
        return self.family == "pwl"

    @property
    def smooth(self) -> bool:
        return self.family == "smooth"

    @property
    def takagi_sugeno(self) -> bool:
        return self.family == "ts"

    @property
    def tsukamoto_invertible(self) -> bool:
        return not isinstance(self.tsukamoto, NA)

    @property
    def ts_constant(self) -> bool:
        """A Takagi-Sugeno output whose value is its one parameter."""
        return self.takagi_sugeno and not self.variadic

    @property
    def ts_linear(self) -> bool:
        """A Takagi-Sugeno output linear in the inputs (coefficients, then the constant)."""
        return self.takagi_sugeno and self.variadic

    @property
    def centre_spread(self) -> bool:
        """Its first two parameters are a centre and a spread around it (a bump: gaussian,
        bell, cosine, spike...): it matters within a few spreads of the centre."""
        return self.roles[:2] == ("x", "width")

    # ---- derived views
    @property
    def tuning(self) -> tuple[str, ...]:
        """Per parameter how a tuner moves it: ``abscissa`` (a breakpoint of the variable),
        ``scale``/``slope`` (log scale, sign kept), ``coef`` (a box around its value)."""
        if self.takagi_sugeno:
            return tuple("coef" for _ in self.params)
        names = {"x": "abscissa", "width": "scale", "number": "scale", "slope": "slope", "coef": "coef"}
        return tuple(names[r] for r in self.roles)

    def parsed(self) -> fm.Formula:
        """The formula, parsed (once)."""
        if "formula" not in self.compiled:
            assert isinstance(self.formula, str), self.kind
            self.compiled["formula"] = fm.parse(self.formula, ("x", *self.params), HELPERS)
        f: fm.Formula = self.compiled["formula"]
        return f

    def parsed_tsukamoto(self) -> fm.Formula:
        if "tsukamoto" not in self.compiled:
            assert isinstance(self.tsukamoto, str), self.kind
            self.compiled["tsukamoto"] = fm.parse(self.tsukamoto, ("y", "h", *self.params), HELPERS)
        f: fm.Formula = self.compiled["tsukamoto"]
        return f

    @property
    def differentiable(self) -> bool:
        """An analytic derivative per parameter (:attr:`gradient`) for the gradient tuner."""
        return not isinstance(self.gradient, NA)

    def parsed_gradient(self) -> tuple[fm.Formula, ...]:
        if "gradient" not in self.compiled:
            assert isinstance(self.gradient, tuple), self.kind
            args = ("x", "mu", *self.params)
            self.compiled["gradient"] = tuple(fm.parse(g, args, HELPERS) for g in self.gradient)
        f: tuple[fm.Formula, ...] = self.compiled["gradient"]
        return f

    def parsed_jfl(self) -> fm.Formula:
        if "jfl" not in self.compiled:
            assert isinstance(self.jfl, str), self.kind
            self.compiled["jfl"] = fm.parse(self.jfl, ("x", *self.params), HELPERS)
        f: fm.Formula = self.compiled["jfl"]
        return f

    def output_probe(self) -> tuple[float, ...] | NA:
        if isinstance(self.probe, NA):
            return self.probe
        return self.probe_output if self.probe_output is not None else tuple(2 * p for p in self.probe)


# --------------------------------------------------------------------------- helper formulas

#: Formulas the shape formulas call (inlined in the IR, functions in float and numpy).
HELPERS: dict[str, fm.Formula] = {}
for _name, _args, _src in (
    # 1 / (1 + exp(-s (x - c))), 0 where the exponent would overflow
    ("sig", ("x", "c", "s"), "0.0 if (z := -s * (x - c)) > 700.0 else 1.0 / (1.0 + exp(z))"),
    ("gauss", ("x", "m", "sd"), "exp(-((d := x - m) * d) / (2.0 * sd * sd))"),
    (
        "smf",
        ("x", "s", "e"),
        "0.0 if x <= s else (2.0 * (t := (x - s) / (e - s)) * t if x <= 0.5 * (s + e) else "
        "(1.0 - 2.0 * (u := (x - e) / (e - s)) * u if x < e else 1.0))",
    ),
    (
        "zmf",
        ("x", "s", "e"),
        "1.0 if x <= s else (1.0 - 2.0 * (t := (x - s) / (e - s)) * t if x <= 0.5 * (s + e) else "
        "(2.0 * (u := (x - e) / (e - s)) * u if x < e else 0.0))",
    ),
):
    HELPERS[_name] = fm.parse(_src, _args, HELPERS)


# --------------------------------------------------------------------------- Java arithmetic


def java_div(a: float, b: float) -> float:
    """``a / b`` as Java computes it: a zero divisor gives an infinity (NaN for 0 / 0)."""
    try:
        return a / b
    except ZeroDivisionError:
        return math.nan if a == 0.0 or math.isnan(a) else math.copysign(math.inf, a) * math.copysign(1.0, b)


def java_pow(base: float, exponent: float) -> float:
    """``base ** exponent``, infinite where it overflows (Java's Math.pow)."""
    try:
        return math.pow(base, exponent)
    except OverflowError:
        return math.inf


# --------------------------------------------------------------------------- breakpoints


def shoulders(points: Points, h: float) -> Points:
    """A triangle or trapezoid with vertices at -inf / +inf is a shoulder (MATLAB
    ``trapmf [-Inf -Inf 2 4]``; fuzzylite gives the height beyond a finite vertex whose
    neighbour is infinite): the infinite vertices are dropped and the ends continue flat."""
    if all(math.isfinite(x) for x, _y in points):
        return points
    finite = tuple((x, y) for x, y in points if math.isfinite(x))
    return finite or ((0.0, h),)
