"""The lookup-table blocks (``codegen --lookup``) through matiec: REAL and integer (int16,
int32) tables of the examples and of a seeded random system translated by iec2c, built by
gcc, and their test bench PROGRAMs run one vector per cycle: PASS, i.e. every output within
the bound the header states of the engine.  Their PLCopen XML is valid against the TC6
schema."""

from __future__ import annotations

import dataclasses
import subprocess
from pathlib import Path

import pytest

import fuzzyctl
from fuzzyctl.codegen import generate_plcopen, generate_st
from tests.codegen import matiec as M
from tests.codegen.test_lookup import _random_system
from tests.conftest import EXAMPLES

N = 60


@pytest.fixture(scope="module")
def matiec() -> Path:
    return M.build()


@pytest.mark.extra("matiec")
def test_matiec_runs_the_table_benches(matiec: Path, tmp_path: Path) -> None:
    cases = [
        ("figure7.fcl", "float", False),
        ("figure7.fcl", "int16", False),
        ("tipper.fis", "int32", False),
        ("tipper.fis", "float", True),
    ]
    texts, names = [], []
    for k, (name, arith, lreal) in enumerate(cases):
        model = fuzzyctl.load(EXAMPLES / name)
        fb = model.blocks[0]
        renamed = fuzzyctl.model.Document((dataclasses.replace(fb, name=f"L{k}"),))
        texts.append(
            generate_st(
                renamed, lookup=True, tolerance=0.01, arith=arith, lreal=lreal, dialect="iec", testbench=N
            )
        )
        names.append(f"TB_L{k}")
    k = len(cases)
    rnd = _random_system(2).replace("FUNCTION_BLOCK rnd", f"FUNCTION_BLOCK L{k}")
    texts.append(
        generate_st(
            fuzzyctl.load(rnd), lookup=True, tolerance=0.02, arith="int16", dialect="iec", testbench=N
        )
    )
    names.append(f"TB_L{k}")
    M.iec2c(matiec, "\n".join(texts), tmp_path)
    exe = M.compile_c(matiec, tmp_path, M.bench_driver(names), "benches")
    for j, label in enumerate([*cases, "random int16"]):
        res = subprocess.run([str(exe), str(j)], capture_output=True, text=True, timeout=60)
        assert res.returncode == 0, res.stderr
        assert tuple(int(v) for v in res.stdout.split()) == (1, 0, 0, N), label


@pytest.mark.extra("plcopen")
@pytest.mark.parametrize("arith", ["float", "int16", "int32"])
def test_the_table_plcopen_is_valid(arith: str) -> None:
    from tests.codegen.test_plcopen import valid

    text = generate_plcopen(fuzzyctl.load(EXAMPLES / "figure7.fcl"), lookup=True, tolerance=0.02, arith=arith)
    root = valid(text)
    assert root is not None and "TAB_valve" in text
