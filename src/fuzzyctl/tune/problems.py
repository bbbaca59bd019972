"""What one candidate costs: against data (a loss over chunks of rows) or against the plant
(one closed-loop simulation per scenario).  A problem splits a candidate's evaluation into
tasks (:meth:`keys`) that can run anywhere - in this process or on Dask workers - and
combines their results in a fixed order, so the cost is the same bit for bit wherever the
tasks ran."""

from __future__ import annotations

import dataclasses
from collections.abc import Sequence
from dataclasses import dataclass, field
from typing import Any

import numpy as np
import numpy.typing as npt

from fuzzyctl.diagnostics import FuzzyctlError
from fuzzyctl.engine.batch import BatchEvaluator
from fuzzyctl.engine.compile import COMPAT_PROFILES
from fuzzyctl.engine.lowering.lower import lower
from fuzzyctl.engine.plan import Plan
from fuzzyctl.model import Document, FunctionBlock
from fuzzyctl.tune import gradient, plant
from fuzzyctl.tune.data import Columns, loss_value, rows
from fuzzyctl.tune.space import Space

Arr = npt.NDArray[np.float64]
Candidate = npt.NDArray[np.float64] | FunctionBlock
CHUNK_ROWS = 50_000


def _plan(fb: FunctionBlock, compat: str) -> Plan:
    # One lowering per candidate and the engine's numpy batch evaluator: no C compilation and
    # no scalar specialisation for a system that is evaluated once.
    plan, diags = lower(fb, COMPAT_PROFILES[compat])
    if plan is None:  # candidates are valid by construction: this is a bug
        raise FuzzyctlError(
            "internal error: a tuning candidate does not compile: " + "; ".join(d.message for d in diags)
        )
    return plan


