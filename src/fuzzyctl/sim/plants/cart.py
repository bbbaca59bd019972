"""What the container crane and the inverted pendulum share: a cart (trolley) with a
pendulum hinged on it, state ``[x, v, theta, omega]``, and equations of motion that are a
2x2 linear system in the two accelerations."""

from __future__ import annotations

import math

import numpy as np

from fuzzyctl.sim.integrate import Vector

G = 9.81
"""Standard gravity [m/s^2]."""


def cart_state(position: float, speed: float, angle_deg: float, angular_speed_deg: float) -> Vector:
    """The state vector ``[x, v, theta, omega]`` (angles in radians) from the parameters'
    units (angles in degrees)."""
    return np.array([position, speed, math.radians(angle_deg), math.radians(angular_speed_deg)])


def cart_derivatives(v: float, w: float, a11: float, a12: float, a22: float, r1: float, r2: float) -> Vector:
    """``d/dt [x, v, theta, omega]``: the accelerations solve the symmetric system
    ``[[a11, a12], [a12, a22]] [x'', theta''] = [r1, r2]`` (Cramer's rule)."""
    det = a11 * a22 - a12 * a12
    acc = (r1 * a22 - a12 * r2) / det
    alpha = (a11 * r2 - a12 * r1) / det
    return np.array([v, acc, w, alpha])
