"""Interval type-2 function blocks (fuzzyctl.codegen.type2): C built with -Wall -Wextra
-Werror -pedantic and its test bench run (PASS; FAIL when an expected value is changed),
Structured Text in every dialect with the sample count, iteration bound and cost per cycle
in the header, the ST through matiec against the engine and its test bench PASSing, and
PLCopen XML valid against the TC6 schema."""

from __future__ import annotations

import re
import shutil
import subprocess
from pathlib import Path

import numpy as np
import pytest

import fuzzyctl
from fuzzyctl.codegen import generate_c, generate_plcopen, generate_st
from fuzzyctl.codegen.api import DIALECTS
from fuzzyctl.engine.type2 import Type2Controller
from fuzzyctl.kinds import targets
from fuzzyctl.model import Document
from tests.codegen import matiec as M
from tests.engine.type2_systems import random_it2

EXAMPLE = "examples/tipper_type2.fis"
STRICT = ["-std=c99", "-Wall", "-Wextra", "-Werror", "-pedantic"]


def _systems() -> list[tuple[str, Document]]:
    out = [("tipper", fuzzyctl.load(EXAMPLE))]
    for seed, sugeno in ((1, False), (2, True)):
        fb = random_it2(seed, sugeno=sugeno, explicit=seed == 2)
        out.append((fb.name or "", Document((fb,))))
    return out


def test_targets_say_they_generate_type2() -> None:
    assert targets.ST.type2 and targets.C.type2 and targets.PLCOPEN.type2
    assert all(d.type2 for d in targets.DIALECTS.values())
    assert not targets.FMU.type2


@pytest.mark.parametrize("dialect", DIALECTS)
def test_st_header_states_samples_bound_and_cost(dialect: str) -> None:
    text = generate_st(fuzzyctl.load(EXAMPLE), dialect=dialect, samples=51)
    assert "output tip: mamdani, sampled at 51 points, type reduction KM: at most 53 iterations" in text
    assert "cost per cycle, worst case:" in text
    assert "FUNCTION_BLOCK" in text and "ENABLE" in text


def test_json_report_has_the_cost() -> None:
    from fuzzyctl.codegen.type2 import Type2Generated

    report: list[Type2Generated] = []
    generate_st(fuzzyctl.load(EXAMPLE), report=report)  # type: ignore[arg-type]
    d = report[0].to_dict()
    assert d["cost"]["worst"]["operations"] > 0 and "sampled at 101 points" in d["notes"][0]


def _c_bench(files: dict[str, str], where: Path) -> str:
    cc = shutil.which("cc") or shutil.which("gcc")
    if cc is None:
        pytest.skip("no C compiler")
    for name, text in files.items():
        (where / name).write_text(text)
    sources = [str(where / n) for n in files if n.endswith(".c")]
    exe = where / "bench"
    res = subprocess.run(
        [cc, *STRICT, "-DFUZZYCTL_TESTBENCH_MAIN", "-o", str(exe), *sources, "-lm"],
        capture_output=True,
        text=True,
        timeout=120,
    )
    assert res.returncode == 0, res.stderr
    run = subprocess.run([str(exe)], capture_output=True, text=True, timeout=60)
    return run.stdout.strip()


@pytest.mark.parametrize("single", [False, True])
@pytest.mark.parametrize("name,doc", _systems(), ids=[s[0] for s in _systems()])
def test_c_test_bench_passes_strict(name: str, doc: Document, single: bool, tmp_path: Path) -> None:
    files = generate_c(doc, testbench=25, single=single)
    assert _c_bench(files, tmp_path).startswith("PASS FAIL_COUNT=0")


def test_c_test_bench_fails_on_a_wrong_expected_value(tmp_path: Path) -> None:
    files = generate_c(fuzzyctl.load(EXAMPLE), testbench=10)
    bench = "tipper_type2_testbench.c"
    m = re.search(r"(tipper_type2_TB_Y0\[10\] = \{)([^}]*)\}", files[bench])
    assert m
    values = m.group(2).split(", ")
    values[2] = repr(float(values[2]) + 1.0)
    files[bench] = files[bench][: m.start(2)] + ", ".join(values) + files[bench][m.end(2) :]
    assert _c_bench(files, tmp_path) == "FAIL FAIL_COUNT=1 FIRST_FAIL=3"


def test_plcopen_is_valid() -> None:
    pytest.importorskip("lxml")
    from tests.codegen.test_plcopen import valid

    for dialect in ("codesys", "iec"):
        root = valid(generate_plcopen(fuzzyctl.load(EXAMPLE), dialect=dialect))
        assert root is not None


test_plcopen_is_valid = pytest.mark.extra("plcopen")(test_plcopen_is_valid)


@pytest.mark.extra("matiec")
@pytest.mark.parametrize("lreal", [False, True])
def test_matiec_block_matches_the_engine_and_its_bench_passes(lreal: bool, tmp_path: Path) -> None:
    """The iec-dialect ST of each system through iec2c + gcc: 200 rows as successive cycles
    against ``Type2Controller(fb, samples=101)`` (REAL within 1e-4 of the range, LREAL 1e-9);
    then its test bench PROGRAM runs to PASS."""
    matiec = M.build()
    real = "LREAL" if lreal else "REAL"
    tol = 1e-9 if lreal else 1e-4
    systems = _systems()
    text = "\n".join(generate_st(doc, dialect="iec", lreal=lreal) for _n, doc in systems)
    blocks = [
        M.Block(
            doc.main.name or "",
            tuple(v.name for v in doc.main.inputs),
            tuple(d.variable for d in doc.main.defuzzify),
        )
        for _n, doc in systems
    ]
    M.iec2c(matiec, text, tmp_path)
    exe = M.compile_c(matiec, tmp_path, M.driver(blocks, real))
    rng = np.random.default_rng(3)
    for k, (_n, doc) in enumerate(systems):
        fb = doc.main
        eng = Type2Controller(fb, samples=101)
        ranges = [eng.input_ranges[v.name] for v in fb.inputs]
        data = np.array([[rng.uniform(lo, hi) for lo, hi in ranges] for _ in range(200)])
        if not lreal:
            data = data.astype(np.float32).astype(np.float64)
        outs, info = M.run_block(exe, k, data)
        for r, row in enumerate(data):
            ex = eng.explain(dict(zip([v.name for v in fb.inputs], row, strict=True)), out_of_range="ignore")
            for c, o in enumerate(ex.outputs):
                span = fb.defuzzify[c].range
                scale = span.high - span.low if span else 1.0
                assert abs(outs[r, c] - o.value) <= tol * scale, (fb.name, row, outs[r, c], o.value)
            assert info[r] == (2 if any(o.yl != o.yl for o in ex.outputs) else 0)
    benches = "\n".join(generate_st(doc, dialect="iec", lreal=lreal, testbench=20) for _n, doc in systems)
    where = tmp_path / "bench"
    where.mkdir()
    M.iec2c(matiec, benches, where)
    names = [f"TB_{doc.main.name}" for _n, doc in systems]
    exe = M.compile_c(matiec, where, M.bench_driver(names), "benches")
    for j in range(len(names)):
        res = subprocess.run([str(exe), str(j)], capture_output=True, text=True, timeout=60)
        assert res.returncode == 0, res.stderr
        passed, fails, first, _cycles = (int(v) for v in res.stdout.split())
        assert (passed, fails, first) == (1, 0, 0), names[j]