@dataclass
class DataProblem:
    """Fit outputs to target columns: loss RMSE, MAE or max error over the training rows."""

    space: Space
    outputs: tuple[str, ...]
    train: Columns
    validation: Columns | None
    loss: str = "rmse"
    compat: str = "iec"
    chunk_rows: int = CHUNK_ROWS
    scales: dict[str, float] = field(default_factory=dict)
    _cache: dict[bytes, Plan] = field(default_factory=dict, repr=False, compare=False)

    def __post_init__(self) -> None:
        inputs = [v.name for v in self.space.block.inputs]
        self.inputs = tuple(i for i in inputs if i in self.train)
        for o in self.outputs:
            y = self.train[o]
            span = float(np.max(y) - np.min(y))
            self.scales.setdefault(o, (span or 1.0) if len(self.outputs) > 1 else 1.0)
        self.penalty = {o: max(1.0, float(np.ptp(self.train[o]))) for o in self.outputs}
        self.type2 = self.space.block.is_type2
        if self.type2:
            # the type-reduced centroid's switch points have no closed-form gradient here
            self.gradient_note: str | None = "an interval type-2 system"
            return
        plan0 = _plan(self.space.block, self.compat)
        self.gradient_note = gradient.unsupported(plan0, self.outputs)
        if self.gradient_note is None and gradient.slot_map(self.space.block, plan0) is None:
            self.gradient_note = "rules that do not map onto the model"

    # ------------------------------------------------------------------ tasks

    def task_keys(self) -> list[int]:
        return list(range(max(1, -(-rows(self.train) // self.chunk_rows))))

    def _rows(self, cols: Columns, key: int) -> slice:
        return slice(key * self.chunk_rows, (key + 1) * self.chunk_rows)

    def candidate_plan(self, cand: Candidate) -> tuple[FunctionBlock, Plan]:
        if isinstance(cand, FunctionBlock):
            return cand, _plan(cand, self.compat)
        tag = np.asarray(cand, dtype=np.float64).tobytes()
        fb = self.space.decode(cand)
        plan = self._cache.get(tag)
        if plan is None:
            plan = _plan(fb, self.compat)
            if len(self._cache) > 8:
                self._cache.clear()
            self._cache[tag] = plan
        return fb, plan

    def predict(self, cand: Candidate, cols: Columns, sl: slice | None = None) -> dict[str, Arr]:
        part = {k: v[sl] if sl is not None else v for k, v in cols.items()}
        n = rows(part)
        if self.type2:
            return self._predict_type2(cand, part, n)
        _fb, plan = self.candidate_plan(cand)
        vals = [part[i.name] if i.name in part else np.full(n, float(i.default or 0.0)) for i in plan.inputs]
        outs = BatchEvaluator(plan).run(vals, [None] * len(plan.outputs))
        return {o.name: outs[k] for k, o in enumerate(plan.outputs) if o.name in self.outputs}

    def _predict_type2(self, cand: Candidate, part: Columns, n: int) -> dict[str, Arr]:
        """The type-2 engine's outputs (one row at a time: it has no batch path yet)."""
        from fuzzyctl.engine.type2 import Type2Controller

        fb = cand if isinstance(cand, FunctionBlock) else self.space.decode(cand)
        data = {
            v.name: part[v.name] if v.name in part else np.full(n, float(v.initial or 0.0)) for v in fb.inputs
        }
        outs = Type2Controller(fb).evaluate_batch(data, out_of_range="ignore")
        return {o: outs[o] for o in self.outputs}

    def residuals(self, cand: Candidate, key: int, cols: Columns | None = None) -> Arr:
        """Scaled residuals (prediction - target) of one chunk, outputs one after the other."""
        cols = self.train if cols is None else cols
        sl = self._rows(cols, key)
        pred = self.predict(cand, cols, sl)
        parts = []
        for o in self.outputs:
            r = pred[o] - cols[o][sl]
            r = np.where(np.isnan(r), self.penalty[o], r)
            parts.append(r / self.scales[o])
        return np.concatenate(parts)

    def task(self, cand: Candidate, key: int) -> tuple[float, float, float, int]:
        r = self.residuals(cand, key)
        return float(np.dot(r, r)), float(np.sum(np.abs(r))), float(np.max(np.abs(r), initial=0.0)), len(r)

    def combine(self, parts: Sequence[tuple[float, float, float, int]]) -> float:
        sse = sum(p[0] for p in parts)
        sae = sum(p[1] for p in parts)
        worst = max((p[2] for p in parts), default=0.0)
        return loss_value(self.loss, sse, sae, worst, sum(p[3] for p in parts))

    def jacobian(self, cand: Arr, key: int) -> tuple[Arr, Arr]:
        """Residuals and their closed-form Jacobian with respect to ``u`` for one chunk."""
        fb, plan = self.candidate_plan(cand)
        smap = gradient.slot_map(fb, plan)
        assert smap is not None
        cols = self.train
        sl = self._rows(cols, key)
        part = {k: v[sl] for k, v in cols.items()}
        n = rows(part)
        vals = [part[i.name] if i.name in part else np.full(n, float(i.default or 0.0)) for i in plan.inputs]
        fwd = gradient.forward(plan, vals, self.outputs)
        deriv = self.space.derivative(cand)
        blocks = []
        for o in self.outputs:
            _y, g = fwd[o]
            J = np.zeros((n, self.space.size))
            for key_, (j, d) in deriv.items():
                ps = smap.get(key_)
                if ps is not None and ps in g:
                    J[:, j] += g[ps] * d
            blocks.append(J / self.scales[o])
        return self.residuals(cand, key), np.vstack(blocks)

    # ------------------------------------------------------------------ reports

    def scores(self, cand: Candidate) -> dict[str, float]:
        """Training and validation errors (the loss, and RMSE/MAE/max per output)."""
        out: dict[str, float] = {}
        for label, cols in (("training", self.train), ("validation", self.validation)):
            if cols is None:
                continue
            pred = self.predict(cand, cols)
            for o in self.outputs:
                r = pred[o] - cols[o]
                r = np.where(np.isnan(r), self.penalty[o], r)
                out[f"{label} RMSE {o}"] = float(np.sqrt(np.mean(r * r)))
                out[f"{label} MAE {o}"] = float(np.mean(np.abs(r)))
                out[f"{label} max error {o}"] = float(np.max(np.abs(r)))
        return out


@dataclass
class PlantProblem:
    """Closed-loop cost: the weighted sum over scenarios of weighted quality figures."""

    space: Space
    document: Document
    block_index: int
    scenarios: list[plant.Scenario]
    weights: dict[str, float]
    runtime: str | None = None

    def task_keys(self) -> list[int]:
        return list(range(len(self.scenarios)))

    def model(self, cand: Candidate) -> Document:
        fb = cand if isinstance(cand, FunctionBlock) else self.space.decode(cand)
        blocks = list(self.document.blocks)
        blocks[self.block_index] = fb
        return dataclasses.replace(self.document, blocks=tuple(blocks))

    def run(self, cand: Candidate, key: int) -> Any:
        return plant.simulate(self.scenarios[key], self.model(cand), self.runtime)

    def task(self, cand: Candidate, key: int) -> dict[str, float]:
        sc = self.scenarios[key]
        values = plant.metrics(sc, self.run(cand, key), list(self.weights))
        values["cost"] = plant.weighted(values, self.weights)
        return values

    def combine(self, parts: Sequence[dict[str, float]]) -> float:
        return float(sum(sc.weight * p["cost"] for sc, p in zip(self.scenarios, parts, strict=True)))
