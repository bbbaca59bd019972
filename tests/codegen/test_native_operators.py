"""Every activation, accumulation, AND/OR norm and defuzzification method on small random
systems (tests/engine/opsweep.py): the native backend (scalar and batch), the Python path
(scalar) and numpy (batch) against the reference interpreter and against an independent
brute-force oracle (tests/engine/bruteforce.py: adaptive Simpson from 2^14 cells, written
against the model), all within 1e-9 of the output range.

``make test`` runs three systems of nine pairs each (every activation and accumulation
appears); ``make fuzz`` (HYPOTHESIS_PROFILE=fuzz) all 63 pairs on fresh seeds.  The repro
files of issue 25 (../shared/repro) are checked in the ``repro`` extra suite."""

from __future__ import annotations

import math
import os
import warnings

import numpy as np
import pytest
from hypothesis import HealthCheck, Phase, given, settings
from hypothesis import strategies as st

import fuzzyctl
from fuzzyctl import model as m
from fuzzyctl.engine.native import NativeController
from tests.codegen import systems as S
from tests.engine import bruteforce, opsweep
from tests.extras import extra_path

TOL = 1e-9  # of the output range
FUZZ = os.environ.get("HYPOTHESIS_PROFILE") == "fuzz"


private_cache = S.private_cache  # builds go to a fresh cache directory (autouse)


def _same(a: float, b: float, span: float, tol: float = TOL) -> bool:
    if math.isnan(a) or math.isnan(b):
        return math.isnan(a) and math.isnan(b)
    return abs(a - b) <= tol * span


def check(fb: m.FunctionBlock, rows: list[dict[str, float]], oracle: bool = True) -> list[str]:
    """Disagreements (as messages) between the paths, the reference and the oracle."""
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # a system native cannot express falls back: still compared
        ref = fuzzyctl.compile(fb, backend="interpreted")
        py = fuzzyctl.compile(fb, backend="python")
        nat = fuzzyctl.compile(fb, backend="native")
    cols = {n: np.array([r[n] for r in rows]) for n in ref.inputs}
    batches = {"native batch": nat.evaluate_batch(cols), "numpy batch": py.evaluate_batch(cols)}
    bad = []
    for i, row in enumerate(rows):
        want = ref.evaluate(row)
        got = {"native": nat.evaluate(row), "python": py.evaluate(row)}
        got.update({k: {o: float(v[o][i]) for o in v} for k, v in batches.items()})
        for out in ref.outputs:
            db = fb.defuzzify_block(out)
            assert db is not None and db.range is not None
            span = db.range.high - db.range.low
            for path, vals in got.items():
                if not _same(vals[out], want[out], span):
                    bad.append(f"{out} {row}: {path} {vals[out]!r} != interpreted {want[out]!r}")
            if oracle and (db.method or "COG") in ("COG", "COA"):
                exact = bruteforce.evaluate(fb, row, out)
                exact = -1.0 if math.isnan(exact) else exact  # DEFAULT := -1
                if not _same(want[out], exact, span):
                    bad.append(f"{out} {row}: interpreted {want[out]!r} != brute force {exact!r}")
                if not _same(got["native"][out], exact, span):
                    bad.append(f"{out} {row}: native {got['native'][out]!r} != brute force {exact!r}")
    return bad


@pytest.mark.parametrize(
    ("seed", "smooth", "methods"),
    [(1, True, ("COG",)), (2, False, ("COG",)), (3, False, ("COG", "COA", "LM", "RM", "MOM"))],
)
def test_every_operator_agrees_with_the_reference_and_the_brute_force(
    seed: int, smooth: bool, methods: tuple[str, ...]
) -> None:
    fb = opsweep.system(seed, smooth, opsweep.some_pairs(seed), methods)
    assert not check(fb, opsweep.inputs(seed, 3))


def test_native_compiles_the_smooth_sweep_rather_than_falling_back() -> None:
    """The COG systems above really run in C (a fallback would compare Python to itself)."""
    fb = opsweep.system(1, True, opsweep.some_pairs(1))
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        assert isinstance(fuzzyctl.compile(fb, backend="native"), NativeController)


@settings(
    max_examples=12 if FUZZ else 1,
    deadline=None,
    derandomize=not FUZZ,
    phases=(Phase.explicit, Phase.generate),
    suppress_health_check=list(HealthCheck),
)
@given(seed=st.integers(0, 2**31 - 1), smooth=st.booleans())
def test_all_pairs_on_fresh_seeds(seed: int, smooth: bool) -> None:
    """All 63 activation x accumulation pairs (one example in make test, twelve in make fuzz)."""
    if not FUZZ:
        pytest.skip("the 63-pair sweep runs under make fuzz")
    fb = opsweep.system(seed, smooth, opsweep.all_pairs())
    assert not check(fb, opsweep.inputs(seed, 4))


# --------------------------------------------------------------------------- issue 25 reproducers

REPRO = [
    ("nipmin_narrow.fcl", [{"service": 8.94542345473419, "food": 5.322094722350856}]),
    ("nipmin_tipper.fcl", None),
    ("native_hamacher.fcl", [{"distance": 0.5696042758105196, "cs": 0.3893604630828713}]),
    ("mam21.fll", [{"angle": -5.0, "velocity": -5.0}]),
    ("arc.fll", None),
]


@pytest.mark.extra("repro")
@pytest.mark.parametrize(("name", "rows"), REPRO, ids=[r[0] for r in REPRO])
def test_issue25_reproducers_native_python_interpreted_and_brute_force(
    name: str, rows: list[dict[str, float]] | None
) -> None:
    doc = fuzzyctl.load(extra_path("repro", "repro", name))
    fb = doc.blocks[0]
    ref = fuzzyctl.compile(doc, backend="interpreted")
    paths = {b: fuzzyctl.compile(doc, backend=b) for b in ("python", "native")}
    assert isinstance(paths["native"], NativeController)
    plan = ref.plan
    if rows is None:  # inputs across each input's terms
        rng = np.random.default_rng(25)
        rows = [
            {n: float(rng.uniform(0.0, 10.0 if "nipmin" in name else 1.0)) for n in ref.inputs}
            for _ in range(12)
        ]
    for out in ref.outputs:
        op = next(o for o in plan.outputs if o.name == out)
        assert op.low is not None and op.high is not None
        span = op.high - op.low
        for row in rows:
            exact = bruteforce.evaluate(fb, row, out, (op.low, op.high))
            if math.isnan(exact):  # no rule fired: the DEFAULT
                exact = math.nan if op.default is None else op.default
            for label, ctl in (("interpreted", ref), *paths.items()):
                got = ctl.evaluate(row)[out]
                assert _same(got, exact, span), (label, row, got, exact)
