"""The ways a loop can run its fuzzy function block: the engine, the PLC blocks with their
cycle time, or the native code of the code generator.  All of them look alike to a
controller structure (:class:`FuzzyRuntime`)."""

from __future__ import annotations

from collections.abc import Mapping
from typing import Protocol

from fuzzyctl.diagnostics import InputError
from fuzzyctl.model import Document, FunctionBlock

RUNTIMES = ("engine", "siemens", "xfuz", "native")


class FuzzyRuntime(Protocol):
    """A fuzzy function block as a structure calls it once per cycle."""

    name: str
    inputs: tuple[str, ...]
    outputs: tuple[str, ...]

    def evaluate(self, inputs: Mapping[str, float]) -> dict[str, float]:
        """Outputs for these inputs (one PLC cycle)."""
        ...

    def reset(self) -> None:
        """Forget everything kept between cycles."""
        ...


class EngineRuntime:
    """The inference engine (:func:`fuzzyctl.compile`), exact IEC 61131-7 semantics."""

    def __init__(self, model: Document | FunctionBlock, *, block: str | None = None) -> None:
        import fuzzyctl

        self.controller = fuzzyctl.compile(model, block=block)
        self.name = "engine"
        self.inputs = self.controller.inputs
        self.outputs = self.controller.outputs

    def evaluate(self, inputs: Mapping[str, float]) -> dict[str, float]:
        return self.controller.evaluate(inputs)

    def reset(self) -> None:
        self.controller.reset()


def make_runtime(
    model: Document | FunctionBlock,
    kind: str = "engine",
    *,
    block: str | None = None,
    cycle: float | None = None,
) -> FuzzyRuntime:
    """The runtime ``kind`` (one of :data:`RUNTIMES`) for a model."""
    if kind == "engine":
        return EngineRuntime(model, block=block)
    if kind == "siemens":
        from fuzzyctl.sim.plc_runtimes import SiemensRuntime

        return SiemensRuntime(model, block=block)
    if kind == "xfuz":
        from fuzzyctl.sim.plc_runtimes import XfuzRuntime

        return XfuzRuntime(model, block=block, cycle=cycle or 0.01)
    if kind == "native":
        raise InputError("controller runtime 'native' is not available in this build (engine, siemens, xfuz)")
    raise InputError(f"unknown controller runtime {kind!r}; runtimes: {', '.join(RUNTIMES)}")
