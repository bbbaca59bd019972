"""On-target test benches: a PROGRAM (Structured Text) or a C function that feeds the
generated block recorded input vectors, one per cycle, compares every output and INFO with
the engine's values (computed here, at generation time, and embedded as literals) to a
tolerance stated in the header, and sets ``PASS`` / ``FAIL_COUNT`` / ``FIRST_FAIL``.

The vectors cover, in this order: every rule where it fires strongest, the ends of every
input's range (one at a time, then all low and all high), an input where no rule fires for
an output (DEFAULT or NC, right after a vector where it fired), then random vectors up to
the requested count.  Vectors where the output changes faster than the tolerance allows
across a rounding of the inputs (a step, a vertical edge) are avoided, so that a REAL target
passes on a correct block and fails on a wrong one.
"""

from __future__ import annotations

import math
import random
from dataclasses import dataclass

from fuzzyctl.engine.plan import Plan, Slot
from fuzzyctl.engine.reference.interp import Interpreter
from fuzzyctl.escape import c_ident, st_ident
from fuzzyctl.ir.state import CodegenError
from fuzzyctl.kinds import shapes as registry
from fuzzyctl.kinds import targets
from fuzzyctl.kinds.methods import METHODS

#: relative tolerance (of each output's range) by arithmetic
TOLERANCE = {"REAL": 1e-4, "LREAL": 1e-9, "float": 1e-4, "double": 1e-9}
_SEARCH = 400  # random candidates searched for the rule and no-rule vectors


@dataclass
class Bench:
    """The vectors of a test bench and the engine's answers (one cycle each, in order)."""

    plan: Plan
    rows: list[list[float]]
    why: list[str]
    expected: list[list[float]]  # the declared outputs
    info: list[int]
    tolerance: list[float]  # absolute, per declared output
    relative: float
    covered_rules: int


def _outputs(plan: Plan) -> list[int]:
    return [k for k, o in enumerate(plan.outputs) if o.is_output]


def _bounds(plan: Plan, i: int) -> tuple[float, float]:
    """Where input ``i`` lives: [0, 1] for a degree, its clamp, else the hull of the constant
    parameters of the terms that read it."""
    spec = plan.inputs[i]
    if spec.degree:
        return 0.0, 1.0
    if spec.clamp is not None:
        return spec.clamp
    xs: list[float] = []
    for fi in plan.fuzzy_inputs:
        for t in fi.terms:
            if fi.slot != i and not any(isinstance(p, Slot) and p.index == i for p in t.params):
                continue
            if t.pwl is not None:
                xs += [x for x, _y in t.pwl]
                continue
            nums = [float(p) for p in t.params if not isinstance(p, Slot)]
            if registry.flag(t.kind, "centre_spread") and len(nums) >= 2:  # a bump: around it
                xs += [nums[0] - 3 * abs(nums[1]), nums[0] + 3 * abs(nums[1])]
            else:
                xs += nums
    xs = [x for x in xs if math.isfinite(x)]
    if not xs:
        return 0.0, 1.0
    lo, hi = min(xs), max(xs)
    return (lo, hi) if hi > lo else (lo - 1.0, hi + 1.0)


class _Engine:
    def __init__(self, plan: Plan, single: bool) -> None:
        self.plan, self.single = plan, single
        self.interp = Interpreter(plan)
        self.outs = _outputs(plan)

    def cast(self, row: list[float]) -> list[float]:
        if not self.single:
            return [float(v) for v in row]
        import numpy as np

        return [float(np.float32(v)) for v in row]

    def once(self, row: list[float]) -> tuple[list[float], list[bool], list[float]]:
        """(declared outputs, fired per output, rule degrees) from a fresh instance."""
        rec = self.interp.run(row, [None] * len(self.plan.outputs))
        return (
            [rec.outputs[k].value for k in self.outs],
            [o.fired for o in rec.outputs],
            list(rec.rule_degrees),
        )


def _relative(plan: Plan, k: int, rel: float) -> float:
    """The relative tolerance of output ``k``: a smooth set's LM, RM or MoM is defined only to
    the stretch where the set is flat to rounding near a smooth peak (docs/engine.md), where
    the block and the engine may answer different points of it: the REAL tolerance there."""
    op = plan.outputs[k]
    smooth_max = op.kind == "mamdani" and not op.exact and METHODS[op.method].maximum is not None
    return max(rel, TOLERANCE["REAL"]) if smooth_max else rel


