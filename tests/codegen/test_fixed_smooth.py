"""Smooth input terms in the integer block (``codegen --arith int16|int32``): chords with a
proven deviation.

The proof (interval arithmetic over each registry formula) is checked against a brute force
that shares nothing with it: the engine's degree at every stored input of a 16-bit grid (and
densely on a 32-bit one) against the chords interpolated by numpy.  The blocks are compiled
(gcc with the strict flags; matiec for the Structured Text) and run against the exact engine
within their stated bound; a block whose breakpoint degree is moved (its proof unchanged)
breaks the bound, so the check is not vacuous."""

from __future__ import annotations

import dataclasses
import json
import math
from fractions import Fraction
from pathlib import Path

import numpy as np
import pytest

import fuzzyctl
from fuzzyctl.cli.app import main
from fuzzyctl.codegen import CodegenError
from fuzzyctl.codegen.api import generate_c, generate_st
from fuzzyctl.engine.plan import TermPlan
from fuzzyctl.engine.semantics.shapes import membership_np
from fuzzyctl.ir.builders import fixed_smooth as fs
from fuzzyctl.ir.programs import fixed_block
from fuzzyctl.kinds import arith as arith_kinds
from fuzzyctl.kinds import shapes as registry
from tests.codegen.fixed_check import run_c, within_bound_or_refused
from tests.codegen.fixed_systems import smooth_fcl
from tests.conftest import EXAMPLES

SMOOTH = sorted(registry.kinds_where(lambda s: s.smooth))


def _param_sets(kind: str) -> list[tuple[float, ...]]:
    """The registry's probe (or 5, 3, ...), and the same moved and squeezed (x -> 0.37 x + 1.3):
    another width, slope and place."""
    shape = registry.get(kind)
    probe = shape.probe if isinstance(shape.probe, tuple) else (5.0, 3.0, 2.0, 7.0)[: len(shape.params)]
    base = tuple(float(p) for p in probe)
    return [base, tuple(0.37 * p + 1.3 for p in base)]


def _grid(params: tuple[float, ...], kind: str, bits: int) -> tuple[Fraction, int, int]:
    """A power-of-two scale putting the term's universe (widened by a fifth) in ``bits - 1``
    bits, and the stored range."""
    a, b = registry.get(kind).span.of(params)
    w = b - a
    lo, hi = a - w / 5, b + w / 5
    scale = Fraction(2) ** math.ceil(math.log2(max(abs(lo), abs(hi)) / (2 ** (bits - 1) - 1)))
    return scale, math.ceil(lo / scale), math.floor(hi / scale)


@pytest.mark.parametrize("kind", SMOOTH)
def test_the_proven_deviation_holds_at_every_stored_input(kind: str) -> None:
    """int16 grid: every stored value checked; int32 grid: 400 001 spread and the 7 around
    every breakpoint.  The observed deviation never exceeds the proven one, which stays
    within the tolerance asked."""
    for params in _param_sets(kind):
        for bits, tol in ((16, 1e-3), (32, 1e-5)):
            scale, low, high = _grid(params, kind, bits)
            term = TermPlan("t", kind, params, 0.8 if bits == 16 else 1.0)
            a = fs.approximate(term, "t", scale, Fraction(0), low, high, tol, loosen=False)
            assert a.deviation <= tol and a.knots[0] == low and a.knots[-1] == high
            if bits == 16:
                ks = np.arange(low, high + 1)
            else:
                near = (np.array(a.knots)[:, None] + np.arange(-3, 4)[None, :]).ravel()
                ks = np.unique(np.concatenate([np.linspace(low, high, 400_001).round(), near]))
                ks = ks[(ks >= low) & (ks <= high)].astype(np.int64)
            exact = membership_np(kind, params, term.height, ks * float(scale))
            chords = np.interp(ks, np.array(a.knots, dtype=float), np.array(a.degrees))
            observed = float(np.max(np.abs(exact - chords)))
            assert observed <= a.deviation, (kind, params, bits, observed, a.deviation)
            assert observed > a.deviation / 10  # the proof is not wildly loose either


