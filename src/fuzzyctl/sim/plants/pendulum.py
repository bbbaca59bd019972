"""The inverted pendulum on a cart (the Siemens manual's "Pendulum" example with its process
simulation; the classic benchmark of fuzzy balancing)."""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import ClassVar

from fuzzyctl.sim.integrate import Vector
from fuzzyctl.sim.plant import OdePlant, Port, param, register
from fuzzyctl.sim.plants.cart import G, cart_derivatives, cart_state


@register
@dataclass(frozen=True)
class InvertedPendulum(OdePlant):
    r"""A uniform rod hinged on a cart that moves on a horizontal track.

    Coordinates: cart position ``x`` [m], rod angle ``theta`` [rad] from the upright,
    positive when the rod leans towards +x.  Cart mass ``M``, rod mass ``m``, distance
    ``l`` from the hinge to the rod's centre of mass (half its length), moment of inertia
    about the centre ``m l^2 / 3``; Lagrange's equations with viscous cart friction ``b`` and
    hinge friction ``c``::

        (M + m) x'' + m l cos(theta) theta'' - m l sin(theta) theta'^2 = F - b x'
        m l cos(theta) x''  + 4/3 m l^2 theta''  - m g l sin(theta)     = -c theta'

    ``F`` [N] is the input ``force`` (saturated to +-``max_force``: the motor's limit) plus
    the disturbance input ``push`` [N] (a hand knocking the cart).  A positive force moves
    the cart towards +x and makes the rod fall back towards -x.

    Measured: ``angle`` (deg), ``angular_speed`` (deg/s), ``position`` (m), ``speed`` (m/s)."""

    kind: ClassVar[str] = "pendulum"
    title: ClassVar[str] = "inverted pendulum on a cart"
    inputs: ClassVar[tuple[Port, ...]] = (
        Port("force", "N", "motor force on the cart", 0.0, -30.0, 30.0),
        Port("push", "N", "disturbance force on the cart (not limited)", 0.0),
    )
    outputs: ClassVar[tuple[Port, ...]] = (
        Port("angle", "deg", "rod angle from the upright, positive leaning towards +x"),
        Port("angular_speed", "deg/s", "rate of change of the angle"),
        Port("position", "m", "cart position"),
        Port("speed", "m/s", "cart speed"),
    )

    cart_mass: float = param(1.0, "kg", "mass of the cart", low=1e-3)
    rod_mass: float = param(0.1, "kg", "mass of the rod", low=1e-3)
    half_length: float = param(0.5, "m", "hinge to the rod's centre of mass (half the rod)", low=1e-3)
    cart_friction: float = param(0.1, "N s/m", "viscous friction of the cart", low=0.0)
    hinge_friction: float = param(0.001, "N m s/rad", "viscous friction of the hinge", low=0.0)
    angle0: float = param(10.0, "deg", "initial angle", low=-89.0, high=89.0)
    angular_speed0: float = param(0.0, "deg/s", "initial angular speed")
    position0: float = param(0.0, "m", "initial cart position")
    speed0: float = param(0.0, "m/s", "initial cart speed")

    def initial_state(self) -> Vector:
        return cart_state(self.position0, self.speed0, self.angle0, self.angular_speed0)

    def derivatives(self, t: float, x: Vector, u: Vector) -> Vector:
        _, v, th, w = x
        M, m, l = self.cart_mass, self.rod_mass, self.half_length  # noqa: E741  (the textbook symbols)
        force = u[0] + u[1]
        s, c = math.sin(th), math.cos(th)
        a11, a12, a22 = M + m, m * l * c, 4.0 / 3.0 * m * l * l
        r1 = force - self.cart_friction * v + m * l * s * w * w
        r2 = m * G * l * s - self.hinge_friction * w
        return cart_derivatives(v, w, a11, a12, a22, r1, r2)

    def measure(self, state: Vector) -> dict[str, float]:
        x, v, th, w = (float(s) for s in state)
        return {"angle": math.degrees(th), "angular_speed": math.degrees(w), "position": x, "speed": v}
