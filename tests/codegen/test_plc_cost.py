"""What generated PLC code costs per cycle, and how it reads.

* The cost counted on the IR (fuzzyctl.ir.cost) against hand-derived counts of small
  programs, and against the operations actually executed by the generated Structured Text:
  blark parses the text, tests/codegen/st_interp.py translates it to Python, and the
  Python is instrumented here (every arithmetic operator, comparison, logic operator and
  array read counted as it runs) - an independent count of the same text.
* Term points are read where they are while in order; a point retuned out of order gives
  the engine's value for the sorted points (the rare branch), at a cost above the usual one
  and within the worst.
* Rule text above each rule, degrees and rules named for what they hold, within 24
  characters and unique without regard to case.
"""

from __future__ import annotations

import ast
import json
import re
from collections import Counter
from typing import Any

import numpy as np
import pytest

import fuzzyctl
from fuzzyctl.codegen.api import Generated, generate_st
from fuzzyctl.escape import MAX_IDENT_ST
from fuzzyctl.ir.cost import cost
from fuzzyctl.ir.nodes import Assign, Builder, Decl, Index, Int, Num, Program, Var, call
from tests.codegen import systems as S
from tests.codegen.st_interp import STBlock, translate

CRANE = S.EXAMPLES / "crane.fcl"


# --------------------------------------------------------------------------- hand counts


def _prog(b: Builder) -> Program:
    return Program("P", [Decl("x", "REAL", "input"), Decl("A", "REAL", "param", 4, (0.0,) * 4)], b.root)


def test_straight_line_counts_every_operator_once() -> None:
    b = Builder()
    x, y, a = Var("x"), Var("y"), Var("A")
    b.set(y, x * 2.0 + a[1] / x - call("EXP", -x))  # + * / - EXP, one negation, one read
    c = cost(_prog(b))
    assert c.usual.n == c.worst.n
    d = c.worst.to_dict()
    assert (d["add"], d["mul"], d["div"], d["array_reads"], d["assignments"]) == (3, 1, 1, 1, 1)
    assert d["calls"] == {"EXP": 1} and d["operations"] == 3 + 1 + 1 + 1


def test_if_costs_its_conditions_and_dearest_branch_and_rare_branches_only_in_the_worst() -> None:
    b = Builder()
    x, y = Var("x"), Var("y")
    with b.if_(x.lt(0.0), rare=True):  # rare: 4 multiplications
        b.set(y, x * x * x * x * x)
    with b.elif_(x.gt(1.0)):  # second condition, 1 addition
        b.set(y, x + 1.0)
    with b.else_():
        b.set(y, 0.0)
    c = cost(_prog(b))
    assert c.worst.n["compare"] == 2 and c.worst.n["mul"] == 4 and c.worst.n["add"] == 1
    assert c.usual.n["compare"] == 2 and c.usual.n.get("mul", 0) == 0 and c.usual.n["add"] == 1


def test_loops_count_iterations_and_their_counter() -> None:
    b = Builder()
    s, a = Var("y"), Var("A")
    with b.for_("k", 0, 3) as k:  # 4 trips: 4 reads, 4 additions + 4 increments, 5 tests
        b.set(s, s + a[k])
    c = cost(_prog(b)).worst
    assert (c.n["array_reads"], c.n["add"], c.n["compare"], c.n["assignments"]) == (4, 8, 5, 4)
    assert c.bounded
    b = Builder()
    with b.for_("k", Var("n"), 3):  # a bound that is no literal and no stated bound
        b.set(s, s + 1.0)
    assert not cost(_prog(b)).worst.bounded
    b = Builder()
    with b.while_(Var("go"), bound=3):  # 3 trips and the test that ends it: 4 tests
        b.set(s, s + 1.0)
        b.add(Assign(Var("go"), Var("y").lt(Num(10.0))))
    w = cost(_prog(b)).worst
    assert w.bounded and w.n["compare"] == 3 and w.n["add"] == 3 and w.n["assignments"] == 6


# --------------------------------------------------------------------------- counted by running


class _Counting(ast.NodeTransformer):
    """Instruments st_interp's Python: each operator evaluated counts once; AND/OR evaluate
    both operands as ST does (no short circuit)."""

    def visit_BinOp(self, node: ast.BinOp) -> Any:
        kind = {ast.Add: "add", ast.Sub: "add", ast.Mult: "mul", ast.Div: "div"}[type(node.op)]
        return self._count(kind, self.generic_visit(node))

    def visit_UnaryOp(self, node: ast.UnaryOp) -> Any:
        kind = "logic" if isinstance(node.op, ast.Not) else "add"
        return self._count(kind, self.generic_visit(node))

    def visit_Compare(self, node: ast.Compare) -> Any:
        return self._count("compare", self.generic_visit(node))

    def visit_BoolOp(self, node: ast.BoolOp) -> Any:
        self.generic_visit(node)
        fn = "_AND" if isinstance(node.op, ast.And) else "_OR"
        call_ = ast.Call(ast.Name(fn, ast.Load()), node.values, [])
        return self._count("logic", call_, len(node.values) - 1)

    def visit_Subscript(self, node: ast.Subscript) -> Any:
        self.generic_visit(node)
        is_ck = isinstance(node.slice, ast.Call) and getattr(node.slice.func, "id", "") == "_ck"
        if isinstance(node.ctx, ast.Load) and is_ck:
            return self._count("array_reads", node)
        return node

    @staticmethod
    def _count(kind: str, node: Any, k: int = 1) -> ast.Call:
        return ast.Call(ast.Name("_N", ast.Load()), [ast.Constant(kind), ast.Constant(k), node], [])


