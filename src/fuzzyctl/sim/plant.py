"""What every plant model provides, and the registry of plant models by name.

A plant is a frozen dataclass: its fields are the physical parameters and the initial
conditions, each with its unit and meaning in the field's metadata (``param(...)``), so that
a TOML file, the docs and the studio can list them.  The state of a running plant is held
by the loop, never by the plant object, so one plant can drive several loops and a loop can
be reset or stepped from outside.
"""

from __future__ import annotations

import dataclasses
import math
from abc import ABC, abstractmethod
from collections.abc import Mapping
from dataclasses import dataclass, field
from typing import Any, ClassVar, Generic, TypeVar

import numpy as np

from fuzzyctl.diagnostics import InputError
from fuzzyctl.sim.integrate import Integrator, Vector

S = TypeVar("S")


@dataclass(frozen=True)
class Port:
    """A named plant signal: an input (manipulated variable or disturbance) or a measured
    output.  Inputs have a default (what the plant gets when nobody drives it) and limits
    (the actuator's range: the loop saturates commands to it)."""

    name: str
    unit: str
    description: str
    default: float = 0.0
    low: float = -math.inf
    high: float = math.inf


def param(default: float, unit: str, doc: str, *, low: float = -math.inf, high: float = math.inf) -> Any:
    """A plant parameter field: default, unit, meaning and the physically valid interval."""
    return field(default=default, metadata={"unit": unit, "doc": doc, "low": low, "high": high})


@dataclass(frozen=True)
class ParamInfo:
    name: str
    default: float
    unit: str
    doc: str
    low: float
    high: float


class Plant(ABC, Generic[S]):
    """A process model.  Subclasses are frozen dataclasses declaring ``kind``, ``inputs``,
    ``outputs`` and implementing :meth:`start`, :meth:`advance` and :meth:`measure`."""

    kind: ClassVar[str]
    title: ClassVar[str]
    inputs: ClassVar[tuple[Port, ...]]
    outputs: ClassVar[tuple[Port, ...]]

    def __post_init__(self) -> None:
        for info in self.parameters():
            value = getattr(self, info.name)
            if isinstance(value, float) and math.isnan(value) and math.isnan(info.default):
                continue  # nan default = "derived from the other parameters"
            if not isinstance(value, (int, float)) or isinstance(value, bool) or not math.isfinite(value):
                raise InputError(
                    f"{self.kind} parameter {info.name!r} must be a finite number, got {value!r}"
                )
            if not info.low <= value <= info.high:
                raise InputError(
                    f"{self.kind} parameter {info.name!r} = {value:g} {info.unit} is outside "
                    f"[{info.low:g}, {info.high:g}]"
                )

    @classmethod
    def parameters(cls) -> tuple[ParamInfo, ...]:
        """Every parameter with its default, unit, meaning and valid interval."""
        out = []
        for f in dataclasses.fields(cls):  # type: ignore[arg-type]
            meta = f.metadata
            default = float(f.default)  # type: ignore[arg-type]
            out.append(ParamInfo(f.name, default, meta["unit"], meta["doc"], meta["low"], meta["high"]))
        return tuple(out)

    @classmethod
    def input_port(cls, name: str) -> Port:
        for port in cls.inputs:
            if port.name == name:
                return port
        raise InputError(
            f"{cls.kind} has no input {name!r} (inputs: {', '.join(p.name for p in cls.inputs)})"
        )

    @abstractmethod
    def start(self) -> S:
        """The initial state, from the initial-condition parameters."""

    @abstractmethod
    def advance(self, state: S, u: Mapping[str, float], t: float, dt: float, integrator: Integrator) -> S:
        """The state at ``t + dt`` with the inputs ``u`` (every input, saturated) held."""

    @abstractmethod
    def measure(self, state: S) -> dict[str, float]:
        """The measured outputs (the sensors) in the state."""

    @classmethod
    def configure(cls, parameters: Mapping[str, Any] | None) -> Plant[Any]:
        """The plant with some parameters changed (a ``[plant]`` table without ``model``);
        unknown names are errors that list the valid ones."""
        names = {p.name for p in cls.parameters()}
        for key in parameters or {}:
            if key not in names:
                raise InputError(
                    f"plant {cls.kind!r} has no parameter {key!r}; parameters: {', '.join(sorted(names))}"
                )
        return cls(**dict(parameters or {}))

    def replace(self, **changes: float) -> Plant[S]:
        """A copy with some parameters changed (validated)."""
        return dataclasses.replace(self, **changes)  # type: ignore[type-var]


class OdePlant(Plant[Vector]):
    """A plant given by ``x' = f(t, x, u)``; integrated by the loop's integrator."""

    @abstractmethod
    def initial_state(self) -> Vector: ...

    @abstractmethod
    def derivatives(self, t: float, x: Vector, u: Vector) -> Vector:
        """``dx/dt`` with the inputs as a vector in ``inputs`` order."""

    def start(self) -> Vector:
        return np.asarray(self.initial_state(), dtype=np.float64)

    def advance(
        self, state: Vector, u: Mapping[str, float], t: float, dt: float, integrator: Integrator
    ) -> Vector:
        uvec = np.array([u[p.name] for p in self.inputs], dtype=np.float64)
        out = integrator.advance(lambda tt, xx: self.derivatives(tt, xx, uvec), t, state, dt)
        if not np.all(np.isfinite(out)):
            raise FloatingPointError(f"the {self.kind} model diverged at t={t:g} s (state {out.tolist()})")
        return out


PLANTS: dict[str, type[Plant[Any]]] = {}


def register(cls: type[Plant[Any]]) -> type[Plant[Any]]:
    """Class decorator: make a plant available by its ``kind`` (TOML ``[plant] model = ...``)."""
    PLANTS[cls.kind] = cls
    return cls


def make_plant(kind: str, parameters: Mapping[str, Any] | None = None) -> Plant[Any]:
    """The plant model ``kind`` with some parameters changed; unknown names are errors that
    list the valid ones."""
    import fuzzyctl.sim.plants  # noqa: F401  (registers the models)

    if kind not in PLANTS:
        raise InputError(f"unknown plant model {kind!r}; models: {', '.join(sorted(PLANTS))}")
    return PLANTS[kind].configure(parameters)
