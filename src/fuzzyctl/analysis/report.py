"""The result of :func:`fuzzyctl.analyze`: typed findings, the stable JSON and a text view."""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Any

from fuzzyctl.analysis.conflicts import Conflict
from fuzzyctl.analysis.gaps import Gap
from fuzzyctl.analysis.monotonicity import Monotonicity
from fuzzyctl.analysis.redundancy import Redundant, UnusedTerm
from fuzzyctl.analysis.surface import SurfaceFacts


def _num(x: float) -> float | None:
    return float(x) if math.isfinite(x) else None


def _pt(point: dict[str, float]) -> str:
    return "(" + ", ".join(f"{k}={v:.6g}" for k, v in point.items()) + ")"


def _box(box: dict[str, tuple[float, float]]) -> dict[str, list[float | None]]:
    return {k: [_num(lo), _num(hi)] for k, (lo, hi) in box.items()}


@dataclass
class Analysis:
    """Everything ``fuzzyctl analyze`` finds in one function block.  ``exact`` is False when
    the gap boxes were decided at one point per cell rather than exactly (``notes`` say why);
    ``cells`` is the number of cells of the decomposition."""

    block: str | None
    inputs: dict[str, tuple[float, float]]
    epsilon: float
    delta: float
    gaps: list[Gap]
    coverage_index: float
    gap_fraction: float
    conflicts: list[Conflict]
    dead_rules: list[str]
    redundant: list[Redundant]
    unused_terms: list[UnusedTerm]
    monotonicity: list[Monotonicity]
    surface: list[SurfaceFacts]
    exact: bool
    cells: int
    notes: list[str] = field(default_factory=list)
    rule_where: dict[str, str | None] = field(default_factory=dict)

    def to_json(self) -> dict[str, Any]:
        """The stable JSON object of docs/analyze.md (keys exactly as documented)."""
        return {
            "block": self.block,
            "inputs": {k: [lo, hi] for k, (lo, hi) in self.inputs.items()},
            "gaps": [
                {"output": g.output, "box": _box(g.box), "best_degree": g.best_degree} for g in self.gaps
            ],
            "coverage_index": self.coverage_index,
            "gap_fraction": self.gap_fraction,
            "conflicts": [
                {
                    "rules": list(c.rules),
                    "output": c.output,
                    "box": _box(c.box),
                    "joint_degree": c.joint_degree,
                }
                for c in self.conflicts
            ],
            "dead_rules": list(self.dead_rules),
            "redundant": [
                {"rule": r.rule, "covered_by": r.covered_by, "kind": r.kind} for r in self.redundant
            ],
            "unused_terms": [{"variable": u.variable, "term": u.term} for u in self.unused_terms],
            "monotonicity": [
                {
                    "output": m.output,
                    "input": m.input,
                    "declared": m.declared,
                    "rule_table": m.rule_table,
                    "counterexamples": [[a, b] for a, b in m.counterexamples],
                }
                for m in self.monotonicity
            ],
        }

    def lines(self) -> list[str]:
        """The findings as text lines, rules at file:line."""
        w = self.rule_where

        def at(rule: str) -> str:
            return f"rule {rule}" + (f" ({w[rule]})" if w.get(rule) else "")

        out = [
            f"gaps: {len(self.gaps)} box(es), {self.gap_fraction:.4g} of the input space; "
            f"coverage index {self.coverage_index:.4g}"
        ]
        for g in self.gaps[:20]:
            box = ", ".join(f"{k} in [{lo:.6g}, {hi:.6g}]" for k, (lo, hi) in g.box.items())
            out.append(f"  {g.output}: {box} (best degree {g.best_degree:.3g})")
        out += [
            f"conflict: {at(c.rules[0])} and {at(c.rules[1])} conclude "
            f"{c.output} IS {c.terms[0]} / {c.terms[1]}, "
            f"joint degree {c.joint_degree:.3g} at {_pt(c.point)}"
            for c in self.conflicts
        ]
        out += [f"dead: {at(r)} never fires" for r in self.dead_rules]
        out += [f"{r.kind}: {at(r.rule)} is covered by {at(r.covered_by)}" for r in self.redundant]
        out += [f"unused term: {u.variable}.{u.term} ({u.reason})" for u in self.unused_terms]
        for m in self.monotonicity:
            state = "proven" if m.proven else m.rule_table
            out.append(f"monotone {m.output} {m.declared}{m.input}: rule table {state}")
            out += [f"  rules {a} < {b} conclude against the declaration" for a, b in m.offending]
            if m.counterexamples:
                out += [f"  surface: {_pt(a)} -> {_pt(b)}" for a, b in m.counterexamples]
            else:
                out.append(f"  surface: no counterexample on a {m.resolution}-point-per-input grid")
        for s in self.surface:
            out.append(
                f"surface {s.output}: min {s.low:.6g} at {_pt(s.low_at)}, "
                f"max {s.high:.6g} at {_pt(s.high_at)}, "
                + (f"largest slope {s.slope:.4g} per unit of {s.slope_input}" if s.slope_input else "flat")
            )
            out += [
                f"  jump {j.values[0]:.6g} -> {j.values[1]:.6g} between {_pt(j.before)} and {_pt(j.after)}"
                for j in s.jumps[:5]
            ]
        out += [f"note: {n}" for n in self.notes]
        return out