def _counting_block(text: str) -> tuple[STBlock, Counter[str]]:
    counts: Counter[str] = Counter()

    def note(kind: str, k: int, value: Any) -> Any:
        counts[kind] += k
        return value

    def instrument(tree: ast.Module) -> tuple[ast.Module, dict[str, Any]]:
        out = _Counting().visit(tree)
        return out, {"_N": note, "_AND": lambda *v: all(v), "_OR": lambda *v: any(v)}

    return STBlock(translate(text), instrument=instrument), counts


def _crane_st() -> tuple[str, Generated]:
    report: list[Generated] = []
    text = generate_st(fuzzyctl.load(CRANE), dialect="iec", report=report)
    return text, report[0]


KINDS = ("add", "mul", "div", "compare", "logic", "array_reads")


def test_cost_bounds_what_the_generated_text_executes_and_is_not_loose() -> None:
    text, gen = _crane_st()
    c = cost(gen.program)
    block, counts = _counting_block(text)
    plan = gen.plan
    data = S.random_inputs(plan, 300, seed=3, single=True)
    # inputs on the breakpoints too (the equal-x branches of the degree)
    data = np.vstack([data, [[x, a] for x in (-4.0, 0.0, 4.0, 10.0, 20.0) for a in (-15.0, -5.0, 0.0, 5.0)]])
    seen: Counter[str] = Counter()
    for row in data:
        counts.clear()
        block.step(dict(zip([i.name for i in plan.inputs], row.tolist(), strict=True)))
        for k in KINDS:
            assert counts[k] <= c.usual.n.get(k, 0), (k, counts[k], c.usual.n.get(k, 0), row)
            seen[k] = max(seen[k], counts[k])
    # not loose beyond what a static bound must be: it takes every term's dearest branch
    # (an interpolation) where an input meets at most two terms of its variable inside
    for k in ("compare", "array_reads"):
        assert seen[k] >= 0.45 * c.usual.n[k], (k, seen[k], c.usual.n[k])


def test_a_point_retuned_out_of_order_is_sorted_as_the_engine_sorts() -> None:
    text, gen = _crane_st()
    c = cost(gen.program)
    block, counts = _counting_block(text)
    # close := (0, 0) (4, 1) (10, 0); its middle point retuned to x = 12
    decl = gen.program.decl("FZ_distance_X")
    k = next(i for i, line in enumerate(decl.comment.split("\n")[1:]) if line.endswith("close x1"))
    block.state["FZ_DISTANCE_X"][k] = block.R(12.0)
    # the engine's stable sort of (0, 0) (12, 1) (10, 0), written in order (FCL wants it so)
    retuned = fuzzyctl.compile(
        CRANE.read_text().replace("(0, 0) (4, 1) (10, 0);", "(0, 0) (10, 0) (12, 1);"),
        backend="interpreted",
    )
    for dist, ang in [(1.0, 0.0), (9.0, 2.0), (11.0, -3.0), (11.5, 7.0), (3.0, -12.0)]:
        counts.clear()
        got = block.step({"distance": dist, "angle": ang})["POWER"]
        want = retuned.evaluate(distance=dist, angle=ang)["power"]
        assert got == pytest.approx(want, abs=1e-4), (dist, ang)
        assert all(counts[k] <= c.worst.n.get(k, 0) for k in KINDS)
        assert counts["array_reads"] > c.usual.n["array_reads"]  # the rare branch ran
    original = fuzzyctl.compile(CRANE, backend="interpreted")
    block.state["FZ_DISTANCE_X"][k] = block.R(4.0)  # back in order: the usual path again
    counts.clear()
    got = block.step({"distance": 9.0, "angle": 2.0})["POWER"]
    assert got == pytest.approx(original.evaluate(distance=9.0, angle=2.0)["power"], abs=1e-4)
    assert counts["array_reads"] <= c.usual.n["array_reads"]


def test_in_order_points_are_read_in_place_without_sorting_each_cycle() -> None:
    text, _gen = _crane_st()
    body = text[text.index("(* ---- fuzzify") : text.index("(* ---- rules")]
    usual = body[body.index("\n    ELSE\n") :]  # the branch taken while the points are in order
    assert "FZ_IX" not in usual and "FZ_IOFF" not in usual and "WHILE" not in usual
    assert re.search(r"FZ_DEG_distance_far := FZ_distance_Y\[12\]", usual)


# --------------------------------------------------------------------------- header and --json


