"""The PID block against closed-form responses: open-loop terms, the back-calculation fixed
point, bumpless switching, and closed loops whose answers are known analytically."""

from __future__ import annotations

import math

import pytest

from fuzzyctl.diagnostics import InputError
from fuzzyctl.sim import PID, FixedStep, Loop, PIDLoop, make_plant, profiles


def test_pi_on_a_constant_error_is_a_ramp():
    kp, ti, h, e = 2.0, 5.0, 0.1, 1.5
    pid = PID(kp, ti)
    outs = [pid.update(e, 0.0, h) for _ in range(50)]
    for k, u in enumerate(outs):
        # u_k = Kp e + Kp h / Ti * e * k  (the integral is updated after the output)
        assert u == pytest.approx(kp * e + kp * h / ti * e * k, rel=1e-12)


def test_derivative_of_a_measurement_step_decays_with_the_filter():
    kp, td, n, h = 3.0, 2.0, 8.0, 0.01
    pid = PID(kp, math.inf, td, n=n)
    pid.update(0.0, 0.0, h)
    ds = []
    for _ in range(300):
        pid.update(0.0, 1.0, h)
        ds.append(pid.last.d)
    ad, bd = td / (td + n * h), kp * td * n / (td + n * h)
    for k, d in enumerate(ds):
        assert d == pytest.approx(-bd * ad**k, rel=1e-9)
    # and it tends to the continuous filter -Kp N exp(-N t / Td)
    t = 100 * h
    assert ds[100] == pytest.approx(-kp * n * math.exp(-n * t / td), rel=0.05)


def test_no_derivative_kick_on_setpoint_steps_with_c_zero():
    pid = PID(1.0, math.inf, 1.0)
    pid.update(0.0, 0.0, 0.1)
    pid.update(10.0, 0.0, 0.1)
    assert pid.last.d == 0.0
    pid = PID(1.0, math.inf, 1.0, c=1.0)
    pid.update(0.0, 0.0, 0.1)
    pid.update(10.0, 0.0, 0.1)
    assert pid.last.d > 0.0


def test_back_calculation_settles_at_its_fixed_point():
    # I += Kp h/Ti e + h/Tt (u_max - Kp e - I)  ->  I* = u_max - Kp e + Tt Kp e / Ti
    kp, ti, tt, e, umax = 2.0, 4.0, 1.0, 3.0, 5.0
    pid = PID(kp, ti, low=-umax, high=umax, tt=tt)
    for _ in range(2000):
        u = pid.update(e, 0.0, 0.05)
    assert u == umax
    assert pid.i == pytest.approx(umax - kp * e + tt * kp * e / ti, rel=1e-9)


def test_without_antiwindup_the_integral_winds_up_and_clamping_stops_it():
    wound, clamped = PID(1.0, 1.0, high=1.0, antiwindup="none"), PID(1.0, 1.0, high=1.0, antiwindup="clamp")
    for _ in range(100):
        wound.update(2.0, 0.0, 0.1)
        clamped.update(2.0, 0.0, 0.1)
    assert wound.i == pytest.approx(2.0 * 0.1 * 100)
    assert clamped.i <= 1.0


def test_antiwindup_recovers_faster_after_saturation():
    def overshoot(antiwindup: str) -> float:
        plant = make_plant("fopdt", {"gain": 1.0, "time_constant": 5.0, "dead_time": 0.5})
        pid = PID(2.0, 4.0, low=0.0, high=1.5, antiwindup=antiwindup)
        loop = Loop(
            plant,
            PIDLoop(pid, setpoint="w", measurement="y", drive="u"),
            period=0.05,
            setpoints={"w": profiles.constant(1.0)},
        )
        return float(loop.run(60)["y"].max() - 1.0)

    assert overshoot("backcalc") < 0.5 * overshoot("none")
    assert overshoot("clamp") < 0.5 * overshoot("none")


def test_bumpless_manual_to_auto_and_gain_change():
    pid = PID(2.0, 3.0, 0.5, low=0.0, high=100.0)
    pid.set_manual(42.0)
    for _ in range(10):
        assert pid.update(50.0, 47.0, 0.1) == 42.0
    pid.set_auto()
    first = pid.update(50.0, 47.0, 0.1)
    # continuing from 42 by one integration step of the error, not jumping to P + I
    assert first == pytest.approx(42.0, abs=2.0 * 0.1 / 3.0 * 3.0 + 1e-9)
    before = pid.update(50.0, 47.0, 0.1)
    pid.set_gains(kp=6.0)
    after = pid.update(50.0, 47.0, 0.1)
    assert abs(after - before) < 6.0 * 0.1 / 3.0 * 3.0 + 1e-9
    # a manual value outside the limits is saturated
    pid.set_manual(150.0)
    assert pid.update(50.0, 47.0, 0.1) == 100.0


def test_closed_loop_pi_with_pole_cancellation_is_first_order():
    # G = K / (tau s + 1), PI with Ti = tau: closed loop 1 / (tau / (K Kp) s + 1).
    K, tau, kp, h = 2.0, 5.0, 1.5, 0.001
    plant = make_plant("fopdt", {"gain": K, "time_constant": tau, "dead_time": 0.0})
    loop = Loop(
        plant,
        PIDLoop(PID(kp, tau), setpoint="w", measurement="y", drive="u"),
        period=h,
        setpoints={"w": profiles.constant(1.0)},
    )
    trace = loop.run(10.0)
    tc = tau / (K * kp)
    for t, y in zip(trace["t"][::500], trace["y"][::500], strict=True):
        assert y == pytest.approx(1 - math.exp(-t / tc), abs=3e-3)


def test_closed_loop_p_only_has_the_textbook_offset():
    K, kp = 2.0, 3.0
    plant = make_plant("fopdt", {"gain": K, "time_constant": 2.0, "dead_time": 0.0})
    loop = Loop(
        plant,
        PIDLoop(PID(kp), setpoint="w", measurement="y", drive="u"),
        period=0.01,
        setpoints={"w": profiles.constant(1.0)},
        integrator=FixedStep(0.01),
    )
    trace = loop.run(30.0)
    assert trace["y"][-1] == pytest.approx(K * kp / (1 + K * kp), rel=1e-6)


def test_bad_settings_are_refused():
    with pytest.raises(InputError, match="ti must be > 0"):
        PID(1.0, 0.0)
    with pytest.raises(InputError, match="low < high"):
        PID(1.0, low=2.0, high=1.0)
    with pytest.raises(InputError, match="antiwindup"):
        PID(1.0, antiwindup="sometimes")
    with pytest.raises(InputError, match="period"):
        PID(1.0).update(0, 0, 0.0)
