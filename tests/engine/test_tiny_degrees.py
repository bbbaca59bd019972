"""Subnormal firing degrees: every path integrates them as the closed form says.

Areas and moments are products of degrees, widths and positions; at degrees of a few ulps of
the smallest subnormal they kept a few bits or underflowed, and the paths split (1.0, 0.5
against the true 0.75 on fuzzylite's SimpleDimmer at Ambient = 5e-324).  The expected values
below are closed forms of the sets in the limit of a vanishing degree."""

from __future__ import annotations

import warnings

import numpy as np
import pytest

import fuzzyctl
from fuzzyctl.engine.reference import pwl
from tests.fuzz import differential as D

TINY = 5e-324  # the smallest subnormal: DARK fires at 4 ulps of it, DIM at 2

FCL = """
FUNCTION_BLOCK tiny
VAR_INPUT x : REAL; END_VAR
VAR_OUTPUT y : REAL; END_VAR
FUZZIFY x
    TERM dark := TRIAN 0 0.25 0.5;
    TERM dim := TRIAN 0 0.5 1;
END_FUZZIFY
DEFUZZIFY y
    RANGE(0..10);
    TERM low := TRIAN 0 1 4;
    TERM high := TRIAN 6 7 8;
    METHOD : COG;
    DEFAULT := 0;
END_DEFUZZIFY
RULEBLOCK rb
    AND : MIN;
    ACT : {act};
    ACCU : MAX;
    RULE 1 : IF x IS dark THEN y IS low;
    RULE 2 : IF x IS dim THEN y IS high;
END_RULEBLOCK
END_FUNCTION_BLOCK
"""

# MIN: each set is its support's rectangle in the limit, heights 4u and 2u:
#   (4 * 4 * 2 + 2 * 2 * 7) / (4 * 4 + 2 * 2) = 60 / 20 = 3.0
# PROD: the triangles scaled by 4u and 2u (areas 2 and 1, centroids 5/3 and 7):
#   (4 * 2 * 5/3 + 2 * 1 * 7) / (4 * 2 + 2 * 1) = (82/3) / 10
EXPECTED = {"MIN": 3.0, "PROD": 82.0 / 30.0}


def _doc(act: str) -> fuzzyctl.Document:
    return fuzzyctl.load(FCL.replace("{act}", act))


@pytest.mark.parametrize("act", sorted(EXPECTED))
@pytest.mark.parametrize("backend", ["interpreted", "python", "native"])
def test_subnormal_degrees_give_the_closed_form(act: str, backend: str) -> None:
    want = EXPECTED[act]
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        ctl = fuzzyctl.compile(_doc(act), backend=backend)
        got = ctl.evaluate({"x": TINY})["y"]
        batch = ctl.evaluate_batch({"x": np.array([TINY, 0.1])})["y"]
    assert got == pytest.approx(want, abs=1e-12)
    assert batch[0] == pytest.approx(want, abs=1e-12)


@pytest.mark.parametrize("act", sorted(EXPECTED))
def test_generated_c_agrees_at_subnormal_degrees(act: str) -> None:
    plan = fuzzyctl.compile(_doc(act), backend="interpreted").plan
    got = D.run_c(plan, [[TINY], [0.1]])
    if got is None:
        pytest.skip("no C compiler")
    assert got[0][0][0] == pytest.approx(EXPECTED[act], abs=1e-12)


def test_the_scale_is_a_power_of_two_and_leaves_normal_degrees() -> None:
    assert pwl.tiny_degree_scale(0.0) == 1.0
    assert pwl.tiny_degree_scale(2.0**-124) == 1.0
    assert pwl.tiny_degree_scale(0.3) == 1.0
    for top in (5e-324, 1e-310, 2.0**-125, 3e-200):
        scaled = top * pwl.tiny_degree_scale(top)
        assert 2.0**-124 <= scaled < 2.0**-60
        assert scaled / pwl.tiny_degree_scale(top) == top  # exact


SINGLETONS = """
FUNCTION_BLOCK s
VAR_INPUT x : REAL; END_VAR
VAR_OUTPUT y : REAL; END_VAR
FUZZIFY x
    TERM dark := TRIAN 0 0.25 0.5;
    TERM dim := TRIAN 0 0.5 1;
END_FUZZIFY
DEFUZZIFY y
    RANGE(0..1);
    TERM a := 0.3;
    TERM b := 0.9;
    METHOD : {method};
    DEFAULT := 0;
END_DEFUZZIFY
RULEBLOCK rb
    AND : MIN;
    ACT : MIN;
    ACCU : MAX;
    RULE 1 : IF x IS dark THEN y IS a;
{rule2}END_RULEBLOCK
END_FUNCTION_BLOCK
"""


@pytest.mark.parametrize("method", ["COGS", "COG"])
@pytest.mark.parametrize("both", [False, True])
def test_singletons_at_subnormal_degrees(method: str, both: bool) -> None:
    # weights 4u (a = 0.3) and 2u (b = 0.9): 0.3 alone (0.25 before: 0.3 * 4u rounds to 1u),
    # (4 * 0.3 + 2 * 0.9) / 6 = 0.5 together
    rule2 = "    RULE 2 : IF x IS dim THEN y IS b;\n" if both else ""
    doc = fuzzyctl.load(SINGLETONS.replace("{method}", method).replace("{rule2}", rule2))
    want = 0.5 if both else 0.3
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        for backend in ("interpreted", "python", "native"):
            ctl = fuzzyctl.compile(doc, backend=backend)
            assert ctl.evaluate({"x": TINY})["y"] == pytest.approx(want, abs=1e-12), backend
            assert ctl.evaluate_batch({"x": np.array([TINY])})["y"][0] == pytest.approx(want, abs=1e-12)
        got = D.run_c(fuzzyctl.compile(doc, backend="interpreted").plan, [[TINY]])
    if got is not None:
        assert got[0][0][0] == pytest.approx(want, abs=1e-12)
