"""The interval type-2 IR program (fuzzyctl.ir.builders.type2) against the Python type-2
engine: rendered as Python it computes what ``Type2Controller(fb, samples=N)`` computes
(to 1e-12), numpy batches and the native C what the Python rendering computes, and all of
them the exact centroid within the sampling's O(h)."""

from __future__ import annotations

import dataclasses
import math
import random

import numpy as np
import pytest

import fuzzyctl
from fuzzyctl import model as m
from fuzzyctl.engine import type_reduction as trm
from fuzzyctl.engine.native import compiler
from fuzzyctl.engine.type2 import Type2Controller
from fuzzyctl.engine.type2_compiled import Type2Compiled
from fuzzyctl.ir.builders.type2_reduce import iterations
from fuzzyctl.ir.programs.type2 import build_type2_fast
from fuzzyctl.ir.render.pysrc import specialise
from tests.engine.type2_systems import random_it2

METHODS = ("KM", "EKM", "IASC", "EIASC")
EXAMPLE = "examples/tipper_type2.fis"
needs_cc = pytest.mark.skipif(compiler() is None, reason="no C compiler")


def _rows(fb: m.FunctionBlock, seed: int, n: int) -> list[dict[str, float]]:
    rng = random.Random(seed)
    return [{v.name: rng.uniform(-0.5, 10.5) for v in fb.inputs} for _ in range(n)]


def _close(a: float, b: float, tol: float) -> bool:
    return (math.isnan(a) and math.isnan(b)) or abs(a - b) <= tol


def _gaussian_system(sugeno: bool) -> m.FunctionBlock:
    """Smooth input terms: an explicit smooth lower function and the scale/lag form of a
    smooth upper one; hedges, NOT and OR in the rules."""
    fb = random_it2(3, sugeno=sugeno)
    terms = (
        m.Term(
            "t0",
            m.ShapeMF("gaussian", (2.0, 1.5)),
            lower=m.LowerMF(mf=m.ShapeMF("gaussian", (2.0, 1.0), 0.7)),
        ),
        m.Term("t1", m.ShapeMF("bell", (2.0, 3.0, 5.0)), lower=m.LowerMF(scale=0.8, lag=(0.3,))),
        m.Term(
            "t2", m.ShapeMF("trapezoid", (5.0, 7.0, 8.0, 11.0)), lower=m.LowerMF(scale=0.9, lag=(0.1, 0.4))
        ),
    )
    fz = tuple(dataclasses.replace(f, terms=terms) for f in fb.fuzzify)
    rules = (
        m.Rule(
            "1",
            m.Or((m.Is("x0", "t0", hedges=("very",)), m.Is("x1", "t1"))),
            (m.Conclusion("y", fb.defuzzify[0].terms[0].name),),
        ),
        m.Rule(
            "2",
            m.And((m.Not(m.Is("x0", "t2")), m.Is("x1", "t2", negated=True))),
            (m.Conclusion("y", fb.defuzzify[0].terms[1].name),),
            weight=0.6,
        ),
        m.Rule(
            "3", m.Is("x1", "t0", hedges=("somewhat",)), (m.Conclusion("y", fb.defuzzify[0].terms[2].name),)
        ),
    )
    block = dataclasses.replace(fb.rule_blocks[0], rules=rules)
    return dataclasses.replace(fb, fuzzify=fz, rule_blocks=(block,))


SYSTEMS = [
    *((f"mamdani{s}", lambda s=s: random_it2(s)) for s in range(6)),
    *((f"explicit{s}", lambda s=s: random_it2(s, explicit=True)) for s in range(6, 10)),
    *((f"sugeno{s}", lambda s=s: random_it2(s, sugeno=True, explicit=s % 2 == 0)) for s in range(10, 16)),
    ("smooth-mamdani", lambda: _gaussian_system(False)),
    ("smooth-sugeno", lambda: _gaussian_system(True)),
]


@pytest.mark.parametrize("name,make", SYSTEMS, ids=[s[0] for s in SYSTEMS])
@pytest.mark.parametrize("method", METHODS)
def test_python_rendering_equals_the_sampled_engine(name: str, make: object, method: str) -> None:
    fb = make()  # type: ignore[operator]
    fn = specialise(build_type2_fast(fb, "py", 101, method).fast)
    ref = Type2Controller(fb, samples=101, method=method)
    for x in _rows(fb, 7, 25):
        got = fn([x[v.name] for v in fb.inputs], [0.0])
        want = ref.evaluate(x, out_of_range="ignore")
        for g, d in zip(got, fb.defuzzify, strict=True):
            assert _close(g, want[d.variable], 1e-12), (x, g, want)


@pytest.mark.parametrize("seed", range(4))
def test_sampled_ir_within_the_sampling_bound_of_the_exact_centroid(seed: int) -> None:
    """docs/type2.md: the sampled end points differ from the exact ones by O(h); the
    output (their mean) by at most 1.5 h here (h = range / (N - 1); measured up to 1.0 h)."""
    fb = random_it2(seed, explicit=seed % 2 == 1)
    exact = Type2Controller(fb)
    for n in (101, 1001):
        ctl = fuzzyctl.compile(fb, backend="python", samples=n)
        h = 10.0 / (n - 1)
        for x in _rows(fb, seed, 30):
            a, b = ctl.evaluate(x)["y"], exact.evaluate(x)["y"]
            assert _close(a, b, 1.5 * h), (n, x, a, b)  # measured: up to 1.0 h


