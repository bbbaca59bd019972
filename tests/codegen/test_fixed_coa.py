"""``codegen --arith int16|int32`` on Mamdani outputs by METHOD COA (the bisector of the
accumulated set): the integer C block against the engine's exact centre of area.

Each block is compiled with ``cc -std=c99 -Wall -Wextra -Werror -pedantic`` and run on random
stored inputs over (and beyond) its stored range; the observed error must stay within the
``error_bound`` the generator derived (the areas' rounding and the width of the band where the
area is within it of half, :mod:`fuzzyctl.ir.programs.fixed_coa`).  Closed forms check the
convention (a triangle's bisector, a gap's middle); mutants of the half-area search break
the bound."""

from __future__ import annotations

import json
import math
import re
import shutil
import subprocess
from pathlib import Path

import numpy as np
import pytest

import fuzzyctl
from fuzzyctl.codegen import CodegenError
from fuzzyctl.codegen.api import generate_c, generate_st
from fuzzyctl.codegen.plcopen import generate_plcopen
from fuzzyctl.ir.nodes import Int
from fuzzyctl.ir.programs import fixed_coa
from tests.codegen.fixed_check import STRICT, generated_in_int32, run_c, within_bound_or_refused
from tests.codegen.fixed_systems import mamdani_variant, random_mamdani_fcl
from tests.conftest import EXAMPLES

RANGE = 300.0  # the Mamdani variants' output RANGE (-150 .. 150)


def coa_variant(name: str) -> str:
    """The Mamdani form of an example (singletons turned into triangles) with METHOD COA."""
    text = mamdani_variant((EXAMPLES / name).read_text())
    out, n = re.subn(r"METHOD\s*:\s*CoG;", "METHOD : CoA;", text, flags=re.I)
    assert n == 1
    return out


#: two overlapping triangles, one rule each: the accumulated set has no gap
SMOOTH = """FUNCTION_BLOCK s
VAR_INPUT x : REAL; END_VAR
VAR_OUTPUT y : REAL; END_VAR
FUZZIFY x RANGE := (0 .. 1); TERM a := (0, 1) (1, 0); TERM b := (0, 0) (1, 1); END_FUZZIFY
DEFUZZIFY y RANGE := (0 .. 3); TERM lo := (0, 0) (1, 1) (2, 0); TERM hi := (1, 0) (2, 1) (3, 0);
METHOD : COA; END_DEFUZZIFY
RULEBLOCK r AND : MIN; RULE 1 : IF x IS a THEN y IS lo; RULE 2 : IF x IS b THEN y IS hi; END_RULEBLOCK
END_FUNCTION_BLOCK
"""


@pytest.mark.parametrize("arith", ["int16", "int32"])
@pytest.mark.parametrize("name", ["crane.fcl", "figure7.fcl"])
def test_coa_examples_within_the_stated_bound(name: str, arith: str) -> None:
    out = run_c(coa_variant(name), arith, rows=5000)
    bound, observed = out.bounds(), out.errors()
    print(
        f"\n{name} COA {arith}: stated {100 * bound[0] / RANGE:.3g} %, "
        f"observed {100 * observed[0] / RANGE:.3g} %"
    )
    assert (observed <= bound).all(), (observed, bound)
    assert (bound <= float(fixed_coa.USEFUL) * RANGE).all(), bound
    assert (observed > 0).all()  # not bit-exact: the comparison is not vacuous


@pytest.mark.parametrize("extra", ["", "ACCU : SUM;", "ACCU : SUM; ACT : PROD;"])
@pytest.mark.parametrize("arith", ["int16", "int32"])
def test_a_set_without_gaps_gets_a_tight_bound(extra: str, arith: str) -> None:
    """Where the set has no gap, the bound is a small fraction of the range (0.5 %), and the
    engine stays within it, also at both ends of the input's range (only one set fires)."""
    doc = fuzzyctl.load(SMOOTH.replace("AND : MIN;", f"AND : MIN; {extra}"))
    out = run_c(doc, arith, rows=1500)
    assert (out.errors() <= out.bounds()).all(), (out.errors(), out.bounds())
    assert out.bounds()[0] <= 0.005 * 3


SEEDS = range(12)


@pytest.mark.parametrize("seed", SEEDS)
def test_random_coa_systems_within_the_stated_bound_or_refused(seed: int) -> None:
    within_bound_or_refused(random_mamdani_fcl(seed, method="COA"), rows=600, seed=seed)


def test_some_random_coa_systems_generate() -> None:
    done = generated_in_int32([random_mamdani_fcl(seed, method="COA") for seed in SEEDS])
    assert done >= 3, done


