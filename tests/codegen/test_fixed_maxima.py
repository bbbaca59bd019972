"""``codegen --arith int16|int32`` on Mamdani outputs under LM, RM and MoM: the integer C
block (``cc -std=c99 -Wall -Wextra -Werror -pedantic``) and the integer ST through matiec
against the engine's exact piecewise-linear maxima.

Two stated bounds are checked: ``error_bound`` (the worst case over every input, which
includes the jump of the maximum where two sets' heights tie) everywhere, and
``error_bound_away_from_ties`` at the inputs where the exact heights of the activated sets,
computed here from the reference interpreter's rule degrees (:mod:`tests.codegen.maxima_check`,
not from the generator), leave one set alone at the top by more than ``tie_margin``.  A
brute-force maximum of the accumulated set sampled on a fine grid checks the engine itself;
a block with a mutated level-set end breaks the away-from-ties bound."""

from __future__ import annotations

import json
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
from fuzzyctl.ir.programs import fixed_maxima
from tests.codegen.fixed_check import STRICT, Outcome, run_c
from tests.codegen.fixed_systems import mamdani_variant, random_mamdani_fcl
from tests.codegen.maxima_check import Heights, with_method
from tests.conftest import EXAMPLES

METHODS = ("LM", "RM", "MoM")


def _example(name: str, method: str) -> fuzzyctl.model.Document:
    return fuzzyctl.load(with_method(mamdani_variant((EXAMPLES / name).read_text()), method))


def _away_rows(doc: fuzzyctl.model.Document, out: Outcome) -> np.ndarray:
    """Which rows of ``out`` are away from ties by the stated margin (exact heights)."""
    h = Heights(doc)
    (port,) = out.report["outputs"]
    names = [p["name"] for p in out.report["inputs"]]
    return np.array([h.away(v, port["tie_margin"]) for v in h.slots(names, out.values_in)])


def _check(doc: fuzzyctl.model.Document, arith: str, rows: int, seed: int = 0) -> tuple[float, float, float]:
    """Both bounds hold; ``(observed, observed away from ties, share of rows away)``."""
    out = run_c(doc, arith, rows=rows, seed=seed)
    (port,) = out.report["outputs"]
    err = np.abs(out.got - out.exact)[:, 0]
    assert err.max() <= port["error_bound"], (arith, err.max(), port["error_bound"])
    away = _away_rows(doc, out)
    assert port["error_bound_away_from_ties"] <= port["error_bound"]
    if away.any():
        worst = err[away].max()
        assert worst <= port["error_bound_away_from_ties"], (arith, worst, port["error_bound_away_from_ties"])
    return float(err.max()), float(err[away].max()) if away.any() else 0.0, float(away.mean())


@pytest.mark.parametrize("arith", ["int16", "int32"])
@pytest.mark.parametrize("method", METHODS)
@pytest.mark.parametrize("name", ["crane.fcl", "figure7.fcl"])
def test_examples_within_both_stated_bounds(name: str, method: str, arith: str) -> None:
    doc = _example(name, method)
    observed, observed_away, share = _check(doc, arith, rows=4000)
    print(
        f"\n{name} {method} {arith}: observed {observed:.3g}, away from ties {observed_away:.3g} "
        f"({share:.0%})"
    )
    assert share > 0.5  # most inputs are away from ties: the second check is not vacuous


SEEDS = range(8)


@pytest.mark.parametrize("method", METHODS)
@pytest.mark.parametrize("seed", SEEDS)
def test_random_systems_within_both_stated_bounds_or_refused(seed: int, method: str) -> None:
    doc = fuzzyctl.load(random_mamdani_fcl(seed, method))
    for arith in ("int16", "int32"):
        try:
            _check(doc, arith, rows=600, seed=seed)
        except CodegenError as exc:
            assert "(use --arith float" in str(exc)
            assert re.match(r"output 'out': ", str(exc)), str(exc)


def test_most_random_systems_under_max_generate() -> None:
    done = 0
    for seed in SEEDS:
        text = random_mamdani_fcl(seed, "LM").replace("ACCU : SUM;", "ACCU : MAX;")
        try:
            generate_c(fuzzyctl.load(text), arith="int32")
            done += 1
        except CodegenError:
            pass
    assert done >= 6, done


