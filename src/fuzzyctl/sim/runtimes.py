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
        self.inputs = tuple(self.controller.inputs)
        self.outputs = tuple(self.controller.outputs)

    def evaluate(self, inputs: Mapping[str, float]) -> dict[str, float]:
        # a plant may leave an input's range (the crane starts 30 m away, distance's terms end
        # at 20): the loop runs on what the terms give there, as the PLC would, without a word
        return self.controller.evaluate(inputs, out_of_range="ignore")

    def reset(self) -> None:
        self.controller.reset()


class NativeRuntime(EngineRuntime):
    """The code generator's native backend (``fuzzyctl.compile(model, backend="native")``):
    the generated C, compiled once into a cached shared library, called each cycle.

    Unlike :func:`fuzzyctl.compile`, which falls back to the numpy path with a warning, a
    loop asked to run native code refuses when it cannot (no C compiler, or a feature the C
    generator cannot express): a simulation labelled "native" must have run the C."""

    def __init__(self, model: Document | FunctionBlock, *, block: str | None = None) -> None:
        import fuzzyctl
        from fuzzyctl.codegen import CodegenError
        from fuzzyctl.engine.native import NativeController, NativeError, build
        from fuzzyctl.type2 import is_type2

        self.name = "native"
        if is_type2(model):  # the type-2 IR program in C (fuzzyctl.engine.type2_compiled)
            from fuzzyctl.engine.type2_compiled import Type2Compiled

            fb = model if isinstance(model, FunctionBlock) else model.block(block)
            self.controller = Type2Compiled(fb, "native")  # type: ignore[assignment]
            self.inputs = tuple(self.controller.inputs)
            self.outputs = tuple(self.controller.outputs)
            return
        plan = fuzzyctl.compile(model, block=block, backend="interpreted").plan
        try:
            library = build(plan)
        except (CodegenError, NativeError) as exc:
            raise InputError(f"controller runtime 'native' cannot run here: {exc}") from exc
        self.controller = NativeController(plan, library)
        self.name = "native"
        self.inputs = tuple(self.controller.inputs)
        self.outputs = tuple(self.controller.outputs)


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
    if kind in ("siemens", "xfuz"):  # the PLC blocks' emulations are type-1
        from fuzzyctl.type2 import refuse

        refuse(model, "blocks")
    if kind == "siemens":
        from fuzzyctl.sim.plc_runtimes import SiemensRuntime

        return SiemensRuntime(model, block=block)
    if kind == "xfuz":
        from fuzzyctl.sim.plc_runtimes import XfuzRuntime

        return XfuzRuntime(model, block=block, cycle=cycle or 0.01)
    if kind == "native":
        return NativeRuntime(model, block=block)
    raise InputError(f"unknown controller runtime {kind!r}; runtimes: {', '.join(RUNTIMES)}")
