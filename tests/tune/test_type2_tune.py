"""Tuning interval type-2 systems (docs/type2.md, "Tune"): every candidate keeps each lower
function below its upper one (checked on every decoded candidate with the engine's exact
checker), tuning against data a known type-2 system generated lowers the cost, an explicit
lower function is projected by the closed-form factor, and widening a type-1 system
(``tune(widen=True)``, ``learn(type2=True)``) never does worse than the type-1 system on
noisy data (the type-1 cost computed here with the type-1 engine)."""

from __future__ import annotations

import dataclasses
import math
from typing import Any

import numpy as np
import pytest

import fuzzyctl
from fuzzyctl.diagnostics import FuzzyctlError
from fuzzyctl.engine import type2_sets as sets
from fuzzyctl.formats.common.type2 import to_type1
from fuzzyctl.model import FunctionBlock, LowerMF, ShapeMF, Term
from fuzzyctl.tune import tune
from fuzzyctl.tune import type2 as t2
from fuzzyctl.tune.learning import learn
from fuzzyctl.tune.space import Space, build_space
from tests.conftest import EXAMPLES

FIS = EXAMPLES / "tipper_type2.fis"


def target() -> FunctionBlock:
    return fuzzyctl.load(FIS).main


def data(rows: int = 48, noise: float = 0.0, seed: int = 1) -> dict[str, Any]:
    ctl = fuzzyctl.compile(target())
    rng = np.random.default_rng(seed)
    x = rng.uniform(0, 10, (rows, 2))
    y = np.array([ctl.evaluate(service=a, food=b)["tip"] for a, b in x])
    return {"service": x[:, 0], "food": x[:, 1], "tip": y + rng.normal(0, noise, rows) if noise else y}


def problems(fb: FunctionBlock) -> list[str]:
    out = []
    for blk in (*fb.fuzzify, *fb.defuzzify):
        span = (blk.range.low, blk.range.high) if blk.range else (-1.0, 1.0)
        for t in blk.terms:
            p = sets.lower_problem(t, span, f"{blk.variable}.{t.name}")
            if p:
                out.append(p)
    return out


def each_term(fb: FunctionBlock, change: Any) -> FunctionBlock:
    return dataclasses.replace(
        fb,
        fuzzify=tuple(dataclasses.replace(f, terms=tuple(change(t) for t in f.terms)) for f in fb.fuzzify),
        defuzzify=tuple(
            dataclasses.replace(d, terms=tuple(change(t) for t in d.terms)) for d in fb.defuzzify
        ),
    )


@pytest.fixture
def watched(monkeypatch: pytest.MonkeyPatch) -> list[int]:
    """Every candidate any tuner decodes is checked: lower <= upper everywhere."""
    seen = [0]
    decode = Space.decode

    def checked(self: Space, u: Any, *, digits: int | None = None) -> FunctionBlock:
        fb = decode(self, u, digits=digits)
        assert problems(fb) == [], problems(fb)
        seen[0] += 1
        return fb

    monkeypatch.setattr(Space, "decode", checked)
    return seen


def moved_lowers(t: Term) -> Term:
    if t.lower is None:
        return t
    return dataclasses.replace(t, lower=LowerMF(None, 0.5, tuple(min(0.9, v + 0.4) for v in t.lower.lag)))


def test_scale_lag_tuned_against_a_type2_system(watched: list[int]) -> None:
    start = each_term(target(), moved_lowers)
    r = tune(start, data=data(), free="all", budget=80, workers=0, validation=0.0)
    # measured: training RMSE 0.928 -> 0.826 in 80 evaluations (0.922 -> 0.450 in 150 on 40 rows)
    assert r.after < 0.95 * r.before
    assert watched[0] > 20 and problems(r.block) == []
    for blk in r.block.fuzzify:
        for t in blk.terms:
            assert t.lower is not None and t2.SCALE_MIN <= t.lower.scale <= 1.0
            assert all(0.0 <= v <= t2.LAG_MAX for v in t.lower.lag)


def test_explicit_lower_projected_below_the_upper() -> None:
    # upper TRIAN 0 5 10, lower TRAPE 1 4 6 9: above the upper around the peak; the
    # largest factor keeping it below is 0.8 (at x = 4 and 6: 0.8 / 1; on [1, 4] the ratio
    # 3x / (5 (x - 1)) decreases to 0.8)
    term = Term(
        "t", ShapeMF("triangle", (0.0, 5.0, 10.0)), lower=LowerMF(ShapeMF("trapezoid", (1.0, 4.0, 6.0, 9.0)))
    )
    fb = dataclasses.replace(target(), fuzzify=(dataclasses.replace(target().fuzzify[0], terms=(term,)),))
    assert "exceeds" in (sets.lower_problem(term, (0, 10), "t") or "")
    projected = t2.project(fb).fuzzify[0].terms[0]
    assert projected.lower is not None and isinstance(projected.lower.mf, ShapeMF)
    assert float(projected.lower.mf.height) == pytest.approx(0.8, rel=1e-11)  # type: ignore[arg-type]
    assert sets.lower_problem(projected, (0, 10), "t") is None


