"""The generated Structured Text through a real IEC 61131-3 compiler: matiec (OpenPLC,
Beremiz) translates the ``--dialect iec`` text of every example and of random systems to C,
gcc compiles it with a generated driver, and each block runs 1000 inputs as successive
cycles of one instance (so DEFAULT := NC is exercised).  Outputs must match the engine:
REAL within 1e-4 of the output's range (inputs representable in REAL), LREAL within 1e-9;
INFO must say "no rule fired" exactly where the engine's outputs did not fire.

All blocks of one precision go through ONE iec2c run and ONE gcc run (iec2c spends ~1 s
reading its standard library); the agreement table is printed in the "conformance
measurements" section of the run."""

from __future__ import annotations

import dataclasses
import re
import time
from pathlib import Path

import numpy as np
import pytest
from hypothesis import HealthCheck, Phase, given, settings

import fuzzyctl
from fuzzyctl.engine.plan import Plan
from fuzzyctl.engine.reference.interp import Interpreter
from fuzzyctl.ir.programs.plc_block import build_program
from fuzzyctl.ir.render.st import render_st
from tests.codegen import matiec as M
from tests.codegen import systems as S
from tests.engine import randsys

pytestmark = pytest.mark.extra("matiec")

N = 1000
N_RANDOM = 6
TOL = {"REAL": 1e-4, "LREAL": 1e-9}


def random_systems(n: int = N_RANDOM) -> list[fuzzyctl.model.FunctionBlock]:
    """``n`` random systems from the engine's strategy, the same ones on every run: drawn in
    a fresh interpreter, since what hypothesis draws depends on what the process ran before."""
    import base64
    import pickle
    import subprocess
    import sys

    from tests.conftest import ROOT

    code = (
        "import base64, pickle; from tests.codegen.test_matiec import _draw; "
        f"print(base64.b64encode(pickle.dumps(_draw({n}))).decode())"
    )
    res = subprocess.run([sys.executable, "-c", code], cwd=ROOT, capture_output=True, text=True, timeout=300)
    assert res.returncode == 0, res.stderr[-3000:]
    drawn: list[fuzzyctl.model.FunctionBlock] = pickle.loads(
        base64.b64decode(res.stdout.strip().splitlines()[-1])
    )
    return drawn


def _draw(n: int) -> list[fuzzyctl.model.FunctionBlock]:
    drawn: list[fuzzyctl.model.FunctionBlock] = []

    @settings(
        max_examples=8 * n,
        derandomize=True,
        database=None,
        phases=[Phase.generate],
        suppress_health_check=list(HealthCheck),
    )
    @given(fb=randsys.system(ands=("MIN", "PROD", "BDIF"), weights=True))
    def draw(fb: fuzzyctl.model.FunctionBlock) -> None:
        drawn.append(fb)

    draw()
    return drawn[7::8][:n]  # the later draws are the larger ones


def systems() -> list[tuple[str, Plan]]:
    out = [(f"examples/{p.name}", S.plan_of(p)) for p in S.example_files()]
    for k, fb in enumerate(random_systems()):
        out.append((f"random/{k}", fuzzyctl.compile(fb, backend="interpreted").plan))
    return [(label, dataclasses.replace(plan, name=f"S{k}")) for k, (label, plan) in enumerate(out)]


def expected_info(plan: Plan, data: np.ndarray) -> np.ndarray:
    """16#02 where the engine fired no rule for some output, else 0 (successive cycles)."""
    interp, state = Interpreter(plan), [None] * len(plan.outputs)
    info = []
    for row in data.tolist():
        rec = interp.run(row, state)
        quiet = any(
            not o.fired for o, op in zip(rec.outputs, plan.outputs, strict=True) if op.kind != "degree"
        )
        info.append(2 if quiet else 0)
    return np.array(info)


@dataclasses.dataclass
class Compiled:
    real: str
    exe: Path
    systems: list[tuple[str, Plan]]
    seconds: float


def compile_all(matiec: Path, where: Path, systems: list[tuple[str, Plan]], real: str) -> Compiled:
    t0 = time.perf_counter()
    text = "\n".join(
        render_st(build_program(plan, "st"), dialect="iec", lreal=real == "LREAL") for _l, plan in systems
    )
    blocks = [
        M.Block(
            plan.name or "",
            tuple(i.name for i in plan.inputs),
            tuple(o.name for o in plan.outputs if o.is_output),
        )
        for _l, plan in systems
    ]
    M.iec2c(matiec, text, where)
    exe = M.compile_c(matiec, where, M.driver(blocks, real))
    return Compiled(real, exe, systems, time.perf_counter() - t0)


