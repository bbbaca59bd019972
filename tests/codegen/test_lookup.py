"""``codegen --lookup`` and ``compile(backend="table")``: the stated error bound holds
against the engine (the reference for every number here) at random points, on the examples
and on seeded random systems; the C forms build with strict warnings and their test benches
PASS (and FAIL on a wrong table); the CLI options are checked."""

from __future__ import annotations

import random
import re
import shutil
import subprocess
from pathlib import Path

import numpy as np
import pytest

import fuzzyctl
from fuzzyctl.cli.app import main
from fuzzyctl.codegen import CodegenError, generate_c, generate_st
from tests.conftest import EXAMPLES

STRICT = ["-std=c99", "-Wall", "-Wextra", "-Werror", "-pedantic"]


def _observed(
    ctl: fuzzyctl.engine.Controller, ref: fuzzyctl.engine.Controller, n: int, seed: int
) -> list[float]:
    rng = np.random.default_rng(seed)
    t = ctl.table  # type: ignore[attr-defined]
    cols = {name: rng.uniform(a[0], a[-1], n) for name, a in zip(t.inputs, t.axes, strict=True)}
    got, want = ctl.evaluate_batch(cols), ref.evaluate_batch(cols, out_of_range="ignore")
    return [float(np.abs(got[o] - want[o]).max()) for o in t.outputs]


@pytest.mark.parametrize("name", ["figure7.fcl", "tipper.fis"])
def test_the_stated_bound_holds_at_random_points_of_the_examples(name: str) -> None:
    model = fuzzyctl.load(EXAMPLES / name)
    ctl = fuzzyctl.compile(model, backend="table", tolerance=0.01)
    ref = fuzzyctl.compile(model, backend="interpreted")
    t = ctl.table  # type: ignore[attr-defined]
    assert max(t.relative(t.bound)) <= 0.01
    seen = _observed(ctl, ref, 20000, 1)
    for k, s in enumerate(seen):
        assert s <= t.bound[k]
        assert s > 0.2 * t.bound[k]  # the bound is not vacuous
    # at the breakpoints the table is the engine (rounded to REAL at most)
    grid = np.meshgrid(*t.axes, indexing="ij")
    at = ctl.evaluate_batch({n: g.ravel() for n, g in zip(t.inputs, grid, strict=True)})
    exact = ref.evaluate_batch({n: g.ravel() for n, g in zip(t.inputs, grid, strict=True)})
    for o in t.outputs:
        assert np.allclose(at[o], exact[o], atol=1e-9)


def _random_system(seed: int) -> str:
    """A random 2-input singleton system (triangles covering each input, MIN/PROD AND)."""
    rng = random.Random(seed)

    def terms(lo: float, hi: float, n: int) -> str:
        xs = sorted(rng.uniform(lo, hi) for _ in range(n - 2))
        pts = [lo, *xs, hi]
        out = []
        for i, c in enumerate(pts):
            left = f"({pts[i - 1]:.3f}, 0) " if i else ""
            right = f" ({pts[i + 1]:.3f}, 0)" if i + 1 < len(pts) else ""
            out.append(f"TERM t{i} := {left}({c:.3f}, 1){right};")
        return "\n".join(out)

    n1, n2 = rng.randint(2, 4), rng.randint(2, 4)
    rules = []
    for i in range(n1):
        for j in range(n2):
            rules.append(f"RULE r{i}_{j} : IF a IS t{i} AND b IS t{j} THEN y IS s{rng.randint(0, 2)};")
    op = rng.choice(["MIN", "PROD"])
    return f"""FUNCTION_BLOCK rnd
VAR_INPUT a : REAL; b : REAL; END_VAR
VAR_OUTPUT y : REAL; END_VAR
FUZZIFY a
{terms(0.0, 10.0, n1)}
END_FUZZIFY
FUZZIFY b
{terms(-5.0, 5.0, n2)}
END_FUZZIFY
DEFUZZIFY y
TERM s0 := -50; TERM s1 := 10; TERM s2 := 80;
METHOD : CoGS;
DEFAULT := 0;
END_DEFUZZIFY
RULEBLOCK rb
AND : {op};
{chr(10).join(rules)}
END_RULEBLOCK
END_FUNCTION_BLOCK
"""