@pytest.mark.parametrize("sugeno", [False, True])
def test_numpy_batch_equals_rows(sugeno: bool) -> None:
    fb = random_it2(21, sugeno=sugeno)
    ctl: object = fuzzyctl.compile(fb, samples=101)
    assert isinstance(ctl, Type2Compiled)
    rows = _rows(fb, 3, 40)
    data = {v.name: np.array([r[v.name] for r in rows]) for v in fb.inputs}
    out = ctl.evaluate_batch(data, out_of_range="ignore")["y"]
    chunked = ctl.evaluate_batch(data, out_of_range="ignore", chunk=7)["y"]
    assert np.array_equal(out, chunked, equal_nan=True)
    for i, r in enumerate(rows):
        assert _close(out[i], ctl.evaluate(r, out_of_range="ignore")["y"], 1e-12)


@needs_cc
@pytest.mark.parametrize("name,make", SYSTEMS[::3], ids=[s[0] for s in SYSTEMS[::3]])
def test_native_equals_python(name: str, make: object) -> None:
    fb = make()  # type: ignore[operator]
    nat = fuzzyctl.compile(fb, backend="native", samples=101)
    py = fuzzyctl.compile(fb, backend="python", samples=101)
    rows = _rows(fb, 5, 40)
    data = {v.name: np.array([r[v.name] for r in rows]) for v in fb.inputs}
    batch = nat.evaluate_batch(data, out_of_range="ignore")
    for i, r in enumerate(rows):
        want = py.evaluate(r, out_of_range="ignore")
        got = nat.evaluate(r, out_of_range="ignore")
        for k in want:
            assert _close(got[k], want[k], 1e-12)
            assert _close(batch[k][i], want[k], 1e-12)


@needs_cc
def test_native_backend_runs_the_example() -> None:
    ctl = fuzzyctl.compile(EXAMPLE, backend="native")
    exact = fuzzyctl.compile(EXAMPLE, backend="python")
    # 1001 samples by default over the range [0, 30]: h = 0.03
    assert abs(ctl.evaluate(service=3, food=8)["tip"] - exact.evaluate(service=3, food=8)["tip"]) < 0.03
    assert ctl.explain(service=3, food=8).outputs[0].exact is False


def _brute(xs: list[float], lo: list[float], up: list[float]) -> tuple[float, float]:
    """Every switch point tried (points sorted)."""
    order = sorted(range(len(xs)), key=lambda i: xs[i])
    x, a, b = [xs[i] for i in order], [lo[i] for i in order], [up[i] for i in order]

    def mean(w: list[float]) -> float:
        s = sum(w)
        return sum(p * q for p, q in zip(x, w, strict=True)) / s if s > 0 else math.nan

    n = len(x)
    left = [mean(b[:k] + a[k:]) for k in range(n + 1)]
    right = [mean(a[:k] + b[k:]) for k in range(n + 1)]
    return min(v for v in left if v == v), max(v for v in right if v == v)


def test_ekm_with_zero_lower_weights_matches_brute_force() -> None:
    """The engine's EKM updated its sums incrementally and cancelled catastrophically when
    the lower weights were 0 (a yl outside the points); it now sums each switch point."""
    xs = [-0.23244619626221485, 1.4167669421204359, 3.7610896895728967, 1.9405993423869505]
    lo = [0.0] * 4
    up = [0.7168500376095548, 0.4913369881202435, 0.04864081178329649, 0.8301177480440944]
    want = _brute(xs, lo, up)
    got = trm.enhanced_karnik_mendel(xs, lo, up)
    assert abs(got[0] - want[0]) < 1e-12 and abs(got[1] - want[1]) < 1e-12
    rng = random.Random(5)
    for _ in range(500):
        n = rng.randint(1, 7)
        xs = [rng.uniform(-5, 5) for _ in range(n)]
        lo = [rng.uniform(0, 1) * rng.choice([0, 1]) for _ in range(n)]
        up = [a + rng.uniform(0, 1) for a in lo]
        want = _brute(xs, lo, up)
        got = trm.enhanced_karnik_mendel(xs, lo, up)
        assert abs(got[0] - want[0]) < 1e-9 and abs(got[1] - want[1]) < 1e-9, (xs, lo, up)


def test_stated_iteration_bounds() -> None:
    assert iterations("KM", 101) == iterations("EKM", 101) == 103
    assert iterations("IASC", 101) == iterations("EIASC", 101) == 101


@pytest.mark.parametrize("samples", [0, 1, -5, 2.5, True])
@pytest.mark.parametrize("backend", [None, "python", "native"])
def test_a_sample_count_below_two_is_refused_not_replaced(samples: object, backend: str | None) -> None:
    # 0 once fell back to the default 101 samples silently
    with pytest.raises(ValueError, match="samples="):
        fuzzyctl.compile(EXAMPLE, backend=backend, samples=samples)
    with pytest.raises(ValueError, match="samples="):
        Type2Controller(fuzzyctl.load(EXAMPLE).main, samples=samples)  # type: ignore[arg-type]


def test_two_samples_are_accepted() -> None:
    ctl = fuzzyctl.compile(EXAMPLE, samples=2)
    assert all(math.isfinite(v) for v in ctl.evaluate({"service": 5, "food": 5}).values())
