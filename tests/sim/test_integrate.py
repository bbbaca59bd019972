"""Integrators against exact solutions, and repeatable noise."""

from __future__ import annotations

import math

import numpy as np
import pytest

import fuzzyctl
from fuzzyctl.diagnostics import InputError
from fuzzyctl.sim import (
    Adaptive,
    DirectFuzzy,
    FixedStep,
    Loop,
    make_integrator,
    make_plant,
    make_runtime,
    profiles,
)
from fuzzyctl.sim.config import build_loop, load_config
from tests.conftest import EXAMPLES


def decay(t: float, x: np.ndarray) -> np.ndarray:
    return -x


@pytest.mark.parametrize(
    ("integrator", "rel"),
    [(FixedStep(0.01), 1e-9), (Adaptive("RK45", 1e-10, 1e-12), 1e-8), (Adaptive("LSODA"), 1e-4)],
)
def test_exponential_decay(integrator, rel):
    x = np.array([1.0, 2.0])
    for k in range(10):
        x = integrator.advance(decay, 0.1 * k, x, 0.1)
    assert x == pytest.approx(np.array([1.0, 2.0]) * math.exp(-1.0), rel=rel)


def test_fixed_step_cuts_the_period_into_equal_substeps():
    # RK4 is exact for a cubic in t: x' = 3 t^2
    x = FixedStep(0.3).advance(lambda t, x: np.array([3 * t * t]), 0.0, np.array([0.0]), 1.0)
    assert x[0] == pytest.approx(1.0, rel=1e-14)


def test_make_integrator():
    assert make_integrator("rk4", max_step=0.5) == FixedStep(0.5)
    assert make_integrator("lsoda") == Adaptive("LSODA")
    with pytest.raises(InputError, match="unknown integrator 'euler'"):
        make_integrator("euler")
    with pytest.raises(InputError, match="max_step must be > 0"):
        FixedStep(0.0)


def test_solve_ivp_and_rk4_loops_agree_on_the_crane():
    fuzzy = make_runtime(fuzzyctl.load(EXAMPLES / "crane.fcl"))
    s = DirectFuzzy(fuzzy, {"distance": "target - position", "angle": "angle"})
    a = Loop(make_plant("crane"), s, period=0.05, setpoints={"target": profiles.constant(15.0)})
    ta = a.run(20.0)
    b = Loop(
        make_plant("crane"),
        s,
        period=0.05,
        setpoints={"target": profiles.constant(15.0)},
        integrator=Adaptive("RK45", 1e-9, 1e-12),
    )
    tb = b.run(20.0)
    assert np.max(np.abs(ta["load_position"] - tb["load_position"])) < 1e-5


def test_noise_is_seeded_and_only_on_the_measurement():
    import dataclasses

    cfg = load_config(EXAMPLES / "crane.toml")
    noisy = dataclasses.replace(cfg, noise={"angle": 0.5}, seed=7)
    t1, t2 = build_loop(noisy).run(5.0), build_loop(noisy).run(5.0)
    clean = build_loop(cfg).run(5.0)
    assert np.array_equal(t1["angle"], t2["angle"])
    assert np.std(t1["angle"][:-1] - clean["angle"][:-1]) > 0.1
    other = build_loop(dataclasses.replace(noisy, seed=8)).run(5.0)
    assert not np.array_equal(other["angle"], t1["angle"])