def test_a_degree_moved_at_a_breakpoint_is_caught_by_the_proof() -> None:
    """The proof speaks of the chords given to it: moved, they are refused (a chord that
    leaves the tolerance at a stored value is split, never accepted)."""
    term = TermPlan("t", "gaussian", (5.0, 1.5))
    grid = fs._Grid(term, Fraction(1, 2048), Fraction(0))
    a = fs.approximate(term, "t", Fraction(1, 2048), Fraction(0), 0, 20480, 1e-3, loosen=False)
    degs = list(a.degrees)
    k = len(degs) // 3
    degs[k] += 0.01
    best, failed = fs._prove(grid, list(a.knots), degs, 1e-3)
    assert set(failed) <= {k - 1, k} and failed
    best, failed = fs._prove(grid, list(a.knots), list(a.degrees), 1e-3)
    assert not failed and max(best) <= 1e-3


def test_too_fine_a_tolerance_is_refused_or_loosened(monkeypatch: pytest.MonkeyPatch) -> None:
    term = TermPlan("t", "gaussian", (5.0, 1.5))
    monkeypatch.setattr(fs, "MAX_PIECES", 40)
    with pytest.raises(CodegenError, match=r"more than 40 chords.*--term-tolerance.*use --arith float"):
        fs.approximate(term, "term 't'", Fraction(1, 2048), Fraction(0), 0, 20480, 1e-4, loosen=False)
    a = fs.approximate(term, "term 't'", Fraction(1, 2048), Fraction(0), 0, 20480, 1e-4, loosen=True)
    assert len(a.knots) - 1 <= 40 and a.deviation <= a.tolerance and a.tolerance > 1e-4


@pytest.mark.parametrize("value", ["0", "-1e-3", "abc", "0.5", "nan"])
def test_a_bad_term_tolerance_names_the_option(value: str, capsys: pytest.CaptureFixture[str]) -> None:
    code = main(["codegen", "--arith", "int16", "--term-tolerance", value, str(EXAMPLES / "tipper.fis")])
    err = capsys.readouterr().err
    assert code not in (0, 3) and "--term-tolerance" in err and "Traceback" not in err


def test_a_tolerance_too_fine_for_the_chords_is_refused_naming_the_term(
    capsys: pytest.CaptureFixture[str],
) -> None:
    code = main(["codegen", "--arith", "int32", "--term-tolerance", "1e-9", str(EXAMPLES / "tipper.fis")])
    err = capsys.readouterr().err
    assert code not in (0, 3) and "Traceback" not in err
    assert "term 'poor' of input 'service'" in err and "--term-tolerance" in err and "--arith float" in err


def test_term_tolerance_applies_to_integer_arithmetic_only(capsys: pytest.CaptureFixture[str]) -> None:
    code = main(["codegen", "--term-tolerance", "1e-4", str(EXAMPLES / "tipper.fis")])
    assert code not in (0, 3) and "--arith int16 and int32" in capsys.readouterr().err


@pytest.mark.parametrize("arith", ["int16", "int32"])
def test_the_tipper_within_its_stated_bound(arith: str) -> None:
    doc = fuzzyctl.load(EXAMPLES / "tipper.fis")
    # the range's ends and the breakpoints' neighbourhoods of the service input
    edges = np.array([[0, 0], [20480, 20480], [0, 20480], [20480, 0], [10240, 10240], [1, 20479]])
    out = run_c(doc, arith, rows=20_000, seed=3, extra=edges)
    bound, observed = out.bounds(), out.errors()
    assert (observed <= bound).all(), (observed, bound)
    assert (observed > 0).all()
    terms = out.report["approximated_terms"]
    assert [t["term"] for t in terms] == ["poor", "good", "excellent"]
    assert all(
        t["deviation"] <= t["tolerance"] == fs.default_tolerance(arith_kinds.get(arith)) for t in terms
    )
    assert bound[0] <= (0.05 if arith == "int16" else 0.001) * 30  # within 5 % / 0.1 % of the tip's range


def test_a_moved_breakpoint_degree_breaks_the_stated_bound(monkeypatch: pytest.MonkeyPatch) -> None:
    """The mutant: each smooth term's chords with one breakpoint's degree moved by 0.02 but
    the proof's deviation kept; the stated bound no longer holds."""
    real = fixed_block.approximate

    def moved(*args, **kw):
        a = real(*args, **kw)
        degs = list(a.degrees)
        k = len(degs) // 3
        degs[k] = degs[k] + 0.02 if degs[k] < 0.9 else degs[k] - 0.02
        pwl = tuple((x, y) for (x, _y), y in zip(a.pwl or (), degs, strict=True))
        return dataclasses.replace(a, pwl=pwl, degrees=tuple(degs))

    monkeypatch.setattr(fixed_block, "approximate", moved)
    out = run_c(fuzzyctl.load(EXAMPLES / "tipper.fis"), "int32", rows=20_000, seed=3)
    assert (out.errors() > out.bounds()).any(), (out.errors(), out.bounds())


