"""Interval type-2 systems: type reduction against brute force and closed forms, the exact
centroid interval against fine sampling, a degenerate type-2 system against the type-1
engine, MATLAB's type-2 FIS files, JSON, the conversions and the refusals."""

from __future__ import annotations

import dataclasses
import math
import random
from pathlib import Path

import numpy as np
import pytest

import fuzzyctl
from fuzzyctl import formats
from fuzzyctl import model as m
from fuzzyctl.diagnostics import DiagnosticError
from fuzzyctl.engine import type2_sets
from fuzzyctl.engine.type2 import Type2Controller, Type2Unsupported
from fuzzyctl.formats.common.type2 import to_type1
from fuzzyctl.kinds import type_reduction as tr
from tests.engine.type2_systems import random_it2, with_lower_equal_upper

EXAMPLE = "examples/tipper_type2.fis"


def brute_force(x: list[float], lo: list[float], up: list[float]) -> tuple[float, float]:
    """Every switch point tried: the least and the greatest weighted mean."""
    order = np.argsort(x)
    xs, lo_s, up_s = np.asarray(x)[order], np.asarray(lo)[order], np.asarray(up)[order]
    means_l, means_r = [], []
    for k in range(len(xs) + 1):
        wl = np.concatenate([up_s[:k], lo_s[k:]])
        wr = np.concatenate([lo_s[:k], up_s[k:]])
        if wl.sum() > 0:
            means_l.append(float((xs * wl).sum() / wl.sum()))
        if wr.sum() > 0:
            means_r.append(float((xs * wr).sum() / wr.sum()))
    return min(means_l), max(means_r)


def test_every_method_entry_is_complete_and_resolves() -> None:
    for code, entry in tr.METHODS.items():
        assert not tr.incomplete(entry), (code, tr.incomplete(entry))
        assert callable(tr.implementation(code))
        assert tr.spelled("fis")[tr.spelling(code, "fis")] == code


@pytest.mark.parametrize("code", sorted(tr.METHODS))
def test_methods_agree_with_brute_force(code: str) -> None:
    rng = random.Random(7)
    method = tr.implementation(code)
    for _ in range(300):
        n = rng.randint(1, 12)
        x = [rng.uniform(-10, 10) for _ in range(n)]
        lo = [rng.choice([0.0, rng.uniform(0, 1)]) for _ in range(n)]
        up = [a + rng.uniform(0, 1 - a) for a in lo]
        if sum(up) == 0.0:
            continue
        want = brute_force(x, lo, up)
        got = method(x, lo, up)
        assert got == pytest.approx(want, rel=1e-12, abs=1e-12), (code, x, lo, up)


def test_two_point_closed_form() -> None:
    # points 0 and 1 with weights [a1, b1], [a2, b2]: yl = a2/(b1+a2), yr = b2/(a1+b2)
    a1, b1, a2, b2 = 0.2, 0.7, 0.1, 0.6
    for code in tr.METHODS:
        yl, yr = tr.implementation(code)([0.0, 1.0], [a1, a2], [b1, b2])
        assert yl == pytest.approx(a2 / (b1 + a2), rel=1e-15)
        assert yr == pytest.approx(b2 / (a1 + b2), rel=1e-15)


def test_continuous_centroid_closed_form() -> None:
    # upper 1 and lower 1/2 on [0, 1]: yl solves s^2 = (1 - s)^2 / 2, i.e. 1 / (1 + sqrt 2)
    yl, yr = type2_sets.centroid_interval([0.0, 1.0], [(1.0, 1.0)], [(0.5, 0.5)])
    assert yl == pytest.approx(1.0 / (1.0 + math.sqrt(2.0)), rel=1e-15)
    assert yr == pytest.approx(1.0 - 1.0 / (1.0 + math.sqrt(2.0)), rel=1e-15)


@pytest.mark.parametrize("seed", range(6))
def test_exact_centroid_against_fine_sampling(seed: int) -> None:
    # The sampled end points (every sample weighing the same, as MATLAB's) converge to the
    # exact ones as h: the error shrinks about 4 times when h does, and stays below h.
    fb = random_it2(seed, explicit=seed % 2 == 1)
    exact = Type2Controller(fb)
    coarse, fine = Type2Controller(fb, samples=2001), Type2Controller(fb, samples=8001)
    grid = [{"x0": a, "x1": b} for a in np.linspace(0, 10, 9) for b in np.linspace(10, 0, 9)]
    x = next(x for x in grid if any(r.lower > 0.0 for r in exact.explain(x).rules))  # lower sets fire
    e = exact.explain(x).outputs[0]
    assert e.exact and e.yl < e.yr
    for end in ("yl", "yr"):
        err_coarse = abs(getattr(e, end) - getattr(coarse.explain(x).outputs[0], end))
        err_fine = abs(getattr(e, end) - getattr(fine.explain(x).outputs[0], end))
        assert err_coarse < 10.0 / 2000
        assert err_fine < err_coarse / 3.0 or err_fine < 1e-9, (end, err_coarse, err_fine)


