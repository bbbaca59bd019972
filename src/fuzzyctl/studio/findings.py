"""The studio's analysis findings (docs/studio.md, "Findings"): what ``fuzzyctl analyze``
finds in the edited block - gaps, conflicts, dead, duplicate and subsumed rules, unused
terms, monotonicity against declared signs - as check-panel entries at the line of the FCL
text and the element they concern, and the gap boxes with, per input, the terms that reach
above 0 inside each box (the cells of the rule matrix a rule could cover the gap from).

Kept in its own router (``/api/findings``): the check itself stays as fast as before, and
the browser asks for the findings after each check."""

# No `from __future__ import annotations`: FastAPI reads the annotations at run time.

from typing import Annotated, Any

import numpy as np
from fastapi import APIRouter
from pydantic import Field, StringConstraints

from fuzzyctl.diagnostics import DiagnosticError, FuzzyctlError
from fuzzyctl.jsonsafe import clean
from fuzzyctl.model import FunctionBlock
from fuzzyctl.studio import analysis
from fuzzyctl.studio.project import split_settings
from fuzzyctl.studio.schemas import ModelBody

#: points per interval where a smooth term's highest value in a box is looked for (a
#: piecewise-linear term's is exact: its breakpoints inside and the ends)
SMOOTH_SAMPLES = 257


class FindingsBody(ModelBody):
    """The model, the declared monotonicity (``"valve:-temp,+flow"``, as ``--monotone``), and
    the FCL text the check panel's lines refer to (the file as opened, or the check's text
    after an edit); without it, the model's FCL text."""

    text: Annotated[str, StringConstraints(max_length=5_000_000)] | None = None
    monotone: Annotated[
        list[Annotated[str, StringConstraints(max_length=1000)]], Field(default_factory=list, max_length=50)
    ]


def term_peak(term: Any, lo: float, hi: float) -> float:
    """The highest membership of ``term`` (a plan term) on [lo, hi]: at the ends and the
    breakpoints inside for a piecewise-linear term (exact), on a sample for a smooth one."""
    from fuzzyctl.analysis.context import term_values

    if term.pwl is not None:
        xs = [lo, hi, *(x for x, _y in term.pwl if lo < x < hi)]
    else:
        xs = list(np.linspace(lo, hi, SMOOTH_SAMPLES))
    return float(np.max(term_values(term, np.asarray(xs, dtype=np.float64))))


def gap_terms(fb: FunctionBlock, gaps: list[Any]) -> list[dict[str, Any]]:
    """Each gap box with, per input, the terms whose membership is above 0 somewhere in it."""
    from fuzzyctl.analysis.context import build_context

    ctx = build_context(fb)
    out = []
    for g in gaps:
        terms: dict[str, list[str]] = {}
        for fi in ctx.plan.fuzzy_inputs:
            lo, hi = g.box[fi.name]
            try:
                terms[fi.name] = [t.name for t in fi.terms if term_peak(t, lo, hi) > 0.0]
            except FuzzyctlError:  # a term with variable parameters: every term may reach it
                terms[fi.name] = [t.name for t in fi.terms]
        box = {k: [lo, hi] for k, (lo, hi) in g.box.items()}
        out.append({"output": g.output, "box": box, "terms": terms})
    return out


def element_lines(fb: FunctionBlock) -> dict[int, str]:
    """Line of the FCL text -> the studio's element id there (rules, variable declarations)."""
    lines: dict[int, str] = {}
    for v in fb.variables:
        if v.span is not None:
            lines.setdefault(v.span.line, f"var:{v.name}")
    for i, rb in enumerate(fb.rule_blocks):
        for j, rule in enumerate(rb.rules):
            if rule.span is not None:
                lines[rule.span.line] = f"rule:{i}:{j}"
    return lines


def findings(document: Any, block: int, monotone: list[str], text: str | None = None) -> dict[str, Any]:
    """The findings of block ``block`` of ``document`` (lines: of ``text``, the FCL text of
    the model the check panel shows, else of the model's FCL text)."""
    from fuzzyctl.analysis import analyze
    from fuzzyctl.analysis.findings import block_diagnostics
    from fuzzyctl.fcl import load_text

    parsed = load_text(text).document if text is not None else None
    if parsed is None or block >= len(parsed.blocks):
        parsed = load_text(analysis.fcl_text(document)).document
    if parsed is None or block >= len(parsed.blocks):
        return {"ok": False, "error": "the model has errors: see the check", "findings": [], "gaps": []}
    fb = parsed.blocks[block]
    try:
        res = analyze(fb, monotone=monotone, surface=bool(monotone))
        gaps = gap_terms(fb, res.gaps)
    except FuzzyctlError as exc:
        return {"ok": False, "error": f"analysis: {exc}", "findings": [], "gaps": []}
    lines = element_lines(fb)
    items = []
    for d in block_diagnostics(fb, res, None):
        item = d.to_dict()
        item["element"] = lines.get(item["line"]) if item["line"] else None
        items.append(item)
    for m in res.monotonicity:
        for a, b in m.counterexamples[:1]:  # one per declaration: the pair, re-evaluated by the engine
            items.append(
                {
                    "severity": "warning",
                    "code": "analyze-monotone",
                    "message": f"monotonicity: {m.output} moves against {m.declared}{m.input} between "
                    + f"{_point(a)} and {_point(b)}",
                    "line": None,
                    "column": None,
                    "element": None,
                }
            )
    return {
        "ok": True,
        "error": None,
        "inputs": {k: [lo, hi] for k, (lo, hi) in res.inputs.items()},
        "gaps": gaps,
        "gap_fraction": res.gap_fraction,
        "coverage_index": res.coverage_index,
        "dead_rules": res.dead_rules,
        "findings": items,
        "notes": res.notes,
    }


def _point(p: dict[str, float]) -> str:
    return "(" + ", ".join(f"{k}={v:.4g}" for k, v in p.items()) + ")"


#: ``POST /api/findings`` (mounted by :func:`fuzzyctl.studio.app.create_app` with the areas' routers).
router = APIRouter()


@router.post("/api/findings")
def post_findings(body: FindingsBody) -> Any:
    """The analysis of the edited block: check-panel entries and gap boxes."""
    try:
        document, _settings = split_settings(analysis.document_from_json(body.document))
    except DiagnosticError:  # an invalid model (points out of order): the check says why
        return {"ok": False, "error": "the model has errors: see the check", "findings": [], "gaps": []}
    return clean(findings(document, body.block, list(body.monotone), body.text))
