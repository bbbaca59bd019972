"""Generated C of smooth outputs (the IR quadrature of :mod:`fuzzyctl.ir.builders.quadrature`)
under every activation and accumulation (tests/engine/opsweep.py) against the reference
interpreter: within 1e-9 of the output range, and within the error bound the generated header
states for that output (its coefficient times range^2 / area, the area from the independent
brute-force oracle tests/engine/bruteforce.py).

``make test`` runs all 63 pairs on one system of smooth terms and nine pairs on one of PWL
terms; ``make fuzz`` (HYPOTHESIS_PROFILE=fuzz) all 63 pairs on fresh seeds."""

from __future__ import annotations

import dataclasses
import math
import os
import re
import warnings
from pathlib import Path

import numpy as np
import pytest
from hypothesis import HealthCheck, Phase, given, settings
from hypothesis import strategies as st

import fuzzyctl
from fuzzyctl import model as m
from tests.codegen.test_c import build_library, run
from tests.engine import bruteforce, opsweep

TOL = 1e-9  # of the output range
FUZZ = os.environ.get("HYPOTHESIS_PROFILE") == "fuzz"
BOUND = re.compile(r"output (\w+): smooth set.*?\|CoG error\| <= ([0-9.e+-]+) x \(high - low\)\^2 / area")


def _area(fb: m.FunctionBlock, row: dict[str, float], out: str) -> float:
    f, _n = bruteforce.accumulated(fb, row, out)
    u = np.linspace(opsweep.LO, opsweep.HI, 200_001)
    return float(np.trapezoid(f(u), u))


def check(fb: m.FunctionBlock, rows: list[dict[str, float]], tmp: Path, name: str) -> list[str]:
    """Disagreements between the generated C and the reference, and with the header's bound."""
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        ref = fuzzyctl.compile(fb, backend="interpreted")
    plan = dataclasses.replace(ref.plan, name=name)
    lib = build_library([plan], tmp)
    text = (tmp / f"{name}.c").read_text() + (tmp / f"{name}.h").read_text()
    bounds = {o: float(c) for o, c in BOUND.findall(text)}
    outs = [o.name for o in plan.outputs if o.is_output]
    smooth = [o.name for o in plan.outputs if o.is_output and o.kind == "mamdani" and not o.exact]
    assert set(smooth) <= set(bounds), "every smooth output states its bound in the header"
    got = run(lib, plan, np.array([[r[n] for n in ref.inputs] for r in rows]))
    span = opsweep.HI - opsweep.LO
    bad = []
    for i, row in enumerate(rows):
        want = ref.evaluate(row)
        for j, out in enumerate(outs):
            d = abs(got[i, j] - want[out])
            if not d <= TOL * span:
                bad.append(f"{out} {row}: C {got[i, j]!r} != interpreted {want[out]!r}")
            elif out in bounds and want[out] != -1.0 and i < 3:
                # the stated bound, against the oracle's CoG (the reference aims at 1e-10)
                area = _area(fb, row, out)
                exact = bruteforce.evaluate(fb, row, out)
                e = abs(got[i, j] - exact)
                stated = bounds[out] * span**2 / area if area > 0 else math.inf
                if e > stated + 4e-16 * span:  # + the rounding of the CoG itself
                    bad.append(f"{out} {row}: |C - brute force| {e:.2e} > stated bound {stated:.2e}")
    return bad


@pytest.mark.parametrize(("seed", "smooth", "pairs"), [(1, True, "all"), (2, False, "some")])
def test_generated_c_of_every_operator_agrees_with_the_reference(
    seed: int, smooth: bool, pairs: str, tmp_path: Path
) -> None:
    chosen = opsweep.all_pairs() if pairs == "all" else opsweep.some_pairs(seed)
    fb = opsweep.system(seed, smooth, chosen)
    assert not check(fb, opsweep.inputs(seed, 8), tmp_path, f"acc{seed}")


@settings(
    max_examples=8 if FUZZ else 1,
    deadline=None,
    derandomize=not FUZZ,
    phases=(Phase.explicit, Phase.generate),
    suppress_health_check=list(HealthCheck),
)
@given(seed=st.integers(0, 2**31 - 1), smooth=st.booleans())
def test_generated_c_all_pairs_on_fresh_seeds(
    seed: int, smooth: bool, tmp_path_factory: pytest.TempPathFactory
) -> None:
    """All 63 activation x accumulation pairs (make fuzz only)."""
    if not FUZZ:
        pytest.skip("the 63-pair sweep of generated C runs under make fuzz")
    fb = opsweep.system(seed, smooth, opsweep.all_pairs())
    assert not check(fb, opsweep.inputs(seed, 6), tmp_path_factory.mktemp("c"), "accf")
