"""The lookup-table block as one IR program (fuzzyctl/ir/programs/table_block.py): the Python
rendering ``compile(..., backend="table")`` runs for one evaluation agrees with the numpy
interpolation of a batch (an independent implementation: tensor weights, no search) at random
points and beyond the ranges, for 1, 2 and 3 inputs; the cost per cycle the header and
``--json`` state matches closed forms of the binary search and the interpolation."""

from __future__ import annotations

import json
import math
import re

import numpy as np
import pytest

import fuzzyctl
from fuzzyctl.cli.app import main
from fuzzyctl.codegen import generate_c, generate_st
from tests.codegen.table_systems import ts_fcl
from tests.conftest import EXAMPLES

THREE = """FUNCTION_BLOCK three
VAR_INPUT a : REAL; b : REAL; c : REAL; END_VAR
VAR_OUTPUT y : REAL; z : REAL; END_VAR
FUZZIFY a RANGE := (0 .. 10); TERM lo := (0, 1) (10, 0); TERM hi := (0, 0) (10, 1); END_FUZZIFY
FUZZIFY b RANGE := (-1 .. 1); TERM lo := (-1, 1) (1, 0); TERM hi := (-1, 0) (1, 1); END_FUZZIFY
FUZZIFY c RANGE := (0 .. 4); TERM lo := (0, 1) (3, 0); TERM hi := (1, 0) (4, 1); END_FUZZIFY
DEFUZZIFY y TERM n := -5; TERM p := 7; METHOD : CoGS; DEFAULT := 0; END_DEFUZZIFY
DEFUZZIFY z TERM n := 0; TERM p := 1; METHOD : CoGS; DEFAULT := 0; END_DEFUZZIFY
RULEBLOCK r AND : PROD;
RULE 1 : IF a IS lo AND b IS hi THEN y IS n, z IS p;
RULE 2 : IF a IS hi OR c IS lo THEN y IS p;
RULE 3 : IF b IS lo AND c IS hi THEN z IS n;
RULE 4 : IF c IS hi THEN y IS n;
RULE 5 : IF a IS lo THEN z IS n;
RULE 6 : IF a IS hi THEN z IS p;
END_RULEBLOCK
END_FUNCTION_BLOCK
"""


@pytest.mark.parametrize("text", [ts_fcl(1), (EXAMPLES / "figure7.fcl").read_text(), THREE])
def test_one_evaluation_runs_the_program_and_agrees_with_the_batch(text: str) -> None:
    ctl = fuzzyctl.compile(fuzzyctl.load(text), backend="table", tolerance=0.1, max_bytes=65536)
    t = ctl.table  # type: ignore[attr-defined]
    rng = np.random.default_rng(3)
    pad = [0.2 * (a[-1] - a[0]) for a in t.axes]
    cols = {n: rng.uniform(a[0] - p, a[-1] + p, 300) for n, a, p in zip(t.inputs, t.axes, pad, strict=True)}
    # the breakpoints themselves, where the search must pick the right cell
    for i, n in enumerate(t.inputs):
        cols[n][: len(t.axes[i])] = t.axes[i][: len(cols[n])]
    batch = ctl.evaluate_batch(cols, out_of_range="ignore")
    for j in range(300):
        one = ctl.evaluate(**{n: float(c[j]) for n, c in cols.items()}, out_of_range="ignore")
        for o in t.outputs:
            assert one[o] == pytest.approx(float(batch[o][j]), abs=1e-12 * (1 + abs(one[o])))
    source = ctl._fast_fn.__closure__[0].cell_contents.__source__  # type: ignore[attr-defined]
    assert "//" in source and "FZ_BP0" in source and not re.search(r"\b(a|b|temp|valve)\b", source)


def _closed_form(shape: tuple[int, ...], outputs: int, integer: bool) -> dict[str, int]:
    """Divisions, multiplications and array reads of the table block, counted by hand: per
    input the binary search's most steps (one halving and one breakpoint read each), two
    clamps (a read in the test, one in the assignment), the fraction's three reads (REAL:
    ``(x - bp[lo]) / (bp[lo+1] - bp[lo])``; integers: the offset's one, the width's two); the
    interpolation's 2^d - 1 steps ``a + (b - a) * f`` per output, the first 2^(d-1) reading
    the table three times each."""
    d = len(shape)
    steps = [max(1, math.ceil(math.log2(n - 1))) for n in shape]
    lerps = (2**d - 1) * outputs
    return {
        "div": sum(steps) + (lerps if integer else d),
        "mul": d + lerps,
        "array_reads": sum(steps) + 7 * d + 3 * 2 ** (d - 1) * outputs,
    }


@pytest.mark.parametrize("arith", ["float", "int16"])
def test_the_stated_cost_per_cycle_matches_the_closed_form(
    arith: str, capsys: pytest.CaptureFixture[str]
) -> None:
    fig7 = str(EXAMPLES / "figure7.fcl")
    assert main(["codegen", fig7, "--lookup", "--tolerance", "2%", "--json", "--arith", arith]) == 0
    block = json.loads(capsys.readouterr().out)["blocks"][0]
    shape = tuple(block["lookup"]["breakpoints"].values())
    worst = block["cost"]["worst"]
    want = _closed_form(shape, 1, arith != "float")
    assert {k: worst[k] for k in want} == want
    st = generate_st(fuzzyctl.load(fig7), lookup=True, tolerance=0.02, arith=arith)
    assert f"cost per cycle (each binary search at its most steps): {worst['operations']} operations" in st
    c = generate_c(fuzzyctl.load(fig7), lookup=True, tolerance=0.02, arith=arith)["Fuzzy_FB.c"]
    assert f"{worst['operations']} operations" in c
