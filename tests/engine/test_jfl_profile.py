"""The jfuzzylogic profile's decisions, each on a system small enough to compute by hand
(the live jFuzzyLogic checks them all on random systems: tests/conformance/test_jfl_oracle.py)."""

from __future__ import annotations

import math

import numpy as np
import pytest

import fuzzyctl
from fuzzyctl.engine.compat.jfl_terms import hashmap_order

HEAD = """FUNCTION_BLOCK f
VAR_INPUT a : REAL; b : REAL; c : REAL; END_VAR
VAR_OUTPUT y : REAL; END_VAR
FUZZIFY a TERM t := (0, 0) (1, 1); END_FUZZIFY
FUZZIFY b TERM t := (0, 0) (1, 1); END_FUZZIFY
FUZZIFY c TERM t := (0, 0) (1, 1); END_FUZZIFY
DEFUZZIFY y TERM one := 1; TERM zero := 0; METHOD : COGS; DEFAULT := -1; END_DEFUZZIFY
"""


def _y(rules: str, compat: str, **inputs: float) -> float:
    text = HEAD + f"RULEBLOCK r\n{rules}\nEND_RULEBLOCK\nEND_FUNCTION_BLOCK\n"
    ctl = fuzzyctl.compile(fuzzyctl.load(text), compat=compat)
    return ctl.evaluate({"a": 0.0, "b": 0.0, "c": 0.0} | inputs)["y"]


def test_and_or_left_to_right() -> None:
    # degree of "a OR b AND c" at a=.8, b=.3, c=.5; y = degree (one: 1) / (degree + 1 - degree)
    rule = "RULE 1 : IF a IS t OR b IS t AND c IS t THEN y IS one;\nRULE 2 : IF a IS t THEN y IS zero;"
    both = {"a": 0.8, "b": 0.3, "c": 0.5}
    iec = 0.8 / (0.8 + 0.8)  # a OR (b AND c) = 0.8, ACCU MAX
    jfl = 0.5 / (0.5 + 0.8)  # (a OR b) AND c = 0.5 (ACCU SUM, one rule per term)
    assert _y("ACCU : MAX;\n" + rule, "iec", **both) == pytest.approx(iec)
    assert _y("ACCU : MAX;\n" + rule, "jfuzzylogic", **both) == pytest.approx(jfl)
    grouped = rule.replace("b IS t AND c IS t", "(b IS t AND c IS t)")
    assert _y("ACCU : MAX;\n" + grouped, "jfuzzylogic", **both) == pytest.approx(iec)


@pytest.mark.parametrize(
    ("decl", "degree"),
    [
        ("AND : PROD;", 0.8 + 0.5 - 0.4),  # OR ASUM, the pair of PROD
        ("AND : PROD; OR : MAX;", 0.8),  # the last declaration sets both: MIN/MAX
        ("OR : MAX; AND : PROD;", 0.8 + 0.5 - 0.4),
        ("AND : BDIF;", 1.0),  # BSUM
    ],
)
def test_the_last_declaration_sets_both_operators(decl: str, degree: float) -> None:
    rules = f"{decl}\nRULE 1 : IF a IS t OR b IS t THEN y IS one;\nRULE 2 : IF c IS t THEN y IS zero;"
    got = _y(rules, "jfuzzylogic", a=0.8, b=0.5, c=1.0)
    assert got == pytest.approx(degree / (degree + 1.0))


def test_accu_sum_by_default_and_nsum_as_bsum() -> None:
    rules = (
        "RULE 1 : IF a IS t THEN y IS one;\nRULE 2 : IF b IS t THEN y IS one;\n"
        "RULE 3 : IF c IS t THEN y IS zero;"
    )
    # one: 0.6 + 0.7 = 1.3 (SUM) / 1.0 (BSUM), zero: 0.5
    assert _y(rules, "jfuzzylogic", a=0.6, b=0.7, c=0.5) == pytest.approx(1.3 / 1.8)
    assert _y("ACCU : NSUM;\n" + rules, "jfuzzylogic", a=0.6, b=0.7, c=0.5) == pytest.approx(1.0 / 1.5)
    assert _y("ACCU : NSUM;\n" + rules, "iec", a=0.6, b=0.7, c=0.5) == pytest.approx(1.3 / 1.8)


