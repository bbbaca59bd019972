"""The specialised scalar path, the numpy batch path and the interpreter compute the same
thing, and all agree with an independent brute-force reference (tests/engine/reference.py)."""

from __future__ import annotations

import math

import numpy as np
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

import fuzzyctl
from fuzzyctl import model as m
from fuzzyctl.engine.controller import Controller
from tests.engine import reference
from tests.engine.randsys import HI, LO, describe, input_values, system

RANGE = HI - LO


def _check_against_reference(c: Controller, fb: m.FunctionBlock, s: dict[str, float]) -> None:
    """The scalar and batch paths against the brute-force reference, within two cells."""
    got = c.evaluate(s)["y"]
    batch = float(c.evaluate_batch({k: np.array([v]) for k, v in s.items()})["y"][0])
    want = reference.evaluate(fb, s)["y"]
    if math.isnan(want) != (got == -1.0) or (got == -1.0) != (batch == -1.0):
        # Fired or not (-1.0 is the random systems' DEFAULT) differs only when the strongest
        # rule degree is rounding noise: 1 - (a + b - a*b) is 0 or 1e-16 depending on the
        # last bit of an exp() in numpy or libm.
        strongest = max(r.degree for r in c.explain(s).rules)
        assert strongest < 1e-12, (got, batch, want, strongest, s, describe(fb))
        return
    if math.isnan(want):
        return
    if abs(got - want) <= 2.5e-5 * RANGE and abs(batch - got) <= 1e-9 * RANGE:
        return
    # A maximum can be ill-conditioned: two maxima within 1e-12 of each other, or a smooth
    # peak flat to rounding (1-(1-g)^4 is exactly 1.0 in double within +-0.014 of a unit
    # Gaussian's peak).  LM may then be any point of the first near-maximal stretch, RM any
    # of the last, MoM anything between; scalar and batch may pick different points.
    method = fb.defuzzify[0].method
    assert method in ("LM", "RM", "MOM"), (got, batch, want, s, describe(fb))
    runs: dict[str, list[tuple[float, float]]] = {}
    reference.evaluate(fb, s, max_tol=1e-7, runs=runs)
    stretches = runs.get("y") or [(want, want)]  # only a term breakpoint reaches it
    first, last = stretches[0], stretches[-1]
    lo, hi = {"LM": first, "RM": last, "MOM": (first[0], last[1])}[method]
    lo, hi = lo - 1e-3 * RANGE, hi + 1e-3 * RANGE
    assert lo <= got <= hi and lo <= batch <= hi, (got, batch, want, runs, s, describe(fb))


def _close(a: float, b: float, tol: float) -> bool:
    return (math.isnan(a) and math.isnan(b)) or abs(a - b) <= tol


@settings(max_examples=80, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(st.data())
def test_specialised_batch_and_interpreter_agree(data: st.DataObject) -> None:
    fb = data.draw(system())
    samples = input_values(data.draw, fb, 6)
    c = fuzzyctl.compile(fb)
    fast = [c.evaluate(s)["y"] for s in samples]
    interp = [c.evaluate_reference(s)["y"] for s in samples]
    batch = c.evaluate_batch({v.name: [s[v.name] for s in samples] for v in fb.inputs})["y"]
    for f, i, b in zip(fast, interp, batch, strict=True):
        assert _close(f, i, 1e-9 * RANGE), (f, i)
        assert _close(float(b), i, 1e-9 * RANGE), (b, i)


@settings(max_examples=30, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(st.data())
def test_exact_engine_matches_brute_force_reference(data: st.DataObject) -> None:
    """Piecewise-linear outputs, every method, activation and accumulation: within two cells
    of a 10^6-cell midpoint reference."""
    fb = data.draw(system())
    c = fuzzyctl.compile(fb)
    assert c.plan.outputs[0].exact
    for s in input_values(data.draw, fb, 2):
        _check_against_reference(c, fb, s)


@settings(max_examples=12, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(st.data())
def test_smooth_output_quadrature_matches_brute_force_reference(data: st.DataObject) -> None:
    fb = data.draw(system(smooth_output=True, accus=("MAX", "BSUM", "SUM", "PROBOR")))
    c = fuzzyctl.compile(fb)
    assert not c.plan.outputs[0].exact
    for s in input_values(data.draw, fb, 2):
        _check_against_reference(c, fb, s)