@pytest.mark.parametrize("seed", range(4))
def test_the_stated_bound_holds_on_seeded_random_systems(seed: int) -> None:
    model = fuzzyctl.load(_random_system(seed))
    ctl = fuzzyctl.compile(model, backend="table", tolerance=0.02)
    ref = fuzzyctl.compile(model, backend="interpreted")
    t = ctl.table  # type: ignore[attr-defined]
    for k, s in enumerate(_observed(ctl, ref, 20000, seed)):
        assert s <= t.bound[k] <= 0.02 * 130


def test_a_size_limit_too_small_is_refused_with_the_tolerance_it_allows() -> None:
    with pytest.raises(CodegenError, match=r"needs more than 2000 bytes .*is within [0-9.]+ [(][0-9.]+%[)]"):
        generate_st(fuzzyctl.load(EXAMPLES / "figure7.fcl"), lookup=True, tolerance=0.001, max_bytes=2000)


def test_a_tolerance_missed_by_a_hair_prints_two_different_numbers(
    capsys: pytest.CaptureFixture[str],
) -> None:
    """The bound the size limit allows, asked for a hair below it: the refusal's two
    percentages differ as text (not "5.21% ... 5.21%") and read in the right order."""
    from fuzzyctl.api import compile_plan
    from fuzzyctl.engine.table import build_table

    fig7 = EXAMPLES / "figure7.fcl"
    # (codegen --lookup stores REAL: the table of that type)
    t = build_table(compile_plan(fuzzyctl.load(fig7)), tolerance=0.06, max_bytes=64, real="REAL")
    worst = max(t.relative(t.bound))
    for tolerance in (worst * (1 - 1e-9), np.nextafter(worst, 0.0)):
        args = ["codegen", str(fig7), "--lookup", "--max-bytes", "64", "--tolerance", repr(float(tolerance))]
        assert main(args) == 1
        err = " ".join(capsys.readouterr().err.split())
        m = re.search(r"a table within ([0-9.e+-]+)% .* is within ([0-9.e+-]+) [(]([0-9.e+-]+)%[)]", err)
        assert m is not None, err
        limit, bound = m.group(1), m.group(3)
        assert limit != bound and float(limit) < float(bound), err
        assert float(m.group(2)) == pytest.approx(worst, rel=1e-3)


@pytest.mark.parametrize("seed", range(3))
def test_apart_tells_numbers_apart_with_the_fewest_digits(seed: int) -> None:
    from fuzzyctl.diagnostics import apart

    rng = random.Random(seed)
    for _ in range(2000):
        a = rng.uniform(-1e3, 1e3) * 10.0 ** rng.randint(-8, 8)
        near = a * (1 + rng.choice([1e-2, 1e-6, 1e-12]))
        b = float(np.nextafter(a, np.inf)) if rng.random() < 0.3 else near
        sa, sb = apart(a, b)
        assert sa != sb and (float(sa) < float(sb)) == (a < b)
        n = len(re.sub(r"e.*|[-.]", "", sa).lstrip("0"))  # significant digits written
        if n > 3:  # one digit fewer would not tell them apart
            assert f"{a:.{n - 1}g}" == f"{b:.{n - 1}g}"
        assert apart(a, a) == (f"{a:.3g}", f"{a:.3g}")


def test_a_system_without_a_derived_bound_is_refused_with_the_reason() -> None:
    text = (
        _random_system(0)
        .replace("METHOD : CoGS;", "METHOD : LM;")
        .replace(
            "TERM s0 := -50; TERM s1 := 10; TERM s2 := 80;",
            "TERM s0 := (-50, 0) (-40, 1) (-30, 0); TERM s1 := (0, 0) (10, 1) (20, 0); "
            "TERM s2 := (70, 0) (80, 1) (90, 0);",
        )
        .replace("DEFAULT := 0;", "RANGE := (-50 .. 90);\nDEFAULT := 0;")
    )
    with pytest.raises(CodegenError, match=r"no proven error bound .*LM"):
        generate_st(fuzzyctl.load(text), lookup=True, tolerance=0.05)


