"""The structures of IEC 61131-7 around a fuzzy block: what each computes cycle by cycle
(checked against hand-written formulas), and that pre-control (B.1) and gain adaptation
(B.2) do what Annex B says they are for."""

from __future__ import annotations

import math

import numpy as np
import pytest

import fuzzyctl
from fuzzyctl.diagnostics import InputError
from fuzzyctl.sim import (
    PID,
    DirectFuzzy,
    FuzzyPI,
    GainScheduledPID,
    Loop,
    PIDLoop,
    PreControl,
    make_plant,
    make_runtime,
    profiles,
    quality,
)
from tests.conftest import EXAMPLES

# u = 2 x on [-10, 10] (two singletons, linear membership: CoGS interpolates exactly)
LINEAR = """
FUNCTION_BLOCK lin
VAR_INPUT x : REAL; END_VAR
VAR_OUTPUT u : REAL; END_VAR
FUZZIFY x TERM lo := (-10, 1) (10, 0); TERM hi := (-10, 0) (10, 1); END_FUZZIFY
DEFUZZIFY u TERM neg := -20; TERM pos := 20; METHOD : CoGS; END_DEFUZZIFY
RULEBLOCK r AND : MIN; RULE 1 : IF x IS lo THEN u IS neg; RULE 2 : IF x IS hi THEN u IS pos; END_RULEBLOCK
END_FUNCTION_BLOCK
"""


def linear() -> object:
    return make_runtime(fuzzyctl.load(LINEAR))


def fopdt(**p: float):
    return make_plant("fopdt", {"gain": 2.0, "time_constant": 10.0, "dead_time": 1.0, **p})


def test_direct_fuzzy_maps_expressions_in_and_out():
    s = DirectFuzzy(linear(), {"x": "w - y"}, {"u": "u / 4 + 1"})
    out = s.step({"w": 3.0, "y": 1.0}, 0.1)
    assert out == {"u": pytest.approx(2 * 2.0 / 4 + 1)}
    assert s.internals == {"fb.x": 2.0, "fb.u": pytest.approx(4.0)}


def test_direct_fuzzy_refuses_unknown_and_missing_inputs():
    with pytest.raises(InputError, match="'z' is not an input"):
        DirectFuzzy(linear(), {"x": "w", "z": "w"})
    with pytest.raises(InputError, match="no signal given for the fuzzy input"):
        DirectFuzzy(linear(), {})


def test_fuzzy_pi_integrates_the_rate_and_stops_at_the_limits():
    s = FuzzyPI(linear(), {"x": "e"}, output="u", drive="heating", gain=0.5, low=0.0, high=10.0, initial=1.0)
    values = [s.step({"e": 3.0}, 0.2)["heating"] for _ in range(5)]
    assert values == pytest.approx([1.0 + 0.5 * 6.0 * 0.2 * k for k in range(1, 6)])
    for _ in range(100):
        s.step({"e": 3.0}, 0.2)
    assert s.value == 10.0
    assert s.step({"e": -3.0}, 0.2)["heating"] == pytest.approx(10.0 - 0.5 * 6.0 * 0.2)  # no windup
    s.reset()
    assert s.value == 1.0


def test_fuzzy_pi_on_a_plant_removes_the_steady_state_error():
    # A velocity-form law with a rate input: dU/dt = 2 (e/10 ... ) behaves as PI.
    s = FuzzyPI(linear(), {"x": "w - y"}, output="u", drive="u", gain=0.05)
    loop = Loop(fopdt(), s, period=0.1, setpoints={"w": profiles.constant(1.0)})
    trace = loop.run(200.0)
    assert trace["y"][-1] == pytest.approx(1.0, abs=1e-3)


def test_precontrol_adds_the_fuzzy_correction_before_the_limits():
    pid = PID(1.0, low=-5.0, high=5.0)
    s = PreControl(
        pid, linear(), {"x": "w"}, setpoint="w", measurement="y", drive="u", correction="u", gain=0.5
    )
    out = s.step({"w": 2.0, "y": 1.0}, 0.1)
    assert out["u"] == pytest.approx(1.0 + 0.5 * 4.0)
    assert s.internals["pid.p"] == pytest.approx(1.0)
    out = s.step({"w": 9.0, "y": 1.0}, 0.1)
    assert out["u"] == 5.0  # PID 8 + correction 9 saturated as one signal


def test_precontrol_from_the_setpoint_beats_the_pid_alone():
    # B.1: the fuzzy block knows the static input for a setpoint (u = w / K for K = 2);
    # the PID only corrects what is left.  Same PID in both loops.
    fb = LINEAR.replace("-20", "-5").replace("TERM pos := 20", "TERM pos := 5")  # u = w / 2

    def ise(structure) -> float:
        loop = Loop(fopdt(), structure, period=0.1, setpoints={"w": profiles.steps([(0, 2.0), (60, 6.0)])})
        trace = loop.run(120.0)
        return quality(trace, "y", "w", band=0.05).ise

    alone = ise(PIDLoop(PID(0.3, 10.0), setpoint="w", measurement="y", drive="u"))
    pre = ise(
        PreControl(
            PID(0.3, 10.0),
            make_runtime(fuzzyctl.load(fb)),
            {"x": "w"},
            setpoint="w",
            measurement="y",
            drive="u",
            correction="u",
        )
    )
    assert pre < 0.5 * alone


