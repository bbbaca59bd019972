"""The native evaluator's C stays small enough to compile in seconds: an exact output whose
straight-line form would be huge (a 3-input, 50-rule system with weighted conclusions came
to 28 MB of C and 150 s of ``cc -O3``) takes the run-time grid's loops, with the same numbers."""

from __future__ import annotations

import numpy as np
import pytest

import fuzzyctl
from fuzzyctl.api import compile_plan
from fuzzyctl.engine import native
from fuzzyctl.ir.builders import grid_pieces as GP
from tests.codegen.fixed_systems import random_mamdani_fcl


@pytest.mark.parametrize("method", ["LM", "RM", "MOM", "COA"])
def test_a_large_exact_output_is_written_with_loops(method: str, monkeypatch: pytest.MonkeyPatch) -> None:
    model = fuzzyctl.load(random_mamdani_fcl(0, method))
    _key, files = native.sources(compile_plan(model))
    looped = sum(len(v) for v in files.values())
    assert looped < 300_000
    # the unrolled form of the same output is what the limit avoids
    monkeypatch.setattr(GP, "UNROLL_LIMIT", 10**9)
    _key, files = native.sources(compile_plan(model))
    assert sum(len(v) for v in files.values()) > 20 * looped


@pytest.mark.skipif(native.compiler() is None, reason="no C compiler")
@pytest.mark.parametrize("method", ["LM", "MOM", "COA"])
def test_the_looped_form_agrees_with_the_reference(method: str) -> None:
    model = fuzzyctl.load(random_mamdani_fcl(0, method))
    nat = fuzzyctl.compile(model, backend="native")
    ref = fuzzyctl.compile(model, backend="interpreted")
    rng = np.random.default_rng(5)
    spans = {"in0": (3.7, 103.7), "in1": (-0.25, 2.25), "in2": (-50.0, -49.0)}
    cols = {v: rng.uniform(lo, hi, 400) for v, (lo, hi) in spans.items()}
    got, want = nat.evaluate_batch(cols)["out"], ref.evaluate_batch(cols)["out"]
    assert np.allclose(got, want, rtol=0.0, atol=1e-9 * 5000.0, equal_nan=True)