def _bench(files: dict[str, str], where: Path) -> str:
    cc = shutil.which("cc")
    assert cc, "the C tests need the system compiler 'cc'"
    where.mkdir(exist_ok=True)
    for name, text in files.items():
        (where / name).write_text(text)
    exe = where / "bench"
    sources = [str(where / n) for n in files if n.endswith(".c")]
    res = subprocess.run(
        [cc, *STRICT, "-DFUZZYCTL_TESTBENCH_MAIN", "-o", str(exe), *sources], capture_output=True, text=True
    )
    assert res.returncode == 0, res.stderr[:3000]
    run = subprocess.run([str(exe)], capture_output=True, text=True, timeout=60)
    return run.stdout.strip()


@pytest.mark.parametrize(
    ("arith", "single"), [("float", False), ("float", True), ("int16", False), ("int32", False)]
)
def test_the_c_table_builds_strictly_and_its_bench_passes(arith: str, single: bool, tmp_path: Path) -> None:
    files = generate_c(
        fuzzyctl.load(EXAMPLES / "tipper.fis"),
        lookup=True,
        tolerance=0.01,
        testbench=300,
        arith=arith,
        single=single,
    )
    head = files["tipper.c"]
    assert re.search(r"maximum error against the engine: tip [0-9.]+ \(0\.\d+% of 0 \.\. 30\)", head)
    assert re.search(r"table size: \d+ bytes", head)
    if arith != "float":
        assert "double" not in head and "float" not in head.replace("floating", "")
    assert _bench(files, tmp_path / "ok") == "PASS FAIL_COUNT=0 FIRST_FAIL=0"
    # a wrong table entry in the middle of the surface fails the bench
    m = re.search(r"(tipper_TAB0\[\d+\] = \{)([^}]*)\}", head)
    assert m
    vals = m.group(2).split(", ")
    mid = len(vals) // 2
    bump = str(int(vals[mid]) + 3000) if arith != "float" else repr(float(vals[mid].strip("()")) + 5.0)
    vals = [bump if abs(i - mid) <= 30 else v for i, v in enumerate(vals)]
    wrong = dict(files, **{"tipper.c": head[: m.start(2)] + ", ".join(vals) + head[m.end(2) :]})
    assert _bench(wrong, tmp_path / "bad").startswith("FAIL")


def test_cli_options(capsys: pytest.CaptureFixture[str], tmp_path: Path) -> None:
    fig7 = str(EXAMPLES / "figure7.fcl")
    assert main(["codegen", fig7, "--tolerance", "1%"]) == 2
    assert "--lookup" in capsys.readouterr().err
    assert main(["codegen", fig7, "--lookup", "--tolerance", "150%"]) == 2
    assert "--tolerance" in capsys.readouterr().err
    assert main(["codegen", fig7, "--lookup", "--lang", "fmu"]) == 2
    assert main(["codegen", fig7, "--lookup", "--tolerance", "1%", "--json", "--arith", "int16"]) == 0
    import json

    report = json.loads(capsys.readouterr().out)
    block = report["blocks"][0]
    assert block["lookup"]["bytes"] > 0
    out = block["outputs"]["valve"]
    assert out["observed"] <= out["error_bound"] <= 2.0 and out["scale"] > 0
    assert "REAL" not in report["text"].split("FUNCTION_BLOCK", 1)[1]


def test_a_table_never_exceeds_max_bytes_even_when_the_tolerance_is_met() -> None:
    """The coarsest crane table (axis ends and kinks) meets a loose tolerance but is larger
    than a tiny size limit: refused naming the limit, never built over it."""
    crane = EXAMPLES / "crane.fcl"
    coarse = fuzzyctl.compile(crane, backend="table", tolerance=0.5).table  # type: ignore[attr-defined]
    size = coarse.size_bytes("LREAL")
    from fuzzyctl.engine.table import TableError

    with pytest.raises(
        TableError, match=rf"smallest table, .* in {size} bytes, is larger than --max-bytes {size - 1}"
    ):
        fuzzyctl.compile(crane, backend="table", tolerance=0.5, max_bytes=size - 1)
    assert (
        fuzzyctl.compile(crane, backend="table", tolerance=0.5, max_bytes=size).table.size_bytes("LREAL")
        <= size
    )  # type: ignore[attr-defined]
