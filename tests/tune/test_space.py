"""The parameter space: every candidate is a valid system (points ascending, inside the
universe, weights in [0, 1], coverage kept), on random systems and random vectors."""

from __future__ import annotations

import numpy as np
import pytest

import fuzzyctl
from fuzzyctl.engine.semantics.shapes import membership_np
from fuzzyctl.fcl import load_text, write
from fuzzyctl.model import (
    Conclusion,
    DefuzzifyBlock,
    FunctionBlock,
    FuzzifyBlock,
    Is,
    Point,
    PointsMF,
    Range,
    Rule,
    RuleBlock,
    ShapeMF,
    SingletonMF,
    Term,
    Variable,
    VarKind,
)
from fuzzyctl.tune.space import DELTA, SpaceError, build_space, catalogue
from tests.conftest import EXAMPLES


def random_block(rng: np.random.Generator) -> FunctionBlock:
    """Two inputs with irregular partitions (IEC points, triangles, a Gaussian), sometimes
    with a RANGE wider than the terms, a singleton output and weighted rules."""
    fuzz = []
    for name in ("a", "b"):
        k = int(rng.integers(2, 6))
        xs = np.sort(rng.choice(np.arange(-50, 51), size=k + 2, replace=False)).astype(float)
        terms = []
        for j in range(k):
            lo, mid, hi = xs[j], xs[j + 1], xs[j + 2]
            if j == 0:
                mf = PointsMF((Point(lo, 1.0), Point(mid, 1.0), Point(hi, 0.0)))
            elif j == k - 1:
                mf = PointsMF((Point(lo, 0.0), Point(mid, 1.0), Point(hi, 1.0)))
            elif rng.random() < 0.5:
                mf = ShapeMF("triangle", (lo, mid, hi))
            else:
                mf = PointsMF((Point(lo, 0.0), Point(mid, 0.7), Point(hi, 0.0)))
            terms.append(Term(f"t{j}", mf))
        if rng.random() < 0.5:
            terms.append(Term("g", ShapeMF("gaussian", (float(xs[1] + 1.0), float(rng.uniform(1, 10))))))
        rng_ = Range(float(xs[0] - 5), float(xs[-1] + 5)) if rng.random() < 0.5 else None
        fuzz.append(FuzzifyBlock(name, tuple(terms), rng_))
    outs = tuple(Term(f"o{j}", SingletonMF(float(v))) for j, v in enumerate(sorted(rng.uniform(-10, 10, 4))))
    rules = []
    for r in range(6):
        ta = fuzz[0].terms[int(rng.integers(len(fuzz[0].terms)))].name
        tb = fuzz[1].terms[int(rng.integers(len(fuzz[1].terms)))].name
        w = float(rng.uniform(0.2, 1.0)) if rng.random() < 0.5 else None
        rules.append(
            Rule(str(r + 1), _and(Is("a", ta), Is("b", tb)), (Conclusion("y", outs[r % 4].name, w),))
        )
    return FunctionBlock(
        "r",
        (Variable("a", VarKind.INPUT), Variable("b", VarKind.INPUT), Variable("y", VarKind.OUTPUT)),
        tuple(fuzz),
        (DefuzzifyBlock("y", outs, Range(-10.0, 10.0), "COGS"),),
        (RuleBlock("rules", tuple(rules), and_op="MIN", accu="MAX"),),
    )


def _and(*c: Is) -> object:
    from fuzzyctl.model import And

    return And(tuple(c))


def abscissae(fb: FunctionBlock, var: str) -> list[float]:
    return [s.value for s in catalogue(fb).values() if s.variable == var and s.role == "x"]


def covered(fb: FunctionBlock, var: str, xs: np.ndarray) -> np.ndarray:
    plan = fuzzyctl.compile(fb, backend="interpreted").plan
    fi = next(f for f in plan.fuzzy_inputs if f.name == var)
    return np.max([membership_np(t.kind, t.params, t.height, xs) for t in fi.terms], axis=0) > 0.0