@pytest.mark.parametrize("method", METHODS)
def test_the_engine_agrees_with_a_brute_force_maximum(method: str) -> None:
    """The exact engine's maximum against the accumulated set sampled on a fine grid (rule
    degrees from the reference interpreter), where no two sets tie: within two grid steps."""
    for doc in (_example("figure7.fcl", method), fuzzyctl.load(random_mamdani_fcl(2, method))):
        h = Heights(doc)
        step = (h.op.high - h.op.low) / (len(h.xs) - 1)
        rng = np.random.default_rng(1)
        ctl = fuzzyctl.compile(doc)
        names = [i.name for i in h.plan.inputs]
        checked = 0
        for _ in range(150):
            row = [
                rng.uniform(*ctl.input_ranges[n]) if hasattr(ctl, "input_ranges") else rng.uniform(-5, 5)
                for n in names
            ]
            v = h.slots(names, np.array([row]))[0]
            if not h.away(v, 1e-3):
                continue
            exact = ctl.evaluate(dict(zip(names, row, strict=True)))[h.op.name]
            assert abs(exact - h.brute(v, method)) <= 2 * step, (row, exact, h.brute(v, method))
            checked += 1
        assert checked > 50


def test_a_mutated_level_set_end_breaks_the_bound(monkeypatch: pytest.MonkeyPatch) -> None:
    """LM taking the level set's right end (the wrong edge of a clipped plateau) is caught by
    the away-from-ties check."""
    doc = _example("crane.fcl", "LM")
    _check(doc, "int16", rows=400)
    real = fixed_maxima.profiles
    monkeypatch.setattr(fixed_maxima, "profiles", lambda edges: (real(edges)[1], real(edges)[1]))
    with pytest.raises(AssertionError):
        _check(doc, "int16", rows=400)


def test_a_known_maximum() -> None:
    """One rule at degree 1/2 on the trapezoid (2, 0) (3, 1) (5, 1) (6, 0): the clipped edges
    cross 1/2 at 2.5 and 5.5 (closed form), so LM 2.5, RM 5.5, MoM 4."""
    base = """FUNCTION_BLOCK k
VAR_INPUT x : REAL; END_VAR
VAR_OUTPUT y : REAL; END_VAR
FUZZIFY x RANGE := (0 .. 1); TERM half := (0, 0.5) (1, 0.5); END_FUZZIFY
DEFUZZIFY y RANGE := (0 .. 10); TERM t := (2, 0) (3, 1) (5, 1) (6, 0); METHOD : LM; END_DEFUZZIFY
RULEBLOCK r AND : MIN; RULE 1 : IF x IS half THEN y IS t; END_RULEBLOCK
END_FUNCTION_BLOCK
"""
    for method, want in (("LM", 2.5), ("RM", 5.5), ("MoM", 4.0)):
        for arith in ("int16", "int32"):
            out = run_c(fuzzyctl.load(with_method(base, method)), arith, rows=20)
            assert abs(out.got - want).max() <= out.report["outputs"][0]["error_bound_away_from_ties"]


TWO = """FUNCTION_BLOCK m
VAR_INPUT x : REAL; END_VAR
VAR_OUTPUT y : REAL; END_VAR
FUZZIFY x TERM a := (0, 1) (1, 0); TERM b := (0, 0) (1, 1); END_FUZZIFY
DEFUZZIFY y TERM lo := (0, 0) (1, 1) (2, 0); TERM hi := (1, 0) (2, 1) (3, 0); METHOD : LM; END_DEFUZZIFY
RULEBLOCK r AND : MIN; RULE 1 : IF x IS a THEN y IS lo; RULE 2 : IF x IS b THEN y IS hi; END_RULEBLOCK
END_FUNCTION_BLOCK
"""