def _one_rule(term: str, lo: float = 0.0, hi: float = 10.0) -> str:
    return f"""FUNCTION_BLOCK k
VAR_INPUT x : REAL; END_VAR
VAR_OUTPUT y : REAL; END_VAR
FUZZIFY x RANGE := (0 .. 1); TERM all := (0, 1) (1, 1); END_FUZZIFY
DEFUZZIFY y RANGE := ({lo} .. {hi}); TERM t := {term}; METHOD : COA; END_DEFUZZIFY
RULEBLOCK r AND : MIN; RULE 1 : IF x IS all THEN y IS t; END_RULEBLOCK
END_FUNCTION_BLOCK
"""


def test_known_bisectors() -> None:
    """Closed forms, independent of the engine: a symmetric triangle's bisector is its peak;
    the triangle (0, 0) (1, 1) (3, 0) of area 3/2 has 3/4 right of 3 - sqrt(3) (where the
    area right of x is (3 - x)^2 / 4)."""
    for term, want in (("(2, 0) (3.5, 1) (5, 0)", 3.5), ("(0, 0) (1, 1) (3, 0)", 3.0 - math.sqrt(3.0))):
        for arith in ("int16", "int32"):
            out = run_c(_one_rule(term), arith, rows=50)
            assert abs(out.got - want).max() <= out.bounds()[0]
            assert out.bounds()[0] < 0.01 * 10


GAP = """FUNCTION_BLOCK g
VAR_INPUT x : REAL; END_VAR
VAR_OUTPUT y : REAL; END_VAR
FUZZIFY x RANGE := (0 .. 1); TERM a := (0, 1) (1, 0); TERM b := (0, 0) (1, 1); END_FUZZIFY
DEFUZZIFY y RANGE := (0 .. 20); TERM lo := (0, 0) (1, 1) (2, 0); TERM hi := (3, 0) (4, 1) (5, 0);
TERM far := (15, 0) (16, 1) (20, 1); METHOD : COA; END_DEFUZZIFY
RULEBLOCK r AND : MIN; RULE 1 : IF x IS a THEN y IS lo; RULE 2 : IF x IS b THEN y IS hi; END_RULEBLOCK
END_FUNCTION_BLOCK
"""


def test_a_gap_is_covered_by_the_bound() -> None:
    """Two triangles with a gap of 1 between them (2 .. 3): at x = 1/2 both fire equally and
    the bisector is the gap's middle, 2.5 (the engine's convention); beside it the bisector
    jumps to the gap's ends, so the stated bound holds at least half the gap."""
    for arith in ("int16", "int32"):
        out = run_c(GAP, arith, rows=800, extra=np.array([[0]]))
        bound = out.bounds()[0]
        assert bound >= 0.5
        assert (out.errors() <= out.bounds()).all()
        half = out.report["inputs"][0]
        stored = round((0.5 - half["offset"]) / half["scale"])
        near = run_c(GAP, arith, rows=1, extra=np.arange(stored - 3, stored + 4)[:, None])
        assert abs(near.exact[-4, 0] - 2.5) < 1e-9  # the engine's middle of the gap
        assert (near.errors() <= near.bounds()).all()


def test_a_wide_gap_is_refused_naming_it() -> None:
    text = GAP.replace("TERM hi := (3, 0) (4, 1) (5, 0);", "TERM hi := (13, 0) (14, 1) (15, 0);")
    for gen in (generate_st, generate_c):
        with pytest.raises(
            CodegenError, match=r"output 'y': METHOD COA: the bisector can move by up to .*--arith float"
        ):
            gen(fuzzyctl.load(text), arith="int32")


# --------------------------------------------------------------------------- mutants


def _third(blk, cells, cum_stmts, v):  # type: ignore[no-untyped-def]
    """The search for a third of the area instead of half (3 C >= A)."""
    b = blk.b
    for cell, (_var, ex) in zip(cells, cum_stmts, strict=True):
        b.set(v["prev"], v["cum"])
        b.set(v["cum"], ex)
        with b.if_(v["found"].eq(Int(0)).and_(v["cum"].ge(v["area"] - v["cum"] - v["cum"]))):
            b.set(v["found"], Int(1))
            b.set(v["xa"], Int(math.floor(cell.a)))
            b.set(v["xw"], Int(math.ceil(cell.b) - math.floor(cell.a)))
            b.set(v["num"], v["area"] - v["prev"] - v["prev"])
            b.set(v["den"], v["cum"] - v["prev"])


