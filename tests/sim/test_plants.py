"""Plant models against physics that does not come from the models: conservation laws,
small-oscillation frequencies, energy balances and the closed-form FOPDT response."""

from __future__ import annotations

import math

import numpy as np
import pytest

from fuzzyctl.diagnostics import InputError
from fuzzyctl.sim import FixedStep, make_plant
from fuzzyctl.sim.plants.tank import RHO_C

G = 9.81


def _simulate(plant, u, duration, dt=0.01):
    integ = FixedStep(dt)
    state = plant.start()
    states = [state]
    n = round(duration / dt)
    for k in range(n):
        state = plant.advance(state, u, k * dt, dt, integ)
        states.append(state)
    return np.array(states)


def test_crane_free_sway_frequency_is_the_coupled_pendulums():
    # A pendulum on a freely rolling cart swings with w^2 = g (M + m) / (M l).
    M, m, rope = 8000.0, 25000.0, 12.0
    plant = make_plant(
        "crane",
        {
            "trolley_mass": M,
            "load_mass": m,
            "rope_length": rope,
            "stall_force": 0.001,
            "top_speed": 1e3,
            "sway_damping": 0.0,
            "angle0": 0.5,
        },
    )
    states = _simulate(plant, {"power": 0.0, "wind": 0.0}, 30.0)
    theta = states[:, 2]
    crossings = np.flatnonzero(np.diff(np.sign(theta)) != 0)
    t = crossings * 0.01
    period = 2 * np.mean(np.diff(t))
    expected = 2 * math.pi / math.sqrt(G * (M + m) / (M * rope))
    assert period == pytest.approx(expected, rel=2e-3)


def test_crane_conserves_momentum_and_energy_without_drive():
    M, m, rope = 5000.0, 20000.0, 10.0
    plant = make_plant(
        "crane",
        {
            "trolley_mass": M,
            "load_mass": m,
            "rope_length": rope,
            "stall_force": 0.001,
            "top_speed": 1e9,
            "sway_damping": 0.0,
            "angle0": 30.0,
            "speed0": 1.0,
        },
    )
    s = _simulate(plant, {"power": 0.0, "wind": 0.0}, 10.0, dt=0.005)
    v, th, w = s[:, 1], s[:, 2], s[:, 3]
    momentum = (M + m) * v + m * rope * np.cos(th) * w
    energy = (
        0.5 * (M + m) * v**2
        + m * rope * np.cos(th) * v * w
        + 0.5 * m * rope**2 * w**2
        - m * G * rope * np.cos(th)
    )
    assert np.ptp(momentum) < 1e-6 * abs(momentum[0])
    assert np.ptp(energy) < 1e-6 * abs(energy[0])


def test_crane_drive_reaches_top_speed_times_power():
    plant = make_plant("crane", {"sway_damping": 0.5})
    s = _simulate(plant, {"power": 50.0, "wind": 0.0}, 60.0, dt=0.02)
    # At constant speed F = F_stall (power/100 - v/v_top) = 0.
    assert s[-1, 1] == pytest.approx(0.5 * 1.6, rel=1e-6)
    out = plant.measure(s[-1])
    assert out["load_position"] == pytest.approx(out["position"] + 12.0 * math.sin(s[-1, 2]))
    assert out["angle"] == pytest.approx(math.degrees(s[-1, 2]))


def test_crane_wind_holds_the_load_at_the_static_angle():
    # A steady horizontal force W on the load: tan(theta) = W / (m g) at rest.
    plant = make_plant("crane", {"sway_damping": 0.7})
    s = _simulate(plant, {"power": 0.0, "wind": 10.0}, 200.0, dt=0.05)
    # The trolley is pushed too; the drive's back-EMF lets it creep at a constant speed
    # where F_drive = -W, so the rope angle is the static one.
    assert math.tan(s[-1, 2]) == pytest.approx(10e3 / (25000 * G), rel=1e-4)


def test_pendulum_conserves_energy_and_momentum_without_friction():
    M, m, half = 1.0, 0.1, 0.5
    plant = make_plant(
        "pendulum",
        {
            "cart_mass": M,
            "rod_mass": m,
            "half_length": half,
            "cart_friction": 0.0,
            "hinge_friction": 0.0,
            "angle0": 170.0 - 180.0 + 5.0,
        },
    )
    s = _simulate(plant, {"force": 0.0, "push": 0.0}, 3.0, dt=0.001)
    v, th, w = s[:, 1], s[:, 2], s[:, 3]
    momentum = (M + m) * v + m * half * np.cos(th) * w
    energy = (
        0.5 * (M + m) * v**2
        + m * half * np.cos(th) * v * w
        + 0.5 * (4 / 3) * m * half**2 * w**2
        + m * G * half * np.cos(th)
    )
    assert np.max(np.abs(th)) > 1.0  # it did fall
    assert np.ptp(momentum) < 1e-9
    assert np.ptp(energy) < 1e-7 * abs(energy[0])


def test_pendulum_falls_at_the_linearised_rate():
    # Free cart, no friction: theta ~ cosh(lambda t), lambda^2 = g (M+m) / (l (4/3 (M+m) - m)).
    M, m, half = 1.0, 0.1, 0.5
    plant = make_plant(
        "pendulum",
        {
            "cart_mass": M,
            "rod_mass": m,
            "half_length": half,
            "cart_friction": 0.0,
            "hinge_friction": 0.0,
            "angle0": 0.001,
        },
    )
    s = _simulate(plant, {"force": 0.0, "push": 0.0}, 1.0, dt=0.001)
    lam = math.sqrt(G * (M + m) / (half * (4 / 3 * (M + m) - m)))
    assert s[-1, 2] == pytest.approx(math.radians(0.001) * math.cosh(lam * 1.0), rel=1e-6)


