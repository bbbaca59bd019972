"""Independent views of a Mamdani output's maximum for the integer LM / RM / MoM tests: each
activated set's exact height from the reference interpreter's rule degrees (not from the
generator), the levels where a term's level set jumps found on a fine grid, the away-from-
ties condition the header states, and a brute-force maximum of the accumulated set sampled
on a fine grid."""

from __future__ import annotations

import re
from typing import Any

import numpy as np

from fuzzyctl.codegen.api import lower_block
from fuzzyctl.engine.reference.interp import Interpreter
from fuzzyctl.engine.semantics.operators import CLIP_BRANCH

#: samples per term and per output range for the brute force
FINE = 20001


def with_method(text: str, method: str) -> str:
    """``text`` with every METHOD line set to ``method``."""
    return re.sub(r"METHOD\s*:\s*\w+\s*;", f"METHOD : {method};", text)


def _degrees(points: tuple[tuple[float, float], ...], xs: np.ndarray) -> np.ndarray:
    """A piecewise-linear term sampled (on a vertical edge: the larger value)."""
    px = np.array([p[0] for p in points])
    py = np.array([p[1] for p in points])
    left = np.interp(xs, px, py, left=py[0], right=py[-1])
    right = np.interp(-xs, -px[::-1], py[::-1], left=py[-1], right=py[0])
    return np.maximum(left, right)


def _jumps(y: np.ndarray) -> list[float]:
    """Levels where the running maximum from the left stays flat (the term below it), then
    rises again: the level set's start jumps there."""
    run = np.maximum.accumulate(y)
    out = []
    flat_below = False
    for i in range(1, len(y)):
        if run[i] > run[i - 1] + 1e-12:
            if flat_below:
                out.append(float(run[i - 1]))
            flat_below = False
        elif y[i] < run[i] - 1e-9 and run[i] > 0:
            flat_below = True
    return out


class Heights:
    """The exact heights of the activated sets of output 0 of ``doc``'s first block."""

    def __init__(self, doc: Any) -> None:
        self.plan = lower_block(doc, None)
        self.interp = Interpreter(self.plan)
        op = self.plan.outputs[0]
        self.op = op
        xs = np.linspace(op.low, op.high, FINE)
        self.xs = xs
        self.samples = {}
        self.jumps = {}
        for t, term in enumerate(op.terms):
            y = _degrees(term.pwl, xs)
            self.samples[t] = y
            self.jumps[t] = _jumps(y) + _jumps(y[::-1])

    def slots(self, names: list[str], rows: np.ndarray) -> list[list[float]]:
        """Rows of values in ``names``' order as the interpreter's input vectors."""
        idx = [self.plan.input_index(n) for n in names]
        out = []
        for row in rows:
            v = [0.0] * len(self.plan.inputs)
            for i, x in zip(idx, row, strict=True):
                v[i] = float(x)
            out.append(v)
        return out

    def sets(self, values: list[float]) -> tuple[dict[tuple[int, str, float], float], list[float]]:
        """``({(term, act, weight): height}, rule degrees)`` at the input values (by slot)."""
        rec = self.interp.run(values, [None] * len(self.plan.outputs))
        out: dict[tuple[int, str, float], float] = {}
        for c in self.op.contributions:
            w = float(c.weight)
            peak = float(self.samples[c.term].max())
            a = rec.rule_degrees[c.rule] * w
            h = min(a, w * peak) if c.act in CLIP_BRANCH else a * peak
            key = (c.term, c.act, w)
            out[key] = max(out.get(key, 0.0), h)
        return out, list(rec.rule_degrees)

    def away(self, values: list[float], margin: float) -> bool:
        """One set alone at the top, every other set more than ``margin`` below, the top above
        ``margin`` and more than ``margin`` from the top set's jump levels."""
        hs, _deg = self.sets(values)
        ranked = sorted(hs.items(), key=lambda kv: -kv[1])
        (term, act, w), top = ranked[0]
        if top <= margin:
            return False
        if len(ranked) > 1 and ranked[1][1] >= top - margin:
            return False
        return not (act in CLIP_BRANCH and any(abs(top - w * j) <= margin for j in self.jumps[term]))

    def brute(self, values: list[float], method: str) -> float:
        """LM / RM / MoM of the accumulated set (MAX) sampled on the fine grid."""
        _hs, deg = self.sets(values)
        mu = np.zeros_like(self.xs)
        for c in self.op.contributions:
            w = float(c.weight)
            a = deg[c.rule] * w
            y = w * self.samples[c.term]
            mu = np.maximum(mu, np.minimum(a, y) if c.act in CLIP_BRANCH else a * self.samples[c.term])
        at = self.xs[mu >= mu.max() * (1 - 1e-9)]
        if method == "LM":
            return float(at[0])
        if method == "RM":
            return float(at[-1])
        return float(at.mean())
