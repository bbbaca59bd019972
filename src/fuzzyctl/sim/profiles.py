"""Setpoint and disturbance profiles: functions of time.

From configuration values (TOML)::

    30                                   constant
    {steps = [[0, 30], [60, 10]]}        piecewise constant: 30 from t = 0, 10 from t = 60
    {points = [[0, 20], [100, 60]]}      piecewise linear, constant beyond the ends
    {pulse = 5, start = 2, width = 0.1}  5 during [2, 2.1), else 0 (or `base`)
    {sine = 1, period = 20, offset = 0}  a sine wave
"""

from __future__ import annotations

import bisect
import itertools
import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from typing import Any

from fuzzyctl.diagnostics import InputError


@dataclass(frozen=True)
class Profile:
    """A signal of time: ``profile(t)``."""

    kind: str
    times: tuple[float, ...]
    values: tuple[float, ...]
    period: float = 0.0
    offset: float = 0.0

    def __call__(self, t: float) -> float:
        if self.kind == "constant":
            return self.values[0]
        if self.kind == "sine":
            return self.offset + self.values[0] * math.sin(2 * math.pi * t / self.period)
        i = bisect.bisect_right(self.times, t) - 1
        if self.kind == "steps":
            return self.values[i] if i >= 0 else self.offset
        # points: linear between, constant beyond
        if i < 0:
            return self.values[0]
        if i >= len(self.times) - 1:
            return self.values[-1]
        t0, t1 = self.times[i], self.times[i + 1]
        v0, v1 = self.values[i], self.values[i + 1]
        return v0 if t1 == t0 else v0 + (v1 - v0) * (t - t0) / (t1 - t0)


def constant(value: float) -> Profile:
    return Profile("constant", (0.0,), (float(value),))


def steps(pairs: Sequence[tuple[float, float]], *, before: float | None = None) -> Profile:
    """Piecewise constant: each ``(t, v)`` holds ``v`` from ``t`` on; before the first time
    the value is ``before`` (default: the first value)."""
    times, values = _pairs(pairs, "steps")
    base = values[0] if before is None else float(before)
    return Profile("steps", times, values, offset=base)


def points(pairs: Sequence[tuple[float, float]]) -> Profile:
    """Piecewise linear through the ``(t, v)`` points, constant beyond them."""
    times, values = _pairs(pairs, "points")
    return Profile("points", times, values)


def pulse(value: float, start: float, width: float, base: float = 0.0) -> Profile:
    if width <= 0:
        raise InputError(f"pulse width must be > 0, got {width}")
    return steps([(start, value), (start + width, base)], before=base)


def sine(amplitude: float, period: float, offset: float = 0.0) -> Profile:
    if period <= 0:
        raise InputError(f"sine period must be > 0, got {period}")
    return Profile("sine", (), (float(amplitude),), period=float(period), offset=float(offset))


def _pairs(pairs: Sequence[Any], what: str) -> tuple[tuple[float, ...], tuple[float, ...]]:
    if not pairs:
        raise InputError(f"{what}: needs at least one [time, value] pair")
    times, values = [], []
    for pair in pairs:
        if not (isinstance(pair, (list, tuple)) and len(pair) == 2 and all(_is_number(x) for x in pair)):
            raise InputError(f"{what}: expected [time, value] pairs of numbers, got {pair!r}")
        times.append(float(pair[0]))
        values.append(float(pair[1]))
    if any(b < a for a, b in itertools.pairwise(times)):
        raise InputError(f"{what}: times must not decrease, got {times}")
    return tuple(times), tuple(values)


def _is_number(x: Any) -> bool:
    return isinstance(x, (int, float)) and not isinstance(x, bool) and math.isfinite(x)


def from_config(value: Any, *, where: str) -> Profile:
    """A profile from a configuration value (see the module docstring); errors name ``where``."""
    try:
        if _is_number(value):
            return constant(float(value))
        if isinstance(value, Mapping):
            keys = set(value)
            if "steps" in keys and keys <= {"steps", "before"}:
                return steps(value["steps"], before=value.get("before"))
            if keys == {"points"}:
                return points(value["points"])
            if "pulse" in keys and keys <= {"pulse", "start", "width", "base"}:
                return pulse(
                    value["pulse"], value.get("start", 0.0), value.get("width", 1.0), value.get("base", 0.0)
                )
            if "sine" in keys and keys <= {"sine", "period", "offset"}:
                return sine(value["sine"], value.get("period", 1.0), value.get("offset", 0.0))
    except InputError as exc:
        raise InputError(f"{where}: {exc}") from None
    raise InputError(
        f"{where}: expected a number or a table with steps / points / pulse / sine, got {value!r}"
    )
