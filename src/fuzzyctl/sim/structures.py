"""The controller structures of IEC 61131-7 built around a fuzzy function block.

A structure is called once per controller cycle with the loop's signals (setpoints,
measurements, time ``t``) and returns the commands for the plant inputs it drives::

    commands = structure.step(signals, dt)
    structure.internals            # its internal signals of that cycle, for plots

* :class:`DirectFuzzy` - Annex B.3: the fuzzy block drives the process directly (the
  operator's knowledge, e.g. the container crane of Annex C).
* :class:`FuzzyPI` - Annex A.3, figure A.13b: error and its derivative in, the output is a
  rate of change that is integrated into the manipulated variable ("a velocity algorithm ...
  dynamic behaviour similar to PI").
* :class:`PIDLoop` - a conventional loop with the :class:`~fuzzyctl.sim.pid.PID` block.
* :class:`PreControl` - Annex B.1: a PID loop whose output gets a corrective signal from the
  fuzzy block.
* :class:`GainScheduledPID` - Annex B.2: the fuzzy block adapts the PID's parameters.

Fuzzy inputs and plant commands are :mod:`~fuzzyctl.sim.signals` expressions, evaluated in
the order given; an expression can use the fuzzy inputs defined before it, and output
expressions see the fuzzy outputs.
"""

from __future__ import annotations

import math
from abc import ABC, abstractmethod
from collections.abc import Mapping

from fuzzyctl.diagnostics import InputError
from fuzzyctl.sim.pid import PID
from fuzzyctl.sim.runtimes import FuzzyRuntime
from fuzzyctl.sim.signals import Expression, compile_all

ExprLike = str | Expression


class Structure(ABC):
    """One controller structure: what the loop calls each cycle."""

    kind: str = ""
    drives: tuple[str, ...] = ()

    def __init__(self) -> None:
        self.internals: dict[str, float] = {}

    @abstractmethod
    def step(self, signals: Mapping[str, float], dt: float) -> dict[str, float]:
        """Commands for the plant inputs in :attr:`drives` after one cycle of ``dt`` s."""

    @abstractmethod
    def reset(self) -> None:
        """Back to the state before the first cycle."""

    def internal_names(self) -> tuple[str, ...]:
        """The names :attr:`internals` will have (stable column order for traces)."""
        return ()


class _FuzzyPart:
    """Preprocessing -> fuzzy block: inputs as expressions of the loop's signals."""

    def __init__(self, fuzzy: FuzzyRuntime, inputs: Mapping[str, ExprLike], where: str) -> None:
        self.fuzzy = fuzzy
        self.inputs = compile_all(inputs, where=f"{where}.inputs")
        missing = [name for name in fuzzy.inputs if name not in self.inputs]
        unknown = [name for name in self.inputs if name not in fuzzy.inputs]
        if unknown:
            raise InputError(
                f"{where}.inputs: {', '.join(map(repr, unknown))} is not an input of function block "
                f"{fuzzy_name(fuzzy)} (inputs: {', '.join(fuzzy.inputs)})"
            )
        if missing:
            raise InputError(
                f"{where}.inputs: no signal given for the fuzzy input(s) {', '.join(map(repr, missing))}"
            )

    def evaluate(self, signals: Mapping[str, float], dt: float) -> tuple[dict[str, float], dict[str, float]]:
        env = dict(signals)
        values: dict[str, float] = {}
        for name, expr in self.inputs.items():
            values[name] = env[name] = expr(env, dt)
        return values, self.fuzzy.evaluate(values)

    def reset(self) -> None:
        self.fuzzy.reset()
        for expr in self.inputs.values():
            expr.reset()

    def names(self) -> tuple[str, ...]:
        return (*(f"fb.{n}" for n in self.inputs), *(f"fb.{n}" for n in self.fuzzy.outputs))

    def record(self, into: dict[str, float], values: Mapping[str, float], out: Mapping[str, float]) -> None:
        for name, v in values.items():
            into[f"fb.{name}"] = v
        for name, v in out.items():
            into[f"fb.{name}"] = v


def fuzzy_name(fuzzy: FuzzyRuntime) -> str:
    controller = getattr(fuzzy, "controller", None)
    return repr(getattr(controller, "name", None) or getattr(fuzzy, "block_name", "") or fuzzy.name)


def _check_output(fuzzy: FuzzyRuntime, name: str, where: str) -> None:
    if name not in fuzzy.outputs:
        raise InputError(
            f"{where}: {name!r} is not an output of the function block (outputs: {', '.join(fuzzy.outputs)})"
        )