def _next_cell(blk, cells, cum_stmts, v):  # type: ignore[no-untyped-def]
    """The right half-area target, but the point placed one cell to the right."""
    b = blk.b
    for cell, (_var, ex) in zip(cells, cum_stmts, strict=True):
        b.set(v["prev"], v["cum"])
        b.set(v["cum"], ex)
        with b.if_(v["found"].eq(Int(0)).and_(v["cum"].ge(v["area"] - v["cum"]))):
            b.set(v["found"], Int(1))
            b.set(v["xa"], Int(math.ceil(cell.b)))
            b.set(v["xw"], Int(math.ceil(cell.b) - math.floor(cell.a)))
            b.set(v["num"], v["area"] - v["prev"] - v["prev"])
            b.set(v["den"], v["cum"] - v["prev"])


@pytest.mark.parametrize("mutant", [_third, _next_cell])
def test_a_wrong_half_area_search_breaks_the_bound(mutant: object, monkeypatch: pytest.MonkeyPatch) -> None:
    doc = fuzzyctl.load(SMOOTH)
    assert (run_c(doc, "int32", rows=300).errors() <= run_c(doc, "int32", rows=300).bounds()).all()
    monkeypatch.setattr(fixed_coa, "_found", mutant)
    out = run_c(doc, "int32", rows=300)
    assert (out.errors() > out.bounds()).any()


# --------------------------------------------------------------------------- the forms


def test_json_and_int_output(capsys: pytest.CaptureFixture[str], tmp_path: Path) -> None:
    """``--json`` reports the CoA output's type, scale, offset and error bound; ``--int-output
    unit`` stores it in its own unit (a coarser bound)."""
    from fuzzyctl.cli.app import main

    src = tmp_path / "crane.fcl"
    src.write_text(coa_variant("crane.fcl"))
    got = {}
    for choice in ("unit", "scaled"):
        args = ["codegen", str(src), "--arith", "int16", "--int-output", choice, "--json", "--lang", "st"]
        assert main(args) == 0
        (y,) = json.loads(capsys.readouterr().out)["blocks"][0]["outputs"]
        assert y["error_bound"] <= float(fixed_coa.USEFUL) * RANGE
        assert y["type"] == "INT" and set(y) >= {"scale", "offset", "error_bound", "stored_range"}
        got[choice] = (y["scale"], y["error_bound"])
    assert got["unit"][0] == 1.0 and got["scaled"][0] < 1.0
    assert got["scaled"][1] < got["unit"][1]
    st = generate_st(fuzzyctl.load(SMOOTH), arith="int32")
    assert "worst-case error against the exact engine" in st and "cost per cycle, worst case:" in st
    assert "REAL" not in re.sub(r"\(\*.*?\*\)", "", st, flags=re.S)


@pytest.mark.parametrize("dialect", ["codesys", "twincat", "scl", "iec", "openplc"])
def test_every_dialect_renders_the_coa_block_in_integers(dialect: str) -> None:
    for arith, wide in (("int16", "DINT"), ("int32", "LINT")):
        st = generate_st(fuzzyctl.load(SMOOTH), arith=arith, dialect=dialect)
        body = re.sub(r"\(\*.*?\*\)|//[^\n]*", "", st, flags=re.S)
        assert "REAL" not in body and f": {wide};" in body and "FOUND_" in body


@pytest.mark.extra("plcopen")
@pytest.mark.parametrize("arith", ["int16", "int32"])
def test_plcopen_of_a_coa_block_is_valid(arith: str) -> None:
    from lxml import etree

    from tests.conftest import shared_path

    schema = etree.XMLSchema(etree.parse(str(shared_path("tools", "plcopen", "tc6_xml_v201.xsd"))))
    root = etree.fromstring(
        generate_plcopen(fuzzyctl.load(coa_variant("figure7.fcl")), arith=arith, dialect="iec").encode()
    )
    assert schema.validate(root), schema.error_log


def _bench(files: dict[str, str], where: Path) -> str:
    for name, text in files.items():
        (where / name).write_text(text)
    cc = shutil.which("cc")
    assert cc
    exe = where / "tb"
    sources = [str(where / n) for n in files if n.endswith(".c")]
    subprocess.run([cc, *STRICT, "-DFUZZYCTL_TESTBENCH_MAIN", "-o", str(exe), *sources], check=True)
    return subprocess.run([str(exe)], capture_output=True, text=True).stdout


@pytest.mark.parametrize("arith", ["int16", "int32"])
def test_c_test_bench_passes_and_fails_on_a_wrong_block(arith: str, tmp_path: Path) -> None:
    for label, text in (("crane", coa_variant("crane.fcl")), ("smooth", SMOOTH)):
        (tmp_path / label).mkdir()
        out = _bench(generate_c(fuzzyctl.load(text), arith=arith, testbench=60), tmp_path / label)
        assert out.startswith("PASS FAIL_COUNT=0"), (label, out)
    # the bench of the right block around a block whose upper term moved by 0.3
    good = generate_c(fuzzyctl.load(SMOOTH), arith=arith, testbench=60)
    wrong = generate_c(
        fuzzyctl.load(SMOOTH.replace("(1, 0) (2, 1) (3, 0)", "(1.3, 0) (2.3, 1) (3, 0)")), arith=arith
    )
    (tmp_path / "wrong").mkdir()
    out = _bench({**good, **wrong}, tmp_path / "wrong")
    assert out.startswith("FAIL"), out