def test_explicit_lowers_stay_below_while_tuned(watched: list[int]) -> None:
    def explicit(t: Term) -> Term:
        if t.lower is None or not isinstance(t.mf, ShapeMF):
            return t
        return dataclasses.replace(t, lower=LowerMF(dataclasses.replace(t.mf, height=0.6)))

    start = each_term(target(), explicit)
    assert problems(start) == []
    r = tune(start, data=data(), free="inputs", budget=60, workers=0, validation=0.0)
    assert r.after < r.before and watched[0] > 10 and problems(r.block) == []


def type1_rmse(fb: FunctionBlock, d: dict[str, Any]) -> float:
    ctl = fuzzyctl.compile(fb)
    pred = ctl.evaluate_batch({"service": d["service"], "food": d["food"]})["tip"]
    return math.sqrt(float(np.mean((pred - d["tip"]) ** 2)))


def test_widening_a_type1_system_never_does_worse(watched: list[int]) -> None:
    d = data(noise=0.5, seed=4)
    t1 = to_type1(target())
    assert not t1.is_type2
    before = type1_rmse(t1, d)
    r = tune(t1, data=d, widen=True, budget=60, workers=0, validation=0.0)
    assert r.block.is_type2 and problems(r.block) == []
    assert r.before == pytest.approx(before, rel=1e-12)  # lower = upper: the type-1 outputs
    assert r.after < before
    # only the lower functions moved
    assert [t.mf for f in r.block.fuzzify for t in f.terms] == [t.mf for f in t1.fuzzify for t in f.terms]


def test_learn_type2_no_worse_than_type1_on_noisy_data() -> None:
    rng = np.random.default_rng(3)
    x, z = rng.uniform(0, 10, 100), rng.uniform(0, 10, 100)
    cols = {"x": x, "z": z, "y": np.sin(x / 2) + 0.1 * z + rng.normal(0, 0.2, 100)}
    one = learn(cols, inputs=["x", "z"], output="y", terms=3, validation=0.0)
    two = learn(cols, inputs=["x", "z"], output="y", terms=3, validation=0.0, type2=True, budget=40)
    assert two.block.is_type2 and not one.block.is_type2 and problems(two.block) == []
    assert two.scores["training RMSE"] <= one.scores["training RMSE"] * (1 + 1e-12)
    with pytest.raises(FuzzyctlError, match="--type2 needs --type tsk"):
        learn(cols, inputs=["x", "z"], output="y", kind="mamdani", type2=True)


def test_space_frees_the_lower_parameters() -> None:
    space = build_space(target(), "food.rancid")
    labels = [space.slots[k].label for k in space.free_keys]
    assert "food.rancid lower scale" in labels
    assert "food.rancid lower lag left" in labels and "food.rancid lower lag right" in labels
    # as written, the space decodes to the system (scale and lags within the boxes)
    fb = space.decode(space.initial())
    assert fb.fuzzify[1].terms[0].lower == target().fuzzify[1].terms[0].lower


def test_cli_learn_type2_and_widen(tmp_path: Any, capsys: pytest.CaptureFixture[str]) -> None:
    from fuzzyctl.cli.app import main

    rng = np.random.default_rng(5)
    x, z = rng.uniform(0, 10, 60), rng.uniform(0, 10, 60)
    y = np.sin(x / 2) + 0.1 * z + rng.normal(0, 0.2, 60)
    csv = tmp_path / "d.csv"
    csv.write_text("x,z,y\n" + "".join(f"{a},{b},{c}\n" for a, b, c in zip(x, z, y, strict=True)))
    out = tmp_path / "t2.fcl"
    argv = ["learn", str(csv), "--inputs", "x,z", "--target", "y", "--terms", "2", "--type2", "-o", str(out)]
    assert main(argv) == 0
    assert "interval type-2: training RMSE" in capsys.readouterr().out
    learned = fuzzyctl.load(out).main
    assert learned.is_type2 and problems(learned) == []
    # a system with singleton outputs (COGS) has no interval type-2 form: said, exit 1
    crane = EXAMPLES / "crane.fcl"
    data_csv = tmp_path / "c.csv"
    data_csv.write_text("distance,angle,power\n1,0,0\n5,2,10\n", encoding="utf-8")
    argv = ["tune", str(crane), "--data", str(data_csv), "--widen", "-o", str(tmp_path / "c.fcl")]
    assert main(argv) == 1
    err = capsys.readouterr().err.replace("\n", " ")
    assert "--widen" in err and "COGS" in err
