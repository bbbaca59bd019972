"""Editing: checking the model and the FCL text, the rule text editor, a term written as
FCL, and the rule viewer (the logic is in :mod:`fuzzyctl.studio.analysis`,
:mod:`fuzzyctl.studio.editing` and :mod:`fuzzyctl.studio.ruleview`)."""

# No `from __future__ import annotations`: FastAPI reads the annotations at run time.

from typing import Any

from fastapi import APIRouter

from fuzzyctl.diagnostics import FuzzyctlError
from fuzzyctl.jsonsafe import clean
from fuzzyctl.kinds.shapes import Shape, placement_tree
from fuzzyctl.model import SHAPES, FunctionBlock
from fuzzyctl.studio import analysis, editing, ruleview
from fuzzyctl.studio.project import split_settings
from fuzzyctl.studio.routes.state import StudioDep, model_of, settings_of
from fuzzyctl.studio.schemas import ModelBody, RulesTextBody, RuleViewBody, TermTextBody, TextBody

router = APIRouter()


def edited_block(body: ModelBody) -> FunctionBlock:
    """The function block being edited, from a request's model."""
    document, _settings = split_settings(analysis.document_from_json(body.document))
    if body.block >= len(document.blocks):
        raise FuzzyctlError(f"block {body.block}: the model has {len(document.blocks)} function block(s)")
    return document.blocks[body.block]


@router.post("/api/check")
def check(body: ModelBody) -> Any:
    """``fuzzyctl check`` of the model: diagnostics tied to elements, the conformance
    level, the FCL text, display ranges.  An invalid model (points out of order) is
    answered like any other: its report says why, tied to the term (the editor shows it);
    the FCL text goes through the same validation as every reader's."""
    document, fb = model_of(body, validated=False)
    text = analysis.fcl_text(document)
    report = analysis.check_text(text)
    ranges = analysis.display_ranges(fb, settings_of(body))
    return clean(
        {
            "text": text,
            "ranges": ranges,
            "curves": analysis.curves(fb, ranges),
            "fcl_losses": analysis.fcl_losses(document),
            **report.to_dict(),
        }
    )


@router.post("/api/parse")
def parse(body: TextBody) -> Any:
    """The text editor: check FCL text; the model when it has no errors."""
    report = analysis.check_text(body.text)
    out: dict[str, Any] = report.to_dict()
    if report.document is not None:
        document, settings = split_settings(report.document)
        out["document"] = analysis.document_to_json(document)
        out["settings"] = settings
        out["ranges"] = analysis.display_ranges(document.main, settings)
    else:
        out["document"] = None
    return clean(out)


def shape_view(spec: Shape) -> dict[str, Any]:
    """A registry entry as the studio's front end reads it (``placement``: expression trees
    over a, b, c and w, see :func:`fuzzyctl.kinds.shapes.placement_tree`)."""
    return {
        "params": list(spec.params),
        "summary": spec.summary,
        "variadic": spec.variadic,
        "family": spec.family,
        "roles": list(spec.roles),
        "placement": [placement_tree(p) for p in spec.studio.placement],
        "handles": [dict(h) for h in spec.studio.handles],
        "polygon": spec.studio.polygon,
        "pickable": spec.studio.pickable,
    }


@router.get("/api/shapes")
def shapes() -> dict[str, Any]:
    """The parametric term kinds the engine reads: parameter names, roles and formulas,
    and how the editor places and drags a term of each (the shape registry's entries:
    the front end keeps no per-kind table)."""
    return {kind: shape_view(spec) for kind, spec in SHAPES.items()}


@router.post("/api/rules/parse")
def rules_parse(body: RulesTextBody) -> Any:
    """The rule text editor: one rule per line, read by the FCL parser and checked;
    the rules when the lines have no errors, diagnostics with the typed lines' numbers."""
    return clean(editing.parse_rules(edited_block(body), body.rule_block, body.text))


@router.post("/api/term/parse")
def term_parse(body: TermTextBody) -> Any:
    """A term written as FCL (any spelling the parser reads): its model form."""
    return clean(editing.parse_term(edited_block(body), body.variable, body.text))


@router.post("/api/ruleview")
def rule_view(body: RuleViewBody, studio: StudioDep) -> Any:
    """The rule viewer's rows at one input point: term degrees, rule degrees and each
    conclusion's activated set, the accumulated sets and the outputs."""
    fb = edited_block(body)
    ranges = analysis.display_ranges(fb, body.settings.model_dump(exclude_none=True))
    return clean(ruleview.rule_view(studio.cache.get(fb, "ruleview"), fb, body.inputs, ranges))
