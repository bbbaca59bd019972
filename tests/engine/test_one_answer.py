"""One answer on every path (issue 25.1, 25.6, 25.10) with small systems written here.

Every shape the engine reads is evaluated at extreme and degenerate parameters and points on
each path - the float scalar formula (``shapes.membership``, what the interpreter uses), numpy
(``shapes.membership_np``), the IR rendered as Python (``compile(backend="python").evaluate``)
and as numpy (``evaluate_batch``), and the native C evaluator when a C compiler is there - and
each must give the same degree, or all the same refusal.  The reference is IEEE arithmetic as
fuzzylite (C++) computes each formula: ``pow(0, e < 0)`` is +inf, an overflowing power or
exponential is inf, so ``1 / (1 + inf)`` is 0."""

from __future__ import annotations

import itertools
import math
import warnings

import numpy as np
import pytest

from fuzzyctl import model as m
from fuzzyctl.api import compile as compile_api
from fuzzyctl.diagnostics import DiagnosticError, FuzzyctlError
from fuzzyctl.engine.semantics import shapes
from tests.engine.builders import is_, rule, shape, single, terms, then, var_in, var_out

HUGE = 1e300
TINY = 5e-324  # the smallest subnormal
# parameter values that break formulas: huge, negative, zero, subnormal
EXTREMES = (0.0, 1.0, -1.0, 0.5, -2.0, 2.0, HUGE, -HUGE, TINY, -TINY, 1e-300, 1e150)
POINTS = (0.0, 0.5, 1.0, -1.0, 2.0, HUGE, -HUGE, TINY, 1e-300, 1e150, -1e150)

ARITY = {name: len(spec.params) for name, spec in m.SHAPES.items()}
KINDS = sorted(k for k in shapes.SMOOTH_KINDS | {"triangle", "trapezoid", "rectangle", "ramp"} if k in ARITY)


def _param_sets(kind: str, n: int) -> list[tuple[float, ...]]:
    """A few dozen parameter tuples per kind: each extreme in each position of a sane base,
    plus the centre-at-the-point cases (x at the centre with a negative/zero slope)."""
    base = {1: (0.5,), 2: (0.0, 1.0), 3: (0.0, 0.5, 1.0), 4: (-1.0, 0.0, 0.5, 1.0)}[n]
    out = {base}
    for i, v in itertools.product(range(n), EXTREMES):
        p = list(base)
        p[i] = v
        out.add(tuple(p))
    if kind == "bell":
        out |= {
            (c, w, s) for c in (0.0, HUGE, -HUGE) for w in (0.2, 1e-300, HUGE) for s in (-2.0, 0.0, 2.0, -9.4)
        }
    return sorted(out)


def _degree_block(kind: str, params: tuple[float, ...]) -> m.FunctionBlock:
    """y = the degree of x in the term (COGS of 1 and 0 weighted by mu and NOT mu)."""
    return m.FunctionBlock(
        "deg",
        variables=var_in("x") + var_out("y"),
        fuzzify=(m.FuzzifyBlock("x", terms(t=shape(kind, *params))),),
        defuzzify=(
            m.DefuzzifyBlock(
                "y", terms(one=single(1.0), zero=single(0.0)), None, "COGS", m.Default(math.nan)
            ),
        ),
        rule_blocks=(
            m.RuleBlock(
                "rb",
                (
                    rule("1", is_("x", "t"), then("y", "one")),
                    rule("2", is_("x", "t", negated=True), then("y", "zero")),
                ),
            ),
        ),
    )


def _same(a: float, b: float) -> bool:
    return (math.isnan(a) and math.isnan(b)) or a == b or abs(a - b) <= 1e-12


def _compile(fb: m.FunctionBlock, backend: str) -> object | None:
    try:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            return compile_api(fb, backend=backend)
    except (DiagnosticError, FuzzyctlError):
        return None


