"""The same loop through the engine, the Siemens FUZZY block and the XFUZ block agrees:
the blocks differ from the engine only by single-precision REALs (Siemens) and 16-bit
words after rescaling (XFUZ), which is what the tolerances below allow.  The Siemens block
adds the degrees of the rules concluding one singleton (S7 manual 1.4), so its reference is
the engine on the program as the block computes it (``block_semantics``: ACCU SUM); the
examples' own ACCU MAX gives another loop.  Through the native backend (the generated C,
double precision) the loop is the engine's to rounding."""

from __future__ import annotations

import numpy as np
import pytest

import fuzzyctl
from fuzzyctl.blocks.siemens.fb import block_semantics
from fuzzyctl.diagnostics import InputError
from fuzzyctl.model import Document
from fuzzyctl.sim import make_runtime
from fuzzyctl.sim.config import build_loop, load_config
from fuzzyctl.sim.plc_runtimes import XfuzRuntime, _auto_factor
from tests.conftest import EXAMPLES


@pytest.fixture
def native_cache(tmp_path, monkeypatch):
    """Native builds go to a fresh cache (the user's is left alone, nothing is reused)."""
    monkeypatch.setenv("FUZZYCTL_CACHE_DIR", str(tmp_path / "cache"))
    return tmp_path / "cache"


# example -> (duration s, signal, absolute tolerance siemens, xfuz)
CASES = {
    "crane": (60.0, "load_position", 1e-5, 2e-3),
    "pendulum": (8.0, "angle", 1e-4, 2e-2),
    "tank": (1500.0, "temp", 1e-5, 5e-3),
}


@pytest.mark.parametrize("example", sorted(CASES))
def test_engine_siemens_and_xfuz_loops_agree(example):
    duration, signal, tol_siemens, tol_xfuz = CASES[example]
    cfg = load_config(EXAMPLES / f"{example}.toml")
    traces = {r: build_loop(cfg, runtime=r).run(duration) for r in ("engine", "siemens", "xfuz")}
    ref = traces["engine"][signal]
    model = fuzzyctl.load(EXAMPLES / f"{example}.fcl")
    as_block = Document(tuple(block_semantics(fb) for fb in model.blocks))
    siemens_ref = build_loop(cfg, runtime="engine", model=as_block).run(duration)[signal]
    assert np.max(np.abs(traces["siemens"][signal] - siemens_ref)) < tol_siemens
    assert np.max(np.abs(traces["xfuz"][signal] - ref)) < tol_xfuz
    # and not trivially: the block's outputs are not bit-identical to the engine's
    fb_out = next(
        n for n in traces["engine"].names if n.startswith("fb.") and n[3:] in ("power", "balance", "dheat")
    )
    assert not np.array_equal(traces["xfuz"][fb_out], traces["engine"][fb_out])


def test_single_evaluations_agree_over_the_crane_inputs():
    model = fuzzyctl.load(EXAMPLES / "crane.fcl")
    rt = {r: make_runtime(model, r, cycle=0.05) for r in ("engine", "siemens", "xfuz")}
    summed = make_runtime(block_semantics(model.main), "engine", cycle=0.05)  # the block's sum (1.4)
    rng = np.random.default_rng(3)
    differs = 0
    for d, a in zip(rng.uniform(-10, 40, 300), rng.uniform(-20, 20, 300), strict=True):
        x = {"distance": float(d), "angle": float(a)}
        e = rt["engine"].evaluate(x)["power"]
        block = rt["siemens"].evaluate(x)["power"]
        assert block == pytest.approx(summed.evaluate(x)["power"], abs=1e-4)
        differs += abs(block - e) > 1e-3
        # XFUZ: inputs to 1 mm / 0.001 deg, output to 0.01 %
        assert rt["xfuz"].evaluate(x)["power"] == pytest.approx(e, abs=0.05)
    assert differs > 0  # the crane concludes terms from several rules: ACCU MAX is not the sum


def test_xfuz_scaling_factors():
    assert _auto_factor([-4, 0, 4, 10, 20]) == 1000.0
    assert _auto_factor([-100, 100]) == 100.0
    assert _auto_factor([0.25, 40000.0]) == 1.0
    model = fuzzyctl.load(EXAMPLES / "tank.fcl")
    x = XfuzRuntime(model, cycle=1.0, input_scale={"error": 10})
    assert x.factors["error"] == 10 and x.factors["rate"] == 10000.0


def test_unknown_or_missing_runtime():
    model = fuzzyctl.load(EXAMPLES / "crane.fcl")
    with pytest.raises(InputError, match="unknown controller runtime 'plc'"):
        make_runtime(model, "plc")


@pytest.mark.parametrize("example", ["crane", "tank"])
def test_native_loop_agrees_with_the_engine_loop(example, native_cache, monkeypatch):
    from fuzzyctl.engine.native import NativeController
    from fuzzyctl.sim import config as sim_config

    made = []

    def spy(*args, **kwargs):
        made.append(make_runtime(*args, **kwargs))
        return made[-1]

    monkeypatch.setattr(sim_config, "make_runtime", spy)
    duration, signal, _tol_siemens, _tol_xfuz = CASES[example]
    cfg = load_config(EXAMPLES / f"{example}.toml")
    made.clear()  # loading checked the configuration with the engine
    native = build_loop(cfg, runtime="native").run(duration)
    # the loop really called the compiled C
    assert [r.name for r in made] == ["native"] and isinstance(made[0].controller, NativeController)
    assert made[0].controller.library.parent == native_cache / "native"
    engine = build_loop(cfg, runtime="engine").run(duration)
    assert native.names == engine.names
    for name in engine.names:  # every recorded signal, the block's outputs included
        ref = engine[name]
        scale = max(1.0, float(np.max(np.abs(ref))))
        assert np.max(np.abs(native[name] - ref)) <= 1e-9 * scale, name
    # not trivially: the loop moved the controlled signal
    assert np.ptp(engine[signal]) > 0


def test_native_runtime_refuses_rather_than_falls_back(native_cache, monkeypatch):
    model = fuzzyctl.load(EXAMPLES / "crane.fcl")
    monkeypatch.setenv("CC", str(native_cache / "no-such-cc"))
    with pytest.raises(InputError, match="runtime 'native' cannot run here: no C compiler"):
        make_runtime(model, "native")
