"""The generated test bench (``codegen --testbench N``): the C bench compiled strictly with
the system compiler prints PASS on the generated block and FAIL (with FIRST_FAIL) when an
expected value or the block is wrong; the vectors cover every rule, the range ends and the
no-rule-fired cases.  The ST bench runs on matiec in tests/codegen/test_matiec.py."""

from __future__ import annotations

import re
import shutil
import subprocess
from pathlib import Path

import pytest

from fuzzyctl.cli.app import main
from fuzzyctl.codegen import CodegenError, generate_c, generate_st
from fuzzyctl.codegen.testbench import choose
from fuzzyctl.engine.reference.interp import Interpreter
from tests.codegen import systems as S

STRICT = ["-std=c99", "-Wall", "-Wextra", "-Werror", "-pedantic"]


def _run_bench(files: dict[str, str], where: Path) -> str:
    cc = shutil.which("cc")
    assert cc, "the C tests need the system compiler 'cc'"
    for name, text in files.items():
        (where / name).write_text(text)
    sources = [str(where / n) for n in files if n.endswith(".c")]
    exe = where / "bench"
    res = subprocess.run(
        [cc, *STRICT, "-DFUZZYCTL_TESTBENCH_MAIN", "-o", str(exe), *sources, "-lm"],
        capture_output=True,
        text=True,
    )
    assert res.returncode == 0, res.stderr[:3000]
    run = subprocess.run([str(exe)], capture_output=True, text=True, timeout=60)
    return run.stdout.strip() + f" rc={run.returncode}"


@pytest.mark.parametrize("name", ["figure7.fcl", "heater_extension.fcl", "tank.fcl"])
@pytest.mark.parametrize("single", [False, True])
def test_c_bench_passes_on_the_generated_block(name: str, single: bool, tmp_path: Path) -> None:
    files = generate_c(S.load(S.EXAMPLES / name), testbench=30, single=single)
    assert any(n.endswith("_testbench.c") for n in files)
    assert _run_bench(files, tmp_path) == "PASS FAIL_COUNT=0 FIRST_FAIL=0 rc=0"


def test_c_bench_fails_on_a_wrong_expected_value_or_block(tmp_path: Path) -> None:
    files = generate_c(S.load(S.EXAMPLES / "figure7.fcl"), testbench=30)
    bench = files["Fuzzy_FB_testbench.c"]
    m = re.search(r"(Fuzzy_FB_TB_Y0\[30\] = \{)([^}]*)\}", bench)
    assert m
    vals = m.group(2).split(", ")
    vals[4] = repr(float(vals[4]) + 0.5)  # vector 5 off by 0.5 (tolerance 0.01)
    tampered = dict(
        files, **{"Fuzzy_FB_testbench.c": bench[: m.start(2)] + ", ".join(vals) + bench[m.end(2) :]}
    )
    (tmp_path / "a").mkdir()
    assert _run_bench(tampered, tmp_path / "a") == "FAIL FAIL_COUNT=1 FIRST_FAIL=5 rc=1"
    # the block itself wrong: the inlet singleton at 99 instead of 100
    src = files["Fuzzy_FB.c"]
    assert "100.0" in src
    wrong = dict(files, **{"Fuzzy_FB.c": src.replace("100.0", "99.0")})
    (tmp_path / "b").mkdir()
    out = _run_bench(wrong, tmp_path / "b")
    assert out.startswith("FAIL FAIL_COUNT=") and out.endswith("rc=1"), out


def test_vectors_cover_every_rule_the_ends_and_no_rule_fired() -> None:
    plan = S.plan_of(S.EXAMPLES / "heater_extension.fcl")
    bench = choose(plan, 40, single=True)
    assert len(bench.rows) == 40 and bench.covered_rules == len(plan.rules)
    interp = Interpreter(plan)
    fresh = [interp.run(row, [None] * len(plan.outputs)) for row in bench.rows]
    for r, rule in enumerate(plan.rules):  # the vector named for a rule fires it
        k = bench.why.index(f"rule {rule.label} fires strongest")
        assert fresh[k].rule_degrees[r] > 0
    assert any("no rule fires, keeps its last value (NC)" in w for w in bench.why)
    assert any("no rule fires, takes its DEFAULT" in w for w in bench.why)
    assert 2 in bench.info and 0 in bench.info
    assert any(w.endswith("at the high end") for w in bench.why)
    for row in bench.rows:  # REAL inputs: exactly representable
        import numpy as np

        assert all(float(np.float32(v)) == v for v in row)


def test_st_bench_states_its_tolerance_and_refuses_scl() -> None:
    text = generate_st(S.load(S.EXAMPLES / "figure7.fcl"), testbench=12)
    assert "PROGRAM TB_Fuzzy_FB" in text and "END_PROGRAM" in text
    assert "(* tolerance: |output - expected| <= 0.0001 x the output's range (arithmetic in REAL)" in text
    assert "(* output valve: tolerance 0.01 *)" in text
    for word in ("PASS : BOOL", "FAIL_COUNT : INT", "FIRST_FAIL : INT"):
        assert word in text
    lreal = generate_st(S.load(S.EXAMPLES / "figure7.fcl"), testbench=12, lreal=True)
    assert "<= 1e-09 x the output's range (arithmetic in LREAL)" in lreal
    with pytest.raises(CodegenError, match=r"test bench.*not scl"):
        generate_st(S.load(S.EXAMPLES / "figure7.fcl"), testbench=12, dialect="scl")


def test_cli_writes_the_c_bench(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    fig7 = str(S.EXAMPLES / "figure7.fcl")
    assert main(["codegen", fig7, "--lang", "c", "--testbench", "8", "-o", str(tmp_path)]) == 0
    assert (tmp_path / "Fuzzy_FB_testbench.c").exists()
    capsys.readouterr()
    assert main(["codegen", fig7, "--dialect", "openplc", "--testbench", "5"]) == 0
    out = capsys.readouterr().out
    assert "(* dialect: iec;" in out and "PROGRAM TB_Fuzzy_FB" in out