@pytest.mark.parametrize(
    ("text", "message"),
    [
        (TWO.replace("AND : MIN;", "AND : MIN; ACCU : SUM;"), r"output 'y': ACCU SUM of overlapping sets"),
        (
            TWO.replace("LM", "MoM").replace(
                "(1, 0) (2, 1) (3, 0)", "(1, 0) (1.5, 1) (2, 0) (2.5, 1) (3, 0)"
            ),
            r"output 'y': term 'hi' has two separate humps",
        ),
        (
            TWO.replace("(0, 1) (1, 0)", "(0, 1) (0.4, 0)")
            .replace("(0, 0) (1, 1)", "(0.6, 0) (1, 1)")
            .replace("METHOD : LM;", "METHOD : LM; DEFAULT := NaN;"),
            r"output 'y': its DEFAULT is NaN and no rule may fire",
        ),
    ],
)
def test_what_is_not_computed_is_refused_naming_it(text: str, message: str) -> None:
    for gen in (generate_st, generate_c):
        with pytest.raises(CodegenError, match=message + r".*--arith float"):
            gen(fuzzyctl.load(text), arith="int16")


def test_sum_of_apart_sets_and_prod_activation() -> None:
    """ACCU SUM where the sets never overlap (the sum is their maximum) and PROD activation
    under MAX: within both bounds."""
    apart = TWO.replace("(1, 0) (2, 1) (3, 0)", "(2, 0) (3, 1) (4, 0)")
    for extra in ("ACCU : SUM;", "ACT : PROD;", "ACCU : SUM; ACT : PROD;"):
        for method in METHODS:
            doc = fuzzyctl.load(with_method(apart.replace("AND : MIN;", f"AND : MIN; {extra}"), method))
            for arith in ("int16", "int32"):
                _check(doc, arith, rows=300)


def test_json_header_and_int_output(capsys: pytest.CaptureFixture[str], tmp_path: Path) -> None:
    from fuzzyctl.cli.app import main

    path = tmp_path / "crane_lm.fcl"
    path.write_text(with_method(mamdani_variant((EXAMPLES / "crane.fcl").read_text()), "MoM"))
    got = {}
    for choice in ("unit", "scaled"):
        assert (
            main(["codegen", str(path), "--arith", "int16", "--int-output", choice, "--json", "--lang", "st"])
            == 0
        )
        (port,) = json.loads(capsys.readouterr().out)["blocks"][0]["outputs"]
        got[choice] = port
    assert got["unit"]["scale"] == 1.0 and got["scaled"]["scale"] < 1.0
    assert got["scaled"]["error_bound_away_from_ties"] < got["unit"]["error_bound_away_from_ties"]
    for port in got.values():
        assert 0 < port["tie_margin"] < 0.01 and port["error_bound_away_from_ties"] < port["error_bound"]
    st = generate_st(fuzzyctl.load(path.read_text()), arith="int16", dialect="iec")
    assert "away from ties" in st and "cost per cycle" in st
    body = re.sub(r"\(\*.*?\*\)", "", st, flags=re.S)
    assert "REAL" not in body


@pytest.mark.parametrize("arith", ["int16", "int32"])
def test_c_test_bench_passes_and_fails_on_a_wrong_block(arith: str, tmp_path: Path) -> None:
    cc = shutil.which("cc")
    assert cc
    text = with_method(mamdani_variant((EXAMPLES / "crane.fcl").read_text()), "LM")
    for label, block_text, want in (
        ("good", text, "PASS FAIL_COUNT=0"),
        (
            "wrong",
            re.sub(r"\(-?[\d.]+, 1\)", lambda m: m.group(0).replace(", 1)", ", 0.6)"), text, count=1),
            "FAIL",
        ),
    ):
        where = tmp_path / label
        where.mkdir()
        good = generate_c(fuzzyctl.load(text), arith=arith, testbench=60)
        block = generate_c(fuzzyctl.load(block_text), arith=arith)
        files = {**good, **{k: v for k, v in block.items() if not k.endswith("_testbench.c")}}
        for name, body in files.items():
            (where / name).write_text(body)
        exe = where / "tb"
        sources = [str(where / n) for n in files if n.endswith(".c")]
        subprocess.run([cc, *STRICT, "-DFUZZYCTL_TESTBENCH_MAIN", "-o", str(exe), *sources], check=True)
        out = subprocess.run([str(exe)], capture_output=True, text=True).stdout
        assert out.startswith(want), (label, out)


