"""The shape registry: one :class:`Shape` entry per parametric membership-function kind.

Everything fuzzyctl knows about a shape is in its entry, and nothing outside this module
compares shape names: the canonical parameters and what each is (:attr:`Shape.roles`), the
formula written once (:attr:`Shape.formula`, compiled by :mod:`fuzzyctl.kinds.formula` into
the float, numpy and IR forms) or the breakpoint list of a piecewise-linear shape, its
spellings in every format (:class:`Spellings`), the tuning roles, the conformance
statement's probe, the studio's default placement and handles, the degenerate-parameter
rule, the universe used without RANGE (jFuzzyLogic's ``estimateUniverse``), the
jFuzzyLogic variant where its Java computes differently, and the family flags.

A field that does not apply to a shape holds :class:`NA` with the reason, never ``None``:
``tests/kinds/test_shapes_registry.py`` fails on an entry that leaves a field out.

Adding a shape is adding one entry to :data:`ENTRIES` (and, when a tool names it, its
spellings there).  Membership functions that are not parametric shapes - IEC points,
singletons, jFuzzyLogic SINGLETONS, function terms - are model types of their own
(:mod:`fuzzyctl.model`), not entries.
"""

from __future__ import annotations

import ast
import math
from collections.abc import Callable, Sequence
from typing import Any

from fuzzyctl.kinds import formula as fm
from fuzzyctl.kinds.shape_types import (
    FL,
    HELPERS,
    JFL,
    NA,
    SB,
    Degenerate,
    Points,
    Role,
    Shape,
    Span,
    Spellings,
    Studio,
    Written,
    java_div,
    java_pow,
    shoulders,
)

__all__ = [
    "ENTRIES",
    "FL",
    "HELPERS",
    "JFL",
    "NA",
    "SB",
    "SHAPES",
    "Degenerate",
    "Shape",
    "Span",
    "Spellings",
    "Studio",
    "Written",
    "flag",
    "get",
    "kinds_where",
    "placement_tree",
    "self_check",
    "vertices",
]


def _sig_span(c: float, s: float) -> tuple[float, float]:
    return c - java_div(9.0, abs(s)), c + java_div(9.0, abs(s))


def _two_sig_span(p: Sequence[float]) -> tuple[float, float]:
    min1, max1 = _sig_span(p[0], p[1])
    min2, max2 = _sig_span(p[2], p[3])
    return (min1 if min1 < min2 else min2), (max1 if max1 > max2 else max2)


def _bell_span(p: Sequence[float]) -> tuple[float, float]:
    c, w, b = p
    delta = java_pow(999.0, java_div(1.0, 2.0 * b)) * w
    return c - delta, c + delta


HULL = Span("the hull of its parameters", lambda p: (min(p), max(p)))
_ZERO_OUTSIDE_HULL = HULL.of
WHOLE_LINE = Span("the whole line (no parameter spans it)", lambda p: (-math.inf, math.inf))


def _ramp(p: Sequence[float], h: float) -> Points:
    s, e = p
    if s == e:  # fuzzylite: a ramp without extent is 0 everywhere
        return ((s, 0.0),)
    return ((s, 0.0), (e, h)) if s < e else ((e, h), (s, 0.0))


def _binary(p: Sequence[float], h: float) -> Points:
    s, direction = p
    if direction > s:
        return ((s, 0.0), (s, h))
    if direction < s:
        return ((s, h), (s, 0.0))
    return ((s, 0.0),)


def _sym(c: float, half: float, ks: Sequence[float]) -> tuple[float, ...]:
    return tuple(c + k * half for k in ks)


def _sig_points(p: Sequence[float]) -> tuple[float, ...]:
    out: list[float] = []
    for c, s in zip(p[0::2], p[1::2], strict=True):
        d = 1.0 / abs(s) if s else 1.0
        out += [c + k * d for k in (-30, -8, -2, 0, 2, 8, 30)]
    return tuple(out)


def _triangle_fpl(v: Sequence[float]) -> list[tuple[float, float]]:
    return [(v[0], 0.0), (v[1], 1.0), (v[2], 0.0)]


def _trapezoid_fpl(v: Sequence[float]) -> list[tuple[float, float]]:
    return [(v[0], 0.0), (v[1], 1.0), (v[2], 1.0), (v[3], 0.0)]


def _rectangle_fpl(v: Sequence[float]) -> list[tuple[float, float]]:
    return [(v[0], 0.0), (v[0], 1.0), (v[1], 1.0), (v[1], 0.0)]


def _nonzero(i: int) -> Degenerate:
    return Degenerate("needs a nonzero width", lambda p: p[i] == 0.0)


_WIDTH_MIN, _WIDTH_MAX = 1e-150, 1e150


