"""compile(model, backend="native") against the Python core (the specialised scalar path) to
1e-12 of the output range: every example and hypothesis-generated random systems, each built
through the backend into its own cached library; plus the cache, the fallback without a
compiler, and the Controller interface (explain, reset, NC state).

The conformance systems are checked to the same 1e-12 in tests/codegen/test_c.py, on the
very C the backend compiles, built in one compiler run: one build per system here would cost
a minute of compiling and prove nothing more (the backend adds only the batch wrapper, which
the builds here exercise, and -O3 with -ffp-contract=off keeps IEEE arithmetic)."""

from __future__ import annotations

import os
import threading
import warnings
from collections.abc import Iterator
from concurrent.futures import ThreadPoolExecutor
from pathlib import Path

import numpy as np
import pytest
from hypothesis import HealthCheck, Phase, given, settings
from hypothesis import strategies as st

import fuzzyctl
from fuzzyctl.codegen import native
from fuzzyctl.codegen.native import NativeController
from fuzzyctl.engine.controller import Controller
from tests.codegen import systems as S
from tests.engine import randsys

TOL = 1e-12


@pytest.fixture(scope="module", autouse=True)
def private_cache(tmp_path_factory: pytest.TempPathFactory) -> Iterator[Path]:
    """Builds go to a fresh cache directory (and the user's cache is left alone)."""
    path = tmp_path_factory.mktemp("cache")
    old = os.environ.get("FUZZYCTL_CACHE_DIR")
    os.environ["FUZZYCTL_CACHE_DIR"] = str(path)
    yield path
    if old is None:
        del os.environ["FUZZYCTL_CACHE_DIR"]
    else:
        os.environ["FUZZYCTL_CACHE_DIR"] = old


def _files() -> list[tuple[str, Path]]:
    return [(f"examples/{p.name}", p) for p in S.example_files()]


def _native_outputs(ctl: Controller, plan_inputs: list[str], data: np.ndarray) -> np.ndarray:
    got = ctl.evaluate_batch({n: data[:, i] for i, n in enumerate(plan_inputs)})
    cols = [got[n] for n in ctl.outputs]
    return np.column_stack(cols) if cols else np.zeros((len(data), 0))


def test_native_agrees_with_the_python_core_on_every_example() -> None:
    files = _files()
    plans = [S.plan_of(p) for _rel, p in files]
    with ThreadPoolExecutor(max_workers=2) as pool:  # the compiler runs in parallel
        libs = list(pool.map(native.build, plans))
    worst = {}
    for (rel, _p), plan, lib in zip(files, plans, libs, strict=True):
        ctl = NativeController(plan, lib)
        data = S.random_inputs(plan, 2000, seed=7)
        got = _native_outputs(ctl, [i.name for i in plan.inputs], data)
        worst[rel] = S.max_error(plan, got, S.reference(plan, data, "scalar"))
    bad = {k: v for k, v in worst.items() if not v <= TOL}
    assert not bad, bad
    print(f"\nnative: worst deviation {max(worst.values()):.2e} of the range over {len(worst)} systems")


AND_NORMS = ("MIN", "PROD", "BDIF", "DMIN", "NIPMIN", "HAMACHER", "EINSTEIN")


# no shrinking: each example compiles a library; the failure message describes the system
@settings(
    max_examples=30,
    deadline=None,
    phases=[Phase.explicit, Phase.reuse, Phase.generate],
    suppress_health_check=[HealthCheck.too_slow],
)
@given(fb=randsys.system(ands=AND_NORMS), seed=st.integers(0, 1000))
def test_native_agrees_on_random_systems(fb: fuzzyctl.model.FunctionBlock, seed: int) -> None:
    plan = fuzzyctl.compile(fb, backend="interpreted").plan
    ctl = NativeController(plan, native.build(plan))
    rng = np.random.default_rng(seed)
    data = rng.uniform(randsys.LO - 1, randsys.HI + 1, (300, len(plan.inputs)))
    got = _native_outputs(ctl, [i.name for i in plan.inputs], data)
    err = S.max_error(plan, got, S.reference(plan, data, "scalar"))
    assert err <= TOL, (err, randsys.describe(fb))