@pytest.mark.parametrize("kind", KINDS)
def test_membership_formulas_agree_at_extremes(kind: str) -> None:
    """The scalar and numpy formulas give the same degree for every extreme parameter set and
    point (the interpreter uses the first, the quadrature of output sets the second)."""
    n = ARITY[kind]
    for params in _param_sets(kind, n):
        if kind in shapes.PWL_KINDS and list(params) != sorted(params):
            continue  # lowering reads unordered vertices as fuzzylite does (test_shapes)
        xs = np.array(POINTS + params)
        with np.errstate(all="ignore"):
            vec = shapes.membership_np(kind, list(params), 1.0, xs)
        for x, v in zip(xs, vec, strict=True):
            s = shapes.membership(kind, list(params), 1.0, float(x))
            assert _same(s, float(v)), (kind, params, float(x), s, float(v))


@pytest.mark.parametrize("kind", KINDS)
def test_every_path_reads_a_term_the_same_at_extremes(kind: str) -> None:
    """Generated Python, generated numpy (and native C) against the interpreter and the
    formula, on a term of the input (so each path's own copy of the formula is used)."""
    n = ARITY[kind]
    checked = 0
    for params in _param_sets(kind, n)[:: 1 if kind == "bell" else 2]:
        fb = _degree_block(kind, params)
        ref, fast = _compile(fb, "interpreted"), _compile(fb, "python")
        assert (ref is None) == (fast is None), (kind, params)  # the same refusal
        if ref is None or fast is None:
            continue
        xs = [float(x) for x in (*POINTS, *params) if math.isfinite(x)]
        batch = fast.evaluate_batch({"x": np.array(xs)})["y"]  # type: ignore[attr-defined]
        tp = ref.plan.fuzzy_inputs[0].terms[0]  # type: ignore[attr-defined]
        for k, x in enumerate(xs):
            want = ref.evaluate({"x": x})["y"]  # type: ignore[attr-defined]
            # the lowered term (subnormals flushed, vertices ordered) through the formula
            mu = shapes.membership(tp.kind, [float(p) for p in tp.params], 1.0, x)
            assert 0.0 <= mu <= 1.0 or math.isnan(mu), ("degree out of [0, 1]", kind, params, x, mu)
            assert _same(want, mu) or (mu == 1.0 and abs(want - 1.0) < 1e-15), (kind, params, x, want, mu)
            got = fast.evaluate({"x": x})["y"]  # type: ignore[attr-defined]
            assert _same(got, want), ("python", kind, params, x, got, want)
            assert _same(float(batch[k]), want), ("numpy", kind, params, x, float(batch[k]), want)
        checked += 1
    assert checked


def _has_cc() -> bool:
    import shutil

    return any(shutil.which(c) for c in ("cc", "gcc", "clang"))


@pytest.mark.skipif(not _has_cc(), reason="no C compiler for the native backend")
def test_native_reads_bell_like_the_interpreter_at_extremes() -> None:
    """The native evaluator's Bell (the IR printed as C) at its centre with negative, zero
    and positive slopes, centres of 1e300: the interpreter's degree."""
    for c, w, s in itertools.product((0.0, HUGE), (0.2, HUGE), (-2.0, 0.0, 2.0)):
        fb = _degree_block("bell", (c, w, s))
        ref, nat = _compile(fb, "interpreted"), _compile(fb, "native")
        assert ref is not None and nat is not None
        for x in (c, 0.0, 0.5, -HUGE, HUGE):
            want = ref.evaluate({"x": x})["y"]  # type: ignore[attr-defined]
            got = nat.evaluate({"x": x})["y"]  # type: ignore[attr-defined]
            assert _same(got, want), (c, w, s, x, got, want)


def test_bell_of_negative_slope_is_zero_at_its_centre() -> None:
    """fuzzylite's formula h / (1 + |(x-c)/w|^(2s)) in IEEE arithmetic: pow(0, -4) = inf,
    so the degree is 0 at the centre (the limit of the term there too); slope 0: 1/2."""
    for s, want in ((-2.0, 0.0), (0.0, 0.5), (2.0, 1.0)):
        fb = _degree_block("bell", (0.0, 0.2, s))
        for backend in ("python", "interpreted"):
            ctl = _compile(fb, backend)
            assert ctl is not None
            assert ctl.evaluate({"x": 0.0})["y"] == want, (backend, s)  # type: ignore[attr-defined]
        assert shapes.membership("bell", [0.0, 0.2, s], 1.0, 0.0) == want
        assert compile_api(fb, backend="python").evaluate_batch({"x": np.array([0.0])})["y"][0] == want
