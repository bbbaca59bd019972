"""A closed, heated tank with one valve that fills or drains it: the temperature / pressure /
valve story of IEC 61131-7 figure 7."""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import ClassVar

import numpy as np

from fuzzyctl.sim.integrate import Vector
from fuzzyctl.sim.plant import OdePlant, Port, param, register

RHO_C = 4186.0  # kJ/(m^3 K): volumetric heat capacity of water (1000 kg/m^3 * 4.186 kJ/(kg K))
P_ATM = 101.325  # kPa
KELVIN = 273.15


def vapour_pressure(temp_c: float) -> float:
    """Saturation pressure of water [kPa] at ``temp_c`` [degC] (Antoine, 1-100 degC, extended)."""
    t = min(max(temp_c, -20.0), 200.0)
    return float(0.133322 * 10.0 ** (8.07131 - 1730.63 / (233.426 + t)))


@register
@dataclass(frozen=True)
class HeatedTank(OdePlant):
    r"""A closed vessel of water with a heating jacket, a feed/drain valve and a gas cushion.

    States: liquid volume ``V`` [m^3], liquid temperature ``T`` [degC], jacket temperature
    ``Tj`` [degC].  Inputs: ``heating`` (0..100 % of the heater power ``Q_max``, a steam valve or
    an electric heater) and ``valve`` (-100..100 %, figure 7's convention: positive opens the
    inlet, negative opens the drainage, 0 is closed); disturbances ``feed_temperature`` and
    ``ambient_temperature`` [degC].  With ``rho c`` the volumetric heat capacity of water::

        q_in  = max(valve, 0)/100 * q_max * max(0, 1 - p / p_pump)         feed pump, shut-off head
        q_out = max(-valve, 0)/100 * k_drain * sqrt(max(p + rho g h, 0))   drain, pressure driven
        V'    = q_in - q_out
        rho c V T' = rho c q_in (T_feed - T) + UA_j (Tj - T) - UA_loss (T - T_amb)
        C_j Tj'    = heating/100 * Q_max - UA_j (Tj - T)

    The headspace holds a fixed amount of air at the liquid temperature plus saturated water
    vapour, so the gauge pressure ``p`` [kPa] rises when the tank fills (less gas volume) and
    when it heats up (figure 7's "temp" and "pressure" move together)::

        p = p_air0 (V_tank - V0)/(V_tank - V) (T + 273.15)/(T0 + 273.15) + p_sat(T) - p_atm

    with ``p_air0 = p_atm - p_sat(T0)`` (the tank was closed at atmospheric pressure) and
    ``p_sat`` Antoine's equation for water.  Measured: ``temp``, ``jacket_temp`` [degC],
    ``pressure`` [kPa gauge], ``level`` [% of the tank volume]."""

    kind: ClassVar[str] = "tank"
    title: ClassVar[str] = "heated tank with valve (IEC 61131-7 figure 7)"
    inputs: ClassVar[tuple[Port, ...]] = (
        Port("heating", "%", "heater power command", 0.0, 0.0, 100.0),
        Port("valve", "%", "feed (+) / drain (-) valve opening", 0.0, -100.0, 100.0),
        Port("feed_temperature", "degC", "temperature of the feed (disturbance)", 15.0),
        Port("ambient_temperature", "degC", "temperature around the tank (disturbance)", 20.0),
    )
    outputs: ClassVar[tuple[Port, ...]] = (
        Port("temp", "degC", "liquid temperature"),
        Port("pressure", "kPa", "gauge pressure in the headspace"),
        Port("level", "%", "liquid volume, percent of the tank volume"),
        Port("jacket_temp", "degC", "heating jacket temperature"),
    )

    tank_volume: float = param(1.0, "m^3", "inner volume of the vessel", low=1e-3)
    heater_power: float = param(50.0, "kW", "heat input at heating = 100 %", low=0.0)
    jacket_capacity: float = param(200.0, "kJ/K", "heat capacity of the jacket", low=1e-3)
    jacket_transfer: float = param(2.0, "kW/K", "heat transfer jacket -> liquid", low=1e-6)
    loss_transfer: float = param(0.05, "kW/K", "heat loss liquid -> ambient", low=0.0)
    feed_flow: float = param(0.002, "m^3/s", "feed flow at valve = +100 % and no back-pressure", low=0.0)
    pump_head: float = param(300.0, "kPa", "feed pump shut-off pressure", low=1e-3)
    drain_coefficient: float = param(
        1e-4, "m^3/(s sqrt(kPa))", "drain flow per sqrt of pressure at -100 %", low=0.0
    )
    volume0: float = param(0.5, "m^3", "initial liquid volume", low=1e-3)
    temperature0: float = param(20.0, "degC", "initial liquid temperature (and when the tank was closed)")
    jacket_temperature0: float = param(20.0, "degC", "initial jacket temperature")

    def __post_init__(self) -> None:
        super().__post_init__()
        from fuzzyctl.diagnostics import InputError

        if not self.volume0 < 0.98 * self.tank_volume:
            raise InputError("tank parameter 'volume0' must leave a gas cushion (< 98 % of tank_volume)")

    def initial_state(self) -> Vector:
        return np.array([self.volume0, self.temperature0, self.jacket_temperature0])

    def pressure(self, volume: float, temp: float) -> float:
        """Gauge pressure [kPa] with ``volume`` m^3 of liquid at ``temp`` degC."""
        gas0 = self.tank_volume - self.volume0
        gas = max(self.tank_volume - volume, 1e-3 * self.tank_volume)
        p_air0 = P_ATM - vapour_pressure(self.temperature0)
        p_air = p_air0 * gas0 / gas * (temp + KELVIN) / (self.temperature0 + KELVIN)
        return p_air + vapour_pressure(temp) - P_ATM

    def derivatives(self, t: float, x: Vector, u: Vector) -> Vector:
        vol, temp, jacket = x
        heating, valve, t_feed, t_amb = u
        p = self.pressure(vol, temp)
        q_in = max(valve, 0.0) / 100.0 * self.feed_flow * max(0.0, 1.0 - p / self.pump_head)
        head = p + 9.81 * vol / self.tank_volume  # kPa: rho g h with h ~ level for a 1 m tall tank
        q_out = max(-valve, 0.0) / 100.0 * self.drain_coefficient * math.sqrt(max(head, 0.0))
        vol_eff = max(vol, 1e-3 * self.tank_volume)
        q_jacket = self.jacket_transfer * (jacket - temp)
        dtemp = (RHO_C * q_in * (t_feed - temp) + q_jacket - self.loss_transfer * (temp - t_amb)) / (
            RHO_C * vol_eff
        )
        djacket = (heating / 100.0 * self.heater_power - q_jacket) / self.jacket_capacity
        return np.array([q_in - q_out, dtemp, djacket])

    def measure(self, state: Vector) -> dict[str, float]:
        vol, temp, jacket = (float(s) for s in state)
        return {
            "temp": temp,
            "pressure": self.pressure(vol, temp),
            "level": 100.0 * vol / self.tank_volume,
            "jacket_temp": jacket,
        }