@settings(max_examples=5, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(fb=randsys.system(smooth_output=True))
def test_inexpressible_systems_fall_back_to_numpy_with_a_warning(fb: fuzzyctl.model.FunctionBlock) -> None:
    with pytest.warns(RuntimeWarning, match="native backend unavailable.*output y"):
        ctl = fuzzyctl.compile(fb, backend="native")
    assert not isinstance(ctl, NativeController)
    assert ctl.evaluate({"x0": 5.0, **({"x1": 5.0} if "x1" in ctl.inputs else {})})


def test_missing_compiler_falls_back_with_a_warning(monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setenv("CC", "/nonexistent/cc")
    doc = fuzzyctl.load(S.EXAMPLES / "figure7.fcl")
    with pytest.warns(RuntimeWarning, match="no C compiler"):
        ctl = fuzzyctl.compile(doc, backend="native")
    assert not isinstance(ctl, NativeController)
    assert ctl.evaluate({"temp": 10, "pressure": 60})["valve"] == pytest.approx(51.8518518519)


def test_builds_are_cached_and_safe_under_concurrency(private_cache: Path) -> None:
    plan = S.plan_of(S.EXAMPLES / "heater_extension.fcl", "heater_concurrent")
    results: list[Path] = []
    errors: list[BaseException] = []

    def build() -> None:
        try:
            results.append(native.build(plan))
        except BaseException as exc:  # pragma: no cover - reported below
            errors.append(exc)

    threads = [threading.Thread(target=build) for _ in range(4)]
    for t in threads:
        t.start()
    for t in threads:
        t.join()
    assert not errors
    assert len(set(results)) == 1
    lib = results[0]
    assert lib.parent == private_cache / "native"
    assert not list(lib.parent.glob(".*.tmp"))  # no half-written leftovers
    stamp = lib.stat().st_mtime_ns
    assert native.build(plan) == lib and lib.stat().st_mtime_ns == stamp  # not rebuilt
    NativeController(plan, lib).evaluate({"temp": 18, "trend": 0.1, "setpoint": 21, "eco": 0.5})


def test_controller_interface_single_explain_reset_and_nc_state() -> None:
    doc = fuzzyctl.load(S.EXAMPLES / "heater_extension.fcl")
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        nat = fuzzyctl.compile(doc, backend="native")
    py = fuzzyctl.compile(doc)
    assert isinstance(nat, NativeController)
    assert (nat.inputs, nat.outputs) == (py.inputs, py.outputs)
    # fan and damper keep their value when no rule fires (DEFAULT := NC): a sequence with
    # firing and non-firing rows must give the same outputs in both
    seq = [
        {"temp": 5.0, "trend": -1.5, "setpoint": 21.0, "eco": 0.3},
        {"temp": 40.0, "trend": 0.0, "setpoint": 40.0, "eco": 0.3},
        {"temp": 21.0, "trend": 2.0, "setpoint": 21.0, "eco": 1.0},
        {"temp": 12.0, "trend": 0.4, "setpoint": 19.0, "eco": 0.0},
    ]
    for row in seq:
        a, b = nat.evaluate(row), py.evaluate(row)
        assert a.keys() == b.keys()
        for k in a:
            assert a[k] == pytest.approx(b[k], abs=1e-12 * 100), (row, k)
    # explain runs the Python core on the native instance's state and advances it
    e = nat.explain(seq[1])
    assert e.output("fan").value == pytest.approx(py.explain(seq[1]).output("fan").value, abs=1e-9)
    assert nat.evaluate(seq[2]) == pytest.approx(py.evaluate(seq[2]), abs=1e-9)
    nat.reset()
    py.reset()
    assert nat.evaluate(seq[1]) == pytest.approx(py.evaluate(seq[1]), abs=1e-9)
    with pytest.raises(fuzzyctl.diagnostics.InputError, match="eco"):
        nat.evaluate({**seq[0], "eco": 1.5})
    with pytest.raises(fuzzyctl.diagnostics.InputError, match="missing input"):
        nat.evaluate({"temp": 1.0})