def _sd_bad(sds: Sequence[float]) -> bool:
    # 2 sd^2 must be a normal number: 0 or inf there makes exp(-d^2 / 2 sd^2) 0/0 at the
    # centre (NaN, or a ZeroDivisionError in Python) where the shape means 1
    return not all(_WIDTH_MIN <= abs(sd) <= _WIDTH_MAX for sd in sds)


_SD = Degenerate(
    f"needs a standard deviation between {_WIDTH_MIN:g} and {_WIDTH_MAX:g} in size", lambda p: _sd_bad(p[1:2])
)
_SD2 = Degenerate(_SD.text, lambda p: _sd_bad(p[1::2]))

NO_FPL = NA("FPL writes points only: the term is written as IEC points or refused")
NO_XFUZ = NA("XFUZ has trapezoids of 0/1 degrees only")
NO_JFL = NA("jFuzzyLogic has no such shape: the engine's formula (a file using it does not load there)")
SAME_JFL = NA("jFuzzyLogic has no such shape: the engine's formula")
NOT_MONOTONIC = NA("not monotonic: no Tsukamoto inverse")
ANY = NA("every value of the parameters defines a shape")


def _h(at: int, y: float, centre: int | None = None, factor: float = 0.0) -> dict[str, Any]:
    """A studio handle (see :class:`Studio`)."""
    return {"at": at, "y": y} if centre is None else {"at": at, "y": y, "centre": centre, "factor": factor}


_AB = Studio(("a", "b"), ())
_SIG2 = ("a + w / 4", "20 / w", "b - w / 4")


_E = math.exp(-0.5)
_PWL = NA("piecewise linear: its breakpoint list is the formula")
_NOT_PWL = NA("not piecewise linear: a formula")
_TS_NA = NA("a Takagi-Sugeno output is a value, not a fuzzy set")
_BP_SUPPORT = NA("piecewise linear: the support follows from the breakpoints")
_BP_POINTS = NA("piecewise linear: its breakpoints are its characteristic points")


def _smooth(
    kind: str,
    params: tuple[str, ...],
    roles: tuple[Role, ...],
    summary: str,
    formula: str,
    *,
    support: Callable[[Sequence[float]], tuple[float, float]],
    characteristic: Callable[[Sequence[float]], tuple[float, ...]],
    spellings: Spellings,
    probe: tuple[float, ...] | NA,
    studio: Studio,
    span: Span = HULL,
    degenerate: Degenerate | NA = ANY,
    tsukamoto: str | NA = NOT_MONOTONIC,
    jfl: str | NA = NO_JFL,
    probe_output: tuple[float, ...] | None = None,
    **extra: Any,
) -> Shape:
    return Shape(
        kind,
        params,
        roles,
        summary,
        "smooth",
        formula,
        _PWL_NA,
        support,
        characteristic,
        tsukamoto,
        spellings,
        probe,
        studio,
        degenerate,
        span,
        jfl,
        probe_output=probe_output,
        **extra,
    )


_PWL_NA = NA("not piecewise linear: its formula")


def _fcl(*ws: Written) -> tuple[Written, ...]:
    return ws


def _sp(
    fcl: tuple[Written, ...] | NA,
    fis: Written | NA,
    fll: Written | NA,
    json: str,
    fpl: Callable[[Sequence[float]], list[tuple[float, float]]] | NA = NO_FPL,
    xfuz: tuple[int, int, int, int] | NA = NO_XFUZ,
) -> Spellings:
    return Spellings(fcl, fis, fll, fpl, xfuz, json)


def _fl(name: str, n: int, order: tuple[int, ...] | None = None) -> Written:
    """fuzzylite's FCL spelling (parameters in its order, optional height)."""
    return Written(name, order or tuple(range(n)), FL, height=True)


_I2, _I3, _I4 = (0, 1), (0, 1, 2), (0, 1, 2, 3)
_NO_FIS = NA("no FIS type: the FIS writer refuses it (or writes points)")

