"""Lookup tables of Takagi-Sugeno outputs (WTAVER, WTSUM) and of Mamdani outputs under CoA,
LM, RM and MoM: the stated bound holds against the reference interpreter at random points of
seeded random systems; an output that jumps is refused, naming where, and the reference
engine confirms the jump there; a Takagi-Sugeno table builds with strict warnings, its C and
matiec test benches PASS."""

from __future__ import annotations

import dataclasses
import re
import subprocess
from pathlib import Path

import numpy as np
import pytest

import fuzzyctl
from fuzzyctl.codegen import CodegenError, generate_c, generate_st
from tests.codegen.table_systems import mamdani_fcl, ts_fcl
from tests.codegen.test_lookup import _bench, _random_system


def _check(text: str, tol: float, seed: int) -> tuple[float, float]:
    """The relative bound stated and the relative error seen at 20,000 random points."""
    model = fuzzyctl.load(text)
    ctl = fuzzyctl.compile(model, backend="table", tolerance=tol)
    ref = fuzzyctl.compile(model, backend="interpreted")
    t = ctl.table  # type: ignore[attr-defined]
    rng = np.random.default_rng(seed)
    cols = {name: rng.uniform(a[0], a[-1], 20000) for name, a in zip(t.inputs, t.axes, strict=True)}
    got, want = ctl.evaluate_batch(cols), ref.evaluate_batch(cols, out_of_range="ignore")
    seen = [float(np.abs(got[o] - want[o]).max()) for o in t.outputs]
    for k, s in enumerate(seen):
        assert s <= t.bound[k], (s, t.bound[k])
    rel = t.relative(t.bound)
    assert max(rel) <= tol
    return max(rel), max(t.relative(seen))


@pytest.mark.parametrize("seed", range(6))
def test_takagi_sugeno_tables_hold_their_bound(seed: int) -> None:
    _check(ts_fcl(seed), 0.01, seed)


@pytest.mark.parametrize("seed", range(2))
def test_coa_tables_hold_their_bound(seed: int) -> None:
    stated, seen = _check(mamdani_fcl(seed, "CoA"), 0.02, seed)
    assert seen > 0.1 * stated  # not vacuous: the table is no exact copy


def test_a_takagi_sugeno_bound_is_not_vacuous() -> None:
    stated, seen = _check(ts_fcl(5), 0.01, 0)
    assert seen > 0.3 * stated


_JUMPING = (
    _random_system(0)
    .replace(
        "TERM s0 := -50; TERM s1 := 10; TERM s2 := 80;",
        "TERM s0 := (-50, 0) (-40, 1) (-30, 0); TERM s1 := (0, 0) (10, 1) (20, 0); "
        "TERM s2 := (70, 0) (80, 1) (90, 0);",
    )
    .replace("DEFAULT := 0;", "RANGE := (-50 .. 90);\nDEFAULT := 0;")
)


@pytest.mark.parametrize("method", ["LM", "RM", "MoM", "CoA"])
def test_an_output_that_jumps_is_refused_where_it_jumps(method: str) -> None:
    text = _JUMPING.replace("METHOD : CoGS;", f"METHOD : {method};")
    with pytest.raises(CodegenError, match=r"no proven error bound within 5%.*jumps by") as info:
        generate_st(fuzzyctl.load(text), lookup=True, tolerance=0.05)
    m = re.search(r"jumps by ([0-9.e+-]+) near a = ([0-9.e+-]+), b = ([0-9.e+-]+)", str(info.value))
    assert m
    size, a, b = (float(v) for v in m.groups())
    # the reference engine jumps there too: along one input, two points 1e-6 apart that differ
    ref = fuzzyctl.compile(fuzzyctl.load(text), backend="interpreted")
    steps = []
    for da, db in ((1e-6, 0.0), (0.0, 1e-6)):
        out = ref.evaluate_batch({"a": np.array([a - da, a + da]), "b": np.array([b - db, b + db])})["y"]
        steps.append(abs(float(out[1] - out[0])))
    assert max(steps) > 0.05 * 140 and size > 0.05 * 140


def _ts_block(seed: int, name: str) -> fuzzyctl.model.Document:
    fb = fuzzyctl.load(ts_fcl(seed)).blocks[0]
    return fuzzyctl.model.Document((dataclasses.replace(fb, name=name),))


@pytest.mark.parametrize("arith", ["float", "int16", "int32"])
def test_a_takagi_sugeno_c_table_builds_strictly_and_its_bench_passes(arith: str, tmp_path: Path) -> None:
    files = generate_c(_ts_block(2, "tsk"), lookup=True, tolerance=0.01, testbench=300, arith=arith)
    assert _bench(files, tmp_path) == "PASS FAIL_COUNT=0 FIRST_FAIL=0"


@pytest.mark.extra("matiec")
def test_matiec_runs_takagi_sugeno_and_coa_table_benches(tmp_path: Path) -> None:
    from tests.codegen import matiec as M

    n = 60
    matiec = M.build()
    coa = fuzzyctl.load(mamdani_fcl(0, "CoA").replace("FUNCTION_BLOCK rnd", "FUNCTION_BLOCK M2"))
    cases = [(_ts_block(2, "M0"), "float", 0.01), (_ts_block(3, "M1"), "int16", 0.01), (coa, "int32", 0.02)]
    texts = [
        generate_st(doc, lookup=True, tolerance=tol, arith=arith, dialect="iec", testbench=n)
        for doc, arith, tol in cases
    ]
    M.iec2c(matiec, "\n".join(texts), tmp_path)
    exe = M.compile_c(matiec, tmp_path, M.bench_driver(["TB_M0", "TB_M1", "TB_M2"]), "benches")
    for j in range(len(cases)):
        res = subprocess.run([str(exe), str(j)], capture_output=True, text=True, timeout=60)
        assert res.returncode == 0, res.stderr
        assert tuple(int(v) for v in res.stdout.split()) == (1, 0, 0, n), j
