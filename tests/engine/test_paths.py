"""The specialised scalar path, the numpy batch path and the interpreter compute the same
thing, and all agree with an independent brute-force reference (tests/engine/reference.py)."""

from __future__ import annotations

import math

import numpy as np
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

import fuzzyctl
from tests.engine import reference
from tests.engine.randsys import HI, LO, describe, input_values, system

RANGE = HI - LO


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
    method = fb.defuzzify[0].method
    for s in input_values(data.draw, fb, 2):
        got = c.evaluate(s)["y"]
        want = reference.evaluate(fb, s)["y"]
        if math.isnan(want):
            assert got == -1.0  # the DEFAULT of the random systems
        elif abs(got - want) > 2.5e-5 * RANGE and method in ("LM", "RM", "MOM"):
            # an ill-conditioned maximum (two maxima within 1e-12 of each other): the answer
            # must lie between the references with a strict and a loose tolerance
            loose = reference.evaluate(fb, s, max_tol=1e-7)["y"]
            lo, hi = min(want, loose), max(want, loose)
            assert lo - 1e-3 * RANGE <= got <= hi + 1e-3 * RANGE, (got, want, loose, s, describe(fb))
        else:
            assert abs(got - want) <= 2.5e-5 * RANGE, (got, want, s, describe(fb))


@settings(max_examples=12, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(st.data())
def test_smooth_output_quadrature_matches_brute_force_reference(data: st.DataObject) -> None:
    fb = data.draw(system(smooth_output=True, accus=("MAX", "BSUM", "SUM", "PROBOR")))
    c = fuzzyctl.compile(fb)
    assert not c.plan.outputs[0].exact
    for s in input_values(data.draw, fb, 2):
        got = c.evaluate(s)["y"]
        want = reference.evaluate(fb, s)["y"]
        if math.isnan(want):
            assert got == -1.0
        elif abs(got - want) > 2.5e-5 * RANGE and fb.defuzzify[0].method in ("LM", "RM", "MOM"):
            loose = reference.evaluate(fb, s, max_tol=1e-7)["y"]  # an ill-conditioned maximum
            lo, hi = min(want, loose), max(want, loose)
            assert lo - 1e-3 * RANGE <= got <= hi + 1e-3 * RANGE, (got, want, loose, s, describe(fb))
        else:
            assert abs(got - want) <= 2.5e-5 * RANGE, (got, want, s, describe(fb))
        batch = c.evaluate_batch({k: np.array([v]) for k, v in s.items()})["y"][0]
        assert abs(batch - got) <= 1e-9 * RANGE
