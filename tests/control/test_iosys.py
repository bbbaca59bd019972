"""fuzzyctl.control: the controller as a python-control system, checked against fuzzyctl
simulate (an independent loop implementation: its own FOPDT solution and fuzzy_pi structure)
and the describing function of a saturation (closed form)."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest

ct = pytest.importorskip("control")

import fuzzyctl  # noqa: E402
import fuzzyctl.control as fc  # noqa: E402
from fuzzyctl import sim  # noqa: E402
from fuzzyctl.diagnostics import InputError  # noqa: E402
from fuzzyctl.sim.config import build_loop, load_config  # noqa: E402

DATA = Path(__file__).parent.parent / "data" / "control"


def closed_loop(K: object, G: object, *, dt: float = 0) -> object:
    """r -> e = r - y -> K -> u -> G -> y, outputs y and u (K's input error, output rate)."""
    err = ct.summing_junction(inputs=["r", "-y"], output="e", dt=dt, name="sum")
    return ct.interconnect(
        [K, G, err],
        connections=[["K.error", "sum.e"], ["G.u", "K.rate"], ["sum.y", "G.y"]],
        inplist=["sum.r"],
        outlist=["G.y", "K.rate"],
        inputs="r",
        outputs=["y", "u"],
    )


def test_static_map_is_the_engine() -> None:
    ctl = fuzzyctl.compile(fuzzyctl.load(DATA / "rate.fcl"))
    K = fc.iosys(ctl)
    assert K.nstates == 0 and K.input_labels == ["error"] and K.output_labels == ["rate"]
    for e in np.linspace(-3, 3, 41):
        assert K.output(0, [], [e])[0] == ctl.evaluate(error=e)["rate"]


def test_discrete_loop_equals_fuzzyctl_simulate() -> None:
    # The same loop both ways: fuzzyctl simulate (the TOML file) and python-control with the
    # FOPDT sampled exactly (zero-order hold, dead time = 10 samples).
    config = load_config(DATA / "fopdt_rate.toml")
    trace = build_loop(config).run(config.duration)
    dt = config.cycle
    K = fc.iosys(
        DATA / "rate.fcl", integrate={"rate": fc.Integral(gain=0.3, low=-1, high=1)}, dt=dt, name="K"
    )
    delay = ct.tf([1], [1] + [0] * 10, dt)
    G = ct.ss(
        ct.sample_system(ct.tf([2.0], [5.0, 1.0]), dt, method="zoh") * delay,
        inputs="u",
        outputs="y",
        name="G",
    )
    T = np.arange(len(trace["t"])) * dt
    resp = ct.input_output_response(closed_loop(K, G, dt=dt), T, 1.5 * np.ones_like(T))
    y, u = resp.outputs
    assert np.max(np.abs(y - np.asarray(trace["y"]))) < 1e-9  # measured: 3e-15
    assert np.max(np.abs(u[:-1] - np.asarray(trace["u"])[:-1])) < 1e-9
    assert np.ptp(trace["y"]) > 1  # a loop that moved, through the nonlinear part of the map
    assert np.sum(u == 1.0) > 10  # and held at the actuator limit for a while (the anti-windup)


def test_continuous_loop_close_to_fuzzyctl_simulate() -> None:
    # continuous time (the map evaluated wherever solve_ivp asks) against simulate's 10 ms
    # cycle, no dead time: they differ by the sample-and-hold, O(cycle)
    plant = sim.make_plant("fopdt", {"gain": 2.0, "time_constant": 5.0, "dead_time": 0.0})
    fuzzy = sim.make_runtime(fuzzyctl.load(DATA / "rate.fcl"))
    structure = sim.FuzzyPI(
        fuzzy, {"error": "setpoint - y"}, output="rate", drive="u", gain=0.3, low=-1, high=1
    )
    trace = sim.Loop(plant, structure, period=0.01, setpoints={"setpoint": sim.profiles.constant(1.5)}).run(
        20
    )
    K = fc.iosys(DATA / "rate.fcl", integrate={"rate": fc.Integral(gain=0.3, low=-1, high=1)}, name="K")
    G = ct.ss(ct.tf([2.0], [5.0, 1.0]), inputs="u", outputs="y", name="G")
    T = np.asarray(trace["t"])
    resp = ct.input_output_response(
        closed_loop(K, G), T, 1.5 * np.ones_like(T), solve_ivp_kwargs={"max_step": 0.05}
    )
    assert np.max(np.abs(resp.outputs[0] - np.asarray(trace["y"]))) < 0.005  # measured: 1.3e-3


def sat_df(a: float) -> float:
    """The describing function of u = clip(e, -1, 1) (closed form, a > 1)."""
    return 2 / math.pi * (math.asin(1 / a) + math.sqrt(1 - 1 / a**2) / a)


def test_describing_function_and_limit_cycle() -> None:
    N = fc.nonlinearity(DATA / "saturation.fcl")
    amplitudes = np.linspace(1.01, 10, 60)
    df = ct.describing_function(N, amplitudes)
    assert np.max(np.abs(df - [sat_df(a) for a in amplitudes])) < 1e-3  # python-control's quadrature
    # G = 12 / (s (s+1) (s+2)) crosses the negative real axis at w = sqrt(2), G = -2: the
    # limit cycle has N(A) = 1/2
    G = ct.tf([12], [1, 3, 2, 0])
    ((a_pred, w_pred),) = ct.describing_function_response(G, N, amplitudes).intersections
    assert w_pred == pytest.approx(math.sqrt(2), rel=1e-3)
    assert sat_df(a_pred) == pytest.approx(0.5, rel=1e-3)
    # the loop itself, e = -y, simulated: amplitude and frequency of e after the start-up
    K = fc.iosys(DATA / "saturation.fcl", name="K")
    P = ct.ss(G, inputs="u", outputs="y", name="P")
    neg = ct.summing_junction(inputs=["-y"], output="e", name="neg")
    cl = ct.interconnect(
        [K, P, neg],
        connections=[["K.e", "neg.e"], ["P.u", "K.u"], ["neg.y", "P.y"]],
        inplist=[],
        outlist=["K.e"],
        inputs=0,
        outputs=["e"],
    )
    T = np.linspace(0, 40, 4001)
    e = ct.input_output_response(cl, T, 0, X0=[0, 0, 0.1], solve_ivp_kwargs={"max_step": 0.05}).outputs[0]
    tail, t = e[T > 20], T[T > 20]
    amplitude = (tail.max() - tail.min()) / 2
    up = np.where((tail[:-1] < 0) & (tail[1:] >= 0))[0]
    crossings = t[up] - tail[up] * (t[up + 1] - t[up]) / (tail[up + 1] - tail[up])
    omega = 2 * math.pi / np.mean(np.diff(crossings))
    # describing-function analysis is approximate: measured 2.526 vs 2.475, 1.395 vs 1.414 rad/s
    assert amplitude == pytest.approx(a_pred, rel=0.05)
    assert omega == pytest.approx(w_pred, rel=0.03)


def test_errors_name_the_parameter() -> None:
    with pytest.raises(InputError, match="integrate: 'nope' is not an output"):
        fc.iosys(DATA / "rate.fcl", integrate={"nope": 1.0})
    with pytest.raises(InputError, match="one-input"):
        fc.nonlinearity("examples/tank.fcl")
    with pytest.raises(InputError, match="low < high"):
        fc.Integral(low=1, high=0)


def test_missing_python_control_names_the_extra() -> None:
    import subprocess
    import sys

    code = (
        "import sys; sys.modules['control'] = None\n"  # as if python-control were not installed
        "import fuzzyctl\n"
        "for get in (lambda: fuzzyctl.control, lambda: __import__('fuzzyctl.control')):\n"
        "    try:\n        get()\n    except ModuleNotFoundError as exc:\n        print(exc)\n"
    )
    done = subprocess.run(
        [sys.executable, "-c", code], capture_output=True, text=True, timeout=60, check=True
    )
    assert done.stdout.count("pip install 'fuzzyctl[control]'") == 2, done.stdout + done.stderr


def test_out_of_range_is_quiet_by_default_and_can_clamp() -> None:
    import warnings

    with warnings.catch_warnings():
        warnings.simplefilter("error")  # a sweep far past the range: no warning per call
        N = fc.nonlinearity(DATA / "saturation.fcl")
        assert N(10.0) == 1.0 and fc.iosys(DATA / "rate.fcl").output(0, [], [5.0])[0] == 0.8
    # clamp: the input limited to [-2, 2] first, as a PLC block's input limiter
    ctl = fuzzyctl.compile(fuzzyctl.load(DATA / "rate.fcl"), out_of_range="ignore")
    K = fc.iosys(DATA / "rate.fcl", out_of_range="clamp")
    assert K.output(0, [], [5.0])[0] == ctl.evaluate(error=2.0)["rate"]
    with pytest.raises(InputError):
        fc.iosys(DATA / "rate.fcl", out_of_range="raise").output(0, [], [5.0])
