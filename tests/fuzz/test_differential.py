"""The differential fuzzer's own parts (issue 25, point 2): the random systems walk every
table the engine reads, a wrong path is caught and named, the C header's bound is read,
and (extra suite ``matiec``) generated ST of random systems agrees with the reference
through a real IEC 61131-3 compiler."""

from __future__ import annotations

import dataclasses
import math
import random
from pathlib import Path
from typing import Any

import numpy as np
import pytest

import fuzzyctl
from fuzzyctl import model as m
from fuzzyctl.engine.semantics import operators
from tests.fuzz import differential as D
from tests.fuzz import systems as S


def test_random_systems_walk_every_table_the_engine_reads() -> None:
    """Any run of as many systems as the longest table covers every entry of every table,
    read from the engine (a new norm, method or shape is drawn without editing the fuzzer)."""
    n = max(len(operators.TNORMS), len(operators.SNORMS), len(operators.ACCU_NAMES), len(m.DEFUZZ_METHODS),
            len(m.SHAPES) + 2)  # fmt: skip
    seen: dict[str, set[Any]] = {k: set() for k in ("and", "or", "act", "accu", "method", "shapes")}
    for k in range(n):
        d = S.describe(S.system(k, seed=31))
        for key, v in d.items():
            seen[key] |= v if isinstance(v, set) else {v}
    assert seen["and"] == set(operators.TNORMS)
    assert seen["act"] == set(operators.TNORMS)
    assert seen["accu"] == set(operators.ACCU_NAMES)
    assert seen["method"] == set(m.DEFUZZ_METHODS)
    shapes = {k for k, spec in m.SHAPES.items() if k not in ("constant", "linear") and not spec.variadic}
    assert shapes <= seen["shapes"], shapes - seen["shapes"]
    assert {"PointsMF", "SingletonMF"} <= seen["shapes"]
    assert seen["or"] - {None} <= set(operators.SNORMS)


def test_extreme_parameters_are_drawn() -> None:
    """Zero widths, negated parameters and the extremes (1e300, subnormals) appear."""
    rng = random.Random(3)
    drawn = [S.params(rng, kind) for _ in range(300) for kind in ("bell", "triangle", "gaussian")]
    flat = [x for p in drawn for x in p]
    assert any(len(set(p)) == 1 for p in drawn)  # zero width
    assert 1e300 in flat and 5e-324 in flat and any(x < 0 for x in flat)


def _tipper(smooth: bool = False) -> m.FunctionBlock:
    """Two rules, gaussian output terms (``smooth``) or triangles."""
    tri = m.ShapeMF
    outs = (
        (tri("gaussian", (2.0, 1.0)), tri("gaussian", (8.0, 1.5)))
        if smooth
        else (tri("triangle", (0.0, 2.0, 5.0)), tri("triangle", (4.0, 8.0, 10.0)))
    )
    return m.FunctionBlock(
        "t",
        variables=(m.Variable("x", m.VarKind.INPUT), m.Variable("y", m.VarKind.OUTPUT)),
        fuzzify=(
            m.FuzzifyBlock(
                "x",
                (
                    m.Term("lo", tri("triangle", (0.0, 0.0, 10.0))),
                    m.Term("hi", tri("triangle", (0.0, 10.0, 10.0))),
                ),
            ),
        ),
        defuzzify=(
            m.DefuzzifyBlock(
                "y",
                (m.Term("a", outs[0]), m.Term("b", outs[1])),
                m.Range(0.0, 10.0),
                "COG",
                m.Default(0.0),
            ),
        ),
        rule_blocks=(
            m.RuleBlock(
                "rb",
                (
                    m.Rule("1", m.Is("x", "lo"), (m.Conclusion("y", "a"),)),
                    m.Rule("2", m.Is("x", "hi"), (m.Conclusion("y", "b"),)),
                ),
                "MIN",
                None,
                "MIN",
                "MAX",
            ),
        ),
    )


def test_a_wrong_path_is_caught_and_named(monkeypatch: pytest.MonkeyPatch) -> None:
    """A python backend off by 1e-8 of the range (10 times the tolerance) is reported as
    ``disagree:python`` and nothing else; the correct model gives no finding."""
    fb = _tipper()
    assert D.check(fb, None, random.Random(1), D.ExtraPaths()).findings == []
    real = D.compile_quiet

    def skewed(model: Any, block: str | None, backend: str | None) -> Any:
        ctl = real(model, block, backend)
        if backend == "python":
            inner = ctl.evaluate
            ctl.evaluate = lambda v: {k: x + 1e-7 for k, x in inner(v).items()}
        return ctl

    monkeypatch.setattr(D, "compile_quiet", skewed)
    res = D.check(fb, None, random.Random(1), D.ExtraPaths())
    assert {f.category for f in res.findings} == {"disagree:python"}, res.findings
    assert {"python", "numpy", "native", "native-batch", "explain", "interpreted"} <= res.compared