SEEDS = range(10)


@pytest.mark.parametrize("seed", SEEDS)
def test_random_smooth_systems_within_the_stated_bound_or_refused(seed: int) -> None:
    within_bound_or_refused(smooth_fcl(seed), rows=1500, seed=seed)


def test_most_random_smooth_systems_generate() -> None:
    from tests.codegen.fixed_check import generated_in_int32

    done = generated_in_int32([smooth_fcl(s) for s in SEEDS])
    print(f"\nint32: {done} of {len(SEEDS)} random smooth systems generate")
    assert done >= 8


def test_the_bisection_costs_log_n_comparisons() -> None:
    """A tolerance a hundred times finer takes about ten times the chords, but the worst
    path's comparisons grow by the bisection's extra depth only."""
    doc = fuzzyctl.load(EXAMPLES / "tipper.fis")
    runs = []
    for tol in (1e-3, 1e-5):
        report: list = []
        generate_c(doc, arith="int32", report=report, term_tolerance=tol)
        rep = report[0].to_dict()
        runs.append((rep["cost"]["worst"]["compare"], [t["chords"] for t in rep["approximated_terms"]]))
    (c1, n1), (c2, n2) = runs
    assert sum(n2) > 5 * sum(n1)
    depth = sum(math.ceil(math.log2(b)) - math.floor(math.log2(a)) for a, b in zip(n1, n2, strict=True))
    assert 0 < c2 - c1 <= depth
    header = generate_st(doc, arith="int32")  # the default tolerance, 1e-5: the header states c2
    assert f"{c2} compare" in header.split("cost per cycle, worst case")[1].splitlines()[0]


def test_json_reports_the_approximated_terms(capsys: pytest.CaptureFixture[str]) -> None:
    code = main(
        ["codegen", "--arith", "int16", "--term-tolerance", "2e-3", "--json", str(EXAMPLES / "tipper.fis")]
    )
    assert code in (0, None)
    rep = json.loads(capsys.readouterr().out)
    (block,) = rep["blocks"]
    terms = block["approximated_terms"]
    assert len(terms) == 3 and all(t["tolerance"] == 2e-3 and 0 < t["deviation"] <= 2e-3 for t in terms)


@pytest.mark.extra("plcopen")
@pytest.mark.parametrize("arith", ["int16", "int32"])
def test_plcopen_of_a_smooth_block_is_valid(arith: str) -> None:
    from lxml import etree

    from fuzzyctl.codegen.plcopen import generate_plcopen
    from tests.conftest import shared_path

    schema = etree.XMLSchema(etree.parse(str(shared_path("tools", "plcopen", "tc6_xml_v201.xsd"))))
    doc = fuzzyctl.load(EXAMPLES / "tipper.fis")
    root = etree.fromstring(generate_plcopen(doc, arith=arith, dialect="iec").encode())
    assert schema.validate(root), schema.error_log
    st = generate_st(doc, arith=arith, dialect="iec")
    assert "DEG_0_1" in st and b"DEG_0_1" in etree.tostring(root)


#: matiec and gcc take minutes on the thousands of chords of the default int32 tolerance
MATIEC_TOL = {"term_tolerance": 1e-4}


def _smooth_systems(arith: str) -> list[tuple[str, fuzzyctl.model.Document, dict]]:
    docs = [("tipper", fuzzyctl.load(EXAMPLES / "tipper.fis"))]
    docs += [(f"smooth {s}", fuzzyctl.load(smooth_fcl(s))) for s in range(4)]
    out = []
    for label, doc in docs:
        report: list = []
        try:
            generate_st(doc, arith=arith, dialect="iec", report=report, **MATIEC_TOL)
        except CodegenError:
            continue
        out.append((label, doc, report[0].to_dict()))
    return out