ENTRIES: tuple[Shape, ...] = (
    Shape(
        "triangle",
        ("a", "b", "c"),
        ("x", "x", "x"),
        "0 at a, 1 at b, 0 at c, linear between",
        "pwl",
        _NOT_PWL,
        lambda p, h: shoulders(((p[0], 0.0), (p[1], h), (p[2], 0.0)), h),
        _BP_SUPPORT,
        _BP_POINTS,
        NOT_MONOTONIC,
        _sp(
            _fcl(Written("TRIAN", _I3, JFL), _fl("Triangle", 3), Written("triangular", _I3, SB)),
            Written("trimf", _I3, matlab=True),
            Written("Triangle", _I3),
            "triangle",
            _triangle_fpl,
            (0, 1, 1, 2),
        ),
        (0, 5, 10),
        Studio(("a", "c", "b"), (_h(0, 0), _h(1, 1), _h(2, 0)), polygon=True),
        Degenerate("needs a <= b <= c", lambda p: not p[0] <= p[1] <= p[2]),
        Span("a..c", lambda p: (p[0], p[2])),
        "0.0 if x < a or x > c else "
        "(1.0 if x == b else ((x - a) / (b - a) if x < b else 1 - (x - b) / (c - b)))",
        infinite=(0, 1, 2),
        vertices=(0.0, 1.0, 0.0),
        zero_outside=_ZERO_OUTSIDE_HULL,
    ),
    Shape(
        "trapezoid",
        ("a", "b", "c", "d"),
        ("x", "x", "x", "x"),
        "0 at a, 1 on [b, c], 0 at d",
        "pwl",
        _NOT_PWL,
        lambda p, h: shoulders(((p[0], 0.0), (p[1], h), (p[2], h), (p[3], 0.0)), h),
        _BP_SUPPORT,
        _BP_POINTS,
        NOT_MONOTONIC,
        _sp(
            _fcl(Written("TRAPE", _I4, JFL), _fl("Trapezoid", 4), Written("trapetzoidal", _I4, SB)),
            Written("trapmf", _I4, matlab=True),
            Written("Trapezoid", _I4),
            "trapezoid",
            _trapezoid_fpl,
            (0, 1, 2, 3),
        ),
        (0, 2, 6, 10),
        Studio(
            ("a", "(a + c) / 2", "(c + b) / 2", "b"), (_h(0, 0), _h(1, 1), _h(2, 1), _h(3, 0)), polygon=True
        ),
        Degenerate("needs a <= b <= c <= d", lambda p: not p[0] <= p[1] <= p[2] <= p[3]),
        Span("a..d", lambda p: (p[0], p[3])),
        "0.0 if x < a or x > d else (1.0 if x >= b and x <= c else "
        "((x - a) / (b - a) if x < b else 1 - (x - c) / (d - c)))",
        infinite=(0, 1, 2, 3),
        vertices=(0.0, 1.0, 1.0, 0.0),
        zero_outside=_ZERO_OUTSIDE_HULL,
    ),
    Shape(
        "rectangle",
        ("start", "end"),
        ("x", "x"),
        "1 on [start, end], 0 elsewhere",
        "pwl",
        _NOT_PWL,
        lambda p, h: ((min(p), 0.0), (min(p), h), (max(p), h), (max(p), 0.0)),
        _BP_SUPPORT,
        _BP_POINTS,
        NOT_MONOTONIC,
        _sp(
            _fcl(_fl("Rectangle", 2)),
            Written("rectmf", _I2),
            Written("Rectangle", _I2),
            "rectangle",
            _rectangle_fpl,
            (0, 0, 1, 1),
        ),
        (2, 6),
        Studio(("a", "b"), (_h(0, 0.5), _h(1, 0.5))),
        ANY,
        HULL,
        NO_JFL,
        zero_outside=_ZERO_OUTSIDE_HULL,
    ),
    _smooth(
        "gaussian",
        ("mean", "sigma"),
        ("x", "width"),
        "exp(-(x-mean)^2 / (2 sigma^2))",
        "gauss(x, mean, sigma)",
        support=lambda p: (-math.inf, math.inf),
        characteristic=lambda p: _sym(p[0], abs(p[1]), (-8, -4, -2, -1, 0, 1, 2, 4, 8)),
        spellings=_sp(
            _fcl(Written("GAUSS", _I2, JFL), _fl("Gaussian", 2)),
            Written("gaussmf", (1, 0), matlab=True),
            Written("Gaussian", _I2),
            "gaussian",
        ),
        probe=(5, 2),
        studio=Studio(("c", "w / 6"), (_h(0, 1), _h(1, _E, 0, 1))),
        span=Span("mean +- 4 sigma", lambda p: (p[0] - 4.0 * p[1], p[0] + 4.0 * p[1])),
        degenerate=_SD,
        jfl="exp(-(x - mean) * (x - mean) / (2 * sigma * sigma))",
        gradient=(
            "mu * (x - mean) / (sigma * sigma)",
            "mu * (x - mean) * (x - mean) / (sigma * sigma * sigma)",
        ),
    ),
    _smooth(
        "gaussian2",
        ("mean1", "sigma1", "mean2", "sigma2"),
        ("x", "width", "x", "width"),
        "g1(x) * g2(x) where g1 = exp(-(x-mean1)^2 / (2 sigma1^2)) for x < mean1 else 1 and "
        "g2 = exp(-(x-mean2)^2 / (2 sigma2^2)) for x > mean2 else 1; so 1 between the means "
        "when mean1 <= mean2 (MATLAB gauss2mf, fuzzylite GaussianProduct, jFuzzyLogic GAUSS2)",
        "(gauss(x, mean1, sigma1) if x < mean1 else 1.0) * (gauss(x, mean2, sigma2) if x > mean2 else 1.0)",
        support=lambda p: (-math.inf, math.inf),
        characteristic=lambda p: (
            _sym(p[0], abs(p[1]), (-8, -4, -2, -1, 0)) + _sym(p[2], abs(p[3]), (0, 1, 2, 4, 8))
        ),
        spellings=_sp(
            _fcl(Written("GAUSS2", _I4, JFL), _fl("GaussianProduct", 4)),
            Written("gauss2mf", (1, 0, 3, 2), matlab=True),
            Written("GaussianProduct", _I4),
            "gaussian2",
        ),
        probe=(3, 1, 6, 1),
        studio=Studio(
            ("c - w / 10", "w / 8", "c + w / 10", "w / 8"),
            (_h(0, 1), _h(1, _E, 0, -1), _h(2, 1), _h(3, _E, 2, 1)),
        ),
        span=Span("mean1 - 4 sigma1 .. mean2 + 4 sigma2", lambda p: (p[0] - 4.0 * p[1], p[2] + 4.0 * p[3])),
        degenerate=_SD2,
        # jFuzzyLogic rejects GAUSS2 with mean1 > mean2 (fuzzylite's product form reads it)
        jfl_refuses=lambda p: p[0] > p[2],
        jfl="exp(-(x - mean1) * (x - mean1) / (2 * sigma1 * sigma1)) if x < mean1 else "
        "(exp(-(x - mean2) * (x - mean2) / (2 * sigma2 * sigma2)) if x > mean2 else 1.0)",
    ),
    _smooth(
        "bell",
        ("center", "width", "slope"),
        ("x", "width", "number"),
        "1 / (1 + |(x-center)/width|^(2 slope))",
        # IEEE pow at the centre (u = 0), as fuzzylite and numpy: 0^e is 0 for e > 0, 1 for e = 0
        # and +inf for e < 0 (a negative slope is 0 at its centre); written out because
        # Structured Text has no pow(0, e)
        "u = abs((x - center) / width); e = 2.0 * slope\n"
        "1.0 / (1.0 + pow(u, e)) if u > 0.0 else "
        "((1.0 if e > 0.0 else (0.5 if e == 0.0 else (0.0 if e < 0.0 else e))) if u == 0.0 else u)",
        support=lambda p: (-math.inf, math.inf),
        characteristic=lambda p: _sym(p[0], abs(p[1]), (-16, -4, -2, -1, 0, 1, 2, 4, 16)),
        spellings=_sp(
            _fcl(Written("GBELL", (2, 0, 1), JFL), _fl("Bell", 3), Written("generalizedBell", (2, 0, 1), SB)),
            Written("gbellmf", (2, 0, 1), matlab=True),
            Written("Bell", _I3),
            "bell",
        ),
        probe=(5, 2, 2),
        studio=Studio(("c", "w / 4", "2"), (_h(0, 1), _h(1, 0.5, 0, 1))),
        span=Span("center +- 999^(1/(2 slope)) width", _bell_span),
        degenerate=_nonzero(1),
        jfl="1.0 / (1.0 + pow(abs((x - center) / width), 2.0 * slope))",
    ),
    _smooth(
        "sigmoid",
        ("center", "slope"),
        ("x", "slope"),
        "1 / (1 + exp(-slope (x-center)))",
        "sig(x, center, slope)",
        support=lambda p: (-math.inf, math.inf),
        characteristic=_sig_points,
        spellings=_sp(
            _fcl(Written("SIGM", (1, 0), JFL), _fl("Sigmoid", 2), Written("sigmoidal", (1, 0), SB)),
            Written("sigmf", (1, 0), matlab=True),
            Written("Sigmoid", _I2),
            "sigmoid",
        ),
        probe=(5, 1),
        probe_output=(5, 1),
        studio=Studio(("c", "10 / w"), (_h(0, 0.5),)),
        span=Span("center +- 9/|slope|", lambda p: _sig_span(p[0], p[1])),
        tsukamoto="center + log(h / y - 1.0) / -slope",
        jfl="1.0 / (1.0 + exp(-slope * (x - center)))",
    ),
    _smooth(
        "dsigmoid",
        ("center1", "slope1", "center2", "slope2"),
        ("x", "slope", "x", "slope"),
        "|s1 - s2| of two sigmoids (fuzzylite SigmoidDifference)",
        "abs(sig(x, center1, slope1) - sig(x, center2, slope2))",
        support=lambda p: (-math.inf, math.inf),
        characteristic=_sig_points,
        spellings=_sp(
            _fcl(_fl("SigmoidDifference", 4, (0, 1, 3, 2))),
            Written("dsigmf", (1, 0, 3, 2), matlab=True),
            Written("SigmoidDifference", (0, 1, 3, 2)),
            "dsigmoid",
        ),
        probe=(2, 2, 8, 2),
        studio=Studio((*_SIG2, "20 / w"), (_h(0, 0.5), _h(2, 0.5))),
        span=Span("centers +- 9/|slope|", _two_sig_span),
    ),
    _smooth(
        "dsigmoid_pos",
        ("center1", "slope1", "center2", "slope2"),
        ("x", "slope", "x", "slope"),
        "max(s1 - s2, 0) of two sigmoids (jFuzzyLogic DSIGM)",
        "max(sig(x, center1, slope1) - sig(x, center2, slope2), 0.0)",
        support=lambda p: (-math.inf, math.inf),
        characteristic=_sig_points,
        spellings=_sp(
            _fcl(Written("DSIGM", (1, 0, 3, 2), JFL)),
            NA("MATLAB's dsigmf is |s1 - s2|: no FIS type"),
            NA("fuzzylite's SigmoidDifference is |s1 - s2|: no FLL class"),
            "dsigmoid_pos",
        ),
        probe=(2, 2, 8, 2),
        studio=Studio((*_SIG2, "20 / w"), (_h(0, 0.5), _h(2, 0.5))),
        span=Span("centers +- 9/|slope|", _two_sig_span),
        jfl="d = 1.0 / (1.0 + exp(-slope1 * (x - center1))) - 1.0 / (1.0 + exp(-slope2 * (x - center2)))\n"
        "nan if isnan(d) else max(d, 0.0)",
    ),
    _smooth(
        "psigmoid",
        ("center1", "slope1", "center2", "slope2"),
        ("x", "slope", "x", "slope"),
        "product of two sigmoids (psigmf / SigmoidProduct)",
        "sig(x, center1, slope1) * sig(x, center2, slope2)",
        support=lambda p: (-math.inf, math.inf),
        characteristic=_sig_points,
        spellings=_sp(
            _fcl(_fl("SigmoidProduct", 4, (0, 1, 3, 2))),
            Written("psigmf", (1, 0, 3, 2), matlab=True),
            Written("SigmoidProduct", (0, 1, 3, 2)),
            "psigmoid",
        ),
        probe=(2, 2, 8, -2),
        studio=Studio((*_SIG2, "-20 / w"), (_h(0, 0.5), _h(2, 0.5))),
        span=Span("centers +- 9/|slope|", _two_sig_span),
    ),
    _smooth(
        "cosine",
        ("center", "width"),
        ("x", "width"),
        "(1 + cos(2 pi (x-center)/width)) / 2 on [center-width/2, center+width/2], 0 outside",
        "0.0 if x < center - 0.5 * width or x > center + 0.5 * width else "
        "0.5 * (1.0 + cos(2.0 / width * pi * (x - center)))",
        support=lambda p: (p[0] - 0.5 * abs(p[1]), p[0] + 0.5 * abs(p[1])),
        characteristic=lambda p: _sym(p[0], abs(p[1]), (-0.5, -0.25, 0, 0.25, 0.5)),
        spellings=_sp(
            _fcl(Written("COSINE", (1, 0), JFL, scale=(1.0, 2.0), ref_kind="cosine_half"), _fl("Cosine", 2)),
            Written("cosinemf", _I2),
            Written("Cosine", _I2),
            "cosine",
        ),
        probe=(5, 6),
        studio=Studio(("c", "w"), (_h(0, 1), _h(1, 0, 0, 0.5))),
        span=Span("center +- width/2", lambda p: (p[0] - 0.5 * abs(p[1]), p[0] + 0.5 * abs(p[1]))),
        degenerate=_nonzero(1),
        zero_outside=lambda p: (p[0] - abs(p[1]) / 2, p[0] + abs(p[1]) / 2),
        jfl="t = 0.5 * width; u = x - center\n(cos(u * (pi / t)) + 1) / 2 if -t <= u and u <= t else 0.0",
    ),
    _smooth(
        "cosine_half",
        ("center", "half_width"),
        ("x", "width"),
        "(1 + cos(pi (x-center)/half_width)) / 2 on [center-half_width, center+half_width], "
        "0 outside: jFuzzyLogic COSINE net_max offset when net_max is a variable (with a "
        "literal net_max the reader gives cosine(offset, 2 net_max))",
        "0.0 if x < center - (a := abs(half_width)) or x > center + a else "
        "0.5 * (1.0 + cos(pi * (x - center) / half_width))",
        support=lambda p: (p[0] - abs(p[1]), p[0] + abs(p[1])),
        characteristic=lambda p: _sym(p[0], abs(p[1]), (-1, -0.5, 0, 0.5, 1)),
        spellings=_sp(
            _fcl(Written("COSINE", (1, 0), JFL, write_only=True)),
            NA("a cosine whose half width is a variable: FIS has no variables"),
            NA("a cosine whose half width is a variable: FLL has no variables"),
            "cosine_half",
        ),
        probe=NA("jFuzzyLogic COSINE with a variable half-width: probed with a variable (COSINE hw 5)"),
        studio=Studio(("c", "w / 2"), (_h(0, 1), _h(1, 0, 0, 1)), pickable=False),
        span=Span("center +- half width", lambda p: (p[0] - p[1], p[0] + p[1])),
        degenerate=Degenerate("needs a nonzero half width", lambda p: p[1] == 0.0),
        jfl="t = half_width; u = x - center\n(cos(u * (pi / t)) + 1) / 2 if -t <= u and u <= t else 0.0",
    ),
    _smooth(
        "sshape",
        ("start", "end"),
        ("x", "x"),
        "0 for x <= start; 2 ((x-start)/(end-start))^2 up to (start+end)/2; "
        "1 - 2 ((x-end)/(end-start))^2 up to end; 1 for x >= end (smf, fuzzylite SShape)",
        "smf(x, start, end)",
        support=lambda p: (p[0], math.inf),
        characteristic=lambda p: (p[0], 0.5 * (p[0] + p[1]), p[1]),
        spellings=_sp(
            _fcl(_fl("SShape", 2)), Written("smf", _I2, matlab=True), Written("SShape", _I2), "sshape"
        ),
        probe=(2, 8),
        studio=Studio(("a", "b"), (_h(0, 0), _h(1, 1))),
        degenerate=Degenerate("needs start < end", lambda p: not p[0] < p[1]),
        tsukamoto="start + (end - start) * sqrt(y / (2.0 * h)) if y <= 0.5 * h else "
        "end - (end - start) * sqrt((h - y) / (2.0 * h))",
    ),
    _smooth(
        "zshape",
        ("start", "end"),
        ("x", "x"),
        "1 - sshape(start, end): 1 for x <= start, 0 for x >= end (zmf, fuzzylite ZShape)",
        "zmf(x, start, end)",
        support=lambda p: (-math.inf, p[1]),
        characteristic=lambda p: (p[0], 0.5 * (p[0] + p[1]), p[1]),
        spellings=_sp(
            _fcl(_fl("ZShape", 2)), Written("zmf", _I2, matlab=True), Written("ZShape", _I2), "zshape"
        ),
        probe=(2, 8),
        studio=Studio(("a", "b"), (_h(0, 1), _h(1, 0))),
        degenerate=Degenerate("needs start < end", lambda p: not p[0] < p[1]),
        tsukamoto="start + (end - start) * sqrt((h - y) / (2.0 * h)) if y >= 0.5 * h else "
        "end - (end - start) * sqrt(y / (2.0 * h))",
    ),
    _smooth(
        "pishape",
        ("a", "b", "c", "d"),
        ("x", "x", "x", "x"),
        "S-shape a..b times Z-shape c..d",
        "smf(x, a, b) * zmf(x, c, d)",
        support=lambda p: (p[0], p[3]),
        characteristic=lambda p: (p[0], 0.5 * (p[0] + p[1]), p[1], p[2], 0.5 * (p[2] + p[3]), p[3]),
        spellings=_sp(
            _fcl(_fl("PiShape", 4)), Written("pimf", _I4, matlab=True), Written("PiShape", _I4), "pishape"
        ),
        probe=(1, 3, 7, 9),
        studio=Studio(("a", "c", "c", "b"), (_h(0, 0), _h(1, 1), _h(2, 1), _h(3, 0))),
        span=Span("a..d", lambda p: (p[0], p[3])),
        degenerate=Degenerate("needs a < b and c < d", lambda p: not (p[0] < p[1] and p[2] < p[3])),
    ),
    Shape(
        "ramp",
        ("start", "end"),
        ("x", "x"),
        "linear from 0 at start to 1 at end, clamped to [0, 1] outside (rising when "
        "start < end, falling when start > end; 0 everywhere when start == end)",
        "pwl",
        _NOT_PWL,
        _ramp,
        _BP_SUPPORT,
        _BP_POINTS,
        "start + (end - start) * y / h",
        _sp(_fcl(_fl("Ramp", 2)), Written("rampmf", _I2), Written("Ramp", _I2), "ramp"),
        (2, 8),
        Studio(("a", "b"), (_h(0, 0), _h(1, 1))),
        NA("start == end is defined: 0 everywhere (fuzzylite)"),
        HULL,
        NO_JFL,
    ),
    _smooth(
        "spike",
        ("center", "width"),
        ("x", "width"),
        "exp(-|10 (x-center) / width|)",
        "exp(-abs(10.0 / width * (x - center)))",
        support=lambda p: (-math.inf, math.inf),
        characteristic=lambda p: _sym(p[0], abs(p[1]) / 10.0, (-40, -8, -2, 0, 2, 8, 40)),
        spellings=_sp(_fcl(_fl("Spike", 2)), Written("spikemf", _I2), Written("Spike", _I2), "spike"),
        probe=(5, 4),
        studio=Studio(("c", "w"), (_h(0, 1), _h(1, math.exp(-1), 0, 0.1))),
        span=Span("center +- |width|", lambda p: (p[0] - abs(p[1]), p[0] + abs(p[1]))),
        degenerate=_nonzero(1),
    ),
    _smooth(
        "concave",
        ("inflection", "end"),
        ("x", "x"),
        "inflection <= end: (end-inflection) / (2 end - inflection - x) for x < end, else 1; "
        "inflection > end: (inflection-end) / (inflection - 2 end + x) for x > end, else 1 "
        "(fuzzylite Concave)",
        "(end - inflection) / (2.0 * end - inflection - x) if inflection <= end and x < end else "
        "((inflection - end) / (inflection - 2.0 * end + x) if inflection >= end and x > end else 1.0)",
        support=lambda p: (-math.inf, math.inf),
        characteristic=lambda p: (p[0], p[1]),
        spellings=_sp(_fcl(_fl("Concave", 2)), Written("concavemf", _I2), Written("Concave", _I2), "concave"),
        probe=(4, 8),
        studio=Studio(("c", "b"), (_h(0, 0.5), _h(1, 1))),
        degenerate=NA("inflection == end is defined: 1 everywhere (fuzzylite)"),
        tsukamoto="h * (inflection - end) / y + 2.0 * end - inflection",
    ),
    Shape(
        "binary",
        ("start", "direction"),
        ("x", "x"),
        "1 for x >= start when direction > start, 1 for x <= start when direction < start, "
        "0 elsewhere (fuzzylite Binary)",
        "pwl",
        _NOT_PWL,
        _binary,
        _BP_SUPPORT,
        _BP_POINTS,
        NOT_MONOTONIC,
        _sp(_fcl(_fl("Binary", 2)), Written("binarymf", _I2), Written("Binary", _I2), "binary"),
        (5, 10),
        Studio(("c", "b"), (_h(0, 0.5),)),
        NA("direction == start is defined: 0 everywhere (fuzzylite)"),
        HULL,
        NO_JFL,
        infinite=(1,),
    ),
    _smooth(
        "arc",
        ("start", "end"),
        ("x", "x"),
        "quarter ellipse: 0 before start, sqrt(r^2 - (x-end)^2) / |r| with r = end - start "
        "between start and end, 1 beyond end (pyfuzzylite Arc; falls when end < start)",
        # (x - end) / r, squared: sqrt(r^2 - (x-end)^2) / |r| without squaring r (1e300 overflows)
        "sqrt(max(1.0 - (t := (x - end) / (end - start)) * t, 0.0)) "
        "if (start < end and start <= x and x <= end) or (start > end and end <= x and x <= start) else "
        "(1.0 if (start < end and x > end) or (start > end and x < end) else 0.0)",
        support=lambda p: (p[0], math.inf) if p[0] < p[1] else (-math.inf, p[0]),
        characteristic=lambda p: (p[0], 0.5 * (p[0] + p[1]), p[1]),
        spellings=_sp(
            _fcl(_fl("Arc", 2)),
            NA("pyfuzzylite 8 only: no FIS type"),
            Written("Arc", _I2, pyfuzzylite_only=True),
            "arc",
        ),
        probe=(2, 8),
        studio=Studio(("a", "b"), (_h(0, 0), _h(1, 1))),
        degenerate=Degenerate("needs start != end", lambda p: p[0] == p[1]),
        tsukamoto="end + (-1.0 if start < end else 1.0) * "
        "sqrt(max((r := end - start) * r - (q := y * r / h) * q, 0.0))",
    ),
    _smooth(
        "semiellipse",
        ("start", "end"),
        ("x", "x"),
        "sqrt(r^2 - (x-c)^2) / r on [start, end] with c, r its centre and half-width, "
        "0 outside (pyfuzzylite SemiEllipse)",
        "s = min(start, end); e = max(start, end); r = 0.5 * (e - s); c = s + r\n"
        "sqrt(max(1.0 - (t := (x - c) / r) * t, 0.0)) if s <= x and x <= e else 0.0",
        support=lambda p: (min(p), max(p)),
        characteristic=lambda p: (p[0], 0.5 * (p[0] + p[1]), p[1]),
        spellings=_sp(
            _fcl(_fl("SemiEllipse", 2)),
            NA("pyfuzzylite 8 only: no FIS type"),
            Written("SemiEllipse", _I2, pyfuzzylite_only=True),
            "semiellipse",
        ),
        probe=(2, 8),
        studio=Studio(("a", "b"), (_h(0, 0), _h(1, 0))),
        degenerate=Degenerate("needs start != end", lambda p: p[0] == p[1]),
        zero_outside=_ZERO_OUTSIDE_HULL,
    ),
    Shape(
        "constant",
        ("value",),
        ("x",),
        "Takagi-Sugeno constant output",
        "ts",
        _TS_NA,
        _TS_NA,
        _TS_NA,
        _TS_NA,
        NA("a Takagi-Sugeno output is averaged as it is"),
        _sp(
            _fcl(Written("Constant", (0,), FL)),
            Written("constant", (0,)),
            Written("Constant", (0,)),
            "constant",
        ),
        (5.0,),
        Studio(("c",), ({"at": 0, "y": 1, "line": True},)),
        ANY,
        WHOLE_LINE,
        NA("jFuzzyLogic reads it as a singleton at its value"),
        probe_output=(5.0,),
        zero_outside=lambda p: (p[0], p[0]),
    ),
    Shape(
        "linear",
        ("coefficients",),
        ("coef",),
        "Takagi-Sugeno linear output: sum(c_i * input_i) + constant, inputs in declaration order",
        "ts",
        _TS_NA,
        _TS_NA,
        _TS_NA,
        _TS_NA,
        NA("a Takagi-Sugeno output is averaged as it is"),
        _sp(
            _fcl(Written("Linear", (), FL, variadic=True)),
            Written("linear", (), variadic=True),
            Written("Linear", (), variadic=True),
            "linear",
        ),
        (0.5, 0.25, 1.0),
        Studio((), ()),
        ANY,
        WHOLE_LINE,
        NA("jFuzzyLogic has no linear output"),
        probe_output=(0.5, 0.25, 1.0),
        variadic=True,
    ),
)