class DirectFuzzy(Structure):
    """Annex B.3: ``plant input = expression(fuzzy outputs)``; by default each fuzzy output
    drives the plant input of the same name."""

    kind = "direct"

    def __init__(
        self,
        fuzzy: FuzzyRuntime,
        inputs: Mapping[str, ExprLike],
        outputs: Mapping[str, ExprLike] | None = None,
    ) -> None:
        super().__init__()
        self.part = _FuzzyPart(fuzzy, inputs, "controller")
        self.outputs = compile_all(outputs or {n: n for n in fuzzy.outputs}, where="controller.outputs")
        self.drives = tuple(self.outputs)

    def step(self, signals: Mapping[str, float], dt: float) -> dict[str, float]:
        values, out = self.part.evaluate(signals, dt)
        env = {**signals, **values, **out}
        self.internals = {}
        self.part.record(self.internals, values, out)
        return {name: expr(env, dt) for name, expr in self.outputs.items()}

    def reset(self) -> None:
        self.part.reset()
        for expr in self.outputs.values():
            expr.reset()
        self.internals = {}

    def internal_names(self) -> tuple[str, ...]:
        return self.part.names()


class FuzzyPI(Structure):
    """Figure A.13b: the fuzzy output ``output`` is a rate (unit of the manipulated variable per
    second); ``U += gain * output * dt``, limited to ``[low, high]`` (the limit is also the
    anti-windup of this velocity form: U never runs past what the actuator can do)."""

    kind = "fuzzy_pi"

    def __init__(
        self,
        fuzzy: FuzzyRuntime,
        inputs: Mapping[str, ExprLike],
        *,
        output: str,
        drive: str,
        gain: float = 1.0,
        low: float = -math.inf,
        high: float = math.inf,
        initial: float = 0.0,
    ) -> None:
        super().__init__()
        if not low < high:
            raise InputError(f"controller: fuzzy_pi needs low < high, got [{low}, {high}]")
        self.part = _FuzzyPart(fuzzy, inputs, "controller")
        _check_output(fuzzy, output, "controller.output")
        self.output, self.drives = output, (drive,)
        self.gain, self.low, self.high, self.initial = gain, low, high, initial
        self.value = min(max(initial, low), high)

    def step(self, signals: Mapping[str, float], dt: float) -> dict[str, float]:
        values, out = self.part.evaluate(signals, dt)
        self.value = min(max(self.value + self.gain * out[self.output] * dt, self.low), self.high)
        self.internals = {}
        self.part.record(self.internals, values, out)
        self.internals["integrated"] = self.value
        return {self.drives[0]: self.value}

    def reset(self) -> None:
        self.part.reset()
        self.value = min(max(self.initial, self.low), self.high)
        self.internals = {}

    def internal_names(self) -> tuple[str, ...]:
        return (*self.part.names(), "integrated")


class _PidPart:
    def __init__(self, pid: PID, setpoint: ExprLike, measurement: ExprLike) -> None:
        self.pid = pid
        exprs = compile_all({"setpoint": setpoint, "measurement": measurement}, where="controller")
        self.setpoint, self.measurement = exprs["setpoint"], exprs["measurement"]

    def update(self, signals: Mapping[str, float], dt: float, feedforward: float = 0.0) -> float:
        return self.pid.update(
            self.setpoint(signals, dt), self.measurement(signals, dt), dt, feedforward=feedforward
        )

    def reset(self) -> None:
        self.pid.reset()
        self.setpoint.reset()
        self.measurement.reset()

    @staticmethod
    def names() -> tuple[str, ...]:
        return ("pid.p", "pid.i", "pid.d", "pid.kp", "pid.ti", "pid.td")

    def record(self, into: dict[str, float]) -> None:
        t = self.pid.last
        into.update(
            {
                "pid.p": t.p,
                "pid.i": t.i,
                "pid.d": t.d,
                "pid.kp": self.pid.kp,
                "pid.ti": self.pid.ti,
                "pid.td": self.pid.td,
            }
        )


class PIDLoop(Structure):
    """A conventional loop: ``drive = PID(setpoint, measurement) + feedforward``."""

    kind = "pid"

    def __init__(
        self,
        pid: PID,
        *,
        setpoint: ExprLike,
        measurement: ExprLike,
        drive: str,
        feedforward: ExprLike | None = None,
    ) -> None:
        super().__init__()
        self.part = _PidPart(pid, setpoint, measurement)
        self.feedforward = (
            None if feedforward is None else compile_all({"ff": feedforward}, where="controller")["ff"]
        )
        self.drives = (drive,)

    def step(self, signals: Mapping[str, float], dt: float) -> dict[str, float]:
        ff = 0.0 if self.feedforward is None else self.feedforward(signals, dt)
        u = self.part.update(signals, dt, ff)
        self.internals = {}
        self.part.record(self.internals)
        return {self.drives[0]: u}

    def reset(self) -> None:
        self.part.reset()
        if self.feedforward is not None:
            self.feedforward.reset()
        self.internals = {}

    def internal_names(self) -> tuple[str, ...]:
        return self.part.names()