@pytest.fixture(scope="module")
def matiec() -> Path:
    return M.build()


@pytest.fixture(scope="module", params=list(TOL))
def compiled(
    request: pytest.FixtureRequest, matiec: Path, tmp_path_factory: pytest.TempPathFactory
) -> Compiled:
    """Every system in one precision, through one iec2c and one gcc run (a worker builds
    only the precision its tests need)."""
    real = str(request.param)
    return compile_all(matiec, tmp_path_factory.mktemp(f"matiec-{real}"), systems(), real)


def test_matiec_compiles_and_runs_what_we_generate(
    compiled: Compiled, record_property: pytest.RecordProperty
) -> None:
    c = compiled
    real = c.real
    assert len(c.systems) == len(S.example_files()) + N_RANDOM
    worst: dict[str, float] = {}
    info_bad: dict[str, int] = {}
    t0 = time.perf_counter()
    for k, (label, plan) in enumerate(c.systems):
        data = S.random_inputs(plan, N, seed=100 + k, single=real == "REAL")
        got, info = M.run_block(c.exe, k, data)
        worst[label] = S.max_error(plan, got, S.reference(plan, data))
        info_bad[label] = int(np.count_nonzero(info != expected_info(plan, data)))
    bad = {k: v for k, v in worst.items() if not v <= TOL[real]}
    assert not bad, bad
    assert not any(info_bad.values()), info_bad
    for label, err in worst.items():
        record_property("report", f"matiec {real:5} {label:32} {N} inputs  worst {err:.2e} of range")
    summary = (
        f"matiec {real:5} {len(worst)} systems x {N} inputs: worst {max(worst.values()):.2e} of range "
        f"(limit {TOL[real]:.0e}); iec2c+gcc {c.seconds:.1f} s, runs {time.perf_counter() - t0:.1f} s"
    )
    record_property("report", summary)
    print("\n" + summary)


# --------------------------------------------------------------------------- the test bench


def _bench_text(plan: Plan, n: int, lreal: bool = False) -> str:
    from fuzzyctl.codegen.testbench import choose, render_st_bench

    block = render_st(build_program(plan, "st"), dialect="iec", lreal=lreal)
    return block + "\n" + render_st_bench(choose(plan, n, single=not lreal), dialect="iec", lreal=lreal)


def _tamper_expected(text: str, vector: int) -> str:
    """Add 1 to the expected value of output 0 at ``vector`` (1-based)."""
    m = re.search(r"(TB_Y0 : ARRAY\[0\.\.\d+\] OF L?REAL := \[)([^\]]*)\]", text)
    assert m
    values = m.group(2).split(", ")
    values[vector - 1] = repr(float(values[vector - 1].strip("()")) + 1.0)
    return text[: m.start(2)] + ", ".join(values) + text[m.end(2) :]


def test_the_st_test_bench_passes_on_matiec_and_fails_on_a_wrong_block(
    matiec: Path, tmp_path: Path, record_property: pytest.RecordProperty
) -> None:
    """The generated PROGRAM through iec2c + gcc, one vector per cycle: PASS on the examples
    (heater_extension has NC and DEFAULT outputs) and a random system, in REAL and LREAL;
    FAIL with FIRST_FAIL on the vector whose expected literal was changed, and FAIL when a
    parameter of the block itself is wrong."""
    import subprocess

    n = 40
    cases: list[tuple[str, Plan, bool]] = []
    for name in ("figure7.fcl", "heater_extension.fcl", "tank.fcl"):
        cases.append((f"examples/{name}", S.plan_of(S.EXAMPLES / name), False))
    cases.append(
        ("examples/heater_extension.fcl LREAL", S.plan_of(S.EXAMPLES / "heater_extension.fcl"), True)
    )
    rnd = random_systems(2)[1]
    cases.append(("random/1", fuzzyctl.compile(rnd, backend="interpreted").plan, False))
    texts, names = [], []
    for k, (_label, plan, lreal) in enumerate(cases):
        texts.append(_bench_text(dataclasses.replace(plan, name=f"B{k}"), n, lreal))
        names.append(f"TB_B{k}")
    fig7 = S.plan_of(S.EXAMPLES / "figure7.fcl")
    k = len(cases)
    texts.append(_tamper_expected(_bench_text(dataclasses.replace(fig7, name=f"B{k}"), n), 3))
    names.append(f"TB_B{k}")
    wrong = _bench_text(dataclasses.replace(fig7, name=f"B{k + 1}"), n)
    assert "FZ_valve_S : ARRAY[0..2] OF REAL := [-100.0, 0.0, 100.0];" in wrong
    texts.append(wrong.replace("[-100.0, 0.0, 100.0]", "[-100.0, 0.0, 99.0]"))  # inlet at 99
    names.append(f"TB_B{k + 1}")
    M.iec2c(matiec, "\n".join(texts), tmp_path)
    exe = M.compile_c(matiec, tmp_path, M.bench_driver(names), "benches")
    results = []
    for j in range(len(names)):
        res = subprocess.run([str(exe), str(j)], capture_output=True, text=True, timeout=60)
        assert res.returncode == 0, res.stderr
        results.append(tuple(int(v) for v in res.stdout.split()))
    for (label, _p, _l), (passed, fails, first, cycles) in zip(cases, results, strict=False):
        assert (passed, fails, first, cycles) == (1, 0, 0, n), label
        record_property("report", f"matiec test bench {label}: PASS ({n} vectors, {cycles} cycles)")
    assert results[k][:3] == (0, 1, 3)  # the changed literal: FAIL at vector 3 only
    passed, fails, first, _c = results[k + 1]
    assert passed == 0 and fails >= 1 and first >= 1  # the wrong block fails
    record_property(
        "report", f"matiec test bench: a wrong block FAILS ({fails} of {n} vectors, first {first})"
    )


