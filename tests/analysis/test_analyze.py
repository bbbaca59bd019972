"""fuzzyctl.analyze: planted defects found and nothing else; gap boxes against brute force
(the engine's own rule degrees at sampled points); examples report no conflicts."""

from __future__ import annotations

import json
import random

import numpy as np
import pytest

import fuzzyctl
from fuzzyctl.analysis import analyze
from tests.analysis.systems import grid_system, random_system
from tests.conftest import ROOT


def best_degree(ctl: fuzzyctl.engine.Controller, point: dict[str, float], output: str) -> float:
    """The highest degree a rule reaches ``output`` with, from the engine's explanation."""
    ex = ctl.explain(point)
    return max([c.degree * c.weight for r in ex.rules for c in r.conclusions if c.variable == output] + [0.0])


@pytest.mark.parametrize("seed", range(12))
def test_planted_defects_found_and_nothing_else(seed: int) -> None:
    text, planted = grid_system(seed)
    r = analyze(fuzzyctl.load(text), surface=False)
    assert r.exact
    # the removed rule leaves exactly the point where only it fired (z is free)
    assert len(r.gaps) == 1
    (g,) = r.gaps
    p = planted.gaps[0]
    assert g.box["x"] == (p["x"], p["x"]) and g.box["y"] == (p["y"], p["y"]) and g.box["z"] == (0.0, 1.0)
    assert r.gap_fraction == 0.0 and r.coverage_index == 0.0
    assert sorted(r.dead_rules) == sorted(planted.dead)
    red = {(x.rule, x.covered_by, x.kind) for x in r.redundant}
    want = {(a, b, "duplicate") for a, b in planted.duplicates} | {
        (a, b, "subsumed") for a, b in planted.subsumed
    }
    assert red == want
    assert {c.rules for c in r.conflicts} == set(planted.conflicts)
    for c in r.conflicts:
        assert c.joint_degree == pytest.approx(1.0)
    assert [(u.variable, u.term) for u in r.unused_terms] == []  # "outside" is read by a dead rule


@pytest.mark.parametrize("seed", range(6))
def test_well_formed_grid_reports_nothing(seed: int) -> None:
    text, _ = grid_system(seed, plant=False)
    r = analyze(fuzzyctl.load(text), monotone=["out:+x,+y"])
    assert (r.gaps, r.conflicts, r.dead_rules, r.redundant, r.unused_terms) == ([], [], [], [], [])
    assert r.coverage_index >= 0.25 - 1e-9  # two neighbours at 0.5 each: MIN 0.5, PROD 0.25
    for m in r.monotonicity:
        assert m.rule_table == "holds" and not m.offending


def test_monotone_table_violation_and_proof() -> None:
    text, _ = grid_system(4, plant=False, and_op="PROD")
    if "CoGS" not in text:
        text, _ = grid_system(5, plant=False, and_op="PROD")
    assert "CoGS" in text
    r = analyze(fuzzyctl.load(text), monotone=["out:+x"])
    assert r.monotonicity[0].proven and r.monotonicity[0].counterexamples == []
    # swap the conclusions of the first two rules of the table (a0 b0 -> o0, a0 b1 -> o1 become o1, o0)
    bad = text.replace("b0 THEN out IS o0;", "b0 THEN out IS oX;").replace(
        "b1 THEN out IS o1;", "b1 THEN out IS o0;"
    )
    bad = bad.replace("oX;", "o1;")
    r = analyze(fuzzyctl.load(bad), monotone=["out:+y"])
    m = r.monotonicity[0]
    assert m.rule_table == "violated" and not m.proven
    assert m.offending == [("1", "2")]  # (a0, b0) -> o1 above (a0, b1) -> o0, nothing else
    ctl = fuzzyctl.compile(fuzzyctl.load(bad), backend="python")
    assert m.counterexamples
    for a, b in m.counterexamples:  # each one moves against "+": checked again here
        assert a["y"] < b["y"] and ctl.evaluate(b)["out"] < ctl.evaluate(a)["out"]


@pytest.mark.parametrize("seed", range(30))
@pytest.mark.parametrize("epsilon", [0.0, 0.3])
def test_gaps_against_brute_force(seed: int, epsilon: float) -> None:
    doc = fuzzyctl.load(random_system(seed))
    r = analyze(doc, epsilon=epsilon, surface=False)
    if not r.exact:
        pytest.skip("not an exact case: " + "; ".join(r.notes))
    ctl = fuzzyctl.compile(doc, backend="python")
    rng = random.Random(seed)
    pts = [{"x": rng.uniform(0, 10), "y": rng.uniform(0, 10)} for _ in range(250)]
    for g in r.gaps:  # points inside each box too
        (x0, x1), (y0, y1) = g.box["x"], g.box["y"]
        pts += [{"x": rng.uniform(x0, x1), "y": rng.uniform(y0, y1)} for _ in range(8)]
    tol = 1e-7
    for p in pts:
        inside = any(all(lo + tol < p[k] < hi - tol for k, (lo, hi) in g.box.items()) for g in r.gaps)
        near = any(all(lo - tol <= p[k] <= hi + tol for k, (lo, hi) in g.box.items()) for g in r.gaps)
        d = best_degree(ctl, p, "out")
        if inside:
            assert (d == 0.0) if epsilon == 0 else (d < epsilon), (p, d)
        elif not near:
            assert (d > 0.0) if epsilon == 0 else (d >= epsilon), (p, d)


