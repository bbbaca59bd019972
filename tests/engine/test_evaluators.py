"""The evaluators ``compile()`` generates from the IR (ir/programs/evaluator.py, printed as Python and
numpy) on what test_paths.py's small random systems do not reach: table-driven rule sections
with sparse evaluation, merged smooth contributions with kink-cut integration, the numpy
renderer's if-conversion, and the caches of load()/compile()."""

from __future__ import annotations

import math
import os
from pathlib import Path

import numpy as np
import pytest

import fuzzyctl
from fuzzyctl import api, cache
from fuzzyctl.engine.controller import Controller
from fuzzyctl.engine.semantics import shapes
from fuzzyctl.ir.nodes import Assign, Bin, If, Num, Program, Var
from fuzzyctl.ir.programs.evaluator import TABLE_THRESHOLD, build_fast
from fuzzyctl.ir.render.npsrc import vectorise
from fuzzyctl.ir.render.pysrc import specialise
from tests.engine import bigsys

RANGE = bigsys.HI - bigsys.LO


def _inputs(n: int, seed: int) -> np.ndarray:
    return np.random.default_rng(seed).uniform(bigsys.LO - 0.2, bigsys.HI + 0.2, (n, 3))


def _check(plan_ctl: Controller, rows: np.ndarray, tol: float = 1e-9 * RANGE) -> None:
    """Generated Python (one row at a time) and numpy (all rows) against the interpreter."""
    ref = Controller(plan_ctl.plan, specialise=False)
    names = list(plan_ctl.inputs)
    batch = plan_ctl.evaluate_batch({n: rows[:, i] for i, n in enumerate(names)})["y"]
    plan_ctl.reset()
    for k, row in enumerate(rows):
        d = dict(zip(names, row, strict=True))
        want = ref.evaluate(d)["y"]
        got = plan_ctl.evaluate(d)["y"]
        assert abs(got - want) <= tol and abs(batch[k] - want) <= tol, (k, got, batch[k], want)


@pytest.mark.parametrize("kind", bigsys.KINDS)
@pytest.mark.parametrize("gaussian", [False, True])
def test_table_driven_rules_agree_with_the_interpreter(kind: str, gaussian: bool) -> None:
    """Above the threshold the rules are tables: sparse lookups for triangular partitions,
    the loop over every rule for Gaussian inputs (never 0), every output kind."""
    fb = bigsys.system(11, kind, gaussian_inputs=gaussian)
    ctl = fuzzyctl.compile(fb, backend="python")
    assert len(ctl.plan.rules) >= TABLE_THRESHOLD
    src = ctl._fast.__source__  # type: ignore[union-attr]
    assert "FZ_HKEY" in src and "for FZ_R" in src, "the sparse lookup and the loop over the table"
    assert "FZ_R17 =" not in src, "one loop, not one statement per rule"
    _check(ctl, _inputs(25, 3 + gaussian), tol=(1e-7 if kind == "smooth" else 1e-9) * RANGE)


def test_sparse_evaluation_visits_only_rules_that_can_fire() -> None:
    """With triangular partitions at most 2 terms per input are non-zero: the generated
    Python looks up at most 2^3 combinations, the rule loop is not run."""
    fb = bigsys.system(5, "mamdani")
    ctl = fuzzyctl.compile(fb, backend="python")
    fp = build_fast(ctl.plan, "py")
    fn = specialise(fp)
    calls = {"fire": 0}
    src = fn.__source__  # type: ignore[attr-defined]
    # count the rules whose slots are updated: instrument the generated source
    marker = "FZ_RD = "
    assert marker in src
    counted = src.replace(marker, "_count(); " + marker)
    env = dict(fn.__globals__)  # type: ignore[attr-defined]
    env["_count"] = lambda: calls.__setitem__("fire", calls["fire"] + 1)
    exec(compile(counted, "<counted>", "exec"), env)
    for row in _inputs(20, 9):
        calls["fire"] = 0
        want = Controller(ctl.plan, specialise=False).evaluate(dict(zip(ctl.inputs, row, strict=True)))["y"]
        got = env["_fast"](list(row), [None])[0]
        assert got == pytest.approx(want, abs=1e-12)
        assert calls["fire"] <= 8, calls