#: The registry: kind name -> entry, in the order of :data:`ENTRIES`.
SHAPES: dict[str, Shape] = {s.kind: s for s in ENTRIES}


def get(kind: str) -> Shape | None:
    """The entry of ``kind``, or ``None`` for a kind that is not a parametric shape (IEC
    points, singletons, function terms)."""
    return SHAPES.get(kind)


def flag(kind: str, name: str) -> bool:
    """A flag of ``kind``'s entry (``"ts_constant"``, ``"takagi_sugeno"``, ...); False for a
    kind that is not a parametric shape (points, singletons, function terms)."""
    shape = SHAPES.get(kind)
    return bool(getattr(shape, name)) if shape is not None else False


def vertices(kind: str) -> tuple[float, ...] | None:
    """The degrees at the parameters of a shape whose parameters are its breakpoints' x in
    order (triangle, trapezoid), else None."""
    shape = SHAPES.get(kind)
    if shape is None or isinstance(shape.vertices, NA):
        return None
    return shape.vertices


def kinds_where(flag: Callable[[Shape], bool]) -> frozenset[str]:
    """The kinds whose entry satisfies ``flag`` (e.g. ``lambda s: s.smooth``)."""
    return frozenset(s.kind for s in ENTRIES if flag(s))


def placement_tree(text: str) -> Any:
    """A placement expression as a JSON tree: a number, a name (a, b, c, w) or
    ``[op, left, right]`` / ``["neg", operand]`` (what the studio evaluates)."""
    import ast

    def tree(n: ast.expr) -> Any:
        if isinstance(n, ast.Constant) and isinstance(n.value, int | float):
            return float(n.value)
        if isinstance(n, ast.Name):
            return n.id
        if isinstance(n, ast.UnaryOp) and isinstance(n.op, ast.USub):
            return ["neg", tree(n.operand)]
        if isinstance(n, ast.BinOp):
            ops = {ast.Add: "+", ast.Sub: "-", ast.Mult: "*", ast.Div: "/"}
            return [ops[type(n.op)], tree(n.left), tree(n.right)]
        raise ValueError(f"placement {text!r}: {ast.dump(n)}")

    return tree(ast.parse(text, mode="eval").body)


def self_check() -> None:
    """Every entry's formulas parse and its parts agree with its parameters: a check of this
    file, run by tests/kinds/test_shapes_registry.py rather than at every import (it parses
    some 150 formulas; each is parsed again on its first use)."""
    for s in ENTRIES:
        assert len(s.roles) == len(s.params), s.kind
        for f in (s.formula, s.jfl):
            if isinstance(f, str):
                fm.parse(f, ("x", *s.params), HELPERS)
        if isinstance(s.tsukamoto, str):
            fm.parse(s.tsukamoto, ("y", "h", *s.params), HELPERS)
        for text in s.studio.placement:
            fm.parse(text, ("a", "b", "c", "w"))
        if not s.variadic:
            assert len(s.studio.placement) == len(s.params), s.kind
