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
import re
import threading
import warnings
from concurrent.futures import ThreadPoolExecutor
from pathlib import Path

import numpy as np
import pytest
from hypothesis import HealthCheck, Phase, given, settings
from hypothesis import strategies as st

import fuzzyctl
from fuzzyctl.engine import native
from fuzzyctl.engine.controller import Controller
from fuzzyctl.engine.native import NativeController
from tests.codegen import systems as S
from tests.engine import randsys

TOL = 1e-12


private_cache = S.private_cache  # builds go to a fresh cache directory (autouse)


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
@given(fb=randsys.system(smooth_output=True, methods=("COA", "LM", "RM", "MOM")))
def test_smooth_sets_run_native_for_every_method(fb: fuzzyctl.model.FunctionBlock) -> None:
    """Smooth sets under CoA, LM, RM and MoM are evaluated in C (no fallback, no warning) and
    agree with the reference; a smooth, unclipped maximum is only defined to the width of its
    flat stretch in double precision (docs/engine.md: 1.5e-6 of the range seen), hence 1e-5."""
    with warnings.catch_warnings():
        warnings.simplefilter("error", RuntimeWarning)
        ctl = fuzzyctl.compile(fb, backend="native")
    assert isinstance(ctl, NativeController)
    plan = ctl.plan
    data = np.random.default_rng(0).uniform(randsys.LO, randsys.HI, (50, len(plan.inputs)))
    got = _native_outputs(ctl, [i.name for i in plan.inputs], data)
    err = S.max_error(plan, got, S.reference(plan, data, "scalar"))
    assert err <= 1e-5, (err, randsys.describe(fb))


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
    inode = lib.stat().st_ino  # a rebuild renames a new file into place
    assert native.build(plan) == lib and lib.stat().st_ino == inode  # not rebuilt
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


# --------------------------------------------------------------------------- the evaluator in C


def _nc_system() -> fuzzyctl.model.FunctionBlock:
    """One input, two outputs: y keeps its value where no rule fires (NC), z falls back to
    its DEFAULT; inputs beyond [0, 10] fire nothing."""
    src = """
    FUNCTION_BLOCK nc
    VAR_INPUT x : REAL; END_VAR
    VAR_OUTPUT y : REAL; z : REAL; END_VAR
    FUZZIFY x TERM lo := (0, 1) (10, 0); TERM hi := (0, 0) (10, 1); END_FUZZIFY
    DEFUZZIFY y TERM a := (0, 0) (5, 1) (10, 0); TERM b := (5, 0) (10, 1) (15, 0);
      RANGE := (0 .. 15); METHOD : COG; DEFAULT := NC; END_DEFUZZIFY
    DEFUZZIFY z TERM a := 2; TERM b := 8; METHOD : COGS; DEFAULT := -1; END_DEFUZZIFY
    RULEBLOCK r
      RULE 1 : IF x IS lo THEN y IS a, z IS a;
      RULE 2 : IF x IS hi THEN y IS b, z IS b;
    END_RULEBLOCK
    END_FUNCTION_BLOCK
    """
    return fuzzyctl.load(src).main


def test_batch_loop_carries_nc_across_rows_and_threads() -> None:
    """One C call per batch; with more rows than a thread takes, slices run in parallel and
    the NC rows at the start of each slice get the previous slice's last value: the result
    is the one of evaluating the rows one after the other, in order."""
    fb = _nc_system()
    plan = fuzzyctl.compile(fb, backend="interpreted").plan
    nat = NativeController(plan, native.build(plan))
    assert nat._parallel and nat._nc == [0]
    rng = np.random.default_rng(4)
    n = 3 * native.THREAD_ROWS + 17
    x = np.where(rng.random(n) < 0.6, rng.uniform(-30, -5, n), rng.uniform(0, 10, n))
    x[: native.THREAD_ROWS + 5] = -20.0  # the first slice fires nothing: NC from the start
    calls = []
    real = nat._call_batch
    nat._call_batch = lambda *a: calls.append(a[1:3]) or real(*a)  # type: ignore[method-assign]
    nat.evaluate({"x": 3.0})  # the state entering the batch
    got = nat.evaluate_batch({"x": x})
    assert len(calls) >= 2, "slices in parallel"
    ref = fuzzyctl.compile(fb, backend="python")
    ref.evaluate({"x": 3.0})
    want = ref.evaluate_batch({"x": x})
    for k in ("y", "z"):  # the same values (to rounding: C and numpy), NC rows included
        assert not np.isnan(got[k]).any() and np.max(np.abs(got[k] - want[k])) <= TOL * 15.0, k
    assert np.array_equal(got["y"][: native.THREAD_ROWS + 5], np.full(native.THREAD_ROWS + 5, got["y"][0]))
    # and the state afterwards continues the sequence
    assert nat.evaluate({"x": -50.0}) == pytest.approx(ref.evaluate({"x": -50.0}), abs=1e-12)