@pytest.mark.parametrize("seed", range(8))
@pytest.mark.parametrize("sugeno", [False, True])
def test_lower_equal_upper_is_the_type1_engine(seed: int, sugeno: bool) -> None:
    fb = random_it2(seed, sugeno=sugeno)
    t2 = Type2Controller(with_lower_equal_upper(fb))
    t1 = fuzzyctl.compile(to_type1(fb), backend="interpreted")  # the upper functions alone
    rng = random.Random(seed)
    for _ in range(10):
        x = {"x0": rng.uniform(0, 10), "x1": rng.uniform(0, 10)}
        want = t1.evaluate(x)["y"]
        got = t2.evaluate(x)["y"]
        if sugeno:  # the same weighted mean, in the same order
            assert got == want, (x, got, want)
        else:  # the same integrals, summed in another order: within a few ulp (measured 2)
            assert got == pytest.approx(want, rel=1e-14, abs=1e-14), (x, got, want)


def test_interval_contains_the_value_and_methods_agree() -> None:
    fb = random_it2(3)
    values = {
        code: Type2Controller(fb, samples=501, method=code).explain(x0=4.0, x1=6.0) for code in tr.METHODS
    }
    first = values["KM"].outputs[0]
    assert first.yl <= first.value <= first.yr
    for e in values.values():
        o = e.outputs[0]
        assert (o.yl, o.yr) == pytest.approx((first.yl, first.yr), rel=1e-12)


def test_sugeno_firing_interval_rule_by_hand() -> None:
    fb = random_it2(11, sugeno=True)
    ctl = Type2Controller(fb)
    e = ctl.explain(x0=2.5, x1=7.0)
    for rule, fired in zip(fb.rule_blocks[0].rules, e.rules, strict=True):
        assert isinstance(rule.condition, m.And)
        los, ups = [], []
        for leaf in rule.condition.operands:
            assert isinstance(leaf, m.Is)
            term = fb.fuzzify_block(leaf.variable).term(leaf.term)  # type: ignore[union-attr]
            x = 2.5 if leaf.variable == "x0" else 7.0
            ups.append(type2_sets.mf_value(term.mf, x, ""))  # type: ignore[union-attr]
            los.append(type2_sets.lower_value(term, x, ""))  # type: ignore[arg-type]
        assert (fired.lower, fired.upper) == (min(los), min(ups))


def test_scale_lag_lower_of_a_triangle() -> None:
    term = m.Term("t", m.ShapeMF("triangle", (0.0, 5.0, 10.0)), lower=m.LowerMF(scale=0.8, lag=(0.2,)))
    # lower = 0.8 * (u - 0.2) / 0.8 = u - 0.2 where u > 0.2: at x = 2.5, u = 0.5
    assert type2_sets.lower_value(term, 2.5, "") == pytest.approx(0.3, rel=1e-15)
    assert type2_sets.lower_value(term, 0.5, "") == 0.0
    assert type2_sets.lower_value(term, 5.0, "") == pytest.approx(0.8, rel=1e-15)


def test_lower_above_upper_is_refused() -> None:
    fb = random_it2(1, explicit=True)
    bad = m.Term(
        "t0",
        m.ShapeMF("triangle", (0.0, 5.0, 10.0)),
        lower=m.LowerMF(mf=m.ShapeMF("triangle", (-1.0, 5.0, 11.0))),
    )
    f0 = dataclasses.replace(fb.fuzzify[0], terms=(bad, *fb.fuzzify[0].terms[1:]))
    with pytest.raises(Type2Unsupported, match=r"x0\.t0.*lower membership function .* exceeds the upper"):
        Type2Controller(dataclasses.replace(fb, fuzzify=(f0, *fb.fuzzify[1:])))


def test_matlab_fis_file_round_trip_and_values() -> None:
    doc = fuzzyctl.load(EXAMPLE)
    fb = doc.main
    assert fb.is_type2 and fb.defuzzify[0].type_reduction == "KM"
    rancid = fb.fuzzify_block("food").term("rancid")  # type: ignore[union-attr]
    assert rancid is not None and rancid.lower == m.LowerMF(scale=1.0, lag=(0.1, 0.3))
    text, losses = formats.convert(doc, "fis")
    assert not losses and "Type='mamdanitype2'" in text and "TypeReductionMethod='karnikmendel'" in text
    assert fuzzyctl.load(text, format="fis").main == fb
    ctl = fuzzyctl.compile(doc)
    e = ctl.explain(service=3.0, food=8.0)
    o = e.outputs[0]
    assert o.yl < o.value < o.yr and o.value == pytest.approx((o.yl + o.yr) / 2)