# --------------------------------------------------------------------------- names


def test_iec_dialect_refuses_every_name_of_matiecs_library(matiec: Path, tmp_path: Path) -> None:
    """matiec refuses a variable named like a function or function block of its library
    (e.g. ``integral``): the iec dialect refuses all of them, read from matiec's own files,
    and nothing else the examples use."""
    from fuzzyctl.codegen import CodegenError, generate_st
    from fuzzyctl.escape import st_ident_iec

    pous = set()
    for lib in sorted((matiec / "lib").glob("*.txt")):
        pous |= set(re.findall(r"^\s*(?:FUNCTION_BLOCK|FUNCTION)\s+(\w+)", lib.read_text(), flags=re.M))
    assert len(pous) > 900 and {"PID", "INTEGRAL", "INT_TO_REAL", "ADD_REAL"} <= pous
    for name in sorted(pous):
        with pytest.raises(CodegenError, match=r"OpenPLC's compiler|reserved word|longer than 24"):
            st_ident_iec(name, "variable")
    src = (S.EXAMPLES / "figure7.fcl").read_text()
    with pytest.raises(CodegenError, match="variable 'integral' is the name of a standard function"):
        generate_st(fuzzyctl.load(src.replace("pressure", "integral")), dialect="openplc")
    # and matiec does refuse the name (the codesys text, which does not check it)
    text = generate_st(fuzzyctl.load(src.replace("pressure", "integral")), dialect="codesys")
    with pytest.raises(AssertionError, match="iec2c failed"):
        M.iec2c(matiec, text, tmp_path)
    for path in S.example_files():  # the examples' names all pass
        generate_st(S.load(path), dialect="iec")


# --------------------------------------------------------------------------- smooth sets


@pytest.mark.parametrize("real", list(TOL))
def test_matiec_smooth_sets_under_every_operator(matiec: Path, tmp_path: Path, real: str) -> None:
    """The adaptive quadrature of smooth sets (ir/builders/quadrature.py) through matiec: every
    activation and accumulation (tests/engine/opsweep.py, smooth and PWL terms) against the
    reference interpreter, LREAL within 1e-9 of the range, REAL within 1e-4; INFO never says
    the quadrature reached its cap (16#04) on these systems."""
    from tests.engine import opsweep

    plans = []
    for k, (seed, smooth) in enumerate([(1, True), (2, False)]):
        fb = opsweep.system(seed, smooth, opsweep.some_pairs(seed))
        plan = fuzzyctl.compile(fb, backend="interpreted").plan
        plans.append((f"opsweep/{seed}", dataclasses.replace(plan, name=f"Q{k}")))
    c = compile_all(matiec, tmp_path, plans, real)
    for k, (label, plan) in enumerate(plans):
        data = S.random_inputs(plan, 20, seed=7 + k, single=real == "REAL")
        got, info = M.run_block(c.exe, k, data)
        err = S.max_error(plan, got, S.reference(plan, data))
        assert err <= TOL[real], (label, err)
        assert np.array_equal(info, expected_info(plan, data)), (label, info)