@pytest.mark.extra("matiec")
@pytest.mark.parametrize("arith", ["int16", "int32"])
def test_matiec_runs_the_smooth_blocks_within_their_bound(arith: str, tmp_path: Path) -> None:
    from tests.codegen import matiec as M

    matiec = M.build()
    systems = _smooth_systems(arith)
    assert len(systems) >= 4
    text = "\n".join(generate_st(doc, arith=arith, dialect="iec", **MATIEC_TOL) for _l, doc, _r in systems)
    M.iec2c(matiec, text, tmp_path)
    blocks = [
        M.Block(r["block"], tuple(p["name"] for p in r["inputs"]), tuple(p["name"] for p in r["outputs"]))
        for _l, _d, r in systems
    ]
    exe = M.compile_c(matiec, tmp_path, M.driver(blocks, {"int16": "IEC_INT", "int32": "IEC_DINT"}[arith]))
    for k, (label, doc, rep) in enumerate(systems):
        rng = np.random.default_rng(k)
        lo = np.array([p["stored_range"][0] for p in rep["inputs"]])
        hi = np.array([p["stored_range"][1] for p in rep["inputs"]])
        stored = np.vstack([rng.integers(lo, hi + 1, size=(1000, len(lo))), lo, hi])
        got, _flags = M.run_block(exe, k, stored.astype(np.float64))
        values = stored * np.array([p["scale"] for p in rep["inputs"]]) + np.array(
            [p["offset"] for p in rep["inputs"]]
        )
        batch = fuzzyctl.compile(doc, out_of_range="ignore").evaluate_batch(
            {p["name"]: values[:, i] for i, p in enumerate(rep["inputs"])}
        )
        for j, p in enumerate(rep["outputs"]):
            err = float(np.max(np.abs(got[:, j] * p["scale"] + p["offset"] - np.asarray(batch[p["name"]]))))
            assert err <= p["error_bound"], (label, p["name"], err, p["error_bound"])


@pytest.mark.extra("matiec")
@pytest.mark.parametrize("arith", ["int16", "int32"])
def test_the_smooth_st_test_bench_passes_on_matiec_and_fails_on_a_wrong_block(
    arith: str, tmp_path: Path
) -> None:
    import subprocess

    from tests.codegen import matiec as M

    matiec = M.build()
    tipper = (EXAMPLES / "tipper.fis").read_text()
    good = generate_st(
        fuzzyctl.load(EXAMPLES / "tipper.fis"), arith=arith, dialect="iec", testbench=60, **MATIEC_TOL
    )
    # the bench of the right block around a block whose Gaussian is a little wider
    moved = tmp_path / "moved.fis"
    moved.write_text(tipper.replace("'good':'gaussmf',[1.5 5]", "'good':'gaussmf',[1.8 5]"))
    assert moved.read_text() != tipper
    wrong_block = generate_st(fuzzyctl.load(moved), arith=arith, dialect="iec", **MATIEC_TOL)
    bench = good[good.index("(* test bench") :]
    for label, text, want in (("good", good, "1 0"), ("wrong", wrong_block + "\n" + bench, "0 ")):
        where = tmp_path / label
        where.mkdir()
        M.iec2c(matiec, text, where)
        exe = M.compile_c(matiec, where, M.bench_driver(["TB_tipper"]))
        out = subprocess.run([str(exe), "0"], capture_output=True, text=True, timeout=120).stdout
        assert out.startswith(want), (label, out)


@pytest.mark.parametrize("arith", ["int16", "int32"])
def test_the_c_test_bench_passes_and_fails_on_a_wrong_block(arith: str, tmp_path: Path) -> None:
    """gcc with the strict flags: the tipper's bench passes; around a block whose Gaussian is
    wider (the bench's expected values kept) it fails."""
    import shutil
    import subprocess

    from tests.codegen.fixed_check import STRICT

    tipper = (EXAMPLES / "tipper.fis").read_text()
    moved = tmp_path / "moved.fis"
    moved.write_text(tipper.replace("'good':'gaussmf',[1.5 5]", "'good':'gaussmf',[1.8 5]"))
    good = generate_c(fuzzyctl.load(EXAMPLES / "tipper.fis"), arith=arith, testbench=60)
    bad = dict(good, **{k: v for k, v in generate_c(fuzzyctl.load(moved), arith=arith).items()})
    cc = shutil.which("cc")
    assert cc
    for label, files, want in (("good", good, "PASS"), ("bad", bad, "FAIL")):
        where = tmp_path / label
        where.mkdir()
        for name, text in files.items():
            (where / name).write_text(text)
        sources = [str(where / n) for n in files if n.endswith(".c")]
        exe = where / "tb"
        subprocess.run([cc, *STRICT, "-DFUZZYCTL_TESTBENCH_MAIN", *sources, "-o", str(exe)], check=True)
        out = subprocess.run([str(exe)], capture_output=True, text=True).stdout
        assert out.startswith(want), (label, out)