@pytest.mark.parametrize("seed", range(4))
def test_gap_boxes_do_not_overlap(seed: int) -> None:
    r = analyze(fuzzyctl.load(random_system(seed)), epsilon=0.3, surface=False)
    for i, a in enumerate(r.gaps):
        for b in r.gaps[i + 1 :]:
            assert any(a.box[k][1] <= b.box[k][0] or b.box[k][1] <= a.box[k][0] for k in a.box)


EXAMPLES = [
    "tank.fcl",
    "crane.fcl",
    "pendulum.fcl",
    "figure7.fcl",
    "tipper.fis",
    "dryer_chained.fcl",
    "dimmer_chained.fll",
    "siemens_fpltest.fcl",
    "fpltest.fpl",
    "xfuz_debit.xfuz",
    "xfuz_3_3.xfuz",
]


@pytest.mark.parametrize("name", EXAMPLES)
def test_examples_report_no_conflicts(name: str) -> None:
    r = analyze(fuzzyctl.load(ROOT / "examples" / name), surface=False)
    assert r.conflicts == []
    json.dumps(r.to_json(), allow_nan=False)


def test_dimmer_gaps_are_the_range_ends() -> None:
    """DARK and BRIGHT are triangles that are 0 at 0 and 1: no rule fires there (the
    output is NaN, its DEFAULT), which the engine confirms."""
    doc = fuzzyctl.load(ROOT / "examples" / "dimmer_chained.fll")
    r = analyze(doc, surface=False)
    boxes = sorted({g.box["Ambient"] for g in r.gaps})
    assert boxes == [(0.0, 0.0), (1.0, 1.0)]
    ctl = fuzzyctl.compile(doc, backend="python")
    assert np.isnan(ctl.evaluate(Ambient=0.0)["Power"]) and not np.isnan(ctl.evaluate(Ambient=1e-6)["Power"])


def test_json_keys() -> None:
    text, _ = grid_system(2)
    r = analyze(fuzzyctl.load(text), monotone=["out:+x"])
    j = json.loads(json.dumps(r.to_json(), allow_nan=False))
    assert list(j) == [
        "block",
        "inputs",
        "gaps",
        "coverage_index",
        "gap_fraction",
        "conflicts",
        "dead_rules",
        "redundant",
        "unused_terms",
        "monotonicity",
    ]
    assert set(j["gaps"][0]) == {"output", "box", "best_degree"}
    assert set(j["conflicts"][0]) == {"rules", "output", "box", "joint_degree"}
    assert set(j["redundant"][0]) == {"rule", "covered_by", "kind"}
    assert set(j["monotonicity"][0]) == {"output", "input", "declared", "rule_table", "counterexamples"}


def test_cli(tmp_path: pytest.TempPathFactory, capsys: pytest.CaptureFixture[str]) -> None:
    from fuzzyctl.cli.app import main

    text, planted = grid_system(3)
    f = tmp_path / "p.fcl"  # type: ignore[operator]
    f.write_text(text)
    assert main(["analyze", str(f), "--json", "--monotone", "out:+x"]) == 0
    j = json.loads(capsys.readouterr().out)
    assert sorted(j["dead_rules"]) == sorted(planted.dead)
    assert main(["analyze", str(f)]) == 0
    out = capsys.readouterr().out
    assert "never fires" in out and f"{f}:" in out
    assert main(["analyze", str(f), "--monotone", "out:+nope"]) == 1
    assert "--monotone" in capsys.readouterr().err


@pytest.mark.parametrize("name", ["grid49", "grid343", "gauss343"])
def test_benchmark_grids_report_nothing(name: str) -> None:
    """Full grids of Ruspini-like partitions (benchmarks/systems.py): no gap, no conflict
    (neighbouring and diagonal cells conclude neighbouring or two-apart terms), nothing dead
    or redundant, the table monotone in every input (the rule is a clamped sum)."""
    from benchmarks.systems import SYSTEMS, fcl

    system = SYSTEMS[name]
    outs = "u:" + ",".join("+" + i for i in system.inputs)
    r = analyze(fuzzyctl.load(fcl(system)), surface=False, monotone=[outs] if name != "grid49" else [])
    assert (r.gaps, r.conflicts, r.dead_rules, r.redundant, r.unused_terms) == ([], [], [], [], [])
    assert r.exact and r.coverage_index > 0.45
    assert all(m.rule_table == "holds" for m in r.monotonicity)


def test_block_without_inputs_or_rules() -> None:
    """No rule at all: the whole space is a gap (the output is always its DEFAULT)."""
    text = (
        "FUNCTION_BLOCK e\nVAR_OUTPUT out : REAL; END_VAR\n"
        "DEFUZZIFY out DEFAULT := 1; END_DEFUZZIFY\nEND_FUNCTION_BLOCK\n"
    )
    r = analyze(fuzzyctl.load(text))
    assert r.to_json()["gaps"] == [{"output": "out", "box": {}, "best_degree": 0.0}]
    assert r.gap_fraction == 1.0 and r.coverage_index == 0.0