GAINS = """
FUNCTION_BLOCK adapt
VAR_INPUT e : REAL; END_VAR
VAR_OUTPUT kf : REAL; END_VAR
FUZZIFY e TERM small := (0, 1) (1, 0); TERM large := (0, 0) (1, 1); END_FUZZIFY
DEFUZZIFY kf TERM low := 0.4; TERM high := 1.5; METHOD : CoGS; END_DEFUZZIFY
RULEBLOCK r AND : MIN;
RULE 1 : IF e IS large THEN kf IS low;
RULE 2 : IF e IS small THEN kf IS high;
END_RULEBLOCK
END_FUNCTION_BLOCK
"""


def test_gain_adaptation_sets_the_pid_gains_each_cycle():
    s = GainScheduledPID(
        PID(2.0, 5.0),
        make_runtime(fuzzyctl.load(GAINS)),
        {"e": "abs(w - y)"},
        setpoint="w",
        measurement="y",
        drive="u",
        gains={"kp": "kf"},
        mode="factor",
    )
    for e, factor in ((2.0, 0.4), (0.0, 1.5), (0.5, 0.95)):
        s.step({"w": e, "y": 0.0}, 0.1)
        assert s.internals["pid.kp"] == pytest.approx(2.0 * factor)
    s.reset()
    assert s.pid_part.pid.kp == 2.0


def test_gain_adaptation_tames_a_fast_pid_without_slowing_it_down():
    # B.2: a high gain is fast but overshoots on big steps; the fuzzy block lowers it while
    # the error is large and raises it near the setpoint.
    plant = fopdt(dead_time=2.0)

    def run(structure):
        loop = Loop(plant, structure, period=0.1, setpoints={"w": profiles.constant(1.0)})
        return quality(loop.run(120.0), "y", "w", band=0.02)

    fixed = run(PIDLoop(PID(1.6, 8.0), setpoint="w", measurement="y", drive="u"))
    slow = run(PIDLoop(PID(0.64, 8.0), setpoint="w", measurement="y", drive="u"))
    adaptive = run(
        GainScheduledPID(
            PID(1.6, 8.0),
            make_runtime(fuzzyctl.load(GAINS)),
            {"e": "abs(w - y)"},
            setpoint="w",
            measurement="y",
            drive="u",
            gains={"kp": "kf"},
            mode="factor",
        )
    )
    assert adaptive.overshoot < 0.5 * fixed.overshoot
    assert adaptive.settling_time < slow.settling_time


def test_gain_adaptation_refuses_bad_parameters():
    fuzzy = make_runtime(fuzzyctl.load(GAINS))
    with pytest.raises(InputError, match="'kd' is not a PID parameter"):
        GainScheduledPID(
            PID(1.0), fuzzy, {"e": "w"}, setpoint="w", measurement="y", drive="u", gains={"kd": "kf"}
        )
    with pytest.raises(InputError, match="'k' is not an output"):
        GainScheduledPID(
            PID(1.0), fuzzy, {"e": "w"}, setpoint="w", measurement="y", drive="u", gains={"kp": "k"}
        )
    s = GainScheduledPID(
        PID(1.0, 1.0),
        fuzzy,
        {"e": "w"},
        setpoint="w",
        measurement="y",
        drive="u",
        gains={"ti": "kf"},
        mode="absolute",
    )
    s.step({"w": 0.0, "y": 0.0}, 0.1)
    assert s.internals["pid.ti"] == pytest.approx(1.5)


def test_stepping_equals_running_and_reset_starts_over():
    def make():
        fuzzy = make_runtime(fuzzyctl.load(EXAMPLES / "crane.fcl"))
        return Loop(
            make_plant("crane"),
            DirectFuzzy(fuzzy, {"distance": "target - position", "angle": "angle"}),
            period=0.05,
            setpoints={"target": profiles.constant(12.0)},
        )

    a, b = make(), make()
    trace = a.run(10.0)
    rows = [b.step() for _ in range(100)]
    assert [r["position"] for r in rows] == pytest.approx(list(trace["position"][:100]), abs=0)
    row = b.step(1.0)  # 20 periods at once
    assert row["t"] == pytest.approx(120 * 0.05 - 0.05)
    b.reset()
    assert b.t == 0.0 and b.step()["position"] == 0.0
    assert np.all(np.isfinite(trace["fb.power"]))


def test_loop_saturates_and_adds_disturbances():
    s = PIDLoop(PID(100.0), setpoint="w", measurement="y", drive="u")
    plant = make_plant("crane")
    with pytest.raises(InputError, match="drives 'u', which is not an input of the crane"):
        Loop(plant, s, period=0.1)
    s = DirectFuzzy(linear(), {"x": "position + 10"}, {"power": "u * 100"})
    loop = Loop(plant, s, period=0.1, disturbances={"wind": profiles.constant(3.0)})
    row = loop.step()
    assert row["power"] == 100.0 and row["wind"] == 3.0
    assert math.isclose(row["fb.u"], 20.0)