def _fine_cog(plan_ctl: Controller, row: np.ndarray) -> float:
    """A 4 million cell midpoint rule of the accumulated set (written from the plan's terms
    and the interpreter's rule degrees, not from the engine's integration)."""
    op = plan_ctl.plan.outputs[0]
    rec = Controller(plan_ctl.plan, specialise=False)._interp.run(list(row), [None])
    h = [0.0] * len(op.terms)
    for ri, r in enumerate(plan_ctl.plan.rules):
        (ah, w) = rec.conclusion_degrees[ri][0]
        t = r.conclusions[0].term
        assert t is not None
        h[t] = max(h[t], ah * w)
    u = np.linspace(bigsys.LO, bigsys.HI, 4_000_001)
    mid = 0.5 * (u[1:] + u[:-1])
    f = np.zeros_like(mid)
    for t, ht in zip(op.terms, h, strict=True):
        mu = shapes.membership_np(t.kind, [float(p) for p in t.params], 1.0, mid)  # type: ignore[arg-type]
        f = np.maximum(f, np.minimum(ht, mu))
    return float((f * mid).sum() / f.sum())


def test_merged_smooth_sets_are_exact_to_the_documented_tolerance() -> None:
    """343 Gaussian rules reach the integration as one set per output term (MIN/MAX), and
    the kink-cut integration agrees with an independent fine midpoint rule to 1e-9."""
    fb = bigsys.system(2, "smooth", gaussian_inputs=True, n_rules=343)
    # without WITH weights, so that the reference's merge is the plain maximum
    fb = _without_weights(fb)
    ctl = fuzzyctl.compile(fb, backend="python")
    rows = _inputs(6, 21)
    batch = ctl.evaluate_batch({n: rows[:, i] for i, n in enumerate(ctl.inputs)})["y"]
    for k, row in enumerate(rows):
        want = _fine_cog(ctl, row)
        assert abs(batch[k] - want) <= 1e-9 * RANGE, (k, batch[k], want)
        assert ctl.evaluate(dict(zip(ctl.inputs, row, strict=True)))["y"] == pytest.approx(
            batch[k], abs=1e-14
        )


def _without_weights(fb: fuzzyctl.model.FunctionBlock) -> fuzzyctl.model.FunctionBlock:
    import dataclasses

    rb = fb.rule_blocks[0]
    rules = tuple(
        dataclasses.replace(r, conclusions=tuple(dataclasses.replace(c, weight=None) for c in r.conclusions))
        for r in rb.rules
    )
    return dataclasses.replace(fb, rule_blocks=(dataclasses.replace(rb, rules=rules),))


def test_numpy_renderer_if_converts_conditions_on_samples() -> None:
    """IF/ELSIF/ELSE on values that differ between samples become masks; MIN written as
    an IF becomes numpy.minimum; conditions on constants stay Python control flow."""
    from fuzzyctl.ir.nodes import Decl
    from fuzzyctl.ir.programs.evaluator import FastProgram

    x, y, t = Var("FZ_IN0"), Var("FZ_OUT0"), Var("FZ_T")
    body = [
        Assign(t, Num(0.5)),
        If([(x.lt(t), [Assign(t, x)])]),  # t := min(0.5, x)
        If([(x.lt(-1.0), [Assign(y, Num(-1.0))]), (x.lt(1.0), [Assign(y, t * 2.0)])], [Assign(y, x)]),
        If([(Bin("<", Num(1.0), Num(2.0)), [Assign(y, y + 0.0)])]),
    ]
    decls = [Decl("FZ_IN0", "REAL", "input"), Decl("FZ_OUT0", "REAL", "output"), Decl("FZ_T", "REAL", "temp")]
    prog = Program("p", decls, body)
    plan = fuzzyctl.compile(fuzzyctl.load("examples/tank.fcl"), backend="interpreted").plan
    fp = FastProgram(prog, "np", ["FZ_IN0"], ["FZ_OUT0"], "FZ_PREV", plan)
    fn = vectorise(fp)
    src = fn.__source__  # type: ignore[attr-defined]
    assert "_np.minimum(FZ_T, FZ_IN0)" in src and "if (1.0 < 2.0):" in src
    xs = np.array([-3.0, -0.5, 0.2, 0.9, 4.0])
    want = [-1.0 if v < -1 else (2 * min(0.5, v) if v < 1 else v) for v in xs]
    assert list(fn([xs], [None], len(xs))[0]) == want


