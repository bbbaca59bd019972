"""The evaluator of an interval type-2 block as one IR program
(:mod:`fuzzyctl.ir.builders.type2`), printed as Python (:mod:`~fuzzyctl.ir.render.pysrc`),
numpy (:mod:`~fuzzyctl.ir.render.npsrc`) and the native backend's C
(:func:`fuzzyctl.ir.render.c.render_native`), the same way as the type-1 evaluator: inputs
``FZ_IN<k>``, outputs ``FZ_OUT<k>``, no name of the model in the program."""

from __future__ import annotations

from dataclasses import dataclass
from typing import cast

from fuzzyctl.engine.plan import Plan
from fuzzyctl.ir.builders.type2 import SAMPLES, OutputInfo, Type2Builder
from fuzzyctl.ir.nodes import Program
from fuzzyctl.ir.programs.evaluator import FastProgram
from fuzzyctl.ir.state import Gen
from fuzzyctl.model import FunctionBlock


@dataclass(frozen=True)
class _Named:
    """What the renderers read of a plan: its name (a type-2 block has no type-1 plan)."""

    name: str


@dataclass
class Type2Program:
    fast: FastProgram
    info: list[OutputInfo]


def build_type2_fast(
    fb: FunctionBlock, target: str, samples: int = SAMPLES, method: str | None = None
) -> Type2Program:
    """The evaluator program of ``fb`` for ``target`` (``"py"``, ``"np"`` or ``"c"``)."""
    g = Gen(target)
    inputs = [g.declare(f"FZ_IN{i}", "REAL", "input") for i in range(len(fb.inputs))]
    outputs = [g.declare(f"FZ_OUT{i}", "REAL", "output") for i in range(len(fb.defuzzify))]
    state = g.declare("FZ_PREV", "REAL", "state", max(1, len(outputs)), (0.0,) * max(1, len(outputs)))
    built = Type2Builder(fb, g, samples, method).build(inputs, outputs)
    prog = Program(fb.name or "FUZZY", g.decls, g.b.root, [], g.uses)
    fast = FastProgram(
        prog,
        target,
        [v.name for v in inputs],
        [v.name for v in outputs],
        state.name,
        cast(Plan, _Named(fb.name or "")),  # the renderers read its name only
    )
    return Type2Program(fast, built.info)
