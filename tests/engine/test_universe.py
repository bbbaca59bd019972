"""The span of the terms, jFuzzyLogic's universe for an output without RANGE (issue 15.1):
closed-form values, and every jFuzzyLogic shape against the live jFuzzyLogic's ``--info``."""

from __future__ import annotations

import math
import subprocess

import pytest

import fuzzyctl
from fuzzyctl.engine.semantics import universe
from tests.extras import extra_path

# (FCL term, jFuzzyLogic's universe computed by hand from MembershipFunction*.estimateUniverse)
SHAPES = {
    "points": ("(1, 0) (3, 1) (7, 0.5)", (1.0, 7.0)),
    "trian": ("TRIAN 1 2 6", (1.0, 6.0)),
    "trape": ("TRAPE -2 0 1 5", (-2.0, 5.0)),
    "gauss": ("GAUSS 5 1.5", (5 - 6.0, 5 + 6.0)),
    "gauss2": ("GAUSS2 2 0.5 4 1", (0.0, 8.0)),
    "gbell": ("GBELL 2 3 10", (10 - 999 ** (1 / 6) * 2, 10 + 999 ** (1 / 6) * 2)),
    "sigm": ("SIGM -2 4", (4 - 4.5, 4 + 4.5)),
    "dsigm": ("DSIGM 3 1 1 6", (6 - 9.0, 6 + 9.0)),  # the hull of 1 +- 9/3 and 6 +- 9/1
    "cosine": ("COSINE 2 5", (3.0, 7.0)),
}


def _fcl() -> str:
    parts = ["FUNCTION_BLOCK u", "VAR_INPUT x : REAL; END_VAR", "VAR_OUTPUT"]
    parts += [f"  o_{k} : REAL;" for k in SHAPES]
    parts += ["END_VAR", "FUZZIFY x", "  TERM a := (0, 0) (1, 1);", "END_FUZZIFY"]
    for k, (term, _) in SHAPES.items():
        parts += [f"DEFUZZIFY o_{k}", f"  TERM t := {term};", "  TERM s := TRIAN 3 4 5;", "  METHOD : COG;",
                  "END_DEFUZZIFY"]  # fmt: skip
    parts += ["RULEBLOCK r"] + [f"  RULE {i + 1} : IF x IS a THEN o_{k} IS t;" for i, k in enumerate(SHAPES)]
    parts += ["END_RULEBLOCK", "END_FUNCTION_BLOCK"]
    return "\n".join(parts) + "\n"


def _expected(k: str) -> tuple[float, float]:
    lo, hi = SHAPES[k][1]
    return min(lo, 3.0), max(hi, 5.0)  # joined with the triangle 3..5


def test_spans_by_hand() -> None:
    plan = fuzzyctl.compile(fuzzyctl.load(_fcl()), compat="jfuzzylogic").plan
    for op in plan.outputs:
        k = op.name[2:]
        assert (op.low, op.high) == pytest.approx(_expected(k), abs=1e-12), k


def test_the_iec_profile_takes_the_span_only_when_a_term_never_falls_to_0() -> None:
    plan = fuzzyctl.compile(fuzzyctl.load(_fcl())).plan
    for op in plan.outputs:
        k = op.name[2:]
        if k in ("points", "trian", "trape", "cosine"):  # bounded: the hull of the supports
            continue
        assert (op.low, op.high) == pytest.approx(_expected(k), abs=1e-12), k
    assert universe.span_rule("gaussian") == "mean +- 4 sigma"
    assert universe.span("function", ()) == (-math.inf, math.inf)


@pytest.mark.extra("jfl_oracle")
def test_spans_are_jfuzzylogics(tmp_path) -> None:  # type: ignore[no-untyped-def]
    path = tmp_path / "u.fcl"
    path.write_text(_fcl())
    out = subprocess.run(
        [str(extra_path("jfl_oracle", "tools", "jfuzzylogic", "jfl")), str(path), "--info"],
        capture_output=True, text=True, check=True,
    ).stdout  # fmt: skip
    plan = fuzzyctl.compile(fuzzyctl.load(path), compat="jfuzzylogic").plan
    seen = 0
    for line in out.splitlines():
        if line.startswith("# var o_"):
            name = line.split()[2]
            lo, hi = (float(v) for v in line.split("universe=[")[1].split("]")[0].split(","))
            op = next(o for o in plan.outputs if o.name == name)
            assert (op.low, op.high) == (lo, hi), name  # to the last bit
            seen += 1
    assert seen == len(SHAPES)