def test_pendulum_force_pushes_the_cart_and_tips_the_rod_back():
    plant = make_plant("pendulum", {"angle0": 0.0})
    s = _simulate(plant, {"force": 10.0, "push": 0.0}, 0.1, dt=0.001)
    assert s[-1, 1] > 0 and s[-1, 2] < 0


def test_tank_energy_balance_with_heating_and_no_losses():
    plant = make_plant("tank", {"loss_transfer": 0.0, "temperature0": 20.0, "jacket_temperature0": 20.0})
    dt, duration = 1.0, 600.0
    s = _simulate(
        plant,
        {"heating": 60.0, "valve": 0.0, "feed_temperature": 15.0, "ambient_temperature": 20.0},
        duration,
        dt,
    )
    vol, temp, jacket = s[-1]
    stored = RHO_C * vol * (temp - 20.0) + plant.jacket_capacity * (jacket - 20.0)
    assert vol == pytest.approx(0.5)  # valve closed
    assert stored == pytest.approx(0.6 * plant.heater_power * duration, rel=1e-9)


def test_tank_feed_mixes_at_the_feed_temperature():
    # No heat exchange: (V T)' = q T_feed with the flow constant (huge pump head).
    plant = make_plant(
        "tank",
        {
            "loss_transfer": 0.0,
            "jacket_transfer": 1e-6,
            "pump_head": 1e9,
            "temperature0": 40.0,
            "jacket_temperature0": 40.0,
        },
    )
    u = {"heating": 0.0, "valve": 50.0, "feed_temperature": 10.0, "ambient_temperature": 20.0}
    s = _simulate(plant, u, 100.0, 0.5)
    q = 0.5 * plant.feed_flow
    vol, temp, _ = s[-1]
    assert vol == pytest.approx(0.5 + q * 100.0, rel=1e-8)  # the pump head takes 1e-9
    assert temp == pytest.approx((0.5 * 40.0 + q * 100.0 * 10.0) / vol, rel=1e-6)


def test_tank_pressure_starts_at_atmospheric_and_rises_when_filling_or_heating():
    plant = make_plant("tank", {})
    assert plant.pressure(0.5, 20.0) == pytest.approx(0.0, abs=1e-9)
    # Boyle: filling to 0.75 m^3 halves the gas volume and doubles the air's pressure.
    p_air = 101.325 - 2.3389  # minus the vapour pressure at 20 degC (2.339 kPa, steam tables)
    assert plant.pressure(0.75, 20.0) == pytest.approx(p_air, rel=1e-3)
    # The vapour pressure of water at 100 degC is one atmosphere (steam tables: 101.42 kPa).
    hot = plant.pressure(0.5, 100.0)
    assert hot == pytest.approx(p_air * 373.15 / 293.15 + 101.42 - 101.325, rel=2e-3)


def test_tank_drain_empties_faster_under_pressure():
    plant = make_plant("tank", {})
    u = {"heating": 0.0, "valve": -100.0, "feed_temperature": 15.0, "ambient_temperature": 20.0}
    s = _simulate(plant, u, 20.0, 0.5)
    assert s[-1, 0] < 0.5


@pytest.mark.parametrize("dt", [0.1, 0.07, 0.5])
def test_fopdt_step_response_is_the_closed_form(dt):
    K, tau, L = 2.5, 7.0, 2.05
    plant = make_plant("fopdt", {"gain": K, "time_constant": tau, "dead_time": L})
    state = plant.start()
    integ = FixedStep(dt)
    for k in range(round(30 / dt)):
        t = k * dt
        y = plant.measure(state)["y"]
        expected = 0.0 if t < L else K * (1 - math.exp(-(t - L) / tau))
        assert y == pytest.approx(expected, abs=1e-12)
        state = plant.advance(state, {"u": 1.0, "load": 0.0}, t, dt, integ)


def test_fopdt_starts_at_rest_with_u0_and_adds_the_load():
    plant = make_plant("fopdt", {"gain": 2.0, "time_constant": 1.0, "dead_time": 0.0, "u0": 3.0})
    state = plant.start()
    assert plant.measure(state)["y"] == 6.0
    for k in range(200):
        state = plant.advance(state, {"u": 3.0, "load": 1.0}, k * 0.1, 0.1, FixedStep())
    assert plant.measure(state)["y"] == pytest.approx(8.0, rel=1e-8)


def test_parameters_are_checked_and_listed():
    with pytest.raises(InputError, match=r"no parameter .mass.*load_mass"):
        make_plant("crane", {"mass": 3})
    with pytest.raises(InputError, match=r"rope_length.*outside"):
        make_plant("crane", {"rope_length": -1})
    with pytest.raises(InputError, match="unknown plant model 'boat'"):
        make_plant("boat")
    with pytest.raises(InputError, match="must be a finite number"):
        make_plant("tank", {"heater_power": "hot"})
    info = {p.name: p for p in make_plant("crane").parameters()}
    assert info["load_mass"].unit == "kg" and info["load_mass"].default == 25000.0
