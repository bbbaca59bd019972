"""Off-line analysis: the 3D/4D display, explanations at a point, and the curve recorder's
test signals (the logic is in :mod:`fuzzyctl.studio.analysis`)."""

# No `from __future__ import annotations`: FastAPI reads the annotations at run time.

from typing import Any

from fastapi import APIRouter

from fuzzyctl.studio import analysis
from fuzzyctl.studio.routes.state import StudioDep, model_of, settings_of
from fuzzyctl.studio.schemas import ExplainBody, RecordBody, SurfaceBody

router = APIRouter()


@router.post("/api/surface")
def surface(body: SurfaceBody, studio: StudioDep) -> Any:
    """The 3D display: an output over two inputs (``evaluate_batch``), optionally one
    frame per step of a third input (4D); every grid point is a fresh evaluation."""
    _doc, fb = model_of(body)
    ranges = analysis.display_ranges(fb, settings_of(body))
    return analysis.surface(
        studio.cache.get(analysis.pointwise(fb), "surface"),
        fb,
        x=body.x,
        y=body.y,
        z=body.z,
        fixed=body.fixed,
        ranges=ranges,
        points=body.points,
        animate=body.animate,
        step_percent=body.step_percent,
    )


@router.post("/api/explain")
def explain(body: ExplainBody, studio: StudioDep) -> Any:
    """Term degrees, rule degrees, accumulated sets and outputs at one point."""
    _doc, fb = model_of(body)
    return analysis.explain(studio.cache.get(fb, "explain"), body.inputs)


@router.post("/api/record")
def record(body: RecordBody, studio: StudioDep) -> Any:
    """The curve recorder's off-line test: test signals at the given times and the
    outputs of successive evaluations (``reset`` starts a new recording)."""
    _doc, fb = model_of(body)
    ranges = analysis.display_ranges(fb, settings_of(body))
    signals = {k: v.model_dump() for k, v in body.signals.items()}
    return analysis.record(
        studio.cache.get(fb, "recorder"),
        fb,
        signals=signals,
        times=body.times,
        length=body.length,
        ranges=ranges,
        reset=body.reset,
    )
