"""The integer Structured Text (``--arith int16|int32 --dialect iec``) through matiec, the
IEC 61131-3 compiler of OpenPLC and Beremiz: the examples and seeded random systems are
translated to C in one iec2c run per width, compiled with gcc and run on stored inputs over
the whole stored range (and beyond it); each output must stay within the ``error_bound`` the
generator states against the engine."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

import fuzzyctl
from fuzzyctl.codegen import CodegenError
from fuzzyctl.codegen.api import generate_st
from tests.codegen import matiec as M
from tests.codegen.fixed_systems import mamdani_variant, random_fcl, random_mamdani_fcl
from tests.conftest import EXAMPLES

pytestmark = pytest.mark.extra("matiec")

N = 1000
#: matiec's C names of the integer types
C_TYPE = {"int16": "IEC_INT", "int32": "IEC_DINT"}


def _systems(arith: str) -> list[tuple[str, fuzzyctl.model.Document, dict]]:
    docs = [(p.name, fuzzyctl.load(p)) for p in (EXAMPLES / "crane.fcl", EXAMPLES / "figure7.fcl")]
    for seed in range(16):
        docs.append((f"random {seed}", fuzzyctl.load(random_fcl(seed).replace("rnd", f"rnd{seed}"))))
    # Mamdani outputs (CoG of piecewise-linear sets)
    for p in (EXAMPLES / "crane.fcl", EXAMPLES / "figure7.fcl"):
        docs.append((f"{p.name} mamdani", fuzzyctl.load(mamdani_variant(p.read_text()))))
    for seed in (1, 3, 4):
        docs.append(
            (f"mamdani {seed}", fuzzyctl.load(random_mamdani_fcl(seed).replace("rnd", f"rndm{seed}")))
        )
    out = []
    for label, doc in docs:
        report: list = []
        try:
            generate_st(doc, arith=arith, dialect="iec", report=report)
        except CodegenError:
            continue
        out.append((label, doc, report[0].to_dict()))
    return out


@pytest.mark.parametrize("arith", ["int16", "int32"])
def test_matiec_runs_the_integer_blocks_within_their_bound(arith: str, tmp_path: Path) -> None:
    matiec = M.build()
    systems = _systems(arith)
    assert len(systems) >= 8
    text = "\n".join(generate_st(doc, arith=arith, dialect="iec") for _l, doc, _r in systems)
    M.iec2c(matiec, text, tmp_path)
    blocks = [
        M.Block(r["block"], tuple(p["name"] for p in r["inputs"]), tuple(p["name"] for p in r["outputs"]))
        for _l, _d, r in systems
    ]
    exe = M.compile_c(matiec, tmp_path, M.driver(blocks, C_TYPE[arith]))
    info = np.iinfo(np.int16 if arith == "int16" else np.int32)
    worst = {}
    for k, (label, doc, rep) in enumerate(systems):
        rng = np.random.default_rng(k)
        lo = np.array([p["stored_range"][0] for p in rep["inputs"]])
        hi = np.array([p["stored_range"][1] for p in rep["inputs"]])
        stored = rng.integers(lo, hi + 1, size=(N, len(lo)))
        stored[:50] = rng.integers(info.min, int(info.max) + 1, size=(50, len(lo)))  # limited by the block
        got, flags = M.run_block(exe, k, stored.astype(np.float64))
        assert not flags.any(), label  # every input fires a rule (that is what the bound proves)
        scale = np.array([p["scale"] for p in rep["inputs"]])
        offset = np.array([p["offset"] for p in rep["inputs"]])
        values = np.clip(stored, lo, hi) * scale + offset
        batch = fuzzyctl.compile(doc, out_of_range="ignore").evaluate_batch(
            {p["name"]: values[:, i] for i, p in enumerate(rep["inputs"])}
        )
        for j, p in enumerate(rep["outputs"]):
            err = float(np.max(np.abs(got[:, j] * p["scale"] + p["offset"] - np.asarray(batch[p["name"]]))))
            assert err <= p["error_bound"], (label, p["name"], err, p["error_bound"])
            worst[f"{label}/{p['name']}"] = (err, p["error_bound"])
    print(f"\nmatiec {arith}: " + "; ".join(f"{k} {e:.2g} <= {b:.2g}" for k, (e, b) in worst.items()))


@pytest.mark.parametrize("arith", ["int16", "int32"])
def test_the_integer_st_test_bench_passes_on_matiec_and_fails_on_a_wrong_block(
    arith: str, tmp_path: Path
) -> None:
    import subprocess

    matiec = M.build()
    crane = (EXAMPLES / "crane.fcl").read_text()
    good = generate_st(fuzzyctl.load(crane), arith=arith, dialect="iec", testbench=60)
    # the same bench (expected values of the right block) around a block with a moved singleton
    wrong_block = generate_st(
        fuzzyctl.load(crane.replace("pos_high := 100", "pos_high := 98")), arith=arith, dialect="iec"
    )
    bench = good[good.index("(* test bench") :]
    for label, text, want in (("good", good, "1 0"), ("wrong", wrong_block + "\n" + bench, "0 ")):
        where = tmp_path / label
        where.mkdir()
        M.iec2c(matiec, text, where)
        exe = M.compile_c(matiec, where, M.bench_driver(["TB_crane"]))
        out = subprocess.run([str(exe), "0"], capture_output=True, text=True, timeout=60).stdout
        assert out.startswith(want), (label, out)
