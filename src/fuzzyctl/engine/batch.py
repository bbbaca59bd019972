"""Columns of samples through a plan without a :class:`~fuzzyctl.engine.controller.Controller`
(what tuning evaluates each candidate with): the generated numpy evaluator
(:mod:`fuzzyctl.ir.render.npsrc`), or the interpreter row by row for a plan it does not
implement.  No semantics live here."""

from __future__ import annotations

from typing import Any

from fuzzyctl.engine.plan import Plan


class BatchEvaluator:
    """``BatchEvaluator(plan).run(columns, state)`` -> one array per plan output."""

    def __init__(self, plan: Plan) -> None:
        from fuzzyctl.engine.controller import Controller

        self.plan = plan
        self._ctl = Controller(plan)

    def run(self, vals: list[Any], state: list[float | None]) -> list[Any]:
        """Every plan output (plan order) for the input columns ``vals`` (plan input order);
        ``state`` holds the previous outputs (NC) and is updated."""
        self._ctl._state = state
        rows = len(vals[0]) if len(vals) else 1  # a plan without inputs: one evaluation
        out = self._ctl._batch_chunk(list(vals), rows)
        state[:] = self._ctl._state
        return out