def _scale(plan: Plan, k: int, values: list[float]) -> float:
    op = plan.outputs[k]
    if op.low is not None and op.high is not None and op.high > op.low:
        return op.high - op.low
    finite = [abs(v) for v in values if math.isfinite(v)]
    return max([1.0, *finite])


def choose(plan: Plan, n: int, *, single: bool, seed: int = 0) -> Bench:
    """``n`` vectors for ``plan`` (``single``: the block computes in REAL/float)."""
    if n < 1:
        raise CodegenError("the test bench needs at least 1 input vector")
    eng = _Engine(plan, single)
    rng = random.Random(seed)
    bounds = [_bounds(plan, i) for i in range(len(plan.inputs))]
    mid = [(lo + hi) / 2 for lo, hi in bounds]
    cands = [eng.cast([rng.uniform(lo, hi) for lo, hi in bounds]) for _ in range(_SEARCH)]
    # beyond the terms (not for degrees): where no rule may fire
    wide = [
        (lo, hi) if plan.inputs[i].degree else (lo - 0.3 * (hi - lo), hi + 0.3 * (hi - lo))
        for i, (lo, hi) in enumerate(bounds)
    ]
    cands += [eng.cast([rng.uniform(lo, hi) for lo, hi in wide]) for _ in range(_SEARCH // 4)]
    evals = [eng.once(c) for c in cands]
    rel = TOLERANCE["REAL" if single else "LREAL"]
    picked: list[tuple[list[float], str]] = []

    step = 1e-6 if single else 1e-12  # a few roundings of the inputs, relative to their spans

    def stable(row: list[float]) -> bool:
        """No step within a few roundings of ``row``: a correct block passes there."""
        base = eng.once(row)
        if not all(math.isfinite(v) for v in base[0]):
            return False
        for i, (lo, hi) in enumerate(bounds):
            for sign in (-1.0, 1.0):
                moved = list(row)
                moved[i] = row[i] + sign * step * max(hi - lo, abs(row[i]))
                got = eng.once(moved)
                if got[1] != base[1]:
                    return False
                for k, (a, b) in enumerate(zip(got[0], base[0], strict=True)):
                    if not abs(a - b) <= 0.5 * rel * _scale(plan, eng.outs[k], [b]):
                        return False
        return True

    covered = 0
    for r, rule in enumerate(plan.rules):
        order = sorted(range(len(cands)), key=lambda j: -evals[j][2][r])
        for j in order[:20]:
            if evals[j][2][r] > 0 and stable(cands[j]):
                picked.append((cands[j], f"rule {rule.label} fires strongest"))
                covered += 1
                break
    for i, (lo, hi) in enumerate(bounds):
        for end, label in ((lo, "low"), (hi, "high")):
            row = eng.cast([*mid[:i], end, *mid[i + 1 :]])
            if stable(row):
                picked.append((row, f"{plan.inputs[i].name} at the {label} end"))
    for label, ends in (
        ("all inputs low", [b[0] for b in bounds]),
        ("all inputs high", [b[1] for b in bounds]),
    ):
        row = eng.cast(ends)
        if plan.inputs and stable(row):
            picked.append((row, label))
    for k, op in enumerate(plan.outputs):
        if op.kind == "degree":
            continue
        quiet = [j for j in range(len(cands)) if not evals[j][1][k]]
        loud = [j for j in range(len(cands)) if evals[j][1][k]]
        q = next((j for j in quiet if stable(cands[j])), None)
        a = next((j for j in loud if stable(cands[j])), None)
        if q is not None and a is not None:
            what = "keeps its last value (NC)" if op.no_change else "takes its DEFAULT"
            picked.append((cands[a], f"{op.name}: a rule fires"))
            picked.append((cands[q], f"{op.name}: no rule fires, {what}"))
    j = 0
    while len(picked) < n and j < len(cands):
        if stable(cands[j]):
            picked.append((cands[j], "random"))
        j += 1
    picked = picked[:n]
    rows = [p[0] for p in picked]
    expected, info = _replay(plan, rows)
    outs = eng.outs
    tol = [_relative(plan, k, rel) * _scale(plan, k, [e[c] for e in expected]) for c, k in enumerate(outs)]
    return Bench(plan, rows, [p[1] for p in picked], expected, info, tol, rel, covered)


def _replay(plan: Plan, rows: list[list[float]]) -> tuple[list[list[float]], list[int]]:
    """The engine's outputs and INFO for the rows as successive cycles of one instance."""
    interp = Interpreter(plan)
    state: list[float | None] = [None] * len(plan.outputs)
    outs = _outputs(plan)
    expected, info = [], []
    for row in rows:
        rec = interp.run(row, state)
        expected.append([rec.outputs[k].value for k in outs])
        quiet = any(
            not o.fired for o, op in zip(rec.outputs, plan.outputs, strict=True) if op.kind != "degree"
        )
        info.append(2 if quiet else 0)
    return expected, info


def _header(bench: Bench, real: str) -> list[str]:
    plan = bench.plan
    lines = [
        f"test bench for function block {plan.name}: generated by fuzzyctl",
        f"{len(bench.rows)} input vectors, one per cycle, through one instance, compared with the values "
        "fuzzyctl's engine computed at generation time",
        f"tolerance: |output - expected| <= {bench.relative:g} x the output's range (arithmetic in {real}); "
        "INFO must be equal",
        f"covers {bench.covered_rules} of {len(plan.rules)} rules where each fires strongest, "
        "the range ends, and no rule fired (DEFAULT / NC) where the block has such inputs",
        "PASS is TRUE once every vector matched; FAIL_COUNT counts the vectors that did not; "
        "FIRST_FAIL is the number (1-based) of the first of them, 0 if none",
    ]
    for k, op in enumerate(o for o in plan.outputs if o.is_output):
        lines.append(f"output {op.name}: tolerance {bench.tolerance[k]:.6g}")
    return lines


def render_st_bench(bench: Bench, *, dialect: str = "codesys", lreal: bool = False) -> str:
    """The test bench as an IEC 61131-3 PROGRAM ``TB_<block>`` (after the block's text)."""
    record = targets.dialect(dialect)
    if not record.testbench:
        able = [name for name, d in targets.DIALECTS.items() if d.testbench]
        listed = ", ".join(able[:-1]) + " or " + able[-1]
        raise CodegenError(f"the test bench is written for --dialect {listed} (not {dialect})")
    plan, real = bench.plan, record.real_type(not lreal)

    def st_real(v: float) -> str:
        return record.real(v, parens=False)

    fb = st_ident(plan.name or "FUZZY", "function block name")
    prog = st_ident(f"TB_{fb}"[:24].rstrip("_"), "test bench name")
    n = len(bench.rows)
    outs = [plan.outputs[k] for k in _outputs(plan)]
    out: list[str] = [record.comment(line) for line in _header(bench, real)]
    out += [record.comment(why, lead=f"vector {r + 1}: ") for r, why in enumerate(bench.why)]

    def array(name: str, typ: str, values: list[str]) -> str:
        return f"    {name} : ARRAY[0..{n - 1}] OF {typ} := [{', '.join(values)}];"

    out += [f"PROGRAM {prog}", "VAR_OUTPUT", "    PASS : BOOL := FALSE;", "    FAIL_COUNT : INT := 0;"]
    out += ["    FIRST_FAIL : INT := 0;", "    DONE : BOOL := FALSE;", "END_VAR", "VAR", f"    TB_FB : {fb};"]
    for i, inp in enumerate(plan.inputs):
        st_ident(inp.name, "variable")
        out.append(array(f"TB_X{i}", real, [st_real(row[i]) for row in bench.rows]))
    for c, _op in enumerate(outs):
        out.append(array(f"TB_Y{c}", real, [st_real(e[c]) for e in bench.expected]))
        out.append(f"    TB_TOL{c} : {real} := {st_real(bench.tolerance[c])};")
    out.append(array("TB_INFO", "BYTE", [str(int(v)) for v in bench.info]))
    out += ["    TB_K : INT := 0;", "    TB_BAD : BOOL;", "END_VAR"]
    args = ", ".join(f"{inp.name} := TB_X{i}[TB_K]" for i, inp in enumerate(plan.inputs))
    out += ["IF NOT DONE THEN", f"    TB_FB({args});", "    TB_BAD := TB_FB.INFO <> TB_INFO[TB_K];"]
    for c, op in enumerate(outs):  # NOT (... <= tol): a NaN output fails too
        out.append(f"    IF NOT (ABS(TB_FB.{op.name} - TB_Y{c}[TB_K]) <= TB_TOL{c}) THEN")
        out += ["        TB_BAD := TRUE;", "    END_IF;"]
    out += st_bench_tail(n)
    return "\n".join(out) + "\n"


def _c_num(v: float) -> str:
    if not math.isfinite(v):
        raise CodegenError(f"the value {v} cannot be written in the C test bench")
    return targets.C.real(v, parens=False)


def render_c_bench(bench: Bench, *, single: bool = False) -> str:
    """The test bench as C99: ``int NAME_testbench(int *first_fail)`` returns FAIL_COUNT;
    compiled with ``-DFUZZYCTL_TESTBENCH_MAIN`` it is a program printing PASS or FAIL."""
    plan = bench.plan
    name = c_ident(plan.name or "FUZZY", "function block name")
    n = len(bench.rows)
    outs = [plan.outputs[k] for k in _outputs(plan)]
    real = targets.C.real_type(single)
    lines = [targets.C.comment(line) for line in _header(bench, real)]
    lines += [targets.C.comment(why, lead=f"vector {r + 1}: ") for r, why in enumerate(bench.why)]
    lines += ["#include <stdio.h>", f'#include "{name}.h"', ""]
    for i, inp in enumerate(plan.inputs):
        c_ident(inp.name, "variable")
        vals = ", ".join(_c_num(row[i]) for row in bench.rows)
        lines.append(f"static const double {name}_TB_X{i}[{n}] = {{{vals}}};")
    for c, _op in enumerate(outs):
        vals = ", ".join(_c_num(e[c]) for e in bench.expected)
        lines.append(f"static const double {name}_TB_Y{c}[{n}] = {{{vals}}};")
    lines.append(
        f"static const unsigned char {name}_TB_INFO[{n}] = {{{', '.join(str(v) for v in bench.info)}}};"
    )
    body = [f"fb.{inp.name} = ({name}_real){name}_TB_X{i}[k];" for i, inp in enumerate(plan.inputs)]
    body.append(f"bad = {name}_step(&fb) != {name}_TB_INFO[k];")
    for c, op in enumerate(outs):
        body.append(f"d = (double)fb.{op.name} - {name}_TB_Y{c}[k];")
        body.append(f"if (!((d < 0 ? -d : d) <= {_c_num(bench.tolerance[c])})) bad = 1;")
    lines += c_bench_driver(name, n, "double", body)
    return "\n".join(lines) + "\n"


def c_bench_driver(name: str, n: int, diff: str, body: list[str]) -> list[str]:
    """The end of a C test bench (every bench form shares it): ``int NAME_testbench(int
    *first_fail)`` running ``body`` (which sets ``bad``, with ``d`` of type ``diff`` at hand) on
    each of ``n`` vectors and returning FAIL_COUNT, then a ``main`` printing PASS or FAIL under
    ``-DFUZZYCTL_TESTBENCH_MAIN``."""
    return [
        "",
        f"int {name}_testbench(int *first_fail)",
        "{",
        f"    {name} fb;",
        "    int k, bad, fails = 0;",
        f"    {diff} d;",
        f"    {name}_init(&fb);",
        "    *first_fail = 0;",
        f"    for (k = 0; k < {n}; k++) {{",
        *(f"        {line}" for line in body),
        "        if (bad) {",
        "            fails++;",
        "            if (*first_fail == 0) *first_fail = k + 1;",
        "        }",
        "    }",
        "    return fails;",
        "}",
        "",
        "#ifdef FUZZYCTL_TESTBENCH_MAIN",
        "int main(void)",
        "{",
        "    int first;",
        f"    int fails = {name}_testbench(&first);",
        '    printf("%s FAIL_COUNT=%d FIRST_FAIL=%d\\n", fails ? "FAIL" : "PASS", fails, first);',
        "    return fails != 0;",
        "}",
        "#endif",
    ]


def st_bench_tail(n: int) -> list[str]:
    """The end of a Structured Text test bench PROGRAM: count the vector that failed, step to
    the next of ``n`` and set DONE and PASS after the last (every bench form shares it)."""
    return [
        "    IF TB_BAD THEN",
        "        FAIL_COUNT := FAIL_COUNT + 1;",
        "        IF FIRST_FAIL = 0 THEN",
        "            FIRST_FAIL := TB_K + 1;",
        "        END_IF;",
        "    END_IF;",
        "    TB_K := TB_K + 1;",
        f"    IF TB_K >= {n} THEN",
        "        DONE := TRUE;",
        "        PASS := FAIL_COUNT = 0;",
        "    END_IF;",
        "END_IF;",
        "END_PROGRAM",
    ]
