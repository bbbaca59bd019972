"""What every analysis reads: the lowered plan, the input universe, the rules' names and
places, and each condition leaf as a vectorised function of one input (the engine's own
membership, hedge and norm functions, never a second copy of their formulas)."""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any

import numpy as np
import numpy.typing as npt

from fuzzyctl.diagnostics import FuzzyctlError
from fuzzyctl.engine.plan import CDegree, CondPlan, CTerm, Plan, Slot, TermPlan
from fuzzyctl.engine.semantics import shapes

if TYPE_CHECKING:
    from fuzzyctl.engine.controller import Controller
    from fuzzyctl.model import Document, FunctionBlock, Span

FloatArray = npt.NDArray[np.float64]


@dataclass(frozen=True)
class Context:
    """A compiled block ready for analysis."""

    model: FunctionBlock
    path: str | None
    controller: Controller
    plan: Plan
    inputs: tuple[str, ...]  # every VAR_INPUT, in slot order
    ranges: tuple[tuple[float, float], ...]  # per slot: the universe analysed
    rule_names: tuple[str, ...]  # per plan rule: as the file names it
    rule_where: tuple[str | None, ...]  # per plan rule: file:line (None: no span kept)
    #: explanations by input point, shared by the checks that ask the engine at one point
    explained: dict[tuple[float, ...], Any] = field(default_factory=dict, compare=False, repr=False)

    @property
    def block_name(self) -> str | None:
        return self.plan.name


def build_context(model: Document | FunctionBlock, block: str | None = None) -> Context:
    """Compile ``model`` (interpreted backend: no C compiler needed) and gather its names."""
    from fuzzyctl.api import compile as compile_model
    from fuzzyctl.model import Document
    from fuzzyctl.type2 import refuse

    fb = model.block(block) if isinstance(model, Document) else model
    refuse(fb, "analyze")
    path = model.path if isinstance(model, Document) else None
    ctl = compile_model(fb, backend="python")
    plan = ctl.plan
    names = [i.name for i in plan.inputs]
    ranges = tuple(_input_range(plan, ctl, name) for name in names)
    labels, where = _rule_names(fb, plan, path)
    return Context(fb, path, ctl, plan, tuple(names), ranges, labels, where)


def _input_range(plan: Plan, ctl: Controller, name: str) -> tuple[float, float]:
    """RANGE when declared, else the span of the terms' characteristic points (an input
    whose terms end in shoulders has no bound of its own), else [0, 1] (a degree input)."""
    info = ctl.inputs.get(name) if hasattr(ctl.inputs, "get") else None
    lo, hi = (info.low, info.high) if info is not None else (None, None)
    if lo is not None and hi is not None and math.isfinite(lo) and math.isfinite(hi) and lo < hi:
        return (float(lo), float(hi))
    xs: list[float] = []
    for fi in plan.fuzzy_inputs:
        if fi.name == name:
            for t in fi.terms:
                xs.extend(term_points(t))
    xs = [x for x in xs if math.isfinite(x)]
    if len(xs) >= 1 and max(xs) > min(xs):
        return (min(xs), max(xs))
    return (0.0, 1.0)


def term_points(t: TermPlan) -> list[float]:
    """The breakpoints of a piecewise-linear term, else its characteristic points."""
    if t.pwl is not None:
        return [x for x, _y in t.pwl]
    if not t.constant or t.kind in shapes.TS_KINDS:
        return []
    return list(shapes.characteristic_points(t.kind, [float(p) for p in t.params]))  # type: ignore[arg-type]


def _rule_names(
    fb: FunctionBlock, plan: Plan, path: str | None
) -> tuple[tuple[str, ...], tuple[str | None, ...]]:
    spans: dict[tuple[str | None, str], Span | None] = {}
    for rb, rule in fb.rules():
        spans.setdefault((rb.name, rule.label), rule.span)
    counts: dict[str, int] = {}
    for r in plan.rules:
        counts[r.label] = counts.get(r.label, 0) + 1
    names = tuple(r.label if counts[r.label] == 1 else f"{r.block}.{r.label}" for r in plan.rules)
    where = []
    for r in plan.rules:
        span = spans.get((r.block, r.label))
        where.append(f"{path or '<text>'}:{span.line}" if span is not None else None)
    return names, tuple(where)


def term_values(t: TermPlan, x: FloatArray) -> FloatArray:
    """The engine's membership of ``t`` at ``x`` (constant parameters only)."""
    if t.pwl is not None:
        return shapes.pwl_value_np(t.pwl, x)
    if not t.constant or t.kind in shapes.TS_KINDS:
        raise FuzzyctlError(
            f"analyze: term {t.name!r} ({t.kind}) has parameters given by variables or no "
            "membership function of its input alone; the analysis needs constant terms"
        )
    params: list[Any] = [float(p) for p in t.params]  # type: ignore[arg-type]
    return np.asarray(shapes.membership_np(t.kind, params, float(t.height), x), dtype=np.float64)  # type: ignore[arg-type]


def leaf_axis(plan: Plan, leaf: CondPlan) -> int | None:
    """The input slot a leaf reads (None: a chained variable)."""
    if isinstance(leaf, CTerm):
        return plan.fuzzy_inputs[leaf.var].slot
    if isinstance(leaf, CDegree):
        return leaf.slot
    return None


def leaf_values(plan: Plan, leaf: CTerm | CDegree, x: FloatArray) -> FloatArray:
    """A leaf's degree as a function of its input, hedges and NOT applied as the engine does
    (the hedge nearest the term first)."""
    slot = leaf_axis(plan, leaf)
    assert slot is not None
    clamp = plan.inputs[slot].clamp
    if clamp is not None:
        x = np.clip(x, clamp[0], clamp[1])
    if isinstance(leaf, CDegree):
        return np.asarray(x, dtype=np.float64)
    if "any" in leaf.hedges:
        d = np.ones_like(x)
    else:
        d = term_values(plan.fuzzy_inputs[leaf.var].terms[leaf.term], x)
    for h in reversed(leaf.hedges):
        d = shapes.hedge_np(h, d)
    return np.asarray(1.0 - d if leaf.negated else d, dtype=np.float64)


def constant(p: Any) -> float | None:
    """A parameter's value when it is a number."""
    return None if isinstance(p, Slot) else float(p)
