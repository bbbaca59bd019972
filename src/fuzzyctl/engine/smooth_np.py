"""Smooth Mamdani outputs on columns of samples (placeholder: row by row)."""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any

import numpy as np

from fuzzyctl.engine.plan import OutputPlan, Plan


def smooth_output(
    plan: Plan, op: OutputPlan, contribs: list[tuple[int, Any, Any, str]], vals: Sequence[Any], outs: Sequence[Any], n: int
) -> tuple[Any, Any]:
    from fuzzyctl.engine.interp import Interpreter

    interp = Interpreter(plan)
    value = np.full(n, np.nan)
    fired = np.zeros(n, dtype=bool)
    for r in range(n):
        cs = []
        for t, a, w, act in contribs:
            ar = float(np.asarray(a)[r] if np.ndim(a) else a)
            wr = float(np.asarray(w)[r] if np.ndim(w) else w)
            if ar * wr > 0.0:
                cs.append((t, ar, wr, act))
        rec = interp.output_from(op, cs, [float(v[r]) for v in vals], [float(o[r]) for o in outs])
        value[r], fired[r] = rec.value, rec.fired
    return value, fired