def test_singletons_at_one_position_merge_under_the_accu() -> None:
    text = HEAD.replace("TERM zero := 0;", "TERM zero := 0; TERM also := 1;")
    text += (
        "RULEBLOCK r\nACCU : MAX;\nRULE 1 : IF a IS t THEN y IS one;\nRULE 2 : IF b IS t THEN y IS also;\n"
    )
    text += "RULE 3 : IF c IS t THEN y IS zero;\nEND_RULEBLOCK\nEND_FUNCTION_BLOCK\n"
    inputs = {"a": 0.6, "b": 0.4, "c": 0.5}
    # jFuzzyLogic: position 1 holds max(0.6, 0.4); IEC: two singletons at 1, 0.6 and 0.4
    assert fuzzyctl.compile(fuzzyctl.load(text), compat="jfuzzylogic").evaluate(inputs)["y"] == pytest.approx(
        0.6 / 1.1
    )
    assert fuzzyctl.compile(fuzzyctl.load(text)).evaluate(inputs)["y"] == pytest.approx(1.0 / 1.5)


def test_nc_starts_at_nan_and_an_output_is_read_by_its_crisp_value() -> None:
    text = HEAD.replace("DEFAULT := -1;", "DEFAULT := NC;").replace(
        "VAR_OUTPUT y : REAL; END_VAR", "VAR_OUTPUT y : REAL; z : REAL; END_VAR"
    )
    text += "DEFUZZIFY z TERM hi := (0, 0) (1, 1); METHOD : COG; RANGE := (0 .. 1); END_DEFUZZIFY\n"
    text += "RULEBLOCK r\nRULE 1 : IF a IS t THEN y IS one;\nRULE 2 : IF y IS one THEN z IS hi;\n"
    text += "END_RULEBLOCK\nEND_FUNCTION_BLOCK\n"
    ctl = fuzzyctl.compile(fuzzyctl.load(text), compat="jfuzzylogic")
    first = ctl.evaluate({"a": 0.0, "b": 0.0, "c": 0.0})
    assert math.isnan(first["y"]) and math.isnan(first["z"])  # nothing fired yet: NaN
    second = ctl.evaluate({"a": 0.5, "b": 0.0, "c": 0.0})
    assert second["y"] == 1.0 and math.isnan(second["z"])  # z read y's NaN from the start
    third = ctl.evaluate({"a": 0.5, "b": 0.0, "c": 0.0})
    # y is now 1.0, which is "one" to degree 1: z = the sampled centroid of the ramp
    xs = np.cumsum(np.r_[0.0, np.full(999, 0.001)])
    assert third["z"] == pytest.approx(float((xs * xs).sum() / xs.sum()), abs=1e-15)
    batch = fuzzyctl.compile(fuzzyctl.load(text), compat="jfuzzylogic").evaluate_batch(
        {"a": [0.0, 0.5, 0.5], "b": [0.0] * 3, "c": [0.0] * 3}
    )
    assert np.isnan(batch["z"][1]) and batch["z"][2] == third["z"]  # the batch path: same rows


def test_rule_blocks_run_in_java_hashmap_order() -> None:
    keys = ["No1", "No2", "first", "second", "zeta", "alpha", "rules", "fast", "slow", "B7", "main",
            "x1", "x2", "x3", "rb10", "rb2"]  # fmt: skip
    # java.util.HashMap's keySet() order for these keys, inserted in this order (jshell)
    java = "zeta,rb2,rules,main,second,No2,No1,fast,slow,B7,alpha,x1,x2,rb10,x3,first"
    assert ",".join(keys[i] for i in hashmap_order(keys)) == java


def test_explain_shows_the_sampled_set() -> None:
    text = HEAD.replace(
        "TERM one := 1; TERM zero := 0; METHOD : COGS;", "TERM up := (0, 0) (2, 1); METHOD : COG;"
    )
    text += "RULEBLOCK r\nRULE 1 : IF a IS t THEN y IS up;\nEND_RULEBLOCK\nEND_FUNCTION_BLOCK\n"
    ctl = fuzzyctl.compile(fuzzyctl.load(text), compat="jfuzzylogic")
    e = ctl.explain({"a": 0.5, "b": 0.0, "c": 0.0})
    out = e.output("y")
    assert len(out.breakpoints) == 1000 and out.breakpoints[0][0] == 0.0
    assert max(v for _x, v in out.breakpoints) == 0.5  # clipped at the rule's degree
    assert out.value == ctl.evaluate({"a": 0.5, "b": 0.0, "c": 0.0})["y"]


