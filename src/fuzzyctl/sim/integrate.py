"""Integrating a plant over one control period with the manipulated variables held constant.

A sampled loop holds the controller's outputs between calls (a zero-order hold), so a plant
only ever has to be integrated over one period with constant inputs.  Two integrators:

* :class:`FixedStep` - classical 4th-order Runge-Kutta with a fixed number of sub-steps per
  period: deterministic, bit-for-bit repeatable, fast; the default of tests.
* :class:`Adaptive` - :func:`scipy.integrate.solve_ivp` (RK45, LSODA, ...) with error control,
  restarted at every period because the inputs jump there.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from typing import Protocol

import numpy as np
import numpy.typing as npt

from fuzzyctl.diagnostics import InputError

Vector = npt.NDArray[np.float64]
Derivatives = Callable[[float, Vector], Vector]


class Integrator(Protocol):
    """Advances ``x' = f(t, x)`` from ``t`` to ``t + dt``."""

    def advance(self, f: Derivatives, t: float, x: Vector, dt: float) -> Vector: ...


@dataclass(frozen=True)
class FixedStep:
    """Runge-Kutta 4 with ``max_step`` as the largest sub-step (seconds).

    A period ``dt`` is cut into ``ceil(dt / max_step)`` equal sub-steps, so the result does not
    depend on floating-point accumulation of time."""

    max_step: float = 0.01

    def __post_init__(self) -> None:
        if not self.max_step > 0:
            raise InputError(f"integrator max_step must be > 0, got {self.max_step}")

    def advance(self, f: Derivatives, t: float, x: Vector, dt: float) -> Vector:
        n = max(1, int(np.ceil(dt / self.max_step - 1e-9)))
        h = dt / n
        for i in range(n):
            ti = t + i * h
            k1 = f(ti, x)
            k2 = f(ti + h / 2, x + (h / 2) * k1)
            k3 = f(ti + h / 2, x + (h / 2) * k2)
            k4 = f(ti + h, x + h * k3)
            x = x + (h / 6) * (k1 + 2 * k2 + 2 * k3 + k4)
        return x


@dataclass(frozen=True)
class Adaptive:
    """:func:`scipy.integrate.solve_ivp` with ``method`` (RK45, RK23, DOP853, Radau, BDF, LSODA)
    and relative/absolute tolerances."""

    method: str = "RK45"
    rtol: float = 1e-6
    atol: float = 1e-9

    def __post_init__(self) -> None:
        methods = ("RK45", "RK23", "DOP853", "Radau", "BDF", "LSODA")
        if self.method not in methods:
            raise InputError(f"integrator method must be one of {', '.join(methods)}, got {self.method!r}")

    def advance(self, f: Derivatives, t: float, x: Vector, dt: float) -> Vector:
        from scipy.integrate import solve_ivp

        sol = solve_ivp(f, (t, t + dt), x, method=self.method, rtol=self.rtol, atol=self.atol)
        if not sol.success:
            raise FloatingPointError(f"solve_ivp failed at t={t:g}: {sol.message}")
        return np.asarray(sol.y[:, -1], dtype=np.float64)


def make_integrator(name: str = "rk4", **options: float | str) -> Integrator:
    """``"rk4"`` (:class:`FixedStep`, option ``max_step``) or ``"solve_ivp"`` / a solve_ivp
    method name (:class:`Adaptive`, options ``method``, ``rtol``, ``atol``)."""
    key = name.lower()
    if key in ("rk4", "fixed", "fixed-step"):
        return FixedStep(**options)  # type: ignore[arg-type]
    if key in ("solve_ivp", "adaptive"):
        return Adaptive(**options)  # type: ignore[arg-type]
    for method in ("RK45", "RK23", "DOP853", "Radau", "BDF", "LSODA"):
        if key == method.lower():
            return Adaptive(method=method, **options)  # type: ignore[arg-type]
    raise InputError(f"unknown integrator {name!r}: use 'rk4' (fixed step) or 'solve_ivp'")