@pytest.mark.extra("plcopen")
@pytest.mark.parametrize("method", METHODS)
def test_plcopen_is_valid(method: str) -> None:
    from lxml import etree

    from tests.conftest import shared_path

    schema = etree.XMLSchema(etree.parse(str(shared_path("tools", "plcopen", "tc6_xml_v201.xsd"))))
    for arith in ("int16", "int32"):
        root = etree.fromstring(
            generate_plcopen(_example("figure7.fcl", method), arith=arith, dialect="iec").encode()
        )
        assert schema.validate(root), schema.error_log


@pytest.mark.extra("matiec")
@pytest.mark.parametrize("arith", ["int16", "int32"])
def test_matiec_runs_the_blocks_within_their_bound_and_the_st_bench_passes(
    arith: str, tmp_path: Path
) -> None:
    """The ``--dialect iec`` ST of the LM / RM / MoM variants through matiec and gcc: within
    the stated worst case everywhere and the away-from-ties bound away from ties; the ST
    test bench of one of them passes."""
    from tests.codegen import matiec as M

    matiec = M.build()
    docs = []
    for name in ("crane.fcl", "figure7.fcl"):
        for method in METHODS:
            text = with_method(mamdani_variant((EXAMPLES / name).read_text()), method)
            text = re.sub(r"FUNCTION_BLOCK (\w+)", rf"FUNCTION_BLOCK \1_{method}", text, count=1)
            docs.append(fuzzyctl.load(text))
    for seed, method in ((2, "MoM"), (4, "LM"), (7, "RM")):
        docs.append(fuzzyctl.load(random_mamdani_fcl(seed, method).replace("rnd", f"rndx{seed}")))
    reports = []
    for doc in docs:
        rep: list = []
        generate_st(doc, arith=arith, dialect="iec", report=rep)
        reports.append(rep[0].to_dict())
    bench = generate_st(docs[0], arith=arith, dialect="iec", testbench=60)
    text = bench + "\n" + "\n".join(generate_st(doc, arith=arith, dialect="iec") for doc in docs[1:])
    M.iec2c(matiec, text, tmp_path)
    blocks = [
        M.Block(r["block"], tuple(p["name"] for p in r["inputs"]), tuple(p["name"] for p in r["outputs"]))
        for r in reports
    ]
    exe = M.compile_c(matiec, tmp_path, M.driver(blocks, {"int16": "IEC_INT", "int32": "IEC_DINT"}[arith]))
    for k, (doc, rep) in enumerate(zip(docs, reports, strict=True)):
        rng = np.random.default_rng(k)
        lo = np.array([p["stored_range"][0] for p in rep["inputs"]])
        hi = np.array([p["stored_range"][1] for p in rep["inputs"]])
        stored = rng.integers(lo, hi + 1, size=(600, len(lo)))
        got, _info = M.run_block(exe, k, stored.astype(np.float64))
        values = stored * np.array([p["scale"] for p in rep["inputs"]]) + np.array(
            [p["offset"] for p in rep["inputs"]]
        )
        (port,) = rep["outputs"]
        exact = np.asarray(
            fuzzyctl.compile(doc).evaluate_batch(
                {p["name"]: values[:, i] for i, p in enumerate(rep["inputs"])}
            )[port["name"]]
        )
        err = np.abs(got[:, 0] * port["scale"] + port["offset"] - exact)
        assert err.max() <= port["error_bound"], (rep["block"], err.max())
        h = Heights(doc)
        away = np.array(
            [h.away(v, port["tie_margin"]) for v in h.slots([p["name"] for p in rep["inputs"]], values)]
        )
        assert away.any() and err[away].max() <= port["error_bound_away_from_ties"], (
            rep["block"],
            err[away].max(),
        )
    where = tmp_path / "bench"
    where.mkdir()
    M.iec2c(matiec, bench, where)
    tb = M.compile_c(matiec, where, M.bench_driver([f"TB_{reports[0]['block']}"[:24].rstrip("_")]))
    out = subprocess.run([str(tb), "0"], capture_output=True, text=True, timeout=60).stdout
    assert out.startswith("1 0"), out
