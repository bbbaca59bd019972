"""The container crane of IEC 61131-7 Annex C: a trolley (the crane head) on a horizontal
track, driven by a motor, with the container hanging from it on ropes."""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import ClassVar

from fuzzyctl.sim.integrate import Vector
from fuzzyctl.sim.plant import OdePlant, Port, param, register
from fuzzyctl.sim.plants.cart import G, cart_derivatives, cart_state


@register
@dataclass(frozen=True)
class Crane(OdePlant):
    r"""Trolley and swinging load: a cart-pendulum with a point-mass load on a rigid rope.

    Coordinates: trolley (crane head) position ``x`` [m] along the track, rope angle
    ``theta`` [rad] from the vertical, positive when the load is ahead of the head (at
    larger ``x``).  Lagrange's equations with trolley mass ``M``, load mass ``m``, rope
    length ``l``::

        (M + m) x'' + m l cos(theta) theta'' - m l sin(theta) theta'^2 = F + W
        m l cos(theta) x'' + m l^2 theta''  + m g l sin(theta)         = -c theta' + W l cos(theta)

    ``W`` is a horizontal force on the load (wind, input ``wind`` in kN); ``c = 2 zeta w0 m l^2``
    is the small damping of the sway (air, rope), ``w0 = sqrt(g / l)``.

    The drive is a DC-motor characteristic: the command ``power`` (percent of the rated
    drive, -100..100) sets the force at standstill and the back-EMF takes it away with speed::

        F = F_stall (power / 100 - x' / v_top)

    so full power gives ``F_stall`` at standstill and a top speed ``v_top`` (no load on the
    drive).  This is what makes Annex C's "motor power" the one output: it fixes both how hard
    the head pulls and how fast it can go.

    Sensors (Annex C): the crane head position (``position``, m: the controller forms the
    distance to the target from it) and the sway angle (``angle``, degrees).  Also measured
    for plots and goals: ``speed`` (m/s), ``angular_speed`` (deg/s), ``load_position`` (m,
    ``x + l sin theta``)."""

    kind: ClassVar[str] = "crane"
    title: ClassVar[str] = "container crane (IEC 61131-7 Annex C)"
    inputs: ClassVar[tuple[Port, ...]] = (
        Port("power", "%", "motor power command, percent of the rated drive", 0.0, -100.0, 100.0),
        Port("wind", "kN", "horizontal force on the load (disturbance)", 0.0),
    )
    outputs: ClassVar[tuple[Port, ...]] = (
        Port("position", "m", "crane head (trolley) position on the track"),
        Port("angle", "deg", "sway angle of the load, positive ahead of the head"),
        Port("speed", "m/s", "trolley speed"),
        Port("angular_speed", "deg/s", "rate of change of the sway angle"),
        Port("load_position", "m", "horizontal position of the load"),
    )

    trolley_mass: float = param(8000.0, "kg", "mass of the trolley (crane head, hoist, spreader)", low=1.0)
    load_mass: float = param(25000.0, "kg", "mass of the container", low=1.0)
    rope_length: float = param(12.0, "m", "rope length, head to the load's centre of mass", low=0.5)
    stall_force: float = param(40.0, "kN", "drive force at full power and standstill", low=0.001)
    top_speed: float = param(1.6, "m/s", "trolley speed at full power with no force needed", low=0.001)
    sway_damping: float = param(0.005, "1", "damping ratio of the free sway (air, rope)", low=0.0)
    position0: float = param(0.0, "m", "initial trolley position")
    speed0: float = param(0.0, "m/s", "initial trolley speed")
    angle0: float = param(0.0, "deg", "initial sway angle", low=-80.0, high=80.0)
    angular_speed0: float = param(0.0, "deg/s", "initial sway rate")

    def initial_state(self) -> Vector:
        return cart_state(self.position0, self.speed0, self.angle0, self.angular_speed0)

    def derivatives(self, t: float, x: Vector, u: Vector) -> Vector:
        _, v, th, w = x
        M, m, l = self.trolley_mass, self.load_mass, self.rope_length  # noqa: E741  (the textbook symbols)
        force = self.stall_force * 1e3 * (u[0] / 100.0 - v / self.top_speed)
        wind = u[1] * 1e3
        s, c = math.sin(th), math.cos(th)
        damping = 2.0 * self.sway_damping * math.sqrt(G / l) * m * l * l
        a11, a12, a22 = M + m, m * l * c, m * l * l
        r1 = force + wind + m * l * s * w * w
        r2 = -m * G * l * s - damping * w + wind * l * c
        return cart_derivatives(v, w, a11, a12, a22, r1, r2)

    def measure(self, state: Vector) -> dict[str, float]:
        x, v, th, w = (float(s) for s in state)
        return {
            "position": x,
            "angle": math.degrees(th),
            "speed": v,
            "angular_speed": math.degrees(w),
            "load_position": x + self.rope_length * math.sin(th),
        }