def test_the_reference_is_blamed_when_every_other_path_agrees(monkeypatch: pytest.MonkeyPatch) -> None:
    fb = _tipper()
    real = D.sequential

    def skewed(ctl: Any, *args: Any) -> Any:
        rows = real(ctl, *args)
        if ctl.__class__.__name__ == "Controller" and not ctl._fast:  # the interpreted reference
            return [[v + 1.0 if isinstance(v, float) else v for v in r] for r in rows]
        return rows

    monkeypatch.setattr(D, "sequential", skewed)
    res = D.check(fb, None, random.Random(1), D.ExtraPaths())
    assert [f.category for f in res.findings] == ["disagree:interpreted"], res.findings


def test_agreement_rule() -> None:
    assert D.agree(1.0, 1.0 + 0.9e-8, 10.0) and not D.agree(1.0, 1.0 + 1.1e-8, 10.0)
    assert D.agree(math.nan, math.nan, 1.0) and not D.agree(math.nan, 0.0, 1.0)
    assert D.agree(math.inf, math.inf, 1.0) and not D.agree(math.inf, -math.inf, 1.0)
    assert D.agree("refused", "refused", 1.0) and not D.agree("refused", 0.0, 1.0)


def test_the_c_header_bound_is_read_and_the_c_path_runs() -> None:
    """The generated header of a smooth CoG output states ``|CoG error| <= K x (high -
    low)^2 / area``; the fuzzer reads K and runs the C block on the vectors."""
    from fuzzyctl.codegen import generate_c

    fb = _tipper(smooth=True)
    plan = fuzzyctl.compile(fb, backend="interpreted").plan
    header = generate_c(dataclasses.replace(plan, name="hb"))["hb.h"]
    bounds = D.header_bounds(header)
    assert set(bounds) == {"y"} and 0 < bounds["y"] < 1e-6
    got = D.run_c(plan, [[0.0], [3.3], [10.0]])
    if got is None:
        pytest.skip("no C compiler")  # run_c needs cc; the native backend too
    values, _b = got
    want = [fuzzyctl.compile(fb, backend="python").evaluate({"x": x})["y"] for x in (0.0, 3.3, 10.0)]
    assert np.allclose([v[0] for v in values], want, rtol=0, atol=1e-6)


# --------------------------------------------------------------------------- matiec (extra)

MATIEC_SYSTEMS = 8


@pytest.mark.extra("matiec")
def test_generated_st_of_random_systems_agrees_on_matiec(tmp_path: Path) -> None:
    """A small sample of the fuzzer's random systems as ``--dialect iec`` LREAL Structured
    Text through matiec and gcc, successive cycles of one instance: each output within 1e-9
    of its range of the reference (or the bound the generated text states)."""
    from fuzzyctl.codegen import CodegenError
    from fuzzyctl.diagnostics import FuzzyctlError
    from fuzzyctl.ir.programs.plc_block import build_program
    from fuzzyctl.ir.render.st import render_st
    from tests.codegen import matiec as M

    chosen: list[tuple[int, Any, str]] = []
    k = 0
    while len(chosen) < MATIEC_SYSTEMS and k < 400:
        fb = S.system(k, seed=77)
        k += 1
        try:
            ref = fuzzyctl.compile(fb, backend="interpreted")
            plan = dataclasses.replace(ref.plan, name=f"R{len(chosen)}")
            text = render_st(build_program(plan, "st"), dialect="iec", lreal=True)
        except (FuzzyctlError, CodegenError):
            continue
        if any(o.default is not None and math.isnan(o.default) for o in plan.outputs):
            continue  # ST has no NaN: DEFAULT := nan needs --default
        chosen.append((k - 1, plan, text))
    assert len(chosen) == MATIEC_SYSTEMS
    matiec = M.build()
    blocks = [
        M.Block(
            p.name or "", tuple(i.name for i in p.inputs), tuple(o.name for o in p.outputs if o.is_output)
        )
        for _k, p, _t in chosen
    ]
    M.iec2c(matiec, "\n".join(t for _k, _p, t in chosen), tmp_path)
    exe = M.compile_c(matiec, tmp_path, M.driver(blocks, "LREAL"))
    bad = []
    for j, (k, plan, text) in enumerate(chosen):
        rows = D.vectors(plan, random.Random(k), 24)
        got, _info = M.run_block(exe, j, np.array(rows, dtype=float))
        ref = fuzzyctl.compile(plan_model := S.system(k, seed=77), backend="interpreted")
        names = [s.name for s in plan.inputs]
        outs = [o.name for o in plan.outputs if o.is_output]
        want = D.sequential(ref, names, rows, outs)
        bounds = D.header_bounds(text)
        for r, (g_row, w_row) in enumerate(zip(got.tolist(), want, strict=True)):
            for c, (g, w) in enumerate(zip(g_row, w_row, strict=True)):
                op = next(o for o in plan.outputs if o.name == outs[c])
                scale = D.output_scale(op, [x[c] for x in want])
                tol = D.REL_TOL
                if outs[c] in bounds:  # K (high - low)^2 / area, relative to the range
                    area = D.accumulated_area(ref, names, rows[r], outs[c])
                    tol = max(tol, bounds[outs[c]] * scale / area if area else math.inf)
                if not D.agree(float(g), w, scale, tol):
                    bad.append(
                        f"system {k} ({S.describe(plan_model)}) row {rows[r]}: ST {g!r}, reference {w!r}"
                    )
    assert not bad, "\n".join(bad[:10])