class _FuzzyPid(Structure):
    """A PID block with a fuzzy block beside it (Annex B.1 and B.2): the parts, their
    internals, the reset and the one drive they share."""

    def __init__(
        self,
        pid: PID,
        fuzzy: FuzzyRuntime,
        inputs: Mapping[str, ExprLike],
        setpoint: ExprLike,
        measurement: ExprLike,
        drive: str,
    ) -> None:
        super().__init__()
        self.pid_part = _PidPart(pid, setpoint, measurement)
        self.part = _FuzzyPart(fuzzy, inputs, "controller")
        self.drives = (drive,)

    def _drive(self, values: Mapping[str, float], out: Mapping[str, float], u: float) -> dict[str, float]:
        """Records this cycle's internals and returns the drive command ``u``."""
        self.internals = {}
        self.part.record(self.internals, values, out)
        self.pid_part.record(self.internals)
        return {self.drives[0]: u}

    def reset(self) -> None:
        self.part.reset()
        self.pid_part.reset()
        self.internals = {}

    def internal_names(self) -> tuple[str, ...]:
        return (*self.part.names(), *self.pid_part.names())


class PreControl(_FuzzyPid):
    """Annex B.1: ``drive = sat(PID + gain * correction)``; the corrective signal enters the
    PID block as its feedforward, before the limits, so the PID's anti-windup sees the sum."""

    kind = "precontrol"

    def __init__(
        self,
        pid: PID,
        fuzzy: FuzzyRuntime,
        inputs: Mapping[str, ExprLike],
        *,
        setpoint: ExprLike,
        measurement: ExprLike,
        drive: str,
        correction: str,
        gain: float = 1.0,
    ) -> None:
        super().__init__(pid, fuzzy, inputs, setpoint, measurement, drive)
        _check_output(fuzzy, correction, "controller.correction")
        self.correction, self.gain = correction, gain

    def step(self, signals: Mapping[str, float], dt: float) -> dict[str, float]:
        values, out = self.part.evaluate(signals, dt)
        return self._drive(values, out, self.pid_part.update(signals, dt, self.gain * out[self.correction]))


class GainScheduledPID(_FuzzyPid):
    """Annex B.2: each cycle the fuzzy block sets some of the PID's parameters (``gains``
    maps ``kp``/``ti``/``td`` to fuzzy outputs), as values (``mode="absolute"``) or as factors
    of the PID's nominal values (``mode="factor"``); changes are bumpless
    (:meth:`~fuzzyctl.sim.pid.PID.set_gains`)."""

    kind = "adaptive_pid"

    def __init__(
        self,
        pid: PID,
        fuzzy: FuzzyRuntime,
        inputs: Mapping[str, ExprLike],
        *,
        setpoint: ExprLike,
        measurement: ExprLike,
        drive: str,
        gains: Mapping[str, str],
        mode: str = "factor",
    ) -> None:
        if mode not in ("absolute", "factor"):
            raise InputError(f"controller.mode must be 'absolute' or 'factor', got {mode!r}")
        for param_name, output in gains.items():
            if param_name not in ("kp", "ti", "td"):
                raise InputError(f"controller.gains: {param_name!r} is not a PID parameter (kp, ti, td)")
            _check_output(fuzzy, output, f"controller.gains.{param_name}")
        if not gains:
            raise InputError("controller.gains: adapt at least one of kp, ti, td")
        super().__init__(pid, fuzzy, inputs, setpoint, measurement, drive)
        self.gains, self.mode = dict(gains), mode
        self.nominal = {"kp": pid.kp, "ti": pid.ti, "td": pid.td}

    def step(self, signals: Mapping[str, float], dt: float) -> dict[str, float]:
        values, out = self.part.evaluate(signals, dt)
        new = {}
        for param_name, output in self.gains.items():
            v = out[output]
            new[param_name] = v * self.nominal[param_name] if self.mode == "factor" else v
        try:
            self.pid_part.pid.set_gains(**new)
        except InputError as exc:
            raise InputError(
                f"controller.gains: the fuzzy block set an invalid PID parameter: {exc}"
            ) from None
        return self._drive(values, out, self.pid_part.update(signals, dt))

    def reset(self) -> None:
        self.pid_part.pid.set_gains(**self.nominal)
        super().reset()