# --------------------------------------------------------------------------- matiec


def _matiec_systems(arith: str) -> list[tuple[str, fuzzyctl.model.Document, dict]]:
    docs = [(n, fuzzyctl.load(coa_variant(n))) for n in ("crane.fcl", "figure7.fcl")]
    docs += [("smooth", fuzzyctl.load(SMOOTH)), ("gap", fuzzyctl.load(GAP))]
    for seed in SEEDS:
        docs.append(
            (f"coa {seed}", fuzzyctl.load(random_mamdani_fcl(seed, "COA").replace("rnd", f"rndc{seed}")))
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


@pytest.mark.extra("matiec")
@pytest.mark.parametrize("arith", ["int16", "int32"])
def test_matiec_runs_the_coa_blocks_within_their_bound(arith: str, tmp_path: Path) -> None:
    from tests.codegen import matiec as M

    matiec = M.build()
    systems = _matiec_systems(arith)
    assert len(systems) >= 6
    text = "\n".join(generate_st(doc, arith=arith, dialect="iec") for _l, doc, _r in systems)
    M.iec2c(matiec, text, tmp_path)
    blocks = [
        M.Block(r["block"], tuple(p["name"] for p in r["inputs"]), tuple(p["name"] for p in r["outputs"]))
        for _l, _d, r in systems
    ]
    exe = M.compile_c(matiec, tmp_path, M.driver(blocks, {"int16": "IEC_INT", "int32": "IEC_DINT"}[arith]))
    info = np.iinfo(np.int16 if arith == "int16" else np.int32)
    worst = {}
    for k, (label, doc, rep) in enumerate(systems):
        rng = np.random.default_rng(k)
        lo = np.array([p["stored_range"][0] for p in rep["inputs"]])
        hi = np.array([p["stored_range"][1] for p in rep["inputs"]])
        stored = rng.integers(lo, hi + 1, size=(800, len(lo)))
        stored[:40] = rng.integers(info.min, int(info.max) + 1, size=(40, len(lo)))  # limited by the block
        stored = np.vstack([stored, lo[None, :], hi[None, :]])
        got, flags = M.run_block(exe, k, stored.astype(np.float64))
        assert not flags.any(), label
        scale = np.array([p["scale"] for p in rep["inputs"]])
        offset = np.array([p["offset"] for p in rep["inputs"]])
        values = np.clip(stored, lo, hi) * scale + offset
        batch = fuzzyctl.compile(doc, out_of_range="ignore").evaluate_batch(
            {p["name"]: values[:, i] for i, p in enumerate(rep["inputs"])}
        )
        for j, p in enumerate(rep["outputs"]):
            err = float(np.max(np.abs(got[:, j] * p["scale"] + p["offset"] - np.asarray(batch[p["name"]]))))
            assert err <= p["error_bound"], (label, p["name"], err, p["error_bound"])
            worst[label] = (err, p["error_bound"])
    print(f"\nmatiec COA {arith}: " + "; ".join(f"{k} {e:.2g} <= {b:.2g}" for k, (e, b) in worst.items()))


@pytest.mark.extra("matiec")
@pytest.mark.parametrize("arith", ["int16", "int32"])
def test_the_st_test_bench_of_a_coa_block_passes_on_matiec_and_fails_on_a_wrong_block(
    arith: str, tmp_path: Path
) -> None:
    from tests.codegen import matiec as M

    matiec = M.build()
    good = generate_st(fuzzyctl.load(SMOOTH), arith=arith, dialect="iec", testbench=60)
    moved = SMOOTH.replace("(1, 0) (2, 1) (3, 0)", "(1.3, 0) (2.3, 1) (3, 0)")
    wrong_block = generate_st(fuzzyctl.load(moved), arith=arith, dialect="iec")
    bench = good[good.index("(* test bench") :]
    for label, text, want in (("good", good, "1 0"), ("wrong", wrong_block + "\n" + bench, "0 ")):
        where = tmp_path / label
        where.mkdir()
        M.iec2c(matiec, text, where)
        exe = M.compile_c(matiec, where, M.bench_driver(["TB_s_FB"]))
        out = subprocess.run([str(exe), "0"], capture_output=True, text=True, timeout=60).stdout
        assert out.startswith(want), (label, out)