def test_plan_cache_is_keyed_by_content(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    """A file compiled before is not parsed or lowered again; changed content (or a changed
    fuzzyctl) is; a cached plan evaluates like a fresh one."""
    monkeypatch.setenv("FUZZYCTL_CACHE_DIR", str(tmp_path / "cache"))
    src = Path("examples/figure7.fcl").read_text()
    f = tmp_path / "f.fcl"
    f.write_text(src)
    first = fuzzyctl.compile(fuzzyctl.load(f), backend="python")
    plans = tmp_path / "cache" / "plans"
    assert len(list(plans.glob("*.pickle"))) == 1
    parsed = []
    import fuzzyctl.fcl as fcl_pkg

    real = fcl_pkg.load_file
    monkeypatch.setattr(fcl_pkg, "load_file", lambda p, **kw: parsed.append(p) or real(p, **kw))
    again = api.compile_path(f, backend="python")
    assert not parsed, "served from the cache"
    x = {"temp": 10.0, "pressure": 60.0}
    assert again.evaluate(x) == first.evaluate(x)
    f.write_text(src.replace("TERM high := (55, 0) (95, 1);", "TERM high := (55, 0) (90, 1);"))
    changed = api.compile_path(f, backend="python")
    assert parsed and changed.evaluate(x) != first.evaluate(x)
    assert len(list(plans.glob("*.pickle"))) == 2
    monkeypatch.setattr(cache, "code_fingerprint", lambda: "another fuzzyctl")
    parsed.clear()
    api.compile_path(f, backend="python")
    assert parsed, "a different fuzzyctl never reads what this one wrote"


def test_caches_can_be_turned_off_and_stay_bounded(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setenv("FUZZYCTL_CACHE_DIR", str(tmp_path / "c"))
    monkeypatch.setenv("FUZZYCTL_NO_CACHE", "1")
    fuzzyctl.compile(fuzzyctl.load("examples/tank.fcl"), backend="python")
    assert not (tmp_path / "c" / "plans").exists()
    d = tmp_path / "lru"
    d.mkdir()
    for i in range(5):
        p = d / f"{i}.so"
        p.write_bytes(b"x" * 1000)
        os.utime(p, (1000 + i, 1000 + i))
    cache.prune(d, 2500, keep=d / "0.so")
    assert sorted(p.name for p in d.iterdir()) == ["0.so", "4.so"]  # oldest gone, the kept one stays


def test_unknown_plan_switch_falls_back_to_the_interpreter() -> None:
    """A plan field the generator does not implement is refused there, so compile() still
    evaluates correctly (through the interpreter) instead of ignoring the switch."""
    import dataclasses

    from fuzzyctl.ir.programs import evaluator as fastprog

    ctl = fuzzyctl.compile(fuzzyctl.load("examples/figure7.fcl"), backend="python")
    known = dict(fastprog.KNOWN_FIELDS)
    known["Options"] = known["Options"] - {"quad_rtol"}
    plan = dataclasses.replace(ctl.plan, options=dataclasses.replace(ctl.plan.options, quad_rtol=1e-9))
    try:
        fastprog.KNOWN_FIELDS.clear()
        fastprog.KNOWN_FIELDS.update(known)
        c2 = Controller(plan)
        assert c2._fast is None and c2._batch is None
        assert math.isclose(c2.evaluate({"temp": 10, "pressure": 60})["valve"], 51.851851851851855)
    finally:
        fastprog.KNOWN_FIELDS.clear()
        fastprog.KNOWN_FIELDS.update(dict(known, Options=known["Options"] | {"quad_rtol"}))
