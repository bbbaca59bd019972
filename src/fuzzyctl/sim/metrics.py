"""Quality figures of a closed-loop response.

For a response ``y`` to a setpoint ``w`` starting from ``y0`` (the step ``w - y0``):

* ISE ``= int e^2 dt``, IAE ``= int |e| dt``, ITAE ``= int t |e| dt`` with ``e = w - y``
  (trapezoidal rule over the recorded samples);
* overshoot: the largest excursion past the setpoint in the direction of the step, absolute
  and in percent of the step (0 when the response never passes the setpoint);
* settling time: the first time from which on ``|y - w| <= band`` (and every extra
  condition) holds until the end of the record; ``inf`` when it never settles, measured
  from ``t_step``.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import asdict, dataclass

import numpy as np
import numpy.typing as npt

from fuzzyctl.sim.loop import Trace

Array = npt.NDArray[np.float64]


def _trapezoid(y: Array, t: Array) -> float:
    if len(t) < 2:
        return 0.0
    return float(np.sum((y[1:] + y[:-1]) * np.diff(t)) / 2.0)


def ise(t: Array, e: Array) -> float:
    return _trapezoid(np.asarray(e) ** 2, np.asarray(t))


def iae(t: Array, e: Array) -> float:
    return _trapezoid(np.abs(np.asarray(e)), np.asarray(t))


def itae(t: Array, e: Array) -> float:
    t = np.asarray(t)
    return _trapezoid(t * np.abs(np.asarray(e)), t)


def overshoot(y: Array, target: float, start: float) -> float:
    """Largest excursion of ``y`` beyond ``target`` in the direction from ``start``."""
    direction = 1.0 if target >= start else -1.0
    return max(0.0, float(np.max(direction * (np.asarray(y) - target))))


def settled_from(t: Array, ok: npt.NDArray[np.bool_]) -> float:
    """The first time from which ``ok`` holds to the end; ``inf`` if it does not hold at the end."""
    ok = np.asarray(ok, dtype=bool)
    if len(ok) == 0 or not ok[-1]:
        return math.inf
    bad = np.flatnonzero(~ok)
    return float(t[0] if len(bad) == 0 else t[bad[-1] + 1])


@dataclass(frozen=True)
class Quality:
    """The quality figures of one response (see the module docstring)."""

    signal: str
    setpoint: float
    ise: float
    iae: float
    itae: float
    overshoot: float
    overshoot_percent: float
    settling_time: float
    band: float
    final_error: float

    def as_dict(self) -> dict[str, float | str]:
        return asdict(self)

    def table_row(self) -> str:
        st = "never" if math.isinf(self.settling_time) else f"{self.settling_time:.1f} s"
        return (
            f"{self.signal}: ISE {self.ise:.4g}, IAE {self.iae:.4g}, overshoot {self.overshoot:.3g} "
            f"({self.overshoot_percent:.1f} %), settling time ({self.band:g} band) {st}, "
            f"final error {self.final_error:.3g}"
        )


def quality(
    trace: Trace,
    signal: str,
    setpoint: str | float,
    *,
    band: float,
    limits: Mapping[str, float] | None = None,
    t_step: float = 0.0,
) -> Quality:
    """Figures for ``trace[signal]`` against the setpoint (a trace column or a number), from
    ``t_step`` on; ``limits`` adds conditions ``|trace[name]| <= limit`` to settling."""
    t_all = trace["t"]
    keep = t_all >= t_step - 1e-12
    t = t_all[keep]
    y = trace[signal][keep]
    w = trace[setpoint][keep] if isinstance(setpoint, str) else np.full_like(y, float(setpoint))
    target = float(w[-1])
    e = w - y
    ok = np.abs(y - w) <= band
    for name, limit in (limits or {}).items():
        ok &= np.abs(trace[name][keep]) <= limit
    step = target - float(y[0])
    over = overshoot(y, target, float(y[0]))
    return Quality(
        signal=signal,
        setpoint=target,
        ise=ise(t, e),
        iae=iae(t, e),
        itae=itae(t - t[0], e),
        overshoot=over,
        overshoot_percent=100.0 * over / abs(step) if step else 0.0,
        settling_time=settled_from(t, ok) - t_step,
        band=band,
        final_error=float(e[-1]),
    )
