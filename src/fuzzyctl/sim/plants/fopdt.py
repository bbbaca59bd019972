"""The first-order-plus-dead-time process, the plant of PID tuning rules."""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass
from typing import ClassVar

from fuzzyctl.sim.integrate import Integrator
from fuzzyctl.sim.plant import Plant, Port, param, register


@dataclass(frozen=True)
class FopdtState:
    """Output ``y`` at time ``t``, the input now acting on the lag, and the inputs still
    travelling through the dead time as (time they arrive, value)."""

    t: float
    y: float
    acting: float
    pending: tuple[tuple[float, float], ...]


@register
@dataclass(frozen=True)
class Fopdt(Plant[FopdtState]):
    r"""``G(s) = K e^{-L s} / (tau s + 1)``: a first-order lag behind a pure dead time::

        tau y'(t) + y(t) = K (u(t - L) + load(t - L))

    Solved exactly, not integrated: between two changes of the delayed input the output
    moves as ``y(t + h) = K u + (y(t) - K u) e^{-h / tau}``, and the loop's inputs are held
    over each period, so the dead time is a queue of input changes.  Before ``t = L`` the lag
    sees ``u0`` (the process was at rest with that input; ``y0`` defaults to ``K u0``).

    Input ``u`` (no limits unless ``u_low``/``u_high``), disturbance ``load`` (added to the
    input, same unit); measured ``y``."""

    kind: ClassVar[str] = "fopdt"
    title: ClassVar[str] = "first order plus dead time"
    inputs: ClassVar[tuple[Port, ...]] = (
        Port("u", "1", "manipulated variable"),
        Port("load", "1", "load disturbance, added to the input"),
    )
    outputs: ClassVar[tuple[Port, ...]] = (Port("y", "1", "process output"),)

    gain: float = param(1.0, "1", "static gain K (output per unit input)")
    time_constant: float = param(10.0, "s", "time constant tau of the lag", low=1e-9)
    dead_time: float = param(2.0, "s", "dead time L", low=0.0)
    u0: float = param(0.0, "1", "input before the start")
    y0: float = param(math.nan, "1", "initial output (default: K u0, at rest)")

    def start(self) -> FopdtState:
        y0 = self.gain * self.u0 if math.isnan(self.y0) else self.y0
        return FopdtState(0.0, y0, self.u0, ())

    def advance(
        self, state: FopdtState, u: Mapping[str, float], t: float, dt: float, integrator: Integrator
    ) -> FopdtState:
        value = u["u"] + u.get("load", 0.0)
        pending = [*state.pending, (t + self.dead_time, value)]
        y, acting, now, end = state.y, state.acting, t, t + dt
        while pending and pending[0][0] <= end + 1e-12 * max(1.0, abs(end)):
            arrive, new = pending.pop(0)
            if arrive > now:
                y = self._lag(y, acting, arrive - now)
                now = arrive
            acting = new
        y = self._lag(y, acting, end - now)
        return FopdtState(end, y, acting, tuple(pending))

    def _lag(self, y: float, u: float, h: float) -> float:
        target = self.gain * u
        return target + (y - target) * math.exp(-h / self.time_constant)

    def measure(self, state: FopdtState) -> dict[str, float]:
        return {"y": state.y}