def test_with_scales_every_conclusion_of_the_rule() -> None:
    # RULE 1 concludes twice; WITH 0.5 scales both in jFuzzyLogic, only the one it follows
    # in IEC (5.4.3: the weighting factor belongs to the conclusion)
    text = HEAD.replace("VAR_OUTPUT y : REAL; END_VAR", "VAR_OUTPUT y : REAL; z : REAL; END_VAR")
    text += "DEFUZZIFY z TERM one := 1; TERM zero := 0; METHOD : COGS; DEFAULT := -1; END_DEFUZZIFY\n"
    text += (
        "RULEBLOCK r\nACCU : MAX;\nRULE 1 : IF a IS t THEN y IS one WITH 0.5, z IS one;\n"
        "RULE 2 : IF b IS t THEN y IS zero, z IS zero;\nEND_RULEBLOCK\nEND_FUNCTION_BLOCK\n"
    )
    inputs = {"a": 0.8, "b": 0.4, "c": 0.0}
    jfl = fuzzyctl.compile(fuzzyctl.load(text), compat="jfuzzylogic").evaluate(inputs)
    iec = fuzzyctl.compile(fuzzyctl.load(text)).evaluate(inputs)
    assert jfl["y"] == pytest.approx(0.4 / 0.8) and jfl["z"] == pytest.approx(0.4 / 0.8)
    assert iec["y"] == pytest.approx(0.4 / 0.8) and iec["z"] == pytest.approx(0.8 / 1.2)


def test_a_range_on_the_var_line_is_ignored() -> None:
    # y's terms span 0..2; RANGE (0 .. 10) on the VAR line would move the 1000 samples
    text = HEAD.replace("y : REAL;", "y : REAL; RANGE := (0 .. 10);").replace(
        "TERM one := 1; TERM zero := 0; METHOD : COGS;", "TERM up := (0, 0) (2, 1); METHOD : COG;"
    )
    text += "RULEBLOCK r\nRULE 1 : IF a IS t THEN y IS up;\nEND_RULEBLOCK\nEND_FUNCTION_BLOCK\n"
    got = fuzzyctl.compile(fuzzyctl.load(text), compat="jfuzzylogic").evaluate({"a": 1.0, "b": 0, "c": 0})
    xs = np.cumsum(np.r_[0.0, np.full(999, 0.002)])  # min 0, step (2 - 0) / 1000, as jFuzzyLogic
    mu = xs / 2
    assert got["y"] == pytest.approx(float((xs * mu).sum() / mu.sum()), abs=1e-12)


def test_a_vertical_edge_takes_the_value_reached_from_the_left() -> None:
    rising = "TERM t := (0, 0.25) (1, 0.25) (1, 1) (2, 0); END_FUZZIFY\nFUZZIFY b"
    text = HEAD.replace("TERM t := (0, 0) (1, 1); END_FUZZIFY\nFUZZIFY b", rising, 1)
    text += "RULEBLOCK r\nRULE 1 : IF a IS t THEN y IS one;\nRULE 2 : IF b IS t THEN y IS zero;\n"
    text += "END_RULEBLOCK\nEND_FUNCTION_BLOCK\n"
    inputs = {"a": 1.0, "b": 0.5, "c": 0.0}
    jfl = fuzzyctl.compile(fuzzyctl.load(text), compat="jfuzzylogic").evaluate(inputs)["y"]
    iec = fuzzyctl.compile(fuzzyctl.load(text)).evaluate(inputs)["y"]
    assert jfl == pytest.approx(0.25 / 0.75)  # a IS t = 0.25, reached from the left
    assert iec == pytest.approx(1.0 / 1.5)  # IEC: the upper value (docs/engine.md)


@pytest.mark.parametrize("backend", ["native", "python", "interpreted", None])
def test_every_backend_gives_jfuzzylogics_numbers(backend: str | None) -> None:
    # the C and generated-Python evaluators compute IEC arithmetic: a jfuzzylogic plan never
    # reaches them, whatever backend is asked for (jFuzzyLogic 3.3: 11.701603788948043)
    import warnings

    from tests.conftest import data_path

    kw = {} if backend is None else {"backend": backend}
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # "native backend unavailable" when asked for explicitly
        ctl = fuzzyctl.compile(
            fuzzyctl.load(data_path("jfuzzylogic", "fcl", "tipper.fcl")), compat="jfuzzylogic", **kw
        )
    assert ctl.evaluate({"service": 3, "food": 7})["tip"] == pytest.approx(11.701603788948043, abs=1e-12)
    assert ctl.evaluate_batch({"service": [3.0], "food": [7.0]})["tip"][0] == pytest.approx(
        11.701603788948043, abs=1e-12
    )
