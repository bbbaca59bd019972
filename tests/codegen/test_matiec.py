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
import time
from pathlib import Path

import numpy as np
import pytest
from hypothesis import HealthCheck, Phase, given, settings

import fuzzyctl
from fuzzyctl.codegen.program import build_program
from fuzzyctl.codegen.render_st import render_st
from fuzzyctl.engine.interp import Interpreter
from fuzzyctl.engine.plan import Plan
from tests.codegen import matiec as M
from tests.codegen import systems as S
from tests.engine import randsys

pytestmark = pytest.mark.extra("matiec")

N = 1000
N_RANDOM = 6
TOL = {"REAL": 1e-4, "LREAL": 1e-9}


def random_systems(n: int = N_RANDOM) -> list[fuzzyctl.model.FunctionBlock]:
    """``n`` random systems from the engine's strategy, the same ones on every run."""
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
        quiet = any(not o.fired for o, op in zip(rec.outputs, plan.outputs, strict=True) if op.kind != "degree")
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
        M.Block(plan.name or "", tuple(i.name for i in plan.inputs), tuple(o.name for o in plan.outputs if o.is_output))
        for _l, plan in systems
    ]
    M.iec2c(matiec, text, where)
    exe = M.compile_c(matiec, where, M.driver(blocks, real))
    return Compiled(real, exe, systems, time.perf_counter() - t0)


@pytest.fixture(scope="module")
def matiec() -> Path:
    return M.build()


@pytest.fixture(scope="module", params=list(TOL))
def compiled(request: pytest.FixtureRequest, matiec: Path, tmp_path_factory: pytest.TempPathFactory) -> Compiled:
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