def test_header_and_json_report_the_cost(capsys: pytest.CaptureFixture[str]) -> None:
    from fuzzyctl.cli.app import main

    text, gen = _crane_st()
    c = cost(gen.program)
    head = text[: text.index("FUNCTION_BLOCK")]
    assert f"usual (no retuned point out of order, no tiny degrees): {c.usual.operations} operations" in head
    assert f"worst case: {c.worst.operations} operations" in head
    capsys.readouterr()
    assert main(["codegen", str(CRANE), "--json"]) == 0
    block = json.loads(capsys.readouterr().out)["blocks"][0]
    assert block["cost"]["usual"]["operations"] == c.usual.operations
    assert set(block["cost"]["worst"]) >= {"add", "mul", "div", "compare", "calls", "array_reads"}
    c_files: list[Generated] = []
    fuzzyctl.codegen.generate_c(fuzzyctl.load(CRANE), report=c_files)
    assert "cost per cycle" in "\n".join(c_files[0].program.header)


# --------------------------------------------------------------------------- readability


def test_each_rule_text_is_above_its_code() -> None:
    text, _gen = _crane_st()
    for line in CRANE.read_text().splitlines():
        m = re.match(r"\s*RULE (\d+) : (IF .*);", line)
        if m:
            assert f"(* RULE {m.group(1)} (block operator) *)\n    (* {m.group(2)} *)" in text, line
    rule13 = text.index("(* RULE 13 (")
    assert text.index("FZ_RULE_13 :=", rule13) < text.index("(* RULE 14 (")


def test_names_say_what_they_hold_and_stay_short_and_distinct() -> None:
    text, _gen = _crane_st()
    rules = text[text.index("(* ---- rules") :]
    assert "FZ_DEG_distance_far" in rules and "FZ_DEG[" not in rules  # (the rare re-sort's table aside)
    assert "FZ_ACC_power_pos_high" in text
    # long and clashing names: cut to 24 characters, told apart regardless of case
    fcl = """FUNCTION_BLOCK longnames
    VAR_INPUT temperature_of_the_inlet : REAL; END_VAR
    VAR_OUTPUT y : REAL; END_VAR
    FUZZIFY temperature_of_the_inlet
        TERM very_cold_indeed_a := (0, 1) (10, 0);
        TERM very_cold_indeed_b := (0, 0) (10, 1) (20, 0);
        TERM Very_Cold_Indeed_C := (10, 0) (20, 1);
    END_FUZZIFY
    DEFUZZIFY y
        TERM lo := 0; TERM hi := 1;
        METHOD : CoGS; DEFAULT := 0;
    END_DEFUZZIFY
    RULEBLOCK r
        RULE 1 : IF temperature_of_the_inlet IS very_cold_indeed_a THEN y IS lo;
        RULE 2 : IF temperature_of_the_inlet IS very_cold_indeed_b THEN y IS hi;
        RULE 3 : IF temperature_of_the_inlet IS Very_Cold_Indeed_C THEN y IS hi;
    END_RULEBLOCK
    END_FUNCTION_BLOCK
    """
    report: list[Generated] = []
    st = generate_st(fuzzyctl.load(fcl), dialect="iec", report=report)
    names = [d.name for d in report[0].program.decls]
    assert all(len(n) <= MAX_IDENT_ST for n in names)
    assert len({n.upper() for n in names}) == len(names)
    degs = [n for n in names if n.startswith("FZ_DEG_temperature")]
    assert len(degs) == 3, names
    block = STBlock(translate(st))
    want = fuzzyctl.compile(fcl, backend="interpreted")
    for x in (-1.0, 2.5, 10.0, 14.0, 25.0):
        got = block.step({"temperature_of_the_inlet": x})["Y"]
        assert got == pytest.approx(want.evaluate(temperature_of_the_inlet=x)["y"], abs=1e-5)


def test_rule_comment_text_is_escaped() -> None:
    from fuzzyctl.engine.plan import CTerm
    from fuzzyctl.ir.builders.ruletext import rule_text
    from fuzzyctl.kinds import targets

    _text, gen = _crane_st()
    plan = gen.plan
    rule = plan.rules[0]
    assert isinstance(rule.condition.operands[0], CTerm)  # type: ignore[union-attr]
    hostile = "x *) y := 1; (* z"
    for caps in (targets.get("st"), targets.get("c")):
        out = caps.comment(rule_text(plan, rule) + hostile)
        assert out.count("*)") <= 1 and out.count("*/") <= 1


def test_named_identifiers_are_cut_and_numbered_within_the_limit() -> None:
    from fuzzyctl.ir.state import Gen

    g = Gen("st")
    first = g.temp_named("DEG_" + "x" * 40)
    second = g.temp_named("deg_" + "X" * 40)  # the same name but for case
    assert len(first.name) == MAX_IDENT_ST and len(second.name) <= MAX_IDENT_ST
    assert first.name.upper() != second.name.upper()
    assert g.temp_named("a b-c").name == "FZ_a_b_c"
    assert isinstance(Index("A", Int(0)), Index)