@pytest.mark.parametrize("seed", range(12))
def test_random_candidates_are_valid(seed: int) -> None:
    rng = np.random.default_rng(seed)
    fb = random_block(rng)
    space = build_space(fb, "all,weights")
    for _ in range(6):
        u = rng.random(space.size) * 1.4 - 0.2  # also outside the box: decode clips
        cand = space.decode(u)
        for blk in cand.fuzzify:
            orig = fb.fuzzify_block(blk.variable)
            assert orig is not None
            before, after = abscissae(fb, blk.variable), abscissae(cand, blk.variable)
            # every abscissa keeps its order (and its ties) relative to every other one
            assert np.array_equal(np.argsort(before, kind="stable"), np.argsort(after, kind="stable"))
            assert len(set(before)) == len(set(after))
            lo, hi = (orig.range.low, orig.range.high) if orig.range else (min(before), max(before))
            assert min(after) >= lo and max(after) <= hi
            for t in blk.terms:
                if isinstance(t.mf, PointsMF):
                    xs = [float(p.x) for p in t.mf.points]  # type: ignore[arg-type]
                    assert xs == sorted(xs)
            # coverage: wherever the written system has a term > 0, so does the candidate
            grid = np.linspace(lo, hi, 801)
            if covered(fb, blk.variable, np.array(before)).all() and covered(fb, blk.variable, grid).all():
                assert covered(cand, blk.variable, grid).all()
                assert covered(cand, blk.variable, np.array(after)).all()
        for rb in cand.rule_blocks:
            for rule in rb.rules:
                for c in rule.conclusions:
                    assert c.weight is None or 0.0 <= float(c.weight) <= 1.0  # type: ignore[arg-type]
        ys = [float(t.mf.value) for t in cand.defuzzify[0].terms]  # type: ignore[union-attr, arg-type]
        assert ys == sorted(ys) and min(ys) >= -10.0 and max(ys) <= 10.0
        fuzzyctl.compile(cand)  # and the engine takes it


def test_initial_vector_reproduces_the_system() -> None:
    fb = fuzzyctl.load(EXAMPLES / "crane.fcl").main
    space = build_space(fb, "all,weights")
    again = space.decode(space.initial())
    values = space.values(space.initial())
    for key, slot in space.slots.items():
        assert abs(values.get(key, slot.value) - slot.value) <= 2 * DELTA * 200  # span of power
    assert space.changes(space.initial(), digits=6) == []
    assert fuzzyctl.compile(again).evaluate({"distance": 7.0, "angle": 3.0})["power"] == pytest.approx(
        fuzzyctl.compile(fb).evaluate({"distance": 7.0, "angle": 3.0})["power"], abs=1e-6
    )


def test_crane_space_ends_fixed_and_shared_points_move_together() -> None:
    fb = fuzzyctl.load(EXAMPLES / "crane.fcl").main
    space = build_space(fb, "all")
    # distance: -4 and 20 are the universe's ends (no RANGE); 0, 4, 10 move; same for angle
    # (-15, 15) and power (singletons -100 .. 100)
    assert space.size == 9
    cand = space.decode(np.full(space.size, 0.3))
    close = cand.fuzzify_block("distance").term("close")  # type: ignore[union-attr]
    medium = cand.fuzzify_block("distance").term("medium")  # type: ignore[union-attr]
    assert close.mf.points[1].x == medium.mf.points[0].x  # type: ignore[union-attr]
    assert cand.fuzzify_block("distance").term("too_far").mf.points[0].x == -4.0  # type: ignore[union-attr]
    assert cand.defuzzify_block("power").term("pos_high").mf.value == 100.0  # type: ignore[union-attr]


def test_free_a_single_term_keeps_the_others() -> None:
    fb = fuzzyctl.load(EXAMPLES / "crane.fcl").main
    space = build_space(fb, "angle.zero")
    assert space.size == 3  # its three points are breakpoints shared with the neighbours
    cand = space.decode(np.full(space.size, 0.9))
    assert cand.fuzzify_block("distance") == fb.fuzzify_block("distance")
    assert cand.defuzzify == fb.defuzzify
    assert build_space(fb, "all,-angle,-distance").size == 3


def test_written_candidate_reads_back_equal(tmp_path: object) -> None:
    fb = fuzzyctl.load(EXAMPLES / "crane.fcl").main
    space = build_space(fb, "all,weights")
    cand = space.decode(np.random.default_rng(3).random(space.size), digits=6)
    back = load_text(write(cand)).raise_for_errors().main
    assert back == cand
    assert back.comments == fb.comments  # comments are kept


@pytest.mark.parametrize(
    ("spec", "message"),
    [
        ("speed", "not a variable"),
        ("angle.huge", "angle has no term 'huge'"),
        ("-all", "nothing to tune"),
    ],
)
def test_bad_free_specifications(spec: str, message: str) -> None:
    fb = fuzzyctl.load(EXAMPLES / "crane.fcl").main
    with pytest.raises(SpaceError, match=message):
        build_space(fb, spec)
