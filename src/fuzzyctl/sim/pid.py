"""A small PID block as PLC libraries have it (ISA form, anti-windup, bumpless manual/auto
and gain changes), so that the structures of IEC 61131-7 Annex B are complete.

Continuous law (ISA / "standard" form, setpoint weights ``b`` and ``c``)::

    u = Kp [ (b w - y) + 1/Ti int(w - y) dt + Td d/dt(c w - y) ] + feedforward,
        the derivative through a first-order filter of time constant Td / N

Discretised with period ``h`` as Astrom & Hagglund (Advanced PID Control, 2006, ch. 13):

* ``P = Kp (b w - y)``
* ``D = ad D + bd ((c w - y) - (c w_prev - y_prev))`` with ``ad = Td / (Td + N h)``,
  ``bd = Kp Td N / (Td + N h)`` (backward difference: stable for every Td, no kick when c = 0)
* ``v = P + I + D + feedforward``, ``u = sat(v)`` to ``[low, high]``
* ``I += Kp h / Ti (w - y) + h / Tt (u - v)`` after the output (back-calculation with tracking
  time ``Tt``; ``antiwindup="clamp"`` stops integrating while the output is saturated and the
  error drives it further; ``"none"`` lets it wind up).

Manual mode outputs the manual value and keeps ``I = u_man - P - D - feedforward`` so that
switching to automatic continues from it (bumpless).  :meth:`PID.set_gains` changes Kp, Ti,
Td while running; the integral is corrected by the change of P (``I += P_old - P_new``) so
that the output does not jump (this is what fuzzy gain adaptation, Annex B.2, relies on).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from fuzzyctl.diagnostics import InputError


@dataclass(frozen=True)
class PIDTerms:
    """What the block computed in its last call (for plots and tests)."""

    p: float
    i: float
    d: float
    feedforward: float
    output: float
    saturated: bool


class PID:
    """A PID controller block.  ``kp`` [output unit / input unit], ``ti`` and ``td`` [s]
    (``ti = inf`` turns the integral off, ``td = 0`` the derivative), ``n`` the derivative
    filter ratio, ``b``/``c`` setpoint weights of P and D (c = 0: derivative on the
    measurement), ``low``/``high`` the output limits, ``tt`` the tracking time of the
    back-calculation (default ``sqrt(ti * td)``, or ``ti`` without derivative)."""

    def __init__(
        self,
        kp: float,
        ti: float = math.inf,
        td: float = 0.0,
        *,
        n: float = 10.0,
        b: float = 1.0,
        c: float = 0.0,
        low: float = -math.inf,
        high: float = math.inf,
        tt: float | None = None,
        antiwindup: str = "backcalc",
        initial_output: float = 0.0,
    ) -> None:
        if antiwindup not in ("backcalc", "clamp", "none"):
            raise InputError(f"pid antiwindup must be 'backcalc', 'clamp' or 'none', got {antiwindup!r}")
        if not low < high:
            raise InputError(f"pid output limits need low < high, got [{low}, {high}]")
        if n <= 0:
            raise InputError(f"pid derivative filter ratio n must be > 0, got {n}")
        self._check_gains(kp, ti, td)
        self.kp, self.ti, self.td = float(kp), float(ti), float(td)
        self.n, self.b, self.c = float(n), float(b), float(c)
        self.low, self.high = float(low), float(high)
        self._tt = tt
        self.antiwindup = antiwindup
        self.initial_output = float(initial_output)
        self.manual = False
        self.manual_value = self.initial_output
        self.reset()

    @staticmethod
    def _check_gains(kp: float, ti: float, td: float) -> None:
        if not math.isfinite(kp):
            raise InputError(f"pid kp must be finite, got {kp}")
        if not ti > 0:
            raise InputError(f"pid ti must be > 0 (inf: no integral action), got {ti}")
        if not (td >= 0 and math.isfinite(td)):
            raise InputError(f"pid td must be >= 0, got {td}")

    @property
    def tt(self) -> float:
        """The tracking time constant of the back-calculation."""
        if self._tt is not None:
            return self._tt
        if math.isinf(self.ti):
            return math.inf
        return math.sqrt(self.ti * self.td) if self.td > 0 else self.ti

    def reset(self) -> None:
        """Back to the state after start-up: integral at the initial output, no history."""
        self.i = min(max(self.initial_output, self.low), self.high)
        self.d = 0.0
        self._prev_d_input: float | None = None
        self._last_p_input: float | None = None
        self.last = PIDTerms(0.0, self.i, 0.0, 0.0, self.i, False)

    def set_manual(self, value: float) -> None:
        """Switch to manual mode with output ``value`` (saturated to the limits)."""
        self.manual = True
        self.manual_value = float(value)

    def set_auto(self) -> None:
        """Switch to automatic; the next call continues from the current output."""
        self.manual = False

    def set_gains(self, kp: float | None = None, ti: float | None = None, td: float | None = None) -> None:
        """Change the gains between calls without a jump of the output."""
        kp = self.kp if kp is None else float(kp)
        ti = self.ti if ti is None else float(ti)
        td = self.td if td is None else float(td)
        self._check_gains(kp, ti, td)
        if self._last_p_input is not None:
            self.i += (self.kp - kp) * self._last_p_input
        self.kp, self.ti, self.td = kp, ti, td

    def update(self, setpoint: float, measurement: float, dt: float, *, feedforward: float = 0.0) -> float:
        """One call with period ``dt`` [s]: the new output."""
        if not dt > 0:
            raise InputError(f"pid period must be > 0, got {dt}")
        p_input = self.b * setpoint - measurement
        self._last_p_input = p_input
        p = self.kp * p_input
        d_input = self.c * setpoint - measurement
        if self.td > 0:
            ad = self.td / (self.td + self.n * dt)
            bd = self.kp * self.td * self.n / (self.td + self.n * dt)
            change = 0.0 if self._prev_d_input is None else d_input - self._prev_d_input
            self.d = ad * self.d + bd * change
        else:
            self.d = 0.0
        self._prev_d_input = d_input
        error = setpoint - measurement
        if self.manual:
            out = min(max(self.manual_value, self.low), self.high)
            # Track: the integral takes whatever makes the automatic output equal the manual one.
            self.i = out - p - self.d - feedforward
            self.last = PIDTerms(p, self.i, self.d, feedforward, out, out != self.manual_value)
            return out
        v = p + self.i + self.d + feedforward
        out = min(max(v, self.low), self.high)
        saturated = out != v
        if not math.isinf(self.ti):
            step = self.kp * dt / self.ti * error
            if self.antiwindup == "backcalc":
                tt = self.tt
                # dt/tt above 1 would overshoot the tracking; 1 is "track within one call".
                self.i += step + (0.0 if math.isinf(tt) else min(dt / tt, 1.0) * (out - v))
            elif self.antiwindup == "clamp":
                if not (saturated and (v - out) * step > 0):
                    self.i += step
            else:
                self.i += step
        self.last = PIDTerms(p, self.i, self.d, feedforward, out, saturated)
        return out