def test_json_round_trip() -> None:
    doc = fuzzyctl.load(EXAMPLE)
    text, losses = formats.convert(doc, "json")
    assert not losses
    assert fuzzyctl.load(text, format="json").main == doc.main
    explicit = m.Document((random_it2(2, explicit=True),))
    assert fuzzyctl.load(formats.convert(explicit, "json")[0], format="json").main == explicit.main


def test_fis_reader_errors_name_the_line() -> None:
    text = Path(EXAMPLE).read_text(encoding="utf-8").replace("'LowerScale',0.9", "'LowerScale',1.5")
    with pytest.raises(DiagnosticError, match="LowerScale must be one value in"):
        fuzzyctl.load(text, format="fis")
    text = Path(EXAMPLE).read_text(encoding="utf-8").replace("karnikmendel", "nosuch")
    with pytest.raises(DiagnosticError, match="TypeReductionMethod='nosuch' is not known"):
        fuzzyctl.load(text, format="fis")


def test_type1_targets_say_what_they_drop() -> None:
    doc = fuzzyctl.load(EXAMPLE)
    with pytest.raises(formats.LossError, match="no interval type-2 terms"):
        formats.convert(doc, "fll")
    text, losses = formats.convert(doc, "fll", lossy=True)
    assert any("type reduction" in str(loss) for loss in losses)
    assert not fuzzyctl.load(text, format="fll").main.is_type2


def test_explicit_lower_in_fis_is_a_loss() -> None:
    doc = m.Document((random_it2(4, explicit=True),))
    with pytest.raises(formats.LossError, match="LowerScale/LowerLag"):
        formats.convert(doc, "fis")


def test_native_backend_evaluates_type2() -> None:
    # (the native backend evaluates the IR program: tests/engine/test_type2_ir.py)
    assert fuzzyctl.compile(EXAMPLE, backend="python").evaluate(service=5, food=5)["tip"] > 0


def test_batch_matches_single_rows() -> None:
    ctl = fuzzyctl.compile(EXAMPLE)
    xs = np.linspace(0, 10, 7)
    out = ctl.evaluate_batch({"service": xs, "food": xs[::-1]})
    for i, x in enumerate(xs):
        assert out["tip"][i] == ctl.evaluate(service=x, food=xs[::-1][i])["tip"]


def _gaussian_system(lower_sigma: float) -> m.FunctionBlock:
    def g(name: str, mean: float) -> m.Term:
        upper = m.ShapeMF("gaussian", (mean, 2.0))
        return m.Term(name, upper, lower=m.LowerMF(mf=m.ShapeMF("gaussian", (mean, lower_sigma), 0.8)))

    return m.FunctionBlock(
        "g",
        (m.Variable("x", m.VarKind.INPUT, range=m.Range(0, 10)), m.Variable("y", m.VarKind.OUTPUT)),
        (m.FuzzifyBlock("x", (g("lo", 0.0), g("hi", 10.0)), m.Range(0, 10)),),
        (m.DefuzzifyBlock("y", (g("a", 2.0), g("b", 8.0)), m.Range(0, 10), "COG", type_reduction="EIASC"),),
        (
            m.RuleBlock(
                "r",
                (
                    m.Rule("1", m.Is("x", "lo"), (m.Conclusion("y", "a"),)),
                    m.Rule("2", m.Is("x", "hi"), (m.Conclusion("y", "b"),)),
                ),
            ),
        ),
    )


def test_smooth_output_sets_are_sampled_and_brute_force_agrees() -> None:
    fb = _gaussian_system(1.5)
    ctl = Type2Controller(fb, samples=201)
    o = ctl.explain(x=3.0).outputs[0]
    assert not o.exact and o.method == "EIASC"
    # the same discrete problem, every switch point tried
    ys = np.linspace(0, 10, 201)
    lo_f = [(0.8 * math.exp(-(3.0**2) / (2 * 1.5**2))), 0.8 * math.exp(-(7.0**2) / (2 * 1.5**2))]
    up_f = [math.exp(-(3.0**2) / 8), math.exp(-(7.0**2) / 8)]
    lower = np.maximum(
        np.minimum(lo_f[0], 0.8 * np.exp(-((ys - 2) ** 2) / (2 * 1.5**2))),
        np.minimum(lo_f[1], 0.8 * np.exp(-((ys - 8) ** 2) / (2 * 1.5**2))),
    )
    upper = np.maximum(
        np.minimum(up_f[0], np.exp(-((ys - 2) ** 2) / 8)), np.minimum(up_f[1], np.exp(-((ys - 8) ** 2) / 8))
    )
    assert (o.yl, o.yr) == pytest.approx(brute_force(list(ys), list(lower), list(upper)), rel=1e-12)


def test_smooth_lower_above_upper_is_found_by_sampling() -> None:
    with pytest.raises(Type2Unsupported, match="exceeds the upper"):
        Type2Controller(_gaussian_system(2.5))  # wider than the upper: above it in the tails
