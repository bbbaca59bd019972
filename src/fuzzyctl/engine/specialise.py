"""Specialisation of the scalar path (placeholder: the interpreter)."""

from __future__ import annotations

from collections.abc import Callable

from fuzzyctl.engine.interp import Interpreter
from fuzzyctl.engine.plan import Plan


def specialise(plan: Plan) -> Callable[[list[float], list[float | None]], list[float]]:
    interp = Interpreter(plan)

    def run(values: list[float], state: list[float | None]) -> list[float]:
        return [o.value for o in interp.run(values, state).outputs]

    return run