@pytest.mark.parametrize("gaussian", [False, True])
def test_table_driven_c_agrees_with_the_interpreter(gaussian: bool) -> None:
    """Above the threshold the C is tables and loops (sparse lookups for triangular
    partitions, the full loop for Gaussian inputs) and agrees with the interpreter."""
    from tests.engine import bigsys

    fb = bigsys.system(7, "mamdani", gaussian_inputs=gaussian)
    plan = fuzzyctl.compile(fb, backend="interpreted").plan
    kind, files = native.sources(plan)
    assert kind == "fast" and "fz_c_FZ_HKEY" in files["fz_native.c"]
    assert "FZ_R17 =" not in files["fz_native.c"], "no statement per rule"
    if native.binary_tables():  # the large tables are data for the assembler, not C text
        assert "fz_c_FZ_HKEY.bin" in files
        assert re.search(r"fz_c_FZ_HKEY\[\d+\] = \{", files["fz_native.c"]) is None
        assert ".incbin" in files["fz_native.c"]
    nat = NativeController(plan, native.build(plan))
    data = np.random.default_rng(1).uniform(-1.2, 1.2, (400, 3))
    got = _native_outputs(nat, [i.name for i in plan.inputs], data)
    err = S.max_error(plan, got, S.reference(plan, data, "scalar"))
    assert err <= TOL, err


def test_smooth_cog_in_c_within_the_documented_tolerance() -> None:
    """Smooth sets (CoG) in C: kinks located, a fixed 8-point Gauss-Legendre rule per piece:
    within 1e-9 of the range of the Python path (adaptive, 1e-10) on Gaussian outputs."""
    from tests.engine import bigsys

    fb = bigsys.system(3, "smooth", gaussian_inputs=True, n_rules=300)
    plan = fuzzyctl.compile(fb, backend="interpreted").plan
    nat = NativeController(plan, native.build(plan))
    py = fuzzyctl.compile(fb, backend="python")
    data = np.random.default_rng(2).uniform(-1, 1, (300, 3))
    cols = {n: data[:, i] for i, n in enumerate(py.inputs)}
    err = np.max(np.abs(nat.evaluate_batch(cols)["y"] - py.evaluate_batch(cols)["y"]))
    assert err <= 1e-9 * 2.0, err


def test_default_backend_is_native_and_a_missing_compiler_is_a_notice(
    monkeypatch: pytest.MonkeyPatch, capfd: pytest.CaptureFixture[str]
) -> None:
    monkeypatch.delenv("FUZZYCTL_BACKEND", raising=False)
    doc = fuzzyctl.load(S.EXAMPLES / "tank.fcl")
    assert isinstance(fuzzyctl.compile(doc), NativeController)
    monkeypatch.setenv("CC", "/nonexistent/cc")
    monkeypatch.setenv("FUZZYCTL_CACHE_DIR", str(Path(os.environ["FUZZYCTL_CACHE_DIR"]) / "empty"))
    monkeypatch.delenv("FUZZYCTL_QUIET", raising=False)
    monkeypatch.setattr(native, "_NOTICE_SHOWN", False)
    with warnings.catch_warnings():
        warnings.simplefilter("error")  # a notice, not a warning
        ctl = fuzzyctl.compile(doc)
        fuzzyctl.compile(doc)
    assert type(ctl) is Controller and ctl.evaluate({"error": 0.3, "rate": 0.01})
    err = capfd.readouterr().err
    assert err.count("\n") == 1 and "no C compiler" in err, err
